/* tests/unit/test_core_lanes.c -- the functional core (sim/core.h) lane by lane: ID-stream fetch
 * (core_sfetch), the partition unit (core_part), merge masking and compares (core_mask).
 *
 * As in test_core.c, every expected value is written by hand from the DESC column of
 * isa/opcodes.def, from docs/isa.md and from the comments of sim/core.h; none is obtained by
 * running the core. Programs are built with tests/support/core_prog.h.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/object.h"
#include "../../isa/isa.h"
#include "../../sim/core.h"
#include "../support/core_prog.h"

/* ==== core_sfetch ==================================================================================== */

/* One sfetch v4, m1, r9, r7 from IDM holding 0x1000 + i at byte 4i. Before it, v4 is 0xDEAD in
 * every lane and m1 all lanes, to see what the fetch leaves. */
static void sfetch_case(int n, uint32_t begin, uint32_t count)
{
    TcCore t;
    tc_init(&t, PROG(V_AI(VLI, 4, 0xDEAD, 0), I_A(MALL, 1), I_ABCD(SFETCH, 4, 1, 9, 7), I_0(HALT)), n);
    for (uint32_t a = 0; a < TC_IDM_BYTES; a += 4)
        tc_poke(t.c, CORE_MEM_IDM, a, 0x1000 + a / 4);
    uint32_t end = begin + 4 * count;
    core_set_sreg(t.c, 9, begin);
    core_set_sreg(t.c, 7, end);
    tc_run_halt(&t);
    /* n := min(N, (rd - rc) / 4) */
    uint32_t k = count < (uint32_t)n ? count : (uint32_t)n;
    for (int l = 0; l < n; l++) {
        uint32_t want;
        if (k == 0)
            want = 0xDEAD; /* empty stream: the vector is left as it was */
        else if ((uint32_t)l < k)
            want = 0x1000 + begin / 4 + (uint32_t)l;
        else
            want = 0x1000 + begin / 4 + k - 1; /* lanes >= n repeat the last ID */
        cr_expect_eq(core_vreg(t.c, 4, l), want, "N=%d begin=%u count=%u: v4[%d] = %#x, expected %#x", n, begin, count, l,
                     core_vreg(t.c, 4, l), want);
    }
    cr_expect_eq(core_mreg(t.c, 1), tc_lanes_mask((int)k), "N=%d count=%u: m1 = %#llx, expected lanes < %u", n, count,
                 (unsigned long long)core_mreg(t.c, 1), k);
    /* rc += 4N, capped at rd */
    uint32_t want_rc = begin + 4u * (uint32_t)n < end ? begin + 4u * (uint32_t)n : end;
    cr_expect_eq(core_sreg(t.c, 9), want_rc, "N=%d count=%u: rc = %u, expected %u", n, count, core_sreg(t.c, 9), want_rc);
    cr_expect_eq(core_sreg(t.c, 7), end, "rd must not change");
    tc_free(&t);
}

Test(core_sfetch, tails_duplication_and_advance)
{
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        uint32_t counts[] = {0, 1, (uint32_t)n - 1, (uint32_t)n, (uint32_t)n + 1, 37, 100};
        for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
            sfetch_case(n, 8, counts[i]);
            sfetch_case(n, 400, counts[i]);
        }
    }
}

Test(core_sfetch, walks_a_stream)
{
    /* A loop of sfetch until rc reaches rd runs ceil(L / N) times and sees every ID once, in order:
     * the IDs of the valid lanes are appended (sapp @m1) to a copy at 512. */
    const uint32_t L = 37;
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        TcCore t;
        tc_init(&t,
               PROG(I_ABCD(SFETCH, 4, 1, 9, 7), /* 0 */
                    V_AB(SAPP, 10, 4, 1),       /* 1 */
                    I_ABI(BLT, 9, 7, 0),        /* 2 */
                    I_0(HALT)),
               n);
        for (uint32_t i = 0; i < L; i++)
            tc_poke(t.c, CORE_MEM_IDM, 4 * i, 0x500 + 3 * i);
        core_set_sreg(t.c, 9, 0);
        core_set_sreg(t.c, 7, 4 * L);
        core_set_sreg(t.c, 10, 512);
        tc_run_halt(&t);
        uint32_t fetches = (L + (uint32_t)n - 1) / (uint32_t)n;
        cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_SFETCH], fetches, "N=%d", n);
        cr_expect_eq(core_sreg(t.c, 10), 512 + 4 * L, "N=%d: appended %u words", n, (core_sreg(t.c, 10) - 512) / 4);
        for (uint32_t i = 0; i < L; i++)
            cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, 512 + 4 * i), 0x500 + 3 * i, "N=%d copy[%u]", n, i);
        tc_free(&t);
    }
}

