/* tests/unit/test_timing.c -- the timing model: the micro-benchmarks of kernels/bench/ against
 * their hand-derived cycle counts, the event queue, and the accounting identity (the scene cache:
 * test_cache.c).
 *
 * Each kernels/bench file carries `;@ run NAME [define S=V]... [set K=V]... expect KEY=V...`
 * lines (kernels/bench/README.md); every run is assembled with its defines, timed on the default
 * machine with its overrides, and every expected figure must match exactly. A stall cause the
 * line does not name must be 0. The expectations are written by hand in the files, with their
 * derivations; nothing here derives a figure by running the model.
 */
#include <criterion/criterion.h>
#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/asm.h"
#include "../../sim/config.h"
#include "../../sim/core.h"
#include "../../sim/event.h"
#include "../../sim/timing.h"
#include "../support/asm_fixture.h"
#include "../support/rng.h"

/* A timing figure by its expect key, or -1 for an unknown key. */
static long long figure(const TimingStats *s, const char *key)
{
    if (!strcmp(key, "cycles")) return (long long)s->cycles;
    if (!strcmp(key, "busy")) return (long long)s->busy;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        if (!strcmp(key, tm_cause_keys[c]))
            return (long long)s->stalls[c];
    if (!strcmp(key, "rb_conflicted")) return (long long)s->rb.conflicted;
    if (!strcmp(key, "agu_fetches")) return (long long)s->agu.fetches;
    if (!strcmp(key, "agu_ahead")) return (long long)s->agu.ahead;
    if (!strcmp(key, "partitions")) return (long long)s->part.runs;
    if (!strcmp(key, "scene_hits")) return (long long)s->l1.hits;
    if (!strcmp(key, "scene_misses")) return (long long)s->l1.misses;
    if (!strcmp(key, "icn_unit_delay")) return (long long)s->xbar.unit_delay;
    return -1;
}

/* Run one `;@ run` line of file; returns the number of failed checks (each reported). */
static int run_case(const char *file, int lineno, char *line)
{
    char *save = NULL, *tok = strtok_r(line, " \t\r\n", &save);
    const char *name = tok ? strtok_r(NULL, " \t\r\n", &save) : NULL;
    cr_assert(name, "%s:%d: `;@ run` without a name", file, lineno);
    AsmDefine defs[16];
    char *exp_key[32];
    long long exp_val[32];
    int ndefs = 0, nexp = 0, mode = 0, fails = 0;
    CfgMachine cfg;
    cfg_defaults(&cfg);
    CfgErrors errs = {0};
    while ((tok = strtok_r(NULL, " \t\r\n", &save))) {
        if (!strcmp(tok, "define") || !strcmp(tok, "set") || !strcmp(tok, "expect")) {
            mode = tok[0];
            continue;
        }
        char *eq = strchr(tok, '=');
        cr_assert(eq && mode, "%s:%d: bad token '%s'", file, lineno, tok);
        if (mode == 'd') {
            cr_assert(ndefs < 16);
            *eq = 0;
            defs[ndefs++] = (AsmDefine){tok, strtoll(eq + 1, NULL, 0)};
        } else if (mode == 's') {
            cr_assert(cfg_set(&cfg, tok, &errs) == 0, "%s:%d: %s", file, lineno, errs.text);
        } else {
            cr_assert(nexp < 32);
            *eq = 0;
            exp_key[nexp] = tok;
            exp_val[nexp++] = strtoll(eq + 1, NULL, 10);
        }
    }
    cr_assert(nexp > 0, "%s:%d: no expectations", file, lineno);

    AsmOptions opt = {defs, ndefs, NULL, 0, NULL, NULL, NULL};
    AsmObject obj;
    cr_assert(asm_assemble_file(file, &opt, &obj) == 0, "%s: %s does not assemble", file, name);
    CoreParams cp;
    cfg_core_params(&cfg, &cp);
    char err[512];
    Core *c = core_new(&cp, &obj, err, sizeof err);
    cr_assert(c, "%s %s: %s", file, name, err);
    TimingParams tp;
    timing_params(&cfg, &tp);
    Timing *t = timing_new(&tp, err, sizeof err);
    cr_assert(t, "%s", err);
    core_set_hook(c, timing_hook, t);
    CoreExit ex = core_run(c, 1000000);
    timing_end(t);
    cr_assert_eq(ex, CORE_EXIT_HALT, "%s %s: %s", file, name, core_trap_message(c));
    cr_assert_null(timing_error(t), "%s %s: %s", file, name, timing_error(t));
    const TimingStats *s = timing_stats(t);
    cr_expect(timing_check(s, err, sizeof err) == 0, "%s %s: %s", file, name, err);
    int named[TM_CAUSE_COUNT] = {0};
    for (int i = 0; i < nexp; i++) {
        long long got = figure(s, exp_key[i]);
        cr_assert(got >= 0, "%s:%d: unknown expect key '%s'", file, lineno, exp_key[i]);
        for (int k = 0; k < TM_CAUSE_COUNT; k++)
            if (!strcmp(exp_key[i], tm_cause_keys[k]))
                named[k] = 1;
        if (got != exp_val[i]) {
            cr_log_error("%s:%d %s: %s = %lld, derived %lld", file, lineno, name, exp_key[i], got, exp_val[i]);
            fails++;
        }
    }
    for (int k = 0; k < TM_CAUSE_COUNT; k++)
        if (!named[k] && s->stalls[k]) {
            cr_log_error("%s:%d %s: %s = %llu, derived 0", file, lineno, name, tm_cause_keys[k],
                         (unsigned long long)s->stalls[k]);
            fails++;
        }
    cfg_errors_free(&errs);
    timing_free(t);
    core_free(c);
    asm_object_free(&obj);
    return fails;
}

