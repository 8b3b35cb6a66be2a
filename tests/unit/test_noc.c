/* tests/unit/test_noc.c -- the on-chip network (sim/mem/noc.c) in front of a memory that answers
 * 20 cycles after a request comes (tests/support/fixed_level.h): every answer's cycle derived by
 * hand in the comments, and asserted exactly.
 *
 * The network of every case: 2 cores, 2 banks (bank = line mod 2), latency 5, 16 bytes a cycle on
 * every port, 64-byte lines: a read request is 1 cycle on a port, a write or a read's answer 4.
 */
#include <criterion/criterion.h>
#include <string.h>

#include "../../sim/mem/l2.h"
#include "../../sim/mem/noc.h"
#include "../support/fixed_level.h"

typedef struct Fix {
    FixedLevel behind;
    Noc *noc;
    uint64_t ans[8][8]; /* answer cycle by core and request number, 0 = none yet */
} Fix;

static void on_answer(void *ctx, uint64_t id, uint64_t cycle)
{
    Fix *f = ctx;
    const uint32_t core = MEM_ID_CORE(id);
    const uint64_t k = id & 0xffff;
    cr_assert(core < 8 && k < 8);
    cr_assert_eq(f->ans[core][k], 0u, "core %u request %llu answered twice", core, (unsigned long long)k);
    f->ans[core][k] = cycle;
}

static void open_fix(Fix *f)
{
    memset(f, 0, sizeof *f);
    char err[256];
    NocParams p = {2, 2, 5, 16, 64};
    f->noc = noc_new(&p, fixed_level(&f->behind), err, sizeof err);
    cr_assert_not_null(f->noc, "%s", err);
}

static void run_all(Fix *f) { noc_run(f->noc, UINT64_MAX, on_answer, f); }

Test(noc, a_read_crosses_four_ports)
{
    Fix f;
    open_fix(&f);
    /* core 0 reads line 0 (bank 0) at 10: its port 10..11, the head at bank 0's port at 15, which
     * takes it 15..16: delivered at 16; answered behind at 36; the line leaves bank 0's port 36..40,
     * its head at core 0's port at 41, which takes it 41..45: the core has it at 45. */
    noc_push(f.noc, 0, 0, 10, MEM_ID(0, 1));
    run_all(&f);
    cr_expect_eq(f.behind.n, 1);
    cr_expect_eq(f.behind.at[0], 36);
    cr_expect_eq(f.ans[0][1], 45);
    cr_expect_eq(noc_stats(f.noc)->port_wait, 0);
    cr_expect_eq(noc_stats(f.noc)->bytes, 64);
    noc_free(f.noc);
}

Test(noc, two_writes_queue_at_the_cores_port)
{
    Fix f;
    open_fix(&f);
    /* core 0 writes lines 0 and 1 at 10: the first takes its port 10..14, reaches bank 0 at 15,
     * crosses 15..19: delivered and answered at 19. The second waits for the port to 14 (4 cycles),
     * crosses 14..18, reaches bank 1 at 19, crosses 19..23: answered at 23. */
    noc_push(f.noc, 0, 1, 10, MEM_ID(0, 1));
    noc_push(f.noc, 64, 1, 10, MEM_ID(0, 2));
    run_all(&f);
    cr_expect_eq(f.ans[0][1], 19);
    cr_expect_eq(f.ans[0][2], 23);
    cr_expect_eq(noc_stats(f.noc)->port_wait, 4);
    cr_expect_eq(f.behind.n, 2);
    cr_expect(f.behind.write[0] && f.behind.write[1]);
    noc_free(f.noc);
}

Test(noc, two_cores_contend_for_a_banks_ports)
{
    Fix f;
    open_fix(&f);
    /* cores 0 and 1 read lines 0 and 2 (both bank 0) at 10. Both heads reach bank 0's port at 15:
     * core 0's (sent first) crosses 15..16, delivered at 16; core 1's waits a cycle, 16..17, delivered
     * at 17. Answered behind at 36 and 37. Core 0's line leaves bank 0's port 36..40, reaches core 0
     * at 41, in at 45. Core 1's waits for bank 0's port to 40 (3 cycles), crosses 40..44, reaches
     * core 1 at 45, in at 49. 1 + 3 cycles of contention. */
    noc_push(f.noc, 0, 0, 10, MEM_ID(0, 1));
    noc_push(f.noc, 128, 0, 10, MEM_ID(1, 1));
    run_all(&f);
    cr_expect_eq(f.behind.at[0], 36);
    cr_expect_eq(f.behind.at[1], 37);
    cr_expect_eq(f.ans[0][1], 45);
    cr_expect_eq(f.ans[1][1], 49);
    cr_expect_eq(noc_stats(f.noc)->port_wait, 4);
    noc_free(f.noc);
}

Test(noc, runs_stop_before_until)
{
    Fix f;
    open_fix(&f);
    /* the read of the first case, stepped: by 16 (exclusive) it is not delivered; by 17 it is;
     * the next thing is behind's answer at 36; by 46 the core has it (45). */
    noc_push(f.noc, 0, 0, 10, MEM_ID(0, 1));
    cr_expect_eq(noc_next(f.noc), 10);
    noc_run(f.noc, 16, on_answer, &f);
    cr_expect_eq(f.behind.n, 0);
    noc_run(f.noc, 17, on_answer, &f);
    cr_expect_eq(f.behind.n, 1);
    cr_expect_eq(noc_next(f.noc), 36);
    noc_run(f.noc, 46, on_answer, &f);
    cr_expect_eq(f.ans[0][1], 45);
    cr_expect_eq(noc_next(f.noc), UINT64_MAX);
    noc_free(f.noc);
}

Test(noc, cores_network_l2_memory)
{
    /* The network in front of the L2 of tests/unit/test_l2.c (2 banks, hit latency 3, one port,
     * 2 registers, write-back), in front of the 20-cycle memory. Core 1 reads line 0 at 10: network
     * 10..11, bank 0's port 15..16, into the L2 at 16, which misses (tag check to 19, the memory
     * answers at 39); the line leaves bank 0's port 39..43, core 1 has it at 48. Core 0 reads line 0
     * at 100: into the L2 at 106, a hit at 109, back through the ports 109..113 and 114..118. */
    FixedLevel mem;
    memset(&mem, 0, sizeof mem);
    char err[256];
    L2Params lp = {1024, 2, 64, 2, 3, 1, 2, 1};
    L2 *l2 = l2_new(&lp, fixed_level(&mem), err, sizeof err);
    cr_assert_not_null(l2, "%s", err);
    NocParams np = {2, 2, 5, 16, 64};
    Fix f;
    memset(&f, 0, sizeof f);
    f.noc = noc_new(&np, l2_level(l2), err, sizeof err);
    cr_assert_not_null(f.noc, "%s", err);
    noc_push(f.noc, 0, 0, 10, MEM_ID(1, 1));
    noc_push(f.noc, 8, 0, 100, MEM_ID(0, 1));
    run_all(&f);
    cr_expect_eq(mem.n, 1);
    cr_expect_eq(f.ans[1][1], 48);
    cr_expect_eq(f.ans[0][1], 118);
    cr_expect_eq(l2_stats(l2)->hits, 1);
    cr_expect_eq(l2_stats(l2)->misses, 1);
    noc_free(f.noc);
    l2_free(l2);
}
