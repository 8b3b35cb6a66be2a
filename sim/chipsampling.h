/* sim/chipsampling.h -- the makespan of a chip's frame estimated from a sample of units timed
 * alone, with a 95 % interval (issue 41's design study, docs/sampling.md "Sampling a chip": the
 * tile-effect model, method (c) of tools/sample41/chiprep.c, made a library module).
 *
 * Owns: the chip distributor's list schedule, and the tile-effect estimate of the makespan and
 * its variance.
 * Must not: run or time anything, print, or use threads (the units are timed by sim/run/; the
 * regression fit is sim/sampling.h's). It allocates working arrays and frees them before it
 * returns.
 *
 * The chip. K cores render T tiles of S passes; unit u = t S + p (N = T S units). The distributor
 * hands tiles in frame order to the core idle first (ties to the lowest core; at cycle 0 tile i
 * goes to core i), and a core runs all passes of its tile back to back, so the frame's cycles are
 * the list schedule of the tiles' cycles exactly (docs/sampling.md, "(b)").
 *
 * The estimate (chip_sample_estimate). A simple random sample s of n units is timed alone (one-core
 * cycles y_s) and fitted by the regression estimator (sampling.h; coefficients b):
 *   pred_u  = b0 + sum_j b_j x_uj, the fit's one-core cycles of unit u;
 *   c_u     = exact_u when known (>= 0: the chip's opening, timed on the chip itself), else
 *             r y_u when sampled, else r pred_u (r: the other cores' factor on one-core cycles).
 * Tile effects. The residuals of one tile's units are correlated (the tile's rays share a part of
 * the scene, so the fit misses its cost as a whole), and with few tiles a core the list schedule
 * of the predicted tiles is biased low (docs/sampling.md, "The makespan's tail"). Model: a unit's
 * relative residual e_u = (y_u - pred_u) / pred_u = a_t + eps_u, a_t ~ (0, sigma_a^2) per tile,
 * eps_u ~ (0, sigma_e^2) per unit, all independent. Over the sampled units that are not exact and
 * have pred > 0 (the residual units; others are skipped):
 *   s2        = mean of e_u^2,
 *   sigma_a^2 = mean of e_i e_j over the pairs i < j of residual units of one tile (= s2 when
 *               there is none), clamped to [0, s2];   sigma_e^2 = s2 - sigma_a^2.
 * Per tile t: m_t its residual units, R_t the sum of their e, P_t = r sum of pred over its
 * unsampled units that are not exact (the cycles the effect scales),
 *   sh_t    = m_t sigma_a^2 / (m_t sigma_a^2 + sigma_e^2) (0 when m_t = 0 or 0 / 0): the
 *             shrinkage of the tile's mean residual to a_t's best linear predictor,
 *   ahat_t  = sh_t R_t / m_t,
 *   tile_t  = sum_{u in t} c_u + ahat_t P_t,
 *   M^      = list schedule of tile_t;  plain = the list schedule without the ahat_t P_t terms.
 * Its variance has three parts (independent by assumption):
 *   V_jack  = the delete-one jackknife of PLAIN (Wolter 2007, Ch. 4, as in sampling.h): for each
 *             sampled unit d, the fit redone without d, the tiles' plain cycles recomputed (d then
 *             predicted, unless exact) and list scheduled -> M_d;
 *             V_jack = (1 - n/N) (n - 1)/n sum_d (M_d - mean_d M_d)^2. It carries the fit's error.
 *   V_draws = the variance (divisor B - 1) of the list schedules of B draws (in->draws, 0: 400)
 *             tile_t + P_t sqrt(sigma_a^2 (1 - sh_t)) z_t, z_t ~ N(0, 1) independent (splitmix64
 *             seeded by in->seed, Box-Muller): the unsampled part of each tile's effect, which the
 *             shrunk ahat_t leaves with variance sigma_a^2 (1 - sh_t), pushed through the
 *             schedule's max (parametric bootstrap).
 *   V_r     = (M^ (1 - E / sum_t tile_t))^2 relvar(r), E the sum of the exact cycles: the
 *             makespan's part proportional to r, approximated by the non-exact share of all
 *             cycles (the critical core's own share is not tracked).
 *   se = sqrt(V_jack + V_draws + V_r); interval M^ -+ t se, t = t_{0.975, df} of the fit (its
 *   lower end not below 0). A census (n == N): V_jack = V_draws = 0 (every P_t = 0) and t = 0, or
 *   t = 1.96 when relvar(r) > 0 (r's error is then the only one, taken as normal).
 * Measured on the chip's real units (docs/sampling.md, "The estimator replayed"): with 4 tiles a
 * core the interval covered 99.3 % of 1,000 seeds, with 16 tiles a core 96.3 %; with 64 tiles a
 * core 86.1 %, where the tail is a non-smooth function of many correlated tile errors.
 */
