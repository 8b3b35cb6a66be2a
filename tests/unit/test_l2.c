/* tests/unit/test_l2.c -- the shared L2 (sim/mem/l2.c) over a memory of a fixed latency: every
 * answer's cycle derived by hand in the comments from the parameters, and asserted exactly.
 *
 * The L2 of most cases: 64-byte lines, 2 ways, 2 banks (bank = line mod 2), 4 sets per bank
 * (1 KiB), hit latency 3, 1 tag port per bank, 2 miss-status registers per bank, write-back.
 * Below it, a memory that answers every request 20 cycles after it comes.
 */
#include <criterion/criterion.h>
#include <string.h>

#include "../../sim/mem/l2.h"
#include "../support/fixed_level.h"

typedef struct Fix {
    FixedLevel below;
    L2 *l2;
    uint64_t ans[1024]; /* answer cycle by request id, 0 = none yet */
    uint8_t from_below[1024]; /* the answer said its line came from below (MEM_FROM_BELOW) */
    int nans;
} Fix;

static void on_answer(void *ctx, uint64_t id, uint64_t cycle)
{
    Fix *f = ctx;
    const int from_below = (id & MEM_FROM_BELOW) != 0;
    id &= ~MEM_FROM_BELOW;
    cr_assert_lt(id, 1024u);
    f->from_below[id] = (uint8_t)from_below;
    cr_assert_eq(f->ans[id], 0u, "request %llu answered twice", (unsigned long long)id);
    f->ans[id] = cycle;
    f->nans++;
}

static L2Params params(void) { return (L2Params){1024, 2, 64, 2, 3, 1, 2, 1}; }

static void open_fix(Fix *f, L2Params p)
{
    memset(f, 0, sizeof *f);
    char err[256];
    f->l2 = l2_new(&p, fixed_level(&f->below), err, sizeof err);
    cr_assert_not_null(f->l2, "%s", err);
}

/* Line k's address. */
static uint64_t L(uint64_t k) { return 64 * k; }

static void run_all(Fix *f) { l2_run(f->l2, UINT64_MAX, on_answer, f); }

Test(l2, read_miss_then_hit)
{
    Fix f;
    open_fix(&f, params());
    /* line 0 at 10: bank 0 starts at 10, the tag check ends at 13, the line is read below at 13
     * and comes at 33, when the read is answered; then a hit at 40: 40 + 3 */
    l2_push(f.l2, L(0), 0, 10, 1);
    run_all(&f);
    cr_expect_eq(f.ans[1], 33);
    cr_expect_eq(f.below.n, 1);
    cr_expect_eq(f.below.at[0], 33);
    l2_push(f.l2, L(0) + 8, 0, 40, 2);
    run_all(&f);
    cr_expect_eq(f.ans[2], 43);
    cr_expect(f.from_below[1] && !f.from_below[2], "the miss's line came from below, the hit's did not");
    const L2Stats *s = l2_stats(f.l2);
    cr_expect_eq(s->reads, 2);
    cr_expect_eq(s->hits, 1);
    cr_expect_eq(s->misses, 1);
    cr_expect_eq(s->read_latency, (33 - 10) + 3);
    l2_free(f.l2);
}

Test(l2, one_port_per_bank_serializes_and_two_banks_do_not)
{
    Fix f;
    open_fix(&f, params());
    /* lines 0 and 2 (bank 0) and 1 (bank 1), all at 50, cold: bank 0 takes line 0 at 50 (below
     * at 53, back at 73) and line 2 at 51 (below at 54, back at 74); bank 1 takes line 1 at 50
     * (below 53, back 73). One cycle of port wait. */
    l2_push(f.l2, L(0), 0, 50, 1);
    l2_push(f.l2, L(2), 0, 50, 2);
    l2_push(f.l2, L(1), 0, 50, 3);
    run_all(&f);
    cr_expect_eq(f.ans[1], 73);
    cr_expect_eq(f.ans[2], 74);
    cr_expect_eq(f.ans[3], 73);
    cr_expect_eq(l2_stats(f.l2)->port_wait, 1);
    l2_free(f.l2);
}

