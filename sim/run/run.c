/* sim/run/run.c -- the entry point of every simulation (run.h): a scene opened for a machine, then
 * a frame or a ray batch in one of the modes.
 *
 * Owns: the opened scene and its shared image, the render size's checks, the engine for each mode.
 * The options were checked once by the commands (sim/cli/runopts.c): here they are asserted.
 * Must not: write files, or render or trace itself (sim/run/engine.c, sim/reference.c and
 * sim/ref_trace.c do).
 */
#include "run.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../reference.h"
#include "../ref_trace.h"
#include "../util.h"
#include "chipsampled.h"
#include "sampled.h"

/* The caller's size over the scene's [render], and the ranges a frame needs. */
static int impose_size(Scene *s, const RunSize *z, char *err, size_t errlen)
{
    if (z->width > 0)
        s->render.width = z->width;
    if (z->height > 0)
        s->render.height = z->height;
    if (z->spp > 0)
        s->render.spp = z->spp;
    if (z->max_depth >= 0)
        s->render.max_depth = z->max_depth;
    if (s->render.width < 1 || s->render.height < 1 || s->render.width > 16384 || s->render.height > 16384) {
        snprintf(err, errlen, "render size %d x %d out of range (1..16384)", s->render.width, s->render.height);
        return -1;
    }
    if (s->render.spp < 1 || s->render.spp > 1 << 20) {
        snprintf(err, errlen, "render.spp %d out of range (1..1048576)", s->render.spp);
        return -1;
    }
    if (s->render.max_depth < 0 || s->render.max_depth >= REF_MAX_GENERATIONS) {
        snprintf(err, errlen, "render.max_depth %d out of range (0..%d)", s->render.max_depth,
                 REF_MAX_GENERATIONS - 1);
        return -1;
    }
    /* The loader checked the camera's ray lengths at the scene's own size; an imposed aspect can
     * lengthen them (docs/scenes.md, "Limits of scene values"). */
    char why[400];
    if ((z->width > 0 || z->height > 0) &&
        scene_camera_view_check(&s->camera, s->render.width, s->render.height, why, sizeof why) != 0) {
        snprintf(err, errlen, "%s: the camera at %d x %d: %s", s->source, s->render.width, s->render.height, why);
        return -1;
    }
    return 0;
}

int run_scene_open(RunScene *sc, const char *path, const RunSize *size, const CfgMachine *cfg, RunMode mode,
                   const char *who, char *err, size_t errlen)
{
    memset(sc, 0, sizeof *sc);
    CfgMachine defcfg;
    if (!cfg) {
        cfg_defaults(&defcfg);
        cfg = &defcfg;
    }
    double t0 = util_now();
    if (scene_load(path, &sc->s, err, errlen) != 0)
        return -1;
    for (uint32_t i = 0; who && i < sc->s.nwarnings; i++) /* what the scene left out (docs/scenes.md) */
        fprintf(stderr, "%s: warning: %s\n", who, sc->s.warnings[i]);
    if (size && impose_size(&sc->s, size, err, errlen) != 0)
        return -1;
    sc->load_seconds = util_now() - t0;
    if (accel_pack(&sc->s, cfg, run_mode_kernel(mode), &sc->p, &sc->accel, err, errlen) != 0)
        return -1;
    /* The kernel modes start cores that each load the packed scene: one shared image spares them
     * the copy. Without a memfd the image would only copy, as the cores do without one. */
    if (run_mode_kernel(mode) && !core_image_shared(sc->image = core_image_new(sc->p.mem, sc->p.size, 0))) {
        core_image_free(sc->image);
        sc->image = NULL;
    }
    return 0;
}

void run_scene_close(RunScene *sc)
{
    core_image_free(sc->image);
    pack_free(&sc->p);
    scene_free(&sc->s);
    memset(sc, 0, sizeof *sc);
}

/* The golden model's frame. */
static int golden_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, RunFrame *fr, char *err,
                        size_t errlen)
{
    assert(run_workload_golden(cfg)); /* spec_holds */
    RefParams rp = {.tile = fr->tile, .seed = spec->seed, .threads = fr->threads, .progress = spec->progress,
                    .progress_ctx = spec->progress_ctx, .bounces = cfg->workload_bounces,
                    .workload = cfg->workload_kind == CFG_WORKLOAD_PHONG ? REF_WORKLOAD_PHONG : REF_WORKLOAD_PATH};
    RefStats st;
    if (ref_render(&sc->p, &rp, fr->rgb, &st, err, errlen) != 0)
        return -1;
    stats_run_from_ref(&fr->run, &st);
    return 0;
}

/* The kernel's frame, timed as the mode says. */
static int kernel_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, RunFrame *fr, char *err,
                        size_t errlen)
{
    char kpath[4200];
    FuncParams fp = {.cfg = cfg,
                     .kernel_path = run_spec_kernel(spec, kpath, sizeof kpath),
                     .image = sc->image,
                     .needs = sc->s.needs,
                     .seed = spec->seed,
                     .threads = fr->threads,
                     .progress = spec->progress,
                     .progress_ctx = spec->progress_ctx,
                     .timed = run_mode_timed(spec->mode),
                     .mem_trace = spec->mode == RUN_DETAILED && spec->mem_trace,
                     .timeline = spec->mode == RUN_DETAILED ? spec->timeline : NULL};
    if (spec->mode == RUN_SAMPLED && chipsampled_wanted(cfg))
        return chipsampled_frame(sc, spec, cfg, &fp, fr, err, errlen);
    if (spec->mode == RUN_SAMPLED)
        return sampled_frame(sc, spec, cfg, &fp, fr, err, errlen);
    int rc = func_render(&sc->p, &fp, fr->rgb, &fr->f, err, errlen);
    if (rc != 0)
        return rc;
    stats_run_from_func(&fr->run, &fr->f);
    return 0;
}