Test(timing, microbenchmarks_match_their_derivations)
{
    glob_t g;
    cr_assert_eq(glob("kernels/bench/*.s", 0, NULL, &g), 0, "no kernels/bench/*.s (run from the repo root)");
    int runs = 0, fails = 0;
    for (size_t i = 0; i < g.gl_pathc; i++) {
        FILE *f = fopen(g.gl_pathv[i], "r");
        cr_assert(f);
        char line[1024];
        int lineno = 0;
        while (fgets(line, sizeof line, f)) {
            lineno++;
            if (strncmp(line, ";@ run", 6))
                continue;
            fails += run_case(g.gl_pathv[i], lineno, line + 3);
            runs++;
        }
        fclose(f);
    }
    globfree(&g);
    cr_log_info("%d micro-benchmark runs, %d mismatches", runs, fails);
    cr_expect_geq(runs, 40, "only %d runs found", runs);
    cr_expect_eq(fails, 0, "%d figures differ from their derivations (see the log)", fails);
}

Test(timing, event_queue_orders_by_time_then_insertion)
{
    EvQueue q;
    evq_init(&q);
    uint64_t times[] = {50, 10, 30, 10, 70, 30, 10, 0};
    for (int i = 0; i < 8; i++)
        cr_assert_eq(evq_push(&q, times[i], 0, (uint16_t)i, 0, 0), 0);
    int order[8], n = 0;
    while (evq_top(&q)) {
        order[n++] = evq_top(&q)->arg;
        evq_pop(&q);
    }
    int want[8] = {7, 1, 3, 6, 2, 5, 0, 4};
    cr_assert_eq(n, 8);
    for (int i = 0; i < 8; i++)
        cr_expect_eq(order[i], want[i], "position %d: event %d, expected %d", i, order[i], want[i]);
    evq_free(&q);
}

Test(timing, every_cause_has_a_key_and_a_description)
{
    for (int c = 0; c < TM_CAUSE_COUNT; c++) {
        cr_expect(tm_cause_keys[c] && tm_cause_keys[c][0]);
        cr_expect(tm_cause_descs[c] && strlen(tm_cause_descs[c]) > 20);
    }
    cr_expect_eq(TM_CAUSE_COUNT, 10, "the ten causes of ARCHITECTURE.md Sec. 3");
}

/* A kernels/bench program and the one define it needs. */
typedef struct BenchProg {
    const char *file, *define;
    long long value;
} BenchProg;

/* prog's stats on a fresh model, or, with `after`, on a model that ran `after` first
 * (timing_reset between, as a worker does for each pass). */
/* A timing model of the default machine, and its core parameters in cp. */
static Timing *default_timing(CoreParams *cp)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg_core_params(&cfg, cp);
    TimingParams tp;
    timing_params(&cfg, &tp);
    char err[512];
    Timing *t = timing_new(&tp, err, sizeof err);
    cr_assert(t, "%s", err);
    return t;
}

/* p's file assembled with its define, or src (assembly text) when not NULL. */
static void assemble_prog(const BenchProg *p, const char *src, AsmObject *obj)
{
    AsmDefine def = {p->define, p->value};
    AsmOptions opt = {&def, p->define ? 1 : 0, NULL, 0, NULL, NULL, NULL};
    if (src)
        ta_assemble_ok(src, NULL, obj);
    else
        cr_assert(asm_assemble_file(p->file, &opt, obj) == 0, "%s does not assemble", p->file);
}

static TimingStats run_on(const BenchProg *prog, const BenchProg *after)
{
    CoreParams cp;
    Timing *t = default_timing(&cp);
    char err[512];
    TimingStats before = {0};
    for (int k = after ? 0 : 1; k < 2; k++) {
        const BenchProg *p = k == 0 ? after : prog;
        AsmObject obj;
        assemble_prog(p, NULL, &obj);
        Core *c = core_new(&cp, &obj, err, sizeof err);
        cr_assert(c, "%s: %s", p->file, err);
        timing_reset(t);
        before = *timing_stats(t);
        core_set_hook(c, timing_hook, t);
        cr_assert_eq(core_run(c, 1000000), CORE_EXIT_HALT, "%s: %s", p->file, core_trap_message(c));
        timing_end(t);
        cr_assert_null(timing_error(t), "%s: %s", p->file, timing_error(t));
        core_free(c);
        asm_object_free(&obj);
    }
    TimingStats s = *timing_stats(t);
    uint64_t *a = (uint64_t *)&s;
    const uint64_t *b = (const uint64_t *)&before;
    for (size_t i = 0; i < sizeof s / sizeof(uint64_t); i++)
        a[i] -= b[i];
    timing_free(t);
    return s;
}