/* ==== core_part ====================================================================================== */

/* A filter as in Fig. 5 of Gribble & Ramani 2008: for each block, sfetch the IDs, gather a flag by
 * ID from RB0, compare it with 1, pmask; then part. Then a second part on the empty stream
 * [end, end) that only succeeds if the first one cleared the queue. */
static const IsaInstr filter_prog[] = {
    V_AI(VLI, 9, 1, 0),              /* 0: v9 = 1 */
    I_ABCD(SFETCH, 4, 1, 9, 7),      /* 1: loop */
    V_ABCI(RGAT, 5, 4, 20, 0, 1),    /* 2: flag of each ID */
    V_ABC(VIEQ, 2, 5, 9, 1),         /* 3: m2 = m1 & (flag == 1) */
    I_A(PMASK, 2),                   /* 4 */
    I_ABI(BLT, 9, 7, 1),             /* 5 */
    I_ABC(PART, 16, 6, 7),           /* 6: r16 = split point */
    I_ABC(PART, 17, 7, 7),           /* 7: queue must be empty again */
    I_0(HALT),                       /* 8 */
};

/* pattern: 0 random flags, 1 all set, 2 none set, 3 alternating */
static void partition_case(int n, uint32_t L, int pattern)
{
    const uint32_t base = 64;
    TcCore t;
    tc_init(&t, filter_prog, sizeof filter_prog / sizeof filter_prog[0], n);
    uint32_t ids[256], flag[1024];
    uint32_t seed = (uint32_t)(n * 1000 + (int)L * 10 + pattern);
    for (uint32_t id = 0; id < 1000; id++) {
        uint32_t f = pattern == 0 ? tc_lcg(&seed) & 1u : pattern == 1 ? 1u : pattern == 2 ? 0u : id & 1u;
        flag[id] = f;
        tc_poke(t.c, CORE_MEM_RB0, 4 * id, f ? 1u : 7u);
    }
    /* IDM: sentinels everywhere, the stream's IDs (distinct, in no particular order) in [base, end) */
    for (uint32_t a = 0; a < TC_IDM_BYTES; a += 4)
        tc_poke(t.c, CORE_MEM_IDM, a, 0xABCD0000u + a);
    for (uint32_t i = 0; i < L; i++) {
        ids[i] = (i * 389u + 11u) % 1000u;
        tc_poke(t.c, CORE_MEM_IDM, base + 4 * i, ids[i]);
    }
    uint32_t end = base + 4 * L;
    core_set_sreg(t.c, 6, base);
    core_set_sreg(t.c, 7, end);
    core_set_sreg(t.c, 9, base);
    core_set_sreg(t.c, 20, 0);
    CoreExit e = tc_run(&t, 1000000);
    cr_assert_eq(e, CORE_EXIT_HALT, "N=%d L=%u pattern %d: %s", n, L, pattern, core_trap_message(t.c));
    /* expected: stable, set first */
    uint32_t want[256], k = 0;
    for (uint32_t i = 0; i < L; i++)
        if (flag[ids[i]])
            want[k++] = ids[i];
    uint32_t nset = k;
    for (uint32_t i = 0; i < L; i++)
        if (!flag[ids[i]])
            want[k++] = ids[i];
    for (uint32_t i = 0; i < L; i++) {
        uint32_t got = tc_peek(t.c, CORE_MEM_IDM, base + 4 * i);
        if (got != want[i]) {
            cr_expect_eq(got, want[i], "N=%d L=%u pattern %d: IDM[%u] = %u, expected %u (stable, set first)", n, L, pattern,
                         i, got, want[i]);
            break;
        }
    }
    /* nothing outside [base, end) changed */
    for (uint32_t a = 0; a < TC_IDM_BYTES; a += 4)
        if (a < base || a >= end)
            cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, a), 0xABCD0000u + a, "N=%d L=%u: IDM[%#x] outside the stream changed", n, L,
                         a);
    cr_expect_eq(core_sreg(t.c, 16), base + 4 * nset, "N=%d L=%u pattern %d: ra = %u, expected rb + 4 * %u = %u", n, L,
                 pattern, core_sreg(t.c, 16), nset, base + 4 * nset);
    cr_expect_eq(core_sreg(t.c, 17), end, "empty partition returns its begin");
    cr_expect_eq(core_stats(t.c)->by_op[ISA_OP_PMASK], (L + (uint32_t)n - 1) / (uint32_t)n);
    tc_free(&t);
}