Test(l2, a_miss_to_a_line_being_filled_is_merged)
{
    Fix f;
    open_fix(&f, params());
    /* line 4 at 100: starts 100, below at 103, back at 123; line 4 again at 101: its line is being
     * filled, so it waits in the register and is answered with the fill at 123; one read below. */
    l2_push(f.l2, L(4), 0, 100, 1);
    l2_push(f.l2, L(4) + 4, 0, 101, 2);
    run_all(&f);
    cr_expect_eq(f.ans[1], 123);
    cr_expect_eq(f.ans[2], 123);
    cr_expect_eq(f.below.n, 1);
    cr_expect_eq(l2_stats(f.l2)->merged, 1);
    cr_expect_eq(l2_stats(f.l2)->fills, 1);
    l2_free(f.l2);
}

Test(l2, a_bank_with_no_free_register_waits_for_a_fill)
{
    Fix f;
    open_fix(&f, params());
    /* lines 6, 8, 10 (bank 0) at 200, two registers: line 6 starts 200 (below 203, back 223), line 8
     * starts 201 (below 204, back 224); line 10 would start at 202 but no register is free: the bank
     * stops until line 6's fill at 223 frees one, then line 10 starts at 223, below at 226, back at
     * 246. mshr_wait = 223 - 202. */
    l2_push(f.l2, L(6), 0, 200, 1);
    l2_push(f.l2, L(8), 0, 200, 2);
    l2_push(f.l2, L(10), 0, 200, 3);
    run_all(&f);
    cr_expect_eq(f.ans[1], 223);
    cr_expect_eq(f.ans[2], 224);
    cr_expect_eq(f.ans[3], 246);
    cr_expect_eq(l2_stats(f.l2)->mshr_wait, 21);
    cr_expect_eq(l2_stats(f.l2)->mshr_max, 2);
    l2_free(f.l2);
}

Test(l2, a_dirty_victim_is_written_back)
{
    Fix f;
    open_fix(&f, params());
    /* Bank 0, set 2 holds lines 12, 28, 44 (line / 2 mod 4 = 2). A write of line 12 at 300 misses
     * and allocates it dirty without a read (answered 303). Line 28 at 310 takes the other way
     * (below 313, back 333). Line 44 at 400 evicts the least recently used, line 12, which is dirty:
     * written below at 403, and line 44 read at 403, back at 423. */
    l2_push(f.l2, L(12), 1, 300, 1);
    l2_push(f.l2, L(28), 0, 310, 2);
    l2_push(f.l2, L(44), 0, 400, 3);
    run_all(&f);
    cr_expect_eq(f.ans[1], 303);
    cr_expect_eq(f.ans[2], 333);
    cr_expect_eq(f.ans[3], 423);
    cr_assert_eq(f.below.n, 3, "a read, a write-back, a read: %d below", f.below.n);
    cr_expect_eq(f.below.write[1], 1);
    cr_expect_eq(f.below.addr[1], L(12));
    cr_expect_eq(f.below.at[1], 423);
    cr_expect_eq(l2_stats(f.l2)->writebacks, 1);
    /* line 12 again at 500: it was evicted, a miss (evicting line 28, clean: no write) */
    l2_push(f.l2, L(12), 0, 500, 4);
    run_all(&f);
    cr_expect_eq(f.ans[4], 523);
    cr_expect_eq(l2_stats(f.l2)->writebacks, 1);
    l2_free(f.l2);
}

