/* sim/chipsampling.c -- the chip distributor's list schedule and the tile-effect estimate of a
 * sampled chip frame's makespan (formulas: chipsampling.h; design and measured coverage:
 * docs/sampling.md, "Sampling a chip"). Pure functions: no I/O, no threads; working arrays are
 * allocated per call and freed before it returns. Must not run or time anything. The regression
 * fit and its refits are sampling.h's; the draws' generator is its splitmix64. */
#include "chipsampling.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---- the distributor's list schedule ---------------------------------------------------------- */

typedef struct ChipSlot {
    double free;   /* the cycle the core becomes idle */
    uint32_t core;
} ChipSlot;

/* The distributor's order: idle first, then the lowest core. A strict total order (cores are
 * distinct), so the heap's top is the one core the distributor picks. */
static int chip_slot_before(const ChipSlot *a, const ChipSlot *b)
{
    return a->free < b->free || (a->free == b->free && a->core < b->core);
}

static void chip_heap_sift_down(ChipSlot *h, uint32_t m)
{
    uint32_t i = 0;
    for (;;) {
        uint32_t l = 2 * i + 1, r = l + 1, best = i;
        if (l < m && chip_slot_before(&h[l], &h[best]))
            best = l;
        if (r < m && chip_slot_before(&h[r], &h[best]))
            best = r;
        if (best == i)
            return;
        ChipSlot tmp = h[i];
        h[i] = h[best];
        h[best] = tmp;
        i = best;
    }
}

/* The list schedule on m cores with caller storage h (m >= 1 slots). Cores all idle at 0 in
 * index order already form a heap. */
static double chip_schedule(const double *tc, uint32_t T, uint32_t m, ChipSlot *h, double *start, uint32_t *core)
{
    double makespan = 0.0;
    for (uint32_t c = 0; c < m; c++)
        h[c] = (ChipSlot){0.0, c};
    for (uint32_t t = 0; t < T; t++) {
        if (start)
            start[t] = h[0].free;
        if (core)
            core[t] = h[0].core;
        h[0].free += tc[t];
        if (h[0].free > makespan)
            makespan = h[0].free;
        chip_heap_sift_down(h, m);
    }
    return makespan;
}

/* Slots the schedule needs: cores past the T-th never get a tile. */
static uint32_t chip_slots(uint32_t ntiles, uint32_t cores)
{
    uint32_t m = cores < ntiles ? cores : ntiles;
    return m > 0 ? m : 1;
}

double chip_list_schedule(const double *tile_cycles, uint32_t ntiles, uint32_t cores, double *start, uint32_t *core)
{
    if (cores == 0 || (ntiles > 0 && !tile_cycles))
        return -1.0;
    if (ntiles == 0)
        return 0.0;
    uint32_t m = chip_slots(ntiles, cores);
    ChipSlot *h = malloc((size_t)m * sizeof *h);
    if (!h)
        return -1.0;
    double makespan = chip_schedule(tile_cycles, ntiles, m, h, start, core);
    free(h);
    return makespan;
}

/* ---- the tile-effect estimate ----------------------------------------------------------------- */

#define CHIP_NONE UINT32_MAX /* a unit not in the sample */

typedef struct ChipWork {
    const ChipSampleIn *in;
    uint32_t N, slots;
    uint32_t *pos;        /* N: the unit's position in the sample, or CHIP_NONE */
    double *plain;        /* T: the tiles' cycles without the tile effects */
    double *P;            /* T: r * the predictions of the tile's unsampled, non-exact units */
    double *R, *Q;        /* T: sum and sum of squares of the tile's relative residuals */
    uint32_t *m;          /* T: the tile's residual units */
    double *sd;           /* T: the sd of the tile's unsampled effect, P_t sqrt(sigma_a^2 (1 - sh_t)) */
    double *scratch;      /* T: a jackknife's or a draw's tiles */
    uint32_t *sub;        /* n - 1: the sample without one unit */
    double *ysub;         /* n - 1: its cycles */
    ChipSlot *heap;
} ChipWork;

