/* sim/chipmemest.h -- the memory figures of a sampled chip (L2 hit rate, the average latency of
 * the requests below the L1s, DRAM's bandwidth) estimated with 95 % intervals from units timed
 * alone (issue 41, deliverable 3; docs/sampling.md, "Sampling a chip", step 8).
 *
 * Owns: the estimator below. Must not: run or time anything, print, or know the schedule. The
 * regression fits are sim/sampling.h's.
 *
 * Three strata. A chip's memory traffic is not spread like its cycles: most DRAM reads are a line's
 * first touch (the compulsory misses), and those crowd into the frame's first units, so a simple
 * random sample weighting each unit N/n misses or multiplies them (tried: seed 2 of
 * bench/chip_error's rows (a) and (b) off by -45 % and +396 % on DRAM's bytes).
 *   - The opening's units (the chip's first wave, run in full: sim/run/chipsampled.h) are a
 *     stratum counted exactly: open[q], the chip's counters when the opening stopped.
 *   - The tiles' first passes outside the opening, F (when first_pass is given): each fills its
 *     tile's framebuffer from DRAM, a few per cent of the units carrying a large share of DRAM's
 *     reads, which a simple random sample of the frame holds a handful of or none. Their own
 *     sample: the simple random sample's units in F plus extra units of F drawn at random by the
 *     caller (sample[n_srs..n)), together a simple random sample of F; estimated by the regression
 *     on first_u alone.
 *   - The rest, R (N_R units), is estimated from the sample's units in R by the regression
 *     estimator (sampling.h) on the golden model's counts plus first_u, the lines unit u is the
 *     first reader of in the predicted schedule (sim/run/chipwarm.h): the compulsory misses are an
 *     auxiliary whose total is known, not a rare event the sample has to hit.
 *   Y_q = open[q] + Yhat_q(F) + Yhat_q(R) + C_q, the sampling variance the two regressions' added
 *   (the opening's part is exact; the strata are sampled independently).
 * The other cores' correction C_q (with 2 waves or more): units alone miss what the other cores
 * change in a unit (queueing at the L2's banks, the network and DRAM; lines they evict or bring
 * in) and what the L1's warming misses. The waves' second units ran after their own predecessor
 * among the other cores (sim/run/chipsampled.h, step 5), so their figures together less alone
 * measure both: C_q = N_R dbar_q(R) + N_F dbar_q(F), dbar the waves' mean difference per unit of
 * each stratum (0 for a stratum no wave measured). Its uncertainty: the delete-one jackknife over
 * waves of each figure computed with the corrected totals, t_{0.975, W-1}; the figure's
 * half-width is that and the sampling's added in quadrature.
 * The ratios (hit rate = hits / accesses, latency = latency sum / requests) are ratios of those
 * totals, their variance by linearization (Cochran 1977, Sec. 6.3): z_u = y_u - Rhat x_u over each
 * stratum's sample, SE(Rhat) = SE(Zhat(F) + Zhat(R)) / X. DRAM's bandwidth is its bytes over the
 * makespan's seconds, the two relative variances added (independent by assumption). Intervals:
 * estimate -+ t SE, t = t_{0.975, df} with Satterthwaite's df of the two strata's variances (one
 * stratum: its regression's df), lower ends not below 0 and the hit rate's upper end not above 1.
 * What it leaves out (measured in docs/sampling.md): what the warming misses of the L2's state
 * before a wave (the waves start from the same warming as the units alone: the lines the full
 * run's L2 evicted long before are there in both), and units still running when the opening
 * stopped, counted in open[] for their first part and again in R.
 */
#ifndef SFSIM_CHIPMEMEST_H
#define SFSIM_CHIPMEMEST_H

#include <stdint.h>

/* A unit's memory figures (each a sum the frame's is the total of). */
enum {
    CME_REQUESTS,       /* requests below the L1 (ChipMemStats.requests) */
    CME_LATENCY,        /* the sum of their read latencies (ChipMemStats.read_latency) */
    CME_L2_ACCESSES,    /* L2 reads + writes */
    CME_L2_HITS,        /* L2 hits */
    CME_DRAM_BYTES,     /* DRAM's bytes, read and written */
    CME_COUNT
};

#define CHIPMEM_MAX_WAVES 8u

typedef struct ChipMemIn {
    uint32_t N;                      /* units in the frame */
    const double *x;                 /* N x k auxiliaries (the golden counts) */
    uint32_t k;                      /* k + 1 <= SAMPLE_MAX_AUX (first_u is one more) */
    const double *first;             /* N: the lines each unit reads first; NULL: none known */
    const uint8_t *opened;           /* N: 1 for the opening's units; NULL: none */
    const uint8_t *first_pass;       /* N: 1 for the units of F (opened ones are not); NULL: no F */
    const uint32_t *sample;          /* n distinct units: a simple random sample of the N, then F's extra */
    const double *ys;                /* n x CME_COUNT: ys[s * CME_COUNT + q], unit sample[s] timed alone */
    uint32_t n;
    uint32_t n_srs;                  /* the simple random sample's units, sample[0..n_srs); 0: all n */
    double open[CME_COUNT];          /* the opening's exact totals */
    /* The other cores' correction, from the waves' second units (docs/sampling.md, step 8): per
     * wave w < nwaves and stratum f (0: R, 1: F), the sum over its units of f that ran after their
     * own predecessor in the wave, of their figures together less the same units alone,
     * wave_diff[(w * 2 + f) * CME_COUNT + q], and how many, wave_units[w * 2 + f]. Fewer than 2
     * waves: no correction. */
    uint32_t nwaves;
    const double *wave_diff;
    const uint32_t *wave_units;
    double makespan, makespan_se;    /* the frame's cycles (the estimate) and its standard error */
    double clock_mhz;                /* the cycles' clock */
    int has_l2;                      /* the chip has an L2 (else no hit rate) */
} ChipMemIn;

typedef struct ChipMemOut {
    int has_mem, has_l2;             /* the latency and bandwidth are estimated; the hit rate is */
    double latency[3];               /* cycles: estimate, lo, hi */
    double l2_hit_rate[3];           /* 0..1 */
    double dram_gbs[3];              /* GB/s (10^9 bytes) */
    double total[CME_COUNT];         /* the frame totals' estimates */
    double total_se[CME_COUNT];      /* ... and their standard errors */
    uint32_t n_rest, n_first;        /* the sample's units in R and in F */
    double correction[CME_COUNT];    /* the other cores' correction in total[] */
    uint32_t waves;                  /* the waves it came from (0: none) */
} ChipMemOut;

/* The estimate (method above). 0; or -1 (out zeroed, has_* 0) on bad arguments (a NULL in, out,
 * sample or ys with n > 0, x with k > 0; N 0; k + 1 > SAMPLE_MAX_AUX; a sample index >= N or
 * repeated; an extra unit outside F), too few of the sample's units in R or in F for a fit (fewer
 * than 2 while the stratum has units the sample missed), no requests, or out of memory. */
int chip_mem_estimate(const ChipMemIn *in, ChipMemOut *out);

#endif
