/* sim/render.c -- orchestration of `sfsim run`: scene -> packed scene memory -> renderer ->
 * images and report.
 *
 * Owns: the output folder's files and their names. Must not: render, or decide anything the
 * renderer or the report's readers would need to know without reading the report.
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
#include <time.h>
#include <unistd.h>

#include "../scenes/pack.h"
#include "../scenes/scene.h"
#include "img.h"
#include "reference.h"

void render_default_options(RenderOptions *o)
{
    memset(o, 0, sizeof *o);
    o->stream_rays = 4096;
    o->seed = 1;
    o->threads = 0;
    o->width = o->height = o->spp = o->max_depth = -1;
    o->bvh_leaf_size = 4;
    o->bvh_bins = 16;
    o->exposure = 1.0f;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* mkdir -p */
static int make_dirs(const char *path, char *err, size_t errlen)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = 0;
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
            snprintf(err, errlen, "%s: cannot create folder: %s", buf, strerror(errno));
            return -1;
        }
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) {
        snprintf(err, errlen, "%s: cannot create folder: %s", buf, strerror(errno));
        return -1;
    }
    return 0;
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
    double el = now() - pr->start;
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

static int write_text(const char *path, const char *text, char *err, size_t errlen)
{
    FILE *f = fopen(path, "w");
    if (!f || fputs(text, f) < 0 || fclose(f) != 0) {
        snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
        if (f)
            fclose(f);
        return -1;
    }
    return 0;
}