static double chip_pred(const double *coef, const double *x, uint32_t k, uint32_t u)
{
    double p = coef[0];
    for (uint32_t j = 0; j < k; j++)
        p += coef[j + 1] * x[(size_t)u * k + j];
    return p;
}

static int chip_is_exact(const ChipSampleIn *in, uint32_t u)
{
    return in->exact && in->exact[u] >= 0.0;
}

/* The bad arguments of chipsampling.h; *N gets the units. */
static int chip_check_args(const ChipSampleIn *in, const double *tile, uint32_t *N)
{
    if (!in || !tile || !in->fit || !in->ys || !in->sample || (in->k > 0 && !in->x))
        return -1;
    uint64_t units = (uint64_t)in->ntiles * in->spp;
    if (in->ntiles == 0 || in->spp == 0 || in->cores == 0 || units > UINT32_MAX || in->k > SAMPLE_MAX_AUX)
        return -1;
    *N = (uint32_t)units;
    if (in->n == 0 || in->n > *N || (in->n < 3 && in->n < *N) || in->fit->n != in->n || in->fit->N != *N)
        return -1;
    if (!(in->r >= 0.0) || !isfinite(in->r) || !(in->r_rel_var >= 0.0) || !isfinite(in->r_rel_var))
        return -1;
    return 0;
}

static void chip_work_free(ChipWork *w)
{
    free(w->pos);
    free(w->plain);
    free(w->P);
    free(w->R);
    free(w->Q);
    free(w->m);
    free(w->sd);
    free(w->scratch);
    free(w->sub);
    free(w->ysub);
    free(w->heap);
}

/* Zeroed working arrays, and the sample's positions; -1 on OOM or a sample index out of range
 * or repeated. */
static int chip_work_init(ChipWork *w, const ChipSampleIn *in, uint32_t N)
{
    const size_t T = in->ntiles, n = in->n;
    memset(w, 0, sizeof *w);
    w->in = in;
    w->N = N;
    w->slots = chip_slots(in->ntiles, in->cores);
    w->pos = malloc((size_t)N * sizeof *w->pos);
    w->plain = calloc(T, sizeof *w->plain);
    w->P = calloc(T, sizeof *w->P);
    w->R = calloc(T, sizeof *w->R);
    w->Q = calloc(T, sizeof *w->Q);
    w->m = calloc(T, sizeof *w->m);
    w->sd = calloc(T, sizeof *w->sd);
    w->scratch = calloc(T, sizeof *w->scratch);
    w->sub = calloc(n, sizeof *w->sub);
    w->ysub = calloc(n, sizeof *w->ysub);
    w->heap = calloc(w->slots, sizeof *w->heap);
    if (!w->pos || !w->plain || !w->P || !w->R || !w->Q || !w->m || !w->sd || !w->scratch || !w->sub || !w->ysub ||
        !w->heap)
        return -1;
    for (uint32_t u = 0; u < N; u++)
        w->pos[u] = CHIP_NONE;
    for (uint32_t s = 0; s < in->n; s++) {
        uint32_t u = in->sample[s];
        if (u >= N || w->pos[u] != CHIP_NONE)
            return -1;
        w->pos[u] = s;
    }
    return 0;
}

/* The tiles' plain chip cycles under the fit coef, the sample's unit at position skip (n: none)
 * counted as unsampled: exact, else r y, else r pred. P (may be NULL) gets r * the predictions of
 * the unsampled non-exact units a tile, *exact_sum (may be NULL) the sum of the exact cycles. */
