/* sim/stats.h -- the statistics registry: every counter and derived figure of a run, once
 * (sim/stats.def), and the one walk over it that writes them.
 *
 * Owns: the statistics part of report.json, report.txt's statistics lines, stats.txt, the `sfsim exec
 * --timing` (and `sfsim trace --mode detailed`) print-out, the sweep CSV's columns and their
 * reading back from report.json, and every derived figure (utilization, timed utilization,
 * stream lengths, shares, hit rate, fps, the sampled-mode estimate): computed here only, used by
 * render.c, main.c, tools/validation.c and bench/.
 * Must not: count anything (the core, the timing model and the renderers do), or write the
 * non-statistics blocks of the report (config, scene, render, image, kernel, kd.tree, host,
 * sample metadata, status: sim/render.c).
 *
 * Adding a counter: its row in sim/stats.def and the code that counts it; report.json,
 * report.txt, the exec print-out, the CSV and docs/report.md follow from the row.
 * Files: sim/stats.c (the table, the figures, the walk, report.json), sim/stats_text.c
 * (report.txt, the exec print-out, stats.txt), sim/stats_csv.c (the CSV), sim/stats_walk.h (between them).
 */
#ifndef SFSIM_STATS_H
#define SFSIM_STATS_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "config.h"
#include "core.h"
#include "run/engine.h"
#include "sampling.h"
#include "timing.h"

struct cJSON;
struct EnergyReport;

#define STATS_GENERATIONS 64   /* generations kept apart: CORE_, FUNC_MAX_ and REF_MAX_GENERATIONS */
#define STATS_MAX_DIMS 3

/* Either renderer's ray counts, in the report's terms (render.c fills it from RefStats or FuncStats). */
typedef struct StatsRun {
    uint64_t primary, shadow, indirect, dropped;
    uint64_t per_gen[STATS_GENERATIONS];
    uint64_t generations;
    uint64_t nodes_visited, prims_tested;   /* the golden model's traversal */
} StatsRun;

struct RefStats;
/* run from the kernel's or the golden model's counters. */
void stats_run_from_func(StatsRun *run, const FuncStats *f);
void stats_run_from_ref(StatsRun *run, const struct RefStats *r);

/* The modes a row appears in (one bit is the run's mode; STATS_M_KD is added when the kernel
 * traverses a kd-tree). */
enum {
    STATS_M_REF = 1 << 0,    /* --mode reference (the golden model) */
    STATS_M_FUNC = 1 << 1,   /* --mode functional */
    STATS_M_DET = 1 << 2,    /* --mode detailed */
    STATS_M_SAMP = 1 << 3,   /* --mode sampled */
    STATS_M_EXEC = 1 << 4,   /* sfsim exec --timing, sfsim trace --mode detailed: TimingStats only */
    STATS_M_KD = 1 << 5,     /* with accel.structure = kd (a row's modes: only then) */
    STATS_M_CHIP = 1 << 6,   /* a chip's run: chip.cores > 1 or chip.memory = shared (only then) */
    STATS_M_SHARED = 1 << 7, /* with chip.memory = shared (only then) */
    STATS_M_QUALIFIERS = STATS_M_KD | STATS_M_CHIP | STATS_M_SHARED,
    STATS_M_KERNEL = STATS_M_FUNC | STATS_M_DET | STATS_M_SAMP,
    STATS_M_TIMED = STATS_M_DET | STATS_M_SAMP,
    STATS_M_ALL = STATS_M_REF | STATS_M_KERNEL,
};

/* Where a row's value comes from. */
typedef enum StatsSrc {
    STATS_SRC_RUN,       /* a uint64 field of StatsRun */
    STATS_SRC_CORE,      /* a uint64 field of CoreStats (FuncStats.core) */
    STATS_SRC_FUNC,      /* a uint64 field of FuncStats */
    STATS_SRC_TIMING,    /* a uint64 field of TimingStats */
    STATS_SRC_TILE,      /* a field of FuncTile (first dimension: the tile) */
    STATS_SRC_CHIPCORE,  /* a uint64 field of FuncCore, the core's (FuncStats.cores[core]) */
    STATS_SRC_CHIPMEM,   /* a uint64 field of ChipMemStats (FuncStats.chip_mem) */
    STATS_SRC_FN,        /* a derived figure computed in stats.c */
    STATS_SRC_EXTERNAL,  /* written by its owner (render.c's host block); read back by the CSV */
} StatsSrc;

