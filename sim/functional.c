/* sim/functional.c -- the functional mode: kernels/pathtrace.s on functional cores, one tile per
 * run, host threads over tiles.
 *
 * Owns: the kernel's build symbols, its launch block and counters (by name from the object's
 * symbol table: kernels/lib/abi.inc is their only definition), copying tiles out of the
 * framebuffer. Must not: compute radiance, or make results depend on the thread count (each
 * tile's pixels come from its own run only).
 */
#include "functional.h"
#include "sampling.h"

#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../asm/asm.h"
#include "datadir.h"
#include "ref_kd.h"

const char *const func_kd_kind_keys[FUNC_KD_KINDS] = {"camera", "indirect", "shadow"};
const char *const func_kd_counter_keys[FUNC_KD_COUNTERS] = {"nodes", "leaves", "prims", "restarts", "overflows",
                                                            "underflows"};

const char *func_default_kernel(char *buf, size_t len)
{
    const char *env = getenv("SFSIM_KERNEL");
    if (env && *env) {
        snprintf(buf, len, "%s", env);
        return buf;
    }
    char err[PATH_MAX + 256];
    if (datadir_path(DATADIR_KERNEL, buf, len, err, sizeof err))
        return buf;
    /* no data folder: name the file where a build tree keeps it, so the error names a path */
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    exe[n > 0 ? n : 0] = 0;
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = 0;
    snprintf(buf, len, "%s/../%s", n > 0 ? exe : ".", DATADIR_KERNEL);
    return buf;
}

/* The ABI constants the host needs, looked up by name. */
typedef struct Abi {
    uint32_t l_x0, l_y0, l_w, l_h, l_seed, l_error;
    uint32_t st_dropped, st_camera, st_indirect, st_shadow, st_generations, st_per_gen, st_max_gen;
    uint32_t st_gen_base, st_gen_bytes, st_g_trav, st_g_isect, st_g_shade;
    uint32_t stack_base, ray_fields, err_stack, err_generations;
    uint32_t f_org[3], f_dir[3], f_tmax, f_kind, f_prim, f_u, f_v;
    uint32_t spad_clear;       /* the host zeroes the scratchpad below it before each run */
    uint32_t kc_base, kc_counters, kc_vec_bytes;
    uint32_t kc[FUNC_KD_COUNTERS], kind[FUNC_KD_KINDS]; /* in FuncStats order */
    uint32_t kstack_base;      /* ACCEL_KD builds only */
} Abi;

static const AsmSymbol *abi_find(const AsmObject *obj, const char *name)
{
    const AsmSymbol *found = NULL;
    for (uint32_t s = 0; s < obj->nsyms; s++)
        if (!strcmp(obj->syms[s].name, name))
            found = &obj->syms[s];
    return found;
}

static int abi_lookup(const AsmObject *obj, Abi *abi, char *err, size_t errlen)
{
    static const struct { const char *name; size_t off; } names[] = {
#define A(field, name) {name, offsetof(Abi, field)}
        A(l_x0, "L_X0"), A(l_y0, "L_Y0"), A(l_w, "L_W"), A(l_h, "L_H"), A(l_seed, "L_SEED"),
        A(l_error, "L_ERROR"), A(st_dropped, "ST_DROPPED"), A(st_camera, "ST_CAMERA"),
        A(st_indirect, "ST_INDIRECT"), A(st_shadow, "ST_SHADOW"), A(st_generations, "ST_GENERATIONS"),
        A(st_per_gen, "ST_PER_GEN"), A(st_max_gen, "ST_MAX_GEN"), A(st_gen_base, "ST_GEN_BASE"),
        A(st_gen_bytes, "ST_GEN_BYTES"), A(st_g_trav, "ST_G_TRAV"), A(st_g_isect, "ST_G_ISECT"),
        A(st_g_shade, "ST_G_SHADE"), A(stack_base, "STACK_BASE"), A(ray_fields, "RAY_FIELDS"),
        A(err_stack, "ERR_STACK"), A(err_generations, "ERR_GENERATIONS"), A(f_org[0], "F_ORGX"),
        A(f_org[1], "F_ORGY"), A(f_org[2], "F_ORGZ"), A(f_dir[0], "F_DIRX"), A(f_dir[1], "F_DIRY"),
        A(f_dir[2], "F_DIRZ"), A(f_tmax, "F_TMAX"), A(f_kind, "F_KIND"), A(f_prim, "F_PRIM"), A(f_u, "F_U"),
        A(f_v, "F_V"), A(spad_clear, "SPAD_CLEAR"), A(kc_base, "KC_BASE"), A(kc_counters, "KC_COUNTERS"),
        A(kc_vec_bytes, "KC_VEC_BYTES"), A(kc[FUNC_KD_NODES], "KC_NODES"), A(kc[FUNC_KD_LEAVES], "KC_LEAVES"),
        A(kc[FUNC_KD_PRIMS], "KC_PRIMS"), A(kc[FUNC_KD_RESTARTS], "KC_RESTARTS"),
        A(kc[FUNC_KD_OVERFLOWS], "KC_OVERFLOWS"), A(kc[FUNC_KD_UNDERFLOWS], "KC_UNDERFLOWS"),
        A(kind[FUNC_KD_CAMERA], "KIND_CAMERA"), A(kind[FUNC_KD_INDIRECT], "KIND_INDIRECT"),
        A(kind[FUNC_KD_SHADOW], "KIND_SHADOW"),
#undef A
    };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        const AsmSymbol *found = abi_find(obj, names[i].name);
        if (!found) {
            snprintf(err, errlen, "kernel: symbol %s missing (kernels/lib/abi.inc defines the host interface)",
                     names[i].name);
            return -1;
        }
        *(uint32_t *)((char *)abi + names[i].off) = found->value;
    }
    if (abi->st_max_gen > FUNC_MAX_GENERATIONS) {
        snprintf(err, errlen, "kernel: ST_MAX_GEN %u exceeds the host's %d", abi->st_max_gen, FUNC_MAX_GENERATIONS);
        return -1;
    }
    return 0;
}

