/* tests/unit/test_chipmemest.c -- a sampled chip's memory figures (sim/chipmemest.h): the
 * opening's stratum exact, the rest by the regression estimator, the ratios' intervals by
 * linearization; every figure below derived by hand in its comment. */
#include <criterion/criterion.h>
#include <math.h>

#include "../../sim/chipmemest.h"
#include "../../sim/sampling.h"

/* Six units, no auxiliaries (the fit is the sample's mean: N_R ybar, V = N_R^2 (1 - n/N_R) s^2 / n).
 * Unit 0 is the opening's (its traffic is open[]); the sample is units 0..3, so R = units 1..5
 * (N_R = 5) and its sample is units 1, 2, 3 (n = 3; unit 0's own figures are not used).
 *   requests 4, 6, 8:      R 5 x 6 = 30,    Y = 10 + 30 = 40
 *   latency 40, 60, 80:    R 300,           Y = 400;    latency 400 / 40 = 10, and z = y - 10 x = 0:
 *                                            an interval of no width
 *   L2 accesses 10 x 3:    R 50,            Y = 70
 *   L2 hits 8, 9, 10:      R 45,            Y = 60;     hit rate 6/7; z = 8 - 60/7, ... = -4/7, 3/7,
 *                                            10/7, s^2 = 1: V = 25 (2/5) / 3 = 10/3, half-width
 *                                            t_{0.975, 2} sqrt(10/3) / 70
 *   DRAM bytes 64, 128, 192: R 640,         Y = 640 + 640 = 1280, s^2 = 4096: V = 25 (2/5) 4096 / 3;
 *                                            1000 cycles at 1 MHz: 1280 B / 1 ms = 1.28e-3 GB/s,
 *                                            half-width t sqrt((SE / 1280)^2 + (10 / 1000)^2) x it */
Test(chipmemest, strata_and_ratios_by_hand)
{
    const uint32_t sample[4] = {0, 1, 2, 3};
    const uint8_t opened[6] = {1, 0, 0, 0, 0, 0};
    const double ys[4 * CME_COUNT] = {
        /* requests, latency, L2 accesses, L2 hits, DRAM bytes */
        999, 999, 999, 999, 999, /* unit 0: the opening's, not used */
        4, 40, 10, 8, 64,
        6, 60, 10, 9, 128,
        8, 80, 10, 10, 192,
    };
    ChipMemIn in = {.N = 6, .opened = opened, .sample = sample, .ys = ys, .n = 4,
                    .open = {10, 100, 20, 15, 640}, .makespan = 1000, .makespan_se = 10, .clock_mhz = 1, .has_l2 = 1};
    ChipMemOut out;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.n_rest, 3);
    cr_expect(out.has_mem && out.has_l2);
    const double want[CME_COUNT] = {40, 400, 70, 60, 1280};
    for (int q = 0; q < CME_COUNT; q++)
        cr_expect_float_eq(out.total[q], want[q], 1e-9, "total %d: %g", q, out.total[q]);
    cr_expect_float_eq(out.latency[0], 10.0, 1e-12);
    cr_expect_float_eq(out.latency[1], 10.0, 1e-9);
    cr_expect_float_eq(out.latency[2], 10.0, 1e-9);
    const double t = sample_t975(2), h = t * sqrt(10.0 / 3.0) / 70.0;
    cr_expect_float_eq(out.l2_hit_rate[0], 6.0 / 7.0, 1e-12);
    cr_expect_float_eq(out.l2_hit_rate[1], 6.0 / 7.0 - h, 1e-9);
    cr_expect_float_eq(out.l2_hit_rate[2], 6.0 / 7.0 + h, 1e-9);
    const double gbs = 1.28e-3, se = sqrt(25.0 * 0.4 * 4096.0 / 3.0);
    const double hb = t * gbs * sqrt((se / 1280.0) * (se / 1280.0) + 1e-4);
    cr_expect_float_eq(out.total_se[CME_DRAM_BYTES], se, 1e-9);
    cr_expect_float_eq(out.dram_gbs[0], gbs, 1e-15);
    cr_expect_float_eq(out.dram_gbs[1], gbs - hb, 1e-12);
    cr_expect_float_eq(out.dram_gbs[2], gbs + hb, 1e-12);

    /* The whole frame in the opening: its counters are the figures, exactly (the bandwidth keeps
     * the makespan's error, at t = 1.96). */
    const uint8_t all[6] = {1, 1, 1, 1, 1, 1};
    in.opened = all;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.n_rest, 0);
    cr_expect_eq(out.total[CME_DRAM_BYTES], 640.0);
    cr_expect_eq(out.latency[0], 10.0);
    cr_expect_eq(out.latency[1], 10.0);
    cr_expect_eq(out.latency[2], 10.0);
    cr_expect_eq(out.l2_hit_rate[0], 0.75);
    cr_expect_float_eq(out.dram_gbs[2] - out.dram_gbs[0], 1.959963985 * 0.64e-3 * 0.01, 1e-15);
}

