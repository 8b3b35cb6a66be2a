/* sim/render.c -- orchestration of `sfsim run`: scene -> packed scene memory -> renderer ->
 * images and report.
 *
 * Owns: the output folder's files and their names. Must not: render, or decide anything the
 * renderer or the report's readers would need to know without reading the report.
 *
 * Outputs (docs/report.md): the folder is checked before any work and created only when there is
 * something to write; every file is staged under a temporary name (sim/outfile.c) and the set is
 * renamed into place only once all of them were written whole, so a failed run leaves no file of
 * its own under a final name and no mix with an older run's files.
 */
#include "render.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../scenes/pack.h"
#include "../scenes/scene.h"
#include "img.h"
#include "config.h"
#include "functional.h"
#include "heatmap.h"
#include "outfile.h"
#include "reference.h"
#include "run/accel.h"
#include "run/kernel.h"
#include "sampling.h"
#include "stats.h"
#include "timing.h"
#include "util.h"

const RenderKey render_keys[RENDER_KEY_COUNT] = {
    {"render.width", 1, 16384},
    {"render.height", 1, 16384},
    {"render.spp", 1, 1 << 20},
    {"render.max_depth", 0, REF_MAX_GENERATIONS - 1},
    {"render.seed", 0, 4294967295LL},
};

void render_default_options(RenderOptions *o)
{
    memset(o, 0, sizeof *o);
    o->stream_rays = 4096;
    o->seed = 1;
    o->threads = 0;
    o->width = o->height = o->spp = o->max_depth = -1;
    o->exposure = 1.0f;
    o->mode = "detailed";
    o->sample = 0.05;
    o->sample_seed = 1;
}

typedef struct Progress {
    pthread_mutex_t lock;
    double start;
    int enabled;
} Progress;

static void progress_cb(void *ctx, uint32_t done, uint32_t total)
{
    Progress *pr = ctx;
    if (!pr->enabled)
        return;
    pthread_mutex_lock(&pr->lock);
    double el = util_now() - pr->start;
    double left = done ? el * (double)(total - done) / (double)done : 0.0;
    int width = 40, fill = (int)((double)width * done / total);
    fprintf(stderr, "\r[%.*s%*s] %u/%u tiles  %.1fs elapsed, ~%.1fs left ", fill,
            "########################################", width - fill, "", done, total, el, left);
    if (done == total)
        fputc('\n', stderr);
    fflush(stderr);
    pthread_mutex_unlock(&pr->lock);
}

static int apply_overrides(const RenderOptions *o, Scene *s, char *err, size_t errlen)
{
    if (o->width > 0)
        s->render.width = o->width;
    if (o->height > 0)
        s->render.height = o->height;
    if (o->spp > 0)
        s->render.spp = o->spp;
    if (o->max_depth >= 0)
        s->render.max_depth = o->max_depth;
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
    if (o->stream_rays != 1024 && o->stream_rays != 4096) {
        snprintf(err, errlen, "stream.rays %d: must be 1024 or 4096", o->stream_rays);
        return -1;
    }
    return 0;
}

/* The outputs of a run, and the names an earlier run may have left that this one does not write. */
static const char *const run_outputs[] = {"frame.exr", "frame.png", "report.txt", "report.json", "cost.png",
                                          "frame.partial.exr"};

/* Remove dir's run outputs not in keep[] (NULL-terminated): a file an earlier run left would
 * otherwise sit beside this run's as if it belonged to it. */
static int remove_stale(const char *dir, const char *const *keep, char *err, size_t errlen)
{
    for (size_t i = 0; i < sizeof run_outputs / sizeof run_outputs[0]; i++) {
        int kept = 0;
        for (const char *const *k = keep; *k; k++)
            kept |= !strcmp(*k, run_outputs[i]);
        char path[4200];
        snprintf(path, sizeof path, "%s/%s", dir, run_outputs[i]);
        if (!kept && unlink(path) != 0 && errno != ENOENT) {
            snprintf(err, errlen, "%s: cannot remove this file of an earlier run: %s", path, strerror(errno));
            return -1;
        }
    }
    return 0;
}

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

/* Either renderer's figures. */
typedef struct RunStats {
    StatsRun run;                           /* rays, generations; the golden model's traversal */
    int functional;
    FuncStats f;
    AccelKdInfo kd;                          /* accel.structure = kd */
} RunStats;

