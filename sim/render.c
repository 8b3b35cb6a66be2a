/* sim/render.c -- `sfsim run`: a frame through the run entry point (sim/run/run.h), then its
 * images and report (sim/report.c) into the output folder.
 *
 * Owns: the output folder's files and their names. Must not: render, or decide anything the
 * renderer or the report's readers would need to know without reading the report.
 *
 * Outputs (docs/report.md): the folder is checked before any work and created only when there is
 * something to write; every file is staged under a temporary name (host/outfile.c) and the set is
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
#include <unistd.h>

#include "config.h"
#include "heatmap.h"
#include "img.h"
#include "../host/outfile.h"
#include "mem/memtrace.h"
#include "timeline.h"
#include "provenance.h"
#include "reference.h"
#include "report.h"
#include "run/chipsampled.h"
#include "run/run.h"
#include "stats.h"
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
    o->seed = 1;
    o->threads = 0;
    o->width = o->height = o->spp = o->max_depth = -1;
    o->exposure = 1.0f;
    o->mode = RUN_DETAILED;
    o->sample = 0.05;        /* used only when target_error is 0 (sfsim run --sample) */
    o->target_error = 0.01;
    o->sample_seed = 1;
    o->timeline_to = TIMELINE_DEFAULT_CYCLES;
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

/* Sampled mode's rounds (RunSpec.note), on the progress line's terminal. */
static void note_cb(void *ctx, const char *line)
{
    Progress *pr = ctx;
    if (!pr->enabled)
        return;
    pthread_mutex_lock(&pr->lock);
    fprintf(stderr, "sampled: %s\n", line);
    fflush(stderr);
    pthread_mutex_unlock(&pr->lock);
}

/* The outputs of a run, and the names an earlier run may have left that this one does not write. */
static const char *const run_outputs[] = {"frame.exr", "frame.png", "report.txt", "report.json", "stats.txt",
                                          "cost.png", "frame.partial.exr"};

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

/* Detailed and sampled modes: cost.png, simulated cycles per pixel of each tile (sampled mode:
 * est holds each tile's estimate, its measured units plus the regression's prediction for the
 * others). */
static int write_cost_map(OutSet *set, const char *dir, const FuncStats *f, const double *est, int width,
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
        double cyc = est ? est[i] : (double)t->cycles;
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
             est ? "; estimated from the sampled units" : "");
    int rc = heatmap_write(set, path, v, width, height, title, "cycles", err, errlen);
    free(v);
    return rc;
}

/* A run whose kernel failed: frame.partial.exr (the finished tiles, the others black) and a
 * report.json with "status": "failed" (and what made the run) replace an earlier run's outputs,
 * whose complete-looking files would now mislead (docs/kernel.md). It has no statistics, so no
 * stats.txt: gem5 too writes none for a run that did not finish. 0, or -1 with werr saying what could not be written
 * (then nothing of this run is in the folder). */
static int write_partial(const RenderOptions *o, const float *rgb, int width, int height, const FuncStats *f,
                         int threads, const char *why, char *werr, size_t werrlen)
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
    cJSON_AddStringToObject(fr, "mode", run_mode_names[o->mode]);
    cJSON *made = cJSON_AddObjectToObject(fr, "run");
    if (!made || prov_json(made) != 0 || !cJSON_AddNumberToObject(made, "threads", threads)) {
        snprintf(werr, werrlen, "out of memory");
        goto out;
    }
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

/* The image's figures for the report: the mean of its finite values, and how many are not. */
static void image_figures(const float *rgb, size_t n, double *mean, long *nonfinite)
{
    double sum = 0.0;
    *nonfinite = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(rgb[i]))
            (*nonfinite)++;
        else
            sum += rgb[i];
    }
    *mean = n ? sum / (double)n : 0.0;
}

