/* sim/report.c -- what `sfsim run` says about a run: report.json, report.txt and stats.txt
 * (docs/report.md).
 *
 * Owns: the blocks that describe the run (mode, what made it, scene, config, render, kernel,
 * kd-tree, image, host), report.txt's lines for them and stats.txt's header. The statistics themselves come from the registry's walk
 * (sim/stats.def, sim/stats.c). Must not: run anything, or write files (sim/render.c does).
 */
#include "report.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../host/version.h"
#include "provenance.h"
#include "stats.h"

/* A SAH cost for report.txt: "%.2f", or why there is none (a cost is a ratio of surface areas,
 * undefined when the scene's bounds are not finite). */
static const char *sah_text(double cost, char *buf, size_t len)
{
    if (isfinite(cost))
        snprintf(buf, len, "%.2f", cost);
    else
        snprintf(buf, len, "n/a (the scene's bounding box is not finite)");
    return buf;
}

/* The same for report.json: a number, or null (JSON has no NaN or infinity). */
static void add_sah_json(cJSON *o, double cost)
{
    if (isfinite(cost))
        cJSON_AddNumberToObject(o, "sah_cost", cost);
    else
        cJSON_AddNullToObject(o, "sah_cost");
}

/* The object name of root, made if the statistics walk did not make it. */
static cJSON *object_of(cJSON *root, const char *name)
{
    cJSON *o = cJSON_GetObjectItemCaseSensitive(root, name);
    return o ? o : cJSON_AddObjectToObject(root, name);
}

/* accel.structure = kd: the tree and the traversal (the kernel's counters: sim/stats.def). */
static void add_kd_json(cJSON *root, const Report *r)
{
    const CfgMachine *cfg = r->cfg;
    const AccelKdInfo *t = &r->sc->accel.kd;
    cJSON *kd = object_of(root, "kd");
    cJSON_AddStringToObject(kd, "structure", cfg_enum_name("accel", "structure", cfg->accel_structure));
    cJSON_AddStringToObject(kd, "traversal", cfg_enum_name("kd", "traversal", cfg->kd_traversal));
    cJSON_AddNumberToObject(kd, "stack_depth", r->fr->f.kd_stack_depth);
    cJSON *tr = cJSON_AddObjectToObject(kd, "tree");
    cJSON_AddNumberToObject(tr, "nodes", t->nodes);
    cJSON_AddNumberToObject(tr, "leaves", t->leaves);
    cJSON_AddNumberToObject(tr, "empty_leaves", t->empty_leaves);
    cJSON_AddNumberToObject(tr, "depth", t->depth);
    cJSON_AddNumberToObject(tr, "primitives", t->prims);
    cJSON_AddNumberToObject(tr, "references", t->refs);
    cJSON_AddNumberToObject(tr, "references_per_primitive", stats_ratio(t->refs, t->prims));
    cJSON_AddNumberToObject(tr, "largest_leaf", t->largest_leaf);
    add_sah_json(tr, t->sah_cost);
    cJSON_AddNumberToObject(tr, "build_seconds", t->build_seconds);
}

/* accel.structure = kd: report.txt's line for the tree (the counters per ray: sim/stats.def). */
static int kd_text(char *txt, size_t cap, const Report *r)
{
    const CfgMachine *cfg = r->cfg;
    const AccelKdInfo *t = &r->sc->accel.kd;
    char sah[64];
    return snprintf(txt, cap,
                    "kd-tree      %s traversal, stack depth %u; %u nodes, %u leaves (%u empty), depth %u, "
                    "%.2f references per primitive, largest leaf %u, SAH cost %s; built in %.2f s\n",
                    cfg_enum_name("kd", "traversal", cfg->kd_traversal), r->fr->f.kd_stack_depth, t->nodes, t->leaves,
                    t->empty_leaves, t->depth, stats_ratio(t->refs, t->prims), t->largest_leaf,
                    sah_text(t->sah_cost, sah, sizeof sah), t->build_seconds);
}