/* The object name of root, made if the statistics walk did not make it. */
static cJSON *object_of(cJSON *root, const char *name)
{
    cJSON *o = cJSON_GetObjectItemCaseSensitive(root, name);
    return o ? o : cJSON_AddObjectToObject(root, name);
}

/* accel.structure = kd: the tree and the traversal (the kernel's counters: sim/stats.def). */
static void add_kd_json(cJSON *root, const RunStats *rs, const CfgMachine *cfg)
{
    const AccelKdInfo *t = &rs->kd;
    cJSON *kd = object_of(root, "kd");
    cJSON_AddStringToObject(kd, "structure", cfg_enum_name("accel", "structure", cfg->accel_structure));
    cJSON_AddStringToObject(kd, "traversal", cfg_enum_name("kd", "traversal", cfg->kd_traversal));
    cJSON_AddNumberToObject(kd, "stack_depth", rs->f.kd_stack_depth);
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
static int kd_text(char *txt, size_t cap, const RunStats *rs, const CfgMachine *cfg)
{
    const AccelKdInfo *t = &rs->kd;
    char sah[64];
    return snprintf(txt, cap,
                    "kd-tree      %s traversal, stack depth %u; %u nodes, %u leaves (%u empty), depth %u, "
                    "%.2f references per primitive, largest leaf %u, SAH cost %s; built in %.2f s\n",
                    cfg_enum_name("kd", "traversal", cfg->kd_traversal), rs->f.kd_stack_depth, t->nodes, t->leaves,
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
    cJSON_AddNumberToObject(k, "instructions", f->kernel_instructions);
}

/* Sampled mode: how the sample was drawn and estimated (its figures: sim/stats.def). */
static void add_sample_json(cJSON *root, double fraction, uint32_t seed)
{
    cJSON *sm = object_of(root, "sample");
    cJSON_AddNumberToObject(sm, "fraction", fraction);
    cJSON_AddNumberToObject(sm, "seed", seed);
    cJSON_AddStringToObject(sm, "estimator", "ratio of cycles to instructions (docs/sampling.md)");
    cJSON_AddNumberToObject(sm, "confidence", 0.95);
}

/* What the report files say about a run (render_run fills it once the image is made). */
typedef struct Report {
    const RenderOptions *o;
    const CfgMachine *cfg;
    const Scene *s;
    const PackedScene *p;
    const RunStats *rs;
    const SampleEstimate *est;     /* sampled mode */
    int detailed, sampled, functional, tile, threads;
    double load_seconds, pack_seconds, secs;   /* host: load, BVH + pack, rendering */
    double mean;                   /* of the image's finite values */
    long nonfinite;
} Report;

/* The statistics walk's view of the run (sim/stats.h). */
static StatsCtx stats_ctx(const Report *r)
{
    StatsCtx c = {.mode = (r->detailed ? STATS_M_DET : r->sampled ? STATS_M_SAMP : r->functional ? STATS_M_FUNC
                                                                                                   : STATS_M_REF) |
                          (r->functional && r->rs->f.kd ? STATS_M_KD : 0),
                  .cfg = r->cfg, .run = &r->rs->run, .f = r->functional ? &r->rs->f : NULL,
                  .t = r->detailed || r->sampled ? &r->rs->f.timing : NULL, .est = r->est};
    return c;
}

static uint64_t report_rays(const Report *r) { return r->rs->run.primary + r->rs->run.shadow + r->rs->run.indirect; }

/* report.json (docs/report.md); NULL when out of memory. */
static cJSON *report_json(const Report *r)
{
    const RenderOptions *o = r->o;
    const CfgMachine *cfg = r->cfg;
    const Scene *sp = r->s;
    const PackedScene *pp = r->p;
    const RunStats *rsp = r->rs;
    int functional = r->functional, sampled = r->sampled, threads = r->threads;
    double secs = r->secs;
    uint64_t total_rays = report_rays(r);
    /* report.json: the names of ARCHITECTURE.md Sec. 1. The statistics come from the registry
     * (sim/stats.def; the timing fields are null unless timed); the blocks below describe the run. */
    StatsCtx sx = stats_ctx(r);
    cJSON *root = cJSON_CreateObject();
    if (!root || !cJSON_AddStringToObject(root, "mode", o->mode) || stats_json(root, &sx) != 0) {
        cJSON_Delete(root);
        return NULL;
    }
    if (functional)
        add_kernel_json(root, &rsp->f, cfg);
    if (sampled)
        add_sample_json(root, o->sample, o->sample_seed);
    if (functional && rsp->f.kd)
        add_kd_json(root, rsp, cfg);
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
    cJSON_AddNumberToObject(ren, "stream_rays", o->stream_rays);
    int tile_w = functional ? (int)rsp->f.tile_w : r->tile, tile_h = functional ? (int)rsp->f.tile_h : r->tile;
    cJSON_AddNumberToObject(ren, "tile", tile_w);
    cJSON_AddNumberToObject(ren, "tile_height", tile_h);
    cJSON *im = cJSON_AddObjectToObject(root, "image");
    cJSON_AddNumberToObject(im, "mean", r->mean);
    cJSON_AddNumberToObject(im, "nonfinite", (double)r->nonfinite);
    cJSON *host = cJSON_AddObjectToObject(root, "host");
    cJSON_AddNumberToObject(host, "seconds", secs);
    cJSON_AddNumberToObject(host, "load_seconds", r->load_seconds);
    cJSON_AddNumberToObject(host, "bvh_pack_seconds", r->pack_seconds);
    cJSON_AddNumberToObject(host, "threads", threads);
    cJSON_AddNumberToObject(host, "rays_per_second", secs > 0 ? (double)total_rays / secs : 0.0);
    if (functional) {
        cJSON_AddNumberToObject(host, "sim_instructions", (double)rsp->f.instructions);
        cJSON_AddNumberToObject(host, "instructions_per_second", secs > 0 ? (double)rsp->f.instructions / secs : 0.0);
    }
    return root;
}

/* report.txt (docs/report.md) into txt. */
static void report_txt(const Report *r, char *txt, size_t cap)
{
    const RenderOptions *o = r->o;
    const CfgMachine *cfg = r->cfg;
    const Scene *sp = r->s;
    const PackedScene *pp = r->p;
    const RunStats *rsp = r->rs;
    int detailed = r->detailed, sampled = r->sampled, functional = r->functional, threads = r->threads;
    double secs = r->secs;
    uint64_t total_rays = report_rays(r);
    StatsCtx sx = stats_ctx(r);
    char needs[256];
    scene_needs_string(sp->needs, needs, sizeof needs);
    int tile_w = functional ? (int)rsp->f.tile_w : r->tile, tile_h = functional ? (int)rsp->f.tile_h : r->tile;
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
             "scene        %s\n"
             "             %u triangles, %u spheres, %u lights; needs: %s\n"
             "             BVH %u nodes, %u leaves, depth %u, SAH cost %s; %u bytes of scene memory\n"
             "config       %s\n"
             "image        %d x %d, %d spp, max depth %d, seed %u, %s\n"
             "             mean %.5f, non-finite values %ld\n",
             o->mode,
             detailed     ? "the kernel on the timing model of the machine"
             : sampled    ? "the kernel; sampled tiles on the timing model, the frame's cycles estimated"
             : functional ? "the kernel on the functional core: no timing"
                          : "golden model: no timing",
             o->scene_path, sp->ntris, sp->nspheres, pp->nlights, needs[0] ? needs : "-", pp->bvh.nnodes,
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
                        "machine      N = %d lanes, %s of %u x %u rays, workload %s; kernel %u instructions (%s)\n",
                        cfg->core_simd_width, cfg->stream_mode == CFG_STREAM_MODE_PACKET ? "packets" : "streams",
                        f->tile_w, f->tile_h, cfg_enum_name("workload", "kind", cfg->workload_kind),
                        f->kernel_instructions, f->defines);
        if (f->kd)
            len += kd_text(txt + len, cap - (size_t)len, rsp, cfg);
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
                        secs > 0 ? 1e-6 * (double)total_rays / secs : 0.0, r->load_seconds, r->pack_seconds);
    else
        len += snprintf(txt + len, cap - (size_t)len,
                        "host         %.2f s rendering on %d %s (%.3f M rays/s); load %.2f s, BVH+pack %.2f s\n", secs,
                        threads, thr, secs > 0 ? 1e-6 * (double)total_rays / secs : 0.0, r->load_seconds, r->pack_seconds);
}