#define STATS_DIMS(X) \
    X(STAGE,    "stage",    "statistics stage (isa.h: other, traversal, intersection, shading)") \
    X(FILTER,   "filter",   "stream filter: traversal, intersection, shading") \
    X(CAUSE,    "cause",    "stall cause (timing.h TM_CAUSES)") \
    X(CATEGORY, "category", "operation category (001 Table 5, plus integer and control)") \
    X(GEN,      "gen",      "breadth-first ray generation (array, as many as the run reached)") \
    X(TILE,     "tile",     "tile, raster order (array)") \
    X(PASS,     "pass",     "a pass of a tile, one sample per pixel (array, render.spp)") \
    X(OPCODE,   "opcode",   "instruction, by mnemonic") \
    X(UNIT,     "unit",     "functional-unit class (isa.h ISA_UNITS)") \
    X(KIND,     "kind",     "ray kind: camera, indirect, shadow") \
    X(COUNTER,  "counter",  "kd-tree counter of the kernel (KC_* in kernels/lib/abi.inc)") \
    X(BOUND,    "bound",    "a 95 % interval's bound: lo, hi (array)") \
    X(CORE,     "core",     "a core of the chip (array, chip.cores)") \
    X(PART,     "part",     "a part of the machine with energy (sim/energy/energy.h ENERGY_PARTS)") \
    X(LEVEL,    "level",    "a level of the machine: datapath, registers, local memories, L1, L2, network, DRAM") \
    X(DRAMPART, "dram_part", "what the DRAM's energy went to: commands, standby states, I/O") \
    X(AREA,     "structure", "a structure with an area (sim/energy/energy.h ENERGY_AREAS)")

typedef enum StatsDim {
#define STATS_DIM_ENUM(name, key, desc) STATS_D_##name,
    STATS_DIMS(STATS_DIM_ENUM)
#undef STATS_DIM_ENUM
    STATS_D_COUNT
} StatsDim;

#define STATS_UNITS(X) \
    X(CYCLES,       "cycles") \
    X(INSTRUCTIONS, "instructions") \
    X(RAYS,         "rays") \
    X(STREAMS,      "streams") \
    X(RAYS_PER_STREAM, "rays per stream") \
    X(PER_RAY,      "per ray") \
    X(RATIO,        "ratio") \
    X(FPS,          "frames/s") \
    X(MHZ,          "MHz") \
    X(CPI,          "cycles per instruction") \
    X(NUMBER,       "number") \
    X(EVENTS,       "count") \
    X(TILES,        "tiles") \
    X(UNITS,        "(tile, pass) units") \
    X(PIXELS,       "pixels") \
    X(ACCESSES,     "accesses") \
    X(LINES,        "lines") \
    X(IDS,          "ray IDs") \
    X(VECTORS,      "ID vectors") \
    X(TRANSFERS,    "transfers") \
    X(PARTITIONS,   "partitions") \
    X(BYTES,        "bytes") \
    X(SECONDS,      "seconds") \
    X(FLAG,         "true/false") \
    X(JOULES,       "J") \
    X(WATTS,        "W") \
    X(MM2,          "mm^2") \
    X(NAMES,        "names")

typedef enum StatsUnit {
#define STATS_UNIT_ENUM(name, text) STATS_U_##name,
    STATS_UNITS(STATS_UNIT_ENUM)
#undef STATS_UNIT_ENUM
    STATS_U_COUNT
} StatsUnit;

/* How report.txt prints a row (the exec print-out: one line per value, see stats_print_exec). */
typedef enum StatsText {
    STATS_T_NONE,    /* not in report.txt */
    STATS_T_HEAD,    /* the headline sentence (cycles, busy, stalls, fps) */
    STATS_T_LINE,    /* starts a line: "label" then "name value" (scalar) or "key value" per element */
    STATS_T_MORE,    /* a scalar continuing the line above: ", name value" */
    STATS_T_TABLE,   /* a 2-D row as a table: a header of the second dimension, a line per first */
    STATS_T_TROW,    /* a 1-D row as one more line (labelled) of the table above */
} StatsText;

typedef struct StatsCtx StatsCtx;
/* A derived figure: the value at idx; *na = 1 when it has no meaning (a ratio over nothing:
 * report.json has 0, report.txt "-"). */
typedef double (*StatsFn)(const StatsCtx *c, const int *idx, int *na);

enum {
    STATS_F_ROUND = 1,       /* report.json gets the value rounded to an integer */
    STATS_F_SPARSE = 2,      /* elements that are 0 are left out */
    STATS_F_NULLED = 4,      /* every mode has the key: null where the row's modes do not */
    STATS_F_LIST_NZ = 8,     /* an array of the names of the (one-dimensional) elements that are not 0 */
    STATS_F_LIST_Z = 16,     /* ... that are 0 */
    STATS_F_NORMALIZE = 32,  /* the CSV divides each element by their sum (shares) */
};

