/* sim/sampling.h -- sampled simulation: which units get detailed timing, and the estimate of a
 * frame's cycles with a confidence interval from those units (SMARTS-style sampling, Wunderlich
 * et al., ISCA 2003; the design and its assumptions: docs/sampling.md).
 *
 * Owns: seeded simple random samples without replacement (a permutation whose every prefix is a
 * sample), the multiple-regression (GREG) estimator, and the sequential stopping rule of
 * --target-error.
 * Must not: run anything, print, allocate, or use threads (sim/run/sampled.c runs the units through
 * sim/run/engine.c; sim/report.c reports).
 *
 * 1. The regression (GREG with intercept) estimator (units, k <= SAMPLE_MAX_AUX auxiliaries x_ij
 *    known exactly for all N units; Cochran 1977 Sec. 7.1-7.2, 7.10; Sarndal, Swensson & Wretman
 *    1992, Ch. 6). With b the OLS fit of y on (1, x) over the sample s of size n:
 *     Y^  = sum_{i<N} (b0 + b'x_i) = N (ybar + b'(Xbar - xbar)),
 *     e_s = y_s - b0 - b'x_s,   df = n - k - 1,
 *     V^  = the delete-one jackknife variance (Wolter, Introduction to Variance Estimation, 2nd
 *           ed., 2007, Ch. 4): with Y^_(s) the estimate refitted without unit s,
 *           V^ = (1 - n/N) (n - 1)/n sum_s (Y^_(s) - mean_s Y^_(s))^2, computed in closed form:
 *           Y^_(s) = Y^ - w_s e_s / (1 - h_s), w_s = N (1/n + (Xbar - xbar)' C^-1 (x_s - xbar))
 *           the unit's regression weight, h_s = 1/n + (x_s - xbar)' C^-1 (x_s - xbar) its
 *           leverage, C the sample's centred cross-products. (The linearization variance
 *           N^2 (1 - n/N) / n * sum_s e_s^2 / df, used only if a unit has leverage 1, is too small
 *           in samples of a few tens: its 95 % interval covered 91.8 % against the jackknife's
 *           95.0 % with 30 of the 256 units of a conference frame, docs/sampling.md.)
 *     interval Y^ +- t_{0.975, df} sqrt(V^), its lower end raised to sum_s y_s when every sampled
 *     y_s >= 0 (the frame takes at least the cycles measured).
 *    The fit centres the columns on their sample means, scales them to unit sum of squares and
 *    solves the normal equations by Cholesky (GSL's: gsl_linalg_cholesky_decomp1 and _solve); a column is dropped (coef 0, not counted in k) when
 *    its centred sum of squares is below 1e-20 of its raw sum of squares (constant), or when its
 *    Cholesky pivot falls below 1e-9 (R^2 > 1 - 1e-9 on the earlier kept columns: collinear).
 *    When n <= k + 1 the LAST kept columns are dropped until df >= 1, so list auxiliaries most
 *    useful first; k = 0 is the expansion estimator N ybar with V^ = N^2 (1 - n/N) s_y^2 / n.
 *    The residuals are recomputed from the data (not from the normal equations), so a perfect fit
 *    gives V^ ~ 0. A census (n == N) is exact: Y^ = sum y, lo = hi = Y^, t = std_error = 0 (the
 *    fit's coef, k, df and r2 are still reported when n >= 2).
 *
 * 2. The sequential rule of --target-error E (sample_sequential): with units taken in the order
 *    of a seeded permutation (sample_order), so that every prefix is a simple random sample,
 *     n_1 = n0 clamped to [min(N, k + 3), N]; measure units order[0, n_1);
 *     round r: estimate from the n_r measured units (regression estimator); h_r = t se / |Y^|;
 *       stop if h_r <= E, or n_r == N (a census: exact), or E <= 0 (one round: the fixed design);
 *       else n* solves 1/n* - 1/N = (E/h_r)^2 (1/n_r - 1/N) (the half-width n* would give if the
 *       residual variance and t stayed as they are; t only falls as n grows), and
 *       n_{r+1} = min(N, 4 n_r, max(n_r + max(1, floor(n_r / 8)), ceil(1.1 n*)));
 *       measure units order[n_r, n_{r+1}).
 *    The sizes grow by at least max(1, n_r / 8) a round, so the rule ends (at N at the latest).
 *    Stopping on an estimated half-width can put the final interval's coverage slightly below its
 *    nominal 95 % for small samples; it is asymptotically exact as E -> 0 (Chow & Robbins 1965).
 *    The 1.1 factor only saves rounds (the stop test is the exact h_r <= E).
 */