Test(timing, a_model_reused_for_another_program_times_it_as_a_fresh_one)
{
    /* The timing core keeps each instruction's scoreboard registers by pc for the run; a new run
     * (timing_reset) on another program must not reuse them. */
    static const BenchProg progs[] = {{"kernels/bench/chains.s", "CLASS", 3},
                                      {"kernels/bench/gather_banks.s", "PATTERN", 1},
                                      {"kernels/bench/partition.s", "N8", 0},
                                      {"kernels/bench/branch.s", NULL, 0},
                                      {"kernels/bench/scene.s", "PATTERN", 0}};
    const int n = (int)(sizeof progs / sizeof progs[0]);
    for (int i = 0; i < n; i++) {
        const BenchProg *p = &progs[i], *prev = &progs[(i + 1) % n];
        TimingStats fresh = run_on(p, NULL), reused = run_on(p, prev);
        cr_expect_gt(fresh.cycles, 0u, "%s", p->file);
        cr_expect(memcmp(&fresh, &reused, sizeof fresh) == 0, "%s after %s: cycles %llu, fresh %llu", p->file,
                  prev->file, (unsigned long long)reused.cycles, (unsigned long long)fresh.cycles);
    }
}

/* How a run_memo run times blocks: the memo off; on, with every record going to the hook; on,
 * with the core counting a replayed block's records itself (timing_follow); that, with each
 * opcode's records going to its kind's hook (timing_op_hook: as sfsim runs it, timing_attach);
 * the kinds' hooks with the memo off. */
enum { MEMO_OFF, MEMO_HOOK, MEMO_FOLLOW, MEMO_KINDS, MEMO_KINDS_OFF };

static uint64_t hook_calls;   /* records the last run_memo run's hook was given */
static TimingMemoCounts memo_counts; /* and what its memo did */

static void counting_hook(void *ctx, const CoreRecord *rec)
{
    hook_calls++;
    timing_hook(ctx, rec);
}

static uint64_t gather_calls; /* of which rgat records (counting_op_hook) */
static uint64_t ldb_calls;    /* and ldb records */

static void counting_op_hook(void *ctx, const CoreRecord *rec)
{
    hook_calls++;
    gather_calls += rec->in->op == ISA_OP_RGAT;
    ldb_calls += rec->in->op == ISA_OP_LDB;
    timing_op_hook(rec->in->op)(ctx, rec);
}

/* prog (or src, assembly text, when not NULL) timed on a fresh model with the memo of blocks as
 * memo says, stopped by an instruction limit (0: run to its halt); the blocks it replayed. */
static TimingStats run_memo_src(const BenchProg *p, const char *src, int memo, uint64_t limit, uint64_t *replays)
{
    CoreParams cp;
    Timing *t = default_timing(&cp);
    char err[512];
    timing_set_memo(t, memo != MEMO_OFF && memo != MEMO_KINDS_OFF);
    AsmObject obj;
    assemble_prog(p, src, &obj);
    Core *c = core_new(&cp, &obj, err, sizeof err);
    cr_assert(c, "%s: %s", p->file, err);
    hook_calls = gather_calls = ldb_calls = 0;
    core_set_hook(c, memo >= MEMO_KINDS ? counting_op_hook : counting_hook, t);
    if (memo >= MEMO_FOLLOW) /* what timing_attach sets, with a counting hook */
        core_set_follow(c, timing_follow(t));
    CoreExit ex = core_run(c, limit ? limit : 1000000);
    cr_assert(ex == CORE_EXIT_HALT || (limit && ex == CORE_EXIT_LIMIT), "%s: %s", p->file, core_trap_message(c));
    timing_end(t);
    cr_assert_null(timing_error(t), "%s: %s", p->file, timing_error(t));
    TimingStats s = *timing_stats(t);
    memo_counts = timing_memo_counts(t);
    *replays = memo_counts.replays;
    timing_free(t);
    core_free(c);
    asm_object_free(&obj);
    return s;
}

/* src timed to its halt with the memo on and the core following, in slices of `slice`
 * instructions with the statistics read after each (a replayed block's counts reach the
 * statistics when they are read: MemoEntry.lz_n); the figures read after the first slice, and
 * at the end. */
static TimingStats run_memo_read_between(const char *src, uint64_t slice, TimingStats *first)
{
    CoreParams cp;
    Timing *t = default_timing(&cp);
    char err[512];
    BenchProg p = {"memo_loop.s", NULL, 0};
    AsmObject obj;
    assemble_prog(&p, src, &obj);
    Core *c = core_new(&cp, &obj, err, sizeof err);
    cr_assert(c, "%s", err);
    timing_attach(t, c);
    CoreExit ex;
    int n = 0;
    while ((ex = core_run_slice(c, slice, 1000000)) == CORE_EXIT_LIMIT && n < 100000)
        if (n++ == 0)
            *first = *timing_stats(t);
        else
            (void)timing_stats(t);
    cr_assert(ex == CORE_EXIT_HALT, "%s", core_trap_message(c));
    cr_assert_gt(n, 0, "the run is longer than one slice of %llu", (unsigned long long)slice);
    timing_end(t);
    cr_assert_null(timing_error(t), "%s", timing_error(t));
    TimingStats s = *timing_stats(t);
    timing_free(t);
    core_free(c);
    asm_object_free(&obj);
    return s;
}

static TimingStats run_memo(const BenchProg *p, int memo, uint64_t limit, uint64_t *replays)
{
    return run_memo_src(p, NULL, memo, limit, replays);
}

/* A loop that exercises what a memoized block meets: plain vector and scalar instructions with
 * dependency chains, a unit with an issue interval, scalar scratchpad accesses and a pmask
 * inside blocks (one a block's last record), a scene load and a ray-buffer gather between
 * blocks, stage and statistics-generation changes inside the loop, a taken branch. */
