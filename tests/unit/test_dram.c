/* tests/unit/test_dram.c -- the DRAM model (sim/mem/dram.h) against cycles derived by hand.
 *
 * Every case runs on the DDR4-2400 preset (sim/mem/dram_presets.def) unless it says otherwise:
 * CL 16, CWL 12, tRCD 16, tRP 16, tRAS 39, tRC 55, tCCD_S 4, tCCD_L 6, tRRD_S 4, tRRD_L 6,
 * tFAW 26, tWR 18, tWTR_S 3, tWTR_L 9, tRTP 9, tREFI 9360, tRFC 420, read-to-write gap 2,
 * BL8 = 4 CK of data bus. Mapping ro,ra,ba,co,bg,ch: byte offset 6 bits, bg bits 6-7, column
 * (in bursts) bits 8-14, bank 15-16, row 17-32. A request's done cycle is its last data beat:
 * a read issued at t is done at t + CL + 4, a write at t + CWL + 4.
 *
 * Suites: dram_params, dram_timing, dram_policy, dram_stream, dram_jump.
 */
#include <criterion/criterion.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/mem/dram.h"

typedef struct Got {
    uint64_t done[4096];
    int write[4096];
    int n;
    uint64_t last_cycle, last_id;
    int order_ok;
} Got;

static void on_done(void *ctx, uint64_t id, int write, uint64_t cycle)
{
    Got *g = ctx;
    cr_assert_lt(id, 4096);
    if (g->n && (cycle < g->last_cycle || (cycle == g->last_cycle && id < g->last_id)))
        g->order_ok = 0;
    g->last_cycle = cycle;
    g->last_id = id;
    g->done[id] = cycle;
    g->write[id] = write;
    g->n++;
}

static DramParams ddr4(void)
{
    DramParams p;
    cr_assert_eq(dram_preset(DRAM_PRESET_ddr4_2400, &p), 0);
    return p;
}

/* DDR4-2400's address of (bank group, bank, row, column in bursts). */
static uint64_t A(int bg, int ba, int row, int col)
{
    return (uint64_t)row << 17 | (uint64_t)ba << 15 | (uint64_t)col << 8 | (uint64_t)bg << 6;
}

typedef struct Rq {
    uint64_t addr;
    int write;
    uint64_t cycle;
} Rq;

/* Pushes the requests (ids 0..n-1) in order, each after running the DRAM to its cycle, then runs
 * until every one is done. */
static void replay(Dram *d, const Rq *r, int n, Got *g)
{
    memset(g, 0, sizeof *g);
    g->order_ok = 1;
    for (int i = 0; i < n; i++) {
        dram_run(d, r[i].cycle, on_done, g);
        dram_push(d, r[i].addr, r[i].write, r[i].cycle, (uint64_t)i);
    }
    while (dram_outstanding(d))
        dram_run(d, dram_next(d) + 1, on_done, g);
    cr_assert_eq(g->n, n);
    cr_assert(g->order_ok, "completions out of (cycle, id) order");
}

static Dram *make(const DramParams *p)
{
    char err[256];
    Dram *d = dram_new(p, err, sizeof err);
    cr_assert_not_null(d, "%s", err);
    return d;
}

static const DramChanStats *st(const Dram *d)
{
    return &dram_stats(d)->total;
}

/* ==== dram_params ================================================================================ */

Test(dram_params, presets_check_and_peak)
{
    /* burst bytes = bus / 8 x BL; data-bus CK per burst = BL / beats per CK */
    static const struct { DramPreset k; int bytes, cycles, mhz; } want[] = {
        {DRAM_PRESET_ddr4_2400, 64, 4, 1200},  {DRAM_PRESET_ddr5_4800, 64, 8, 2400},
        {DRAM_PRESET_lpddr5_6400, 32, 2, 800}, {DRAM_PRESET_gddr6_14000, 32, 2, 1750},
        {DRAM_PRESET_hbm2_2000, 64, 2, 1000}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        DramParams p;
        cr_assert_eq(dram_preset(want[i].k, &p), 0, "%s", dram_preset_name(want[i].k));
        cr_expect_eq(p.burst_bytes, want[i].bytes, "%s", p.name);
        cr_expect_eq(p.burst_cycles, want[i].cycles, "%s", p.name);
        cr_expect_eq(p.clock_mhz, want[i].mhz, "%s", p.name);
        cr_expect_geq(p.trc, p.tras + p.trp, "%s", p.name);
    }
}

