; kernels/pathtrace.s -- the stream-filter path tracer (Gribble & Ramani 2008, Sec. 3-4), the
; program sfsim runs in `--mode functional` and under the timing model. This file is the driver:
; the generation loop, the BVH traversal of Fig. 3 and the shading filter stack of Fig. 4, and
; where each filter's code lies in the program; the filters themselves are kernels/filters/*.inc
; (one file per filter), their register frames kernels/lib/frames.inc, the numbers shared with
; the simulator kernels/lib/kconst.inc (generated). docs/kernel.md describes the whole.
;
; One run renders one tile of at most RAYS pixels, all samples: for each sample a stream of
; camera rays, then breadth-first generations -- set-up filter, traversal by stream filtering,
; intersection, shading filter stacks -- until a generation is empty. Radiance is scatter-added
; into the tile framebuffer. The algorithm and every float operation follow the golden model
; (sim/reference.c, docs/golden-model.md) so the images agree bit for bit.
;
; Assembled by the host (sim/run/kernel.c) with -D RAYS=M, SPAD_BYTES and one -D per scene
; feature (HAS_LAMBERT, HAS_GLOSSY, HAS_DIELECTRIC, HAS_TEXTURES, HAS_EMISSIVE_TEX, HAS_COLORS,
; HAS_NORMALS, HAS_SPHERES, HAS_PUNCTUAL, HAS_BACKGROUND, HAS_AMBIENT); WORKLOAD (with BOUNCES)
; for the utilization workloads; ORDER_FIRST; ACCEL_KD with KD_VARIANT and KD_STACK_DEPTH;
; TRACE_ONLY for `sfsim trace`.

        .include "abi.inc"              ; host interface, ray record
        .include "layout.inc"           ; scene memory (generated)
        .include "kconst.inc"           ; stages, workloads, kd variants, kinds (generated)
        .include "frames.inc"           ; register frames
        .include "vmath.inc"
        .include "isect.inc"
        .include "stream.inc"
        .include "shade.inc"
        .include "texture.inc"

.ifndef WORKLOAD
WORKLOAD = WL_PATH
.endif
.if (WORKLOAD == WL_SPECULAR || WORKLOAD == WL_PHONG) && !defined(BOUNCES)
        .error "the specular and phong workloads need -D BOUNCES=n"
.endif

        .include "filters/camera.inc"
        .include "filters/setup.inc"
        .include "filters/traverse.inc"
        .include "filters/intersect.inc"
        .include "filters/shadow.inc"
        .include "filters/miss.inc"
        .include "filters/emissive.inc"
        .include "filters/surface.inc"
        .include "filters/diffuse.inc"
        .include "filters/lights.inc"
        .include "filters/lambert.inc"
        .include "filters/glossy.inc"
        .include "filters/direct.inc"
        .include "filters/indirect.inc"
        .include "filters/dielectric.inc"
        .include "filters/specular.inc"
        .include "filters/onebounce.inc"
        .include "filters/phong.inc"

; ---- registers kept for the whole run ---------------------------------------------------------
; r0 = 0 (never written)          r16 chunk pointer of the running stream loop
; r17 sample                      r18 generation (= depth of every non-shadow ray in it)
; r19 current stream begin        r20 current stream end
; r21 next stream base            r22 next stream append pointer
; r23 next ray slot counter       r24 traversal stack pointer (scratchpad)
; r25 N                           r26, r27: scene header values (below)
; r28 end of the passes   r29 max depth         r30, r31 link registers

        .text
start:  vli     vz, 0
        vli     vm2, -2
        rdn     r25
        spld    r28, r0, L_PASS1        ; this run's passes: [L_PASS0, L_PASS1)
        ld      r29, r0, SM_HDR_MAX_DEPTH
        spld    r17, r0, L_PASS0
.ifdef TRACE_ONLY
; ==== `sfsim trace`: the host put L_W rays (origin, direction, tmax, kind) in the current ray
; buffer; the stream is their IDs 0..L_W-1. Set-up filter and traversal only; the host reads
; F_PRIM, F_TMAX, F_U, F_V back (docs/trace.md).
        li      r18, 0
        sgen    r0
        li      r19, 0
        mov     r20, r19
        spld    r1, r0, L_W
        li      r2, 0
trace_ids:
        sub     r3, r1, r2
        mtail   m1, r3
        viota   v0 @m1
        vbcast  v1, r2 @m1
        vadd    v0, v0, v1 @m1
        sapp    r20, v0 @m1
        add     r2, r2, r25
        blt     r2, r1, trace_ids
        jal     r30, setup
        beq     r19, r20, trace_only_done
        jal     r30, trace
trace_only_done:
        halt
.endif

; ==== one pass per sample: the camera filter makes the tile's stream ============================
sample_loop:
        CAMERA_RAYS
        li      r18, 0

; ==== generations ================================================================================
gen_loop:
        stage   STAGE_OTHER
        sgen    r18                     ; per-generation counters
        li      r1, FIELD_BYTES
        sub     r21, r1, r19            ; the other stream region
        mov     r22, r21
        li      r23, 0
        li      r1, ST_MAX_GEN
        bge     r18, r1, err_generations
        jal     r30, setup
        ; counters: rays traced in this generation, generations reached
        sub     r1, r20, r19
        shri    r1, r1, 2
        shli    r2, r18, 2
        spld    r3, r2, ST_PER_GEN
        add     r3, r3, r1
        spst    r3, r2, ST_PER_GEN
        addi    r2, r18, 1
        spld    r3, r0, ST_GENERATIONS
        bge     r3, r2, gen_counted
        spst    r2, r0, ST_GENERATIONS
