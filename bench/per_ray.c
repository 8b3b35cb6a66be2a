/* bench/per_ray.c -- host time per traced ray of each engine against Embree, on the same rays,
 * measured in one run on one host thread.
 *
 * For each scene (the shipped Cornell box, the conference room and sponza by default) it makes
 * three batches of rays:
 *   primary  SIDE x SIDE camera rays through the scene's camera (one jittered ray per cell),
 *   diffuse  one cosine-weighted ray from each primary hit (closest hit),
 *   shadow   one ray from each primary hit toward a point on a light (any hit): a quad light's
 *            surface, a point or spot light's position, far along a directional light, an emissive
 *            triangle; a scene without lights: a random point inside its bounds.
 * Each batch goes through Embree 3 (rtcIntersect1 / rtcOccluded1, robust, the high-quality build,
 * one thread), the golden model, functional mode and detailed mode (the kernel's traversal and
 * intersection, `sfsim trace`'s path; N = 16, M = 4096), detailed mode with the memory hierarchy
 * on (the 16-core chip of configs/chip16-ddr4.ini: L1s, a shared L2, a network and DDR4; the
 * batches handed out to its cores), best of REPS runs each (the engines take
 * turns, one run each per round), and the bench prints ns per ray, the kernel's instructions per
 * ray and each engine's ratio to Embree.
 * The three engines of ours must return identical hits and Embree must agree with them (the rule
 * of tests/support/xcheck.c), or the bench fails.
 *
 * It also times the conference-size question of issue 17: our BVH build and pack (accel_pack)
 * against Embree's high-quality build on one thread, best of REPS; and the start-to-exit wall time
 * of `bin/sfsim run` of a 32 x 32, 1 spp Cornell frame (best of 5), when bin/sfsim is built.
 *
 * usage: per_ray [--save-rays DIR] [SIDE [REPS]] [-- SCENE ...]   (default 256 3; run from the
 * repository root). --save-rays writes each batch as DIR/SCENE-KIND.rays (the binary ray format of
 * docs/trace.md), so that one engine can be profiled alone on the same rays:
 * `bin/sfsim trace -s SCENE --rays DIR/conference-diffuse.rays --mode detailed -j 1 -o hits`.
 * Not a test: numbers depend on the host. docs/performance.md quotes runs.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "../sim/raybatch.h"
#include "../sim/reference.h"
#include "../sim/run/accel.h"
#include "../sim/run/run.h"
#include "../sim/util.h"
#include "../tests/support/xcheck.h"
#include "bench_scenes.h"

enum { ENG_EMBREE, ENG_GOLDEN, ENG_FUNCTIONAL, ENG_DETAILED, ENG_HIER, ENG_COUNT };

/* ENG_HIER: detailed mode on the chip of configs/chip16-ddr4.ini (16 cores, each with its L1, a
 * shared 4 MB L2, a network and DDR4-2400; the batches of M rays handed out to the cores in
 * simulated time), the memory hierarchy on (docs/chip.md). */
static const char *const hier_config = "configs/chip16-ddr4.ini";
static CfgMachine hier_cfg;

typedef struct Batch {
    const char *kind;          /* primary, diffuse, shadow */
    RayBatch b;
} Batch;

typedef struct Timing {
    double seconds[ENG_COUNT];     /* best of reps */
    uint64_t instructions;         /* the kernel's, functional mode */
    uint64_t agree, ties, disagree; /* Embree against the golden model */
    int ours_differ;               /* functional or detailed hits differ from the golden model's */
} Timing;

static float dot3(const float *a, const float *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(float *v)
{
    float l = sqrtf(dot3(v, v));
    if (l > 0.0f)
        for (int k = 0; k < 3; k++)
            v[k] /= l;
}

static int batch_alloc(Batch *bt, const char *kind, uint32_t n)
{
    bt->kind = kind;
    bt->b.count = 0;
    bt->b.rays = calloc(n ? n : 1, sizeof *bt->b.rays);
    return bt->b.rays ? 0 : -1;
}

/* SIDE x SIDE camera rays through the packed camera (the scene.ini's), one jittered ray per cell. */
static void make_primary(const PackedScene *p, uint32_t side, Batch *bt)
{
    for (uint32_t i = 0; i < side * side; i++) {
        uint32_t key = ref_path_key(7, i, 0);
        float px = ((float)(i % side) + ref_rand(key, 0, 0)) / (float)side - 0.5f;
        float py = 0.5f - ((float)(i / side) + ref_rand(key, 0, 1)) / (float)side;
        BatchRay *r = &bt->b.rays[bt->b.count++];
        for (int k = 0; k < 3; k++) {
            r->org[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_POS + k));
            r->dir[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_W + k)) + px * sm_f32(p, sm_hdr(p, SM_HDR_CAM_U + k)) +
                        py * sm_f32(p, sm_hdr(p, SM_HDR_CAM_V + k));
        }
        normalize3(r->dir);
        r->tmax = INFINITY;
        r->query = RAY_CLOSEST;
    }
}