Test(core_part, stable_set_first_return_value_queue_cleared)
{
    for (int w = 0; w < TC_N_WIDTHS; w++)
        for (int pattern = 0; pattern < 4; pattern++) {
            partition_case(tc_widths[w], 37, pattern);
            partition_case(tc_widths[w], 131, pattern);
            partition_case(tc_widths[w], 1, pattern);
        }
}

Test(core_part, bits_past_the_stream_are_ignored)
{
    /* N = 4, L = 5, two pmask of an all-set mask: 8 bits queued, bits 5..7 set but without IDs.
     * Every ID is kept, in order: ra = rb + 4 * L. */
    TcCore t;
    tc_init(&t, PROG(I_A(PMASK, 0), I_A(PMASK, 0), I_ABC(PART, 1, 2, 3), I_0(HALT)), 4);
    for (uint32_t i = 0; i < 5; i++)
        tc_poke(t.c, CORE_MEM_IDM, 16 + 4 * i, 50 - i);
    core_set_sreg(t.c, 2, 16);
    core_set_sreg(t.c, 3, 36);
    tc_run_halt(&t);
    cr_expect_eq(core_sreg(t.c, 1), 36u);
    for (uint32_t i = 0; i < 5; i++)
        cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, 16 + 4 * i), 50 - i);
    tc_free(&t);
}

Test(core_part, queue_order_is_lane_zero_first)
{
    /* N = 4: m1 = lanes {0, 2} (0101 from lane 0), m2 = lane {3}; queue = 1,0,1,0, 0,0,0,1.
     * Stream of 8 IDs 10..17: set first -> 10 12 17, then 11 13 14 15 16. */
    TcCore t;
    tc_init(&t,
           PROG(V_A(VIOTA, 1, 0), V_ABI(VANDI, 2, 1, 1, 0), V_AI(VLI, 3, 0, 0), V_ABC(VIEQ, 1, 2, 3, 0), /* m1 even */
                I_AI(LI, 4, 3), I_AB(MTAIL, 2, 4), I_AB(MNOT, 2, 2),                                    /* m2 = {3} */
                I_A(PMASK, 1), I_A(PMASK, 2), I_ABC(PART, 5, 6, 7), I_0(HALT)),
           4);
    for (uint32_t i = 0; i < 8; i++)
        tc_poke(t.c, CORE_MEM_IDM, 4 * i, 10 + i);
    core_set_sreg(t.c, 6, 0);
    core_set_sreg(t.c, 7, 32);
    tc_run_halt(&t);
    const uint32_t want[8] = {10, 12, 17, 11, 13, 14, 15, 16};
    for (uint32_t i = 0; i < 8; i++)
        cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, 4 * i), want[i], "IDM[%u] = %u, expected %u", i,
                     tc_peek(t.c, CORE_MEM_IDM, 4 * i), want[i]);
    cr_expect_eq(core_sreg(t.c, 5), 12u);
    tc_free(&t);
}

/* ==== core_mask: merge masking and compares =========================================================== */