Test(dram_params, mapping_per_preset)
{
    /* DDR4: offset 6, bg 2 bits at 6, co 7 bits at 8, ba 2 at 15, ro 16 at 17 (8 GiB). */
    DramParams p = ddr4();
    DramAddr a = dram_decode(&p, (5ULL << 17) | (2ULL << 15) | (3ULL << 8) | (1ULL << 6) | 0x15);
    cr_expect(a.ch == 0 && a.ra == 0 && a.bg == 1 && a.ba == 2 && a.ro == 5 && a.co == 3);
    cr_expect_eq(p.addr_bits, 33);
    a = dram_decode(&p, (1ULL << 33) | (65535ULL << 17)); /* a bit above the capacity is ignored */
    cr_expect(a.ro == 65535 && a.bg == 0 && a.co == 0);
    /* DDR5: 64 B bursts; ch 1 bit at 6, bg 3 at 7, co 6 (1024 / 16) at 10, ba 2 at 16, ro 16 at 18. */
    cr_assert_eq(dram_preset(DRAM_PRESET_ddr5_4800, &p), 0);
    a = dram_decode(&p, (7ULL << 18) | (3ULL << 16) | (63ULL << 10) | (5ULL << 7) | (1ULL << 6));
    cr_expect(a.ch == 1 && a.bg == 5 && a.co == 63 && a.ba == 3 && a.ro == 7);
    /* LPDDR5: 32 B bursts; ch 2 bits at 5, bg 2 at 7, co 6 at 9, ba 2 at 15, ro 16 at 17. */
    cr_assert_eq(dram_preset(DRAM_PRESET_lpddr5_6400, &p), 0);
    a = dram_decode(&p, (9ULL << 17) | (1ULL << 15) | (2ULL << 9) | (3ULL << 7) | (2ULL << 5));
    cr_expect(a.ch == 2 && a.bg == 3 && a.co == 2 && a.ba == 1 && a.ro == 9);
    /* GDDR6: 32 B; ch 1 at 5, bg 2 at 6, co 6 at 8, ba 2 at 14, ro 14 at 16. */
    cr_assert_eq(dram_preset(DRAM_PRESET_gddr6_14000, &p), 0);
    a = dram_decode(&p, (16383ULL << 16) | (2ULL << 14) | (1ULL << 8) | (2ULL << 6) | (1ULL << 5));
    cr_expect(a.ch == 1 && a.bg == 2 && a.co == 1 && a.ba == 2 && a.ro == 16383);
    /* HBM2: 64 B; ch 3 bits at 6, bg 2 at 9, co 4 (64 / 4) at 11, ba 2 at 15, ro 15 at 17. */
    cr_assert_eq(dram_preset(DRAM_PRESET_hbm2_2000, &p), 0);
    a = dram_decode(&p, (3ULL << 17) | (1ULL << 15) | (15ULL << 11) | (3ULL << 9) | (6ULL << 6));
    cr_expect(a.ch == 6 && a.bg == 3 && a.co == 15 && a.ba == 1 && a.ro == 3);
}

