/* sim/run/run.h -- THE ENTRY POINT of every simulation: a scene opened for a machine (loaded, sized,
 * its acceleration structure built and packed), then a frame rendered or a batch of rays traced in
 * one of the modes.
 *
 * `sfsim run` (sim/render.c), `sfsim trace` (sim/trace.c), tools/validation.c and bench/ go through
 * these calls; the pieces behind them are sim/run/spec.c (the modes, RunSpec and its defaults),
 * sim/run/accel.c (the structures), sim/run/kernel.c (the kernel build), sim/run/tiles.c (the tile
 * launcher), sim/run/timedcore.c (a core with its timing model: the kernel modes' workers and
 * `sfsim exec`), sim/run/engine.c (the kernel engine), sim/run/sampled.c (sampled mode's frame),
 * sim/reference.c and sim/ref_trace.c (the golden model).
 *
 * Owns: the opened scene (and its shared image), choosing the engine for a mode, and the figures
 * common to all modes. Must not: write files (render.c and trace.c do), parse the command line, or
 * render itself. Nothing it calls calls it back: the engines get what they need as arguments.
 */
#ifndef SFSIM_RUN_RUN_H
#define SFSIM_RUN_RUN_H

#include <stddef.h>
#include <stdint.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../config.h"
#include "../core.h"
#include "../raybatch.h"
#include "../sampling.h"
#include "../stats.h"
#include "../timing.h"
#include "accel.h"
#include "engine.h"
#include "spec.h"

/* The render size a caller imposes over the scene file's [render]; -1 (or 0 for the sizes) keeps
 * the scene's value. */
typedef struct RunSize {
    int width, height, spp, max_depth;
} RunSize;
#define RUN_SIZE_KEEP ((RunSize){-1, -1, -1, -1})

/* A scene opened for one machine. */
typedef struct RunScene {
    Scene s;
    PackedScene p;
    AccelInfo accel;           /* what was built, and its host time */
    double load_seconds;       /* reading the scene file */
    /* p's bytes as one shared image (a sealed memfd, sim/core.h) that the kernel modes' cores map
     * instead of each copying them (26 MB on the conference room); NULL for the golden model, or
     * when the host has no memfd (the cores copy). The scene owns it: whoever starts cores on p is
     * passed it (FuncParams.image, run_trace's image) and p's bytes must not change while it lives. */
    CoreImage *image;
} RunScene;

/* Load path, print the scene's warnings on stderr as "<who>: warning: ..." (who NULL: not printed;
 * they stay in s.warnings), impose size and check the render settings a frame needs (size NULL: the
 * scene as it is, for ray batches, which have no frame), and build and pack
 * the acceleration structures of cfg (NULL: the defaults) for the engines of mode. 0, or -1 with a
 * message naming the file or the setting; sc must be closed with run_scene_close either way. */
int run_scene_open(RunScene *sc, const char *path, const RunSize *size, const CfgMachine *cfg, RunMode mode,
                   const char *who, char *err, size_t errlen);
void run_scene_close(RunScene *sc);

/* A rendered frame and its figures. */
typedef struct RunFrame {
    float *rgb;                /* 3 x width x height, linear radiance */
    StatsRun run;              /* rays and generations, from either engine */
    FuncStats f;               /* the kernel modes' counters (zero for the golden model) */
    SampleEstimate est;        /* RUN_SAMPLED: the frame's cycles estimated from the sample */
    SampleEstimate est_instructions; /* ... and its instructions */
    int has_est;
    uint32_t units_sampled;    /* RUN_SAMPLED: units timed */
    uint32_t rounds;           /* RUN_SAMPLED: rounds of the sequential rule */
    double golden_seconds;     /* RUN_SAMPLED: host time of the golden model (image and counts) */
    double *tile_cycles;       /* RUN_SAMPLED: each tile's estimated cycles (f.ntiles entries) */
    StatsChipSample chip;      /* RUN_SAMPLED on a chip */
    int tile;                  /* the stream's tile side for the golden model: sqrt(stream.rays) */
    int threads;               /* host threads used */
    double seconds;            /* host time rendering */
} RunFrame;

/* Render sc's frame as spec says. spec must hold what the commands check once (sim/cli/runopts.c)
 * and this asserts: a mode; RUN_REFERENCE and RUN_SAMPLED on a workload with a golden model
 * (run_workload_golden); in RUN_SAMPLED a target error in [0, 1) and, without one, a sample
 * fraction in (0, 1]; no target error and no no_image in the other modes. 0; -1 with a message
 * (a kernel that does not assemble, memories too small, too few tiles to estimate from); -2 when
 * the simulated program
 * failed in a tile: then fr->rgb holds the tiles that finished (fr->f.tiles_done of fr->f.ntiles)
 * and the rest black. fr must be freed with run_frame_free either way. */
int run_frame(const RunScene *sc, const RunSpec *spec, RunFrame *fr, char *err, size_t errlen);
void run_frame_free(RunFrame *fr);

/* A traced batch's figures. */
typedef struct RunTrace {
    uint64_t instructions;     /* simulated (the kernel modes) */
    int timed;                 /* RUN_DETAILED: timing holds the cycles of every batch */
    TimingStats timing;
    uint32_t cores, cores_used; /* RUN_DETAILED on a chip: its cores, those that got a batch; else 0 */
    uint64_t makespan;         /* ... the cycle its last core finished (timing: the batches' cycles summed) */
    double seconds;            /* host time tracing */
} RunTrace;

/* Trace batch b against p (a scene of needs) as spec says: RUN_REFERENCE (the golden model),
 * RUN_FUNCTIONAL or RUN_DETAILED (the kernel's traversal and intersection; asserted: a batch has
 * no units to sample); hits[i] for ray i.
 * image: p's shared image (an open scene's RunScene.image) for the kernel's cores to map, or NULL
 * (they copy p's bytes; the results are the same). 0, -1 (input) or -2 (the kernel failed). out
 * may be NULL. */
int run_trace(const PackedScene *p, const CoreImage *image, uint32_t needs, const RunSpec *spec, const RayBatch *b,
              BatchHit *hits, RunTrace *out, char *err, size_t errlen);

#endif