/* Detailed and sampled modes: cost.png, simulated cycles per pixel of each tile (sampled mode:
 * tiles not sampled get the sample's cycles per instruction times their instructions). */
static int write_cost_map(OutSet *set, const char *dir, const FuncStats *f, const SampleEstimate *est, int width,
                          int height, char *err, size_t errlen)
{
    /* One value per pixel; an image wider or taller than the heat map takes (8192) is drawn one
     * value per tile instead (the values are per tile either way). */
    int scale_x = 1, scale_y = 1;
    if (width > 8192 || height > 8192) {
        scale_x = (int)f->tile_w;
        scale_y = (int)f->tile_h;
    }
    int mw = (width + scale_x - 1) / scale_x, mh = (height + scale_y - 1) / scale_y;
    double *v = calloc((size_t)mw * (size_t)mh, sizeof *v);
    if (!v) {
        snprintf(err, errlen, "out of memory for cost.png");
        return -1;
    }
    for (uint32_t i = 0; i < f->ntiles; i++) {
        const FuncTile *t = &f->tiles[i];
        double cyc = stats_tile_cycles(f, est, i);
        double per = t->w && t->h ? cyc / ((double)t->w * t->h) : 0.0;
        for (uint32_t y = t->y0; y < t->y0 + t->h && y < (uint32_t)height; y += (uint32_t)scale_y)
            for (uint32_t x = t->x0; x < t->x0 + t->w && x < (uint32_t)width; x += (uint32_t)scale_x)
                v[(size_t)(y / (uint32_t)scale_y) * (size_t)mw + x / (uint32_t)scale_x] = per;
    }
    width = mw;
    height = mh;
    char path[4200], title[128];
    snprintf(path, sizeof path, "%s/cost.png", dir);
    snprintf(title, sizeof title, "simulated cycles per pixel (tiles of %u x %u%s)", f->tile_w, f->tile_h,
             est ? "; unsampled tiles estimated" : "");
    int rc = heatmap_write(set, path, v, width, height, title, "cycles", err, errlen);
    free(v);
    return rc;
}

