/* tests/unit/test_chipmemest.c -- a sampled chip's memory figures (sim/chipmemest.h): the
 * opening's stratum exact, the tiles' first passes and the rest by the regression estimator, the
 * ratios' intervals by linearization; every figure below derived by hand in its comment. */
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

/* The tiles' first passes as a stratum F of their own. Eight units, no auxiliaries (each stratum's
 * fit is its sample's mean: N_h ybar, V_h = N_h^2 (1 - n_h/N_h) s_h^2 / n_h). Unit 0 is the
 * opening's; F = units 1, 2, 3; R = units 4..7. The simple random sample is 0, 1, 4, 5, 6 and F's
 * extra unit is 2 (sample[5], n_srs = 5): F's sample 1, 2 (N_F 3, n 2: V_F = 1.5 s^2), R's 4, 5, 6
 * (N_R 4, n 3: V_R = 4/3 s^2).
 *   requests   F 10, 10 -> 30;   R 5, 5, 5 -> 20;    Y = 10 + 30 + 20 = 60
 *   latency    ten times those:  Y = 600, latency 10 and z = 0 everywhere: no width
 *   accesses   as requests:      Y = 60
 *   hits       F 4, 6 -> 15;     R 5, 4, 3 -> 16;    Y = 5 + 15 + 16 = 36: hit rate 0.6;
 *              z = hits - 0.6 acc: F -2, 0 (s^2 2, V_F 3), R 2, 1, 0 (s^2 1, V_R 4/3);
 *              V = 13/3, Satterthwaite's df = V^2 / (V_F^2 / 1 + V_R^2 / 2) = 169/89 -> 1
 *   DRAM bytes F 6400, 3840 -> 15360 (s^2 2 x 1280^2, V_F 4,915,200);
 *              R 0, 64, 128 -> 256 (s^2 4096, V_R 5461 1/3); Y = 640 + 15360 + 256 = 16256;
 *              df = V^2 / (V_F^2 + V_R^2 / 2) = 1.002 -> 1; over 1 ms: 0.016256 GB/s */
Test(chipmemest, first_passes_are_a_stratum_of_their_own)
{
    const uint32_t sample[6] = {0, 1, 4, 5, 6, 2};
    const uint8_t opened[8] = {1, 0, 0, 0, 0, 0, 0, 0}, fpass[8] = {0, 1, 1, 1, 0, 0, 0, 0};
    const double ys[6 * CME_COUNT] = {
        999, 999, 999, 999, 999, /* unit 0: the opening's */
        10, 100, 10, 4, 6400,    /* unit 1 (F) */
        5, 50, 5, 5, 0,          /* unit 4 (R) */
        5, 50, 5, 4, 64,         /* unit 5 */
        5, 50, 5, 3, 128,        /* unit 6 */
        10, 100, 10, 6, 3840,    /* unit 2 (F, the extra one) */
    };
    ChipMemIn in = {.N = 8, .opened = opened, .first_pass = fpass, .sample = sample, .ys = ys, .n = 6, .n_srs = 5,
                    .open = {10, 100, 10, 5, 640}, .makespan = 1000, .makespan_se = 10, .clock_mhz = 1, .has_l2 = 1};
    ChipMemOut out;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.n_rest, 3);
    cr_expect_eq(out.n_first, 2);
    const double want[CME_COUNT] = {60, 600, 60, 36, 16256};
    for (int q = 0; q < CME_COUNT; q++)
        cr_expect_float_eq(out.total[q], want[q], 1e-9, "total %d: %g", q, out.total[q]);
    cr_expect_float_eq(out.latency[1], 10.0, 1e-9);
    cr_expect_float_eq(out.latency[2], 10.0, 1e-9);
    const double t1 = sample_t975(1), h = t1 * sqrt(13.0 / 3.0) / 60.0;
    cr_expect_float_eq(out.l2_hit_rate[0], 0.6, 1e-12);
    cr_expect_float_eq(out.l2_hit_rate[1], 0.6 - h, 1e-9);
    cr_expect_float_eq(out.l2_hit_rate[2], 0.6 + h > 1.0 ? 1.0 : 0.6 + h, 1e-9);
    const double v = 4915200.0 + 4096.0 * 4.0 / 3.0, se = sqrt(v), gbs = 0.016256;
    const double hb = t1 * gbs * sqrt((se / 16256.0) * (se / 16256.0) + 1e-4);
    cr_expect_float_eq(out.total_se[CME_DRAM_BYTES], se, 1e-9);
    cr_expect_float_eq(out.dram_gbs[0], gbs, 1e-15);
    cr_expect_float_eq(out.dram_gbs[1], gbs - hb > 0.0 ? gbs - hb : 0.0, 1e-12);
    cr_expect_float_eq(out.dram_gbs[2], gbs + hb, 1e-12);

    /* Without first_pass the same eight units are one stratum R of 7 (sample 1, 4, 5, 6 and the
     * extra unit 2 not allowed there). */
    in.first_pass = NULL;
    cr_expect_eq(chip_mem_estimate(&in, &out), -1, "an extra unit outside F");
    in.n = 5;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.n_rest, 4);
    cr_expect_eq(out.n_first, 0);
    /* ... and F with one sampled unit of three: no fit for it */
    in.first_pass = fpass;
    cr_expect_eq(chip_mem_estimate(&in, &out), -1, "one unit of F's three");
}