static const char memo_loop[] =
    "        li      r1, 150\n"
    "        li      r2, 4096\n"
    "        vli     v1, 0x3f800000\n"
    "        viota   v5\n"
    "loop:   stage   1\n"
    "        vfadd   v2, v1, v1\n"
    "        vfmul   v3, v2, v1\n"
    "        vrcp    v4, v3\n"
    "        vrcp    v6, v1\n"
    "        spld    r9, r0, 68\n"
    "        ld      r3, r2, 0\n"
    "        add     r4, r3, r1\n"
    "        spst    r4, r0, 64\n"
    "        vfadd   v1, v1, v3\n"
    "        spld    r7, r0, 64\n"
    "        add     r8, r7, r1\n"
    "        pmask   m1\n"
    "        stage   2\n"
    "        andi    r6, r1, 3\n"
    "        sgen    r6\n"
    "        rgat    v7, v5, r0, 0\n"
    "        vfmin   v8, v7, v4\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, loop\n"
    "        halt\n";

/* Loops whose blocks recur with another path: an sgen inside a block that keeps the generation
 * on the first passes (so the block stored spans it) and changes it every 32 passes after, and a
 * branch inside a block taken on some passes and not on others, so that a replay meets, at the
 * next pc, a record that runs in another generation or took a branch, and must leave the stored
 * path there (for another way of the same start state, or timing from the start). */
static const char memo_paths[] =
    "        li      r1, 200\n"
    "        vli     v1, 0x3f800000\n"
    "gens:   vfadd   v2, v1, v1\n"
    "        andi    r6, r1, 32\n"
    "        sgen    r6\n"
    "        vfmul   v3, v2, v1\n"
    "        vfadd   v1, v1, v3\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, gens\n"
    "        li      r1, 200\n"
    "loop:   vfadd   v2, v1, v1\n"
    "        andi    r6, r1, 2\n"
    "        sgen    r6\n"
    "        vfmul   v3, v2, v1\n"
    "        vfadd   v1, v1, v3\n"
    "        andi    r7, r1, 4\n"
    "        beq     r7, r0, skip\n"
    "        vfadd   v4, v3, v2\n"
    "        vfmul   v4, v4, v1\n"
    "skip:   vfmin   v5, v4, v3\n"
    "        vfadd   v6, v5, v1\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, loop\n"
    "        halt\n";

Test(timing, memoized_blocks_leave_a_stored_path_at_a_taken_branch_or_another_generation)
{
    BenchProg prog = {"memo_paths.s", NULL, 0};
    uint64_t r_on, r_off;
    TimingStats off = run_memo_src(&prog, memo_paths, MEMO_OFF, 0, &r_off);
    cr_expect_eq(hook_calls, off.busy, "without the memo every record goes to the hook");
    for (int memo = MEMO_HOOK; memo <= MEMO_KINDS; memo++) {
        TimingStats on = run_memo_src(&prog, memo_paths, memo, 0, &r_on);
        cr_expect(memcmp(&on, &off, sizeof on) == 0, "memo mode %d: cycles %llu with the memo, %llu without", memo,
                  (unsigned long long)on.cycles, (unsigned long long)off.cycles);
        cr_expect_gt(r_on, 100u, "the blocks recur: %llu replayed", (unsigned long long)r_on);
        cr_expect_gt(on.gen_busy[32], 0u, "the loop runs in generation 32 too");
        cr_expect_gt(on.gen_busy[2], 0u, "and in generation 2");
        /* each path taken from a start state is stored as a way of it the first time, and a
         * replay that meets the other path goes on with that way: only the records before
         * those first divergences are timed again, not some on every pass (about 600) */
        cr_expect_lt(memo_counts.retimed * 10, on.busy, "%llu records timed again of %llu",
                     (unsigned long long)memo_counts.retimed,
                     (unsigned long long)on.busy);
        if (memo >= MEMO_FOLLOW) /* the records inside replayed blocks were counted by the core */
            cr_expect_lt(hook_calls + r_on, off.busy, "the core following: %llu hook calls for %llu records",
                         (unsigned long long)hook_calls, (unsigned long long)off.busy);
        else
            cr_expect_eq(hook_calls, off.busy);
        for (uint64_t limit = 1; limit < on.busy; limit += limit < 200 ? 1 : 11) {
            TimingStats a = run_memo_src(&prog, memo_paths, memo, limit, &r_on),
                        b = run_memo_src(&prog, memo_paths, MEMO_OFF, limit, &r_off);
            cr_expect(memcmp(&a, &b, sizeof a) == 0,
                      "memo mode %d, stopped after %llu instructions: cycles %llu with the memo, %llu without", memo,
                      (unsigned long long)limit, (unsigned long long)a.cycles, (unsigned long long)b.cycles);
        }
    }
}

/* Blocks that start with a ray-buffer gather and take in later gathers of the same rays (the
 * box test's chunk loop): the rays' stride changes every pass, so the first gather's bank
 * cycles do (1 to 4 lines a bank); a branch inside the block is taken on some passes and not on
 * others (a replay leaves its path there, after gathers); the index register is rewritten before
 * a gather, inside a block and after a branch (which then may not join), another gathers with
 * another index (never joins), two
 * gathers have no lanes (an empty exec mask), and the generation changes between blocks. */
