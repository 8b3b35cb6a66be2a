/* asm/main_sfasm.c -- the sfasm command line: assemble a file, or disassemble an object.
 *
 * Owns: argument parsing, output naming and exit codes (sim/exitcodes.def: EXIT_OK, EXIT_INPUT for
 * errors in the source or object read, EXIT_USAGE, EXIT_IO when the output cannot be written).
 * Must not: assemble or format anything itself (asm/ does).
 */
#include <errno.h>
#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../sim/exitcodes.h"
#include "../sim/exithelp.h"
#include "../host/outfile.h"
#include "../host/version.h"
#include "asm.h"


typedef struct Args {
    AsmDefine *defines; int ndefines;
    const char **include_dirs; int ninclude_dirs;
    const char *input, *output, *disasm;
    int source;
    int optimize;              /* -O: the scheduling pass */
    int report;                /* --schedule-report */
    AsmSchedModel model;       /* sched_model_default, then --latency / --issue / --lanes */
} Args;

static void usage(FILE *f)
{
    fprintf(f,
            "usage: sfasm [options] FILE.s [-o FILE.sfo]\n"
            "       sfasm -d FILE.sfo [--source]\n"
            "\n"
            "Assembles sfsim assembly into an object (.sfo), or disassembles an object to stdout.\n"
            "\n"
            "options (a value as -o OUT, -oOUT, --output OUT or --output=OUT; options and the file in any\n"
            "order; -- ends the options):\n"
            "  -o, --output OUT           output object (default: the input with .sfo instead of .s); written\n"
            "                             whole or not at all: a full disk keeps the object that was there\n"
            "  -D, --define NAME[=VAL]    define symbol NAME (VAL an integer, default 1)\n"
            "  -I, --include-dir DIR      search DIR for .include files (after the including file's directory)\n"
            "  -d, --disassemble FILE.sfo disassemble FILE.sfo to stdout\n"
            "  --source                   with -d: add each instruction's file:line as a comment\n"
            "  -O, -O1                    schedule each basic block for the machine (list scheduling by\n"
            "                             critical path; docs/assembler.md); -O0 keeps the source order (default)\n"
            "  --latency CLASS=N          with -O: the result latency of unit class CLASS (vfma, vadd, rbuf, ...;\n"
            "                             the classes of docs/isa.md); default configs/streamray.ini's\n"
            "  --issue CLASS=N            with -O: cycles between two issues of CLASS (default as --latency)\n"
            "  --lanes N                  with -O: the SIMD width N the code runs at (default 16)\n"
            "  --schedule-report          with -O: print, per block, its length, critical path and estimated\n"
            "                             cycles before and after, then a total, to stdout\n"
            "  -h, --help                 this text\n"
            "  --version                  the version (the same as sfsim's) and the object format's\n"
            "\n"
            "At most 50 errors are printed (in source order), then how many more there were.\n"
            "\n"
            "examples:\n"
            "  sfasm prog.s                                   writes prog.sfo\n"
            "  sfasm kernels/pathtrace.s -I kernels/lib -I kernels -DRAYS=4096 -D SPAD_BYTES=65536 -o k.sfo\n"
            "  sfasm -d k.sfo --source | less                 the disassembly, each line with its source line\n"
            "  sfasm -O --latency vfma=6 --schedule-report k.s  scheduled for a 6-cycle FMA, with the report\n"
            "\n"
            "exit codes (shared by sfsim; sfasm returns 0, 1, 2 or 4; docs/exit-codes.md):\n");
    exithelp_print(f);
    fprintf(f, "\ndocumentation: docs/assembler.md, docs/object-format.md\n");
}

__attribute__((format(printf, 1, 2)))
static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "sfasm: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n(try 'sfasm --help')\n");
    va_end(ap);
    return EXIT_USAGE;
}

static int parse_define(Args *a, char *spec)
{
    char *eq = strchr(spec, '=');
    long long v = 1;
    if (eq) {
        char *end;
        *eq = '\0';
        errno = 0;
        v = strtoll(eq + 1, &end, 0);
        if (eq[1] == '\0' || *end != '\0' || errno == ERANGE)
            return usage_error("-D %s: the value must be an integer", spec);
    }
    if (spec[0] == '\0')
        return usage_error("-D needs a NAME");
    a->defines[a->ndefines++] = (AsmDefine){spec, v};
    return 0;
}

