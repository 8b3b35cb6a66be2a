/* sim/chipmemest.c -- a sampled chip's memory figures: the opening counted exactly, the rest by the
 * regression estimator with each unit's first-read lines as one more auxiliary (formulas:
 * chipmemest.h). Pure: no I/O, no threads; working arrays are allocated per call and freed before
 * it returns. */
#include "chipmemest.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sampling.h"

/* A stratum (the rest R, or the first passes F): its units' auxiliaries (kr columns), the
 * sample's units in it as indices into it, and their figures. */
typedef struct Stratum {
    uint32_t NR, nr, kr;
    double *x;       /* NR x kr */
    uint32_t *sample; /* nr */
    double *y;       /* CME_COUNT x nr: y[q * n + s] (rows n apart: the first nr of each used) */
    double *z;       /* nr: a ratio's linearized variable */
} Stratum;

enum { S_OPEN, S_REST, S_FIRST };

static void strat_free(Stratum *r)
{
    free(r->x);
    free(r->sample);
    free(r->y);
    free(r->z);
}

static int bad_args(const ChipMemIn *in)
{
    return !in || in->N == 0 || (in->n > 0 && (!in->sample || !in->ys)) || (in->k > 0 && !in->x) ||
           in->k + 1 > SAMPLE_MAX_AUX || in->n > in->N || in->nwaves > CHIPMEM_MAX_WAVES ||
           (in->nwaves > 0 && (!in->wave_diff || !in->wave_units));
}

static int which(const ChipMemIn *in, uint32_t u)
{
    if (in->opened && in->opened[u])
        return S_OPEN;
    return in->first_pass && in->first_pass[u] ? S_FIRST : S_REST;
}

/* The stratum id built from in: R's auxiliaries are the golden counts and first_u, F's first_u
 * alone (its sample is a handful of units). -1 on OOM, a sample index out of range or repeated,
 * or a unit of the sample's extra part (index >= in->n_srs) outside F. */