Test(dram_params, mapping_errors_name_the_key)
{
    static const char *const bad[][2] = {
        {"ro,ra,ba,co,bg", "does not name ch"},
        {"ro,ra,ba,co,bg,ch,ro", "names ro twice"},
        {"ro,ra,xx,co,bg,ch", "'xx'"},
        {"ro,ra,ba,co,bg,ch,", "ends with a comma"},
        {"", "does not name"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        DramParams p = ddr4();
        char err[256] = "";
        snprintf(p.mapping, sizeof p.mapping, "%s", bad[i][0]);
        cr_expect_eq(dram_params_check(&p, err, sizeof err), -1, "%s", bad[i][0]);
        cr_expect(strstr(err, "key dram.mapping") && strstr(err, bad[i][1]), "%s: %s", bad[i][0], err);
    }
    DramParams p = ddr4();
    char err[256] = "";
    p.rows = 1 << 24; /* 24 + 2 + 7 + 2 + 6 bits fit */
    cr_expect_eq(dram_params_check(&p, err, sizeof err), 0, "%s", err);
    p = ddr4();
    p.trc = 50;
    cr_expect_eq(dram_params_check(&p, err, sizeof err), -1);
    cr_expect(strstr(err, "key dram.trc"), "%s", err);
    p = ddr4();
    p.banks = 3;
    cr_expect_eq(dram_params_check(&p, err, sizeof err), -1);
    cr_expect(strstr(err, "key dram.banks"), "%s", err);
    p = ddr4();
    p.write_low = p.write_high;
    cr_expect_eq(dram_params_check(&p, err, sizeof err), -1);
    cr_expect(strstr(err, "key dram.write_low"), "%s", err);
}

Test(dram_params, from_config_keys)
{
    CfgMachine c;
    cfg_defaults(&c);
    DramParams p;
    char err[256];
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    cr_expect_str_eq(p.name, "ddr4_2400");
    c.dram_preset = DRAM_PRESET_hbm2_2000;
    c.dram_trcd = 20;
    c.dram_mapping = 2; /* "ro,ra,bg,ba,co,ch" */
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(p.trcd, 20);
    cr_expect_eq(p.trp, 14);
    cr_expect_str_eq(p.mapping, "ro,ra,bg,ba,co,ch");
    c.dram_write_high = 40; /* more than the 32 entries of the write queue */
    cr_expect_eq(dram_params(&c, &p, err, sizeof err), -1);
    cr_expect(strstr(err, "key dram.write_high"), "%s", err);
}

Test(dram_params, histogram_buckets)
{
    for (uint64_t v = 0; v < 5000; v++) {
        int b = dram_hist_bucket(v);
        cr_assert_leq(dram_hist_low(b), v);
        cr_assert(b + 1 >= DRAM_HIST_BUCKETS || dram_hist_low(b + 1) > v);
    }
    cr_expect_eq(dram_hist_low(dram_hist_bucket(1023)), 1023); /* exact below 1024 */
    cr_expect_eq(dram_hist_low(dram_hist_bucket(1025)), 1024); /* then 32 per octave: 1024..1055 */
    uint64_t h[DRAM_HIST_BUCKETS] = {0};
    for (int v = 1; v <= 100; v++)
        h[v]++;
    cr_expect_eq(dram_hist_quantile(h, 0.5), 50);
    cr_expect_eq(dram_hist_quantile(h, 0.95), 95);
    cr_expect_eq(dram_hist_quantile(h, 0.99), 99);
}

/* ==== dram_timing ================================================================================ */

Test(dram_timing, read_to_closed_bank)
{
    /* ACT at 0, RD at tRCD = 16, data 32..35: done at tRCD + CL + 4 = 36. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}};
    Got g;
    replay(d, r, 1, &g);
    cr_expect_eq(g.done[0], 36);
    cr_expect_eq(st(d)->row_misses, 1);
    cr_expect_eq(st(d)->activates, 1);
    cr_expect_eq(st(d)->read_latency, 36);
    dram_free(d);
}

Test(dram_timing, row_hit)
{
    /* The row opened by the first read stays open (open page): a read arriving at 100 issues RD at
     * 100 and is done at 100 + CL + 4 = 120, latency 20. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 7, 0), 0, 0}, {A(0, 0, 7, 5), 0, 100}};
    Got g;
    replay(d, r, 2, &g);
    cr_expect_eq(g.done[0], 36);
    cr_expect_eq(g.done[1], 120);
    cr_expect_eq(st(d)->row_hits, 1);
    cr_expect_eq(st(d)->row_misses, 1);
    dram_free(d);
}

Test(dram_timing, row_conflict)
{
    /* Row 0 open; a read of row 1 in the same bank at 100: PRE at 100, ACT at 100 + tRP = 116, RD at
     * 116 + tRCD = 132, done 132 + 20 = 152 = arrival + tRP + tRCD + CL + 4.
     * Arriving at 20 instead, the PRE must wait for tRAS: PRE at ACT 0 + 39 = 39 (RD 16 + tRTP 9 =
     * 25 is earlier); ACT at 39 + 16 = 55 (= tRC after the first ACT, too), RD 71, done 91. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}, {A(0, 0, 1, 0), 0, 100}};
    Got g;
    replay(d, r, 2, &g);
    cr_expect_eq(g.done[1], 152);
    cr_expect_eq(st(d)->row_conflicts, 1);
    cr_expect_eq(st(d)->precharges, 1);
    dram_free(d);
    d = make(&p);
    Rq r2[] = {{A(0, 0, 0, 0), 0, 0}, {A(0, 0, 1, 0), 0, 20}};
    replay(d, r2, 2, &g);
    cr_expect_eq(g.done[0], 36);
    cr_expect_eq(g.done[1], 91);
    dram_free(d);
}

Test(dram_timing, activates_spaced_by_trrd)
{
    /* Four banks of one bank group: ACTs at 0, 6, 12, 18 (tRRD_L); RDs at 16, 22, 28, 34; done
     * 36, 42, 48, 54. Four bank groups: ACTs at 0, 4, 8, 12 (tRRD_S); RDs 16, 20, 24, 28 (tCCD_S);
     * done 36, 40, 44, 48. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq same[] = {{A(0, 0, 1, 0), 0, 0}, {A(0, 1, 1, 0), 0, 0}, {A(0, 2, 1, 0), 0, 0}, {A(0, 3, 1, 0), 0, 0}};
    Got g;
    replay(d, same, 4, &g);
    cr_expect(g.done[0] == 36 && g.done[1] == 42 && g.done[2] == 48 && g.done[3] == 54, "%llu %llu %llu %llu",
              (unsigned long long)g.done[0], (unsigned long long)g.done[1], (unsigned long long)g.done[2],
              (unsigned long long)g.done[3]);
    dram_free(d);
    d = make(&p);
    Rq across[] = {{A(0, 0, 1, 0), 0, 0}, {A(1, 0, 1, 0), 0, 0}, {A(2, 0, 1, 0), 0, 0}, {A(3, 0, 1, 0), 0, 0}};
    replay(d, across, 4, &g);
    cr_expect(g.done[0] == 36 && g.done[1] == 40 && g.done[2] == 44 && g.done[3] == 48);
    dram_free(d);
}

Test(dram_timing, fifth_activate_waits_for_tfaw)
{
    /* Banks in bank groups 0, 1, 2, 3, then bank 1 of group 0: ACTs at 0, 4, 8, 12 (tRRD_S); the
     * fifth would be legal at 16 by tRRD_S (6 by tRRD_L) but tFAW holds it to 0 + 26 = 26. RDs at
     * 16, 20, 24, 28 and 26 + 16 = 42: the fifth is done at 42 + 20 = 62. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 1, 0), 0, 0}, {A(1, 0, 1, 0), 0, 0}, {A(2, 0, 1, 0), 0, 0},
              {A(3, 0, 1, 0), 0, 0}, {A(0, 1, 1, 0), 0, 0}};
    Got g;
    replay(d, r, 5, &g);
    cr_expect_eq(g.done[3], 48);
    cr_expect_eq(g.done[4], 62);
    dram_free(d);
    /* Without the window (tFAW = 4 x tRRD_S = 16, no longer binding) the fifth ACT is legal at 16,
     * but the first read's RD takes the command bus at 16 (row hits first): ACT 17, RD 33, done 53. */
    p.tfaw = 16;
    d = make(&p);
    replay(d, r, 5, &g);
    cr_expect_eq(g.done[4], 53);
    dram_free(d);
}

Test(dram_timing, tccd_long_within_a_group_short_across)
{
    /* Eight reads of one row of one bank: ACT 0, RDs every tCCD_L = 6 from 16: the last at 58, done
     * 78. Eight consecutive bursts (bank groups 0..3, columns 0 and 1): ACTs 0, 4, 8, 12; RDs 16,
     * 20, 24, 28 then 32, 36, 40, 44 (tCCD_S, and the bus: 4 CK a burst): last done 64. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq one[8], seq[8];
    for (int i = 0; i < 8; i++) {
        one[i] = (Rq){A(0, 0, 3, i), 0, 0};
        seq[i] = (Rq){(uint64_t)i * 64 + (3ULL << 17), 0, 0};
    }
    Got g;
    replay(d, one, 8, &g);
    cr_expect_eq(g.done[7], 78);
    cr_expect_eq(st(d)->row_hits, 7);
    dram_free(d);
    d = make(&p);
    replay(d, seq, 8, &g);
    cr_expect_eq(g.done[3], 48);
    cr_expect_eq(g.done[7], 64);
    cr_expect_eq(st(d)->busy_cycles, 32);
    dram_free(d);
}

Test(dram_timing, read_to_write_turnaround)
{
    /* A read and a write of one open row, both at 0: ACT 0, RD 16 (data 32..35). The write's data
     * may start 2 CK after the read's (36 + 2 = 38): WR at 38 - CWL = 26, done 26 + 12 + 4 = 42. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}, {A(0, 0, 0, 1), 1, 0}};
    Got g;
    replay(d, r, 2, &g);
    cr_expect_eq(g.done[0], 36);
    cr_expect_eq(g.done[1], 42);
    cr_expect_eq(g.write[1], 1);
    dram_free(d);
}

Test(dram_timing, write_to_read_twtr)
{
    /* Rows open in bank groups 0 and 1 (ACT 0 and 4, RD 16 and 20, done 36, 40). A write to group
     * 0 at 100: WR at 100, data 112..115, done 116. Reads at 101: in group 1 tWTR_S holds RD to
     * 116 + 3 = 119 (done 139); in group 0 tWTR_L to 116 + 9 = 125 (done 145). */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}, {A(1, 0, 0, 0), 0, 0}, {A(0, 0, 0, 1), 1, 100},
              {A(1, 0, 0, 1), 0, 101}, {A(0, 0, 0, 2), 0, 101}};
    Got g;
    replay(d, r, 5, &g);
    cr_expect_eq(g.done[1], 40);
    cr_expect_eq(g.done[2], 116);
    cr_expect_eq(g.done[3], 139);
    cr_expect_eq(g.done[4], 145);
    dram_free(d);
}

