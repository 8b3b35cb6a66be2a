/* tests/unit/test_dram_level.c -- the DRAM as a level in the cores' clock (sim/mem/dram_level.c):
 * the clock crossing, exact in integers, and a read's cycles derived by hand across it. */
#include <criterion/criterion.h>

#include "../../sim/mem/dram_level.h"

static uint64_t got_id, got_cycle;
static int got_n;

static void on_answer(void *ctx, uint64_t id, uint64_t cycle)
{
    (void)ctx;
    got_id = id;
    got_cycle = cycle;
    got_n++;
}

static Dram *ddr4(void)
{
    DramParams p;
    cr_assert_eq(dram_preset(DRAM_PRESET_ddr4_2400, &p), 0);
    char err[256];
    Dram *d = dram_new(&p, err, sizeof err);
    cr_assert_not_null(d, "%s", err);
    return d;
}

Test(dram_level, clocks_cross_to_the_first_cycle_at_or_after)
{
    /* cores at 500 MHz, DDR4-2400's CK at 1200 MHz: 12 DRAM cycles are 5 core cycles */
    Dram *d = ddr4();
    DramLevel *l = dram_level_new(d, 500000, 64);
    cr_assert_not_null(l);
    cr_expect_eq(dram_level_to_dram(l, 0), 0);
    cr_expect_eq(dram_level_to_dram(l, 5), 12);
    cr_expect_eq(dram_level_to_dram(l, 1), 3);    /* 2.4 -> 3 */
    cr_expect_eq(dram_level_to_core(l, 12), 5);
    cr_expect_eq(dram_level_to_core(l, 13), 6);   /* 5.42 -> 6 */
    cr_expect_eq(dram_level_to_core(l, 1), 1);
    /* no overflow far out: 5 x 2^48 core cycles */
    cr_expect_eq(dram_level_to_dram(l, (uint64_t)5 << 48), (uint64_t)12 << 48);
    dram_level_free(l);
    dram_free(d);
}

Test(dram_level, a_read_to_a_closed_bank_across_the_clocks)
{
    /* A read at core cycle 10 reaches the DRAM at ceil(10 x 1200 / 500) = 24; a closed bank:
     * ACT 24, RD at 24 + tRCD 16 = 40, done 40 + CL 16 + 4 = 60 (tests/unit/test_dram.c's first
     * case, 36 cycles); back at the cores' ceil(60 x 500 / 1200) = 25. */
    Dram *d = ddr4();
    DramLevel *l = dram_level_new(d, 500000, 64);
    MemLevel lv = dram_level(l);
    got_n = 0;
    lv.push(lv.self, 0, 0, 10, 77);
    cr_expect_eq(lv.next(lv.self), 10);
    lv.run(lv.self, 25, on_answer, NULL);
    cr_expect_eq(got_n, 0, "done at 25: not before a run to 25 (exclusive)");
    lv.run(lv.self, 26, on_answer, NULL);
    cr_expect_eq(got_n, 1);
    cr_expect_eq(got_id, 77);
    cr_expect_eq(got_cycle, 25);
    dram_level_free(l);
    dram_free(d);
}
