/* tests/unit/test_isa_programs.c -- runs the per-instruction programs tests/isa/<mnemonic>.s on the
 * functional core at several vector widths and checks the expectations written in them.
 *
 * Each program is a small real program that exercises its instruction (masks, tails, edge values)
 * and ends in `halt`. Its expected results are written by hand from the DESC column of
 * isa/opcodes.def, as comment lines starting with ";!" (anywhere in the file; the assembler sees
 * comments). The harness never derives an expected value by running the core.
 *
 * Every file is assembled once (asm_assemble_file) and run for N = 1, 4, 12, 16, 64 with
 * memories RB0/RB1 512 KiB, IDM 32 KiB, SP 64 KiB, SM 1 MiB, FB 64 KiB, and a limit of 1,000,000
 * instructions. A failure names file, line, N and lane:
 *     tests/isa/vfadd.s:12 N=4 lane 3: v2 = 0x40000000 (2) expected 0x3fc00000 (1.5)
 *
 * The expectation syntax is tests/support/isa_expect.h's.
 */
#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <ctype.h>
#include <glob.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../../asm/asm.h"
#include "../../isa/isa.h"
#include "../../sim/core.h"
#include "../support/isa_expect.h"

#define ISA_PROG_DIR "tests/isa"

static const int widths[] = {1, 4, 12, 16, 64};
#define N_WIDTHS (int)(sizeof widths / sizeof widths[0])

/* ---- running ------------------------------------------------------------------------------ */

static void test_params(CoreParams *p, int lanes)
{
    memset(p, 0, sizeof *p);
    p->lanes = lanes;
    p->mem_bytes[CORE_MEM_RB0] = 512 * 1024;
    p->mem_bytes[CORE_MEM_RB1] = 512 * 1024;
    p->mem_bytes[CORE_MEM_IDM] = 32 * 1024;
    p->mem_bytes[CORE_MEM_SPAD] = 64 * 1024;
    p->mem_bytes[CORE_MEM_SCENE] = 1024 * 1024;
    p->mem_bytes[CORE_MEM_FB] = 64 * 1024;
}

typedef struct Run {
    const char *path;
    int lanes;
    Core *core;
    const AsmObject *obj;
    int failures;
} Run;

#define MAX_REPORTS 40

static void report(Run *run, const Check *ck, int lane, const char *fmt, ...)
{
    run->failures++;
    if (run->failures > MAX_REPORTS)
        return;
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (lane >= 0)
        cr_expect_fail("%s:%d N=%d lane %d: %s", run->path, ck->line, run->lanes, lane, msg);
    else
        cr_expect_fail("%s:%d N=%d: %s", run->path, ck->line, run->lanes, msg);
}

static int stage_from_key(const char *k, size_t n)
{
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        if (strlen(isa_stage_keys[s]) == n && !strncmp(k, isa_stage_keys[s], n))
            return s;
    return -1;
}

static int stat_value(Core *c, const char *key, uint64_t *out)
{
    const CoreStats *st = core_stats(c);
    if (!strcmp(key, "total")) {
        *out = core_instructions(c);
        return 0;
    }
    int gen = -1;
    if (!strncmp(key, "gen", 3) && key[3] >= '0' && key[3] <= '9') {
        char *end;
        long g = strtol(key + 3, &end, 10);
        if (*end != '.' || g < 0 || g >= CORE_GENERATIONS)
            return -1;
        gen = (int)g;
        key = end + 1;
    }
    const char *dot = strchr(key, '.');
    if (!dot)
        return -1;
    size_t head = (size_t)(dot - key);
    if (gen >= 0) {
        int gs = stage_from_key(dot + 1, strlen(dot + 1));
        if (gs < 0)
            return -1;
        if (head == 5 && !strncmp(key, "instr", 5))
            *out = st->gen_instructions[gen][gs];
        else if (head == 3 && !strncmp(key, "vec", 3))
            *out = st->gen_vec_instructions[gen][gs];
        else if (head == 5 && !strncmp(key, "lanes", 5))
            *out = st->gen_active_lanes[gen][gs];
        else
            return -1;
        return 0;
    }
    const char *rest = dot + 1;
    if (head == 2 && !strncmp(key, "op", 2)) {
        int op = isa_op_from_mnemonic(rest);
        if (op < 0)
            return -1;
        *out = st->by_op[op];
        return 0;
    }
    if (head == 3 && !strncmp(key, "cat", 3)) {
        const char *dot2 = strchr(rest, '.');
        if (!dot2)
            return -1;
        int s = stage_from_key(rest, (size_t)(dot2 - rest));
        for (int cat = 0; s >= 0 && cat < ISA_C_COUNT; cat++)
            if (!strcmp(dot2 + 1, isa_category_keys[cat])) {
                *out = st->ops[s][cat];
                return 0;
            }
        return -1;
    }
    int s = stage_from_key(rest, strlen(rest));
    if (s < 0)
        return -1;
    if (head == 5 && !strncmp(key, "instr", 5))
        *out = st->instructions[s];
    else if (head == 3 && !strncmp(key, "vec", 3))
        *out = st->vec_instructions[s];
    else if (head == 5 && !strncmp(key, "lanes", 5))
        *out = st->active_lanes[s];
    else
        return -1;
    return 0;
}