gen_counted:
        beq     r19, r20, gen_shade     ; everything dropped
        jal     r30, trace
gen_shade:
        jal     r30, shade
        stage   STAGE_OTHER
        rswap
        mov     r19, r21
        mov     r20, r22
        addi    r18, r18, 1
        bne     r19, r20, gen_loop
        addi    r17, r17, 1
        blt     r17, r28, sample_loop
        halt

err_generations:
        li      r1, ERR_GENERATIONS
        spst    r1, r0, L_ERROR
        halt
err_stack:
        li      r1, ERR_STACK
        spst    r1, r0, L_ERROR
        halt

; ==== set-up filter ===============================================================================
setup:
        SETUP_FILTER

; ==== traversal (Fig. 3): traverse(node, stream) with an explicit stack ==========================
.ifdef ACCEL_KD
        .include "kdtrace.inc"          ; the kd-tree traversals (accel.structure = kd)
.else
trace:
        stage   STAGE_TRAVERSAL
        ld      r15, r0, SM_HDR_NNODES
        beq     r15, r0, trace_done
        ld      r26, r0, SM_HDR_NODES
        ld      r27, r0, SM_HDR_PRIMS
        li      r24, STACK_BASE
        PUSH    r26, r19, r20           ; (root, the generation's stream)
        FRAME_BOX
trav_pop:
        li      r1, STACK_BASE
        beq     r24, r1, trace_done
        BOX_FILTER                      ; out_stream = filter<node_test>(in_stream): [r3, r5)
        beq     r5, r3, trav_pop        ; if empty(out_stream) return
        ld      r6, r2, SM_NODE_INFO
        ld      r7, r2, SM_NODE_FIRST
        blt     r6, r0, trav_inner
        stage   STAGE_INTERSECTION      ; if is_leaf(node) intersect(primitives, out_stream)
        jal     r31, isect
        stage   STAGE_TRAVERSAL
        jmp     trav_pop
trav_inner:                             ; else traverse(front_child), traverse(back_child)
        CHILD_AXIS
.ifdef ORDER_FIRST
        PUSH_FRONT_FIRST                ; the stream's first ray decides the front child
.endif
        PUSH_NEAR_FAR                   ; each ray's own front child first
trace_done:
        stage   STAGE_OTHER
        jr      r30
.endif

.if !defined(ACCEL_KD) || KD_VARIANT == KD_STREAM
; ==== intersection: a leaf's primitives against the stream [r3, r5) ==============================
isect:
        INTERSECT_FILTER
.endif

; ==== shading (Fig. 4): the filter stack on the generation's stream [r19, r20) ===================
shade:
        spst    r30, r0, L_LINK         ; the shaders below use r30 and r31 themselves
        stage   STAGE_SHADING
        beq     r19, r20, shade_done
        SHADOW_FILTER                   ; shadow rays [r19, r3): unoccluded ones add radiance
        MISS_FILTER                     ; misses [r3, r4): the background
        ; ---- surfaces; the hit-light filter
        beq     r4, r20, sh_return
        SHADE_STREAM r4, r20
        mov     r3, r4
        jal     r31, surface            ; [r3, r20) -> emitters first, r5 = end of them
.if WORKLOAD == WL_SPECULAR
        WORKLOAD_SHADER forced_specular
.elif WORKLOAD == WL_DIFFUSE
        WORKLOAD_SHADER one_bounce_diffuse
.elif WORKLOAD == WL_PHONG
        WORKLOAD_SHADER phong
.else
        ; ---- one filter per material kind on the hits [r5, r20), each to its shader
.ifdef HAS_LAMBERT
        MATERIAL_FILTER MAT_LAMBERT, diffuse
.endif
.ifdef HAS_GLOSSY
        MATERIAL_FILTER MAT_GLOSSY, diffuse
.endif
.ifdef HAS_DIELECTRIC
        MATERIAL_FILTER MAT_DIELECTRIC, dielectric, 0
.endif
.endif
sh_return:
shade_done:
        spld    r30, r0, L_LINK
        jr      r30

; ---- surface filter on [r3, r20), hit-light filter: emitters first, [r3, r5)
surface:
        SURFACE_FILTER

.if WORKLOAD == WL_PATH
diffuse:                                ; Lambert and glossy: direct/indirect split
        DIFFUSE_SHADER
direct:                                 ; direct lighting: shadow rays
        DIRECT_LIGHT
indirect:                               ; indirect lighting: bounces
        INDIRECT_LIGHT
.ifdef HAS_DIELECTRIC
dielectric:                             ; reflection or refraction
        DIELECTRIC_SHADER
.endif
.endif
.if WORKLOAD == WL_SPECULAR
forced_specular:
        SPECULAR_WORKLOAD
.endif
.if WORKLOAD == WL_DIFFUSE
one_bounce_diffuse:
        DIFFUSE_WORKLOAD
.endif
.if WORKLOAD == WL_PHONG
phong:
        PHONG_WORKLOAD
.endif
