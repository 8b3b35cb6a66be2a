/* sim/chipmemest.c -- a sampled chip's memory figures: the opening counted exactly, the rest by the
 * regression estimator with each unit's first-read lines as one more auxiliary (formulas:
 * chipmemest.h). Pure: no I/O, no threads; working arrays are allocated per call and freed before
 * it returns. */
#include "chipmemest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sampling.h"

/* The rest R: its units' auxiliaries (x then first, kr columns), the sample's units in R as
 * indices into it, and their figures. */
typedef struct Rest {
    uint32_t NR, nr, kr;
    double *x;       /* NR x kr */
    uint32_t *sample; /* nr */
    double *y;       /* CME_COUNT x nr: y[q * nr + s] */
    double *z;       /* nr: a ratio's linearized variable */
} Rest;

static void rest_free(Rest *r)
{
    free(r->x);
    free(r->sample);
    free(r->y);
    free(r->z);
}

static int bad_args(const ChipMemIn *in)
{
    return !in || in->N == 0 || (in->n > 0 && (!in->sample || !in->ys)) || (in->k > 0 && !in->x) ||
           in->k + 1 > SAMPLE_MAX_AUX || in->n > in->N;
}

/* R built from in; -1 on OOM or a sample index out of range or repeated. */
static int rest_init(Rest *r, const ChipMemIn *in)
{
    memset(r, 0, sizeof *r);
    const uint32_t N = in->N;
    uint32_t *map = malloc((size_t)N * sizeof *map); /* unit -> its index in R, or UINT32_MAX */
    if (!map)
        return -1;
    for (uint32_t u = 0; u < N; u++)
        if (!in->opened || !in->opened[u])
            map[u] = r->NR++;
        else
            map[u] = UINT32_MAX;
    r->kr = in->k + (in->first ? 1 : 0);
    r->x = malloc(((size_t)r->NR * r->kr + 1) * sizeof *r->x);
    r->sample = malloc(((size_t)in->n + 1) * sizeof *r->sample);
    r->y = malloc(((size_t)in->n * CME_COUNT + 1) * sizeof *r->y);
    r->z = malloc(((size_t)in->n + 1) * sizeof *r->z);
    uint8_t *seen = calloc(N, 1);
    int rc = r->x && r->sample && r->y && r->z && seen ? 0 : -1;
    for (uint32_t u = 0; rc == 0 && u < N; u++) {
        if (map[u] == UINT32_MAX)
            continue;
        double *xr = r->x + (size_t)map[u] * r->kr;
        for (uint32_t j = 0; j < in->k; j++)
            xr[j] = in->x[(size_t)u * in->k + j];
        if (in->first)
            xr[in->k] = in->first[u];
    }
    for (uint32_t s = 0; rc == 0 && s < in->n; s++) {
        const uint32_t u = in->sample[s];
        if (u >= N || seen[u]) {
            rc = -1;
            break;
        }
        seen[u] = 1;
        if (map[u] == UINT32_MAX)
            continue;
        r->sample[r->nr] = map[u];
        for (int q = 0; q < CME_COUNT; q++)
            r->y[(size_t)q * in->n + r->nr] = in->ys[(size_t)s * CME_COUNT + q];
        r->nr++;
    }
    /* (y's rows are n apart: only the first nr of each are used) */
    free(seen);
    free(map);
    return rc;
}

/* The regression estimate of R's total of the sample's v (nr values); a census of an empty R is
 * 0 exactly. -1 when the fit cannot be made. */
static int rest_total(const Rest *r, const double *v, SampleEstimate *e)
{
    if (r->NR == 0) {
        memset(e, 0, sizeof *e);
        return 0;
    }
    return sample_regression_estimate(v, r->x, r->kr, r->sample, r->nr, r->NR, e);
}

/* A ratio of two frame totals Y = oy + Yhat(R), X = ox + Xhat(R) with its interval into f[3]. */
static int ratio(const Rest *r, const ChipMemIn *in, int qy, int qx, double hi_cap, double f[3])
{
    const double *y = r->y + (size_t)qy * in->n, *x = r->y + (size_t)qx * in->n;
    SampleEstimate ey, ex, ez;
    if (rest_total(r, y, &ey) != 0 || rest_total(r, x, &ex) != 0)
        return -1;
    const double Y = in->open[qy] + ey.total, X = in->open[qx] + ex.total;
    if (!(X > 0.0))
        return -1;
    const double R = Y / X;
    for (uint32_t s = 0; s < r->nr; s++)
        r->z[s] = y[s] - R * x[s];
    if (rest_total(r, r->z, &ez) != 0)
        return -1;
    const double h = ez.t * ez.std_error / X;
    f[0] = R;
    f[1] = R - h > 0.0 ? R - h : 0.0;
    f[2] = R + h < hi_cap ? R + h : hi_cap;
    return 0;
}

int chip_mem_estimate(const ChipMemIn *in, ChipMemOut *out)
{
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if (bad_args(in))
        return -1;
    Rest r;
    int rc = rest_init(&r, in);
    if (rc == 0 && r.nr < 2 && r.nr < r.NR)
        rc = -1;
    SampleEstimate e[CME_COUNT];
    for (int q = 0; rc == 0 && q < CME_COUNT; q++) {
        rc = rest_total(&r, r.y + (size_t)q * in->n, &e[q]);
        out->total[q] = in->open[q] + e[q].total;
        out->total_se[q] = e[q].std_error;
    }
    if (rc == 0)
        rc = ratio(&r, in, CME_LATENCY, CME_REQUESTS, INFINITY, out->latency);
    if (rc == 0 && in->has_l2)
        rc = ratio(&r, in, CME_L2_HITS, CME_L2_ACCESSES, 1.0, out->l2_hit_rate);
    const double secs = in->clock_mhz > 0.0 ? in->makespan / (in->clock_mhz * 1e6) : 0.0;
    if (rc == 0 && secs > 0.0) {
        const double B = out->total[CME_DRAM_BYTES], gbs = B / secs / 1e9;
        const double rb = B > 0.0 ? out->total_se[CME_DRAM_BYTES] / B : 0.0;
        const double rm = in->makespan_se / in->makespan;
        const double t = e[CME_DRAM_BYTES].t > 0.0 ? e[CME_DRAM_BYTES].t : 1.959963985; /* (R a census) */
        const double h = t * gbs * sqrt(rb * rb + rm * rm);
        out->dram_gbs[0] = gbs;
        out->dram_gbs[1] = gbs - h > 0.0 ? gbs - h : 0.0;
        out->dram_gbs[2] = gbs + h;
    } else if (rc == 0) {
        rc = -1;
    }
    out->n_rest = r.nr;
    rest_free(&r);
    if (rc != 0) {
        memset(out, 0, sizeof *out);
        return -1;
    }
    out->has_mem = 1;
    out->has_l2 = in->has_l2;
    return 0;
}