static const char memo_gathers[] =
    "        li      r1, 160\n"
    "        viota   v5\n"
    "        mclr    m2\n"
    "loop:   andi    r6, r1, 3\n"
    "        addi    r6, r6, 1\n"
    "        muli    r6, r6, 272\n"
    "        vbcast  v6, r6\n"
    "        vmul    v7, v5, v6\n"
    "        rgat    v1, v7, r0, 0\n"
    "        rgat    v2, v7, r0, 4096\n"
    "        rgat    v3, v7, r0, 8192\n"
    "        vfadd   v4, v1, v2\n"
    "        vfmul   v4, v4, v3\n"
    "        rgat    v8, v7, r0, 12288\n"
    "        vandi   v7, v7, 15\n"
    "        rgat    v15, v7, r0, 4096\n"
    "        andi    r7, r1, 8\n"
    "        beq     r7, r0, skip\n"
    "        vfadd   v4, v4, v1\n"
    "        rgat    v9, v7, r0, 64\n"
    "skip:   vaddi   v7, v7, 1\n"
    "        rgat    v9, v7, r0, 0\n"
    "        vfadd   v11, v9, v8\n"
    "        rgat    v10, v5, r0, 64\n"
    "        rgat    v12, v7, r0, 128\n"
    "        vfadd   v11, v11, v10\n"
    "        andi    r6, r1, 16\n"
    "        sgen    r6\n"
    "        rgat    v13, v7, r0, 0 @m2\n"
    "        rgat    v14, v7, r0, 4096 @m2\n"
    "        vfmin   v12, v11, v4\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, loop\n"
    "        halt\n";

/* src timed with the memo on in each mode that replays (every record to the hook, the core
 * following, the kinds' hooks) gives every counter of `off` (its run with the memo off), whole and
 * stopped at every point of its first 300 instructions and every 7th after; its blocks recur.
 * After each whole run, check(memo) asks the test's own questions of hook_calls and the others. */
static void expect_memo_modes_agree(const BenchProg *prog, const char *src, const TimingStats *off, void (*check)(int memo))
{
    uint64_t r_on, r_off;
    for (int memo = MEMO_HOOK; memo <= MEMO_KINDS; memo++) {
        TimingStats on = run_memo_src(prog, src, memo, 0, &r_on);
        cr_expect(memcmp(&on, off, sizeof on) == 0,
                  "%s, memo mode %d: cycles %llu with the memo, %llu without; ray-buffer accesses %llu, %llu, "
                  "lines %llu, %llu; transfers %llu, %llu; scene accesses %llu, %llu, hits %llu, %llu",
                  prog->file, memo, (unsigned long long)on.cycles, (unsigned long long)off->cycles,
                  (unsigned long long)on.rb.accesses, (unsigned long long)off->rb.accesses,
                  (unsigned long long)on.rb.lines, (unsigned long long)off->rb.lines,
                  (unsigned long long)on.xbar.transfers, (unsigned long long)off->xbar.transfers,
                  (unsigned long long)on.l1.accesses, (unsigned long long)off->l1.accesses,
                  (unsigned long long)on.l1.hits, (unsigned long long)off->l1.hits);
        cr_expect_gt(r_on, 100u, "%s: the blocks recur: %llu replayed", prog->file, (unsigned long long)r_on);
        check(memo);
        for (uint64_t limit = 1; limit < on.busy; limit += limit < 300 ? 1 : 7) {
            TimingStats a = run_memo_src(prog, src, memo, limit, &r_on),
                        b = run_memo_src(prog, src, MEMO_OFF, limit, &r_off);
            cr_expect(memcmp(&a, &b, sizeof a) == 0,
                      "%s, memo mode %d, stopped after %llu instructions: cycles %llu with the memo, %llu without",
                      prog->file, memo, (unsigned long long)limit, (unsigned long long)a.cycles,
                      (unsigned long long)b.cycles);
        }
    }
}

static uint64_t all_gathers; /* every rgat record of memo_gathers, the memo off */

static void gathers_check(int memo)
{
    if (memo == MEMO_KINDS) /* later gathers of replayed blocks were counted by the core: of the
                               ten or eleven a pass, the three that always join and the one with
                               no lanes, on nearly every pass */
        cr_expect_gt(all_gathers - gather_calls, 4u * 140u, "%llu of %llu gathers came to the hook",
                     (unsigned long long)gather_calls, (unsigned long long)all_gathers);
}

Test(timing, memoized_blocks_with_gathers_give_the_same_figures)
{
    BenchProg prog = {"memo_gathers.s", NULL, 0};
    uint64_t r_off;
    TimingStats off = run_memo_src(&prog, memo_gathers, MEMO_OFF, 0, &r_off);
    TimingStats koff = run_memo_src(&prog, memo_gathers, MEMO_KINDS_OFF, 0, &r_off);
    all_gathers = gather_calls;
    cr_expect(memcmp(&koff, &off, sizeof koff) == 0);
    cr_expect_gt(off.stalls[TM_BANK_CONFLICT], 0u, "the gathers meet bank conflicts");
    cr_expect_gt(off.rb.conflicted, 0u);
    expect_memo_modes_agree(&prog, memo_gathers, &off, gathers_check);
}

/* Blocks that start with a scene load and take in later loads of the same line (the box test's
 * loads of a node's bounds): the node is one of 32 lines, at the start of its line or 32 bytes
 * in, so the first load hits or misses and one load stays in the line or crosses into the next
 * (it may join only in the first case); a scalar ld of the same line (another opcode), a branch
 * inside the block taken on some passes and not on others (a replay leaves its path there, after
 * loads), the base register rewritten, a load with no lanes, a store, and a generation change. */
