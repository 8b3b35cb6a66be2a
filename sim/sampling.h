/* sim/sampling.h -- sampled simulation: which tiles get detailed timing, and the estimate of a
 * frame's cycles with a confidence interval from those tiles (SMARTS-style sampling, Wunderlich
 * et al., ISCA 2003; the estimator and its assumptions: docs/sampling.md).
 *
 * Owns: the seeded simple random sample of tiles (without replacement) and the ratio estimator.
 * Must not: run anything (sim/functional.c runs the tiles; sim/render.c reports).
 *
 * Every tile runs on the functional core, so its instruction count x_i is known exactly for all
 * N tiles; the sampled tiles also get their cycles y_i from the timing model. The frame's cycles
 * Y = sum y_i are estimated by the ratio estimator
 *     Y^ = X * R^,  R^ = sum_s y_i / sum_s x_i  (cycles per instruction of the sample),
 * with variance  V^ = N^2 (1 - n/N) / n * s_d^2,  s_d^2 = sum_s (y_i - R^ x_i)^2 / (n - 1),
 * and the interval Y^ +- t_{0.975, n-1} sqrt(V^) (Cochran, Sampling Techniques, 1977, 6.3-6.4).
 * With every tile sampled the interval has zero width and Y^ = Y exactly.
 */
#ifndef SFSIM_SAMPLING_H
#define SFSIM_SAMPLING_H

#include <stddef.h>
#include <stdint.h>

/* Tiles a fraction f of N selects: ceil(f N), at least 2 (a variance needs two), at most N. */
uint32_t sample_count(uint32_t ntiles, double fraction);

/* A simple random sample without replacement of sample_count(ntiles, fraction) of the tiles,
 * fixed by seed: selected[i] = 1 for the chosen tiles (selected has ntiles entries). */
void sample_select(uint32_t ntiles, double fraction, uint32_t seed, uint8_t *selected);

typedef struct SampleEstimate {
    uint32_t n, N;          /* tiles sampled, tiles in the frame */
    double total;           /* estimated frame total of y */
    double lo, hi;          /* its 95 % confidence interval (lo >= the sampled tiles' own sum) */
    double ratio;           /* R^: y per unit of x in the sample */
    double std_error;       /* sqrt(V^) */
    double t;               /* the t quantile used (0 when every tile is sampled) */
} SampleEstimate;

/* The ratio estimate of sum y over all N tiles from the sampled ones (y read only where
 * selected). x must be > 0 for the sampled tiles' sum. 0, or -1 if fewer than 2 tiles are
 * sampled (unless all are) or the sampled x sum to 0. */
int sample_ratio_estimate(const double *y, const double *x, const uint8_t *selected, uint32_t ntiles,
                          SampleEstimate *out);

/* The 0.975 quantile of Student's t distribution with df degrees of freedom (df >= 1). */
double sample_t975(uint32_t df);

#endif
