/* tests/unit/test_raybuf.c -- the ray-buffer bank model (sim/machine/raybuf.c) against a plain
 * reference, and the interconnect's port search (sim/machine/interconnect.c) in its corner cases
 * and, for the data path, against its definition by brute force over random states.
 *
 * rb_access has a fast path for the common access (lines that never go down, over fewer lines
 * than banks) beside the general count; both must give what the definition gives: the cycles are
 * the most distinct lines any one bank serves, rb_lines counts distinct lines, rb_conflicted the
 * accesses with a bank serving two or more. The reference here counts that by brute force, over
 * random, ascending, repeated and conflicting address vectors of every length at several bank
 * counts (a power of two and not).
 */
#include <criterion/criterion.h>
#include <stdint.h>
#include <string.h>

#include "../../sim/machine/interconnect.h"
#include "../../sim/machine/raybuf.h"
#include "../../sim/timing.h"
#include "../support/rng.h"

/* The definition, by brute force: distinct lines, and the most of them in one bank. */
static int reference(const uint32_t *addr, int n, int line_bytes, int banks, int *distinct)
{
    uint32_t lines[ISA_MAX_LANES];
    int k = 0;
    for (int i = 0; i < n; i++) {
        uint32_t l = addr[i] / (uint32_t)line_bytes;
        int seen = 0;
        for (int j = 0; j < k; j++)
            seen |= lines[j] == l;
        if (!seen)
            lines[k++] = l;
    }
    int worst = 0;
    for (int b = 0; b < banks; b++) {
        int c = 0;
        for (int j = 0; j < k; j++)
            c += (int)(lines[j] % (uint32_t)banks) == b;
        if (c > worst)
            worst = c;
    }
    *distinct = k;
    return worst;
}

static uint64_t rng = TEST_RNG_SEED;
static uint32_t next_u32(void) { return test_rng_u32(&rng); }

/* One address vector of n lanes of the given kind. */
static void make_vector(uint32_t *a, int n, int kind, int line_bytes, int banks)
{
    uint32_t base = (next_u32() % 4096u) * 4u;
    switch (kind) {
    case 0: /* random words over 64 K */
        for (int i = 0; i < n; i++)
            a[i] = (next_u32() % 16384u) * 4u;
        break;
    case 1: /* ascending IDs with small gaps: the stream's usual gather (the fast path) */
        for (int i = 0; i < n; i++) {
            a[i] = base;
            base += 4u * (next_u32() % 5u);
        }
        break;
    case 2: /* ascending over a span near the bank count: the fast path's edge */
        for (int i = 0; i < n; i++)
            a[i] = base + (uint32_t)(i * (banks - 1 + (int)(next_u32() % 3u)) / (n > 1 ? n - 1 : 1)) *
                              (uint32_t)line_bytes;
        break;
    case 3: /* ascending, then one lane going down */
        for (int i = 0; i < n; i++)
            a[i] = base + 4u * (uint32_t)i;
        if (n > 1)
            a[n - 1] = base > 0 ? base - 4u : 0;
        break;
    case 4: /* lanes a whole bank cycle apart: every line in one bank */
        for (int i = 0; i < n; i++)
            a[i] = base + (uint32_t)(i * banks * line_bytes) * (next_u32() % 2u);
        break;
    default: /* three lines of one bank in random order: a conflicting line met again */
        for (int i = 0; i < n; i++)
            a[i] = base + (next_u32() % 3u) * (uint32_t)(banks * line_bytes) + 4u * (next_u32() % 16u);
        break;
    }
}