static const char memo_scene_loads[] =
    "        li      r1, 160\n"
    "        mclr    m2\n"
    "loop:   andi    r6, r1, 31\n"
    "        muli    r6, r6, 832\n"
    "        andi    r7, r1, 1\n"
    "        shli    r7, r7, 5\n"
    "        add     r2, r6, r7\n"
    "        ldb     v1, r2, 0\n"
    "        ldb     v2, r2, 4\n"
    "        ldb     v3, r2, 8\n"
    "        vfadd   v4, v1, v2\n"
    "        ldb     v5, r2, 12\n"
    "        ldb     v6, r2, 36\n"
    "        ld      r3, r2, 16\n"
    "        andi    r8, r1, 4\n"
    "        beq     r8, r0, skip\n"
    "        ldb     v7, r2, 20\n"
    "        vfmul   v4, v4, v3\n"
    "skip:   addi    r2, r2, 0\n"
    "        ldb     v8, r2, 24\n"
    "        ldb     v9, r2, 28 @m2\n"
    "        ldb     v12, r2, 12\n"
    "        st      r3, r2, 40\n"
    "        ldb     v10, r2, 44\n"
    "        andi    r9, r1, 16\n"
    "        sgen    r9\n"
    "        vfmin   v11, v10, v4\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, loop\n"
    "        halt\n";

static uint64_t all_ldb; /* every ldb record of memo_scene_loads, the memo off */

static void scene_loads_check(int memo)
{
    if (memo == MEMO_KINDS) /* later loads of replayed blocks were counted by the core: of the nine
                               or ten a pass, the three after the first that always join, on most
                               passes */
        cr_expect_gt(all_ldb - ldb_calls, 3u * 100u, "%llu of %llu ldb came to the hook",
                     (unsigned long long)ldb_calls, (unsigned long long)all_ldb);
}

Test(timing, memoized_blocks_with_scene_loads_give_the_same_figures)
{
    BenchProg prog = {"memo_scene_loads.s", NULL, 0};
    uint64_t r_off;
    TimingStats off = run_memo_src(&prog, memo_scene_loads, MEMO_KINDS_OFF, 0, &r_off);
    all_ldb = ldb_calls;
    cr_expect_gt(off.l1.misses, 20u, "the nodes' first loads miss at first");
    cr_expect_gt(off.l1.hits, 1000u);
    expect_memo_modes_agree(&prog, memo_scene_loads, &off, scene_loads_check);
}

/* A loop whose blocks start in more states than a start keeps ways: a scene load that misses
 * (a new line each pass) and a delay loop of 0 to 15 passes after it, so the blocks of the delay
 * loop and after it start with the load's result landing at many distances ahead. Ways replayed
 * are replaced by others while their replays' counts are still to be added (MemoEntry.lz_n). */
static const char memo_churn[] =
    "        li      r1, 300\n"
    "        li      r2, 0\n"
    "        vli     v1, 0x3f800000\n"
    "loop:   ld      r3, r2, 0\n"
    "        addi    r2, r2, 64\n"
    "        andi    r7, r1, 30\n"
    "        beq     r7, r0, join\n"
    "delay:  addi    r7, r7, -2\n"
    "        vfadd   v2, v1, v1\n"
    "        bne     r7, r0, delay\n"
    "join:   add     r4, r3, r1\n"
    "        vfadd   v2, v1, v1\n"
    "        vfmul   v3, v2, v1\n"
    "        add     r5, r4, r1\n"
    "        addi    r1, r1, -1\n"
    "        bne     r1, r0, loop\n"
    "        halt\n";

Test(timing, memoized_blocks_replaced_while_their_replays_are_uncounted_give_the_same_figures)
{
    BenchProg prog = {"memo_churn.s", NULL, 0};
    uint64_t r_on, r_off;
    TimingStats off = run_memo_src(&prog, memo_churn, MEMO_OFF, 0, &r_off);
    TimingStats on = run_memo_src(&prog, memo_churn, MEMO_KINDS, 0, &r_on);
    cr_expect(memcmp(&on, &off, sizeof on) == 0, "cycles %llu with the memo, %llu without",
              (unsigned long long)on.cycles, (unsigned long long)off.cycles);
    /* a handful of block starts, many more ways stored than they keep (MEMO_WAYS each), many replayed */
    cr_expect_gt(memo_counts.stores, 100u, "%llu ways stored", (unsigned long long)memo_counts.stores);
    cr_expect_gt(r_on, 200u, "%llu replays", (unsigned long long)r_on);
    cr_expect_gt(on.stalls[TM_SCENE_MEMORY], 0u, "the load misses");
}