/* Report r's files into set, staged under temporary names (host/outfile.h). 0, or -1 with a message. */
static int stage_outputs(OutSet *set, const Report *r, char *err, size_t errlen)
{
    const RenderOptions *o = r->o;
    const Scene *s = &r->sc->s;
    char path[4200];
    snprintf(path, sizeof path, "%s/frame.exr", o->out_dir);
    if (!o->no_image && img_write_linear(set, path, r->fr->rgb, s->render.width, s->render.height, err, errlen) != 0)
        return -1;
    snprintf(path, sizeof path, "%s/frame.png", o->out_dir);
    if (!o->no_image &&
        img_write_display(set, path, r->fr->rgb, s->render.width, s->render.height, o->exposure, err, errlen) != 0)
        return -1;
    cJSON *root = report_json(r);
    char *json_text = root ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    snprintf(path, sizeof path, "%s/report.json", o->out_dir);
    if (!json_text) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    int rc = outfile_write_file(set, path, json_text, strlen(json_text), err, errlen);
    cJSON_free(json_text);
    if (rc != 0)
        return -1;
    char txt[65536];   /* (the command line it opens with can be long) */
    report_txt(r, txt, sizeof txt);
    snprintf(path, sizeof path, "%s/report.txt", o->out_dir);
    if (outfile_write_file(set, path, txt, strlen(txt), err, errlen) != 0)
        return -1;
    char *stats = NULL;
    size_t stats_len = 0;
    snprintf(path, sizeof path, "%s/stats.txt", o->out_dir);
    if (report_stats_txt(r, &stats, &stats_len) != 0) {
        snprintf(err, errlen, "%s: out of memory", path);
        return -1;
    }
    rc = outfile_write_file(set, path, stats, stats_len, err, errlen);
    free(stats);
    if (rc != 0)
        return -1;
    if (run_mode_timed(r->mode) && write_cost_map(set, o->out_dir, &r->fr->f, r->fr->has_est ? r->fr->tile_cycles : NULL,
                                                  s->render.width, s->render.height, err, errlen) != 0)
        return -1;
    return 0;
}

/* The run's files: the folder is made now that there is something to write, every file staged,
 * and the set put into place with what an earlier run left that this one does not write (cost.png,
 * frame.partial.exr) removed. 0, or -1 with a message; then nothing of this run is in the folder. */
static int write_outputs(const Report *r, char *err, size_t errlen)
{
    static const char *const keep_timed[] = {"frame.exr", "frame.png", "report.txt", "report.json", "stats.txt",
                                             "cost.png", NULL};
    static const char *const keep_untimed[] = {"frame.exr", "frame.png", "report.txt", "report.json", "stats.txt", NULL};
    static const char *const keep_no_image[] = {"report.txt", "report.json", "stats.txt", "cost.png", NULL};
    const char *dir = r->o->out_dir;
    const char *const *keep = r->o->no_image ? keep_no_image : run_mode_timed(r->mode) ? keep_timed : keep_untimed;
    OutDirs dirs = {0};
    OutSet *set = outset_new();
    int rc = -1;
    if (!set)
        snprintf(err, errlen, "%s: out of memory", dir);
    else if (outfile_make_dirs(dir, &dirs, err, errlen) == 0 && stage_outputs(set, r, err, errlen) == 0 &&
             remove_stale(dir, keep, err, errlen) == 0 &&
             outset_commit(set, err, errlen) == 0) {
        outfile_keep_dirs(&dirs);
        rc = 0;
    }
    outset_free(set);
    outfile_remove_dirs(&dirs);
    return rc;
}

/* The kernel failed in a tile: keep what the finished tiles rendered, marked partial, and say so
 * after the failure's message in err. */
static void keep_partial(const RenderOptions *o, const RunScene *sc, const RunFrame *fr, char *err, size_t errlen)
{
    char werr[4400], text[16384];
    if (write_partial(o, fr->rgb, sc->s.render.width, sc->s.render.height, &fr->f, fr->threads, err, werr, sizeof werr) == 0)
        snprintf(text, sizeof text, "%s\n(%u of %u tiles finished: %s/frame.partial.exr; unfinished tiles are black)",
                 err, fr->f.tiles_done, fr->f.ntiles, o->out_dir);
    else
        snprintf(text, sizeof text, "%s\n(%u of %u tiles finished; the partial image was not kept: %s)", err,
                 fr->f.tiles_done, fr->f.ntiles, werr);
    snprintf(err, errlen, "%s", text);
}

/* The L1s' requests of a detailed run (FuncStats.trace) in sfsim's trace format (docs/dram.md),
 * each with its core as the source, written whole or not at all. 0, or -1 with a message. */
static int write_mem_trace(const char *path, const CfgMachine *cfg, const FuncStats *f, char *err, size_t errlen)
{
    MtrWriter *w = mtr_create(path, cfg->core_clock_mhz, err, errlen);
    if (!w)
        return -1;
    char src[32];
    for (size_t i = 0; i < f->ntrace; i++) {
        const FuncMemRec *m = &f->trace[i];
        snprintf(src, sizeof src, "core%u", m->core);
        if (mtr_write(w, m->cycle, m->write, m->addr, src, err, errlen) != 0) {
            mtr_discard(w);
            return -1;
        }
    }
    return mtr_finish(w, err, errlen);
}

/* A sampled chip's --target-error stops on the units' total (docs/sampling.md, "Built: sampled
 * mode on a chip"); when the makespan's own interval came out wider, the user is told, not left
 * to find it in the report. */