/* ---- kd-tree (accel.structure = kd) ------------------------------------------------------------ */

/* Bytes per entry of the kd kernel's stacks (kernels/pathtrace.s owns their layout). */
#define KD_PACKET_ENTRY_BYTES 1040u /* packet short stack, in the scratchpad from KSTACK_BASE */
#define KD_STREAM_ENTRY_BYTES 36u   /* stream-filter stack, 3 * depth + 8 entries like the BVH kernel's */
#define KD_LANE_ENTRY_BYTES 1024u   /* per-lane stacks, in the next generation's ray buffer */

/* The kernel's KD_VARIANT constants (kernels/lib/kconst.inc, generated from kd.traversal's names). */
static const char *const kd_variant_syms[CFG_KD_TRAVERSALS] = {"KD_STACK", "KD_RESTART", "KD_PUSHDOWN",
                                                               "KD_SHORTSTACK", "KD_PACKET", "KD_STREAM"};

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void kd_params(const CfgMachine *cfg, KdParams *kp)
{
    kd_default_params(kp);
    kp->cost_traversal = (float)cfg->kd_cost_traversal;
    kp->cost_intersect = (float)cfg->kd_cost_intersect;
    kp->empty_bonus = (float)cfg->kd_empty_bonus;
    kp->max_depth = cfg->kd_max_depth;
    kp->leaf_size = cfg->kd_leaf_size;
}

static void kd_info(const KdTree *t, FuncKdInfo *info)
{
    info->nodes = t->nnodes;
    info->leaves = t->nleaves;
    info->empty_leaves = t->nempty;
    info->depth = t->depth;
    info->largest_leaf = t->max_leaf;
    info->prims = t->nprims;
    info->refs = t->nrefs;
    info->sah_cost = t->sah_cost;
}

/* The invariants are checked on every build, as the BVH's are (scenes/pack.c): a broken tree
 * would silently lose geometry. */
static int kd_check_packed(const PackedScene *p, const KdTree *t, const CfgMachine *cfg, char *err, size_t errlen)
{
    float *bmin, *bmax;
    if (ref_kd_prim_boxes(p, &bmin, &bmax) != 0) {
        snprintf(err, errlen, "accel.structure = kd: out of memory for %u primitive boxes", p->nprims);
        return -1;
    }
    char why[512];
    int rc = kd_check(t, bmin, bmax, why, sizeof why);
    if (rc != 0)
        snprintf(err, errlen,
                 "accel.structure = kd: the kd-tree built with kd.cost_traversal = %g, kd.cost_intersect = %g, "
                 "kd.empty_bonus = %g, kd.max_depth = %d, kd.leaf_size = %d breaks an invariant: %s",
                 cfg->kd_cost_traversal, cfg->kd_cost_intersect, cfg->kd_empty_bonus, cfg->kd_max_depth,
                 cfg->kd_leaf_size, why);
    free(bmin);
    free(bmax);
    return rc;
}

int func_add_kd(PackedScene *p, const CfgMachine *cfg, FuncKdInfo *info, char *err, size_t errlen)
{
    memset(info, 0, sizeof *info);
    if (cfg->accel_structure != CFG_ACCEL_KD)
        return 0;
    double t0 = now();
    KdParams kp;
    kd_params(cfg, &kp);
    KdTree t;
    char why[512];
    if (ref_kd_build(p, &kp, &t, why, sizeof why) != 0) {
        snprintf(err, errlen, "accel.structure = kd: %s", why);
        return -1;
    }
    int rc = kd_check_packed(p, &t, cfg, err, errlen);
    if (rc == 0 && (rc = pack_add_kd(p, &t, why, sizeof why)) != 0)
        snprintf(err, errlen, "accel.structure = kd: %s", why);
    if (rc == 0)
        kd_info(&t, info);
    kd_free(&t);
    info->build_seconds = now() - t0;
    return rc;
}

/* KD_STACK_DEPTH: the entries of the kernel's per-ray (or per-packet) stack. */
static uint32_t kd_stack_depth(const CfgMachine *cfg, const PackedScene *p)
{
    switch (cfg->kd_traversal) {
    case CFG_KD_STACK:
        return p->kd_depth + 1; /* a full stack never overflows: an entry per level, and one more */
    case CFG_KD_SHORTSTACK:
    case CFG_KD_PACKET:
        return (uint32_t)cfg->kd_stack_depth;
    default:
        return 1;               /* restart, push-down and the stream filter keep no per-ray stack */
    }
}

/* The kd part of the object's interface: KSTACK_BASE; the chosen variant's constant must be the
 * value the host passed as KD_VARIANT; the counters of N lanes must lie below SPAD_CLEAR, so that
 * each run starts them at 0. */