/* Kernel modes: the kernel that ran (its statistics: sim/stats.def). */
static void add_kernel_json(cJSON *root, const FuncStats *f, const CfgMachine *cfg)
{
    cJSON *k = cJSON_AddObjectToObject(root, "kernel");
    cJSON_AddStringToObject(k, "stream_mode", cfg_enum_name("stream", "mode", cfg->stream_mode));
    cJSON_AddStringToObject(k, "workload", cfg_enum_name("workload", "kind", cfg->workload_kind));
    if (cfg->workload_kind == CFG_WORKLOAD_SPECULAR || cfg->workload_kind == CFG_WORKLOAD_PHONG)
        cJSON_AddNumberToObject(k, "bounces", cfg->workload_bounces);
    cJSON_AddNumberToObject(k, "tile_width", f->tile_w);
    cJSON_AddNumberToObject(k, "tile_height", f->tile_h);
    cJSON_AddStringToObject(k, "defines", f->defines);
    cJSON_AddNumberToObject(k, "unroll_box", f->unroll_box); /* resolved: config's kernel.unroll_box may be 0, auto */
    cJSON_AddNumberToObject(k, "instructions", f->kernel_instructions);
}

/* Sampled mode: how the sample was drawn and estimated (its figures: sim/stats.def). */
static void add_sample_json(cJSON *root, const RenderOptions *o, const RunFrame *fr)
{
    cJSON *sm = object_of(root, "sample");
    if (o->target_error > 0.0)
        cJSON_AddNumberToObject(sm, "target_error", o->target_error);
    else
        cJSON_AddNumberToObject(sm, "fraction", o->sample);
    cJSON_AddNumberToObject(sm, "seed", o->sample_seed);
    cJSON_AddStringToObject(sm, "unit", "one pass of one tile");
    cJSON_AddStringToObject(sm, "estimator", "regression on the golden model's SIMD-step counts (docs/sampling.md)");
    cJSON_AddNumberToObject(sm, "auxiliaries", fr->est.k);
    cJSON_AddNumberToObject(sm, "confidence", 0.95);
    cJSON_AddBoolToObject(sm, "image", !o->no_image);
    cJSON_AddNumberToObject(sm, "golden_seconds", fr->golden_seconds);
}

static uint64_t report_rays(const Report *r) { return r->fr->run.primary + r->fr->run.shadow + r->fr->run.indirect; }

/* The statistics walk's view of the run (sim/stats.h). */
static StatsCtx stats_ctx(const Report *r)
{
    static const unsigned mode_bit[RUN_MODE_COUNT] = {
        [RUN_REFERENCE] = STATS_M_REF, [RUN_FUNCTIONAL] = STATS_M_FUNC, [RUN_DETAILED] = STATS_M_DET,
        [RUN_SAMPLED] = STATS_M_SAMP};
    int kernel = run_mode_kernel(r->mode);
    StatsCtx c = {.mode = mode_bit[r->mode] | (kernel && r->fr->f.kd ? STATS_M_KD : 0) |
                          (kernel && (r->fr->f.chip_cores || r->fr->chip.on) ? STATS_M_CHIP : 0) |
                          (kernel && (r->fr->f.chip_mem || (r->fr->chip.on && r->fr->chip.shared)) ? STATS_M_SHARED : 0),
                  .cfg = r->cfg, .run = &r->fr->run, .f = kernel ? &r->fr->f : NULL,
                  .t = run_mode_timed(r->mode) ? &r->fr->f.timing : NULL,
                  .est = r->fr->has_est ? &r->fr->est : NULL,
                  .est_instructions = r->fr->has_est ? &r->fr->est_instructions : NULL, .rounds = r->fr->rounds,
                  .chip_sample = r->fr->chip.on ? &r->fr->chip : NULL,
                  .energy = r->has_energy ? &r->energy : NULL};
    return c;
}

int report_energy(Report *r, char *err, size_t errlen)
{
    r->has_energy = 0;
    if (!run_mode_timed(r->mode))
        return 0;
    /* A sampled chip with shared memory: its units ran alone, so the L2's, the network's and DRAM's
     * events of the frame are not estimated yet (docs/energy.md, "Sampled mode"): no energy rather
     * than a part of it (the figures read null). */
    if (r->fr->chip.on && r->cfg->chip_memory == CFG_CHIP_MEMORY_SHARED)
        return 0;
    StatsCtx sx = stats_ctx(r);
    const StatsFrame fr = stats_frame_of(&sx);
    const double hz = r->cfg->core_clock_mhz * 1e6;
    const FuncStats *f = &r->fr->f;
    EnergyInput in = {.cfg = r->cfg, .f = f, .seconds = fr.cycles / hz, .scale = 1, .rays = (double)report_rays(r)};
    if (sx.est_instructions && f->instructions > 0) {
        /* Sampled mode: the counted events are the sampled units'; the frame's are estimated as its
         * instructions are (docs/energy.md, "Sampled mode"). */
        const double k = (double)f->instructions;
        in.scale = sx.est_instructions->total / k;
        in.scale_lo = sx.est_instructions->lo / k;
        in.scale_hi = sx.est_instructions->hi / k;
        in.seconds_lo = fr.cycles_lo / hz;
        in.seconds_hi = fr.cycles_hi / hz;
    }
    if (energy_compute(&in, &r->energy, err, errlen) != 0)
        return -1;
    r->has_energy = 1;
    return 0;
}