/* A run whose kernel failed: frame.partial.exr (the finished tiles, the others black) and a
 * report.json with "status": "failed" replace an earlier run's outputs, whose complete-looking
 * files would now mislead (docs/kernel.md). 0, or -1 with werr saying what could not be written
 * (then nothing of this run is in the folder). */
static int write_partial(const RenderOptions *o, const float *rgb, int width, int height, const FuncStats *f,
                         const char *why, char *werr, size_t werrlen)
{
    static const char *const keep[] = {"frame.partial.exr", "report.json", NULL};
    OutDirs dirs = {0};
    OutSet *set = outset_new();
    cJSON *fr = cJSON_CreateObject();
    char *text = NULL, path[4200];
    int rc = -1;
    if (!set || !fr) {
        snprintf(werr, werrlen, "out of memory");
        goto out;
    }
    if (outfile_make_dirs(o->out_dir, &dirs, werr, werrlen) != 0)
        goto out;
    snprintf(path, sizeof path, "%s/frame.partial.exr", o->out_dir);
    if (img_write_linear(set, path, rgb, width, height, werr, werrlen) != 0)
        goto out;
    cJSON_AddStringToObject(fr, "mode", o->mode);
    cJSON_AddStringToObject(fr, "status", "failed");
    cJSON_AddStringToObject(fr, "error", why);
    cJSON_AddNumberToObject(fr, "tiles_done", f->tiles_done);
    cJSON_AddNumberToObject(fr, "tiles", f->ntiles);
    cJSON_AddStringToObject(fr, "partial_image", "frame.partial.exr");
    text = cJSON_Print(fr);
    snprintf(path, sizeof path, "%s/report.json", o->out_dir);
    if (!text) {
        snprintf(werr, werrlen, "%s: out of memory", path);
        goto out;
    }
    if (outfile_write_file(set, path, text, strlen(text), werr, werrlen) != 0 ||
        remove_stale(o->out_dir, keep, werr, werrlen) != 0 || outset_commit(set, werr, werrlen) != 0)
        goto out;
    outfile_keep_dirs(&dirs);
    rc = 0;
out:
    outset_free(set);
    outfile_remove_dirs(&dirs);
    cJSON_free(text);
    cJSON_Delete(fr);
    return rc;
}