Test(core_mask, merge_masking)
{
    /* m2 = even lanes, m3 = lanes 0..2. Each destination starts as 0x77 in every lane; a masked
     * instruction changes only the lanes of its exec mask. */
    static const IsaInstr prog[] = {
        V_A(VIOTA, 0, 0),                   /* v0 = l */
        V_ABI(VANDI, 1, 0, 1, 0),
        V_AI(VLI, 2, 0, 0),
        V_ABC(VIEQ, 2, 1, 2, 0),            /* m2 = even lanes */
        I_AI(LI, 1, 3),
        I_AB(MTAIL, 3, 1),                  /* m3 = lanes < 3 */
        V_AI(VLI, 20, 0x3FC00000, 0),       /* 1.5f */
        V_AI(VLI, 21, 0x40100000, 0),       /* 2.25f */
        V_ABI(VSHLI, 14, 0, 2, 0),          /* v14 = 4l */
        V_AI(VLI, 3, 0x77, 0), V_AI(VLI, 4, 0x77, 0), V_AI(VLI, 5, 0x77, 0), V_AI(VLI, 6, 0x77, 0),
        V_AI(VLI, 7, 0x77, 0), V_AI(VLI, 8, 0x77, 0), V_AI(VLI, 9, 0x77, 0), V_AI(VLI, 10, 0x77, 0),
        V_AI(VLI, 11, 0x77, 0), V_AI(VLI, 12, 0x77, 0), V_AI(VLI, 13, 0x77, 0), V_AI(VLI, 15, 0x77, 0),
        V_AI(VLI, 16, 0x77, 0), V_AI(VLI, 17, 0x77, 0),
        V_ABC(VADD, 3, 0, 0, 2),            /* even: 2l */
        V_ABC(VFADD, 4, 20, 21, 2),         /* even: 3.75f */
        V_ABCD(VSEL, 5, 14, 1, 2, 3),       /* lanes < 3: m2 ? 4l : (l & 1) */
        V_AB(VBCAST, 6, 1, 2),              /* even: r1 = 3 */
        V_A(VIOTA, 7, 2),                   /* even: l */
        V_AB(RALLOC, 8, 4, 2),              /* even: r4 + rank among even lanes */
        V_ABI(LDB, 9, 5, 0, 2),             /* even: SM[r5] */
        V_ABCI(RGAT, 10, 0, 0, 0, 2),       /* even: RB0[4l] (r0 = 0) */
        V_AB(VFNEG, 11, 20, 2),             /* even: -1.5f */
        V_AB(VCVTFI, 12, 20, 2),            /* even: 1 */
        V_ABI(LDG, 13, 14, 0, 2),           /* even: SM[4l] */
        V_ABI(VSPLD, 15, 0, 0, 2),          /* even: SP[4l] */
        V_ABCD(VFMA, 16, 20, 20, 21, 2),    /* even: 1.5 * 1.5 + 2.25 = 4.5 */
        V_AB(VMOV, 17, 14, 3),              /* lanes < 3: 4l */
        V_ABCI(RSCT, 0, 0, 6, 0, 2),        /* even: RB0[r6 + 4l] := l */
        V_AB(SAPP, 7, 0, 2),                /* even lanes' l, in order, at IDM[r7] */
        V_ABI(FBADD, 20, 14, 0, 2),         /* even: FB[4l] += 1.5 */
        I_0(HALT),
    };
    const int ws[] = {1, 4, 12, 64};
    for (size_t w = 0; w < sizeof ws / sizeof ws[0]; w++) {
        int n = ws[w];
        TcCore t;
        tc_init(&t, prog, sizeof prog / sizeof prog[0], n);
        core_set_sreg(t.c, 4, 100);
        core_set_sreg(t.c, 5, 1024);
        core_set_sreg(t.c, 6, 2048);
        core_set_sreg(t.c, 7, 256);
        tc_poke(t.c, CORE_MEM_SCENE, 1024, 0xCAFE);
        for (int l = 0; l < n; l++) {
            tc_poke(t.c, CORE_MEM_SCENE, 4 * (uint32_t)l, 0x9000u + (uint32_t)l);
            tc_poke(t.c, CORE_MEM_RB0, 4 * (uint32_t)l, 0x500u + (uint32_t)l);
            tc_poke(t.c, CORE_MEM_SPAD, 4 * (uint32_t)l, 0x3000u + (uint32_t)l);
        }
        tc_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 2), 0x5555555555555555ull & tc_lanes_mask(n), "N=%d m2", n);
        uint32_t even_count = 0;
        for (int l = 0; l < n; l++) {
            uint32_t ul = (uint32_t)l;
            int even = (l & 1) == 0, low = l < 3;
            struct { int v; uint32_t want; } exp[] = {
                {3, even ? 2 * ul : 0x77},
                {4, even ? tc_fbits(3.75f) : 0x77},
                {5, low ? (even ? 4 * ul : (ul & 1)) : 0x77},
                {6, even ? 3u : 0x77},
                {7, even ? ul : 0x77},
                {8, even ? 100 + ul / 2 : 0x77},
                {9, even ? 0xCAFEu : 0x77},
                {10, even ? 0x500 + ul : 0x77},
                {11, even ? tc_fbits(-1.5f) : 0x77},
                {12, even ? 1u : 0x77},
                {13, even ? 0x9000 + ul : 0x77},
                {15, even ? 0x3000 + ul : 0x77},
                {16, even ? tc_fbits(4.5f) : 0x77},
                {17, low ? 4 * ul : 0x77},
            };
            for (size_t i = 0; i < sizeof exp / sizeof exp[0]; i++)
                cr_expect_eq(core_vreg(t.c, exp[i].v, l), exp[i].want, "N=%d v%d[%d] = %#x, expected %#x", n, exp[i].v, l,
                             core_vreg(t.c, exp[i].v, l), exp[i].want);
            /* scatters write nothing for lanes outside E */
            cr_expect_eq(tc_peek(t.c, CORE_MEM_RB0, 2048 + 4 * ul), even ? ul : 0u, "N=%d rsct lane %d", n, l);
            cr_expect_eq(tc_peek(t.c, CORE_MEM_FB, 4 * ul), even ? tc_fbits(1.5f) : 0u, "N=%d fbadd lane %d", n, l);
            if (even) {
                cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, 256 + 4 * even_count), ul, "N=%d sapp word %u", n, even_count);
                even_count++;
            }
        }
        cr_expect_eq(core_sreg(t.c, 4), 100 + even_count, "N=%d ralloc: rb += popcount(E)", n);
        cr_expect_eq(core_sreg(t.c, 7), 256 + 4 * even_count, "N=%d sapp: ra += 4 popcount(E)", n);
        cr_expect_eq(tc_peek(t.c, CORE_MEM_IDM, 256 + 4 * even_count), 0u, "N=%d sapp wrote past its lanes", n);
        tc_free(&t);
    }
}