static void chip_plain_tiles(const ChipWork *w, const double *coef, uint32_t skip, double *tc, double *P,
                             double *exact_sum)
{
    const ChipSampleIn *in = w->in;
    double E = 0.0;
    for (uint32_t t = 0; t < in->ntiles; t++) {
        double c = 0.0, p_sum = 0.0;
        for (uint32_t u = t * in->spp; u < (t + 1) * in->spp; u++) {
            uint32_t s = w->pos[u];
            if (chip_is_exact(in, u)) {
                c += in->exact[u];
                E += in->exact[u];
            } else if (s != CHIP_NONE && s != skip) {
                c += in->r * in->ys[s];
            } else {
                double p = in->r * chip_pred(coef, in->x, in->k, u);
                c += p;
                p_sum += p;
            }
        }
        tc[t] = c;
        if (P)
            P[t] = p_sum;
    }
    if (exact_sum)
        *exact_sum = E;
}

/* The relative residuals' moments: R, Q and m per tile, and sigma_a^2, sigma_e^2 from them
 * (chipsampling.h). Same-tile pairs i < j sum e_i e_j to (R_t^2 - Q_t) / 2 in each tile. */
static void chip_tile_effects(ChipWork *w, double *sa2, double *se2)
{
    const ChipSampleIn *in = w->in;
    double s2 = 0.0, cross = 0.0, pairs = 0.0;
    uint32_t ne = 0;
    for (uint32_t s = 0; s < in->n; s++) {
        uint32_t u = in->sample[s], t = u / in->spp;
        double p = chip_pred(in->fit->coef, in->x, in->k, u);
        if (chip_is_exact(in, u) || !(p > 0.0))
            continue;
        double e = (in->ys[s] - p) / p;
        w->R[t] += e;
        w->Q[t] += e * e;
        w->m[t]++;
        s2 += e * e;
        ne++;
    }
    s2 = ne > 0 ? s2 / ne : 0.0;
    for (uint32_t t = 0; t < in->ntiles; t++)
        if (w->m[t] >= 2) {
            cross += 0.5 * (w->R[t] * w->R[t] - w->Q[t]);
            pairs += 0.5 * w->m[t] * (w->m[t] - 1.0);
        }
    double a = pairs > 0.0 ? cross / pairs : s2;
    *sa2 = a < 0.0 ? 0.0 : a > s2 ? s2 : a;
    *se2 = s2 - *sa2;
}

/* Running mean and sum of squared deviations (Welford), for the jackknife and the draws. */
typedef struct ChipMoments {
    double mean, ss;
    uint32_t count;
} ChipMoments;

static void chip_moments_add(ChipMoments *mo, double v)
{
    mo->count++;
    double d = v - mo->mean;
    mo->mean += d / mo->count;
    mo->ss += d * (v - mo->mean);
}

/* V_jack: the delete-one jackknife of the plain makespan; -1 if a refit fails (it cannot with
 * n - 1 >= 2 distinct units in range, which the arguments' check ensures). sub holds the sample
 * without position d: sample[0, d) then sample[d + 1, n), updated in O(1) from d - 1 to d. */
static double chip_var_jack(ChipWork *w)
{
    const ChipSampleIn *in = w->in;
    const uint32_t n = in->n;
    ChipMoments mo = {0};
    for (uint32_t s = 1; s < n; s++) {
        w->sub[s - 1] = in->sample[s];
        w->ysub[s - 1] = in->ys[s];
    }
    for (uint32_t d = 0; d < n; d++) {
        if (d > 0) {
            w->sub[d - 1] = in->sample[d - 1];
            w->ysub[d - 1] = in->ys[d - 1];
        }
        SampleEstimate e;
        if (sample_regression_estimate(w->ysub, in->x, in->k, w->sub, n - 1, w->N, &e) != 0)
            return -1.0;
        chip_plain_tiles(w, e.coef, d, w->scratch, NULL, NULL);
        chip_moments_add(&mo, chip_schedule(w->scratch, in->ntiles, w->slots, w->heap, NULL, NULL));
    }
    return (1.0 - (double)n / w->N) * (n - 1.0) / n * mo.ss;
}

/* A standard normal by Box-Muller (the cosine branch) from two uniforms in (0, 1). */
static double chip_normal(uint64_t *state)
{
    double u = ((double)(sample_splitmix64(state) >> 11) + 0.5) / 9007199254740992.0;
    double v = ((double)(sample_splitmix64(state) >> 11) + 0.5) / 9007199254740992.0;
    return sqrt(-2.0 * log(u)) * cos(6.283185307179586 * v);
}