Test(l2, write_through_writes_below_and_does_not_allocate)
{
    Fix f;
    L2Params p = params();
    p.write_back = 0;
    open_fix(&f, p);
    /* a write to line 3 (bank 1) at 10 misses: written below at 13, answered at 13, not allocated;
     * a read of it at 20 then misses (below 23, back 43); a write to it at 50 hits: written below at
     * 53; a read at 60 hits: 63. */
    l2_push(f.l2, L(3), 1, 10, 1);
    l2_push(f.l2, L(3), 0, 20, 2);
    l2_push(f.l2, L(3), 1, 50, 3);
    l2_push(f.l2, L(3), 0, 60, 4);
    run_all(&f);
    cr_expect_eq(f.ans[1], 13);
    cr_expect_eq(f.ans[2], 43);
    cr_expect_eq(f.ans[3], 53);
    cr_expect_eq(f.ans[4], 63);
    cr_assert_eq(f.below.n, 3);
    cr_expect(f.below.write[0] && !f.below.write[1] && f.below.write[2]);
    cr_expect_eq(l2_stats(f.l2)->hits, 2);
    l2_free(f.l2);
}

Test(l2, runs_stop_before_until_and_resume)
{
    Fix f;
    open_fix(&f, params());
    /* the miss of the first case, stepped: nothing is done before 10; by 13 (exclusive) the tag
     * check has started but the line is not back; at 34 it is answered (33). */
    l2_push(f.l2, L(0), 0, 10, 1);
    cr_expect_eq(l2_next(f.l2), 10);
    l2_run(f.l2, 10, on_answer, &f);
    cr_expect_eq(f.nans, 0);
    l2_run(f.l2, 13, on_answer, &f);
    cr_expect_eq(f.nans, 0);
    cr_expect_eq(l2_next(f.l2), 33);
    l2_run(f.l2, 34, on_answer, &f);
    cr_expect_eq(f.ans[1], 33);
    cr_expect_eq(l2_next(f.l2), UINT64_MAX);
    l2_free(f.l2);
}

Test(l2, impossible_geometry_is_refused)
{
    char err[256];
    L2Params p = params();
    p.bytes = 1000;
    cr_expect_eq(l2_check(&p, err, sizeof err), -1);
    cr_expect(strstr(err, "1000") != NULL, "%s", err);
    p = params();
    p.line_bytes = 48;
    cr_expect_eq(l2_check(&p, err, sizeof err), -1);
}

/* Functional warming (l2_warm, a sampled chip's unit): a warmed line hits with nothing sent below
 * and nothing counted; warming is least-recently-used like reads. */
Test(l2, warming_brings_lines_in_as_reads_would)
{
    Fix f;
    open_fix(&f, params());
    /* lines 0, 8, 16 map to bank 0, set 0 (line / 2 banks = 0, 4, 8: set 0 of 4); 2 ways, so
     * warming all three leaves 8 and 16. A read of 16 at 10 hits: 10 + 3 = 13. Of 0 at 20: a miss,
     * below at 23, back at 43. */
    cr_expect_eq(l2_warm(f.l2, L(0)), 1);
    cr_expect_eq(l2_warm(f.l2, L(8)), 1);
    cr_expect_eq(l2_warm(f.l2, L(0)), 0, "line 0 is there: now the most recent");
    cr_expect_eq(l2_warm(f.l2, L(16)), 1, "line 8, the least recent, leaves");
    cr_expect_eq(l2_warm(f.l2, L(16)), 0);
    cr_expect_eq(l2_stats(f.l2)->reads, 0, "warming counts nothing");
    l2_push(f.l2, L(16), 0, 10, 1);
    l2_push(f.l2, L(0), 0, 11, 2);
    l2_push(f.l2, L(8), 0, 20, 3);
    run_all(&f);
    cr_expect_eq(f.ans[1], 13);
    cr_expect_eq(f.ans[2], 14);
    cr_expect_eq(f.ans[3], 43);
    cr_expect_eq(f.below.n, 1, "only line 8 was read below");
    const L2Stats *s = l2_stats(f.l2);
    cr_expect_eq(s->hits, 2);
    cr_expect_eq(s->misses, 1);
    l2_free(f.l2);
}

