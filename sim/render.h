/* sim/render.h -- one `sfsim run`: load the scene, pack it, render, write the images and the
 * report into the output folder.
 *
 * Owns: the orchestration of a run and the files it writes (frame.exr, frame.png, report.json,
 * report.txt, cost.png; frame.partial.exr when the kernel fails). Must not: implement a renderer or parse the command line.
 */
#ifndef SFSIM_RENDER_H
#define SFSIM_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include "run/run.h"

typedef struct RenderOptions {
    const char *scene_path;    /* .gltf/.glb or scene.ini */
    const char *out_dir;       /* created if missing, once there is something to write */
    uint32_t seed;
    int threads;               /* host threads; 0 = all cores */
    int width, height, spp, max_depth; /* overrides of the scene's [render]; -1 = keep */
    float exposure;            /* for frame.png */
    int progress;              /* 1: progress bar on stderr (the CLI sets it when stderr is a tty) */
    RunMode mode;              /* parsed once, by the command line (run_mode_parse) */
    const struct CfgMachine *cfg; /* the machine (functional mode; NULL: defaults) */
    const char *config_path;   /* the -c file as given, for the report; NULL: the built-in defaults */
    const char *kernel_path;   /* kernel modes: the kernel source (NULL: next to the binary) */
    double sample;             /* sampled mode: a fixed fraction of the units timed, (0, 1], when */
    double target_error;       /* ... target_error is 0; else the 95 % half-width wanted (0.01 = 1 %) */
    uint32_t sample_seed;      /* sampled mode: which units */
    int no_image;              /* sampled mode: no image, a pilot of the golden model for the counts */
    const char *mem_trace;     /* detailed mode: write the L1s' requests below here (docs/chip.md), or NULL */
    const char *timeline;      /* detailed mode: write the timeline of cycles [timeline_from, timeline_to)
                                  here (docs/timeline.md), or NULL */
    uint64_t timeline_from, timeline_to;
} RenderOptions;

/* The render keys `--set` takes beside the machine keys (sfsim run, sfsim sweep), with their
 * ranges: one table for every command that accepts them. */
enum { RENDER_KEY_WIDTH, RENDER_KEY_HEIGHT, RENDER_KEY_SPP, RENDER_KEY_MAX_DEPTH, RENDER_KEY_SEED, RENDER_KEY_COUNT };
typedef struct RenderKey {
    const char *key;       /* "render.width" */
    long long lo, hi;
} RenderKey;
extern const RenderKey render_keys[RENDER_KEY_COUNT];

void render_default_options(RenderOptions *o);

/* A run in o->mode: "reference" (the golden model, sim/reference.c) or "functional" (the
 * kernel on functional cores, sim/run/engine.c). 0, or -1 with a message naming the file or
 * the setting at fault; -2 when the simulated program failed (trap, instruction limit); -3 when
 * an output could not be written (the folder checked before any work, a full disk, ...). Outputs
 * are written whole or not at all (host/outfile.h): after a failure no file of this run is left
 * under a final name, except a kernel failure's frame.partial.exr and "failed" report.json. */
int render_run(const RenderOptions *o, char *err, size_t errlen);

#endif