typedef struct StatsRow {
    const char *path;        /* report.json key path: "a.b", "{dim}" an object key per element, "[dim]" an
                                array index; NULL: report.txt only */
    StatsSrc src;
    size_t offset;           /* field rows: offsetof in the source struct (arrays in dimension order) */
    StatsFn fn;              /* STATS_SRC_FN */
    int u32;                 /* the field is a uint32_t (TILE32) */
    int ndims;
    StatsDim dims[STATS_MAX_DIMS];
    StatsUnit unit;
    unsigned modes;          /* STATS_M_* */
    unsigned flags;          /* STATS_F_* */
    int csv_order;           /* position of the row's columns in the sweep CSV; -1: none */
    const char *csv;         /* the CSV column name, with {dim} placeholders */
    StatsText text;
    const char *label;       /* report.txt and exec label */
    const char *desc;
} StatsRow;

#define STATS_MAX_ROWS 512   /* a bound on stats.def's rows, checked where the table is built */
extern const StatsRow stats_rows[];
extern const int stats_nrows;
extern const char *const stats_dim_names[STATS_D_COUNT];
extern const char *const stats_dim_descs[STATS_D_COUNT];
extern const char *const stats_unit_names[STATS_U_COUNT];

/* The dimension's static size (its elements; for GEN and TILE the capacity) and key of element i. */
int stats_dim_size(StatsDim d);
const char *stats_dim_key(StatsDim d, int i);

/* What the walk reads. */
/* A sampled chip's own figures (sim/run/chipsampled.c, docs/sampling.md "Sampling a chip"). */
typedef struct StatsChipSample {
    int on;                    /* the frame was a chip's, sampled */
    uint32_t cores;            /* chip.cores */
    uint32_t opening_units;    /* units timed exactly in the chip's opening (its first wave) */
    uint32_t waves, wave_units, alone_units; /* waves timed on the whole chip, their units, and those timed alone too */
    double r, r_lo, r_hi;      /* the other cores' factor (the waves' cycles over the same units' alone), 95 % */
    double plain;              /* the makespan estimate without the tile-effect correction */
    double var_jack, var_draws, var_r; /* the makespan's variance by part */
    double sigma_a, sigma_e;   /* tile effect and within-tile spread of the fit's relative residuals */
    uint32_t tail_units;       /* units timed for the makespan's tail, beyond phase 1's sample */
    uint32_t first_units;      /* tiles' first passes timed for the memory figures, beyond phase 1's sample */
    uint32_t mem_waves;        /* the waves the memory figures' correction came from (0: none) */
    uint32_t warm_units;       /* units whose lines the golden model recorded for the warming */
    uint32_t record_step;      /* the warming's first-reader record held every record_step-th pass (0: none) */
    double warm_seconds;       /* ... and its host time */
    /* The memory figures (chip.memory = shared; sim/chipmemest.h), each {estimate, lo, hi} of its
     * 95 % interval: the average read latency below the L1s (cycles; has_mem), the L2's hit rate
     * (has_l2), DRAM's bandwidth (GB/s over the estimated makespan; has_mem). */
    int shared;                /* chip.memory = shared (report.json then has these) */
    int has_mem, has_l2;
    double latency[3], l2_hit_rate[3], dram_gbs[3];
} StatsChipSample;

struct StatsCtx {
    unsigned mode;               /* one of STATS_M_REF/FUNC/DET/SAMP/EXEC, | STATS_M_KD */
    const CfgMachine *cfg;       /* lanes, clock, scene cache (may be NULL in exec) */
    const StatsRun *run;         /* every mode but exec */
    const FuncStats *f;          /* kernel modes */
    const TimingStats *t;        /* timed modes (&f->timing) and exec */
    const SampleEstimate *est;   /* sampled mode: the cycles */
    const SampleEstimate *est_instructions; /* ... the instructions */
    uint32_t rounds;             /* ... rounds of the sequential rule */
    const StatsChipSample *chip_sample; /* ... on a chip */
    const struct EnergyReport *energy; /* timed modes: the run's energy and area (sim/energy/energy.h) */
};

/* The statistics of report.json, added to root (objects the walk creates may be shared with the
 * hand-written blocks: kd, sample). 0, or -1 when out of memory. */