/* The hit point of primary ray r (hit h) lifted off its triangle along the geometric normal that
 * faces the ray, into org; the normal into n. -1 for a primitive that is not a triangle. */
static int hit_frame(const RunScene *sc, const BatchRay *r, const BatchHit *h, float eps, float *org, float *n)
{
    const PackedScene *p = &sc->p;
    uint32_t prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    uint32_t src = sm_u32(p, sm_rec(prims, SM_PRIM_WORDS, h->prim, SM_PRIM_SRC));
    if (src >= sc->s.ntris)
        return -1;
    const float *v = &sc->s.pos[9 * (size_t)src];
    float e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = v[3 + k] - v[k];
        e2[k] = v[6 + k] - v[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    normalize3(n);
    if (dot3(n, r->dir) > 0.0f)
        for (int k = 0; k < 3; k++)
            n[k] = -n[k];
    for (int k = 0; k < 3; k++)
        org[k] = r->org[k] + h->t * r->dir[k] + eps * n[k];
    return 0;
}

/* A cosine-weighted direction about n from two uniform numbers. */
static void cosine_dir(const float *n, float u1, float u2, float *d)
{
    float a[3] = {fabsf(n[0]) > 0.9f ? 0.0f : 1.0f, fabsf(n[0]) > 0.9f ? 1.0f : 0.0f, 0.0f};
    float t[3] = {a[1] * n[2] - a[2] * n[1], a[2] * n[0] - a[0] * n[2], a[0] * n[1] - a[1] * n[0]};
    normalize3(t);
    float b[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
    float r = sqrtf(u1), phi = 6.2831853f * u2, z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    for (int k = 0; k < 3; k++)
        d[k] = r * cosf(phi) * t[k] + r * sinf(phi) * b[k] + z * n[k];
    normalize3(d);
}

/* A point to aim shadow ray i at (key: its random stream); *far: a directional light (aim along
 * -direction without an end). */
static void light_point(const Scene *s, const PackedScene *p, uint32_t key, float *q, int *far)
{
    *far = 0;
    uint32_t nl = s->nlights + s->nemissive;
    float u = ref_rand(key, 2, 1), v = ref_rand(key, 2, 2);
    if (nl == 0) {
        for (int k = 0; k < 3; k++) {
            float lo = sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MIN + k)), hi = sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MAX + k));
            q[k] = lo + ref_rand(key, 2, 3 + (uint32_t)k) * (hi - lo);
        }
        return;
    }
    uint32_t j = (uint32_t)(ref_rand(key, 2, 0) * (float)nl);
    if (j >= nl)
        j = nl - 1;
    if (j >= s->nlights) {
        const float *v0 = &s->pos[9 * (size_t)s->emissive_tris[j - s->nlights]];
        if (u + v > 1.0f) {
            u = 1.0f - u;
            v = 1.0f - v;
        }
        for (int k = 0; k < 3; k++)
            q[k] = v0[k] + u * (v0[3 + k] - v0[k]) + v * (v0[6 + k] - v0[k]);
        return;
    }
    const SceneLight *l = &s->lights[j];
    for (int k = 0; k < 3; k++) {
        q[k] = l->position[k];
        if (l->kind == SCENE_LIGHT_QUAD)
            q[k] += u * l->edge_u[k] + v * l->edge_v[k];
        else if (l->kind == SCENE_LIGHT_DIRECTIONAL)
            q[k] = -l->direction[k];
    }
    *far = l->kind == SCENE_LIGHT_DIRECTIONAL;
}