/* The other cores' correction from the waves' second units (chipmemest.h): strata_and_ratios_by_hand's
 * frame (N_R = 5, no F) and three waves whose units of R, together less alone, summed:
 *   wave 0: 2 units, latency +4, accesses -2, hits -2, DRAM bytes +64
 *   wave 1: 2 units, latency +8, hits -2
 *   wave 2: 4 units, accesses -2, hits -2, DRAM bytes +128
 * Per unit over the 8: latency 12/8, accesses -4/8, hits -6/8, DRAM 192/8; times N_R = 5: 7.5,
 * -2.5, -3.75, 120 on the totals 40, 400, 70, 60, 1280 -> 40, 407.5, 67.5, 56.25, 1400.
 * Latency 407.5 / 40 = 10.1875; its sampling part: z = y - 10.1875 x = -0.75, -1.125, -1.5, s^2 =
 * 0.140625, V = 25 (2/5) s^2 / 3, hs = t_2 sqrt(V) / 40. Leaving a wave out: 4/6, 8/6 per unit less
 * (5 x: 406.6667, 403.3333) and 12/4 (415): latency 10.16667, 10.08333, 10.375; their jackknife
 * variance 2/3 sum of squared deviations from their mean, hw = t_2 sqrt of it; h = sqrt(hs^2 + hw^2).
 * DRAM: 1400 B over 1 ms = 1.4e-3 GB/s; leaving a wave out: 1280 + 5 x 128/6, 5 x 192/6, 5 x 64/4. */