static int kd_abi_lookup(const AsmObject *obj, const CfgMachine *cfg, Abi *abi, char *err, size_t errlen)
{
    const AsmSymbol *ks = abi_find(obj, "KSTACK_BASE");
    const AsmSymbol *vs = abi_find(obj, kd_variant_syms[cfg->kd_traversal]);
    if (!ks || !vs) {
        snprintf(err, errlen, "kernel: symbol %s missing (kernels/lib/abi.inc defines the host interface)",
                 ks ? kd_variant_syms[cfg->kd_traversal] : "KSTACK_BASE");
        return -1;
    }
    if (vs->value != (uint32_t)cfg->kd_traversal) {
        snprintf(err, errlen, "kernel: %s = %u, but the host passes KD_VARIANT = %d for kd.traversal = %s",
                 vs->name, vs->value, cfg->kd_traversal, cfg_enum_name("kd", "traversal", cfg->kd_traversal));
        return -1;
    }
    abi->kstack_base = ks->value;
    uint64_t lanes_bytes = 4ull * (uint64_t)cfg->core_simd_width;
    uint64_t top = abi->kc_base + (uint64_t)FUNC_KD_KINDS * abi->kc_counters * abi->kc_vec_bytes;
    if (abi->kc_vec_bytes < lanes_bytes || top > abi->spad_clear) {
        snprintf(err, errlen, "kernel: kd counters (KC_BASE %u, KC_VEC_BYTES %u) must hold core.simd_width = %d lanes "
                 "below SPAD_CLEAR %u", abi->kc_base, abi->kc_vec_bytes, cfg->core_simd_width, abi->spad_clear);
        return -1;
    }
    for (int k = 0; k < FUNC_KD_KINDS; k++)
        if (abi->kind[k] >= FUNC_KD_KINDS) {
            snprintf(err, errlen, "kernel: ray kind %s = %u has no kd counters (3 kinds)", func_kd_kind_keys[k],
                     abi->kind[k]);
            return -1;
        }
    for (int c = 0; c < FUNC_KD_COUNTERS; c++)
        if (abi->kc[c] >= abi->kc_counters) {
            snprintf(err, errlen, "kernel: kd counter %s = %u is not below KC_COUNTERS = %u", func_kd_counter_keys[c],
                     abi->kc[c], abi->kc_counters);
            return -1;
        }
    return 0;
}

/* The scratchpad and the ray buffers must hold the kd kernel's stacks (depth: KD_STACK_DEPTH). */
static int kd_memories_ok(const CfgMachine *cfg, const CoreParams *cp, const Abi *a, const PackedScene *p,
                          uint32_t depth, char *err, size_t errlen)
{
    uint64_t spad = cp->mem_bytes[CORE_MEM_SPAD], rb = cp->mem_bytes[CORE_MEM_RB1];
    int v = cfg->kd_traversal;
    if (spad < a->kstack_base) {
        snprintf(err, errlen, "spad.size_kb = %d: the kd-tree traversal keeps %u bytes of counters and per-lane state "
                 "in the scratchpad", cfg->spad_size_kb, a->kstack_base);
        return -1;
    }
    uint64_t need = a->kstack_base + (uint64_t)KD_PACKET_ENTRY_BYTES * depth;
    if (v == CFG_KD_PACKET && spad < need) {
        snprintf(err, errlen, "spad.size_kb = %d: kd.traversal = packet with kd.stack_depth = %u needs %llu KiB of "
                 "scratchpad (stack entries of %u bytes from byte %u)", cfg->spad_size_kb, depth,
                 (unsigned long long)((need + 1023) / 1024), KD_PACKET_ENTRY_BYTES, a->kstack_base);
        return -1;
    }
    need = a->kstack_base + (uint64_t)KD_STREAM_ENTRY_BYTES * (3ull * p->kd_depth + 8);
    if (v == CFG_KD_STREAM && spad < need) {
        snprintf(err, errlen, "spad.size_kb = %d: kd.traversal = stream over a kd-tree of depth %u needs %llu KiB of "
                 "scratchpad for its stack (kd.max_depth limits the depth)", cfg->spad_size_kb, p->kd_depth,
                 (unsigned long long)((need + 1023) / 1024));
        return -1;
    }
    /* Per-lane stacks (the packet variant falls back to them) live in the next generation's ray
     * buffer. */
    need = (uint64_t)KD_LANE_ENTRY_BYTES * depth;
    if ((v == CFG_KD_STACK || v == CFG_KD_SHORTSTACK || v == CFG_KD_PACKET) && rb < need) {
        snprintf(err, errlen, "raybuf.size_kb = %d: kd.traversal = %s keeps per-lane stacks of %u entries (%s) in "
                 "a ray buffer: needs %llu KiB", cfg->raybuf_size_kb, cfg_enum_name("kd", "traversal", v), depth,
                 v == CFG_KD_STACK ? "the kd-tree's depth + 1; kd.max_depth limits it" : "kd.stack_depth",
                 (unsigned long long)((need + 1023) / 1024));
        return -1;
    }
    return 0;
}

typedef struct Job {
    const PackedScene *p;
    const FuncParams *fp;
    const AsmObject *obj;
    const Abi *abi;
    CoreParams cp;
    float *rgb;
    uint32_t width, height, tile_w, tile_h, tiles_x, ntiles, rays;
    FuncTile *tiles;
    uint8_t *sel;              /* sampled mode: the tiles to time */
    atomic_uint next_tile, done_tiles;
    atomic_int failed;
    int trapped;               /* the failure was the kernel's (trap, limit, error code) */
    pthread_mutex_t lock;
    char err[1024];
} Job;

typedef struct Worker {
    Job *job;
    FuncStats st;
    Timing *tm;                /* detailed mode */
    int tile_timed;            /* the current tile is timed (every tile, or the sample) */
} Worker;


static uint32_t spad_u32(Core *c, uint32_t addr)
{
    uint32_t v, size;
    uint8_t *m = core_mem(c, CORE_MEM_SPAD, &size);
    memcpy(&v, m + addr, 4);
    return v;
}

static void spad_set(Core *c, uint32_t addr, uint32_t v)
{
    uint32_t size;
    uint8_t *m = core_mem(c, CORE_MEM_SPAD, &size);
    memcpy(m + addr, &v, 4);
}

/* Add one run's kd counters, lanes 0..N-1 of each (kind, counter) vector. */
static void kd_counts_add(Core *c, const Abi *a, int lanes, FuncStats *st)
{
    for (int k = 0; k < FUNC_KD_KINDS; k++)
        for (int n = 0; n < FUNC_KD_COUNTERS; n++) {
            uint32_t at = a->kc_base + (a->kind[k] * a->kc_counters + a->kc[n]) * a->kc_vec_bytes;
            for (int l = 0; l < lanes; l++)
                st->kd_counts[k][n] += spad_u32(c, at + 4u * (uint32_t)l);
        }
}