/* From every primary hit on a triangle: a diffuse ray and a shadow ray. */
static void make_secondary(const RunScene *sc, const Batch *prim, const BatchHit *hits, Batch *dif, Batch *shd)
{
    const PackedScene *p = &sc->p;
    float ext = 0.0f;
    for (int k = 0; k < 3; k++)
        ext = fmaxf(ext, sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MAX + k)) - sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MIN + k)));
    float eps = 1e-4f * ext;
    for (uint32_t i = 0; i < prim->b.count; i++) {
        float org[3], n[3], q[3];
        if (hits[i].prim == UINT32_MAX || hits[i].invalid || hit_frame(sc, &prim->b.rays[i], &hits[i], eps, org, n))
            continue;
        uint32_t key = ref_path_key(7, i, 1);
        BatchRay *d = &dif->b.rays[dif->b.count++];
        memcpy(d->org, org, sizeof org);
        cosine_dir(n, ref_rand(key, 1, 0), ref_rand(key, 1, 1), d->dir);
        d->tmax = INFINITY;
        d->query = RAY_CLOSEST;
        BatchRay *s = &shd->b.rays[shd->b.count++];
        memcpy(s->org, org, sizeof org);
        int far;
        light_point(&sc->s, p, key, q, &far);
        for (int k = 0; k < 3; k++)
            s->dir[k] = far ? q[k] : q[k] - org[k];
        float len = sqrtf(dot3(s->dir, s->dir));
        normalize3(s->dir);
        s->tmax = far || len == 0.0f ? INFINITY : len * (1.0f - 1e-4f);
        s->query = RAY_ANY;
    }
}

static RefRay ref_ray(const BatchRay *r)
{
    RefRay q = {{r->org[0], r->org[1], r->org[2]}, {r->dir[0], r->dir[1], r->dir[2]}, r->tmax};
    return q;
}

/* Embree over the batch, best of reps (the loop of queries alone is timed), and its agreement with
 * the golden model's hits. */