enum { A_SOURCE = 0x100, A_VERSION, A_LATENCY, A_ISSUE, A_LANES, A_REPORT };
static const struct option longs[] = {
    {"output", required_argument, NULL, 'o'},      {"define", required_argument, NULL, 'D'},
    {"include-dir", required_argument, NULL, 'I'}, {"disassemble", required_argument, NULL, 'd'},
    {"source", no_argument, NULL, A_SOURCE},       {"help", no_argument, NULL, 'h'},
    {"version", no_argument, NULL, A_VERSION},     {"latency", required_argument, NULL, A_LATENCY},
    {"issue", required_argument, NULL, A_ISSUE},   {"lanes", required_argument, NULL, A_LANES},
    {"schedule-report", no_argument, NULL, A_REPORT}, {NULL, 0, NULL, 0}};

/* "N" in lo..hi into *v, or -1. */
static int parse_int(const char *s, int lo, int hi, int *v)
{
    char *end;
    errno = 0;
    long x = strtol(s, &end, 10);
    if (!*s || *end || errno == ERANGE || x < lo || x > hi)
        return -1;
    *v = (int)x;
    return 0;
}

/* --latency / --issue CLASS=N: a unit class of isa/isa.h and 1..1024 cycles. */
static int parse_class(Args *a, const char *opt, const char *spec, int issue)
{
    char name[32];
    const char *eq = strchr(spec, '=');
    size_t n = eq ? (size_t)(eq - spec) : 0;
    int u = -1, v;
    if (eq && n < sizeof name) {
        memcpy(name, spec, n);
        name[n] = '\0';
        u = sched_unit_from_name(name);
    }
    if (u < 0)
        return usage_error("--%s %s: expected CLASS=N with CLASS a unit class (vfma, vadd, rbuf, ...: docs/isa.md)",
                           opt, spec);
    if (parse_int(eq + 1, 1, 1024, &v) != 0)
        return usage_error("--%s %s: N must be an integer in 1..1024", opt, spec);
    (issue ? a->model.issue : a->model.lat)[u] = v;
    return 0;
}

/* getopt_long's (glibc) error for the argument it just looked at. */
static int option_error(int code, int argc, char **argv)
{
    const char *w = optind - 1 >= 1 && optind - 1 < argc ? argv[optind - 1] : "?";
    if (code == ':')
        return usage_error("option '%s' needs a value", w);
    if (strncmp(w, "--", 2) != 0)
        return usage_error("unknown option '-%c'", optopt ? optopt : '?');
    if (optopt && strchr(w, '='))
        return usage_error("option '%.*s' takes no value", (int)(strchr(w, '=') - w), w);
    return usage_error("unknown or ambiguous option '%s'", w);
}