static void fail(Job *j, const char *msg, int trapped)
{
    pthread_mutex_lock(&j->lock);
    if (!atomic_load(&j->failed)) {
        snprintf(j->err, sizeof j->err, "%s", msg);
        j->trapped = trapped;
    }
    atomic_store(&j->failed, 1);
    pthread_mutex_unlock(&j->lock);
}

/* Detailed mode: start a cold machine for one tile or batch. */
static void timing_begin(Worker *w, Core *c, uint32_t t, TimingStats *before)
{
    w->tile_timed = w->tm && (!w->job->sel || w->job->sel[t]);
    if (w->tm)
        core_set_hook(c, w->tile_timed ? timing_hook : NULL, w->tile_timed ? w->tm : NULL);
    if (w->tile_timed) {
        timing_reset(w->tm);
        *before = *timing_stats(w->tm);
    }
}

/* Detailed mode: close the run and give its figures to the tile; -1 if the model failed. */
static int timing_close(Worker *w, const TimingStats *before, FuncTile *ft)
{
    if (!w->tile_timed)
        return 0;
    ft->sampled = 1;
    timing_end(w->tm);
    const TimingStats *s = timing_stats(w->tm);
    if (ft) {
        ft->cycles = s->cycles - before->cycles;
        ft->busy = s->busy - before->busy;
        for (int c = 0; c < TM_CAUSE_COUNT; c++)
            ft->stalls[c] = s->stalls[c] - before->stalls[c];
    }
    if (timing_error(w->tm)) {
        fail(w->job, timing_error(w->tm), 0);
        return -1;
    }
    return 0;
}

static void rb_set(uint8_t *rb, uint32_t addr, uint32_t v) { memcpy(rb + addr, &v, 4); }
static uint32_t rb_get(const uint8_t *rb, uint32_t addr)
{
    uint32_t v;
    memcpy(&v, rb + addr, 4);
    return v;
}

/* One batch of `sfsim trace`: rays [t * M, ...) into RB0, run, hits out. */
static int trace_batch(Worker *w, Core *c, uint32_t t, FuncStats *st)
{
    Job *j = w->job;
    const Abi *a = j->abi;
    const RayBatch *b = j->fp->batch;
    uint32_t first = t * j->rays, n = b->count - first < j->rays ? b->count - first : j->rays;
    core_restart(c);
    uint32_t size;
    uint8_t *sp = core_mem(c, CORE_MEM_SPAD, &size);
    memset(sp, 0, a->spad_clear);
    spad_set(c, a->l_w, n);
    uint8_t *rb = core_mem(c, CORE_MEM_RB0, &size);
    const float nan = NAN;
    uint32_t nanbits;
    memcpy(&nanbits, &nan, 4);
    for (uint32_t i = 0; i < n; i++) {
        const BatchRay *r = &b->rays[first + i];
        int invalid = raybatch_ray_invalid(r);
        for (int k = 0; k < 3; k++) {
            uint32_t o, d;
            memcpy(&o, &r->org[k], 4);
            memcpy(&d, &r->dir[k], 4);
            rb_set(rb, a->f_org[k] + 4 * i, invalid ? nanbits : o); /* NaN: the set-up filter drops it */
            rb_set(rb, a->f_dir[k] + 4 * i, d);
        }
        uint32_t tm;
        memcpy(&tm, &r->tmax, 4);
        rb_set(rb, a->f_tmax + 4 * i, tm);
        rb_set(rb, a->f_kind + 4 * i, r->query == RAY_ANY ? 2u : 0u);
        rb_set(rb, a->f_prim + 4 * i, UINT32_MAX);
    }
    TimingStats before;
    timing_begin(w, c, t, &before);
    CoreExit ex = core_run(c, (uint64_t)j->fp->cfg->sim_max_instructions);
    FuncTile *ft = &j->tiles[t];
    ft->x0 = first;
    ft->w = n;
    ft->h = 1;
    if (timing_close(w, &before, ft))
        return -1;
    char msg[1400];
    if (ex != CORE_EXIT_HALT) {
        snprintf(msg, sizeof msg, "kernel, rays %u..%u: %s%s", first, first + n - 1, core_trap_message(c),
                 ex == CORE_EXIT_LIMIT ? " (sim.max_instructions)" : "");
        fail(j, msg, 1);
        return -1;
    }
    if (spad_u32(c, a->l_error)) {
        snprintf(msg, sizeof msg, "kernel, rays %u..%u: traversal stack overflow (raise spad.size_kb)", first,
                 first + n - 1);
        fail(j, msg, 1);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        const BatchRay *r = &b->rays[first + i];
        BatchHit *h = &j->fp->hits[first + i];
        memset(h, 0, sizeof *h);
        h->invalid = (uint32_t)raybatch_ray_invalid(r);
        uint32_t tm = rb_get(rb, a->f_tmax + 4 * i), u = rb_get(rb, a->f_u + 4 * i), v = rb_get(rb, a->f_v + 4 * i);
        if (r->query == RAY_ANY) {
            float tf;
            memcpy(&tf, &tm, 4);
            h->prim = !h->invalid && tf < 0.0f;
            continue;
        }
        h->prim = h->invalid ? UINT32_MAX : rb_get(rb, a->f_prim + 4 * i);
        if (h->prim != UINT32_MAX) {
            memcpy(&h->t, &tm, 4);
            memcpy(&h->u, &u, 4);
            memcpy(&h->v, &v, 4);
        }
    }
    st->rays_camera += n;
    if (j->fp->cfg->accel_structure == CFG_ACCEL_KD)
        kd_counts_add(c, a, j->cp.lanes, st);
    return 0;
}