static double embree_time(const RunScene *sc, const XcheckEmbree *e, const Batch *bt, const BatchHit *golden,
                          int reps, Timing *tm)
{
    uint32_t n = bt->b.count;
    struct RTCRayHit *rh = malloc(sizeof *rh * (n ? n : 1));
    if (!rh)
        return -1.0;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    double best = INFINITY;
    for (int rep = 0; rep < reps; rep++) {
        for (uint32_t i = 0; i < n; i++) {
            RefRay q = ref_ray(&bt->b.rays[i]);
            memset(&rh[i], 0, sizeof rh[i]);
            xcheck_embree_ray(&q, &rh[i].ray);
            rh[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
        }
        double t0 = util_now();
        for (uint32_t i = 0; i < n; i++)
            if (bt->b.rays[i].query == RAY_ANY)
                rtcOccluded1(e->scene, &ctx, &rh[i].ray);
            else
                rtcIntersect1(e->scene, &ctx, &rh[i]);
        best = fmin(best, util_now() - t0);
    }
    for (uint32_t i = 0; i < n; i++) {
        const BatchRay *r = &bt->b.rays[i];
        XcheckVerdict v;
        if (r->query == RAY_ANY) {
            v = (rh[i].ray.tfar == -INFINITY) == (golden[i].prim != 0) ? XCHECK_AGREE : XCHECK_DISAGREE;
        } else {
            RefRay q = ref_ray(r);
            RefHit oh = {.prim = golden[i].prim, .t = golden[i].t, .u = golden[i].u, .v = golden[i].v};
            v = xcheck_compare(&sc->s, &sc->p, &q, &oh, rh[i].hit.geomID != RTC_INVALID_GEOMETRY_ID, rh[i].hit.primID,
                               rh[i].ray.tfar);
        }
        tm->agree += v == XCHECK_AGREE;
        tm->ties += v == XCHECK_TIE;
        tm->disagree += v == XCHECK_DISAGREE;
    }
    free(rh);
    return best;
}

/* One of our engines over the batch, best of reps; its hits into hits. -1 after printing why. */
static double ours_time(const RunScene *sc, RunMode mode, const CfgMachine *cfg, const Batch *bt, int reps,
                        BatchHit *hits, uint64_t *instructions)
{
    static char err[65536];
    RunSpec spec = {.mode = mode, .cfg = cfg, .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = 1};
    double best = INFINITY;
    for (int rep = 0; rep < reps; rep++) {
        RunTrace rt;
        if (run_trace(&sc->p, sc->image, sc->s.needs, &spec, &bt->b, hits, &rt, err, sizeof err) != 0) {
            fprintf(stderr, "per_ray: %s\n", err);
            return -1.0;
        }
        best = fmin(best, rt.seconds);
        if (instructions)
            *instructions = rt.instructions;
    }
    return best;
}

/* Every engine over one batch, best of reps each. The engines take turns, one run each per round,
 * so a busy spell on a shared host weighs on all of them alike rather than on whichever ran then.
 * Embree's agreement is counted in the first round. 0, or -1 after printing why. */
static int batch_time(const RunScene *sc, const XcheckEmbree *e, const Batch *bt, int reps, Timing *tm)
{
    memset(tm, 0, sizeof *tm);
    uint32_t n = bt->b.count ? bt->b.count : 1;
    BatchHit *golden = calloc(n, sizeof *golden), *other = calloc(n, sizeof *other);
    int rc = -1;
    if (!golden || !other) {
        fprintf(stderr, "per_ray: out of memory for %u hits\n", n);
        goto out;
    }
    for (int k = 0; k < ENG_COUNT; k++)
        tm->seconds[k] = INFINITY;
    static const RunMode kernel_modes[3] = {RUN_FUNCTIONAL, RUN_DETAILED, RUN_DETAILED};
    for (int rep = 0; rep < reps; rep++) {
        double s;
        if ((s = ours_time(sc, RUN_REFERENCE, NULL, bt, 1, golden, NULL)) < 0)
            goto out;
        tm->seconds[ENG_GOLDEN] = fmin(tm->seconds[ENG_GOLDEN], s);
        Timing agree = {0};
        if ((s = embree_time(sc, e, bt, golden, 1, &agree)) < 0)
            goto out;
        tm->seconds[ENG_EMBREE] = fmin(tm->seconds[ENG_EMBREE], s);
        if (rep == 0) {
            tm->agree = agree.agree;
            tm->ties = agree.ties;
            tm->disagree = agree.disagree;
        }
        for (int m = 0; m < 3; m++) {
            uint64_t instr = 0;
            if ((s = ours_time(sc, kernel_modes[m], m == 2 ? &hier_cfg : NULL, bt, 1, other, &instr)) < 0)
                goto out;
            tm->seconds[ENG_FUNCTIONAL + m] = fmin(tm->seconds[ENG_FUNCTIONAL + m], s);
            if (m == 0)
                tm->instructions = instr;
            tm->ours_differ |= memcmp(golden, other, sizeof *golden * bt->b.count) != 0;
        }
    }
    rc = 0;
out:
    free(golden);
    free(other);
    return rc;
}

static void print_row(const char *scene, const Batch *bt, const Timing *tm)
{
    double n = bt->b.count ? (double)bt->b.count : 1.0;
    printf("%-12s %-8s %8u", scene, bt->kind, bt->b.count);
    for (int e = 0; e < ENG_COUNT; e++)
        printf(" %9.1f", 1e9 * tm->seconds[e] / n);
    printf(" %8.1f", (double)tm->instructions / n);
    for (int e = ENG_GOLDEN; e < ENG_COUNT; e++)
        printf(" %7.1fx", tm->seconds[e] / tm->seconds[ENG_EMBREE]);
    printf(" %7.3f%%%s%s\n", 100.0 * (double)(tm->agree + tm->ties) / n, tm->ours_differ ? "  OUR ENGINES DIFFER" : "",
           tm->disagree ? "  EMBREE DISAGREES" : "");
}

/* Our BVH build and pack against Embree's build, best of reps each. */
static int build_time(const RunScene *sc, int reps, double *ours, double *embree)
{
    *ours = *embree = INFINITY;
    CfgMachine cfg;
    cfg_defaults(&cfg);
    for (int rep = 0; rep < reps; rep++) {
        char err[4096];
        PackedScene p;
        AccelInfo info;
        int rc = accel_pack(&sc->s, &cfg, 0, &p, &info, err, sizeof err);
        pack_free(&p);
        XcheckEmbree e;
        if (rc != 0 || xcheck_embree_open(&sc->s, &e, err, sizeof err) != 0) {
            fprintf(stderr, "per_ray: %s\n", err);
            return -1;
        }
        *ours = fmin(*ours, info.pack_seconds);
        *embree = fmin(*embree, e.build_seconds);
        xcheck_embree_close(&e);
    }
    return 0;
}

/* "scenes/conference/scene.ini" -> "conference"; "x/bunny.glb" -> "bunny.glb". */
static void scene_label(const char *path, char *label, size_t len)
{
    const char *base = strrchr(path, '/');
    if (base && !strcmp(base, "/scene.ini")) {
        const char *dir = base;
        while (dir > path && dir[-1] != '/')
            dir--;
        snprintf(label, len, "%.*s", (int)(base - dir), dir);
    } else {
        snprintf(label, len, "%s", base ? base + 1 : path);
    }
}

/* DIR/LABEL-KIND.rays in the binary format of docs/trace.md, whole or not at all. */
static int save_rays(const char *dir, const char *label, const Batch *bt)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s-%s.rays", dir, label, bt->kind);
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "per_ray: %s: cannot create: %s\n", path, strerror(errno));
        return -1;
    }
    unsigned char head[16] = {0};
    memcpy(head, RAYBATCH_MAGIC, 8);
    uint32_t count = bt->b.count;
    for (int k = 0; k < 4; k++)
        head[8 + k] = (unsigned char)(count >> (8 * k));
    int ok = fwrite(head, 1, sizeof head, f) == sizeof head;
    for (uint32_t i = 0; ok && i < count; i++) {
        const BatchRay *r = &bt->b.rays[i];
        float v[7] = {r->org[0], r->org[1], r->org[2], r->dir[0], r->dir[1], r->dir[2], r->tmax};
        unsigned char rec[32];
        for (int k = 0; k < 7; k++) {
            uint32_t w;
            memcpy(&w, &v[k], 4);
            for (int b = 0; b < 4; b++)
                rec[4 * k + b] = (unsigned char)(w >> (8 * b));
        }
        for (int b = 0; b < 4; b++)
            rec[28 + b] = (unsigned char)(r->query >> (8 * b));
        ok = fwrite(rec, 1, sizeof rec, f) == sizeof rec;
    }
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "per_ray: %s: write failed\n", path);
        remove(path);
        return -1;
    }
    printf("per_ray: wrote %s (%u rays)\n", path, count);
    return 0;
}