Test(dram_timing, refresh_delays_a_read)
{
    /* All banks closed; a read arriving at tREFI = 9360 finds the refresh due: REF at 9360, the ACT
     * waits tRFC: 9780, RD 9796, done 9816: latency tRFC + tRCD + CL + 4 = 456. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 9360}};
    Got g;
    replay(d, r, 1, &g);
    cr_expect_eq(g.done[0], 9816);
    cr_expect_eq(st(d)->refreshes, 1);
    cr_expect_eq(st(d)->refresh_cycles, 420);
    dram_free(d);
    /* With a row open (a read at 0), the refresh first precharges it: PRE 9360, REF at 9360 + tRP =
     * 9376, ACT 9376 + 420 = 9796, RD 9812, done 9832; the read is a miss, not a hit. */
    d = make(&p);
    Rq r2[] = {{A(0, 0, 0, 0), 0, 0}, {A(0, 0, 0, 1), 0, 9360}};
    replay(d, r2, 2, &g);
    cr_expect_eq(g.done[1], 9832);
    cr_expect_eq(st(d)->row_misses, 2);
    cr_expect_eq(st(d)->precharges, 1);
    dram_free(d);
}

/* ==== dram_policy ================================================================================ */

Test(dram_policy, closed_page)
{
    /* Closed page: the first read's bank auto-precharges at max(ACT + tRAS, RD + tRTP) = 39, so
     * the next ACT may come at 39 + tRP = 55. A read of the same row at 100 is a miss: ACT 100,
     * RD 116, done 136 (open page: 120). */
    DramParams p = ddr4();
    p.page_policy = DRAM_PAGE_CLOSED;
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 7, 0), 0, 0}, {A(0, 0, 7, 5), 0, 100}};
    Got g;
    replay(d, r, 2, &g);
    cr_expect_eq(g.done[1], 136);
    cr_expect_eq(st(d)->row_misses, 2);
    cr_expect_eq(st(d)->precharges, 2);
    dram_free(d);
    /* A queued hit keeps the row open: both at 0, RDs 16 and 22 (tCCD_L), done 36 and 42; one
     * auto-precharge after the second. */
    d = make(&p);
    Rq r2[] = {{A(0, 0, 7, 0), 0, 0}, {A(0, 0, 7, 5), 0, 0}};
    replay(d, r2, 2, &g);
    cr_expect_eq(g.done[1], 42);
    cr_expect_eq(st(d)->precharges, 1);
    cr_expect_eq(st(d)->row_hits, 1);
    dram_free(d);
}