Test(timing, memoized_blocks_give_the_same_figures_as_timing_each_instruction)
{
    /* Every counter with the memo on equals the one with it off: for whole runs, and for runs
     * stopped by an instruction limit at every point of their first few hundred instructions
     * and then at intervals, so that runs end inside recorded and inside replayed blocks
     * (timing_end times a replayed block's records that came before the stop). */
    static const BenchProg progs[] = {{"kernels/bench/chains.s", "CLASS", 3}, {"kernels/bench/chains.s", "CLASS", 0},
                                      {"kernels/bench/branch.s", NULL, 0},   {"kernels/bench/contention.s", "PATTERN", 1},
                                      {"kernels/bench/partition.s", "N8", 0}, {"kernels/bench/scene.s", "PATTERN", 0},
                                      {"kernels/bench/gather_banks.s", "PATTERN", 1}, {"kernels/bench/spad.s", "OFF", 32}};
    uint64_t replayed_any = 0;
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++) {
        const BenchProg *p = &progs[i];
        uint64_t r_on, r_off;
        TimingStats on = run_memo(p, MEMO_FOLLOW, 0, &r_on), off = run_memo(p, MEMO_OFF, 0, &r_off);
        cr_assert_eq(r_off, 0u, "%s: the memo replayed blocks while off", p->file);
        cr_expect(memcmp(&on, &off, sizeof on) == 0, "%s %s=%lld: cycles %llu with the memo, %llu without", p->file,
                  p->define ? p->define : "", p->value, (unsigned long long)on.cycles, (unsigned long long)off.cycles);
        for (int memo = MEMO_KINDS; memo <= MEMO_KINDS_OFF; memo++) { /* the hooks by kind, memo on and off */
            TimingStats k = run_memo(p, memo, 0, &r_on);
            cr_expect(memcmp(&k, &off, sizeof k) == 0, "%s %s=%lld, memo mode %d: cycles %llu, %llu with timing_hook",
                      p->file, p->define ? p->define : "", p->value, memo, (unsigned long long)k.cycles,
                      (unsigned long long)off.cycles);
        }
        replayed_any += r_on;
        const uint64_t n = on.busy; /* one issue cycle per instruction */
        for (uint64_t limit = 1; limit < n; limit += limit < 300 ? 1 : 97) {
            TimingStats a = run_memo(p, limit % 2 ? MEMO_KINDS : MEMO_FOLLOW, limit, &r_on),
                        b = run_memo(p, MEMO_OFF, limit, &r_off);
            cr_expect(memcmp(&a, &b, sizeof a) == 0, "%s stopped after %llu instructions: cycles %llu with the memo, %llu without",
                      p->file, (unsigned long long)limit, (unsigned long long)a.cycles, (unsigned long long)b.cycles);
        }
    }
    (void)replayed_any; /* the micro-benchmarks are straight lines: they check recording */
    BenchProg loop = {"memo_loop.s", NULL, 0};
    uint64_t r_on, r_off;
    TimingStats off = run_memo_src(&loop, memo_loop, MEMO_OFF, 0, &r_off);
    TimingStats kinds_off = run_memo_src(&loop, memo_loop, MEMO_KINDS_OFF, 0, &r_on);
    cr_expect(memcmp(&kinds_off, &off, sizeof off) == 0, "the loop, the hooks by kind without the memo: cycles %llu, %llu",
              (unsigned long long)kinds_off.cycles, (unsigned long long)off.cycles);
    for (int memo = MEMO_HOOK; memo <= MEMO_KINDS; memo++) {
        TimingStats on = run_memo_src(&loop, memo_loop, memo, 0, &r_on);
        cr_expect(memcmp(&on, &off, sizeof on) == 0, "the loop, memo mode %d: cycles %llu with the memo, %llu without",
                  memo, (unsigned long long)on.cycles, (unsigned long long)off.cycles);
        /* four blocks a pass (to the scene load, to the stage change, to the gather, to the
         * branch) over 150 passes, each replayed whole once its start state has been seen */
        cr_expect_gt(r_on, 4 * 140u, "the loop's blocks recur: %llu replayed", (unsigned long long)r_on);
        /* and their paths do not change from pass to pass: a replay leaves its path only in the
         * first passes, not at the scratchpad accesses inside the blocks (their records name
         * the memory they touched; the stored path names instructions) on every pass */
        cr_expect_lt(memo_counts.left * 10, 150u, "%llu replays left their path", (unsigned long long)memo_counts.left);
        cr_expect_gt(on.stalls[TM_FU_BUSY] + on.stalls[TM_DATA_DEPENDENCY], 0u, "the loop stalls");
        /* its scalar scratchpad accesses are plain instructions inside its blocks, counted when
         * a block is replayed too */
        cr_expect_eq(on.spad.accesses, 3 * 150u, "scratchpad accesses %llu", (unsigned long long)on.spad.accesses);
        /* the statistics read between slices of the run (a replayed block's counts reach them
         * when they are read: MemoEntry.lz_n): the same at the end; after the first slice, those
         * of a run stopped there but for the records of a block still being replayed (at most
         * 16, counted when it ends), not behind by the blocks replayed so far */
        if (memo == MEMO_FOLLOW)
            for (uint64_t slice = 37; slice < 2000; slice = slice * 3 + 1) {
                TimingStats first = {0}, read = run_memo_read_between(memo_loop, slice, &first);
                cr_expect(memcmp(&read, &off, sizeof read) == 0, "read every %llu instructions: cycles %llu, %llu without the memo",
                          (unsigned long long)slice, (unsigned long long)read.cycles, (unsigned long long)off.cycles);
                TimingStats stop = run_memo_src(&loop, memo_loop, MEMO_OFF, slice, &r_off);
                cr_expect(first.busy <= stop.busy && stop.busy - first.busy < 16,
                          "after %llu instructions: %llu issue cycles read, %llu in a run stopped there",
                          (unsigned long long)slice, (unsigned long long)first.busy, (unsigned long long)stop.busy);
                cr_expect(first.simd.uses[ISA_U_VADD] <= stop.simd.uses[ISA_U_VADD] &&
                          stop.simd.uses[ISA_U_VADD] - first.simd.uses[ISA_U_VADD] < 16);
            }
        for (uint64_t limit = 1; limit < on.busy; limit += limit < 400 ? 1 : 13) {
            TimingStats a = run_memo_src(&loop, memo_loop, memo, limit, &r_on),
                        b = run_memo_src(&loop, memo_loop, MEMO_OFF, limit, &r_off);
            cr_expect(memcmp(&a, &b, sizeof a) == 0,
                      "the loop, memo mode %d, stopped after %llu instructions: cycles %llu with the memo, %llu without",
                      memo, (unsigned long long)limit, (unsigned long long)a.cycles, (unsigned long long)b.cycles);
        }
    }
}