static int scene_run(const char *path, uint32_t side, int reps, const char *save_dir)
{
    char err[65536];
    RunScene sc;
    if (run_scene_open(&sc, path, NULL, NULL, RUN_DETAILED, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "per_ray: %s\n", err);
        run_scene_close(&sc);
        return -1;
    }
    char label[64];
    scene_label(path, label, sizeof label);
    uint32_t n = side * side;
    Batch bt[3];
    BatchHit *hits = calloc(n, sizeof *hits);
    XcheckEmbree e;
    int rc = -1, opened = 0;
    memset(bt, 0, sizeof bt);
    if (!hits || batch_alloc(&bt[0], "primary", n) || batch_alloc(&bt[1], "diffuse", n) ||
        batch_alloc(&bt[2], "shadow", n)) {
        fprintf(stderr, "per_ray: out of memory for %u rays\n", n);
        goto out;
    }
    if (xcheck_embree_open(&sc.s, &e, err, sizeof err) != 0) {
        fprintf(stderr, "per_ray: %s: %s\n", path, err);
        goto out;
    }
    opened = 1;
    make_primary(&sc.p, side, &bt[0]);
    RunSpec golden = {.mode = RUN_REFERENCE, .threads = 1};
    if (run_trace(&sc.p, sc.image, sc.s.needs, &golden, &bt[0].b, hits, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "per_ray: %s\n", err);
        goto out;
    }
    make_secondary(&sc, &bt[0], hits, &bt[1], &bt[2]);
    for (int k = 0; save_dir && k < 3; k++)
        if (save_rays(save_dir, label, &bt[k]) != 0)
            goto out;
    rc = 0;
    for (int k = 0; k < 3; k++) {
        Timing tm;
        if (batch_time(&sc, &e, &bt[k], reps, &tm) != 0) {
            rc = -1;
            goto out;
        }
        print_row(label, &bt[k], &tm);
        fflush(stdout);
        rc |= tm.ours_differ || tm.disagree;
    }
    double ob, eb;
    if (build_time(&sc, reps, &ob, &eb) != 0)
        rc = -1;
    else
        printf("%-12s build    %8u triangles: our BVH build and pack %.3f s, Embree high-quality build %.3f s: %.2fx\n",
               label, sc.s.ntris, ob, eb, ob / eb);
out:
    if (opened)
        xcheck_embree_close(&e);
    for (int k = 0; k < 3; k++)
        free(bt[k].b.rays);
    free(hits);
    run_scene_close(&sc);
    return rc;
}

