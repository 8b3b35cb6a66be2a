/* sim/run/kernel.c -- the kernel builder (see kernel.h). */
#include "kernel.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../datadir.h"
#include "schedmodel.h"

const char *const func_kd_kind_keys[FUNC_KD_KINDS] = {"camera", "indirect", "shadow"};
const char *const func_kd_counter_keys[FUNC_KD_COUNTERS] = {"nodes", "leaves", "prims", "restarts", "overflows",
                                                            "underflows"};

const char *kernel_default_path(char *buf, size_t len)
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

static const AsmSymbol *abi_find(const AsmObject *obj, const char *name)
{
    const AsmSymbol *found = NULL;
    for (uint32_t s = 0; s < obj->nsyms; s++)
        if (!strcmp(obj->syms[s].name, name))
            found = &obj->syms[s];
    return found;
}

static int abi_lookup(const AsmObject *obj, KernelAbi *abi, char *err, size_t errlen)
{
    static const struct { const char *name; size_t off; } names[] = {
#define A(field, name) {name, offsetof(KernelAbi, field)}
        A(l_x0, "L_X0"), A(l_y0, "L_Y0"), A(l_w, "L_W"), A(l_h, "L_H"), A(l_seed, "L_SEED"),
        A(l_error, "L_ERROR"), A(l_pass0, "L_PASS0"), A(l_pass1, "L_PASS1"), A(st_dropped, "ST_DROPPED"), A(st_camera, "ST_CAMERA"),
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

/* Bytes per entry of the kd kernel's stacks (kernels/lib/kdtrace.inc, kdpacket.inc and kdstream.inc own their layout). */
#define KD_PACKET_ENTRY_BYTES 1040u /* packet short stack, in the scratchpad from KSTACK_BASE */
#define KD_STREAM_ENTRY_BYTES 36u   /* stream-filter stack, 3 * depth + 8 entries like the BVH kernel's */
#define KD_LANE_ENTRY_BYTES 1024u   /* per-lane stacks, in the next generation's ray buffer */

/* The kernel's KD_VARIANT constants (kernels/lib/kconst.inc, generated from kd.traversal's names). */
static const char *const kd_variant_syms[CFG_KD_TRAVERSALS] = {"KD_STACK", "KD_RESTART", "KD_PUSHDOWN",
                                                               "KD_SHORTSTACK", "KD_PACKET", "KD_STREAM"};

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
static int kd_abi_lookup(const AsmObject *obj, const CfgMachine *cfg, KernelAbi *abi, char *err, size_t errlen)
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
static int kd_memories_ok(const CfgMachine *cfg, const CoreParams *cp, const KernelAbi *a, const PackedScene *p,
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

static void add_define(AsmDefine *defs, int *n, char *list, size_t len, const char *name, long long v)
{
    defs[*n].name = name;
    defs[*n].value = v;
    (*n)++;
    size_t used = strlen(list);
    snprintf(list + used, len - used, "%s%s=%lld", used ? " " : "", name, v);
}

/* Stream mode: tiles of sqrt(M) x sqrt(M) rays; packet mode: packets of N rays, as square as N
 * allows (2 x 2, 4 x 2, 4 x 3, 4 x 4, 8 x 8). The Phong workload traces each hit's shadow rays from
 * the current ray buffer, beside the hits (kernels/filters/phong.inc): two ray records per pixel,
 * so a stream-mode tile holds M/2 pixels (64 x 32 for M = 4096) and a packet's buffers 2N records. */
static void tile_shape(const CfgMachine *cfg, int phong, Kernel *k)
{
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
    if (phong) {
        if (cfg->stream_mode != CFG_STREAM_MODE_PACKET)
            tile_h = (tile_w + 1) / 2;
        rays = 2 * tile_w * tile_h;
    }
    k->tile_w = tile_w;
    k->tile_h = tile_h;
    k->rays = rays;
}

/* The symbols of the scene's features, read from the packed scene itself (docs/kernel.md). */
static void scene_defines(const PackedScene *p, uint32_t needs, AsmDefine *defs, int *nd, Kernel *k)
{
    char *list = k->defines;
    size_t len = sizeof k->defines;
    uint32_t nmats = sm_u32(p, sm_hdr(p, SM_HDR_NMATS)), mats = sm_u32(p, sm_hdr(p, SM_HDR_MATS));
    int kinds = 0;
    for (uint32_t m = 0; m < nmats; m++) {
        uint32_t kind = sm_u32(p, sm_rec(mats, SM_MAT_WORDS, m, SM_MAT_KIND));
        if (kind <= SCENE_MAT_DIELECTRIC)
            kinds |= 1 << kind;
    }
    if (kinds & (1 << SCENE_MAT_LAMBERT))
        add_define(defs, nd, list, len, "HAS_LAMBERT", 1);
    if (kinds & (1 << SCENE_MAT_GLOSSY))
        add_define(defs, nd, list, len, "HAS_GLOSSY", 1);
    if (kinds & (1 << SCENE_MAT_DIELECTRIC))
        add_define(defs, nd, list, len, "HAS_DIELECTRIC", 1);
    /* From the packer's count: a scan of the primitive array for a sphere took 4 ms on a
     * triangle-only scene of 280 K primitives, at every run. */
    if (p->nspheres)
        add_define(defs, nd, list, len, "HAS_SPHERES", 1);
    if (sm_u32(p, sm_hdr(p, SM_HDR_NORMALS)))
        add_define(defs, nd, list, len, "HAS_NORMALS", 1);
    if ((needs & SCENE_NEED_TEXTURES) && sm_u32(p, sm_hdr(p, SM_HDR_UVS)))
        add_define(defs, nd, list, len, "HAS_TEXTURES", 1);
    /* pack_scene writes these arrays only for scenes that need them; the golden model reads
     * the same header words */
    if (sm_u32(p, sm_hdr(p, SM_HDR_MATX)))
        add_define(defs, nd, list, len, "HAS_EMISSIVE_TEX", 1);
    if (sm_u32(p, sm_hdr(p, SM_HDR_COLORS)))
        add_define(defs, nd, list, len, "HAS_COLORS", 1);
    uint32_t nlights = sm_u32(p, sm_hdr(p, SM_HDR_NLIGHTS)), lights = sm_u32(p, sm_hdr(p, SM_HDR_LIGHTS));
    int punctual = 0;
    for (uint32_t l = 0; l < nlights; l++)
        if (sm_u32(p, sm_rec(lights, SM_LIGHT_WORDS, l, SM_LIGHT_KIND)) <= SM_LIGHT_DIRECTIONAL)
            punctual = 1;
    if (punctual)
        add_define(defs, nd, list, len, "HAS_PUNCTUAL", 1);
    float bg = 0.0f, amb = 0.0f;
    for (int c = 0; c < 3; c++) {
        bg += sm_f32(p, sm_hdr(p, SM_HDR_BACKGROUND + c));
        amb += sm_f32(p, sm_hdr(p, SM_HDR_AMBIENT + c));
    }
    if (bg != 0.0f)
        add_define(defs, nd, list, len, "HAS_BACKGROUND", 1);
    if (amb > 0.0f)
        add_define(defs, nd, list, len, "HAS_AMBIENT", 1);
}

/* kernel.unroll_box = 0 (auto) unrolls the box-test loop for tiles of at least this many ID
 * vectors (rays / N). */
#define KERNEL_UNROLL_MIN_VECTORS 256u

/* kernel.unroll_box as it runs: the key's 1 or 2, or for 0 (auto) 2 in stream mode where a run's
 * stream starts with at least KERNEL_UNROLL_MIN_VECTORS ID vectors (rays: a tile's, or for
 * `sfsim trace` its batch's if fewer), else 1. The pair loop hides a box test's latency behind
 * another's but costs a pair test on every box filter, so it pays where traversal streams are
 * many vectors long. Measured on the Cornell box, conference and sponza (docs/validation.md, "When
 * the pair loop pays"): 4096-ray tiles gain up to 6.5 % at N = 4-16 (at worst +0.12 % at N = 16 in
 * the per-ray order) and lose up to 1.4 % on the big scenes at N = 32 and 64; 1024-ray tiles gain
 * at N = 4 and lose up to 1.1 % at N = 16; packet mode loses 2.4-3.4 %. A kd-tree kernel has no
 * BVH box-test loop: 1. */
static int box_unroll(const CfgMachine *cfg, uint32_t rays)
{
    if (cfg->kernel_unroll_box != 0)
        return cfg->kernel_unroll_box;
    if (cfg->accel_structure == CFG_ACCEL_KD || cfg->stream_mode == CFG_STREAM_MODE_PACKET)
        return 1;
    return rays >= KERNEL_UNROLL_MIN_VECTORS * (uint32_t)cfg->core_simd_width ? 2 : 1;
}

/* Every -D symbol, in the order report.json's kernel.defines lists them. */
static int choose_defines(const PackedScene *p, const CfgMachine *cfg, uint32_t needs, int trace_only,
                          uint32_t trace_rays, AsmDefine *defs, int *nd, Kernel *k, char *err, size_t errlen)
{
    char *list = k->defines;
    size_t len = sizeof k->defines;
    int phong = cfg->workload_kind == CFG_WORKLOAD_PHONG && !trace_only;
    tile_shape(cfg, phong, k);
    add_define(defs, nd, list, len, "RAYS", k->rays);
    if (trace_only)
        add_define(defs, nd, list, len, "TRACE_ONLY", 1);
    if (cfg->stream_order == CFG_STREAM_ORDER_FIRST)
        add_define(defs, nd, list, len, "ORDER_FIRST", 1);
    if (cfg->workload_kind == CFG_WORKLOAD_SPECULAR) {
        add_define(defs, nd, list, len, "WORKLOAD", CFG_WORKLOAD_SPECULAR);
        add_define(defs, nd, list, len, "BOUNCES", cfg->workload_bounces);
    } else if (cfg->workload_kind == CFG_WORKLOAD_DIFFUSE) {
        add_define(defs, nd, list, len, "WORKLOAD", CFG_WORKLOAD_DIFFUSE);
    } else if (phong) {
        add_define(defs, nd, list, len, "WORKLOAD", CFG_WORKLOAD_PHONG);
        add_define(defs, nd, list, len, "BOUNCES", cfg->workload_bounces);
    }
    add_define(defs, nd, list, len, "SPAD_BYTES", (uint32_t)cfg->spad_size_kb * 1024u);
    k->unroll_box = box_unroll(cfg, trace_only && trace_rays < k->rays ? trace_rays : k->rays);
    if (k->unroll_box == 2)
        add_define(defs, nd, list, len, "BOX_UNROLL", 1);
    scene_defines(p, needs, defs, nd, k);
    if (cfg->accel_structure == CFG_ACCEL_KD) {
        if (sm_u32(p, sm_hdr(p, SM_HDR_KD_NODES)) == 0) {
            snprintf(err, errlen, "accel.structure = kd: the scene was packed without a kd-tree (accel_add_kd)");
            return -1;
        }
        k->kd = 1;
        k->kd_stack_depth = kd_stack_depth(cfg, p);
        add_define(defs, nd, list, len, "ACCEL_KD", 1);
        add_define(defs, nd, list, len, "KD_VARIANT", cfg->kd_traversal);
        add_define(defs, nd, list, len, "KD_STACK_DEPTH", k->kd_stack_depth);
    }
    return 0;
}

static int assemble(const char *path, const AsmDefine *defs, int nd, const CfgMachine *cfg, AsmObject *obj, char *err,
                    size_t errlen)
{
    AsmSchedModel model; /* kernel.schedule = list: each block scheduled for this machine */
    schedmodel_fill(cfg, &model);
    char libdir[PATH_MAX + 8];
    snprintf(libdir, sizeof libdir, "%s", path);
    char *slash = strrchr(libdir, '/');
    if (slash)
        snprintf(slash, sizeof libdir - (size_t)(slash - libdir), "/lib");
    else
        snprintf(libdir, sizeof libdir, "lib");
    const char *incs[1] = {libdir};
    char *diag = NULL;
    size_t diaglen = 0;
    FILE *dm = open_memstream(&diag, &diaglen);
    AsmOptions ao = {defs, nd, incs, 1, dm, cfg->kernel_schedule == CFG_KERNEL_SCHEDULE_LIST ? &model : NULL, NULL};
    int nerr = asm_assemble_file(path, &ao, obj);
    if (dm)
        fclose(dm);
    if (nerr)
        snprintf(err, errlen, "kernel %s does not assemble (%d error%s):\n%s", path, nerr, nerr == 1 ? "" : "s", diag ? diag : "");
    free(diag);
    return nerr ? -1 : 0;
}

/* The machine's memories must hold what the kernel keeps in them. */
static int memories_ok(const PackedScene *p, const CfgMachine *cfg, const Kernel *k, char *err, size_t errlen)
{
    const CoreParams *cp = &k->cp;
    const KernelAbi *a = &k->abi;
    uint64_t rb_need = (uint64_t)a->ray_fields * k->rays * 4u;
    if (cp->mem_bytes[CORE_MEM_RB0] < rb_need) {
        snprintf(err, errlen,
                 "raybuf.size_kb = %d: the kernel's %u-word ray records for %u rays need %llu KiB per ray buffer",
                 cfg->raybuf_size_kb, a->ray_fields, k->rays, (unsigned long long)((rb_need + 1023) / 1024));
        return -1;
    }
    if (cp->mem_bytes[CORE_MEM_IDM] < 8u * k->rays) {
        snprintf(err, errlen, "idm.size_kb = %d: two streams of %u ray IDs need %u KiB", cfg->idm_size_kb, k->rays,
                 8u * k->rays / 1024u);
        return -1;
    }
    if (cp->mem_bytes[CORE_MEM_FB] < 12u * k->tile_w * k->tile_h) {
        snprintf(err, errlen, "fb.size_kb = %d: a tile of %u RGB pixels needs %u KiB", cfg->fb_size_kb,
                 k->tile_w * k->tile_h, (12u * k->tile_w * k->tile_h + 1023u) / 1024u);
        return -1;
    }
    if (cp->mem_bytes[CORE_MEM_SPAD] < a->spad_clear) {
        snprintf(err, errlen, "spad.size_kb = %d: the kernel's launch block and counters need %u bytes",
                 cfg->spad_size_kb, a->spad_clear);
        return -1;
    }
    uint64_t stack_need = a->stack_base + 12ull * (3ull * p->bvh.depth + 8);
    if (!k->kd && cp->mem_bytes[CORE_MEM_SPAD] < stack_need) {
        snprintf(err, errlen, "spad.size_kb = %d: the traversal stack of a BVH of depth %u needs %llu KiB",
                 cfg->spad_size_kb, p->bvh.depth, (unsigned long long)((stack_need + 1023) / 1024));
        return -1;
    }
    if (k->kd && kd_memories_ok(cfg, cp, a, p, k->kd_stack_depth, err, errlen) != 0)
        return -1;
    if (cp->mem_bytes[CORE_MEM_SCENE] < p->size) {
        snprintf(err, errlen, "scene.size_mb = %d: the packed scene needs %u bytes", cfg->scene_size_mb, p->size);
        return -1;
    }
    return 0;
}

int kernel_build(const PackedScene *p, const CfgMachine *cfg, const char *path, uint32_t needs, int trace_only,
                 uint32_t trace_rays, Kernel *k, char *err, size_t errlen)
{
    memset(k, 0, sizeof *k);
    AsmDefine defs[24];
    int nd = 0;
    if (choose_defines(p, cfg, needs, trace_only, trace_rays, defs, &nd, k, err, errlen) != 0)
        return -1;
    if (assemble(path, defs, nd, cfg, &k->obj, err, errlen) != 0)
        return -1;
    if (abi_lookup(&k->obj, &k->abi, err, errlen) != 0 ||
        (k->kd && kd_abi_lookup(&k->obj, cfg, &k->abi, err, errlen) != 0))
        return -1;
    cfg_core_params(cfg, &k->cp);
    return memories_ok(p, cfg, k, err, errlen);
}

void kernel_free(Kernel *k)
{
    asm_object_free(&k->obj);
    memset(k, 0, sizeof *k);
}