/* V_draws: the variance (divisor B - 1) of the list schedules of B draws of the tiles' unsampled
 * effects around tile[]. z is drawn tile by tile, draw by draw, from in->seed. */
static double chip_var_draws(ChipWork *w, const double *tile)
{
    const ChipSampleIn *in = w->in;
    const uint32_t B = in->draws ? in->draws : CHIP_DRAWS_DEFAULT;
    uint64_t state = in->seed;
    ChipMoments mo = {0};
    for (uint32_t b = 0; b < B; b++) {
        for (uint32_t t = 0; t < in->ntiles; t++)
            w->scratch[t] = tile[t] + w->sd[t] * chip_normal(&state);
        chip_moments_add(&mo, chip_schedule(w->scratch, in->ntiles, w->slots, w->heap, NULL, NULL));
    }
    return B > 1 ? mo.ss / (B - 1.0) : 0.0;
}

/* tile[] = the plain tiles plus each tile's shrunk effect on its unsampled cycles; sd[] the
 * effect's remaining sd. Returns the sum of tile[]. */
static double chip_correct_tiles(ChipWork *w, double sa2, double se2, double *tile)
{
    double total = 0.0;
    for (uint32_t t = 0; t < w->in->ntiles; t++) {
        double m = w->m[t], den = m * sa2 + se2;
        double sh = m > 0.0 && den > 0.0 ? m * sa2 / den : 0.0;
        double ahat = m > 0.0 ? sh * w->R[t] / m : 0.0;
        tile[t] = w->plain[t] + ahat * w->P[t];
        w->sd[t] = w->P[t] * sqrt(sa2 * (1.0 - sh));
        total += tile[t];
    }
    return total;
}

int chip_sample_estimate(const ChipSampleIn *in, double *tile, ChipSampleOut *out)
{
    uint32_t N = 0;
    if (!out)
        return -1;
    memset(out, 0, sizeof *out);
    if (chip_check_args(in, tile, &N) != 0)
        return -1;
    ChipWork w;
    int rc = -1;
    if (chip_work_init(&w, in, N) != 0)
        goto done;
    double sa2, se2, E;
    chip_tile_effects(&w, &sa2, &se2);
    chip_plain_tiles(&w, in->fit->coef, in->n, w.plain, w.P, &E);
    double total = chip_correct_tiles(&w, sa2, se2, tile);
    out->sigma_a = sqrt(sa2);
    out->sigma_e = sqrt(se2);
    out->makespan = chip_schedule(tile, in->ntiles, w.slots, w.heap, NULL, NULL);
    out->plain = chip_schedule(w.plain, in->ntiles, w.slots, w.heap, NULL, NULL);
    const int census = in->n == N;
    if (!census) {
        out->var_jack = chip_var_jack(&w);
        if (out->var_jack < 0.0)
            goto done;
        out->var_draws = chip_var_draws(&w, tile);
    }
    /* The part of the makespan proportional to r: its non-exact share, taken as that of all cycles. */
    double share = total > 0.0 ? 1.0 - E / total : 1.0;
    share = share < 0.0 ? 0.0 : share > 1.0 ? 1.0 : share;
    out->var_r = out->makespan * share * out->makespan * share * in->r_rel_var;
    out->std_error = sqrt(out->var_jack + out->var_draws + out->var_r);
    out->t = !census ? sample_t975(in->fit->df) : in->r_rel_var > 0.0 ? 1.96 : 0.0;
    double h = out->std_error > 0.0 ? out->t * out->std_error : 0.0;
    out->lo = out->makespan - h > 0.0 ? out->makespan - h : 0.0;
    out->hi = out->makespan + h;
    rc = 0;
done:
    chip_work_free(&w);
    if (rc != 0)
        memset(out, 0, sizeof *out);
    return rc;
}