/* report.json (docs/report.md); NULL when out of memory. */
cJSON *report_json(const Report *r)
{
    const RenderOptions *o = r->o;
    const CfgMachine *cfg = r->cfg;
    const Scene *sp = &r->sc->s;
    const PackedScene *pp = &r->sc->p;
    const RunFrame *rsp = r->fr;
    int functional = run_mode_kernel(r->mode), sampled = r->mode == RUN_SAMPLED, threads = r->fr->threads;
    double secs = r->fr->seconds;
    uint64_t total_rays = report_rays(r);
    /* report.json: the names of ARCHITECTURE.md Sec. 1. The statistics come from the registry
     * (sim/stats.def; the timing fields are null unless timed); the blocks below describe the run. */
    StatsCtx sx = stats_ctx(r);
    cJSON *root = cJSON_CreateObject();
    /* What made the run (sim/provenance.h): it changes with every run, so the same-outputs digest
     * leaves the whole object out (tools/outputs_digest.c). */
    cJSON *made = root && cJSON_AddStringToObject(root, "mode", run_mode_names[o->mode]) ? cJSON_AddObjectToObject(root, "run") : NULL;
    if (!made || prov_json(made) != 0 || !cJSON_AddNumberToObject(made, "threads", threads) || stats_json(root, &sx) != 0) {
        cJSON_Delete(root);
        return NULL;
    }
    if (functional)
        add_kernel_json(root, &rsp->f, cfg);
    if (sampled)
        add_sample_json(root, o, rsp);
    if (functional && rsp->f.kd)
        add_kd_json(root, r);
    cJSON *sc = cJSON_AddObjectToObject(root, "scene");
    cJSON_AddStringToObject(sc, "file", o->scene_path);
    cJSON_AddNumberToObject(sc, "triangles", sp->ntris);
    cJSON_AddNumberToObject(sc, "spheres", sp->nspheres);
    cJSON_AddNumberToObject(sc, "lights", pp->nlights);
    char needs[256];
    scene_needs_string(sp->needs, needs, sizeof needs);
    cJSON *nd = cJSON_AddArrayToObject(sc, "needs");
    char needs_tok[256];
    memcpy(needs_tok, needs, sizeof needs_tok);
    for (char *save = NULL, *tok = strtok_r(needs_tok, ",", &save); tok; tok = strtok_r(NULL, ",", &save))
        cJSON_AddItemToArray(nd, cJSON_CreateString(tok));
    cJSON *bvh = cJSON_AddObjectToObject(sc, "bvh");
    cJSON_AddNumberToObject(bvh, "nodes", pp->bvh.nnodes);
    cJSON_AddNumberToObject(bvh, "leaves", pp->bvh.nleaves);
    cJSON_AddNumberToObject(bvh, "depth", pp->bvh.depth);
    add_sah_json(bvh, pp->bvh.sah_cost);
    cJSON_AddNumberToObject(bvh, "leaf_size", r->cfg->bvh_leaf_size);
    cJSON_AddNumberToObject(bvh, "bins", r->cfg->bvh_bins);
    cJSON_AddNumberToObject(sc, "scene_memory_bytes", pp->size);
    cJSON_AddNumberToObject(sc, "skipped_primitives", sp->skipped_primitives);
    cJSON *warn = cJSON_AddArrayToObject(sc, "warnings");
    for (uint32_t i = 0; i < sp->nwarnings; i++)
        cJSON_AddItemToArray(warn, cJSON_CreateString(sp->warnings[i]));
    /* The machine: every key of sim/config.def as used, in every mode (docs/report.md). */
    cJSON_AddStringToObject(root, "config_file", o->config_path ? o->config_path : "built-in");
    cfg_json(cfg, cJSON_AddObjectToObject(root, "config"));
    cJSON *ren = cJSON_AddObjectToObject(root, "render");
    cJSON_AddNumberToObject(ren, "width", sp->render.width);
    cJSON_AddNumberToObject(ren, "height", sp->render.height);
    cJSON_AddNumberToObject(ren, "spp", sp->render.spp);
    cJSON_AddNumberToObject(ren, "max_depth", sp->render.max_depth);
    cJSON_AddNumberToObject(ren, "seed", o->seed);
    cJSON_AddNumberToObject(ren, "stream_rays", cfg->stream_rays);
    int tile_w = functional ? (int)rsp->f.tile_w : r->fr->tile, tile_h = functional ? (int)rsp->f.tile_h : r->fr->tile;
    cJSON_AddNumberToObject(ren, "tile", tile_w);
    cJSON_AddNumberToObject(ren, "tile_height", tile_h);
    cJSON *im = cJSON_AddObjectToObject(root, "image");
    cJSON_AddNumberToObject(im, "mean", r->mean);
    cJSON_AddNumberToObject(im, "nonfinite", (double)r->nonfinite);
    cJSON *host = cJSON_AddObjectToObject(root, "host");
    cJSON_AddNumberToObject(host, "seconds", secs);
    cJSON_AddNumberToObject(host, "load_seconds", r->sc->load_seconds);
    cJSON_AddNumberToObject(host, "bvh_pack_seconds", r->sc->accel.pack_seconds);
    cJSON_AddNumberToObject(host, "threads", threads);
    cJSON_AddNumberToObject(host, "rays_per_second", secs > 0 ? (double)total_rays / secs : 0.0);
    if (functional) {
        cJSON_AddNumberToObject(host, "sim_instructions", (double)rsp->f.instructions);
        cJSON_AddNumberToObject(host, "instructions_per_second", secs > 0 ? (double)rsp->f.instructions / secs : 0.0);
    }
    return root;
}