/* l2_warm_written: a line warmed as written is dirty, so the read that evicts it writes it back
 * first (nothing counted for the warming itself). Bank 0, set 2 (lines 12, 28, 44): 12 warmed
 * written, 28 warmed read; a read of 44 at 400 evicts 12, the least recent: one write-back of line
 * 12 and one read of 44 below, answered at 423 as in a_dirty_victim_is_written_back. Warmed as
 * read instead, line 12 leaves with nothing written. */
Test(l2, a_line_warmed_as_written_is_written_back)
{
    for (int written = 0; written <= 1; written++) {
        Fix f;
        open_fix(&f, params());
        cr_expect_eq(written ? l2_warm_written(f.l2, L(12)) : l2_warm(f.l2, L(12)), 1);
        cr_expect_eq(l2_warm(f.l2, L(28)), 1);
        cr_expect_eq(l2_stats(f.l2)->writes, 0, "warming counts nothing");
        l2_push(f.l2, L(44), 0, 400, 1);
        run_all(&f);
        cr_expect_eq(f.ans[1], 423);
        int writes = 0;
        for (int i = 0; i < f.below.n; i++)
            if (f.below.write[i]) {
                writes++;
                cr_expect_eq(f.below.addr[i], L(12));
            }
        cr_expect_eq(f.below.n, 1 + written, "warmed %s: %d requests below", written ? "written" : "read", f.below.n);
        cr_expect_eq(writes, written);
        cr_expect_eq(l2_stats(f.l2)->writebacks, (uint64_t)written);
        l2_free(f.l2);
    }
}

static void count_answer(void *ctx, uint64_t id, uint64_t cycle)
{
    (void)id;
    (void)cycle;
    (*(int *)ctx)++;
}

/* Each core's share (l2_count_cores), by the core in the ids (MEM_ID): a_dirty_victim_is_written_back's
 * requests, sent by two cores, and one more.
 *   core 0 writes line 12: a miss, allocated dirty, nothing below       core 0: 1 access
 *   core 1 reads line 28: a miss, its fill below                        core 1: 1 access, 1 below
 *   core 1 reads line 44: a miss evicting dirty line 12: a write-back
 *       and a fill below                                                core 1: 2 accesses, 3 below
 *   core 0 reads line 44 again: a hit                                   core 0: 2 accesses, 1 hit
 * Summed: reads + writes 4, hits 1, fills + writebacks 3. A core past the count is not counted. */
Test(l2, each_cores_share_is_counted)
{
    Fix f;
    open_fix(&f, params());
    cr_assert_eq(l2_count_cores(f.l2, 2), 0);
    cr_expect_null(l2_core_stats(f.l2, 2));
    l2_push(f.l2, L(12), 1, 300, MEM_ID(0, 1));
    l2_push(f.l2, L(28), 0, 310, MEM_ID(1, 2));
    l2_push(f.l2, L(44), 0, 400, MEM_ID(1, 3));
    l2_push(f.l2, L(44), 0, 500, MEM_ID(0, 4));
    l2_push(f.l2, L(45), 0, 600, MEM_ID(7, 5)); /* core 7: a miss counted in the totals only */
    int n = 0;
    l2_run(f.l2, UINT64_MAX, count_answer, &n);
    cr_expect_eq(n, 5);
    const L2CoreStats *c0 = l2_core_stats(f.l2, 0), *c1 = l2_core_stats(f.l2, 1);
    cr_assert(c0 && c1);
    cr_expect(c0->accesses == 2 && c0->hits == 1 && c0->below == 0, "core 0: %llu %llu %llu",
              (unsigned long long)c0->accesses, (unsigned long long)c0->hits, (unsigned long long)c0->below);
    cr_expect(c1->accesses == 2 && c1->hits == 0 && c1->below == 3, "core 1: %llu %llu %llu",
              (unsigned long long)c1->accesses, (unsigned long long)c1->hits, (unsigned long long)c1->below);
    const L2Stats *s = l2_stats(f.l2);
    cr_expect_eq(s->reads + s->writes, 5);
    cr_expect_eq(s->hits, 1);
    cr_expect_eq(s->fills + s->writebacks, 4);
    l2_free(f.l2);
}
