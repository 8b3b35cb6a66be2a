/* sim/run/spec.h -- how a simulation is asked for: the modes, the RunSpec every entry point of
 * sim/run/run.h takes, and the defaults its zero fields stand for (the machine, the host threads,
 * the kernel's source).
 *
 * Owns: the mode names and their parse, the RunSpec and its defaults. Must not: check how the
 * settings go together (the commands do it once, sim/cli/runopts.c; sim/run/run.c asserts what
 * that check guarantees), or run anything. It sits below run.c and sampled.c, which both read it,
 * so that neither calls the other back.
 */
#ifndef SFSIM_RUN_SPEC_H
#define SFSIM_RUN_SPEC_H

#include <stddef.h>
#include <stdint.h>

#include "../config.h"

/* The modes: the golden model, the kernel on the functional core, the kernel timed on the
 * machine, and a sample of the kernel's (tile, pass) units timed (docs/sampling.md). */
typedef enum RunMode { RUN_REFERENCE, RUN_FUNCTIONAL, RUN_DETAILED, RUN_SAMPLED, RUN_MODE_COUNT } RunMode;
extern const char *const run_mode_names[RUN_MODE_COUNT]; /* "reference", "functional", ... */

/* name as a mode: 0, or -1 when it names none. */
int run_mode_parse(const char *name, RunMode *mode);
/* The kernel runs (every mode but the golden model's). */
static inline int run_mode_kernel(RunMode m) { return m != RUN_REFERENCE; }
/* The timing model runs (on every unit, or on the sample). */
static inline int run_mode_timed(RunMode m) { return m == RUN_DETAILED || m == RUN_SAMPLED; }
/* The workload of cfg has a golden model (the path tracer and the Phong workload; the forced
 * specular and diffuse workloads exist only as kernel variants, docs/kernel.md): the reference
 * mode renders it and the sampled mode draws its units' auxiliary counts from it. */
static inline int run_workload_golden(const CfgMachine *cfg)
{
    return cfg->workload_kind == CFG_WORKLOAD_PATH || cfg->workload_kind == CFG_WORKLOAD_PHONG;
}

/* How to run: the mode, the machine and the host. Zero-initialised fields take the defaults. */
typedef struct RunSpec {
    RunMode mode;
    const CfgMachine *cfg;     /* NULL: the defaults of sim/config.def */
    const char *kernel_path;   /* NULL: kernels/pathtrace.s beside the binary (sim/run/kernel.h) */
    uint32_t seed;             /* the path tracer's random stream */
    int threads;               /* host threads; 0: every core */
    /* RUN_SAMPLED (docs/sampling.md): the fraction of the (tile, pass) units timed, (0, 1], or
     * when target_error > 0 as many as the sequential rule needs for a 95 % interval of the cycles
     * within +-target_error (a fraction, 0.01 = 1 %); sample_seed fixes which units. no_image: the
     * golden model runs only a pilot (fr->rgb stays black). Zero in the other modes. */
    double sample;
    double target_error;
    uint32_t sample_seed;
    int no_image;
    int mem_trace;             /* RUN_DETAILED: keep the L1s' requests below (RunFrame.f.trace) */
    struct Timeline *timeline; /* RUN_DETAILED: record the run's timeline here (sim/timeline.h), or NULL */
    void (*progress)(void *ctx, uint32_t tiles_done, uint32_t tiles_total);
    /* A line on what a long run is doing (sampled mode's rounds); may be NULL. */
    void (*note)(void *ctx, const char *line);
    void *progress_ctx;
} RunSpec;

/* spec's machine: spec->cfg, or the defaults written into *defcfg. */
const CfgMachine *run_spec_machine(const RunSpec *spec, CfgMachine *defcfg);
/* spec's host threads: spec->threads, or every core. */
int run_spec_threads(const RunSpec *spec);
/* spec's kernel source: spec->kernel_path, or kernels/pathtrace.s beside the binary (kpath holds it). */
const char *run_spec_kernel(const RunSpec *spec, char *kpath, size_t len);

#endif