Test(chipmemest, the_waves_correct_the_totals)
{
    const uint32_t sample[4] = {0, 1, 2, 3};
    const uint8_t opened[6] = {1, 0, 0, 0, 0, 0};
    const double ys[4 * CME_COUNT] = {999, 999, 999, 999, 999, 4, 40, 10, 8, 64, 6, 60, 10, 9, 128, 8, 80, 10, 10, 192};
    const double diff[3 * 2 * CME_COUNT] = {
        0, 4, -2, -2, 64,  0, 0, 0, 0, 0, /* wave 0: R, F */
        0, 8, 0, -2, 0,    0, 0, 0, 0, 0,
        0, 0, -2, -2, 128, 0, 0, 0, 0, 0,
    };
    const uint32_t units[3 * 2] = {2, 0, 2, 0, 4, 0};
    ChipMemIn in = {.N = 6, .opened = opened, .sample = sample, .ys = ys, .n = 4, .nwaves = 3, .wave_diff = diff,
                    .wave_units = units, .open = {10, 100, 20, 15, 640}, .makespan = 1000, .makespan_se = 10,
                    .clock_mhz = 1, .has_l2 = 1};
    ChipMemOut out;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.waves, 3);
    const double want[CME_COUNT] = {40, 407.5, 67.5, 56.25, 1400}, corr[CME_COUNT] = {0, 7.5, -2.5, -3.75, 120};
    for (int q = 0; q < CME_COUNT; q++) {
        cr_expect_float_eq(out.total[q], want[q], 1e-9, "total %d: %g", q, out.total[q]);
        cr_expect_float_eq(out.correction[q], corr[q], 1e-9, "correction %d: %g", q, out.correction[q]);
    }
    const double t2 = sample_t975(2);
    const double lj[3] = {406.0 + 2.0 / 3.0, 403.0 + 1.0 / 3.0, 415.0};
    double m = 0.0, v = 0.0;
    for (int w = 0; w < 3; w++)
        m += lj[w] / 40.0 / 3.0;
    for (int w = 0; w < 3; w++)
        v += (lj[w] / 40.0 - m) * (lj[w] / 40.0 - m) * 2.0 / 3.0;
    const double hs = t2 * sqrt(25.0 * 0.4 * 0.140625 / 3.0) / 40.0, hw = t2 * sqrt(v), h = sqrt(hs * hs + hw * hw);
    cr_expect_float_eq(out.latency[0], 10.1875, 1e-12);
    cr_expect_float_eq(out.latency[1], 10.1875 - h, 1e-9);
    cr_expect_float_eq(out.latency[2], 10.1875 + h, 1e-9);
    const double bj[3] = {1280.0 + 5.0 * 128.0 / 6.0, 1280.0 + 5.0 * 192.0 / 6.0, 1280.0 + 5.0 * 64.0 / 4.0};
    double bm = 0.0, bv = 0.0;
    for (int w = 0; w < 3; w++)
        bm += bj[w] / 3.0;
    for (int w = 0; w < 3; w++)
        bv += (bj[w] - bm) * (bj[w] - bm) * 2.0 / 3.0;
    const double gbs = 1.4e-3, se = sqrt(25.0 * 0.4 * 4096.0 / 3.0);
    const double hbs = t2 * gbs * sqrt((se / 1400.0) * (se / 1400.0) + 1e-4), hbw = t2 * sqrt(bv) / 1e-3 / 1e9;
    cr_expect_float_eq(out.dram_gbs[0], gbs, 1e-15);
    cr_expect_float_eq(out.dram_gbs[2], gbs + sqrt(hbs * hbs + hbw * hbw), 1e-12);

    /* One wave tells no spread: no correction, the figures as without waves. */
    in.nwaves = 1;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_eq(out.waves, 0);
    cr_expect_float_eq(out.total[CME_DRAM_BYTES], 1280.0, 1e-9);
    cr_expect_float_eq(out.latency[0], 10.0, 1e-12);
    /* The waves' units of F correct F's total only: with F empty (first_pass all 0) their rows add
     * nothing however large. */
    const double fdiff[3 * 2 * CME_COUNT] = {
        0, 0, 0, 0, 0, 0, 0, 0, 0, 1e6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1e6, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1e6,
    };
    const uint32_t funits[3 * 2] = {1, 1, 1, 1, 1, 1};
    const uint8_t nofirst[6] = {0};
    in.nwaves = 3;
    in.wave_diff = fdiff;
    in.wave_units = funits;
    in.first_pass = nofirst;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_float_eq(out.total[CME_DRAM_BYTES], 1280.0, 1e-9, "F has no units: %g", out.total[CME_DRAM_BYTES]);
    /* without first_pass every unit measured is one of R: 3e6 over 6 units, 5 x 5e5 */
    in.first_pass = NULL;
    cr_assert_eq(chip_mem_estimate(&in, &out), 0);
    cr_expect_float_eq(out.total[CME_DRAM_BYTES], 1280.0 + 2.5e6, 1e-6);
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
    const uint32_t two[2] = {0, 1};
    ChipMemIn waves = {.N = 6, .sample = sample, .ys = ys, .n = 2, .makespan = 1000, .clock_mhz = 1, .nwaves = 2};
    waves.sample = two;
    cr_expect_eq(chip_mem_estimate(&waves, &out), -1, "waves without their figures");
    const double d[9 * 2 * CME_COUNT] = {0};
    const uint32_t u[9 * 2] = {0};
    waves.wave_diff = d;
    waves.wave_units = u;
    waves.nwaves = CHIPMEM_MAX_WAVES + 1;
    cr_expect_eq(chip_mem_estimate(&waves, &out), -1, "more waves than CHIPMEM_MAX_WAVES");
}