#ifndef SFSIM_CHIPSAMPLING_H
#define SFSIM_CHIPSAMPLING_H

#include <stdint.h>

#include "sampling.h"

/* The list schedule of the chip's distributor: tiles in order to the core idle first (ties: the
 * lowest core). Returns the makespan; start[t] (may be NULL) the tile's start, core[t] (may be NULL)
 * its core. O(T log K) (a binary heap), no allocation beyond one malloc of K entries (-1.0 on OOM
 * or cores == 0). (Only min(K, T) entries are allocated: cores past the T-th never get a tile.
 * 0.0 for ntiles == 0.) */
double chip_list_schedule(const double *tile_cycles, uint32_t ntiles, uint32_t cores, double *start, uint32_t *core);

#define CHIP_DRAWS_DEFAULT 400 /* tile-effect draws when ChipSampleIn.draws is 0 */

typedef struct ChipSampleIn {
    uint32_t ntiles, spp, cores;     /* N = ntiles * spp units, unit = tile * spp + pass */
    const double *x; uint32_t k;     /* N x k auxiliaries (as sample_regression_estimate) */
    const uint32_t *sample;          /* the n sampled units (a simple random sample) */
    const double *ys;                /* ys[s]: one-core cycles of unit sample[s] */
    uint32_t n;
    const SampleEstimate *fit;       /* sample_regression_estimate(ys, x, k, sample, n, N) */
    const double *exact;             /* NULL, or N entries: a unit's exact chip cycles, < 0 when unknown */
    double r, r_rel_var;             /* the other cores' factor on one-core cycles; r's relative variance (0: exact) */
    uint32_t draws;                  /* tile-effect draws; 0: 400 */
    uint64_t seed;                   /* the draws' generator */
} ChipSampleIn;

typedef struct ChipSampleOut {
    double makespan, lo, hi;         /* the estimate and its 95 % interval */
    double std_error, t;             /* sqrt of the variance below; t quantile (sample_t975(fit->df); 0 for a census) */
    double plain;                    /* the list schedule of the tiles without the tile-effect correction */
    double var_jack, var_draws, var_r; /* the variance's three parts */
    double sigma_a, sigma_e;         /* tile effect and within-tile sd of the relative residuals */
} ChipSampleOut;

/* The makespan estimate (method above); tile[t] (ntiles entries, caller storage) gets each tile's
 * estimated chip cycles (the corrected ones the makespan is the list schedule of). 0, or -1 on
 * bad arguments or out of memory. Bad arguments: a NULL in, tile, out, fit, ys or sample (n > 0),
 * or x with k > 0; ntiles, spp or cores 0; N over 2^32 - 1; n == 0, n > N, n < 3 below a census
 * (the jackknife refits n - 1 >= 2 units); fit->n != n or fit->N != N; k > SAMPLE_MAX_AUX; a
 * sample index >= N or repeated; r < 0, r_rel_var < 0 or either not finite. On -1, *out is
 * zeroed and tile[] unspecified. */
int chip_sample_estimate(const ChipSampleIn *in, double *tile, ChipSampleOut *out);

#endif