static int run_tile(Worker *w, Core *c, uint32_t t, FuncStats *st)
{
    Job *j = w->job;
    const Abi *a = j->abi;
    if (j->fp->batch)
        return trace_batch(w, c, t, st);
    FuncTile *ft = &j->tiles[t];
    ft->x0 = (t % j->tiles_x) * j->tile_w;
    ft->y0 = (t / j->tiles_x) * j->tile_h;
    ft->w = j->width - ft->x0 < j->tile_w ? j->width - ft->x0 : j->tile_w;
    ft->h = j->height - ft->y0 < j->tile_h ? j->height - ft->y0 : j->tile_h;
    core_restart(c);
    uint32_t size;
    uint8_t *sp = core_mem(c, CORE_MEM_SPAD, &size);
    memset(sp, 0, a->spad_clear);
    spad_set(c, a->l_x0, ft->x0);
    spad_set(c, a->l_y0, ft->y0);
    spad_set(c, a->l_w, ft->w);
    spad_set(c, a->l_h, ft->h);
    spad_set(c, a->l_seed, j->fp->seed);
    uint8_t *fb = core_mem(c, CORE_MEM_FB, &size);
    memset(fb, 0, (size_t)ft->w * ft->h * 12);
    uint64_t before = core_instructions(c), lanes_before[ISA_STAGE_COUNT];
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        lanes_before[k] = core_stats(c)->active_lanes[k];
    TimingStats tbefore;
    timing_begin(w, c, t, &tbefore);
    CoreExit ex = core_run(c, (uint64_t)j->fp->cfg->sim_max_instructions);
    if (timing_close(w, &tbefore, ft))
        return -1;
    char msg[1400];
    if (ex != CORE_EXIT_HALT) {
        snprintf(msg, sizeof msg, "kernel, tile at (%u, %u): %s%s", ft->x0, ft->y0, core_trap_message(c),
                 ex == CORE_EXIT_LIMIT ? " (sim.max_instructions)" : "");
        fail(j, msg, 1);
        return -1;
    }
    uint32_t kerr = spad_u32(c, a->l_error);
    if (kerr) {
        snprintf(msg, sizeof msg, "kernel, tile at (%u, %u): %s", ft->x0, ft->y0,
                 kerr == a->err_stack ? "traversal stack overflow (raise spad.size_kb)"
                 : kerr == a->err_generations ? "more generations than the kernel counts (64)"
                                             : "error code set");
        fail(j, msg, 1);
        return -1;
    }
    for (uint32_t y = 0; y < ft->h; y++)
        memcpy(&j->rgb[3 * ((size_t)(ft->y0 + y) * j->width + ft->x0)], fb + (size_t)12 * y * ft->w,
               (size_t)12 * ft->w);
    ft->instructions = core_instructions(c) - before;
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        ft->active_lanes[k] = core_stats(c)->active_lanes[k] - lanes_before[k];
    st->dropped += spad_u32(c, a->st_dropped);
    st->rays_camera += spad_u32(c, a->st_camera);
    st->rays_indirect += spad_u32(c, a->st_indirect);
    st->rays_shadow += spad_u32(c, a->st_shadow);
    ft->rays = (uint64_t)spad_u32(c, a->st_camera) + spad_u32(c, a->st_indirect) + spad_u32(c, a->st_shadow);
    uint32_t g = spad_u32(c, a->st_generations);
    if (g > st->generations)
        st->generations = g;
    for (uint32_t k = 0; k < a->st_max_gen; k++)
        st->rays_per_generation[k] += spad_u32(c, a->st_per_gen + 4 * k);
    const uint32_t off[FUNC_STAGES] = {a->st_g_trav, a->st_g_isect, a->st_g_shade};
    for (uint32_t k = 0; k < a->st_max_gen; k++)
        for (int s = 0; s < FUNC_STAGES; s++) {
            uint32_t at = a->st_gen_base + k * a->st_gen_bytes + off[s];
            st->gen_streams[k][s] += spad_u32(c, at);
            st->gen_rays[k][s] += spad_u32(c, at + 4);
        }
    if (j->fp->cfg->accel_structure == CFG_ACCEL_KD)
        kd_counts_add(c, a, j->cp.lanes, st);
    return 0;
}

static void *worker_main(void *arg)
{
    Worker *w = arg;
    Job *j = w->job;
    char err[512];
    Core *c = core_new(&j->cp, j->obj, err, sizeof err);
    if (!c) {
        char msg[600];
        snprintf(msg, sizeof msg, "kernel: %s", err);
        fail(j, msg, 0);
        return NULL;
    }
    if (j->fp->timed) {
        TimingParams tp;
        timing_params(j->fp->cfg, &tp);
        w->tm = timing_new(&tp, err, sizeof err);
        if (!w->tm) {
            char msg[600];
            snprintf(msg, sizeof msg, "timing model: %s", err);
            fail(j, msg, 0);
            core_free(c);
            return NULL;
        }
        core_set_hook(c, timing_hook, w->tm);
    }
    uint32_t size;
    uint8_t *sm = core_mem(c, CORE_MEM_SCENE, &size);
    memcpy(sm, j->p->mem, j->p->size);
    while (!atomic_load(&j->failed)) {
        uint32_t t = atomic_fetch_add(&j->next_tile, 1u);
        if (t >= j->ntiles)
            break;
        if (run_tile(w, c, t, &w->st) != 0)
            break;
        uint32_t done = atomic_fetch_add(&j->done_tiles, 1u) + 1u;
        if (j->fp->progress)
            j->fp->progress(j->fp->progress_ctx, done, j->ntiles);
    }
    w->st.core = *core_stats(c);
    w->st.instructions = core_instructions(c);
    if (w->tm) {
        w->st.timing = *timing_stats(w->tm);
        timing_free(w->tm);
        w->tm = NULL;
    }
    core_free(c);
    return NULL;
}