/* What the commands' one check of the options guarantees (sim/cli/runopts.c) and every other
 * caller must hold too (run.h, run_frame). */
static int spec_holds(const RunSpec *spec, const CfgMachine *cfg)
{
    if ((unsigned)spec->mode >= RUN_MODE_COUNT || (cfg->stream_rays != 1024 && cfg->stream_rays != 4096))
        return 0;
    if (spec->mode != RUN_SAMPLED)
        return spec->target_error == 0.0 && !spec->no_image && (spec->mode != RUN_REFERENCE || run_workload_golden(cfg));
    return run_workload_golden(cfg) && spec->target_error >= 0.0 && spec->target_error < 1.0 &&
           (spec->target_error > 0.0 || (spec->sample > 0.0 && spec->sample <= 1.0));
}

int run_frame(const RunScene *sc, const RunSpec *spec, RunFrame *fr, char *err, size_t errlen)
{
    memset(fr, 0, sizeof *fr);
    CfgMachine defcfg;
    const CfgMachine *cfg = run_spec_machine(spec, &defcfg);
    int holds = spec_holds(spec, cfg); /* (a build with NDEBUG still uses the function) */
    assert(holds);
    (void)holds;
    size_t npx = (size_t)sc->s.render.width * (size_t)sc->s.render.height;
    fr->rgb = calloc(3 * npx, sizeof(float));
    if (!fr->rgb) {
        snprintf(err, errlen, "out of memory for a %d x %d image", sc->s.render.width, sc->s.render.height);
        return -1;
    }
    fr->threads = run_spec_threads(spec);
    fr->tile = (int)lrint(sqrt((double)cfg->stream_rays));
    double t0 = util_now();
    int rc = run_mode_kernel(spec->mode) ? kernel_frame(sc, spec, cfg, fr, err, errlen)
                                         : golden_frame(sc, spec, cfg, fr, err, errlen);
    fr->seconds = util_now() - t0;
    return rc;
}

void run_frame_free(RunFrame *fr)
{
    free(fr->rgb);
    free(fr->tile_cycles);
    func_stats_free(&fr->f);
    memset(fr, 0, sizeof *fr);
}

/* The golden model's answer for each ray of the batch. */
static void golden_trace(const PackedScene *p, const RayBatch *b, BatchHit *hits)
{
    for (uint32_t i = 0; i < b->count; i++) {
        const BatchRay *r = &b->rays[i];
        BatchHit *h = &hits[i];
        memset(h, 0, sizeof *h);
        h->invalid = (uint32_t)raybatch_ray_invalid(r);
        if (h->invalid) {
            h->prim = r->query == RAY_ANY ? 0 : UINT32_MAX;
            continue;
        }
        RefRay q = {{r->org[0], r->org[1], r->org[2]}, {r->dir[0], r->dir[1], r->dir[2]}, r->tmax};
        if (r->query == RAY_ANY) {
            h->prim = (uint32_t)ref_any_hit(p, &q, NULL);
        } else {
            RefHit rh;
            ref_closest_hit(p, &q, &rh, NULL);
            h->prim = rh.prim;
            if (rh.prim != REF_NO_HIT) {
                h->t = rh.t;
                h->u = rh.u;
                h->v = rh.v;
            }
        }
    }
}

int run_trace(const PackedScene *p, const CoreImage *image, uint32_t needs, const RunSpec *spec, const RayBatch *b,
              BatchHit *hits, RunTrace *out, char *err, size_t errlen)
{
    RunTrace local;
    if (!out)
        out = &local;
    memset(out, 0, sizeof *out);
    double t0 = util_now();
    if (spec->mode == RUN_REFERENCE) {
        golden_trace(p, b, hits);
        out->seconds = util_now() - t0;
        return 0;
    }
    assert(spec->mode == RUN_FUNCTIONAL || spec->mode == RUN_DETAILED);
    CfgMachine defcfg;
    const CfgMachine *cfg = run_spec_machine(spec, &defcfg);
    char kpath[4200];
    FuncParams fp = {.cfg = cfg,
                     .kernel_path = run_spec_kernel(spec, kpath, sizeof kpath),
                     .image = image,
                     .needs = needs,
                     .seed = spec->seed ? spec->seed : 1,
                     .threads = spec->threads,
                     .batch = b,
                     .hits = hits,
                     .timed = spec->mode == RUN_DETAILED};
    FuncStats st;
    int rc = func_trace(p, &fp, &st, err, errlen);
    out->seconds = util_now() - t0;
    if (rc == 0) {
        out->instructions = st.instructions;
        out->timed = fp.timed;
        out->timing = st.timing;
        out->cores = st.chip_cores;
        out->makespan = st.makespan;
        for (uint32_t k = 0; k < st.chip_cores; k++)
            out->cores_used += st.cores[k].tiles > 0;
    }
    func_stats_free(&st);
    return rc;
}