Test(core_mask, compares_clear_lanes_outside_e)
{
    /* Destinations start all-set; every test below is true in every lane, so the result must be
     * exactly E (m2 = even lanes): lanes outside E are cleared, not merged. */
    static const IsaInstr a[] = {
        V_A(VIOTA, 0, 0), V_ABI(VANDI, 1, 0, 1, 0), V_AI(VLI, 2, 0, 0), V_ABC(VIEQ, 2, 1, 2, 0),
        V_AI(VLI, 3, 0x3F800000, 0),  /* 1.0f */
        V_AI(VLI, 4, 0x40000000, 0),  /* 2.0f */
        V_AI(VLI, 7, 0x7FC00000, 0),  /* NaN */
        V_AI(VLI, 6, 5, 0),
        I_A(MALL, 3), I_A(MALL, 4), I_A(MALL, 5), I_A(MALL, 6), I_A(MALL, 7),
        V_ABC(VFLT, 3, 3, 4, 2),      /* 1 < 2 */
        V_ABC(VFLE, 4, 3, 3, 2),      /* 1 <= 1 */
        V_ABC(VFEQ, 5, 4, 4, 2),      /* 2 == 2 */
        V_ABC(VFNE, 6, 7, 7, 2),      /* NaN != NaN: true */
        V_ABC(VILT, 7, 0, 6, 2),      /* l < 5: true only for l < 5 */
        I_0(HALT),
    };
    static const IsaInstr b[] = {
        V_A(VIOTA, 0, 0), V_ABI(VANDI, 1, 0, 1, 0), V_AI(VLI, 2, 0, 0), V_ABC(VIEQ, 2, 1, 2, 0),
        V_AI(VLI, 5, -1, 0), V_AI(VLI, 6, 5, 0), V_AI(VLI, 3, 0x3F800000, 0),
        I_A(MALL, 3), I_A(MALL, 4), I_A(MALL, 5), I_A(MALL, 6), I_A(MALL, 7), I_A(MCLR, 1),
        V_ABC(VIEQ, 3, 5, 5, 2),      /* true */
        V_ABC(VILT, 4, 5, 6, 2),      /* -1 < 5 signed: true */
        V_ABC(VILTU, 5, 6, 5, 2),     /* 5 < 0xFFFFFFFF unsigned: true */
        V_ABC(VILTU, 6, 5, 6, 2),     /* false */
        V_ABC(VFNE, 7, 3, 3, 2),      /* 1 != 1: false */
        V_ABC(VIEQ, 1, 0, 0, 0),      /* under m0: every lane, nothing above N */
        I_0(HALT),
    };
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        uint64_t even = 0x5555555555555555ull & tc_lanes_mask(n), low5 = tc_lanes_mask(n < 5 ? n : 5);
        TcCore t;
        tc_init(&t, a, sizeof a / sizeof a[0], n);
        tc_run_halt(&t);
        for (int m = 3; m <= 6; m++)
            cr_expect_eq(core_mreg(t.c, m), even, "N=%d program a: m%d = %#llx, expected %#llx", n, m,
                         (unsigned long long)core_mreg(t.c, m), (unsigned long long)even);
        cr_expect_eq(core_mreg(t.c, 7), even & low5, "N=%d vilt: m7 = %#llx", n, (unsigned long long)core_mreg(t.c, 7));
        tc_free(&t);

        tc_init(&t, b, sizeof b / sizeof b[0], n);
        tc_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 3), even, "N=%d vieq", n);
        cr_expect_eq(core_mreg(t.c, 4), even, "N=%d vilt signed", n);
        cr_expect_eq(core_mreg(t.c, 5), even, "N=%d viltu", n);
        cr_expect_eq(core_mreg(t.c, 6), 0u, "N=%d viltu false", n);
        cr_expect_eq(core_mreg(t.c, 7), 0u, "N=%d vfne false", n);
        cr_expect_eq(core_mreg(t.c, 1), tc_lanes_mask(n), "N=%d compare under m0", n);
        tc_free(&t);
    }
}