Test(dram_policy, write_draining)
{
    /* Reads in groups 0 and 3, writes in groups 1 and 2, all at 0, watermarks high 2, low 0: the
     * write queue is at its high mark, so writes go first: ACT 0 (g1), 4 (g2), WR 16, 20 (data
     * 28..31, 32..35): done 32, 36. The queue empty, reads: ACT 21 (g0: the cycle after the WR),
     * 25 (g3); RD g0 at max(21 + 16, last write data 36 + tWTR_S 3) = 39, done 59; RD g3 at
     * 25 + 16 = 41 -> tCCD_S 43, done 63. */
    DramParams p = ddr4();
    p.write_high = 2;
    p.write_low = 0;
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}, {A(1, 0, 0, 0), 1, 0}, {A(2, 0, 0, 0), 1, 0}, {A(3, 0, 0, 0), 0, 0}};
    Got g;
    replay(d, r, 4, &g);
    cr_expect(g.done[1] == 32 && g.done[2] == 36 && g.done[0] == 59 && g.done[3] == 63, "%llu %llu %llu %llu",
              (unsigned long long)g.done[0], (unsigned long long)g.done[1], (unsigned long long)g.done[2],
              (unsigned long long)g.done[3]);
    dram_free(d);
    /* Below the high mark reads go first: ACT 0, 4, RD 16, 20 (done 36, 40); then the writes: ACT
     * 21, 25; WR at 21 + 16 = 37 (bus: read data end 40 + 2 - CWL = 30), done 53; WR 41, done 57. */
    p = ddr4();
    d = make(&p);
    replay(d, r, 4, &g);
    cr_expect(g.done[0] == 36 && g.done[3] == 40 && g.done[1] == 53 && g.done[2] == 57);
    dram_free(d);
}