static int strat_init(Stratum *r, const ChipMemIn *in, int id)
{
    memset(r, 0, sizeof *r);
    const uint32_t N = in->N;
    uint32_t *map = malloc((size_t)N * sizeof *map); /* unit -> its index in the stratum, or UINT32_MAX */
    if (!map)
        return -1;
    for (uint32_t u = 0; u < N; u++)
        map[u] = which(in, u) == id ? r->NR++ : UINT32_MAX;
    const uint32_t kx = id == S_REST ? in->k : 0;
    r->kr = kx + (in->first ? 1 : 0);
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
        for (uint32_t j = 0; j < kx; j++)
            xr[j] = in->x[(size_t)u * in->k + j];
        if (in->first)
            xr[kx] = in->first[u];
    }
    const uint32_t nsrs = in->n_srs ? in->n_srs : in->n;
    for (uint32_t s = 0; rc == 0 && s < in->n; s++) {
        const uint32_t u = in->sample[s];
        if (u >= N || seen[u] || (s >= nsrs && which(in, u) != S_FIRST)) {
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
    free(seen);
    free(map);
    return rc;
}

/* The regression estimate of a stratum's total of the sample's v (nr values); a census of an empty
 * stratum is 0 exactly. -1 when the fit cannot be made. */
static int strat_total(const Stratum *r, const double *v, SampleEstimate *e)
{
    if (r->NR == 0) {
        memset(e, 0, sizeof *e);
        return 0;
    }
    return sample_regression_estimate(v, r->x, r->kr, r->sample, r->nr, r->NR, e);
}

/* Two strata's estimates added: the total, its standard error, and the t of Satterthwaite's
 * degrees of freedom (Cochran 1977, Sec. 5.4); a census of both gives t = 1.96 (no sampling
 * error to scale). */
typedef struct Sum {
    double total, se, t;
} Sum;

static Sum sum_of(const SampleEstimate *a, const SampleEstimate *b)
{
    const double va = a->std_error * a->std_error, vb = b->std_error * b->std_error;
    Sum s = {a->total + b->total, sqrt(va + vb), 1.959963985};
    double den = 0.0;
    if (va > 0.0 && a->df > 0)
        den += va * va / a->df;
    if (vb > 0.0 && b->df > 0)
        den += vb * vb / b->df;
    if (den > 0.0) {
        const double df = (va + vb) * (va + vb) / den;
        s.t = sample_t975(df < 1.0 ? 1u : (uint32_t)df);
    }
    return s;
}

/* The other cores' correction of each figure's total (chipmemest.h): each stratum's units (R's
 * N[0], F's N[1]) times the waves' mean of together less alone per unit of it, leaving wave
 * `leave` out (-1: none); a stratum no wave measured adds 0. 0 without 2 waves. */
static void wave_corr(const ChipMemIn *in, const double N[2], int leave, double c[CME_COUNT])
{
    double sum[2][CME_COUNT] = {{0}}, n[2] = {0};
    for (uint32_t w = 0; in->nwaves >= 2 && w < in->nwaves; w++) {
        if ((int)w == leave)
            continue;
        for (int f = 0; f < 2; f++) {
            n[f] += in->wave_units[2 * w + (uint32_t)f];
            for (int q = 0; q < CME_COUNT; q++)
                sum[f][q] += in->wave_diff[((size_t)w * 2 + (size_t)f) * CME_COUNT + (size_t)q];
        }
    }
    if (!in->first_pass) { /* no stratum F: every unit measured is one of R */
        n[0] += n[1];
        n[1] = 0.0;
        for (int q = 0; q < CME_COUNT; q++)
            sum[0][q] += sum[1][q];
    }
    for (int q = 0; q < CME_COUNT; q++)
        c[q] = (n[0] > 0.0 ? N[0] * sum[0][q] / n[0] : 0.0) + (n[1] > 0.0 ? N[1] * sum[1][q] / n[1] : 0.0);
}

/* The half-width the correction adds to figure g(c) (g of the corrected totals): t_{W-1} times the
 * delete-one jackknife's standard error over the W waves; 0 without 2 waves. */
typedef double (*Figure)(const double tot[CME_COUNT], const void *ctx);

static double wave_half(const ChipMemIn *in, const double N[2], const double base[CME_COUNT], Figure g, const void *ctx)
{
    const uint32_t W = in->nwaves;
    if (W < 2)
        return 0.0;
    double v[CHIPMEM_MAX_WAVES], mean = 0.0, var = 0.0;
    for (uint32_t w = 0; w < W; w++) {
        double c[CME_COUNT], t[CME_COUNT];
        wave_corr(in, N, (int)w, c);
        for (int q = 0; q < CME_COUNT; q++)
            t[q] = base[q] + c[q];
        v[w] = g(t, ctx);
        mean += v[w] / W;
    }
    for (uint32_t w = 0; w < W; w++)
        var += (v[w] - mean) * (v[w] - mean);
    var *= (double)(W - 1) / W;
    return sample_t975(W - 1) * sqrt(var);
}

typedef struct RatioOf {
    int qy, qx;
} RatioOf;

static double ratio_fig(const double t[CME_COUNT], const void *ctx)
{
    const RatioOf *r = ctx;
    return t[r->qx] > 0.0 ? t[r->qy] / t[r->qx] : 0.0;
}

/* A ratio of two frame totals Y = oy + Yhat(R) + Yhat(F) + cy, X likewise (c the correction), with
 * its interval into f[3]: the sampling's half-width and the correction's added in quadrature. */
static int ratio(Stratum st[2], const ChipMemIn *in, const double base[CME_COUNT], const double corr[CME_COUNT],
                 int qy, int qx, double hi_cap, double f[3])
{
    const double Y = base[qy] + corr[qy], X = base[qx] + corr[qx];
    if (!(X > 0.0))
        return -1;
    const double R = Y / X;
    SampleEstimate ez[2];
    for (int i = 0; i < 2; i++) {
        const double *y = st[i].y + (size_t)qy * in->n, *x = st[i].y + (size_t)qx * in->n;
        for (uint32_t s = 0; s < st[i].nr; s++)
            st[i].z[s] = y[s] - R * x[s];
        if (strat_total(&st[i], st[i].z, &ez[i]) != 0)
            return -1;
    }
    const Sum z = sum_of(&ez[0], &ez[1]);
    const RatioOf ro = {qy, qx};
    const double N[2] = {st[0].NR, st[1].NR};
    const double hs = z.t * z.se / X, hw = wave_half(in, N, base, ratio_fig, &ro);
    const double h = sqrt(hs * hs + hw * hw);
    f[0] = R;
    f[1] = R - h > 0.0 ? R - h : 0.0;
    f[2] = R + h < hi_cap ? R + h : hi_cap;
    return 0;
}

static double bytes_fig(const double t[CME_COUNT], const void *ctx)
{
    (void)ctx;
    return t[CME_DRAM_BYTES];
}

int chip_mem_estimate(const ChipMemIn *in, ChipMemOut *out)
{
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if (bad_args(in))
        return -1;
    Stratum st[2]; /* R, F */
    int rc = strat_init(&st[0], in, S_REST);
    rc = strat_init(&st[1], in, S_FIRST) == 0 ? rc : -1;
    for (int i = 0; rc == 0 && i < 2; i++)
        if (st[i].nr < 2 && st[i].nr < st[i].NR)
            rc = -1;
    Sum tot[CME_COUNT];
    double base[CME_COUNT], corr[CME_COUNT];
    for (int q = 0; rc == 0 && q < CME_COUNT; q++) {
        SampleEstimate e[2];
        for (int i = 0; rc == 0 && i < 2; i++)
            rc = strat_total(&st[i], st[i].y + (size_t)q * in->n, &e[i]);
        if (rc == 0) {
            tot[q] = sum_of(&e[0], &e[1]);
            base[q] = in->open[q] + tot[q].total;
        }
    }
    const double N[2] = {st[0].NR, st[1].NR};
    if (rc == 0) {
        wave_corr(in, N, -1, corr);
        for (int q = 0; q < CME_COUNT; q++) {
            if (base[q] + corr[q] < 0.0) /* (a total is never below 0) */
                corr[q] = -base[q];
            out->total[q] = base[q] + corr[q];
            out->total_se[q] = tot[q].se;
            out->correction[q] = corr[q];
        }
        out->waves = in->nwaves >= 2 ? in->nwaves : 0;
    }
    if (rc == 0)
        rc = ratio(st, in, base, corr, CME_LATENCY, CME_REQUESTS, INFINITY, out->latency);
    if (rc == 0 && in->has_l2)
        rc = ratio(st, in, base, corr, CME_L2_HITS, CME_L2_ACCESSES, 1.0, out->l2_hit_rate);
    const double secs = in->clock_mhz > 0.0 ? in->makespan / (in->clock_mhz * 1e6) : 0.0;
    if (rc == 0 && secs > 0.0) {
        const double B = out->total[CME_DRAM_BYTES], gbs = B / secs / 1e9;
        const double rb = B > 0.0 ? out->total_se[CME_DRAM_BYTES] / B : 0.0;
        const double rm = in->makespan_se / in->makespan;
        const double hs = tot[CME_DRAM_BYTES].t * gbs * sqrt(rb * rb + rm * rm);
        const double hw = wave_half(in, N, base, bytes_fig, NULL) / secs / 1e9;
        const double h = sqrt(hs * hs + hw * hw);
        out->dram_gbs[0] = gbs;
        out->dram_gbs[1] = gbs - h > 0.0 ? gbs - h : 0.0;
        out->dram_gbs[2] = gbs + h;
    } else if (rc == 0) {
        rc = -1;
    }
    out->n_rest = st[0].nr;
    out->n_first = st[1].nr;
    strat_free(&st[0]);
    strat_free(&st[1]);
    if (rc != 0) {
        memset(out, 0, sizeof *out);
        return -1;
    }
    out->has_mem = 1;
    out->has_l2 = in->has_l2;
    return 0;
}