static int truthy(Val v) { return v.isf ? v.f != 0 : v.i != 0; }

static void fmt_word(char *buf, size_t len, uint32_t w, int as_float)
{
    if (as_float)
        snprintf(buf, len, "0x%08" PRIx32 " (%.9g)", w, (double)ie_bits_f32(w));
    else
        snprintf(buf, len, "0x%08" PRIx32 " (%" PRId32 ")", w, (int32_t)w);
}

/* Compare a 32-bit value; 0 when it matches. */
static int compare_word(Run *run, const Check *ck, int lane, Env *env, const char *what, uint32_t actual)
{
    Val ex = ie_eval(ck->expect, env);
    Val tol = ck->tol ? ie_eval(ck->tol, env) : ie_vi(0);
    if (env->err[0]) {
        report(run, ck, lane, "%s", env->err);
        return -1;
    }
    char got[64], want[64];
    switch (ck->op) {
    case OP_EQ:
    case OP_NE: {
        if (ex.isf) {
            report(run, ck, lane, "== needs an integer expectation (use ==f for floats)");
            return -1;
        }
        uint32_t w = (uint32_t)ex.i;
        int eq = actual == w;
        if (eq == (ck->op == OP_EQ))
            return 0;
        fmt_word(got, sizeof got, actual, 0);
        fmt_word(want, sizeof want, w, 0);
        report(run, ck, lane, "%s = %s expected %s%s", what, got, ck->op == OP_NE ? "not " : "", want);
        return -1;
    }
    case OP_FEQ: {
        uint32_t w = ie_f32_bits(ie_as_f(ex));
        float a = ie_bits_f32(actual);
        if (actual == w || (isnan(a) && isnan(ie_as_f(ex))))
            return 0;
        fmt_word(got, sizeof got, actual, 1);
        fmt_word(want, sizeof want, w, 1);
        report(run, ck, lane, "%s = %s expected %s", what, got, want);
        return -1;
    }
    case OP_APPROX: {
        double a = ie_bits_f32(actual), e = ie_as_f(ex), t = ie_as_f(tol);
        if ((isnan(a) && isnan(e)) || a == e || fabs(a - e) <= t)
            return 0;
        fmt_word(got, sizeof got, actual, 1);
        report(run, ck, lane, "%s = %s expected %.9g within %g", what, got, e, t);
        return -1;
    }
    }
    return -1;
}

static int compare_u64(Run *run, const Check *ck, int lane, Env *env, const char *what, uint64_t actual)
{
    Val ex = ie_eval(ck->expect, env);
    if (env->err[0]) {
        report(run, ck, lane, "%s", env->err);
        return -1;
    }
    if (ex.isf) {
        report(run, ck, lane, "%s needs an integer expectation", what);
        return -1;
    }
    int eq = actual == (uint64_t)ex.i;
    if (eq == (ck->op == OP_EQ))
        return 0;
    report(run, ck, lane, "%s = 0x%" PRIx64 " (%" PRIu64 ") expected %s0x%" PRIx64 " (%" PRId64 ")", what, actual,
           actual, ck->op == OP_NE ? "not " : "", (uint64_t)ex.i, ex.i);
    return -1;
}