#ifndef SFSIM_SAMPLING_H
#define SFSIM_SAMPLING_H

#include <stddef.h>
#include <stdint.h>

/* Units a fraction f of N selects (--sample F): ceil(f N), at least 2 (a variance needs two), at
 * most N. */
uint32_t sample_count(uint32_t ntiles, double fraction);

/* A permutation of 0..N-1 fixed by seed (a Fisher-Yates shuffle driven by splitmix64). Every
 * prefix order[0, n) is a simple random sample without replacement of size n. */
void sample_order(uint32_t N, uint32_t seed, uint32_t *order);

/* splitmix64 (Steele, Lea & Flood 2014): advances *state and returns 64 random bits. The one
 * generator of sampled mode (sample_order's shuffle, sim/chipsampling.c's tile-effect draws). */
uint64_t sample_splitmix64(uint64_t *state);

#define SAMPLE_MAX_AUX 8 /* auxiliary variables the regression estimator takes at most */

typedef struct SampleEstimate {
    uint32_t n, N;          /* units sampled, units in the frame */
    double total;           /* estimated frame total of y */
    double lo, hi;          /* its 95 % confidence interval (lo >= the sampled units' own sum) */
    double std_error;       /* sqrt(V^) */
    double t;               /* the t quantile used (0 when every unit is sampled) */
    uint32_t k;             /* auxiliaries used, after dropping constant or collinear ones */
    uint32_t df;            /* n - k - 1: degrees of freedom of the residual variance */
    double coef[SAMPLE_MAX_AUX + 1]; /* b0, then b_j per ORIGINAL column j (0 for dropped ones) */
    double r2;              /* the fit's R^2 on the sample (1 when the sampled y do not vary) */
} SampleEstimate;

/* The regression estimate of Y = sum of y over all N units (formulas above). ys[s] is y of unit
 * sample[s] (s < n); x[i * k + j] is auxiliary j of unit i for EVERY unit i < N (x may be NULL
 * when k == 0). O(N k + n k^2) time, no allocation. 0, or -1 when n < 2 (and n < N), n > N,
 * N == 0, k > SAMPLE_MAX_AUX or a sample index is >= N. */
int sample_regression_estimate(const double *ys, const double *x, uint32_t k, const uint32_t *sample,
                               uint32_t n, uint32_t N, SampleEstimate *out);

/* Measures y for `count` more units: ys[c] = y of unit units[c]. 0, or -1 to stop the rule. */
typedef int (*SampleMeasure)(void *ctx, const uint32_t *units, uint32_t count, double *ys);

/* The sequential rule above: measures order[0, n) in growing slices (each slice is one call of
 * measure(ctx, order + n_r, n_{r+1} - n_r, ys + n_r)), so ys (caller storage for N values) ends
 * with y in order position for the n = out->n measured units. *rounds (may be NULL) gets the
 * number of estimates made (= successful calls of measure). 0; -1 when measure fails (not
 * retried; out holds the last estimate made, if any) or on bad arguments (N == 0,
 * k > SAMPLE_MAX_AUX, a NULL x with k > 0, a NULL order, measure or ys). */
int sample_sequential(const double *x, uint32_t k, const uint32_t *order, uint32_t N, uint32_t n0, double target,
                      SampleMeasure measure, void *ctx, double *ys, SampleEstimate *out, uint32_t *rounds);

/* The 0.975 quantile of Student's t distribution with df degrees of freedom (df >= 1): GSL's
 * gsl_cdf_tdist_Pinv; infinite for df = 0. */
double sample_t975(uint32_t df);

#endif