int render_run(const RenderOptions *o, char *err, size_t errlen)
{
    int rc = -1;
    OutDirs dirs = {0};
    OutSet *set = NULL;
    Scene s;
    PackedScene p;
    float *rgb = NULL;
    char *json_text = NULL;
    cJSON *root = NULL;
    RunStats rs;
    memset(&rs, 0, sizeof rs);
    memset(&p, 0, sizeof p);
    CfgMachine defcfg;
    cfg_defaults(&defcfg);
    const CfgMachine *cfg = o->cfg ? o->cfg : &defcfg;
    int detailed = !strcmp(o->mode, "detailed"), sampled = !strcmp(o->mode, "sampled");
    int functional = detailed || sampled || !strcmp(o->mode, "functional");
    if (!functional && strcmp(o->mode, "reference") != 0) {
        snprintf(err, errlen, "--mode %s: expected detailed, sampled, functional or reference", o->mode);
        return -1;
    }
    if (sampled && !(o->sample > 0.0 && o->sample <= 1.0)) {
        snprintf(err, errlen, "--sample %g: expected a fraction of the tiles in (0, 1]", o->sample);
        return -1;
    }
    /* Before any work: an output folder that cannot be made would fail the run only at its end. */
    if (outfile_check_dir(o->out_dir, err, errlen) != 0)
        return -3;
    SampleEstimate est_store, *est = NULL;
    double t0 = util_now();
    if (scene_load(o->scene_path, &s, err, errlen) != 0)
        return -1;
    for (uint32_t i = 0; i < s.nwarnings; i++) /* what the scene left out (docs/scenes.md) */
        fprintf(stderr, "sfsim run: warning: %s\n", s.warnings[i]);
    if (apply_overrides(o, &s, err, errlen) != 0)
        goto out;
    double t_load = util_now();
    AccelInfo accel;
    if (accel_pack(&s, cfg, functional, &p, &accel, err, errlen) != 0)
        goto out;
    rs.kd = accel.kd;
    double t_kd = util_now();
    size_t npx = (size_t)s.render.width * (size_t)s.render.height;
    rgb = calloc(3 * npx, sizeof(float));
    if (!rgb) {
        snprintf(err, errlen, "out of memory for a %d x %d image", s.render.width, s.render.height);
        goto out;
    }
    int threads = o->threads > 0 ? o->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    Progress pr = {PTHREAD_MUTEX_INITIALIZER, util_now(), o->progress};
    int tile = (int)lrint(sqrt((double)o->stream_rays));
    if (functional) {
        char kpath[4200];
        FuncParams fp = {.cfg = cfg,
                         .kernel_path = o->kernel_path ? o->kernel_path : kernel_default_path(kpath, sizeof kpath),
                         .needs = s.needs,
                         .seed = o->seed,
                         .threads = threads,
                         .progress = progress_cb,
                         .progress_ctx = &pr,
                         .timed = detailed || sampled,
                         .sample = sampled ? o->sample : 0.0,
                         .sample_seed = o->sample_seed};
        int frc = func_render(&p, &fp, rgb, &rs.f, err, errlen);
        if (frc == -2) {
            /* The kernel failed in a tile: keep what the finished tiles rendered, marked partial. */
            char werr[4400], text[16384];
            if (write_partial(o, rgb, s.render.width, s.render.height, &rs.f, err, werr, sizeof werr) == 0)
                snprintf(text, sizeof text, "%s\n(%u of %u tiles finished: %s/frame.partial.exr; unfinished tiles are black)",
                         err, rs.f.tiles_done, rs.f.ntiles, o->out_dir);
            else
                snprintf(text, sizeof text, "%s\n(%u of %u tiles finished; the partial image was not kept: %s)", err,
                         rs.f.tiles_done, rs.f.ntiles, werr);
            snprintf(err, errlen, "%s", text);
        }
        if (frc != 0) {
            rc = frc;
            goto out;
        }
        rs.functional = 1;
        if (sampled) {
            /* The frame's cycles from the sampled tiles (sim/sampling.h). */
            if (stats_sample_estimate(&rs.f, &est_store) != 0) {
                snprintf(err, errlen, "sampled mode: cannot estimate from %u sampled of %u tiles (the frame needs at "
                         "least 2 tiles; render more pixels or use --mode detailed)", rs.f.tiles_timed, rs.f.ntiles);
                goto out;
            }
            est = &est_store;
        }
        stats_run_from_func(&rs.run, &rs.f);
    } else {
        /* The golden model renders the path tracer and the Phong workload; the forced specular and
         * diffuse workloads exist only as kernel variants (docs/kernel.md). */
        if (cfg->workload_kind != CFG_WORKLOAD_PATH && cfg->workload_kind != CFG_WORKLOAD_PHONG) {
            snprintf(err, errlen, "--mode reference: workload.kind = %s has no golden model (path and phong do)",
                     cfg_enum_name("workload", "kind", cfg->workload_kind));
            goto out;
        }
        RefParams rp = {.tile = tile, .seed = o->seed, .threads = threads, .progress = progress_cb,
                        .progress_ctx = &pr, .bounces = cfg->workload_bounces,
                        .workload = cfg->workload_kind == CFG_WORKLOAD_PHONG ? REF_WORKLOAD_PHONG : REF_WORKLOAD_PATH};
        RefStats st;
        if (ref_render(&p, &rp, rgb, &st, err, errlen) != 0)
            goto out;
        stats_run_from_ref(&rs.run, &st);
    }
    double t_render = util_now();

    /* From here on a failure is an output that could not be written (EXIT_IO); the folder is
     * made now that there is something to write, and removed again if nothing is written. */
    rc = -3;
    set = outset_new();
    if (!set) {
        snprintf(err, errlen, "%s: out of memory", o->out_dir);
        goto out;
    }
    if (outfile_make_dirs(o->out_dir, &dirs, err, errlen) != 0)
        goto out;
    char path[4200];
    snprintf(path, sizeof path, "%s/frame.exr", o->out_dir);
    if (img_write_linear(set, path, rgb, s.render.width, s.render.height, err, errlen) != 0)
        goto out;
    snprintf(path, sizeof path, "%s/frame.png", o->out_dir);
    if (img_write_display(set, path, rgb, s.render.width, s.render.height, o->exposure, err, errlen) != 0)
        goto out;

    long nonfinite = 0;
    double sum = 0.0;
    for (size_t i = 0; i < 3 * npx; i++) {
        if (!isfinite(rgb[i]))
            nonfinite++;
        else
            sum += rgb[i];
    }
    Report rep = {.o = o, .cfg = cfg, .s = &s, .p = &p, .rs = &rs, .est = est, .detailed = detailed,
                  .sampled = sampled, .functional = functional, .tile = tile, .threads = threads,
                  .load_seconds = t_load - t0, .pack_seconds = accel.pack_seconds, .secs = t_render - t_kd,
                  .mean = npx ? sum / (3.0 * (double)npx) : 0.0, .nonfinite = nonfinite};
    root = report_json(&rep);
    if (!root) {
        snprintf(err, errlen, "%s/report.json: out of memory", o->out_dir);
        goto out;
    }
    json_text = cJSON_Print(root);
    snprintf(path, sizeof path, "%s/report.json", o->out_dir);
    if (!json_text) {
        snprintf(err, errlen, "%s: out of memory", path);
        goto out;
    }
    if (outfile_write_file(set, path, json_text, strlen(json_text), err, errlen) != 0)
        goto out;

    char txt[16384];
    report_txt(&rep, txt, sizeof txt);
    snprintf(path, sizeof path, "%s/report.txt", o->out_dir);
    if (outfile_write_file(set, path, txt, strlen(txt), err, errlen) != 0)
        goto out;
    if ((detailed || sampled) &&
        write_cost_map(set, o->out_dir, &rs.f, est, s.render.width, s.render.height, err, errlen) != 0)
        goto out;
    /* Every file is whole under its temporary name: the set goes into place, and what an earlier
     * run left that this one does not write (cost.png, frame.partial.exr) goes away. */
    static const char *const keep_timed[] = {"frame.exr", "frame.png", "report.txt", "report.json", "cost.png", NULL};
    static const char *const keep_untimed[] = {"frame.exr", "frame.png", "report.txt", "report.json", NULL};
    if (remove_stale(o->out_dir, detailed || sampled ? keep_timed : keep_untimed, err, errlen) != 0 ||
        outset_commit(set, err, errlen) != 0)
        goto out;
    outfile_keep_dirs(&dirs);
    rc = 0;
out:
    if (rc == -3 && set) {
        size_t n = strlen(err);
        snprintf(err + n, errlen - n, " (no output of this run was kept in %s)", o->out_dir);
    }
    outset_free(set);
    outfile_remove_dirs(&dirs);
    cJSON_free(json_text);
    cJSON_Delete(root);
    free(rgb);
    func_stats_free(&rs.f);
    pack_free(&p);
    scene_free(&s);
    return rc;
}