Test(raybuf, access_counts_match_the_definition_on_every_path)
{
    const int bank_counts[] = {32, 16, 64, 24, 1};
    for (size_t bi = 0; bi < sizeof bank_counts / sizeof *bank_counts; bi++) {
        RbParams p = {.banks = bank_counts[bi], .line = 64, .access = 2, .align_cycles = 1};
        RayBufs rb;
        cr_assert_eq(rb_init(&rb, &p), 0);
        int fast_seen = 0, conflict_seen = 0;
        for (int iter = 0; iter < 4000; iter++) {
            int n = 1 + iter % ISA_MAX_LANES;
            if (iter % 3 == 0)
                n = 16;
            uint32_t a[ISA_MAX_LANES];
            make_vector(a, n, iter % 6, p.line, p.banks);
            int distinct;
            int want = reference(a, n, p.line, p.banks, &distinct);
            memset(&rb.st, 0, sizeof rb.st);
            int got = rb_access(&rb, a, n);
            const RbStats st = rb.st;
            cr_assert_eq(got, want, "banks %d, kind %d, n %d: %d cycles, the definition gives %d", p.banks,
                         iter % 6, n, got, want);
            cr_assert_eq(st.accesses, 1u);
            cr_assert_eq(st.lines, (uint64_t)distinct, "banks %d, kind %d, n %d: %llu lines, want %d",
                         p.banks, iter % 6, n, (unsigned long long)st.lines, distinct);
            cr_assert_eq(st.conflicted, (uint64_t)(want > 1));
            fast_seen += want == 1 && distinct > 1;
            conflict_seen += want > 1;
        }
        /* both kinds of access were exercised */
        if (p.banks > 1)
            cr_assert(fast_seen > 100 && conflict_seen > 100, "banks %d: %d one-cycle, %d conflicting", p.banks,
                      fast_seen, conflict_seen);
        rb_free(&rb);
    }
}

/* rb_access keeps its last access's counts for an access whose lanes are the last one's moved by
 * one whole number of lines (the next field of the same rays). Each access here is the one before
 * moved by whole lines (also across the top of the address space), by part of a line, or with one
 * lane changed, after accesses of every kind; every answer must still be the definition's. */
Test(raybuf, an_access_moved_by_whole_lines_keeps_the_counts_and_no_other_does)
{
    const int bank_counts[] = {32, 64, 16, 24};
    for (size_t bi = 0; bi < sizeof bank_counts / sizeof *bank_counts; bi++) {
        RbParams p = {.banks = bank_counts[bi], .line = 64, .access = 2, .align_cycles = 1};
        RayBufs rb;
        cr_assert_eq(rb_init(&rb, &p), 0);
        uint32_t a[ISA_MAX_LANES];
        int n = 16, conflicts = 0;
        for (int iter = 0; iter < 6000; iter++) {
            const int step = iter % 8;
            if (step == 0) { /* a fresh vector of any kind and length */
                n = iter % 3 ? 16 : 1 + (int)(next_u32() % ISA_MAX_LANES);
                make_vector(a, n, (iter / 8) % 6, p.line, p.banks);
            } else if (step == 4) { /* to just below the top of the address space, then across it */
                uint32_t lo = a[0];
                for (int i = 1; i < n; i++)
                    lo = a[i] < lo ? a[i] : lo;
                const uint32_t d = (0u - (uint32_t)(p.line * (1 + (int)(next_u32() % 4u)))) - (lo & ~63u);
                for (int i = 0; i < n; i++)
                    a[i] += d;
            } else if (step == 6) { /* part of a line */
                const uint32_t d = 4u * (1u + next_u32() % 15u);
                for (int i = 0; i < n; i++)
                    a[i] += d;
            } else if (step == 7) { /* one lane to another line */
                a[next_u32() % (uint32_t)n] += (uint32_t)p.line * (1u + next_u32() % 40u);
            } else { /* whole lines, a field further on (or back) */
                const uint32_t d = (uint32_t)p.line * (next_u32() % 600u) - (uint32_t)p.line * 300u;
                for (int i = 0; i < n; i++)
                    a[i] += d;
            }
            int distinct;
            const int want = reference(a, n, p.line, p.banks, &distinct);
            memset(&rb.st, 0, sizeof rb.st);
            const int got = rb_access(&rb, a, n);
            const RbStats st = rb.st;
            cr_assert_eq(got, want, "banks %d, step %d, n %d: %d cycles, the definition gives %d", p.banks, step, n,
                         got, want);
            cr_assert_eq(st.lines, (uint64_t)distinct, "banks %d, step %d, n %d: %llu lines, want %d", p.banks,
                         step, n, (unsigned long long)st.lines, distinct);
            cr_assert_eq(st.accesses, 1u);
            cr_assert_eq(st.conflicted, (uint64_t)(want > 1));
            conflicts += want > 1;
        }
        cr_assert(conflicts > 200, "banks %d: only %d conflicting accesses", p.banks, conflicts);
        rb_free(&rb);
    }
}