/* report.txt (docs/report.md) into txt. */
void report_txt(const Report *r, char *txt, size_t cap)
{
    const RenderOptions *o = r->o;
    const CfgMachine *cfg = r->cfg;
    const Scene *sp = &r->sc->s;
    const PackedScene *pp = &r->sc->p;
    const RunFrame *rsp = r->fr;
    int detailed = r->mode == RUN_DETAILED, sampled = r->mode == RUN_SAMPLED, functional = run_mode_kernel(r->mode);
    int threads = r->fr->threads;
    double secs = r->fr->seconds;
    uint64_t total_rays = report_rays(r);
    StatsCtx sx = stats_ctx(r);
    char needs[256];
    scene_needs_string(sp->needs, needs, sizeof needs);
    int tile_w = functional ? (int)rsp->f.tile_w : r->fr->tile, tile_h = functional ? (int)rsp->f.tile_h : r->fr->tile;
    /* The tiles the image was cut into: a partial tile is said, since the tile size alone would
     * suggest more pixels than there are. */
    char tiles_txt[160], sah[64];
    int tiles_x = (sp->render.width + tile_w - 1) / tile_w, tiles_y = (sp->render.height + tile_h - 1) / tile_h;
    if (tiles_x * tiles_y == 1 && (sp->render.width < tile_w || sp->render.height < tile_h))
        snprintf(tiles_txt, sizeof tiles_txt, "one partial tile (tiles are %d x %d pixels)", tile_w, tile_h);
    else
        snprintf(tiles_txt, sizeof tiles_txt, "%d tile%s of %d x %d pixels%s", tiles_x * tiles_y,
                 tiles_x * tiles_y == 1 ? "" : "s", tile_w, tile_h,
                 sp->render.width % tile_w && sp->render.height % tile_h ? ", the last column and row partial"
                 : sp->render.width % tile_w                           ? ", the last column partial"
                 : sp->render.height % tile_h                          ? ", the last row partial"
                                                                     : "");
    const char *thr = threads == 1 ? "thread" : "threads";
    int len = snprintf(txt, cap,
             "sfsim report -- mode %s (%s)\n"
             "run          sfsim %s (commit %s), started %s on %s, %d host %s\n"
             "command      %s\n"
             "             in %s\n"
             "scene        %s\n"
             "             %u triangles, %u spheres, %u lights; needs: %s\n"
             "             BVH %u nodes, %u leaves, depth %u, SAH cost %s; %u bytes of scene memory\n"
             "config       %s\n"
             "image        %d x %d, %d spp, max depth %d, seed %u, %s\n"
             "             mean %.5f, non-finite values %ld\n",
             run_mode_names[o->mode],
             detailed     ? "the kernel on the timing model of the machine"
             : sampled    ? "the golden model's image; sampled (tile, pass) units on the timed kernel, the frame's cycles estimated"
             : functional ? "the kernel on the functional core: no timing"
                          : "golden model: no timing",
             version_string(), version_commit(), prov_date(), prov_host()[0] ? prov_host() : "an unnamed host", threads,
             thr, prov_argc() ? prov_command() : "(none: not run from sfsim's command line)",
             prov_cwd()[0] ? prov_cwd() : "(a folder that could not be read)", o->scene_path, sp->ntris, sp->nspheres, pp->nlights, needs[0] ? needs : "-", pp->bvh.nnodes,
             pp->bvh.nleaves, pp->bvh.depth, sah_text(pp->bvh.sah_cost, sah, sizeof sah), pp->size,
             o->config_path ? o->config_path : "built-in (the defaults of sim/config.def)", sp->render.width,
             sp->render.height, sp->render.spp, sp->render.max_depth, o->seed, tiles_txt, r->mean,
             r->nonfinite);
    if (sp->skipped_primitives)
        len += snprintf(txt + len, cap - (size_t)len, "skipped      %u glTF primitives that are not triangles\n",
                        sp->skipped_primitives);
    for (uint32_t i = 0; i < sp->nwarnings && len < (int)cap; i++)
        len += snprintf(txt + len, cap - (size_t)len, "warning      %s\n", sp->warnings[i]);
    if (len >= (int)cap) /* (truncated: the writes below stay inside txt) */
        len = (int)cap - 1;
    if (functional) {
        const FuncStats *f = &rsp->f;
        len += snprintf(txt + len, cap - (size_t)len,
                        "machine      N = %d lanes, %s of %u x %u rays, workload %s; kernel %u instructions (%s), "
                        "kernel.unroll_box %d%s\n",
                        cfg->core_simd_width, cfg->stream_mode == CFG_STREAM_MODE_PACKET ? "packets" : "streams",
                        f->tile_w, f->tile_h, cfg_enum_name("workload", "kind", cfg->workload_kind),
                        f->kernel_instructions, f->defines, f->unroll_box,
                        cfg->kernel_unroll_box == 0 ? " (0, auto)" : "");
        if (f->kd)
            len += kd_text(txt + len, cap - (size_t)len, r);
    }
    if (len >= (int)cap)
        len = (int)cap - 1;
    size_t tlen = (size_t)len;   /* the statistics: sim/stats.def */
    stats_text(txt, cap, &tlen, &sx);
    len = (int)tlen;
    if (functional)
        len += snprintf(txt + len, cap - (size_t)len,
                        "host         %.2f s on %d %s: %.2f M instructions/s, %.3f M rays/s; load %.2f s, BVH+pack %.2f s\n",
                        secs, threads, thr, secs > 0 ? 1e-6 * (double)rsp->f.instructions / secs : 0.0,
                        secs > 0 ? 1e-6 * (double)total_rays / secs : 0.0, r->sc->load_seconds, r->sc->accel.pack_seconds);
    else
        len += snprintf(txt + len, cap - (size_t)len,
                        "host         %.2f s rendering on %d %s (%.3f M rays/s); load %.2f s, BVH+pack %.2f s\n", secs,
                        threads, thr, secs > 0 ? 1e-6 * (double)total_rays / secs : 0.0, r->sc->load_seconds, r->sc->accel.pack_seconds);
}


/* stats.txt (docs/report.md): a comment naming the sfsim that wrote it, then the statistics in
 * gem5's form from the registry's walk. 0, or -1 when out of memory. */
int report_stats_txt(const Report *r, char **text, size_t *len)
{
    StatsCtx sx = stats_ctx(r);
    *text = NULL;
    *len = 0;
    FILE *fp = open_memstream(text, len);
    if (!fp)
        return -1;
    fprintf(fp, "# sfsim %s (commit %s), mode %s; the command line, date and host: report.json's \"run\"\n",
            version_string(), version_commit(), run_mode_names[r->o->mode]);
    int rc = stats_gem5(fp, &sx);
    if (fclose(fp) != 0 || rc != 0) {
        free(*text);
        *text = NULL;
        return -1;
    }
    return 0;
}