static void check_one(Run *run, const Check *ck, int lane)
{
    Env env = {run->lanes, lane, run->obj, ""};
    if (ck->guard) {
        Val g = ie_eval(ck->guard, &env);
        if (env.err[0]) {
            report(run, ck, lane, "%s", env.err);
            return;
        }
        if (!truthy(g))
            return;
    }
    int64_t idx = 0;
    if (ck->index) {
        Val iv = ie_eval(ck->index, &env);
        if (env.err[0] || iv.isf) {
            report(run, ck, lane, "%s", env.err[0] ? env.err : "index is not an integer");
            return;
        }
        idx = iv.i;
    }
    char what[96];
    Core *c = run->core;
    switch (ck->kind) {
    case X_SREG:
        snprintf(what, sizeof what, "r%d", ck->reg);
        compare_word(run, ck, lane, &env, what, core_sreg(c, ck->reg));
        return;
    case X_VREG:
        if (idx < 0 || idx >= run->lanes) {
            report(run, ck, lane, "lane index %" PRId64 " outside 0..%d (add a guard)", idx, run->lanes - 1);
            return;
        }
        if (lane >= 0 && idx != lane)
            snprintf(what, sizeof what, "v%d[%" PRId64 "]", ck->reg, idx);
        else
            snprintf(what, sizeof what, "v%d", ck->reg);
        compare_word(run, ck, lane < 0 ? (int)idx : lane, &env, what, core_vreg(c, ck->reg, (int)idx));
        return;
    case X_MBIT:
        if (idx < 0 || idx >= run->lanes) {
            report(run, ck, lane, "lane index %" PRId64 " outside 0..%d (add a guard)", idx, run->lanes - 1);
            return;
        }
        snprintf(what, sizeof what, "m%d bit", ck->reg);
        compare_u64(run, ck, lane < 0 ? (int)idx : lane, &env, what, (core_mreg(c, ck->reg) >> idx) & 1u);
        return;
    case X_MASK:
        snprintf(what, sizeof what, "m%d", ck->reg);
        compare_u64(run, ck, lane, &env, what, core_mreg(c, ck->reg));
        return;
    case X_PC:
        compare_u64(run, ck, lane, &env, "pc", core_pc(c));
        return;
    case X_STAT: {
        uint64_t v;
        if (stat_value(c, ck->key, &v) != 0) {
            report(run, ck, lane, "unknown stat key %s", ck->key);
            return;
        }
        snprintf(what, sizeof what, "stat %s", ck->key);
        compare_u64(run, ck, lane, &env, what, v);
        return;
    }
    case X_MEM: {
        int m = ck->reg;
        if (m == -1)
            m = core_current_rb(c) ? CORE_MEM_RB1 : CORE_MEM_RB0;
        else if (m == -2)
            m = core_current_rb(c) ? CORE_MEM_RB0 : CORE_MEM_RB1;
        uint32_t bytes;
        uint8_t *mem = core_mem(c, (CoreMem)m, &bytes);
        if (idx < 0 || idx % 4 != 0 || (uint64_t)idx + 4 > bytes || !mem) {
            report(run, ck, lane, "address %" PRId64 " is not a word of %s (%u bytes)", idx, core_mem_names[m], bytes);
            return;
        }
        uint32_t w = (uint32_t)mem[idx] | (uint32_t)mem[idx + 1] << 8 | (uint32_t)mem[idx + 2] << 16 |
                     (uint32_t)mem[idx + 3] << 24;
        snprintf(what, sizeof what, "%s[%" PRId64 "]", core_mem_names[m], idx);
        compare_word(run, ck, lane, &env, what, w);
        return;
    }
    case X_TRAP:
    case X_LIMIT:
    case X_MAX: return;
    }
}

/* Guards of trap/limit checks use N only. */
static int applies(Run *run, const Check *ck)
{
    if (!ck->guard)
        return 1;
    Env env = {run->lanes, -1, run->obj, ""};
    Val g = ie_eval(ck->guard, &env);
    if (env.err[0]) {
        report(run, ck, -1, "%s", env.err);
        return 0;
    }
    return truthy(g);
}