Test(core_mask, mask_registers_stay_within_n)
{
    /* bits for lanes >= N are always 0: mnot, mtail with a huge count, mxor of complements */
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        TcCore t;
        tc_init(&t,
               PROG(I_A(MCLR, 1), I_AB(MNOT, 2, 1), I_AI(LI, 1, 1000), I_AB(MTAIL, 3, 1), I_AI(LI, 2, -5),
                    I_AB(MTAIL, 4, 2), I_ABC(MXOR, 5, 2, 4), I_AB(MPOP, 3, 5), I_AB(MFIRST, 4, 4), I_AB(MFIRST, 5, 2),
                    I_0(HALT)),
               n);
        tc_run_halt(&t);
        cr_expect_eq(core_mreg(t.c, 2), tc_lanes_mask(n), "N=%d mnot", n);
        cr_expect_eq(core_mreg(t.c, 3), tc_lanes_mask(n), "N=%d mtail 1000", n);
        cr_expect_eq(core_mreg(t.c, 4), 0u, "N=%d mtail -5", n);
        cr_expect_eq(core_mreg(t.c, 5), tc_lanes_mask(n), "N=%d mxor", n);
        cr_expect_eq(core_sreg(t.c, 3), (uint32_t)n, "N=%d mpop", n);
        cr_expect_eq(core_sreg(t.c, 4), 0xFFFFFFFFu, "N=%d mfirst of empty = -1", n);
        cr_expect_eq(core_sreg(t.c, 5), 0u, "N=%d mfirst", n);
        tc_free(&t);
    }
}