/* Unit 1's first-read lines as an auxiliary: DRAM's bytes are 64 a first-read line, so the fit is
 * exact and the frame's bytes are 64 times the lines first read (known for every unit), whichever
 * units were sampled: R = all 6 units, first = 0, 2, 0, 1, 0, 3 (6 lines), sampled 0, 1, 3:
 * Y = 64 x 6 = 384 with no error. */
Test(chipmemest, first_reads_are_an_auxiliary)
{
    const uint32_t sample[3] = {0, 1, 3};
    const double first[6] = {0, 2, 0, 1, 0, 3};
    const double ys[3 * CME_COUNT] = {1, 10, 1, 1, 0, 1, 10, 1, 0, 128, 1, 10, 1, 0, 64};
    ChipMemIn in = {.N = 6, .first = first, .sample = sample, .ys = ys, .n = 3, .makespan = 1000,
                    .clock_mhz = 1000, .has_l2 = 1};
    ChipMemOut out;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_float_eq(out.total[CME_DRAM_BYTES], 384.0, 1e-9);
    cr_expect_float_eq(out.total_se[CME_DRAM_BYTES], 0.0, 1e-9);
    cr_expect_float_eq(out.dram_gbs[0], 384.0 / 1e-6 / 1e9, 1e-12);
}

Test(chipmemest, bad_arguments)
{
    const uint32_t sample[3] = {0, 1, 1}, outside[3] = {0, 1, 6};
    const double ys[3 * CME_COUNT] = {1, 10, 1, 1, 64, 1, 10, 1, 1, 64, 1, 10, 1, 1, 64};
    ChipMemIn in = {.N = 6, .sample = sample, .ys = ys, .n = 3, .makespan = 1000, .clock_mhz = 1};
    ChipMemOut out;
    cr_expect_eq(chip_mem_estimate(&in, &out), -1, "a unit sampled twice");
    cr_expect_eq(out.has_mem, 0);
    in.sample = outside;
    cr_expect_eq(chip_mem_estimate(&in, &out), -1, "a unit past N");
    cr_expect_eq(chip_mem_estimate(NULL, &out), -1);
    cr_expect_eq(chip_mem_estimate(&in, NULL), -1);
    const uint32_t one[1] = {0};
    ChipMemIn few = {.N = 6, .sample = one, .ys = ys, .n = 1, .makespan = 1000, .clock_mhz = 1};
    cr_expect_eq(chip_mem_estimate(&few, &out), -1, "one unit of six: no fit");
    const double none[3 * CME_COUNT] = {0};
    ChipMemIn quiet = {.N = 3, .sample = (const uint32_t[]){0, 1, 2}, .ys = none, .n = 3, .makespan = 1000,
                       .clock_mhz = 1};
    cr_expect_eq(chip_mem_estimate(&quiet, &out), -1, "no request below the L1s: no latency to give");
}