Test(timing, memory_kinds_are_neither_branches_nor_halts)
{
    /* sim/timing.c times ray-buffer vector accesses, scratchpad and scene-memory or framebuffer
     * instructions on paths without the tests for a taken branch or the program's end
     * (TM_NO_FLOW): an opcode of those units that branched or halted would be timed wrong. */
    int seen = 0;
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaOpInfo *oi = &isa_ops[op];
        const int memory_kind = (oi->unit == ISA_U_RBUF && (oi->flags & ISA_FL_VEC)) || oi->unit == ISA_U_SPAD ||
                                oi->unit == ISA_U_SCENE || oi->unit == ISA_U_FB;
        if (!memory_kind)
            continue;
        seen++;
        cr_expect_eq(oi->flags & (ISA_FL_BRANCH | ISA_FL_END), 0u, "%s: a memory kind's opcode branches or halts",
                     oi->mnemonic);
    }
    cr_expect_gt(seen, 6, "the ISA table's memory opcodes: %d", seen);
}

/* Random loops (a seeded generator): a scene load each pass whose stride makes it hit or miss,
 * then branches on the pass count around runs of plain instructions of several latencies, some
 * reading the load's result. Their blocks start with results landing at many distances, some
 * before the instruction that first reads them (a way's slack live-ins) and some after, and end at
 * branches that go either way from the same start (a replay whose last branch flips). Every
 * counter with the memo on, in each of its modes, equals the one with it off. */
static uint32_t gen_next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static void gen_loop(char *out, size_t cap, uint32_t seed)
{
    static const char *const sops[] = {"add", "sub", "mul"}, *const vops[] = {"vfadd", "vfmul", "vfdiv"};
    static const char *const ssrc[] = {"r1", "r3", "r4", "r5", "r6"}, *const sdst[] = {"r4", "r5", "r6"};
    static const int strides[] = {0, 8, 64, 128};
    uint32_t s = seed;
    size_t n = 0;
#define EMIT(...) (n += (size_t)snprintf(out + n, cap - n, __VA_ARGS__))
    EMIT("        li      r1, 120\n        li      r2, 0\n        li      r4, 1\n        li      r5, 2\n"
         "        li      r6, 3\n        vli     v1, 0x3f800000\n        vli     v2, 0x40000000\n"
         "        vli     v3, 0x3f000000\n        vli     v4, 0x3fc00000\n");
    EMIT("loop:   ld      r3, r2, 0\n        addi    r2, r2, %d\n", strides[gen_next(&s) % 4]);
    const int nbr = 1 + (int)(gen_next(&s) % 4);
    for (int b = 0; b < nbr; b++) {
        EMIT("        andi    r7, r1, %u\n", 1u + gen_next(&s) % 7);
        EMIT("        %s     r7, r0, j%d\n", gen_next(&s) % 2 ? "beq" : "bne", b);
        if (gen_next(&s) % 2) /* a load after it: the block ends at the branch taken or not */
            EMIT("        ld      r%u, r2, 4\n", 4 + gen_next(&s) % 3);
        for (int part = 0; part < 2; part++) {
            if (part)
                EMIT("j%d:\n", b);
            const int k = (int)(gen_next(&s) % 8);
            for (int i = 0; i < k; i++) {
                if (gen_next(&s) % 2)
                    EMIT("        %s     %s, %s, %s\n", sops[gen_next(&s) % 3], sdst[gen_next(&s) % 3],
                         ssrc[gen_next(&s) % 5], ssrc[gen_next(&s) % 5]);
                else
                    EMIT("        %s   v%u, v%u, v%u\n", vops[gen_next(&s) % 3], 3 + gen_next(&s) % 4,
                         1 + gen_next(&s) % 6, 1 + gen_next(&s) % 6);
            }
        }
    }
    EMIT("        addi    r1, r1, -1\n        bne     r1, r0, loop\n        halt\n");
#undef EMIT
    cr_assert_lt(n, cap, "the generated loop fits");
}

Test(timing, memoized_blocks_of_random_loops_give_the_same_figures)
{
    uint64_t replays = 0, flipped = 0;
    for (uint32_t seed = 1; seed <= 100; seed++) {
        char src[8192];
        gen_loop(src, sizeof src, seed);
        BenchProg prog = {"random_loop.s", NULL, 0};
        uint64_t r_on, r_off;
        TimingStats off = run_memo_src(&prog, src, MEMO_OFF, 0, &r_off);
        for (int memo = MEMO_HOOK; memo <= MEMO_KINDS; memo++) {
            TimingStats on = run_memo_src(&prog, src, memo, 0, &r_on);
            cr_expect(memcmp(&on, &off, sizeof on) == 0, "seed %u, memo mode %d: cycles %llu with the memo, %llu without\n%s",
                      seed, memo, (unsigned long long)on.cycles, (unsigned long long)off.cycles, src);
            replays += r_on;
            flipped += memo_counts.flipped;
        }
    }
    /* the loops exercise what they are for: replays, and replays whose last branch flipped */
    cr_expect_gt(replays, 10000u, "%llu replays", (unsigned long long)replays);
    cr_expect_gt(flipped, 100u, "%llu replays with their last branch flipped", (unsigned long long)flipped);
}