Test(dram_policy, queue_full_back_pressure)
{
    /* A read queue of 2 and four reads of one row at 0: RDs at 16, 22, 28, 34 (tCCD_L), done 36,
     * 42, 48, 54. The third enters the cycle after the first RD frees its slot (17), the fourth
     * at 23: back-pressure 17 + 23 = 40 cycles over 2 requests. */
    DramParams p = ddr4();
    p.read_queue = 2;
    Dram *d = make(&p);
    Rq r[4];
    for (int i = 0; i < 4; i++)
        r[i] = (Rq){A(0, 0, 0, i), 0, 0};
    Got g;
    replay(d, r, 4, &g);
    cr_expect(g.done[0] == 36 && g.done[1] == 42 && g.done[2] == 48 && g.done[3] == 54);
    cr_expect_eq(st(d)->backpressure, 40);
    cr_expect_eq(st(d)->backpressured, 2);
    cr_expect_eq(st(d)->occupancy_max, 2);
    dram_free(d);
}

Test(dram_policy, reset_is_cold_and_keeps_counters)
{
    DramParams p = ddr4();
    Dram *d = make(&p);
    Rq r[] = {{A(0, 0, 0, 0), 0, 0}};
    Got g;
    replay(d, r, 1, &g);
    dram_reset(d);
    replay(d, r, 1, &g);
    cr_expect_eq(g.done[0], 36); /* a closed bank again, at time 0 */
    cr_expect_eq(st(d)->reads, 2);
    dram_free(d);
}

/* Functional warming (dram_warm, a sampled chip's unit): the row is open as if read, with no
 * time spent and nothing counted. */
Test(dram_policy, warming_opens_the_row_and_nothing_else)
{
    /* Row 7 of bank (0, 0) warmed open: a read of it at 0 is a row hit, RD at 0, done CL + 4 = 20;
     * a read of row 8 of the same bank at 0 a conflict: PRE 0 (nothing to wait for), ACT at tRP =
     * 16, RD at 16 + tRCD = 32, done 32 + 20 = 52. */
    DramParams p = ddr4();
    Dram *d = make(&p);
    dram_warm(d, A(0, 0, 7, 0));
    cr_expect_eq(dram_outstanding(d), 0);
    cr_expect_eq(st(d)->activates, 0, "warming counts no command");
    Rq r[] = {{A(0, 0, 7, 5), 0, 0}};
    Got g;
    replay(d, r, 1, &g);
    cr_expect_eq(g.done[0], 20);
    cr_expect_eq(st(d)->row_hits, 1);
    cr_expect_eq(st(d)->activates, 0);
    dram_reset(d);
    dram_warm(d, A(0, 0, 7, 0));
    Rq r2[] = {{A(0, 0, 8, 0), 0, 0}};
    replay(d, r2, 1, &g);
    cr_expect_eq(g.done[0], 52);
    cr_expect_eq(st(d)->row_conflicts, 1);
    dram_free(d);
    /* Closed page: nothing stays open, so warming opens nothing: a closed bank, done 36. */
    p.page_policy = DRAM_PAGE_CLOSED;
    d = make(&p);
    dram_warm(d, A(0, 0, 7, 0));
    replay(d, r, 1, &g);
    cr_expect_eq(g.done[0], 36);
    cr_expect_eq(st(d)->row_misses, 1);
    dram_free(d);
}