Test(raybuf, interconnect_port_search_waits_only_when_every_port_is_taken)
{
    XbarParams p = {.latency = 1, .ports = 2};
    Xbar x;
    xbar_init(&x, &p);
    /* one AGU transfer in flight: a port is left for the data path at once */
    cr_assert_eq(xbar_transfer(&x, XBAR_AGU, 10, 4, 10), 10u);
    cr_assert_eq(xbar_transfer(&x, XBAR_DP, 11, 2, 11), 11u);
    /* the AGU and the data path hold both ports over [11, 13): the partition unit waits to 13 */
    cr_assert_eq(xbar_transfer(&x, XBAR_PART, 11, 1, 11), 13u);
    cr_assert_eq(x.st.unit_delay, 2u);
    /* two transfers in the window, but only one at cycle 12 itself: no wait */
    cr_assert_eq(xbar_transfer(&x, XBAR_AGU, 12, 1, 12), 12u);
    cr_assert_eq(x.st.unit_delay, 2u);
    /* the partition unit and the first AGU transfer hold both ports at 13: the data path waits */
    cr_assert_eq(xbar_transfer(&x, XBAR_DP, 13, 1, 13), 14u);
    /* with one port every transfer serializes */
    p.ports = 1;
    xbar_init(&x, &p);
    cr_assert_eq(xbar_transfer(&x, XBAR_AGU, 0, 3, 0), 0u);
    cr_assert_eq(xbar_transfer(&x, XBAR_DP, 1, 1, 1), 3u);
}

/* The data path's transfer by definition: the first cycle s >= from at which, over every cycle of
 * [s, s + max(len, 1)), fewer than `ports` of the partition unit's and the AGUs' transfers are
 * running. */
static uint64_t dp_reference(const Xbar *x, uint64_t from, uint64_t len)
{
    const uint64_t span = len ? len : 1;
    for (uint64_t s = from;; s++) {
        int ok = 1;
        for (uint64_t c = s; c < s + span && ok; c++) {
            int used = x->part.s <= c && c < x->part.e;
            for (int i = 0; i < x->agu_n; i++)
                used += x->agu[i].s <= c && c < x->agu[i].e;
            ok = used < x->p.ports;
        }
        if (ok)
            return s;
    }
}

Test(raybuf, interconnect_data_path_transfer_matches_the_definition)
{
    /* Random states of the other users' transfers (the data path's fast path when fewer than
     * `ports` of them run at `from`, the search otherwise), 1-3 ports. */
    int fast = 0, waited = 0;
    for (int trial = 0; trial < 20000; trial++) {
        XbarParams p = {.latency = 1, .ports = 1 + (int)(test_rng_u32(&rng) % 3)};
        Xbar x;
        xbar_init(&x, &p);
        const uint64_t from = 100;
        uint64_t s0 = from - 5 + test_rng_u32(&rng) % 12;
        x.part = (XbarIvl){s0, s0 + test_rng_u32(&rng) % 8};
        x.agu_n = (int)(test_rng_u32(&rng) % 5);
        for (int i = 0; i < x.agu_n; i++) {
            uint64_t s = from - 5 + test_rng_u32(&rng) % 12;
            x.agu[i] = (XbarIvl){s, s + test_rng_u32(&rng) % 6};
        }
        const uint64_t len = test_rng_u32(&rng) % 5;
        const uint64_t want = dp_reference(&x, from, len);
        memset(&x.st, 0, sizeof x.st);
        const uint64_t got = xbar_transfer(&x, XBAR_DP, from, len, from);
        cr_assert_eq(got, want, "trial %d: ports %d, part [%llu, %llu), %d AGU transfers, len %llu: %llu, want %llu",
                     trial, p.ports, (unsigned long long)x.part.s, (unsigned long long)x.part.e, x.agu_n,
                     (unsigned long long)len, (unsigned long long)got, (unsigned long long)want);
        cr_assert_eq(x.dp.s, got);
        cr_assert_eq(x.dp.e, got + len);
        cr_assert_eq(x.st.transfers, 1u);
        if (got == from)
            fast++;
        else
            waited++;
    }
    cr_assert(fast > 1000 && waited > 1000, "%d without a wait, %d waited", fast, waited);
}