static void run_width(const char *path, const AsmObject *obj, const Spec *spec, int lanes, int file_op)
{
    CoreParams prm;
    test_params(&prm, lanes);
    char err[512];
    Run run = {path, lanes, NULL, obj, 0};
    run.core = core_new(&prm, obj, err, sizeof err);
    if (!run.core) {
        cr_expect_fail("%s N=%d: core_new failed: %s", path, lanes, err);
        return;
    }
    CoreExit ex = core_run(run.core, spec->limit);
    const char *msg = ex == CORE_EXIT_HALT ? "" : core_trap_message(run.core);
    if (!msg)
        msg = "";

    const Check *trap = NULL, *limit = NULL;
    for (int i = 0; i < spec->n; i++) {
        const Check *ck = &spec->checks[i];
        if (ck->kind == X_TRAP && applies(&run, ck) && !trap)
            trap = ck;
        if (ck->kind == X_LIMIT && applies(&run, ck) && !limit)
            limit = ck;
    }
    static const char *const exits[] = {"halt", "trap", "instruction limit"};
    if (trap) {
        if (ex != CORE_EXIT_TRAP)
            report(&run, trap, -1, "expected a trap, the run ended in %s %s", exits[ex], msg);
        for (int i = 0; ex == CORE_EXIT_TRAP && i < spec->n; i++) {
            const Check *ck = &spec->checks[i];
            if (ck->kind != X_TRAP || !applies(&run, ck))
                continue;
            for (int k = 0; k < ck->nsub; k++)
                if (!strstr(msg, ck->subs[k]))
                    report(&run, ck, -1, "trap message \"%s\" does not contain \"%s\"", msg, ck->subs[k]);
        }
    } else if (limit) {
        if (ex != CORE_EXIT_LIMIT)
            report(&run, limit, -1, "expected the instruction limit, the run ended in %s %s", exits[ex], msg);
    } else if (ex != CORE_EXIT_HALT) {
        run.failures++;
        cr_expect_fail("%s N=%d: the program did not halt: %s %s", path, lanes, exits[ex], msg);
    }

    for (int i = 0; i < spec->n; i++) {
        const Check *ck = &spec->checks[i];
        if (ck->kind == X_TRAP || ck->kind == X_LIMIT || ck->kind == X_MAX)
            continue;
        if (ck->per_lane)
            for (int l = 0; l < lanes; l++)
                check_one(&run, ck, l);
        else
            check_one(&run, ck, -1);
    }

    if (file_op >= 0 && core_stats(run.core)->by_op[file_op] == 0) {
        run.failures++;
        cr_expect_fail("%s N=%d: the program never executes %s", path, lanes, isa_ops[file_op].mnemonic);
    }
    if (run.failures > MAX_REPORTS)
        cr_expect_fail("%s N=%d: %d more failures not shown", path, lanes, run.failures - MAX_REPORTS);
    core_free(run.core);
}

/* The mnemonic a program is named after, or -1. */
static int op_of_path(const char *path)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    char name[64];
    snprintf(name, sizeof name, "%s", base);
    char *dot = strrchr(name, '.');
    if (dot)
        *dot = '\0';
    return isa_op_from_mnemonic(name);
}

static void run_program(const char *path, int schedule)
{
    Spec spec;
    int bad = ie_spec_load(path, &spec);
    if (bad) {
        ie_spec_free(&spec);
        return;
    }
    /* A trapping program may stop at another instruction when scheduled (docs/assembler.md,
     * "Traps"): those programs are checked as written only. */
    for (int i = 0; schedule && i < spec.n; i++)
        if (spec.checks[i].kind == X_TRAP) {
            ie_spec_free(&spec);
            return;
        }
    int has_checks = 0;
    for (int i = 0; i < spec.n; i++) {
        if (spec.checks[i].kind == X_MAX) {
            Env env = {1, -1, NULL, ""};
            Val v = ie_eval(spec.checks[i].expect, &env);
            spec.limit = (uint64_t)(v.isf ? v.f : (double)v.i);
        } else {
            has_checks = 1;
        }
    }
    cr_expect(has_checks, "%s: no expectations (;! lines)", path);

    char *diag_buf = NULL;
    size_t diag_len = 0;
    FILE *diag = open_memstream(&diag_buf, &diag_len);
    AsmSchedModel model;
    sched_model_default(&model);
    AsmOptions opt = {.diag = diag, .schedule = schedule ? &model : NULL};
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    int errors = asm_assemble_file(path, &opt, &obj);
    fclose(diag);
    if (errors) {
        cr_expect_fail("%s: %d assembly errors:\n%s", path, errors, diag_buf ? diag_buf : "");
    } else {
        int op = op_of_path(path);
        for (int w = 0; w < N_WIDTHS; w++)
            run_width(path, &obj, &spec, widths[w], op);
        asm_object_free(&obj);
    }
    free(diag_buf);
    ie_spec_free(&spec);
}

/* ---- tests -------------------------------------------------------------------------------- */

typedef struct ProgParam {
    char path[256];
} ProgParam;

static struct criterion_test_params isa_programs_run_params(void)
{
    glob_t g;
    size_t n = 0;
    ProgParam *params = NULL;
    if (glob(ISA_PROG_DIR "/*.s", 0, NULL, &g) == 0) {
        n = g.gl_pathc;
        params = cr_malloc(n * sizeof *params);
        for (size_t i = 0; i < n; i++)
            snprintf(params[i].path, sizeof params[i].path, "%s", g.gl_pathv[i]);
        globfree(&g);
    }
    return cr_make_param_array(ProgParam, params, n);
}

ParameterizedTestParameters(isa_programs, run)
{
    return isa_programs_run_params();
}

ParameterizedTest(ProgParam *p, isa_programs, run)
{
    run_program(p->path, 0);
}

/* The same programs list-scheduled (asm/sched.h): every expectation must still hold, traps too. */
ParameterizedTestParameters(isa_programs, run_scheduled)
{
    return isa_programs_run_params();
}

