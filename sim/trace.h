/* sim/trace.h -- `sfsim trace`: closest-hit and any-hit queries for a batch of rays, through the
 * kernel's traversal and intersection on the functional core (timed in detailed mode), or
 * through the golden model.
 *
 * Owns: the orchestration of a trace run (scene, rays, engine, hit file, summary).
 * Must not: parse the command line or implement a ray query.
 */
#ifndef SFSIM_TRACE_H
#define SFSIM_TRACE_H

#include <stddef.h>
#include <stdint.h>

#include "config.h"
#include "run/run.h"
#include "raybatch.h"
#include "timing.h"

typedef struct TraceOptions {
    const char *scene_path, *rays_path, *out_path;
    RunMode mode;                 /* RUN_FUNCTIONAL (the default), RUN_DETAILED (the kernel, timed) or RUN_REFERENCE */
    const char *kernel_path;      /* NULL: next to the executable */
    const CfgMachine *cfg;
    int threads;
    int binary;                   /* hits in binary */
} TraceOptions;

typedef struct TraceSummary {
    uint32_t rays, hits, misses, occluded, clear, invalid;
    uint64_t sim_instructions;
    double seconds;
    int timed;                    /* detailed mode: timing holds the cycles of all batches */
    TimingStats timing;
    uint32_t cores, cores_used;   /* a chip's: its cores, those that got a batch; else 0 */
    uint64_t makespan;            /* a chip's: the cycle its last core finished */
} TraceSummary;

/* The whole command: 0, -1 with a message naming the file or key, -2 when the kernel failed, -3
 * when the hit file could not be written (checked before any work; written whole or not at all). */
int trace_run(const TraceOptions *o, TraceSummary *sum, char *err, size_t errlen);

#endif