static void warn_makespan_interval(const RunSpec *spec, const RunFrame *fr)
{
    if (!fr->chip.on || !fr->has_est || spec->target_error <= 0.0 || fr->est.total <= 0.0)
        return;
    const double half = (fr->est.hi - fr->est.lo) / 2.0 / fr->est.total;
    if (half > spec->target_error)
        fprintf(stderr,
                "sfsim run: warning: the makespan's 95 %% interval is +-%.2f %%, wider than --target-error %g %%: on a "
                "chip the makespan rests on the tiles the latest cores end with, and the %u units timed for them "
                "beyond the sample (at most twice its units) left it so (docs/sampling.md); --sample F times a "
                "larger share\n",
                100.0 * half, 100.0 * spec->target_error, fr->chip.tail_units);
}

/* A sampled chip's memory figures need the warming's whole record, which --no-image cuts
 * (docs/sampling.md, step 4): the user is told why they read "-". */
static void warn_partial_record(const RunFrame *fr)
{
    if (fr->chip.on && fr->chip.shared && fr->chip.record_step > 1)
        fprintf(stderr,
                "sfsim run: warning: with --no-image above %u samples per pixel the L2's warming record holds one "
                "pass in %u of each tile: the makespan is estimated as ever, the memory figures (latency, L2 hit "
                "rate, DRAM bandwidth) are not (with part of the record DRAM's traffic reads tens of per cent "
                "high; docs/sampling.md); run without --no-image for them\n",
                CHIPSAMPLED_RECORD_PASSES, fr->chip.record_step);
}

int render_run(const RenderOptions *o, char *err, size_t errlen)
{
    CfgMachine defcfg;
    cfg_defaults(&defcfg);
    const CfgMachine *cfg = o->cfg ? o->cfg : &defcfg;
    Progress pr = {PTHREAD_MUTEX_INITIALIZER, 0.0, o->progress};
    RunSpec spec = {.cfg = cfg, .kernel_path = o->kernel_path, .seed = o->seed, .threads = o->threads,
                    .sample = o->sample, .sample_seed = o->sample_seed, .progress = progress_cb, .note = note_cb,
                    .progress_ctx = &pr};
    spec.mode = o->mode; /* o as the command line checked it (sim/cli/runopts.c); run_frame asserts */
    if (spec.mode == RUN_SAMPLED) {
        spec.target_error = o->target_error;
        spec.no_image = o->no_image;
    }
    spec.mem_trace = o->mem_trace != NULL;
    /* Before any work: an output folder that cannot be made would fail the run only at its end. */
    if (outfile_check_dir(o->out_dir, err, errlen) != 0)
        return -3;
    if (o->timeline && spec.mode == RUN_DETAILED) {
        if (outfile_check_file(o->timeline, err, errlen) != 0)
            return -3;
        if (!(spec.timeline = timeline_new(o->timeline_from, o->timeline_to, cfg->chip_cores, cfg->core_clock_mhz, 0))) {
            snprintf(err, errlen, "out of memory for the timeline");
            return -1;
        }
    }
    RunScene sc;
    RunFrame fr;
    memset(&fr, 0, sizeof fr);
    RunSize size = {o->width, o->height, o->spp, o->max_depth};
    int rc = run_scene_open(&sc, o->scene_path, &size, cfg, spec.mode, "sfsim run", err, errlen);
    if (rc == 0) {
        pr.start = util_now();
        rc = run_frame(&sc, &spec, &fr, err, errlen);
        if (rc == 0) {
            warn_makespan_interval(&spec, &fr);
            warn_partial_record(&fr);
        }
        if (rc == -2 && spec.mode != RUN_SAMPLED) /* sampled mode's image is the golden model's, never partial */
            keep_partial(o, &sc, &fr, err, errlen);
    }
    if (rc == 0) {
        Report rep = {.o = o, .mode = spec.mode, .cfg = cfg, .sc = &sc, .fr = &fr};
        image_figures(fr.rgb, 3 * (size_t)sc.s.render.width * (size_t)sc.s.render.height, &rep.mean, &rep.nonfinite);
        /* Energy and area: once, from the finished run's counters (sim/energy/energy.h). */
        if (report_energy(&rep, err, errlen) != 0) {
            rc = -1;
        /* From here on a failure is an output that could not be written (EXIT_IO). */
        } else if (write_outputs(&rep, err, errlen) != 0) {
            size_t n = strlen(err);
            snprintf(err + n, errlen - n, " (no output of this run was kept in %s)", o->out_dir);
            rc = -3;
        } else if ((o->mem_trace && write_mem_trace(o->mem_trace, cfg, &fr.f, err, errlen) != 0) ||
                   (spec.timeline && timeline_write(spec.timeline, o->timeline, err, errlen) != 0)) {
            size_t n = strlen(err);
            snprintf(err + n, errlen - n, " (the run's other outputs are in %s)", o->out_dir);
            rc = -3;
        }
    }
    timeline_free(spec.timeline);
    run_frame_free(&fr);
    run_scene_close(&sc);
    return rc;
}
