/* sim/run/kernel.h -- the kernel builder: the path-tracing kernel (kernels/pathtrace.s)
 * assembled for one scene and one machine, with the launch interface the host reads back from
 * the object's symbols. Used by the functional, detailed and sampled modes and by `sfsim trace`.
 *
 * Owns: the tile (or packet) shape; the -D symbols chosen from the packed scene's features and
 * the config (docs/kernel.md: RAYS, SPAD_BYTES, WORKLOAD, BOUNCES, HAS_*, ACCEL_KD, KD_VARIANT,
 * KD_STACK_DEPTH, ORDER_FIRST, TRACE_ONLY, BOX_UNROLL), with kernel.unroll_box = 0 (auto)
 * resolved; assembling; the ABI symbols (kernels/lib/abi.inc is their only definition); checking
 * that the machine's memories hold what the kernel keeps in them. Must not: run the kernel
 * (sim/run/engine.c) or time it.
 */
#ifndef SFSIM_RUN_KERNEL_H
#define SFSIM_RUN_KERNEL_H

#include <stddef.h>
#include <stdint.h>

#include "../../asm/asm.h"
#include "../../scenes/pack.h"
#include "../config.h"
#include "../core.h"

/* The kernel's counters as the host reads them back (kernels/lib/abi.inc defines them; named after
 * the figures they fill, FuncStats in sim/run/engine.h, which sim/stats.def reads): the generations
 * it counts at most (its ST_MAX_GEN may not exceed it), and with accel.structure = kd its kd-tree
 * counters (KC_*) per ray kind, with their names in the report. */
#define FUNC_MAX_GENERATIONS 64
enum { FUNC_KD_CAMERA, FUNC_KD_INDIRECT, FUNC_KD_SHADOW, FUNC_KD_KINDS };
enum { FUNC_KD_NODES, FUNC_KD_LEAVES, FUNC_KD_PRIMS, FUNC_KD_RESTARTS, FUNC_KD_OVERFLOWS, FUNC_KD_UNDERFLOWS,
       FUNC_KD_COUNTERS };
extern const char *const func_kd_kind_keys[FUNC_KD_KINDS];       /* "camera", "indirect", "shadow" */
extern const char *const func_kd_counter_keys[FUNC_KD_COUNTERS]; /* "nodes", "leaves", "prims", "restarts",
                                                                    "overflows", "underflows" */

/* The ABI constants the host needs, looked up by name. */
typedef struct KernelAbi {
    uint32_t l_x0, l_y0, l_w, l_h, l_seed, l_error, l_pass0, l_pass1;
    uint32_t st_dropped, st_camera, st_indirect, st_shadow, st_generations, st_per_gen, st_max_gen;
    uint32_t st_gen_base, st_gen_bytes, st_g_trav, st_g_isect, st_g_shade;
    uint32_t stack_base, ray_fields, err_stack, err_generations;
    uint32_t f_org[3], f_dir[3], f_tmax, f_kind, f_prim, f_u, f_v;
    uint32_t spad_clear;       /* the host zeroes the scratchpad below it before each run */
    uint32_t kc_base, kc_counters, kc_vec_bytes;
    uint32_t kc[FUNC_KD_COUNTERS], kind[FUNC_KD_KINDS]; /* in FuncStats order */
    uint32_t kstack_base;      /* ACCEL_KD builds only */
} KernelAbi;

typedef struct Kernel {
    AsmObject obj;             /* the assembled program */
    KernelAbi abi;
    CoreParams cp;             /* the machine's cores (config), checked to hold the kernel's data */
    uint32_t tile_w, tile_h;   /* pixels of a tile (stream mode) or packet (packet mode) */
    uint32_t rays;             /* ray records per buffer: RAYS */
    char defines[512];         /* the -D symbols, "RAYS=1024 SPAD_BYTES=65536 ..." */
    int kd;                    /* accel.structure = kd */
    uint32_t kd_stack_depth;   /* KD_STACK_DEPTH */
    int unroll_box;            /* kernel.unroll_box resolved: 1 or 2 (BOX_UNROLL) */
} Kernel;

/* Assemble the kernel at path for packed scene p on the machine of cfg (needs: SCENE_NEED_* of
 * the scene; trace_only: `sfsim trace`'s build, traversal and intersection of a ray batch of
 * trace_rays rays, which a run's stream holds at most of: kernel.unroll_box = 0 resolves for
 * them). 0, or -1 with a message (assembly errors, a missing ABI symbol, memories too small, a kd
 * config without a packed kd-tree). Free k with kernel_free either way. */
int kernel_build(const PackedScene *p, const CfgMachine *cfg, const char *path, uint32_t needs, int trace_only,
                 uint32_t trace_rays, Kernel *k, char *err, size_t errlen);
void kernel_free(Kernel *k);

/* The shipped kernel: $SFSIM_KERNEL, or kernels/pathtrace.s in the data folder (sim/datadir.h). */
const char *kernel_default_path(char *buf, size_t len);

#endif