ParameterizedTest(ProgParam *p, isa_programs, run_scheduled)
{
    run_program(p->path, 1);
}

Test(isa_programs, every_opcode_has_a_program)
{
    int missing = 0;
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        char path[128];
        struct stat st;
        snprintf(path, sizeof path, ISA_PROG_DIR "/%s.s", isa_ops[op].mnemonic);
        if (stat(path, &st) != 0) {
            missing++;
            cr_expect_fail("%s is missing: every opcode needs a test program", path);
        }
    }
    cr_expect_eq(missing, 0, "%d of %d opcodes have no test program", missing, (int)ISA_OP_COUNT);
}

/* The harness itself: the evaluator and the parser, on expectations whose answers are known. */
Test(isa_programs, expectation_language)
{
    struct { const char *text; int64_t want; } ints[] = {
        {"1 + 2 * 3", 7},          {"(1 + 2) * 3", 9},        {"7 / 2", 3},       {"-7 % 3", -1},
        {"1 << 31", 2147483648ll}, {"0xff & 0x0f | 0x100", 0x10f}, {"5 > 3 && 2 < 1", 0},
        {"0 || 3", 1},             {"N - 1", 3},              {"l * 2 + 1", 5},   {"l < 3 ? 10 : 20", 10},
        {"f(1.5)", 0x3FC00000},    {"f(-0.0)", 0x80000000ll}, {"u32(-1)", 0xFFFFFFFFll},
        {"s32(0xFFFFFFFF)", -1},   {"popcount(0xF0F0)", 8},   {"min(3, -2)", -2}, {"max(3, -2)", 3},
        {"int(-2.7)", -2},         {"f(float(float(0.1) + float(0.2)))", 0x3E99999A}, {"~0 & 0xF", 15},
        {"!0", 1},                 {"1 ? 2 ? 3 : 4 : 5", 3},  {"f(fl(0x7F800000))", 0x7F800000},
    };
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++) {
        Lexer lx;
        memset(&lx, 0, sizeof lx);
        lx.s = ints[i].text;
        ie_lex_next(&lx);
        Expr *e = ie_parse_expr(&lx);
        cr_assert_eq(lx.err[0], 0, "\"%s\": %s", ints[i].text, lx.err);
        cr_assert_eq(lx.tok, T_EOF, "\"%s\": not fully parsed", ints[i].text);
        Env env = {4, 2, NULL, ""};
        Val v = ie_eval(e, &env);
        cr_expect_eq(env.err[0], 0, "\"%s\": %s", ints[i].text, env.err);
        cr_expect(!v.isf && v.i == ints[i].want, "\"%s\" = %lld, expected %lld", ints[i].text, (long long)v.i,
                  (long long)ints[i].want);
        ie_expr_free(e);
    }
    Check ck;
    char err[200];
    cr_expect_eq(ie_parse_check(" v2[l] ==f l * 0.5", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_VREG);
    cr_expect_eq(ck.op, OP_FEQ);
    cr_expect(ck.per_lane);
    ie_expr_free(ck.index);
    ie_expr_free(ck.expect);
    cr_expect_eq(ie_parse_check(" if N >= 4: r3 ~= 1.5 1e-6", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_SREG);
    cr_expect_eq(ck.op, OP_APPROX);
    cr_expect_not_null(ck.tol);
    cr_expect_not_null(ck.guard);
    cr_expect(!ck.per_lane);
    ie_expr_free(ck.guard);
    ie_expr_free(ck.expect);
    ie_expr_free(ck.tol);
    cr_expect_eq(ie_parse_check(" trap \"divu\" \"x.s:3\"", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.nsub, 2);
    cr_expect_str_eq(ck.subs[1], "x.s:3");
    cr_expect_eq(ie_parse_check(" mem idm[4*l] == l", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_MEM);
    cr_expect_eq(ck.reg, CORE_MEM_IDM);
    ie_expr_free(ck.index);
    ie_expr_free(ck.expect);
    cr_expect_eq(ie_parse_check(" m1 == 3", 3, &ck, err, sizeof err), 0, "%s", err);
    cr_expect_eq(ck.kind, X_MASK);
    ie_expr_free(ck.expect);
    cr_expect_eq(ie_parse_check(" r3 = 7", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(ie_parse_check(" r32 == 7", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(ie_parse_check(" m1 ==f 1.0", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(ie_parse_check(" r3 ~= 1.5", 3, &ck, err, sizeof err), -1);
    cr_expect_eq(ie_parse_check(" r3 == (1", 3, &ck, err, sizeof err), -1);
}