static void add_define(AsmDefine *defs, int *n, char *list, size_t len, const char *name, long long v)
{
    defs[*n].name = name;
    defs[*n].value = v;
    (*n)++;
    size_t used = strlen(list);
    snprintf(list + used, len - used, "%s%s=%lld", used ? " " : "", name, v);
}

int func_render(const PackedScene *p, const FuncParams *fp, float *rgb, FuncStats *st, char *err,
                size_t errlen)
{
    memset(st, 0, sizeof *st);
    const CfgMachine *cfg = fp->cfg;
    /* Build symbols from the packed scene itself (docs/kernel.md). */
    AsmDefine defs[24];
    int nd = 0;
    /* Stream mode: tiles of sqrt(M) x sqrt(M) rays; packet mode: packets of N rays, as square as
     * N allows (2 x 2, 4 x 2, 4 x 3, 4 x 4, 8 x 8). */
    uint32_t tile_w, tile_h;
    if (cfg->stream_mode == CFG_STREAM_MODE_PACKET) {
        uint32_t n = (uint32_t)cfg->core_simd_width;
        tile_w = 1;
        while (tile_w * tile_w < n)
            tile_w++;
        while (n % tile_w)
            tile_w++;
        tile_h = n / tile_w;
    } else {
        tile_w = 1;
        while (tile_w * tile_w < (uint32_t)cfg->stream_rays)
            tile_w++;
        tile_h = tile_w;
    }
    uint32_t rays = tile_w * tile_h;
    /* The Phong workload traces each hit's shadow rays from the current ray buffer, beside the
     * hits (kernels/filters/phong.inc): two ray records per pixel, so a stream-mode tile holds
     * M/2 pixels (64 x 32 for M = 4096) and a packet's buffers 2N records. */
    int phong = cfg->workload_kind == CFG_WORKLOAD_PHONG && !fp->batch;
    if (phong) {
        if (cfg->stream_mode != CFG_STREAM_MODE_PACKET)
            tile_h = (tile_w + 1) / 2;
        rays = 2 * tile_w * tile_h;
    }
    st->tile_w = tile_w;
    st->tile_h = tile_h;
    add_define(defs, &nd, st->defines, sizeof st->defines, "RAYS", rays);
    if (fp->batch)
        add_define(defs, &nd, st->defines, sizeof st->defines, "TRACE_ONLY", 1);
    if (cfg->stream_order == CFG_STREAM_ORDER_FIRST)
        add_define(defs, &nd, st->defines, sizeof st->defines, "ORDER_FIRST", 1);
    if (cfg->workload_kind == CFG_WORKLOAD_SPECULAR) {
        add_define(defs, &nd, st->defines, sizeof st->defines, "WORKLOAD", CFG_WORKLOAD_SPECULAR);
        add_define(defs, &nd, st->defines, sizeof st->defines, "BOUNCES", cfg->workload_bounces);
    } else if (cfg->workload_kind == CFG_WORKLOAD_DIFFUSE) {
        add_define(defs, &nd, st->defines, sizeof st->defines, "WORKLOAD", CFG_WORKLOAD_DIFFUSE);
    } else if (phong) {
        add_define(defs, &nd, st->defines, sizeof st->defines, "WORKLOAD", CFG_WORKLOAD_PHONG);
        add_define(defs, &nd, st->defines, sizeof st->defines, "BOUNCES", cfg->workload_bounces);
    }
    uint32_t spad_bytes = (uint32_t)cfg->spad_size_kb * 1024u;
    add_define(defs, &nd, st->defines, sizeof st->defines, "SPAD_BYTES", spad_bytes);
    uint32_t nmats = sm_u32(p, sm_hdr(p, SM_HDR_NMATS)), mats = sm_u32(p, sm_hdr(p, SM_HDR_MATS));
    int kinds = 0;
    for (uint32_t m = 0; m < nmats; m++) {
        uint32_t k = sm_u32(p, sm_rec(mats, SM_MAT_WORDS, m, SM_MAT_KIND));
        if (k <= SCENE_MAT_DIELECTRIC)
            kinds |= 1 << k;
    }
    if (kinds & (1 << SCENE_MAT_LAMBERT))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_LAMBERT", 1);
    if (kinds & (1 << SCENE_MAT_GLOSSY))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_GLOSSY", 1);
    if (kinds & (1 << SCENE_MAT_DIELECTRIC))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_DIELECTRIC", 1);
    uint32_t prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    int spheres = 0;
    for (uint32_t i = 0; i < p->nprims && !spheres; i++)
        spheres = sm_u32(p, sm_rec(prims, SM_PRIM_WORDS, i, SM_PRIM_KIND)) == 1;
    if (spheres)
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_SPHERES", 1);
    if (sm_u32(p, sm_hdr(p, SM_HDR_NORMALS)))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_NORMALS", 1);
    if ((fp->needs & SCENE_NEED_TEXTURES) && sm_u32(p, sm_hdr(p, SM_HDR_UVS)))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_TEXTURES", 1);
    /* pack_scene writes these arrays only for scenes that need them; the golden model reads
     * the same header words */
    if (sm_u32(p, sm_hdr(p, SM_HDR_MATX)))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_EMISSIVE_TEX", 1);
    if (sm_u32(p, sm_hdr(p, SM_HDR_COLORS)))
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_COLORS", 1);
    uint32_t nlights = sm_u32(p, sm_hdr(p, SM_HDR_NLIGHTS)), lights = sm_u32(p, sm_hdr(p, SM_HDR_LIGHTS));
    int punctual = 0;
    for (uint32_t l = 0; l < nlights; l++)
        if (sm_u32(p, sm_rec(lights, SM_LIGHT_WORDS, l, SM_LIGHT_KIND)) <= SM_LIGHT_DIRECTIONAL)
            punctual = 1;
    if (punctual)
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_PUNCTUAL", 1);
    float bg = 0.0f, amb = 0.0f;
    for (int k = 0; k < 3; k++) {
        bg += sm_f32(p, sm_hdr(p, SM_HDR_BACKGROUND + k));
        amb += sm_f32(p, sm_hdr(p, SM_HDR_AMBIENT + k));
    }
    if (bg != 0.0f)
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_BACKGROUND", 1);
    if (amb > 0.0f)
        add_define(defs, &nd, st->defines, sizeof st->defines, "HAS_AMBIENT", 1);
    if (cfg->accel_structure == CFG_ACCEL_KD) {
        if (sm_u32(p, sm_hdr(p, SM_HDR_KD_NODES)) == 0) {
            snprintf(err, errlen, "accel.structure = kd: the scene was packed without a kd-tree (func_add_kd)");
            return -1;
        }
        st->kd = 1;
        st->kd_stack_depth = kd_stack_depth(cfg, p);
        add_define(defs, &nd, st->defines, sizeof st->defines, "ACCEL_KD", 1);
        add_define(defs, &nd, st->defines, sizeof st->defines, "KD_VARIANT", cfg->kd_traversal);
        add_define(defs, &nd, st->defines, sizeof st->defines, "KD_STACK_DEPTH", st->kd_stack_depth);
    }

    char libdir[PATH_MAX + 8];
    snprintf(libdir, sizeof libdir, "%s", fp->kernel_path);
    char *slash = strrchr(libdir, '/');
    if (slash)
        snprintf(slash, sizeof libdir - (size_t)(slash - libdir), "/lib");
    else
        snprintf(libdir, sizeof libdir, "lib");
    const char *incs[1] = {libdir};
    char *diag = NULL;
    size_t diaglen = 0;
    FILE *dm = open_memstream(&diag, &diaglen);
    AsmOptions ao = {defs, nd, incs, 1, dm};
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    int nerr = asm_assemble_file(fp->kernel_path, &ao, &obj);
    if (dm)
        fclose(dm);
    if (nerr) {
        snprintf(err, errlen, "kernel %s does not assemble (%d errors):\n%s", fp->kernel_path, nerr,
                 diag ? diag : "");
        free(diag);
        return -1;
    }
    free(diag);
    int rc = -1;
    Worker *ws = NULL;
    pthread_t *th = NULL;
    Abi abi;
    Job *job = calloc(1, sizeof *job);
    if (!job) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    pthread_mutex_init(&job->lock, NULL);
    if (abi_lookup(&obj, &abi, err, errlen) != 0 || (st->kd && kd_abi_lookup(&obj, cfg, &abi, err, errlen) != 0))
        goto out;
    st->kernel_instructions = obj.ntext;

    /* The machine's memories must hold what the kernel keeps in them. */
    CoreParams cp;
    cfg_core_params(cfg, &cp);
    uint64_t rb_need = (uint64_t)abi.ray_fields * rays * 4u;
    if (cp.mem_bytes[CORE_MEM_RB0] < rb_need) {
        snprintf(err, errlen,
                 "raybuf.size_kb = %d: the kernel's %u-word ray records for %u rays need %llu KiB per ray buffer",
                 cfg->raybuf_size_kb, abi.ray_fields, rays, (unsigned long long)((rb_need + 1023) / 1024));
        goto out;
    }
    if (cp.mem_bytes[CORE_MEM_IDM] < 8u * rays) {
        snprintf(err, errlen, "idm.size_kb = %d: two streams of %u ray IDs need %u KiB", cfg->idm_size_kb, rays,
                 8u * rays / 1024u);
        goto out;
    }
    if (cp.mem_bytes[CORE_MEM_FB] < 12u * tile_w * tile_h) {
        snprintf(err, errlen, "fb.size_kb = %d: a tile of %u RGB pixels needs %u KiB", cfg->fb_size_kb,
                 tile_w * tile_h, (12u * tile_w * tile_h + 1023u) / 1024u);
        goto out;
    }
    if (cp.mem_bytes[CORE_MEM_SPAD] < abi.spad_clear) {
        snprintf(err, errlen, "spad.size_kb = %d: the kernel's launch block and counters need %u bytes",
                 cfg->spad_size_kb, abi.spad_clear);
        goto out;
    }
    uint64_t stack_need = abi.stack_base + 12ull * (3ull * p->bvh.depth + 8);
    if (!st->kd && cp.mem_bytes[CORE_MEM_SPAD] < stack_need) {
        snprintf(err, errlen, "spad.size_kb = %d: the traversal stack of a BVH of depth %u needs %llu KiB",
                 cfg->spad_size_kb, p->bvh.depth, (unsigned long long)((stack_need + 1023) / 1024));
        goto out;
    }
    if (st->kd && kd_memories_ok(cfg, &cp, &abi, p, st->kd_stack_depth, err, errlen) != 0)
        goto out;
    if (cp.mem_bytes[CORE_MEM_SCENE] < p->size) {
        snprintf(err, errlen, "scene.size_mb = %d: the packed scene needs %u bytes", cfg->scene_size_mb, p->size);
        goto out;
    }

    job->p = p;
    job->fp = fp;
    job->obj = &obj;
    job->abi = &abi;
    job->cp = cp;
    job->rgb = rgb;
    job->width = sm_u32(p, sm_hdr(p, SM_HDR_WIDTH));
    job->height = sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT));
    uint32_t spp = sm_u32(p, sm_hdr(p, SM_HDR_SPP));
    job->tile_w = tile_w;
    job->tile_h = tile_h;
    job->rays = rays;
    job->tiles_x = (job->width + tile_w - 1) / tile_w;
    job->ntiles = job->tiles_x * ((job->height + tile_h - 1) / tile_h);
    if (fp->batch)
        job->ntiles = (fp->batch->count + rays - 1) / rays;
    job->tiles = calloc(job->ntiles ? job->ntiles : 1, sizeof(FuncTile));
    if (fp->timed && fp->sample > 0.0) {
        if (fp->batch || !(fp->sample <= 1.0)) {
            snprintf(err, errlen, fp->batch ? "sampled mode renders frames, not ray batches"
                                            : "sample fraction %g outside (0, 1]", fp->sample);
            goto out;
        }
        job->sel = calloc(job->ntiles ? job->ntiles : 1, 1);
        if (!job->sel) {
            snprintf(err, errlen, "out of memory");
            goto out;
        }
        sample_select(job->ntiles, fp->sample, fp->sample_seed, job->sel);
    }
    atomic_init(&job->next_tile, 0u);
    atomic_init(&job->done_tiles, 0u);
    atomic_init(&job->failed, 0);
    /* At most one thread per tile, but always the calling thread: with no tile (an empty ray
     * batch) it finds no work and the run yields empty, valid results (docs/trace.md). */
    int nthreads = fp->threads < 1 ? 1 : fp->threads;
    if ((uint32_t)nthreads > job->ntiles)
        nthreads = job->ntiles ? (int)job->ntiles : 1;
    ws = calloc((size_t)nthreads, sizeof *ws);
    th = calloc((size_t)nthreads, sizeof *th);
    if (!job->tiles || !ws || !th) {
        snprintf(err, errlen, "out of memory");
        goto out;
    }
    int started = 0;
    for (int i = 0; i < nthreads; i++)
        ws[i].job = job;
    for (int i = 1; i < nthreads; i++, started++)
        if (pthread_create(&th[i], NULL, worker_main, &ws[i]) != 0)
            break;
    worker_main(&ws[0]);
    for (int i = 1; i <= started; i++)
        pthread_join(th[i], NULL);
    float inv = 1.0f / (float)spp;
    if (atomic_load(&job->failed)) {
        snprintf(err, errlen, "%s", job->err);
        rc = job->trapped ? -2 : -1;
        /* The tiles that finished are kept (the caller may write them as a partial image). */
        for (size_t i = 0; rgb && i < 3 * (size_t)job->width * job->height; i++)
            rgb[i] = rgb[i] * inv;
        st->tiles_done = atomic_load(&job->done_tiles);
        st->ntiles = job->ntiles;
        goto out;
    }
    for (size_t i = 0; rgb && i < 3 * (size_t)job->width * job->height; i++)
        rgb[i] = rgb[i] * inv;
    for (int i = 0; i < nthreads; i++) {
        const FuncStats *s = &ws[i].st;
        for (int k = 0; k < ISA_STAGE_COUNT; k++) {
            st->core.instructions[k] += s->core.instructions[k];
            st->core.vec_instructions[k] += s->core.vec_instructions[k];
            st->core.active_lanes[k] += s->core.active_lanes[k];
            for (int c = 0; c < ISA_C_COUNT; c++)
                st->core.ops[k][c] += s->core.ops[k][c];
            for (int g = 0; g < CORE_GENERATIONS; g++) {
                st->core.gen_instructions[g][k] += s->core.gen_instructions[g][k];
                st->core.gen_vec_instructions[g][k] += s->core.gen_vec_instructions[g][k];
                st->core.gen_active_lanes[g][k] += s->core.gen_active_lanes[g][k];
            }
        }
        for (int o = 0; o < ISA_OP_COUNT; o++)
            st->core.by_op[o] += s->core.by_op[o];
        st->instructions += s->instructions;
        timing_stats_add(&st->timing, &s->timing);
        st->rays_camera += s->rays_camera;
        st->rays_indirect += s->rays_indirect;
        st->rays_shadow += s->rays_shadow;
        st->dropped += s->dropped;
        for (int g = 0; g < FUNC_MAX_GENERATIONS; g++)
            st->rays_per_generation[g] += s->rays_per_generation[g];
        if (s->generations > st->generations)
            st->generations = s->generations;
        for (int g = 0; g < FUNC_MAX_GENERATIONS; g++)
            for (int k = 0; k < FUNC_STAGES; k++) {
                st->gen_streams[g][k] += s->gen_streams[g][k];
                st->gen_rays[g][k] += s->gen_rays[g][k];
            }
        for (int k = 0; k < FUNC_KD_KINDS; k++)
            for (int c = 0; c < FUNC_KD_COUNTERS; c++)
                st->kd_counts[k][c] += s->kd_counts[k][c];
    }
    for (int g = 0; g < FUNC_MAX_GENERATIONS; g++) {
        st->trav_streams += st->gen_streams[g][0];
        st->trav_rays += st->gen_rays[g][0];
        st->isect_streams += st->gen_streams[g][1];
        st->isect_rays += st->gen_rays[g][1];
        st->shade_streams += st->gen_streams[g][2];
        st->shade_rays += st->gen_rays[g][2];
    }
    if (fp->timed) {
        st->timed = 1;
        for (uint32_t i = 0; i < job->ntiles; i++)
            st->tiles_timed += job->tiles[i].sampled;
        if (timing_check(&st->timing, err, errlen) != 0)
            goto out;
    }
    st->tiles = job->tiles;
    st->ntiles = job->ntiles;
    st->tiles_done = job->ntiles;
    job->tiles = NULL;
    rc = 0;
out:
    if (job) {
        free(job->tiles);
        free(job->sel);
        pthread_mutex_destroy(&job->lock);
    }
    free(job);
    free(ws);
    free(th);
    asm_object_free(&obj);
    return rc;
}

int func_trace(const PackedScene *p, const FuncParams *fp, FuncStats *st, char *err, size_t errlen)
{
    if (!fp->batch || !fp->hits) {
        snprintf(err, errlen, "trace: no ray batch");
        return -1;
    }
    return func_render(p, fp, NULL, st, err, errlen);
}

void func_stats_free(FuncStats *st)
{
    free(st->tiles);
    st->tiles = NULL;
}