int stats_json(struct cJSON *root, const StatsCtx *c);
/* report.txt's statistics lines, appended at buf + *len (bounded by cap; *len advances). */
void stats_text(char *buf, size_t cap, size_t *len, const StatsCtx *c);
/* The exec print-out: the headline "timing: C cycles = B busy + S stall", then one line per value
 * ("  stall control  2"; elements that are 0 left out). */
void stats_print_exec(FILE *out, const StatsCtx *c);

/* stats.txt (docs/report.md): gem5's "---------- Begin Simulation Statistics ----------", a line
 * per number of report.json's statistics, "name  value  # description (unit)", with the name the
 * report.json path in dots and a vector's element "name::key" (a summing one's "name::total"
 * after its elements), then gem5's End line. 0, or -1 when fp reports an error. */
int stats_gem5(FILE *fp, const StatsCtx *c);

/* ---- derived figures: computed here, and only here ---------------------------------------- */
double stats_ratio(uint64_t a, uint64_t b);            /* a / b; 0 when b = 0 */
uint64_t stats_rays_total(const FuncStats *f);         /* camera + indirect + shadow */
uint64_t stats_ops(const CoreStats *s, int category);  /* over all stages */
/* SIMD utilization: active lanes / (N x vector instructions) of a stage, over generations
 * [g0, g1) (stats_utilization: all of them). */
double stats_utilization(const CoreStats *s, int lanes, int stage);
double stats_utilization_gens(const CoreStats *s, int lanes, int stage, int g0, int g1);
/* Timed utilization: the timed tiles' active lanes / (N x (vector issue + stall cycles)). */
double stats_utilization_timed(const FuncStats *f, int lanes, int stage);
/* Active lanes over all lane-cycles of a stage (scalar issue and stalls as idle lanes). */
double stats_utilization_cycles(const FuncStats *f, int lanes, int stage);
/* Mean rays per stream entering a filter (FUNC_STAGES order), over generations [g0, g1). */
double stats_stream_length(const FuncStats *f, int filter, int g0, int g1);
double stats_stall_share(const TimingStats *t, int cause);
/* A kd counter per ray of a kind (FUNC_KD_KINDS: all kinds). */
double stats_kd_per_ray(const FuncStats *f, int kind, int counter);

/* The frame's timing: measured (detailed), or estimated from the sampled units (est != NULL:
 * the cycles; busy is then the instructions given, the estimated ones). */
typedef struct StatsFrame {
    double cycles, busy, fps, fps_no_stall;
    double cycles_lo, cycles_hi, fps_lo, fps_hi;   /* sampled mode: the 95 % intervals */
} StatsFrame;
StatsFrame stats_frame(const TimingStats *t, double instructions, double clock_mhz, const SampleEstimate *est);
/* The frame's timing of c: stats_frame, or a chip's makespan (the report's cycles and fps). */
StatsFrame stats_frame_of(const StatsCtx *c);

/* The table's rules for one row (path names the dimensions, sources and text styles fit, fields
 * inside their struct): 0, or -1 with the row and the rule in err. */
int stats_row_check(const StatsRow *r, char *err, size_t errlen);

/* ---- the sweep CSV ------------------------------------------------------------------------- */
/* Its figure columns, in order: the rows with a csv name, by csv_order, expanded over their
 * dimensions. */
int stats_csv_count(void);
/* Column col's name ("utilization_traversal"); "" when col is out of range. */
const char *stats_csv_name(int col, char *buf, size_t len);
/* One point's figures from its parsed report.json: value[col] and has[col] (0 where the report
 * has no finite number there; shares normalized over their row). Both have stats_csv_count() entries. */
void stats_csv_read(const struct cJSON *report, double *value, unsigned char *has);
/* Column col's report.json path ("stall_shares.control", "fps_ci95[1]"); "" when out of range. */
const char *stats_csv_key(int col, char *buf, size_t len);
/* A reason a point's report.json cannot give a figure its run must have (stats_csv_check). */
typedef struct StatsCsvProblem {
    int col;        /* the figure column */
    char key[128];  /* the report.json key at fault: the figure's, or one on its path */
    char what[64];  /* "missing", "is not a number (a string)", "is not an object (null)" ... */
} StatsCsvProblem;
/* The figures report lacks, or holds as no finite number, that a run of mode (STATS_M_FUNC, DET
 * or SAMP, | STATS_M_KD) writes: a row of the mode must be there (a SPARSE row's elements may be
 * absent); a row the mode does not have may be absent, null or a number, nothing else (a string).
 * The first max into out (a wrong key on the way to several elements counts once); returns how
 * many there are, 0 when the report has every figure of its mode. */
int stats_csv_check(const struct cJSON *report, unsigned mode, StatsCsvProblem *out, int max);

#endif