/* ==== dram_stream ================================================================================ */

/* A sequential read stream of n bursts, all waiting at 0: data-bus busy / elapsed cycles. */
static double stream_share(DramPreset k, int n, uint64_t *elapsed)
{
    DramParams p;
    cr_assert_eq(dram_preset(k, &p), 0);
    Dram *d = make(&p);
    for (int i = 0; i < n; i++)
        dram_push(d, (uint64_t)i * (uint64_t)p.burst_bytes, 0, 0, (uint64_t)i);
    while (dram_outstanding(d))
        dram_run(d, dram_next(d) + 1, NULL, NULL);
    const DramChanStats *s = st(d);
    cr_assert_eq(s->reads, (uint64_t)n);
    *elapsed = s->cycles;
    double share = (double)s->busy_cycles / ((double)s->cycles * p.channels);
    dram_free(d);
    return share;
}

Test(dram_stream, sequential_reads_reach_90_percent_of_peak)
{
    for (int k = 0; k < DRAM_NPRESETS; k++) {
        uint64_t el;
        double share = stream_share((DramPreset)k, 200000, &el);
        cr_expect_geq(share, 0.90, "%s: %.4f of peak over %llu cycles", dram_preset_name((DramPreset)k), share,
                      (unsigned long long)el);
    }
}

/* ==== dram_jump ================================================================================== */

static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* Replays r both ways (jumping and ticking every cycle) and asserts the same completions and
 * counters. */
static void same_both_ways(const DramParams *p, const Rq *r, int n)
{
    static Got a, b;
    Dram *dj = make(p), *dt = make(p);
    dram_set_tick_every_cycle(dt, 1);
    replay(dj, r, n, &a);
    replay(dt, r, n, &b);
    for (int i = 0; i < n; i++)
        cr_assert_eq(a.done[i], b.done[i], "%s request %d: jumping %llu, ticking %llu", p->name, i,
                     (unsigned long long)a.done[i], (unsigned long long)b.done[i]);
    /* The ticking run ends at the same cycle: stats equal field by field. */
    const DramChanStats *x = st(dj), *y = st(dt);
#define DRAM_X(f, unit, desc) cr_assert_eq(x->f, y->f, "%s: %s", p->name, #f);
    DRAM_STATS(DRAM_X)
#undef DRAM_X
    cr_assert_eq(memcmp(x->hist, y->hist, sizeof x->hist), 0);
    dram_free(dj);
    dram_free(dt);
}

Test(dram_jump, ticking_every_cycle_gives_the_same_results)
{
    static Rq r[3000];
    uint64_t seed = 0x9e3779b97f4a7c15ULL;
    for (int k = 0; k < DRAM_NPRESETS; k++) {
        DramParams p;
        cr_assert_eq(dram_preset((DramPreset)k, &p), 0);
        p.trefi = 700; /* many refreshes in a short trace */
        p.trfc = 90;
        for (int shape = 0; shape < 6; shape++) {
            /* tiny queues (back-pressure, draining at every turn), then the default 32 / 32 */
            p.read_queue = shape < 4 ? 6 : 32;
            p.write_queue = shape < 4 ? 5 : 32;
            p.write_high = shape < 4 ? 4 : 24;
            p.write_low = shape < 4 ? 1 : 8;
            p.page_policy = shape & 1 ? DRAM_PAGE_CLOSED : DRAM_PAGE_OPEN;
            uint64_t cyc = 0;
            for (int i = 0; i < 3000; i++) {
                uint64_t x = rng_next(&seed);
                if (shape < 2 || shape >= 4) /* random: rows and banks everywhere, bursts, gaps */
                    cyc += x % 7 == 0 ? x % 200 : x % 3;
                else /* adversarial: two rows of one bank in turn, same cycle, and far jumps */
                    cyc += i % 64 == 63 ? 1000 + x % 2000 : 0;
                uint64_t addr = shape < 2 ? (x >> 8)
                                : shape >= 4 ? (x >> 52) << 6 /* bits 6-17: two rows a bank, many hits */
                                             : ((uint64_t)(i & 1) << 26) | ((uint64_t)(i % 5) << 6);
                r[i] = (Rq){addr, (int)((x >> 3) % 3 == 0), cyc};
            }
            same_both_ways(&p, r, 3000);
        }
    }
}