/* 0 to go on, -1 when --help or --version was printed, or EXIT_USAGE (said). */
static int parse_args(int argc, char **argv, Args *a)
{
    a->defines = calloc((size_t)argc, sizeof *a->defines);
    a->include_dirs = calloc((size_t)argc, sizeof *a->include_dirs);
    if (!a->defines || !a->include_dirs)
        return usage_error("out of memory");
    opterr = 0;
    int code;
    int tuned = 0;
    sched_model_default(&a->model);
    while ((code = getopt_long(argc, argv, ":o:D:I:d:hO::", longs, NULL)) != -1) {
        switch (code) {
        case 'h': usage(stdout); return -1;
        case A_VERSION:
            printf("sfasm %s (commit %s, object format version %u)\n", version_string(), version_commit(), ASM_OBJ_VERSION);
            return -1;
        case A_SOURCE: a->source = 1; break;
        case 'O':
            if (optarg && strcmp(optarg, "0") != 0 && strcmp(optarg, "1") != 0)
                return usage_error("-O%s: the levels are -O0 (source order) and -O or -O1 (scheduled)", optarg);
            a->optimize = !optarg || optarg[0] == '1';
            break;
        case A_LATENCY:
        case A_ISSUE:
            if (parse_class(a, code == A_LATENCY ? "latency" : "issue", optarg, code == A_ISSUE) != 0)
                return EXIT_USAGE;
            tuned = 1;
            break;
        case A_LANES:
            if (parse_int(optarg, 1, ISA_MAX_LANES, &a->model.lanes) != 0)
                return usage_error("--lanes %s: N must be an integer in 1..%d", optarg, ISA_MAX_LANES);
            tuned = 1;
            break;
        case A_REPORT: a->report = 1; break;
        case 'D':
            if (parse_define(a, optarg) != 0)
                return EXIT_USAGE;
            break;
        case 'I': a->include_dirs[a->ninclude_dirs++] = optarg; break;
        case 'o': a->output = optarg; break;
        case 'd': a->disasm = optarg; break;
        default: return option_error(code, argc, argv);
        }
    }
    for (int i = optind; i < argc; i++) {
        if (a->input)
            return usage_error("more than one input file ('%s')", argv[i]);
        a->input = argv[i];
    }
    if (a->disasm && (a->input || a->output))
        return usage_error("-d takes only an object file");
    if (!a->disasm && a->source)
        return usage_error("--source goes with -d");
    if (!a->disasm && !a->input)
        return usage_error("no input file");
    if ((tuned || a->report) && !a->optimize)
        return usage_error("--latency, --issue, --lanes and --schedule-report go with -O");
    if (a->disasm && a->optimize)
        return usage_error("-O goes with assembling, not with -d");
    return 0;
}

static int disassemble(const Args *a)
{
    AsmObject obj;
    char err[512];
    if (asm_object_read(a->disasm, &obj, err, sizeof err) < 0) {
        fprintf(stderr, "sfasm: %s\n", err);
        return EXIT_INPUT;
    }
    asm_disassemble(&obj, stdout, a->source);
    asm_object_free(&obj);
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "sfasm: -d %s: cannot write the disassembly to stdout\n", a->disasm);
        return EXIT_IO;
    }
    return EXIT_OK;
}

/* FILE.s -> FILE.sfo; any other name gets .sfo appended. */
static char *default_output(const char *in)
{
    size_t n = strlen(in);
    char *out = malloc(n + 5);
    if (!out)
        return NULL;
    memcpy(out, in, n + 1);
    if (n > 2 && strcmp(in + n - 2, ".s") == 0)
        out[n - 2] = '\0';
    strcat(out, ".sfo");
    return out;
}

static int assemble(const Args *a)
{
    AsmOptions opt = {a->defines, a->ndefines, a->include_dirs, a->ninclude_dirs, stderr,
                      a->optimize ? &a->model : NULL, a->report ? stdout : NULL};
    AsmObject obj;
    int errors = asm_assemble_file(a->input, &opt, &obj);
    if (errors) {
        fprintf(stderr, "sfasm: %d error%s\n", errors, errors == 1 ? "" : "s");
        return EXIT_INPUT;
    }
    char *out = a->output ? NULL : default_output(a->input), err[512];
    int rc = -1;
    if (!a->output && !out)
        snprintf(err, sizeof err, "out of memory");
    else
        rc = asm_object_write(&obj, a->output ? a->output : out, err, sizeof err);
    if (rc < 0)
        fprintf(stderr, "sfasm: %s\n", err);
    free(out);
    asm_object_free(&obj);
    return rc < 0 ? EXIT_IO : EXIT_OK;
}

int main(int argc, char **argv)
{
    Args a = {0};
    outfile_process_init();
    int rc = parse_args(argc, argv, &a);
    if (rc == 0)
        rc = a.disasm ? disassemble(&a) : assemble(&a);
    else if (rc < 0)
        rc = EXIT_OK;
    free(a.defines);
    free(a.include_dirs);
    if (fflush(stdout) != 0 || ferror(stdout)) { /* --help, --version */
        fprintf(stderr, "sfasm: cannot write to standard output\n");
        if (rc == EXIT_OK)
            rc = EXIT_IO;
    }
    return rc;
}