Test(core_mask, ldb_with_empty_mask_does_no_access)
{
    /* ldb: one access serves all lanes; with no lane there is no access: no trap even from an
     * address outside scene memory, and the destination keeps its value. */
    TcCore t;
    tc_init(&t, PROG(V_AI(VLI, 1, 0x1234, 0), V_ABI(LDB, 1, 2, 0, 7), I_0(HALT)), 16);
    core_set_sreg(t.c, 2, 0x7FFFFFF0u);
    tc_run_halt(&t);
    for (int l = 0; l < 16; l++)
        cr_expect_eq(core_vreg(t.c, 1, l), 0x1234u);
    tc_free(&t);
}

Test(core_mask, fbadd_adds_in_lane_order)
{
    /* Three lanes add 1, 1e8, -1e8 to the same word. In lane order 1 + 1e8 rounds to 1e8 and the
     * result is 0; in reverse order -1e8 + 1e8 = 0 and the result is 1. */
    TcCore t;
    /* lane 0 = 1, lane 1 = 1e8, lane 2 = -1e8 (vli under one-lane masks), lane 3 idle */
    tc_init(&t,
           PROG(V_A(VIOTA, 0, 0), V_AI(VLI, 5, 1, 0), V_ABC(VIEQ, 1, 0, 5, 0), /* m1 = {1} */
                V_AI(VLI, 5, 2, 0), V_ABC(VIEQ, 2, 0, 5, 0),                     /* m2 = {2} */
                V_AI(VLI, 6, tc_fbits(1.0f), 0), V_AI(VLI, 6, tc_fbits(1e8f), 1), V_AI(VLI, 6, tc_fbits(-1e8f), 2),
                I_AI(LI, 3, 3), I_AB(MTAIL, 3, 3), V_AI(VLI, 7, 16, 0), V_ABI(FBADD, 6, 7, 0, 3), I_0(HALT)),
           4);
    tc_run_halt(&t);
    cr_expect_eq(tc_peek(t.c, CORE_MEM_FB, 16), tc_fbits(0.0f), "FB[16] = %#x, expected +0 (lanes in order)",
                 tc_peek(t.c, CORE_MEM_FB, 16));
    tc_free(&t);
}

Test(core_mask, lanes_at_or_above_n_are_never_written)
{
    /* The core computes lanes in blocks of 16 (sim/core.c); lanes N.. of a block are computed but
     * must never reach a register: every vector write, whole or under a mask, keeps them 0. */
    static const IsaInstr prog[] = {
        V_A(VIOTA, 0, 0),                   /* v0 = l */
        V_AI(VLI, 1, 0x3FC00000, 0),        /* 1.5f */
        V_ABC(VFADD, 2, 1, 1, 0),
        V_ABC(VFMUL, 3, 1, 2, 0),
        V_ABI(VANDI, 4, 0, 1, 0),
        V_AI(VLI, 5, 0, 0),
        V_ABC(VIEQ, 2, 4, 5, 0),            /* m2 = even lanes */
        V_ABC(VFSUB, 6, 3, 1, 2),           /* under m2 */
        V_ABCD(VSEL, 7, 1, 3, 2, 0),
        V_AB(VFNEG, 8, 1, 2),
        I_0(HALT),
    };
    for (int w = 0; w < TC_N_WIDTHS; w++) {
        int n = tc_widths[w];
        TcCore t;
        tc_init(&t, prog, sizeof prog / sizeof prog[0], n);
        tc_run_halt(&t);
        for (int v = 0; v <= 8; v++)
            for (int l = n; l < ISA_MAX_LANES; l++)
                cr_expect_eq(core_vreg(t.c, v, l), 0u, "N=%d v%d lane %d written", n, v, l);
        for (int l = 0; l < n; l++) {
            cr_expect_eq(core_vreg(t.c, 6, l), (l % 2 == 0) ? tc_fbits(3.0f) : 0u, "N=%d vfsub under m2 lane %d", n, l);
            cr_expect_eq(core_vreg(t.c, 7, l), (l % 2 == 0) ? tc_fbits(1.5f) : tc_fbits(4.5f), "N=%d vsel lane %d", n, l);
        }
        tc_free(&t);
    }
}