int render_reference(const RenderOptions *o, char *err, size_t errlen)
{
    int rc = -1;
    Scene s;
    PackedScene p;
    float *rgb = NULL;
    char *json_text = NULL;
    cJSON *root = NULL;
    memset(&p, 0, sizeof p);
    double t0 = now();
    if (scene_load(o->scene_path, &s, err, errlen) != 0)
        return -1;
    if (apply_overrides(o, &s, err, errlen) != 0 || make_dirs(o->out_dir, err, errlen) != 0)
        goto out;
    BvhParams bp;
    bvh_default_params(&bp);
    bp.max_leaf_size = o->bvh_leaf_size;
    bp.bins = o->bvh_bins;
    double t_load = now();
    if (pack_scene(&s, &bp, 0, &p, err, errlen) != 0)
        goto out;
    double t_pack = now();
    size_t npx = (size_t)s.render.width * (size_t)s.render.height;
    rgb = calloc(3 * npx, sizeof(float));
    if (!rgb) {
        snprintf(err, errlen, "out of memory for a %d x %d image", s.render.width, s.render.height);
        goto out;
    }
    int threads = o->threads > 0 ? o->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    Progress pr = {PTHREAD_MUTEX_INITIALIZER, now(), o->progress};
    RefParams rp = {(int)lrint(sqrt((double)o->stream_rays)), o->seed, threads, progress_cb, &pr};
    RefStats st;
    if (ref_render(&p, &rp, rgb, &st, err, errlen) != 0)
        goto out;
    double t_render = now();

    char path[4200];
    snprintf(path, sizeof path, "%s/frame.exr", o->out_dir);
    if (img_write_linear(path, rgb, s.render.width, s.render.height, err, errlen) != 0)
        goto out;
    snprintf(path, sizeof path, "%s/frame.png", o->out_dir);
    if (img_write_display(path, rgb, s.render.width, s.render.height, o->exposure, err, errlen) != 0)
        goto out;

    long nonfinite = 0;
    double sum = 0.0;
    for (size_t i = 0; i < 3 * npx; i++) {
        if (!isfinite(rgb[i]))
            nonfinite++;
        else
            sum += rgb[i];
    }
    uint64_t total_rays = st.rays[REF_RAY_CAMERA] + st.rays[REF_RAY_SHADOW] + st.rays[REF_RAY_INDIRECT];
    double secs = t_render - t_pack;

    /* report.json: the names of ARCHITECTURE.md Sec. 1; timing fields are null in this mode. */
    root = cJSON_CreateObject();
    cJSON_AddStringToObject(root, "mode", "reference");
    cJSON_AddNullToObject(root, "cycles");
    cJSON_AddNullToObject(root, "busy_cycles");
    cJSON_AddNullToObject(root, "fps");
    cJSON_AddNullToObject(root, "fps_no_stall");
    cJSON *rays = cJSON_AddObjectToObject(root, "rays");
    cJSON_AddNumberToObject(rays, "primary", (double)st.rays[REF_RAY_CAMERA]);
    cJSON_AddNumberToObject(rays, "shadow", (double)st.rays[REF_RAY_SHADOW]);
    cJSON_AddNumberToObject(rays, "indirect", (double)st.rays[REF_RAY_INDIRECT]);
    cJSON_AddNumberToObject(rays, "total", (double)total_rays);
    cJSON_AddNumberToObject(rays, "dropped", (double)st.dropped);
    cJSON *gens = cJSON_AddArrayToObject(root, "rays_per_generation");
    for (uint64_t g = 0; g < st.generations && g < REF_MAX_GENERATIONS; g++)
        cJSON_AddItemToArray(gens, cJSON_CreateNumber((double)st.rays_per_generation[g]));
    cJSON *trav = cJSON_AddObjectToObject(root, "traversal");
    cJSON_AddNumberToObject(trav, "nodes_visited", (double)st.nodes_visited);
    cJSON_AddNumberToObject(trav, "primitives_tested", (double)st.prims_tested);
    cJSON *sc = cJSON_AddObjectToObject(root, "scene");
    cJSON_AddStringToObject(sc, "file", o->scene_path);
    cJSON_AddNumberToObject(sc, "triangles", s.ntris);
    cJSON_AddNumberToObject(sc, "spheres", s.nspheres);
    cJSON_AddNumberToObject(sc, "lights", p.nlights);
    char needs[256];
    scene_needs_string(s.needs, needs, sizeof needs);
    cJSON *nd = cJSON_AddArrayToObject(sc, "needs");
    char needs_tok[256];
    memcpy(needs_tok, needs, sizeof needs_tok);
    for (char *save = NULL, *tok = strtok_r(needs_tok, ",", &save); tok; tok = strtok_r(NULL, ",", &save))
        cJSON_AddItemToArray(nd, cJSON_CreateString(tok));
    cJSON *bvh = cJSON_AddObjectToObject(sc, "bvh");
    cJSON_AddNumberToObject(bvh, "nodes", p.bvh.nnodes);
    cJSON_AddNumberToObject(bvh, "leaves", p.bvh.nleaves);
    cJSON_AddNumberToObject(bvh, "depth", p.bvh.depth);
    cJSON_AddNumberToObject(bvh, "sah_cost", p.bvh.sah_cost);
    cJSON_AddNumberToObject(bvh, "leaf_size", bp.max_leaf_size);
    cJSON_AddNumberToObject(bvh, "bins", bp.bins);
    cJSON_AddNumberToObject(sc, "scene_memory_bytes", p.size);
    cJSON *ren = cJSON_AddObjectToObject(root, "render");
    cJSON_AddNumberToObject(ren, "width", s.render.width);
    cJSON_AddNumberToObject(ren, "height", s.render.height);
    cJSON_AddNumberToObject(ren, "spp", s.render.spp);
    cJSON_AddNumberToObject(ren, "max_depth", s.render.max_depth);
    cJSON_AddNumberToObject(ren, "seed", o->seed);
    cJSON_AddNumberToObject(ren, "stream_rays", o->stream_rays);
    cJSON_AddNumberToObject(ren, "tile", rp.tile);
    cJSON *im = cJSON_AddObjectToObject(root, "image");
    cJSON_AddNumberToObject(im, "mean", npx ? sum / (3.0 * (double)npx) : 0.0);
    cJSON_AddNumberToObject(im, "nonfinite", (double)nonfinite);
    cJSON *host = cJSON_AddObjectToObject(root, "host");
    cJSON_AddNumberToObject(host, "seconds", secs);
    cJSON_AddNumberToObject(host, "load_seconds", t_load - t0);
    cJSON_AddNumberToObject(host, "bvh_pack_seconds", t_pack - t_load);
    cJSON_AddNumberToObject(host, "threads", threads);
    cJSON_AddNumberToObject(host, "rays_per_second", secs > 0 ? (double)total_rays / secs : 0.0);
    json_text = cJSON_Print(root);
    snprintf(path, sizeof path, "%s/report.json", o->out_dir);
    if (!json_text || write_text(path, json_text, err, errlen) != 0)
        goto out;

    char txt[4096];
    snprintf(txt, sizeof txt,
             "sfsim report -- mode reference (golden model: no timing)\n"
             "scene        %s\n"
             "             %u triangles, %u spheres, %u lights; needs: %s\n"
             "             BVH %u nodes, %u leaves, depth %u, SAH cost %.2f; %u bytes of scene memory\n"
             "image        %d x %d, %d spp, max depth %d, seed %u, tiles %d x %d (M = %d)\n"
             "             mean %.5f, non-finite values %ld\n"
             "rays         %llu total: %llu primary, %llu shadow, %llu indirect; %llu dropped\n"
             "traversal    %llu nodes visited, %llu primitive tests\n"
             "host         %.2f s rendering on %d threads (%.3f M rays/s); load %.2f s, BVH+pack %.2f s\n",
             o->scene_path, s.ntris, s.nspheres, p.nlights, needs[0] ? needs : "-", p.bvh.nnodes,
             p.bvh.nleaves, p.bvh.depth, p.bvh.sah_cost, p.size, s.render.width, s.render.height,
             s.render.spp, s.render.max_depth, o->seed, rp.tile, rp.tile, o->stream_rays, sum / (3.0 * (double)npx),
             nonfinite, (unsigned long long)total_rays, (unsigned long long)st.rays[REF_RAY_CAMERA],
             (unsigned long long)st.rays[REF_RAY_SHADOW], (unsigned long long)st.rays[REF_RAY_INDIRECT],
             (unsigned long long)st.dropped, (unsigned long long)st.nodes_visited,
             (unsigned long long)st.prims_tested, secs, threads, secs > 0 ? 1e-6 * (double)total_rays / secs : 0.0,
             t_load - t0, t_pack - t_load);
    snprintf(path, sizeof path, "%s/report.txt", o->out_dir);
    if (write_text(path, txt, err, errlen) != 0)
        goto out;
    rc = 0;
out:
    cJSON_free(json_text);
    cJSON_Delete(root);
    free(rgb);
    pack_free(&p);
    scene_free(&s);
    return rc;
}