/* Wall time of `bin/sfsim run` of a 32 x 32, 1 spp Cornell frame, start to exit, best of 5. */
static void startup_time(void)
{
    if (access("bin/sfsim", X_OK) != 0) {
        printf("per_ray: skipped the start-up time: bin/sfsim is not built (make)\n");
        return;
    }
    char dir[] = "/tmp/per_ray_XXXXXX";
    if (!mkdtemp(dir)) {
        perror("per_ray: mkdtemp");
        return;
    }
    double best = INFINITY;
    int status = 0;
    for (int rep = 0; rep < 5; rep++) {
        fflush(stdout); /* or the child's freopen writes the parent's buffered lines again */
        double t0 = util_now();
        pid_t pid = fork();
        if (pid == 0) {
            FILE *quiet = freopen("/dev/null", "w", stdout);
            if (!quiet || dup2(STDOUT_FILENO, STDERR_FILENO) < 0)
                _exit(126);
            execl("bin/sfsim", "sfsim", "run", "-s", "scenes/cornell/scene.ini", "-o", dir, "--set", "render.width=32",
                  "--set", "render.height=32", "--set", "render.spp=1", "-j", "1", "--no-progress", (char *)NULL);
            _exit(127);
        }
        if (pid < 0 || waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
            printf("per_ray: bin/sfsim run failed (status %d)\n", status);
            break;
        }
        best = fmin(best, util_now() - t0);
    }
    if (best < INFINITY)
        printf("start-up: bin/sfsim run, Cornell 32 x 32 x 1 spp, detailed, 1 thread: %.3f s wall, start to exit\n", best);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd) != 0)
        printf("per_ray: could not remove %s\n", dir);
}

int main(int argc, char **argv)
{
    static const char *const defaults[] = {"scenes/cornell/scene.ini", "scenes/conference/scene.ini",
                                           "scenes/sponza-dabrovic/scene.ini"};
    uint32_t side = 256;
    int reps = 3, a = 1;
    const char *save_dir = NULL;
    if (a + 1 < argc && !strcmp(argv[a], "--save-rays")) {
        save_dir = argv[a + 1];
        a += 2;
    }
    if (a < argc && strcmp(argv[a], "--"))
        side = (uint32_t)strtoul(argv[a++], NULL, 10);
    if (a < argc && strcmp(argv[a], "--"))
        reps = atoi(argv[a++]);
    const char *const *list = defaults;
    int n = (int)(sizeof defaults / sizeof defaults[0]);
    if (a < argc && !strcmp(argv[a], "--")) {
        list = (const char *const *)argv + a + 1;
        n = argc - a - 1;
        a = argc;
    }
    if (a != argc || side < 1 || side > 4096 || reps < 1 || reps > 100 || n < 1) {
        fprintf(stderr, "usage: per_ray [--save-rays DIR] [SIDE [REPS]] [-- SCENE ...]   (SIDE 1..4096, default 256; REPS 1..100, "
                        "default 3)\n");
        return 2;
    }
    printf("per traced ray on 1 host thread, best of %d; %u x %u camera rays, then a diffuse and a shadow ray per hit; "
           "kernel modes N = 16, M = 4096\n",
           reps, side, side);
    CfgErrors ce = {0};
    cfg_defaults(&hier_cfg);
    if (cfg_load(&hier_cfg, hier_config, &ce) != 0) {
        fprintf(stderr, "per_ray: %s: the chip for the hierarchy's row cannot be read\n", hier_config);
        cfg_errors_free(&ce);
        return 1;
    }
    cfg_errors_free(&ce);
    printf("'hier': detailed mode with the memory hierarchy on, the chip of %s (%d cores, L2 %d KB, DRAM %s)\n",
           hier_config, hier_cfg.chip_cores, hier_cfg.l2_size_kb, cfg_enum_name("dram", "preset", hier_cfg.dram_preset));
    printf("%-12s %-8s %8s %9s %9s %9s %9s %9s %8s %8s %8s %8s %8s %8s\n", "scene", "rays", "count", "embree ns",
           "golden ns", "func ns", "detail ns", "hier ns", "instr", "golden/E", "func/E", "detail/E", "hier/E", "agree");
    int rc = 0, skipped = 0;
    for (int i = 0; i < n; i++) {
        int ok = bench_scene_ok("per_ray", list[i], &skipped);
        if (ok < 0)
            return 1;
        if (ok && scene_run(list[i], side, reps, save_dir) != 0)
            rc = 1;
    }
    startup_time();
    bench_scenes_summary("per_ray", skipped, n);
    return rc;
}
