; kernels/pathtrace.s -- the stream-filter path tracer (Gribble & Ramani 2008, Sec. 3-4), the
; program sfsim runs in `--mode functional` (and, later, under the timing model).
;
; One run renders one tile of at most RAYS pixels, all samples: for each sample a stream of
; camera rays, then breadth-first generations -- set-up filter, BVH traversal by stream
; filtering, intersection, shading filter stacks -- until a generation is empty. Radiance is
; scatter-added into the tile framebuffer. The algorithm and every float operation follow the
; golden model (sim/reference.c, docs/golden-model.md) so the images agree bit for bit;
; docs/kernel.md describes the structure, registers and memories.
;
; Assembled by the host with -D RAYS=M and one -D per scene feature (docs/kernel.md):
;   HAS_GLOSSY, HAS_DIELECTRIC, HAS_LAMBERT, HAS_NORMALS, HAS_BACKGROUND, HAS_AMBIENT,
;   HAS_EMISSIVE_TEX, HAS_COLORS; and
;   WORKLOAD (with BOUNCES) for the utilization workloads instead of the material shaders.

        .include "abi.inc"
        .include "layout.inc"
        .include "kconst.inc"
        .include "frames.inc"
        .include "vmath.inc"
        .include "isect.inc"

INV_PI_F  = 0.318309886
INV_2PI_F = 0.159154943
TWO_PI_F  = 6.28318531
SHADOW_TMAX = 0.999
RR_START_DEPTH = 3
RR_MAX_SURVIVAL = 0.95
SLAB_FAR_SCALE = 1.00000072
HIT_SCALE_F = 1.000244140625    ; 1 + 2^-12: pruning beyond the hit so far (REF_HIT_SCALE)
INF_BITS  = 0x7F800000
NODE_BYTES_LOG2 = 5
DIM_DIRECT = 0
DIM_LIGHT = 1
DIM_LIGHT_U = 2
DIM_LIGHT_V = 3
DIM_LOBE = 4
DIM_DIR_U = 5
DIM_DIR_V = 6
DIM_RR = 7
.ifndef WORKLOAD
WORKLOAD = WL_PATH
.endif
.if (WORKLOAD == WL_SPECULAR || WORKLOAD == WL_PHONG) && !defined(BOUNCES)
        .error "the specular and phong workloads need -D BOUNCES=n"
.endif
PHONG_AMBIENT = 0.05            ; phong: the ambient light of a scene without render.ambient

; ---- registers kept for the whole run ---------------------------------------------------------
; r0 = 0 (never written)          r16 chunk pointer of the running stream loop
; r17 sample                      r18 generation (= depth of every non-shadow ray in it)
; r19 current stream begin        r20 current stream end
; r21 next stream base            r22 next stream append pointer
; r23 next ray slot counter       r24 traversal stack pointer (scratchpad)
; r25 N                           r26, r27: scene header values (below)
; r28 spp   r29 max depth         r30, r31 link registers

.macro  PUSH node, b, e
        spst    \node, r24, 0
        spst    \b, r24, 4
        spst    \e, r24, 8
        addi    r24, r24, 12
.endm

; Per-generation stream counters: one more stream of [\b, \e) for stage offset \off.
.macro  COUNT_STREAM off, b, e, t1, t2, t3
        muli    \t1, r18, ST_GEN_BYTES
        spld    \t2, \t1, ST_GEN_BASE + \off
        addi    \t2, \t2, 1
        spst    \t2, \t1, ST_GEN_BASE + \off
        sub     \t3, \e, \b
        shri    \t3, \t3, 2
        spld    \t2, \t1, ST_GEN_BASE + \off + 4
        add     \t2, \t2, \t3
        spst    \t2, \t1, ST_GEN_BASE + \off + 4
.endm

        .text
start:  vli     vz, 0
        vli     vm2, -2
        rdn     r25
        ld      r28, r0, SM_HDR_SPP
        ld      r29, r0, SM_HDR_MAX_DEPTH
        li      r17, 0
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

; ==== one pass per sample: camera rays of the tile ==============================================
sample_loop:
        stage   STAGE_OTHER
        sgen    r0                      ; counters of generation 0 (camera rays)
        li      r19, 0                  ; streams live at IDM 0 and IDM FIELD_BYTES
        mov     r20, r19
        spld    r1, r0, L_W
        spld    r2, r0, L_H
        spld    r3, r0, L_X0
        spld    r4, r0, L_Y0
        spld    r5, r0, L_SEED          ; hash32(seed), scalar
        shri    r6, r5, 16
        xor     r5, r5, r6
        muli    r5, r5, 0x7feb352d
        shri    r6, r5, 15
        xor     r5, r5, r6
        muli    r5, r5, 0x846ca68b
        shri    r6, r5, 16
        xor     r5, r5, r6
        ld      r6, r0, SM_HDR_WIDTH
        ld      r13, r0, SM_HDR_HEIGHT
        cvtif   r14, r6                 ; (float) width, height
        cvtif   r15, r13
        li      r7, 0                   ; ly
        FRAME_CAMERA
cam_row:
        li      r8, 0                   ; lx of the chunk's first lane
cam_chunk:
        sub     r9, r1, r8
        mtail   m1, r9
        viota   vlx @m1
        vbcast  tc, r8 @m1
        vadd    vlx, vlx, tc @m1
        mul     r10, r7, r1
        vbcast  tc, r10 @m1
        vadd    cid, vlx, tc @m1        ; ray ID = ly * w + lx (raster order in the tile)
        add     r11, r4, r7             ; y
        mul     r12, r11, r6
        add     r12, r12, r3
        vbcast  tc, r12 @m1
        vadd    vkey, vlx, tc @m1       ; pixel = y * width + x
        vbcast  tc, r5 @m1
        vxor    vkey, vkey, tc @m1
        HASH    vkey, tc
        vbcast  tc, r17 @m1
        vadd    vkey, vkey, tc @m1
        HASH    vkey, tc                ; path key
        RAND    jx, vkey, 0, tc
        RAND    jy, vkey, 1, tc
        RAND    lr, vkey, 2, tc
        RAND    phi, vkey, 3, tc
        ; px = ((float) x + jx) / width - 0.5
        vbcast  tc, r3 @m1
        vadd    tc, vlx, tc @m1
        vcvtif  tc, tc @m1
        vfadd   jx, tc, jx @m1
        vbcast  tc, r14 @m1
        vfdiv   jx, jx, tc @m1
        vli     tc, 0.5 @m1
        vfsub   jx, jx, tc @m1
        ; py = 0.5 - ((float) y + jy) / height
        cvtif   r12, r11
        vbcast  tc2, r12 @m1
        vfadd   jy, tc2, jy @m1
        vbcast  tc2, r15 @m1
        vfdiv   jy, jy, tc2 @m1
        vfsub   jy, tc, jy @m1
        ; lens sample
        vsqrt   lr, lr @m1
        vli     tc, TWO_PI_F @m1
        vfmul   phi, tc, phi @m1
        vcos    lensx, phi @m1
        vfmul   lensx, lr, lensx @m1
        vsin    lensy, phi @m1
        vfmul   lensy, lr, lensy @m1
.macro  CAMAXIS d, o, off
        ldb     w0, r0, SM_HDR_CAM_W + \off @m1
        ldb     w1, r0, SM_HDR_CAM_U + \off @m1
        vfmul   w1, jx, w1 @m1
        vfadd   w0, w0, w1 @m1
        ldb     w1, r0, SM_HDR_CAM_V + \off @m1
        vfmul   w1, jy, w1 @m1
        vfadd   w0, w0, w1 @m1          ; focal point
        ldb     w1, r0, SM_HDR_LENS_U + \off @m1
        vfmul   w1, lensx, w1 @m1
        ldb     w2, r0, SM_HDR_LENS_V + \off @m1
        vfmul   w2, lensy, w2 @m1
        vfadd   w1, w1, w2 @m1          ; lens offset
        ldb     \o, r0, SM_HDR_CAM_POS + \off @m1
        vfadd   \o, \o, w1 @m1
        vfsub   \d, w0, w1 @m1
.endm
        CAMAXIS dx, ox, 0
        CAMAXIS dy, oy, 4
        CAMAXIS dz, oz, 8
        NORMALIZE3 d, tc, tc2
        rsct    ox, cid, r0, F_ORGX @m1
        rsct    oy, cid, r0, F_ORGY @m1
        rsct    oz, cid, r0, F_ORGZ @m1
        rsct    dx, cid, r0, F_DIRX @m1
        rsct    dy, cid, r0, F_DIRY @m1
        rsct    dz, cid, r0, F_DIRZ @m1
        vli     tc, INF_BITS @m1
        rsct    tc, cid, r0, F_TMAX @m1
        vli     tc, 1.0 @m1
        rsct    tc, cid, r0, F_THRR @m1
        rsct    tc, cid, r0, F_THRG @m1
        rsct    tc, cid, r0, F_THRB @m1
        vmuli   tc, cid, 12 @m1
        rsct    tc, cid, r0, F_FBOFF @m1
        rsct    vkey, cid, r0, F_KEY @m1
        vli     tc, KIND_CAMERA @m1
        rsct    tc, cid, r0, F_KIND @m1
        vli     tc, 0 @m1
        rsct    tc, cid, r0, F_SPEC @m1
        sapp    r20, cid @m1
        add     r8, r8, r25
        blt     r8, r1, cam_chunk
        addi    r7, r7, 1
        blt     r7, r2, cam_row
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

; ==== set-up filter: drop non-finite rays, precompute the traversal constants ====================
; Stream [r19, r20) -> [r19, r20') of finite rays; r20 moves down.
setup:
        beq     r19, r20, setup_done
        FRAME_SETUP
        mov     r16, r19
setup_chunk:
        sfetch  vid, m1, r16, r20
        rgat    ox, vid, r0, F_ORGX @m1
        rgat    oy, vid, r0, F_ORGY @m1
        rgat    oz, vid, r0, F_ORGZ @m1
        rgat    dx, vid, r0, F_DIRX @m1
        rgat    dy, vid, r0, F_DIRY @m1
        rgat    dz, vid, r0, F_DIRZ @m1
        ; finite: the sum of x * 0 over the nine values is 0, else NaN
        vfmul   vt, ox, vz @m1
        vfmul   vt2, oy, vz @m1
        vfadd   vt, vt, vt2 @m1
        vfmul   vt2, oz, vz @m1
        vfadd   vt, vt, vt2 @m1
        vfmul   vt2, dx, vz @m1
        vfadd   vt, vt, vt2 @m1
        vfmul   vt2, dy, vz @m1
        vfadd   vt, vt, vt2 @m1
        vfmul   vt2, dz, vz @m1
        vfadd   vt, vt, vt2 @m1
        rgat    ax, vid, r0, F_THRR @m1
        vfmul   vt2, ax, vz @m1
        vfadd   vt, vt, vt2 @m1
        rgat    ax, vid, r0, F_THRG @m1
        vfmul   vt2, ax, vz @m1
        vfadd   vt, vt, vt2 @m1
        rgat    ax, vid, r0, F_THRB @m1
        vfmul   vt2, ax, vz @m1
        vfadd   vt, vt, vt2 @m1
        vfeq    m2, vt, vz @m1
        pmask   m2
        ; sanitized direction and its inverse
        SANITIZE1 dx, vt, vt2, m3
        SANITIZE1 dy, vt, vt2, m3
        SANITIZE1 dz, vt, vt2, m3
        vrcp    vt, dx @m1
        rsct    vt, vid, r0, F_INVX @m1
        vrcp    vt, dy @m1
        rsct    vt, vid, r0, F_INVY @m1
        vrcp    vt, dz @m1
        rsct    vt, vid, r0, F_INVZ @m1
        ; watertight test set-up: kz = axis of the largest |d|, kx, ky the next ones
        vfabs   ax, dx @m1
        vfabs   ay, dy @m1
        vfabs   az, dz @m1
        vli     vone, 1 @m1
        vli     vtwo, 2 @m1
        vflt    m3, ay, ax @m1          ; ax > ay
        vflt    m4, az, ax @m1          ; ax > az
        vflt    m5, az, ay @m1          ; ay > az
        vmov    kz, vtwo @m1
        vmov    kz, vone @m5
        mand    m6, m3, m4
        vli     kz, 0 @m6
        mandn   m6, m3, m4
        vmov    kz, vtwo @m6
        vaddi   kx, kz, 1 @m1
        vieq    m6, kz, vtwo @m1
        vli     kx, 0 @m6
        vaddi   ky, kx, 1 @m1
        vieq    m6, kx, vtwo @m1
        vli     ky, 0 @m6
.macro  PICK d, idx, a                  ; d = a[idx] for idx in 0..2 (lane-wise)
        vmov    \d, \a\()x @m1
        vieq    m6, \idx, vone @m1
        vmov    \d, \a\()y @m6
        vieq    m6, \idx, vtwo @m1
        vmov    \d, \a\()z @m6
.endm
        PICK    dkz, kz, d
        vflt    m6, dkz, vz @m1         ; d[kz] < 0: swap kx and ky to keep the winding
        vmov    vt, kx @m6
        vmov    kx, ky @m6
        vmov    ky, vt @m6
        PICK    vt, kx, d
        vfdiv   vt, vt, dkz @m1
        rsct    vt, vid, r0, F_SX @m1
        PICK    vt, ky, d
        vfdiv   vt, vt, dkz @m1
        rsct    vt, vid, r0, F_SY @m1
        vrcp    vt, dkz @m1
        rsct    vt, vid, r0, F_SZ @m1
        PICK    vt, kx, o
        rsct    vt, vid, r0, F_POX @m1
        PICK    vt, ky, o
        rsct    vt, vid, r0, F_POY @m1
        PICK    vt, kz, o
        rsct    vt, vid, r0, F_POZ @m1
        vshli   vt, kx, 2 @m1
        rsct    vt, vid, r0, F_KX @m1
        vshli   vt, ky, 2 @m1
        rsct    vt, vid, r0, F_KY @m1
        vshli   vt, kz, 2 @m1
        rsct    vt, vid, r0, F_KZ @m1
        ; no hit yet; shadow rays are marked -2
        rgat    vt, vid, r0, F_KIND @m1
        vieq    m6, vt, vtwo @m1
        vli     vt2, -1 @m1
        vmov    vt2, vm2 @m6
        rsct    vt2, vid, r0, F_PRIM @m1
        blt     r16, r20, setup_chunk
        part    r1, r19, r20
        sub     r2, r20, r1
        shri    r2, r2, 2
        spld    r3, r0, ST_DROPPED
        add     r3, r3, r2
        spst    r3, r0, ST_DROPPED
        mov     r20, r1
setup_done:
        jr      r30

; the slab test of a ray against a box (BVH node or kd-tree voxel); far ends widened
.macro  SLAB bmin, bmax, o, inv
        vfsub   t0, \bmin, \o @m1
        vfmul   t0, t0, \inv @m1
        vfsub   t1, \bmax, \o @m1
        vfmul   t1, t1, \inv @m1
        vfmin   tlo, t0, t1 @m1
        vfmax   t1, t0, t1 @m1
        vfmul   t1, t1, vscale @m1
        vfmax   tn, tn, tlo @m1
        vfmin   tf, tf, t1 @m1
.endm
.ifdef ACCEL_KD
        .include "kdtrace.inc"
.else
; ==== traversal: stream filtering down the BVH (Fig. 3), front to back per ray ==================
; A stack entry is (node address, begin, end) of an ID range in IDM; ranges are partitioned in
; place, so a child's range is a prefix of its parent's. At an inner node the passing rays are
; split by the sign of their direction on the split axis, and the four (child, half) entries are
; pushed so that every ray meets the near child's whole subtree first -- the golden model's
; visiting order, hence its hit distances and tie breaks, for every ray.
trace:
        stage   STAGE_TRAVERSAL
        ld      r15, r0, SM_HDR_NNODES
        beq     r15, r0, trace_done
        ld      r26, r0, SM_HDR_NODES
        ld      r27, r0, SM_HDR_PRIMS
        li      r24, STACK_BASE
        spst    r26, r24, 0
        spst    r19, r24, 4
        spst    r20, r24, 8
        addi    r24, r24, 12
        FRAME_BOX
trav_pop:
        li      r1, STACK_BASE
        beq     r24, r1, trace_done
        addi    r24, r24, -12
        spld    r2, r24, 0              ; node address
        spld    r3, r24, 4              ; range
        spld    r4, r24, 8
        ldb     bminx, r2, SM_NODE_BMIN
        ldb     bminy, r2, SM_NODE_BMIN + 4
        ldb     bminz, r2, SM_NODE_BMIN + 8
        ldb     bmaxx, r2, SM_NODE_BMAX
        ldb     bmaxy, r2, SM_NODE_BMAX + 4
        ldb     bmaxz, r2, SM_NODE_BMAX + 8
        vli     vscale, SLAB_FAR_SCALE
        COUNT_STREAM ST_G_TRAV, r3, r4, r5, r6, r7
        mov     r16, r3
box_chunk:
        sfetch  vid, m1, r16, r4
        rgat    ox, vid, r0, F_ORGX @m1
        rgat    oy, vid, r0, F_ORGY @m1
        rgat    oz, vid, r0, F_ORGZ @m1
        rgat    ix, vid, r0, F_INVX @m1
        rgat    iy, vid, r0, F_INVY @m1
        rgat    iz, vid, r0, F_INVZ @m1
        rgat    tf, vid, r0, F_TMAX @m1
        vli     t0, HIT_SCALE_F @m1
        vfmul   tf, tf, t0 @m1          ; the hit distance so far, widened (REF_HIT_SCALE)
        vli     tn, 0 @m1
        SLAB    bminx, bmaxx, ox, ix
        SLAB    bminy, bmaxy, oy, iy
        SLAB    bminz, bmaxz, oz, iz
        vfle    m2, tn, tf @m1
        pmask   m2
        blt     r16, r4, box_chunk
        part    r5, r3, r4              ; [r3, r5): rays that overlap the box
        beq     r5, r3, trav_pop        ; empty streams are pruned
        ld      r6, r2, SM_NODE_INFO
        ld      r7, r2, SM_NODE_FIRST
        blt     r6, r0, trav_inner
        stage   STAGE_INTERSECTION
        jal     r31, isect
        stage   STAGE_TRAVERSAL
        jmp     trav_pop
trav_inner:
        andi    r8, r6, 3               ; split axis: F_INV of that axis
        muli    r8, r8, FIELD_BYTES
        addi    r8, r8, F_INVX
.ifdef ORDER_FIRST
        ; stream.order = first: the whole stream visits the near child of its first ray first
        ; (Fig. 3's front_child; images may differ from the golden model's in exact ties)
        mov     r16, r3
        sfetch  vid, m1, r16, r5
        rgat    t0, vid, r8, 0 @m1
        vext    r9, t0, 0
        shli    r10, r7, NODE_BYTES_LOG2
        add     r10, r10, r26           ; left child
        addi    r11, r10, SM_NODE_BYTES ; right child
        li      r12, STACK_LIMIT
        addi    r1, r24, 24
        bltu    r12, r1, err_stack
        blt     r9, r0, first_neg       ; (the sign bit of 1 / d)
        PUSH    r11, r3, r5
        PUSH    r10, r3, r5
        jmp     trav_pop
first_neg:
        PUSH    r10, r3, r5
        PUSH    r11, r3, r5
        jmp     trav_pop
.endif
        mov     r16, r3
split_chunk:
        sfetch  vid, m1, r16, r5
        rgat    t0, vid, r8, 0 @m1
        vflt    m2, t0, vz @m1          ; negative direction: the right child is nearer
        pmask   m2
        blt     r16, r5, split_chunk
        part    r9, r3, r5              ; [r3, r9) negative, [r9, r5) positive
        shli    r10, r7, NODE_BYTES_LOG2
        add     r10, r10, r26           ; left child
        addi    r11, r10, SM_NODE_BYTES ; right child
        li      r12, STACK_LIMIT        ; room for four entries?
        addi    r1, r24, 48
        bltu    r12, r1, err_stack
        beq     r9, r5, push_neg_only   ; no positive rays
        beq     r3, r9, push_pos_only   ; no negative rays
        PUSH    r11, r9, r5             ; positive rays: right child second
        PUSH    r10, r3, r9             ; negative rays: left child second
        PUSH    r10, r9, r5             ; positive rays: left child first
        PUSH    r11, r3, r9             ; negative rays: right child first
        jmp     trav_pop
push_pos_only:
        PUSH    r11, r9, r5
        PUSH    r10, r9, r5
        jmp     trav_pop
push_neg_only:
        PUSH    r10, r3, r9
        PUSH    r11, r3, r9
        jmp     trav_pop
trace_done:
        stage   STAGE_OTHER
        jr      r30

.endif

.if !defined(ACCEL_KD) || KD_VARIANT == KD_STREAM
; ==== intersection: the leaf's primitives against the stream [r3, r5) ===========================
; Per ray the primitives are tested in order (the golden model's order); the best hit stays in
; registers over the leaf and is scattered once per chunk (conditional scatter).
; In: r7 first primitive, r6 count. Clobbers r1-r15 (not r24, r26, r27).
isect:
        FRAME_ISECT
        COUNT_STREAM ST_G_ISECT, r3, r5, r8, r9, r10
.ifdef ACCEL_KD
        shli    r8, r7, 2               ; kd-tree leaf: r7 is its first KD_PRIMS entry
        add     r8, r8, r14
        shli    r9, r6, 2
        add     r9, r9, r8              ; one past its last
.else
        li      r8, SM_PRIM_BYTES
        mul     r8, r8, r7
        add     r8, r8, r27             ; address of the first primitive
        add     r9, r7, r6              ; one past the last index
.endif
        mov     r16, r3
isect_chunk:
        sfetch  vid, m1, r16, r5
        ISECT_LOAD
.ifdef ACCEL_KD
        mov     r13, r8
isect_prim:
        ld      r11, r13, 0             ; primitive index and address
        muli    r10, r11, SM_PRIM_BYTES
        add     r10, r10, r27
.else
        mov     r10, r8                 ; primitive address
        mov     r11, r7                 ; primitive index
isect_prim:
.endif
.ifdef HAS_SPHERES
        ld      r12, r10, SM_PRIM_KIND
        bne     r12, r0, isect_sphere
.endif
        vbcast  ta, r10 @m1
        TRI_TEST isect_next
isect_update:
        HIT_UPDATE vbcast, r11
.ifdef HAS_SPHERES
        jmp     isect_next
isect_sphere:
        SPH_TEST ldb, r10
        jmp     isect_update
.endif
isect_next:
.ifdef ACCEL_KD
        addi    r13, r13, 4
        blt     r13, r9, isect_prim
.else
        addi    r10, r10, SM_PRIM_BYTES
        addi    r11, r11, 1
        blt     r11, r9, isect_prim
.endif
        rsct    tm, vid, r0, F_TMAX @m3
        rsct    prim, vid, r0, F_PRIM @m4
        rsct    bu, vid, r0, F_U @m4
        rsct    bv, vid, r0, F_V @m4
.ifdef ACCEL_KD
        rgatn   ex, vid, r0, KS_CLEAVES @m1 ; per-ray counters (kdstream.inc)
        vaddi   ex, ex, 1 @m1
        rsctn   ex, vid, r0, KS_CLEAVES @m1
        rgatn   ex, vid, r0, KS_CPRIMS @m1
        vbcast  ey, r6 @m1
        vadd    ex, ex, ey @m1
        rsctn   ex, vid, r0, KS_CPRIMS @m1
.endif
        blt     r16, r5, isect_chunk
        jr      r31

.endif

; ==== shading: the filter stack of Fig. 4 ========================================================
; Stream [r19, r20) after traversal. Shadow filter, miss filter, surface + hit-light filter, then
; one filter per material kind; each material shader splits direct and indirect rays with a
; further filter. New rays go to the next ray buffer (ralloc, rsctn) and their IDs to the next
; stream (sapp r22).

; count a shading filter's input stream [\b, \e) (scratch r1, r2, r4 saved around it)
.macro  SHADE_STREAM b, e
        spst    r4, r0, L_SCRATCH
        COUNT_STREAM ST_G_SHADE, \b, \e, r1, r2, r4
        spld    r4, r0, L_SCRATCH
.endm

; New ray into the next buffer for the lanes of mask k; o, d, th triples; vid the parent. The
; Phong workload's shadow rays go into the current buffer instead (sct = rsct, slots from r23 and
; IDs to r22 as set by phong).
.macro  EMIT k, o, d, th, tmaxv, kind, spec, slot, t, sct=rsctn
        ralloc  \slot, r23 @\k
        \sct    \o\()x, \slot, r0, F_ORGX @\k
        \sct    \o\()y, \slot, r0, F_ORGY @\k
        \sct    \o\()z, \slot, r0, F_ORGZ @\k
        \sct    \d\()x, \slot, r0, F_DIRX @\k
        \sct    \d\()y, \slot, r0, F_DIRY @\k
        \sct    \d\()z, \slot, r0, F_DIRZ @\k
        \sct    \th\()x, \slot, r0, F_THRR @\k
        \sct    \th\()y, \slot, r0, F_THRG @\k
        \sct    \th\()z, \slot, r0, F_THRB @\k
        vli     \t, \tmaxv @\k
        \sct    \t, \slot, r0, F_TMAX @\k
        rgat    \t, vid, r0, F_FBOFF @\k
        \sct    \t, \slot, r0, F_FBOFF @\k
        rgat    \t, vid, r0, F_KEY @\k
        \sct    \t, \slot, r0, F_KEY @\k
        vli     \t, \kind @\k
        \sct    \t, \slot, r0, F_KIND @\k
        vli     \t, \spec @\k
        \sct    \t, \slot, r0, F_SPEC @\k
        sapp    r22, \slot @\k
.endm

; n := the unit geometric normal turned to face the incoming ray (nf), d := the ray direction;
; m := lanes where it was turned. t, t2 scratch.
.macro  FACING_NORMAL n, d, t, t2, m, k=m1
        GATHER3 \n, F_NGX, F_NGY, F_NGZ, \k
        GATHER3 \d, F_DIRX, F_DIRY, F_DIRZ, \k
        DOT3    \t, \n, \d, \t2, \k
        vflt    \m, vz, \t @\k
        vfneg   \n\()x, \n\()x @\m
        vfneg   \n\()y, \n\()y @\m
        vfneg   \n\()z, \n\()z @\m
.endm

; c := a cosine-weighted direction's local coordinates (sqrt(u) cos phi, sqrt(u) sin phi,
; sqrt(max(0, 1 - u))), d := it around the unit vector n. t1..t5 scratch.
.macro  COSINE_DIR d, n, u, phi, c, t1, t2, t3, t4, t5, k=m1
        vsqrt   \t1, \u @\k
        vcos    \c\()x, \phi @\k
        vfmul   \c\()x, \t1, \c\()x @\k
        vsin    \c\()y, \phi @\k
        vfmul   \c\()y, \t1, \c\()y @\k
        vli     \t1, 1.0 @\k
        vfsub   \t1, \t1, \u @\k
        vfmax   \t1, vz, \t1 @\k
        vsqrt   \c\()z, \t1 @\k
        TO_WORLD \d, \n, \c\()x, \c\()y, \c\()z, \t1, \t2, \t3, \t4, \t5, \k
.endm

; fbadd of a triple at the rays' pixels (vid the rays; t scratch)
.macro  FBADD3 v, t, k
        rgat    \t, vid, r0, F_FBOFF @\k
        fbadd   \v\()x, \t, 0 @\k
        fbadd   \v\()y, \t, 4 @\k
        fbadd   \v\()z, \t, 8 @\k
.endm

; thr triple of the rays
.macro  GATHER3 v, f0, f1, f2, k=m1
        rgat    \v\()x, vid, r0, \f0 @\k
        rgat    \v\()y, vid, r0, \f1 @\k
        rgat    \v\()z, vid, r0, \f2 @\k
.endm

; d := c > 0 ? 2^(n log2 c) : 0 -- c^n as sim/reference.c's pow_lobe computes it (vexp2 and
; vlog2 are exp2f and log2f, sim/core.c); d may be c; t (not c or n) and the mask mt clobbered.
.macro  POW_LOBE d, c, n, t, mt, k=m1
        vflt    \mt, vz, \c @\k
        vlog2   \t, \c @\mt
        vfmul   \t, \n, \t @\mt
        vexp2   \t, \t @\mt
        vli     \d, 0 @\k
        vmov    \d, \t @\mt
.endm

; n := the Phong exponent 2 / max(roughness^2, 0.001) - 2 of the roughness in n; t = 2.0 after.
.macro  GLOSSY_EXP n, t, k=m1
        vfmul   \n, \n, \n @\k
        vli     \t, 0.001 @\k
        vfmax   \n, \n, \t @\k
        vli     \t, 2.0 @\k
        vfdiv   \n, \t, \n @\k
        vfsub   \n, \n, \t @\k
.endm

; Ambient term of the m1 rays' hits: thr x base x the scene's ambient (render.ambient), or
; PHONG_AMBIENT when it has none (the Phong workload). th, b triples and t clobbered.
.macro  AMBIENT_ADD th, b, t
        GATHER3 \th, F_THRR, F_THRG, F_THRB
        GATHER3 \b, F_BASER, F_BASEG, F_BASEB
        vfmul   \th\()x, \th\()x, \b\()x @m1
        vfmul   \th\()y, \th\()y, \b\()y @m1
        vfmul   \th\()z, \th\()z, \b\()z @m1
.ifdef HAS_AMBIENT
        ldb     \b\()x, r0, SM_HDR_AMBIENT @m1
        ldb     \b\()y, r0, SM_HDR_AMBIENT + 4 @m1
        ldb     \b\()z, r0, SM_HDR_AMBIENT + 8 @m1
        vfmul   \th\()x, \th\()x, \b\()x @m1
        vfmul   \th\()y, \th\()y, \b\()y @m1
        vfmul   \th\()z, \th\()z, \b\()z @m1
.else
        vli     \t, PHONG_AMBIENT @m1
        SCALE3  \th, \t
.endif
        FBADD3  \th, \t, m1
.endm

; Shadow filter: the unoccluded shadow rays of [b, e) (occluded ones have tmax = -1) add the
; radiance they carry. tm, t and the triple th clobbered; r16 runs over the stream.
.macro  SHADOW_ADD b, e, tm, th, t
        mov     r16, \b
sa\@:
        sfetch  vid, m1, r16, \e
        rgat    \tm, vid, r0, F_TMAX @m1
        vfle    m2, vz, \tm @m1
        GATHER3 \th, F_THRR, F_THRG, F_THRB, m2
        FBADD3  \th, \t, m2
        blt     r16, \e, sa\@
.endm

; The m1 hits' mirror rays about the facing geometric normal, from the hit point moved off on
; that side, with throughput th (the forced specular and Phong bounces). Triples d, nf, p, o and
; vt, vt2, m2 clobbered.
.macro  MIRROR_EMIT th
        FACING_NORMAL nf, d, vt, vt2, m2
        REFLECT3 d, d, nf, vt, vt2
        GATHER3 p, F_PX, F_PY, F_PZ
        OFFSET3 o, p, nf, vt, vt2, vz, m2
        EMIT    m1, o, d, \th, INF_BITS, KIND_INDIRECT, 1, vt, vt2
.endm

; filter: partition [\b, \e) so the rays whose field \field equals \val (integer) come first;
; \split := end of that part
.macro  FILTER_EQ b, e, split, field, val
        mov     \split, \b
        beq     \b, \e, fd\@
        mov     r16, \b
fe\@:
        sfetch  v0, m1, r16, \e
        rgat    v1, v0, r0, \field @m1
        vli     v2, \val @m1
        vieq    m2, v1, v2 @m1
        pmask   m2
        blt     r16, \e, fe\@
        part    \split, \b, \e
fd\@:
.endm


.macro  LPOINT p, e1, e2, o
        vfmul   vt, lu, \e1 @m4
        vfadd   \p, \p, vt @m4
        vfmul   vt, lv, \e2 @m4
        vfadd   \p, \p, vt @m4
        vfsub   \p, \p, \o @m1         ; shadow ray direction: light point - origin
.endm

; The light at la (per lane) seen from the origins o, at the point (lu, lv) of its sampling
; parametrization (P + c1 E1 + c2 E2; quad: c = (u, v); triangle: sqrt(u) (1 - v), sqrt(u) v):
; lp := the shadow-ray direction (light point - o, or 4 scene scales along a directional
; light), wi := it normalized, e1 := le, the radiance it brings x geometry, e2 := the shading
; normal, vt3 := cos at it; m2 := the m1 lanes that receive light and see it from both
; normals (nf facing the ray). sample_light and shade_direct of sim/reference.c, operation
; for operation. Registers of FRAME_LIGHT; clobbers m3-m7, nl, vt, vt2, r1, r7 (and, with
; HAS_EMISSIVE_TEX, p: the emissive texel of a textured triangle light).
.macro  LIGHT_SAMPLE
        ldg     lk, la, SM_LIGHT_KIND @m1
        ; light kinds: m4 area (quad, triangle), m5 spot, m6 directional, m7 point
.ifdef HAS_PUNCTUAL
        vli     vt, LIGHT_QUAD @m1
        vilt    m4, lk, vt @m1
        mandn   m4, m1, m4
        vli     vt, LIGHT_SPOT @m1
        vieq    m5, lk, vt @m1
        vli     vt, LIGHT_DIRECTIONAL @m1
        vieq    m6, lk, vt @m1
        vli     vt, LIGHT_POINT @m1
        vieq    m7, lk, vt @m1
.else
        mmov    m4, m1
.endif
        vli     vt, LIGHT_TRIANGLE @m1
        vieq    m2, lk, vt @m1
        vsqrt   vt, lu @m2
        vli     vt2, 1.0 @m2
        vfsub   vt2, vt2, lv @m2
        vfmul   vt2, vt, vt2 @m2
        vfmul   lv, vt, lv @m2
        vmov    lu, vt2 @m2
.ifdef HAS_EMISSIVE_TEX
        ; triangles with an emissive texture (LIGHT TEX >= 0; m3): p := the texel's colour at
        ; the sampled point (emissive coordinates at barycentrics (1 - c1 - c2, c1, c2)), which
        ; scales le below; 1 on the other lanes
        vli     px, 1.0 @m1
        vli     py, 1.0 @m1
        vli     pz, 1.0 @m1
        ldg     e2x, la, SM_LIGHT_TEX @m2
        vilt    m3, e2x, vz @m2
        mandn   m3, m2, m3
        bmz     m3, ls_notex\@
        ldg     e1x, la, SM_LIGHT_SRC @m3
        vmuli   e1x, e1x, 24 @m3
        ldb     vt, r0, SM_HDR_EMIT_UVS @m3
        vadd    e1x, e1x, vt @m3        ; the three emissive uv pairs
        vli     vt3, 1.0 @m3
        vfsub   vt3, vt3, lu @m3
        vfsub   vt3, vt3, lv @m3
        BARY    e1y, e1x, 0, 8, vt3, lu, lv, vt, m3
        BARY    e1z, e1x, 4, 8, vt3, lu, lv, vt, m3
        TEXEL3  p, e2x, e1y, e1z, e1x, vt, vt2, m3, m2
ls_notex\@:
.endif
        ldg     lpx, la, SM_LIGHT_P @m1
        ldg     lpy, la, SM_LIGHT_P + 4 @m1
        ldg     lpz, la, SM_LIGHT_P + 8 @m1
        ldg     e1x, la, SM_LIGHT_E1 @m1
        ldg     e1y, la, SM_LIGHT_E1 + 4 @m1
        ldg     e1z, la, SM_LIGHT_E1 + 8 @m1
        ldg     e2x, la, SM_LIGHT_E2 @m4
        ldg     e2y, la, SM_LIGHT_E2 + 4 @m4
        ldg     e2z, la, SM_LIGHT_E2 + 8 @m4
        LPOINT  lpx, e1x, e2x, ox
        LPOINT  lpy, e1y, e2y, oy
        LPOINT  lpz, e1z, e2z, oz
        DOT3    vt3, lp, lp, vt         ; d2
        vflt    m2, vz, vt3 @m1         ; d2 > 0
        vrsqrt  vt, vt3 @m2
        vfmul   lu, lpx, vt @m2         ; wi (in lu, lv, lk)
        vfmul   lv, lpy, vt @m2
        vfmul   lk, lpz, vt @m2
        ; area lights: the cosine at the light (front side unless two-sided); scale in vt2
        mand    m3, m2, m4
        CROSS3  nl, e1, e2, vt, m3
        NORMALIZE3 nl, vt, vt2, m3
        DOT3    vt2, nl, wi, vt, m3
        vfneg   vt2, vt2 @m3            ; cosl
        ldg     vt, la, SM_LIGHT_TWO_SIDED @m3
        vsub    nlx, vz, vt @m3
        vor     vt, vt, nlx @m3
        vshri   vt, vt, 31 @m3
        vshli   vt, vt, 31 @m3
        vxori   vt, vt, -1 @m3
        vand    vt2, vt2, vt @m3        ; two-sided: |cosl|
        vflt    m3, vz, vt2 @m3         ; cosl > 0
        mandn   m4, m4, m3
        mandn   m2, m2, m4              ; area lanes failing it are out
        ldg     vt, la, SM_LIGHT_AREA @m3
        vfmul   vt2, vt2, vt @m3
        vfdiv   vt2, vt2, vt3 @m3       ; scale = cosl area / d2
.ifdef HAS_PUNCTUAL
        ; spot: falloff between the cone angles / d2
        mand    m3, m2, m5
        NORMALIZE3 e1, vt, nlx, m3
        DOT3    nlx, e1, wi, vt, m3
        vfneg   nlx, nlx @m3            ; cd
        ldg     nly, la, SM_LIGHT_COS_INNER @m3
        ldg     nlz, la, SM_LIGHT_COS_OUTER @m3
        vfsub   nlx, nlx, nlz @m3
        vfsub   nly, nly, nlz @m3
        vli     vt, 0.000001 @m3
        vfmax   nly, nly, vt @m3
        vfdiv   nlx, nlx, nly @m3
        vfmax   nlx, nlx, vz @m3
        vli     vt, 1.0 @m3
        vfmin   nlx, nlx, vt @m3
        vfdiv   vt2, nlx, vt3 @m3
        ; point: 1 / d2
        mand    m3, m2, m7
        vrcp    vt2, vt3 @m3
        ; directional: wi = normalize(-P), direction wi x 4 scene scale, scale 1
        bmz     m6, ls_nodir\@
        ldg     lu, la, SM_LIGHT_P @m6
        ldg     lv, la, SM_LIGHT_P + 4 @m6
        ldg     lk, la, SM_LIGHT_P + 8 @m6
        vfneg   lu, lu @m6
        vfneg   lv, lv @m6
        vfneg   lk, lk @m6
        NORMALIZE3 wi, vt, nlx, m6
        ld      r7, r0, SM_HDR_EPSILON
        li      r1, 4.0
        fmul    r7, r1, r7
        vbcast  vt, r7 @m6
        vfmul   lpx, wix, vt @m6
        vfmul   lpy, wiy, vt @m6
        vfmul   lpz, wiz, vt @m6
        vli     vt2, 1.0 @m6
        mor     m2, m2, m6
        ld      r1, r0, SM_HDR_LIGHTS   ; (r1: direct's light array, clobbered above)
ls_nodir\@:
.endif
        ldg     e1x, la, SM_LIGHT_RADIANCE @m2
        ldg     e1y, la, SM_LIGHT_RADIANCE + 4 @m2
        ldg     e1z, la, SM_LIGHT_RADIANCE + 8 @m2
        SCALE3  e1, vt2, m2             ; le
.ifdef HAS_EMISSIVE_TEX
        vfmul   e1x, e1x, px @m2        ; x the emissive texel (1 for other lights)
        vfmul   e1y, e1y, py @m2
        vfmul   e1z, e1z, pz @m2
.endif
        vflt    m2, vz, vt2 @m2         ; scale > 0
        ; both normals must see the light
        DOT3    vt, wi, nf, vt3, m2
        vfle    m3, vt, vz @m2
        mandn   m2, m2, m3
        GATHER3 e2, F_NSX, F_NSY, F_NSZ, m2
        DOT3    vt, wi, e2, vt3, m2
        vfle    m3, vt, vz @m2
        mandn   m2, m2, m3
        DOT3    vt3, e2, wi, vt, m2     ; cosi = ns . wi
.endm

; d := w a[off] + u a[off + stride] + v a[off + 2 stride] (per lane at address a): one
; attribute interpolated at barycentrics (w, u, v), as sim/reference.c writes it. t scratch.
.macro  BARY d, a, off, stride, w, u, v, t, k
        ldg     \d, \a, \off @\k
        vfmul   \d, \w, \d @\k
        ldg     \t, \a, \off + \stride @\k
        vfmul   \t, \u, \t @\k
        vfadd   \d, \d, \t @\k
        ldg     \t, \a, \off + 2 * \stride @\k
        vfmul   \t, \v, \t @\k
        vfadd   \d, \d, \t @\k
.endm

; d := the texel index along one axis at coordinate t (clobbered) of a texture `size` texels
; long: repeat wrapping (t - floor t), scaled, truncated, clamped to [0, size - 1]; texel() of
; sim/reference.c. s and the mask mt scratch.
.macro  TEXIDX d, t, size, s, k, mt
        vffloor \s, \t @\k
        vfsub   \t, \t, \s @\k        ; fractional part
        vcvtif  \s, \size @\k
        vfmul   \t, \t, \s @\k
        vcvtfi  \d, \t @\k
        vilt    \mt, \d, vz @\k          ; (integer compare with 0)
        vli     \d, 0 @\mt
        vilt    \mt, \d, \size @\k
        mandn   \mt, \k, \mt
        vaddi   \d, \size, -1 @\mt
.endm

; d := channel `shift` / 8 of the RGBA8 texel words, sRGB-decoded through the table at lut. s scratch.
.macro  TEXCH d, texel, shift, lut, s, k
        vshri   \s, \texel, \shift @\k
        vandi   \s, \s, 255 @\k
        vshli   \s, \s, 2 @\k
        vadd    \s, \s, \lut @\k
        ldg     \d, \s, 0 @\k
.endm

; o := the linear colour of texture `tex` (index per lane; clobbered) at (tu, tv) (clobbered):
; the nearest texel with repeat wrapping, sRGB-decoded -- texel() and texel_channel() of
; sim/reference.c. a, t, t2 and the mask mt scratch.
.macro  TEXEL3 o, tex, tu, tv, a, t, t2, k, mt
        vshli   \a, \tex, 4 @\k           ; SM_TEX_BYTES = 16
        ldb     \t, r0, SM_HDR_TEXS @\k
        vadd    \a, \a, \t @\k            ; texture record
        ldg     \t, \a, SM_TEX_WIDTH @\k
        ldg     \t2, \a, SM_TEX_HEIGHT @\k
        TEXIDX  \o\()x, \tu, \t, \o\()z, \k, \mt  ; ix
        TEXIDX  \o\()y, \tv, \t2, \o\()z, \k, \mt ; iy
        vmul    \o\()y, \o\()y, \t @\k
        vadd    \o\()y, \o\()y, \o\()x @\k
        vshli   \o\()y, \o\()y, 2 @\k
        ldg     \a, \a, SM_TEX_TEXELS @\k
        vadd    \o\()y, \o\()y, \a @\k
        ldg     \tex, \o\()y, 0 @\k         ; RGBA8 texel
        ldb     \t, r0, SM_HDR_SRGB_LUT @\k
        TEXCH   \o\()x, \tex, 0, \t, \a, \k
        TEXCH   \o\()y, \tex, 8, \t, \a, \k
        TEXCH   \o\()z, \tex, 16, \t, \a, \k
.endm

shade:
        spst    r30, r0, L_LINK         ; the shaders below use r30 and r31 themselves
        stage   STAGE_SHADING
        beq     r19, r20, shade_done
        ; ---- shadow filter: unoccluded shadow rays add the radiance they carry
        FILTER_EQ r19, r20, r3, F_KIND, KIND_SHADOW
        sub     r1, r3, r19
        shri    r1, r1, 2
        spld    r2, r0, ST_SHADOW
        add     r2, r2, r1
        spst    r2, r0, ST_SHADOW
        sub     r1, r20, r3
        shri    r1, r1, 2
        li      r4, ST_INDIRECT
        bne     r18, r0, sh_count
        li      r4, ST_CAMERA
sh_count:
        spld    r2, r4, 0
        add     r2, r2, r1
        spst    r2, r4, 0
        beq     r19, r3, sh_shadow_done
        SHADE_STREAM r19, r3
        FRAME_SHADE
        SHADOW_ADD r19, r3, tm, th, vt
sh_shadow_done:
        ; ---- miss filter
        FILTER_EQ r3, r20, r4, F_PRIM, -1
.ifdef HAS_BACKGROUND
        beq     r3, r4, sh_miss_done
        SHADE_STREAM r3, r4
        mov     r16, r3
sh_miss:
        sfetch  vid, m1, r16, r4
        ldb     bgx, r0, SM_HDR_BACKGROUND @m1
        ldb     bgy, r0, SM_HDR_BACKGROUND + 4 @m1
        ldb     bgz, r0, SM_HDR_BACKGROUND + 8 @m1
        GATHER3 th, F_THRR, F_THRG, F_THRB
        vfmul   thx, thx, bgx @m1
        vfmul   thy, thy, bgy @m1
        vfmul   thz, thz, bgz @m1
        FBADD3  th, vt, m1
        blt     r16, r4, sh_miss
sh_miss_done:
.endif
        ; ---- surfaces; the hit-light filter
        beq     r4, r20, sh_return
        SHADE_STREAM r4, r20
        mov     r3, r4
        jal     r31, surface            ; [r3, r20) -> emitters first, r5 = end of them
.if WORKLOAD == WL_SPECULAR
        mov     r12, r5
        mov     r13, r20
        jal     r31, forced_specular
        jmp     sh_return
.elif WORKLOAD == WL_DIFFUSE
        mov     r12, r5
        mov     r13, r20
        jal     r31, one_bounce_diffuse
        jmp     sh_return
.elif WORKLOAD == WL_PHONG
        mov     r12, r5
        mov     r13, r20
        jal     r31, phong
        jmp     sh_return
.else
        ; ---- one filter per material kind on [r5, r20)
.ifdef HAS_LAMBERT
        FILTER_EQ r5, r20, r6, F_MATKIND, MAT_LAMBERT
        mov     r12, r5
        mov     r13, r6
        li      r14, MAT_LAMBERT
        jal     r31, diffuse
        mov     r5, r6
.endif
.ifdef HAS_GLOSSY
        FILTER_EQ r5, r20, r6, F_MATKIND, MAT_GLOSSY
        mov     r12, r5
        mov     r13, r6
        li      r14, MAT_GLOSSY
        jal     r31, diffuse
        mov     r5, r6
.endif
.ifdef HAS_DIELECTRIC
        FILTER_EQ r5, r20, r6, F_MATKIND, MAT_DIELECTRIC
        mov     r12, r5
        mov     r13, r6
        jal     r31, dielectric
        mov     r5, r6
.endif
.endif
sh_return:
shade_done:
        spld    r30, r0, L_LINK
        jr      r30

; ---- surface filter on [r3, r20): hit point, normals, material, base colour into the ray's
; dead set-up fields; emitters seen from their emitting side go first ([r3, r5)) and add their
; emission for camera rays and after delta bounces. Clobbers r1, r2, r4, r7-r16.
surface:
        FRAME_SURFACE
        ld      r7, r0, SM_HDR_PRIMS
        ld      r8, r0, SM_HDR_MATS
        ld      r9, r0, SM_HDR_NORMALS
        ld      r10, r0, SM_HDR_TEXS
        ld      r11, r0, SM_HDR_UVS
        ld      r12, r0, SM_HDR_SRGB_LUT
        mov     r16, r3
surf_chunk:
        sfetch  vid, m1, r16, r20
        rgat    pa, vid, r0, F_PRIM @m1
        vmuli   pa, pa, SM_PRIM_BYTES @m1
        vbcast  vt, r7 @m1
        vadd    pa, pa, vt @m1
        ldg     ax, pa, SM_PRIM_V0 @m1
        ldg     ay, pa, SM_PRIM_V0 + 4 @m1
        ldg     az, pa, SM_PRIM_V0 + 8 @m1
        ldg     ex, pa, SM_PRIM_V1 @m1
        ldg     ey, pa, SM_PRIM_V1 + 4 @m1
        ldg     ez, pa, SM_PRIM_V1 + 8 @m1
        ldg     fx, pa, SM_PRIM_V2 @m1
        ldg     fy, pa, SM_PRIM_V2 + 4 @m1
        ldg     fz, pa, SM_PRIM_V2 + 8 @m1
        ; triangles: the hit point interpolated from the vertices, w0 v0 + u v1 + v v2 (spheres
        ; overwrite it below with o + t d)
        rgat    bu, vid, r0, F_U @m1
        rgat    bv, vid, r0, F_V @m1
        vli     w0, 1.0 @m1
        vfsub   w0, w0, bu @m1
        vfsub   w0, w0, bv @m1
.macro  BARYP a, e, f, fld
        vfmul   vt, w0, \a @m1
        vfmul   vt2, bu, \e @m1
        vfadd   vt, vt, vt2 @m1
        vfmul   vt2, bv, \f @m1
        vfadd   vt, vt, vt2 @m1
        rsct    vt, vid, r0, \fld @m1
.endm
        BARYP   ax, ex, fx, F_PX
        BARYP   ay, ey, fy, F_PY
        BARYP   az, ez, fz, F_PZ
        vfsub   ex, ex, ax @m1          ; e1 = v1 - v0
        vfsub   ey, ey, ay @m1
        vfsub   ez, ez, az @m1
        vfsub   fx, fx, ax @m1          ; e2 = v2 - v0
        vfsub   fy, fy, ay @m1
        vfsub   fz, fz, az @m1
        CROSS3  g, e, f, vt             ; geometric normal (winding)
        NORMALIZE3 g, vt, vt2
        rsct    gx, vid, r0, F_NGX @m1
        rsct    gy, vid, r0, F_NGY @m1
        rsct    gz, vid, r0, F_NGZ @m1
        GATHER3 e, F_DIRX, F_DIRY, F_DIRZ
.ifdef HAS_SPHERES
        ; spheres: the hit point o + t d, the outward normal p - center (m5: sphere lanes, kept
        ; for the blocks below)
        ldg     vt, pa, SM_PRIM_KIND @m1
        vli     vt2, 0 @m1
        vieq    m5, vt, vt2 @m1
        mandn   m5, m1, m5
        bmz     m5, surf_nosphere
        GATHER3 a, F_ORGX, F_ORGY, F_ORGZ, m5
        rgat    vt2, vid, r0, F_TMAX @m5
.macro  HITP a, e, f
        vfmul   vt, vt2, \e @m5
        vfadd   vt, \a, vt @m5
        rsct    vt, vid, r0, \f @m5
.endm
        HITP    ax, ex, F_PX
        HITP    ay, ey, F_PY
        HITP    az, ez, F_PZ
.macro  SPHN g, f, off
        rgat    \g, vid, r0, \f @m5
        ldg     vt, pa, SM_PRIM_V0 + \off @m5
        vfsub   \g, \g, vt @m5
.endm
        SPHN    gx, F_PX, 0
        SPHN    gy, F_PY, 4
        SPHN    gz, F_PZ, 8
        NORMALIZE3 g, vt, vt2, m5
        rsct    gx, vid, r0, F_NGX @m5
        rsct    gy, vid, r0, F_NGY @m5
        rsct    gz, vid, r0, F_NGZ @m5
surf_nosphere:
.endif
        DOT3    dn, g, e, vt            ; ng . d
        vmov    nfx, gx @m1
        vmov    nfy, gy @m1
        vmov    nfz, gz @m1
        vflt    m2, vz, dn @m1          ; facing away: flip
        vfneg   nfx, nfx @m2
        vfneg   nfy, nfy @m2
        vfneg   nfz, nfz @m2
        vmov    nsx, nfx @m1
        vmov    nsy, nfy @m1
        vmov    nsz, nfz @m1
.ifdef HAS_NORMALS
        ; interpolated vertex normals: w0 n0 + u n1 + v n2, normalized, on nf's side
        mmov    m6, m1
.ifdef HAS_SPHERES
        mandn   m6, m1, m5              ; (not on spheres)
.endif
        ldg     vt, pa, SM_PRIM_SRC @m6
        vmuli   vt, vt, 36 @m6
        vbcast  vt2, r9 @m6
        vadd    vt, vt, vt2 @m6         ; address of the three normals
.macro  NINTERP d, off
        BARY    \d, vt, \off, 12, w0, bu, bv, vt2, m6
.endm
        NINTERP ax, 0
        NINTERP ay, 4
        NINTERP az, 8
        NORMALIZE3 a, vt, vt2, m6
        vfmul   vt, ax, vz @m6          ; finite?
        vfmul   vt2, ay, vz @m6
        vfadd   vt, vt, vt2 @m6
        vfmul   vt2, az, vz @m6
        vfadd   vt, vt, vt2 @m6
        vfeq    m3, vt, vz @m6
        DOT3    vt, a, nf, vt2, m3
        vflt    m4, vt, vz @m3          ; on the other side: flip
        vfneg   ax, ax @m4
        vfneg   ay, ay @m4
        vfneg   az, az @m4
        vmov    nsx, ax @m3
        vmov    nsy, ay @m3
        vmov    nsz, az @m3
.endif
        rsct    nsx, vid, r0, F_NSX @m1
        rsct    nsy, vid, r0, F_NSY @m1
        rsct    nsz, vid, r0, F_NSZ @m1
        ; material
        ldg     mat, pa, SM_PRIM_MAT @m1
        vmuli   mat, mat, SM_MAT_BYTES @m1
        vbcast  vt, r8 @m1
        vadd    mat, mat, vt @m1
        ldg     ex, mat, SM_MAT_BASE @m1
        ldg     ey, mat, SM_MAT_BASE + 4 @m1
        ldg     ez, mat, SM_MAT_BASE + 8 @m1
.ifdef HAS_TEXTURES
        ; base colour texture: nearest texel, repeat wrapping, sRGB decoded through the table
        ldg     vt, mat, SM_MAT_TEX @m1
        vilt    m3, vt, vz @m1
        mandn   m3, m1, m3              ; textured (index >= 0)
.ifdef HAS_SPHERES
        mandn   m3, m3, m5              ; (spheres have no texture coordinates)
.endif
        bmz     m3, surf_notex
        vshli   vt, vt, 4 @m3           ; SM_TEX_BYTES = 16
        vbcast  vt2, r10 @m3
        vadd    vt, vt, vt2 @m3         ; texture record
        ldg     fx, pa, SM_PRIM_SRC @m3
        vmuli   fx, fx, 24 @m3
        vbcast  vt2, r11 @m3
        vadd    fx, fx, vt2 @m3         ; the three uv pairs
.macro  UVINTERP d, off
        BARY    \d, fx, \off, 8, w0, bu, bv, vt2, m3
.endm
        UVINTERP fy, 0                  ; tu
        UVINTERP fz, 4                  ; tv
.macro  TEXCOORD d, t, size
        TEXIDX  \d, \t, \size, vt2, m3, m4
.endm
        ldg     gx, vt, SM_TEX_WIDTH @m3
        ldg     gy, vt, SM_TEX_HEIGHT @m3
        TEXCOORD gz, fy, gx             ; ix
        TEXCOORD fy, fz, gy             ; iy
        vmul    fy, fy, gx @m3
        vadd    fy, fy, gz @m3
        vshli   fy, fy, 2 @m3
        ldg     vt, vt, SM_TEX_TEXELS @m3
        vadd    fy, fy, vt @m3
        ldg     fy, fy, 0 @m3           ; RGBA8 texel
        vbcast  vt2, r12 @m3
.macro  TEXMUL b, shift
        vshri   vt, fy, \shift @m3
        vandi   vt, vt, 255 @m3
        vshli   vt, vt, 2 @m3
        vadd    vt, vt, vt2 @m3
        ldg     vt, vt, 0 @m3
        vfmul   \b, \b, vt @m3
.endm
        TEXMUL  ex, 0
        TEXMUL  ey, 8
        TEXMUL  ez, 16
surf_notex:
.endif
.ifdef HAS_COLORS
        ; vertex colours (COLOR_0): base x (w0 c0 + u c1 + v c2), on triangles
        mmov    m3, m1
.ifdef HAS_SPHERES
        mandn   m3, m1, m5
.endif
        ldg     fx, pa, SM_PRIM_SRC @m3
        vmuli   fx, fx, 36 @m3
        ldb     vt, r0, SM_HDR_COLORS @m3
        vadd    fx, fx, vt @m3          ; the three colours
        BARY    fy, fx, 0, 12, w0, bu, bv, vt2, m3
        vfmul   ex, ex, fy @m3
        BARY    fy, fx, 4, 12, w0, bu, bv, vt2, m3
        vfmul   ey, ey, fy @m3
        BARY    fy, fx, 8, 12, w0, bu, bv, vt2, m3
        vfmul   ez, ez, fy @m3
.endif
        rsct    ex, vid, r0, F_BASER @m1
        rsct    ey, vid, r0, F_BASEG @m1
        rsct    ez, vid, r0, F_BASEB @m1
        ldg     vt, mat, SM_MAT_KIND @m1
        rsct    mat, vid, r0, F_MAT @m1
        rsct    vt, vid, r0, F_MATKIND @m1
        ; hit-light filter: emission > 0 seen from the front (or double-sided)
        ldg     ax, mat, SM_MAT_EMISSION @m1
        ldg     ay, mat, SM_MAT_EMISSION + 4 @m1
        ldg     az, mat, SM_MAT_EMISSION + 8 @m1
        vfadd   vt, ax, ay @m1
        vfadd   vt, vt, az @m1
        vflt    m2, vz, vt @m1          ; emits
        vflt    m3, dn, vz @m1          ; seen from the front
        ldg     vt, mat, SM_MAT_DOUBLE_SIDED @m1
        vli     vt2, 0 @m1
        vieq    m4, vt, vt2 @m1
        mandn   m4, m1, m4
        mor     m3, m3, m4
        mand    m2, m2, m3
.if WORKLOAD == WL_SPECULAR || WORKLOAD == WL_DIFFUSE
        mclr    m2                      ; (these utilization workloads treat emitters as surfaces)
.endif
.ifdef HAS_EMISSIVE_TEX
        ; emitters with an emissive texture (MATX EMIT_TEX >= 0; m3): the texel at the hit's
        ; emissive coordinates scales the emission (triangles: spheres have none), and they stay
        ; in the stream to be shaded as well; only the others end their paths here
        ldb     vt, r0, SM_HDR_MATS @m2
        vsub    vt, mat, vt @m2
        vshri   vt, vt, 2 @m2           ; SM_MAT_BYTES / SM_MATX_BYTES = 4
        ldb     vt2, r0, SM_HDR_MATX @m2
        vadd    vt, vt, vt2 @m2
        ldg     gx, vt, SM_MATX_EMIT_TEX @m2
        vilt    m3, gx, vz @m2
        mandn   m3, m2, m3
        mmov    m4, m3
.ifdef HAS_SPHERES
        mandn   m4, m3, m5
.endif
        bmz     m4, surf_noemtex
        ldg     fx, pa, SM_PRIM_SRC @m4
        vmuli   fx, fx, 24 @m4
        ldb     vt, r0, SM_HDR_EMIT_UVS @m4
        vadd    fx, fx, vt @m4          ; the three emissive uv pairs
        BARY    fy, fx, 0, 8, w0, bu, bv, vt2, m4
        BARY    fz, fx, 4, 8, w0, bu, bv, vt2, m4
        TEXEL3  e, gx, fy, fz, fx, vt, vt2, m4, m6
        vfmul   ax, ax, ex @m4
        vfmul   ay, ay, ey @m4
        vfmul   az, az, ez @m4
surf_noemtex:
        mandn   m4, m2, m3
        pmask   m4
.else
        pmask   m2
.endif
        ; emission counts for camera rays and after delta bounces
        beq     r18, r0, surf_add
        rgat    vt, vid, r0, F_SPEC @m2
        vli     vt2, 0 @m2
        vieq    m3, vt, vt2 @m2
        mandn   m2, m2, m3
surf_add:
        GATHER3 e, F_THRR, F_THRG, F_THRB, m2
        vfmul   ex, ex, ax @m2
        vfmul   ey, ey, ay @m2
        vfmul   ez, ez, az @m2
        FBADD3  e, vt, m2
        blt     r16, r20, surf_chunk
        part    r5, r3, r20
        jr      r31

.if WORKLOAD == WL_PATH
; ---- Lambertian and coupled glossy shaders on [r12, r13), kind r14 (scalar: the filter above
; made the stream one kind). Direct/indirect split by a filter, then one pass for each part.
; Preserves r5, r6, r17-r30.
diffuse:
        beq     r12, r13, diff_done
        SHADE_STREAM r12, r13
        addi    r7, r18, 1              ; vertex = depth + 1
        shli    r8, r7, 4               ; 16 * vertex
        slt     r9, r29, r7             ; can_bounce = depth + 1 <= max_depth
        xori    r9, r9, 1
        ld      r10, r0, SM_HDR_NLIGHTS
        li      r11, 0.5                ; p_direct
        bne     r9, r0, diff_pd1
        li      r11, 1.0
diff_pd1:
.ifdef HAS_AMBIENT
        li      r1, MAT_LAMBERT
        bne     r14, r1, diff_pd2
        li      r11, 1.0
diff_pd2:
.endif
        bne     r10, r0, diff_pd3
        li      r11, 0.0
diff_pd3:
        FRAME_SPLIT
        ; ---- split: direct (u < p_direct) first
        mov     r16, r12
diff_split:
        sfetch  vid, m1, r16, r13
        rgat    kb, vid, r0, F_KEY @m1
        vbcast  st, r8 @m1
        vadd    kb, kb, st @m1
        RAND    u0, kb, DIM_DIRECT, st
        vbcast  vpd, r11 @m1
        vflt    m2, u0, vpd @m1
        pmask   m2
.ifdef HAS_AMBIENT
        li      r1, MAT_LAMBERT
        bne     r14, r1, diff_noamb
        AMBIENT_ADD th, b, st
diff_noamb:
.endif
        blt     r16, r13, diff_split
        part    r15, r12, r13           ; [r12, r15) direct, [r15, r13) indirect
        beq     r12, r15, diff_indirect
        SHADE_STREAM r12, r15
        jal     r30, direct
diff_indirect:
        beq     r9, r0, diff_done       ; cannot bounce
        beq     r15, r13, diff_done
        SHADE_STREAM r15, r13
        jal     r30, indirect
diff_done:
        jr      r31

; ---- direct lighting on [r12, r15): one shadow ray per path toward a uniformly chosen light.
; Scalars: r8 = 16 * vertex, r10 = number of lights, r11 = p_direct (float), r14 = kind.
; Clobbers r1-r4, r7, r16.
direct:
        FRAME_LIGHT
        ld      r1, r0, SM_HDR_LIGHTS
        cvtif   r2, r10                 ; (float) nlights
        fdiv    r3, r2, r11             ; weight nlights / p_direct
        addi    r4, r10, -1
        mov     r16, r12
dir_chunk:
        sfetch  vid, m1, r16, r15
        rgat    kb, vid, r0, F_KEY @m1
        vbcast  vt, r8 @m1
        vadd    kb, kb, vt @m1
        ; light index l = (int)(u * nlights), at most nlights - 1
        RAND    la, kb, DIM_LIGHT, vt
        vbcast  vt, r2 @m1
        vfmul   la, la, vt @m1
        vcvtfi  la, la @m1
        vbcast  vt, r10 @m1
        viltu   m2, la, vt @m1
        mandn   m2, m1, m2
        vbcast  la, r4 @m2
        vmuli   la, la, SM_LIGHT_BYTES @m1
        vbcast  vt, r1 @m1
        vadd    la, la, vt @m1
        ; origin: the hit point moved off the surface on the incoming side
        GATHER3 p, F_PX, F_PY, F_PZ
        FACING_NORMAL nf, o, vt, vt2, m2
        OFFSET3 o, p, nf, vt, vt2, vz, m2
        ; point on the light: P + c1 E1 + c2 E2 (quad: c = (u, v); triangle: sqrt(u) (1 - v), sqrt(u) v)
        RAND    lu, kb, DIM_LIGHT_U, vt
        RAND    lv, kb, DIM_LIGHT_V, vt
        LIGHT_SAMPLE
        ; brdf x cos into px, py, pz
        GATHER3 p, F_BASER, F_BASEG, F_BASEB, m2
.ifdef HAS_GLOSSY
        li      r7, MAT_GLOSSY
        beq     r14, r7, dir_glossy
.endif
        vli     vt, INV_PI_F @m2
        vfmul   px, px, vt @m2
        vfmul   px, px, vt3 @m2
        vfmul   py, py, vt @m2
        vfmul   py, py, vt3 @m2
        vfmul   pz, pz, vt @m2
        vfmul   pz, pz, vt3 @m2
.ifdef HAS_GLOSSY
        jmp     dir_emit
dir_glossy:
        ; coupled glossy: (kd / pi + ks (n + 2) / (2 pi) cos^n(refl . wi)) cos
        ; (wi in v12-14, ns in v21-23 (e2), base in p, cosi vt3; free: v15-17 (shadow dir: keep),
        ;  v5-7 (nf), v24-26, v27, v28)
        GATHER3 nf, F_DIRX, F_DIRY, F_DIRZ, m2
        REFLECT3 nf, nf, e2, nlx, vt, m2 ; mirror direction
        DOT3    nly, nf, wi, vt, m2     ; cos alpha
        rgat    nlz, vid, r0, F_MAT @m2
        ldg     vt2, nlz, SM_MAT_ROUGHNESS @m2
        ldg     nlz, nlz, SM_MAT_METALLIC @m2
        GLOSSY_EXP vt2, vt, m2          ; exponent n (vt = 2)
        POW_LOBE nly, nly, vt2, nlx, m3, m2 ; cos^n (0 unless cos > 0)
        vfadd   nlx, vt2, vt @m2        ; n + 2
        vli     vt, INV_2PI_F @m2
        vfmul   nlx, nlx, vt @m2
        vfmul   nlx, nlx, nly @m2       ; lobe
        vli     vt, 1.0 @m2
        vfsub   nly, vt, nlz @m2        ; 1 - metallic
.macro  GLOSSYF b
        vfmul   vt, \b, nly @m2         ; kd
        vli     vt2, INV_PI_F @m2
        vfmul   vt, vt, vt2 @m2
        vli     vt2, 0.04 @m2
        vfmul   vt2, vt2, nly @m2
        vfmul   nfx, \b, nlz @m2
        vfadd   vt2, vt2, nfx @m2       ; ks
        vfmul   vt2, vt2, nlx @m2
        vfadd   vt, vt, vt2 @m2
        vfmul   \b, vt, vt3 @m2
.endm
        GLOSSYF px
        GLOSSYF py
        GLOSSYF pz
dir_emit:
.endif
        ; throughput x f x le x nlights / p_direct
        vbcast  vt2, r3 @m2
.macro  DIRTHR f, le, thr
        rgat    vt, vid, r0, \thr @m2
        vfmul   vt, vt, \f @m2
        vfmul   vt, vt, \le @m2
        vfmul   \f, vt, vt2 @m2
.endm
        DIRTHR  px, e1x, F_THRR
        DIRTHR  py, e1y, F_THRG
        DIRTHR  pz, e1z, F_THRB
        EMIT    m2, o, lp, p, SHADOW_TMAX, KIND_SHADOW, 0, vt, vt2
        blt     r16, r15, dir_chunk
        jr      r30

; Russian roulette on new rays of depth >= RR_START_DEPTH (scalar r7 = new depth): survive with
; q = min(max(thr), 0.95), thr / q. Mask k keeps the survivors; kb = key + 16 vertex.
; u, q, t scratch.
.macro  ROULETTE k, th, u, q, t
        li      r1, RR_START_DEPTH
        blt     r7, r1, rr\@
        vfmax   \q, \th\()x, \th\()y @\k
        vfmax   \q, \q, \th\()z @\k
        vli     \u, RR_MAX_SURVIVAL @\k
        vfmin   \q, \q, \u @\k
        RAND    \u, kb, DIM_RR, \t, \k
        vflt    \k, \u, \q @\k
        vfdiv   \th\()x, \th\()x, \q @\k
        vfdiv   \th\()y, \th\()y, \q @\k
        vfdiv   \th\()z, \th\()z, \q @\k
rr\@:
.endm

; ---- indirect bounce on [r15, r13): cosine-weighted (Lambert) or lobe-sampled (glossy).
; Scalars: r8 = 16 * vertex, r11 = p_direct, r14 = kind. Clobbers r1-r4, r7, r16.
indirect:
        FRAME_BOUNCE
        addi    r7, r18, 1              ; depth of the new rays
        li      r1, 1.0
        fsub    r2, r1, r11
        fdiv    r2, r1, r2              ; weight 1 / (1 - p_direct)
        mov     r16, r15
ind_chunk:
        sfetch  vid, m1, r16, r13
        mmov    m2, m1
        rgat    kb, vid, r0, F_KEY @m1
        vbcast  vt, r8 @m1
        vadd    kb, kb, vt @m1
        RAND    u5, kb, DIM_DIR_U, vt
        RAND    phi, kb, DIM_DIR_V, vt
        vli     vt, TWO_PI_F @m1
        vfmul   phi, vt, phi @m1
        GATHER3 ns, F_NSX, F_NSY, F_NSZ
        GATHER3 th, F_THRR, F_THRG, F_THRB
        GATHER3 b, F_BASER, F_BASEG, F_BASEB
.ifdef HAS_GLOSSY
        li      r3, MAT_GLOSSY
        beq     r14, r3, ind_glossy
.endif
        ; Lambert: cosine-weighted hemisphere around ns; thr x base x weight
        COSINE_DIR d, ns, u5, phi, c, vt, vt2, vt3, vt4, vt5
        vbcast  vt, r2 @m1
        vfmul   thx, thx, bx @m1
        vfmul   thx, thx, vt @m1
        vfmul   thy, thy, by @m1
        vfmul   thy, thy, vt @m1
        vfmul   thz, thz, bz @m1
        vfmul   thz, thz, vt @m1
.ifdef HAS_GLOSSY
        jmp     ind_spawn
ind_glossy:
        ; kd = base (1 - metallic), ks = 0.04 (1 - metallic) + base metallic, n, ps
        rgat    vt, vid, r0, F_MAT @m1
        ldg     vt2, vt, SM_MAT_ROUGHNESS @m1
        ldg     vt, vt, SM_MAT_METALLIC @m1
        GLOSSY_EXP vt2, vt3             ; n
        vli     vt3, 1.0 @m1
        vfsub   vt3, vt3, vt @m1        ; 1 - metallic
.macro  KDKS b, kd, t
        vli     \t, 0.04 @m1
        vfmul   \t, \t, vt3 @m1
        vfmul   \kd, \b, vt @m1
        vfadd   \t, \t, \kd @m1         ; ks (into t)
        vfmul   \kd, \b, vt3 @m1        ; kd
.endm
        KDKS    bx, cx, vt4
        vmov    bx, vt4 @m1             ; b := ks, c := kd
        KDKS    by, cy, vt4
        vmov    by, vt4 @m1
        KDKS    bz, cz, vt4
        vmov    bz, vt4 @m1
        vfadd   vt4, bx, by @m1
        vfadd   vt4, vt4, bz @m1        ; ls
        vfadd   vt5, cx, cy @m1
        vfadd   vt5, vt5, cz @m1        ; ld
        vfadd   vt5, vt4, vt5 @m1
        vfdiv   vt4, vt4, vt5 @m1       ; ps = ls / (ls + ld)
        RAND    vt5, kb, DIM_LOBE, vt
        vflt    m3, vt5, vt4 @m1        ; specular lobe
        mandn   m4, m1, m3              ; diffuse lobe
        ; throughput: diffuse lanes thr kd (weight / (1 - ps)); specular lanes thr ks (x lobe below)
        vbcast  vt, r2 @m4
        vli     vt5, 1.0 @m4
        vfsub   vt5, vt5, vt4 @m4
        vfdiv   vt5, vt, vt5 @m4
        vmov    dx, bx @m3
        vmov    dy, by @m3
        vmov    dz, bz @m3
        vmov    dx, cx @m4
        vmov    dy, cy @m4
        vmov    dz, cz @m4
        vfmul   thx, thx, dx @m1
        vfmul   thy, thy, dy @m1
        vfmul   thz, thz, dz @m1
        vfmul   thx, thx, vt5 @m4
        vfmul   thy, thy, vt5 @m4
        vfmul   thz, thz, vt5 @m4
        ; -- diffuse lanes: cosine-weighted around ns
        COSINE_DIR d, ns, u5, phi, c, vt, vt3, vt5, vt6, vt7, m4
        ; -- specular lanes: around the mirror direction, cos a = exp2(log2(u5) / (n + 1))
        GATHER3 b, F_DIRX, F_DIRY, F_DIRZ, m3
        REFLECT3 nf, b, ns, vt, vt3, m3 ; refl (in nf)
        vli     vt, 1.0 @m3
        vfadd   vt6, vt2, vt @m3        ; n + 1
        vlog2   cz, u5 @m3
        vfdiv   cz, cz, vt6 @m3
        vexp2   cz, cz @m3              ; cos a
        vfmul   vt3, cz, cz @m3
        vfsub   vt3, vt, vt3 @m3
        vfmax   vt3, vz, vt3 @m3
        vsqrt   vt3, vt3 @m3            ; sin a
        vcos    cx, phi @m3
        vfmul   cx, vt3, cx @m3
        vsin    cy, phi @m3
        vfmul   cy, vt3, cy @m3
        TO_WORLD d, nf, cx, cy, cz, vt, vt3, vt5, vt7, vt8, m3
        DOT3    vt, ns, d, vt3, m3      ; cos at the shading normal
        vflt    m5, vz, vt @m3
        mandn   m6, m3, m5
        mandn   m2, m2, m6              ; below the surface: absorbed
        mand    m3, m3, m5
        ; lobe = (n + 2) / (n + 1) x cos / ps x weight
        vli     vt3, 2.0 @m3
        vfadd   vt3, vt2, vt3 @m3
        vfdiv   vt3, vt3, vt6 @m3
        vfmul   vt3, vt3, vt @m3
        vfdiv   vt3, vt3, vt4 @m3
        vbcast  vt5, r2 @m3
        vfmul   vt3, vt3, vt5 @m3
        vfmul   thx, thx, vt3 @m3
        vfmul   thy, thy, vt3 @m3
        vfmul   thz, thz, vt3 @m3
ind_spawn:
.endif
        ; keep directions above the geometric surface
        FACING_NORMAL nf, b, vt, vt2, m3
        DOT3    vt, d, nf, vt2, m2
        vflt    m2, vz, vt @m2
        ROULETTE m2, th, vt, vt2, vt3
        GATHER3 b, F_PX, F_PY, F_PZ, m2
        OFFSET3 c, b, nf, vt, vt2, vz, m3, m2
        EMIT    m2, c, d, th, INF_BITS, KIND_INDIRECT, 0, vt, vt2
        blt     r16, r13, ind_chunk
        jr      r30

.ifdef HAS_DIELECTRIC
; ---- dielectric shader on [r12, r13): Fresnel-weighted choice of reflection or refraction.
; Preserves r5, r6, r17-r30.
dielectric:
        beq     r12, r13, diel_done
        SHADE_STREAM r12, r13
        addi    r7, r18, 1
        blt     r29, r7, diel_done      ; cannot bounce
        shli    r8, r7, 4
        FRAME_DIELECTRIC
        mov     r16, r12
diel_chunk:
        sfetch  vid, m1, r16, r13
        rgat    kb, vid, r0, F_KEY @m1
        vbcast  vt, r8 @m1
        vadd    kb, kb, vt @m1
        GATHER3 d, F_DIRX, F_DIRY, F_DIRZ
        GATHER3 ng, F_NGX, F_NGY, F_NGZ
        rgat    vt, vid, r0, F_MAT @m1
        ldg     eta, vt, SM_MAT_IOR @m1
        DOT3    cosi, d, ng, vt
        vflt    m2, cosi, vz @m1        ; entering
        mandn   m3, m1, m2
        vrcp    eta, eta @m2            ; eta = 1 / ior entering, ior leaving
        vmov    nnx, ngx @m1
        vmov    nny, ngy @m1
        vmov    nnz, ngz @m1
        vfneg   nnx, nnx @m3
        vfneg   nny, nny @m3
        vfneg   nnz, nnz @m3
        DOT3    cc, d, nn, vt
        vfneg   cc, cc @m1
        ; k2 = 1 - eta^2 (1 - cc^2); F = 1 (total internal reflection) unless k2 > 0
        vfmul   vt, eta, eta @m1
        vfmul   vt2, cc, cc @m1
        vli     vt3, 1.0 @m1
        vfsub   vt2, vt3, vt2 @m1
        vfmul   vt, vt, vt2 @m1
        vfsub   vt, vt3, vt @m1
        vli     fr, 1.0 @m1
        vli     ct, 0 @m1
        vflt    m2, vz, vt @m1
        vsqrt   ct, vt @m2
        vfmul   vt, eta, cc @m2
        vfsub   vt2, vt, ct @m2
        vfadd   vt, vt, ct @m2
        vfdiv   vt2, vt2, vt @m2        ; rs
        vfmul   vt, eta, ct @m2
        vfsub   vt3, vt, cc @m2
        vfadd   vt, vt, cc @m2
        vfdiv   vt3, vt3, vt @m2        ; rp
        vfmul   vt2, vt2, vt2 @m2
        vfmul   vt3, vt3, vt3 @m2
        vfadd   vt2, vt2, vt3 @m2
        vli     vt, 0.5 @m2
        vfmul   fr, vt, vt2 @m2
        GATHER3 th, F_THRR, F_THRG, F_THRB
        RAND    vt, kb, DIM_LOBE, vt2
        vflt    m2, vt, fr @m1          ; reflect
        mandn   m3, m1, m2              ; refract
        ; reflection: d - 2 (d . nn) nn
        REFLECT3 o, d, nn, vt, vt2, m2
        ; refraction: eta d + (eta cc - ct) nn, normalized; tinted by the base colour
        vfmul   vt, eta, cc @m3
        vfsub   vt, vt, ct @m3
.macro  REFR o, d, n, th, base
        vfmul   \o, eta, \d @m3
        vfmul   vt2, vt, \n @m3
        vfadd   \o, \o, vt2 @m3
        rgat    vt2, vid, r0, \base @m3
        vfmul   \th, \th, vt2 @m3
.endm
        REFR    ox, dx, nnx, thx, F_BASER
        REFR    oy, dy, nny, thy, F_BASEG
        REFR    oz, dz, nnz, thz, F_BASEB
        NORMALIZE3 o, vt, vt2, m3
        mmov    m2, m1
        ROULETTE m2, th, vt, vt2, vt3
        ; origin on the side the new ray leaves: sign of d' . nf
        vmov    nnx, ngx @m2
        vmov    nny, ngy @m2
        vmov    nnz, ngz @m2
        vflt    m3, vz, cosi @m2        ; nf = -ng when ng . d > 0
        vfneg   nnx, nnx @m3
        vfneg   nny, nny @m3
        vfneg   nnz, nnz @m3
        DOT3    vt, o, nn, vt2, m2
        vflt    m3, vt, vz @m2          ; d' . nf < 0: below
        vfneg   nnx, nnx @m3
        vfneg   nny, nny @m3
        vfneg   nnz, nnz @m3
        GATHER3 p, F_PX, F_PY, F_PZ, m2
        OFFSET3 d, p, nn, vt, vt2, vz, m3, m2
        EMIT    m2, d, o, th, INF_BITS, KIND_INDIRECT, 1, vt, vt2
        blt     r16, r13, diel_chunk
diel_done:
        jr      r31
.endif
.endif ; WORKLOAD == WL_PATH

.if WORKLOAD == WL_SPECULAR
; ---- forced specular workload (seed 000 Sec. 5.3) on [r12, r13): every hit is a mirror for
; BOUNCES bounces, whatever its material; a path's last hit adds throughput x base colour.
forced_specular:
        beq     r12, r13, fs_done
        SHADE_STREAM r12, r13
        addi    r7, r18, 1
        li      r1, BOUNCES
        slt     r9, r1, r7
        xori    r9, r9, 1               ; another bounce?
        FRAME_MIRROR
        mov     r16, r12
fs_chunk:
        sfetch  vid, m1, r16, r13
        GATHER3 mth, F_THRR, F_THRG, F_THRB
        bne     r9, r0, fs_bounce
        GATHER3 p, F_BASER, F_BASEG, F_BASEB
        vfmul   mthx, mthx, px @m1
        vfmul   mthy, mthy, py @m1
        vfmul   mthz, mthz, pz @m1
        FBADD3  mth, vt, m1
        jmp     fs_next
fs_bounce:
        MIRROR_EMIT mth
fs_next:
        blt     r16, r13, fs_chunk
fs_done:
        jr      r31
.endif

.if WORKLOAD == WL_DIFFUSE
; ---- one-bounce diffuse workload (seed 000 Sec. 5.4) on [r12, r13): camera-ray hits send one
; cosine-weighted ray around the shading normal (throughput x base colour); its hit adds
; throughput x base colour.
one_bounce_diffuse:
        beq     r12, r13, od_done
        SHADE_STREAM r12, r13
        addi    r7, r18, 1
        shli    r8, r7, 4
        FRAME_BOUNCE
        mov     r16, r12
od_chunk:
        sfetch  vid, m1, r16, r13
        GATHER3 th, F_THRR, F_THRG, F_THRB
        GATHER3 b, F_BASER, F_BASEG, F_BASEB
        vfmul   thx, thx, bx @m1
        vfmul   thy, thy, by @m1
        vfmul   thz, thz, bz @m1
        beq     r18, r0, od_bounce
        FBADD3  th, vt, m1
        jmp     od_next
od_bounce:
        rgat    kb, vid, r0, F_KEY @m1
        vbcast  vt, r8 @m1
        vadd    kb, kb, vt @m1
        RAND    u5, kb, DIM_DIR_U, vt
        RAND    phi, kb, DIM_DIR_V, vt
        vli     vt, TWO_PI_F @m1
        vfmul   phi, vt, phi @m1
        GATHER3 ns, F_NSX, F_NSY, F_NSZ
        COSINE_DIR d, ns, u5, phi, c, vt, vt2, vt3, vt4, vt5
        FACING_NORMAL nf, b, vt, vt2, m2
        DOT3    vt, d, nf, vt2
        vflt    m2, vz, vt @m1          ; above the geometric surface
        GATHER3 b, F_PX, F_PY, F_PZ, m2
        OFFSET3 c, b, nf, vt, vt2, vz, m3, m2
        EMIT    m2, c, d, th, INF_BITS, KIND_INDIRECT, 0, vt, vt2
od_next:
        blt     r16, r13, od_chunk
od_done:
        jr      r31
.endif

.if WORKLOAD == WL_PHONG
; ---- Phong workload on the hits [r12, r13) (seed 004 Sec. 4: "for each light ... a shadow ray
; for each hit ... local Phong shading for the hits not in shadow"; specular bounces "Phong shaded
; and accumulated, with weights"). Emitters were handled by the hit-light filter. Each hit adds
; the ambient term; then one pass per light: each hit's shadow ray toward the light (a quad's
; centre, a triangle's centroid, a punctual light) carries thr x (base cos + ks cos_r^shininess)
; x le, and the pass's shadow stream is traced and added at once -- so every pixel receives its
; lights in light order, as in the golden model (sim/reference.c, shade_phong). The shadow rays
; live beside the hits, in the upper half of the current ray buffer and stream region (the host
; gives phong tiles of at most RAYS / 2 pixels), which keeps the next buffer dead during their
; traversal, as the kd-tree traversals need. Last, in generations below BOUNCES, each hit's
; mirror ray about the facing normal, throughput thr x ks. docs/kernel.md, "Variants".
PHONG_EXP_MIN = 1.0             ; lowest shininess: no cos^0 step at the highlight's edge
PHONG_TRI_U = 4.0 / 9.0         ; a triangle's centroid: sqrt(u) (1 - v) = sqrt(u) v = 1/3
PH_SLOT0 = RAYS / 2             ; the shadow rays' first slot in the current buffer
PH_IDS = FIELD_BYTES / 2        ; their stream: the upper half of the current stream region
PH_LINK = L_SAVE                ; phong's return address (trace calls through r31)
PH_BEGIN = L_SAVE + 4           ; the hits [r12, r13)
PH_END = L_SAVE + 8
PH_LIGHT = L_SAVE + 12          ; the light of the running pass
PH_R19 = L_SAVE + 16            ; the generation's stream, while a shadow stream has r19, r20
PH_R20 = L_SAVE + 20

; ks := 0.04 + 0.96 metallic of the hits' materials (lanes k); t scratch.
.macro  PHONG_KS ks, t, k=m1
        rgat    \ks, vid, r0, F_MAT @\k
        ldg     \ks, \ks, SM_MAT_METALLIC @\k
        vli     \t, 0.96 @\k
        vfmul   \ks, \ks, \t @\k
        vli     \t, 0.04 @\k
        vfadd   \ks, \t, \ks @\k
.endm

; one channel of a shadow ray's radiance: thr x (base cos + ks lobe) x le (b: base, in place)
.macro  PHONG_RAD b, le, thr
        vfmul   \b, \b, vt3 @m2
        vfadd   \b, \b, nly @m2
        rgat    vt, vid, r0, \thr @m2
        vfmul   vt, vt, \b @m2
        vfmul   \b, vt, \le @m2
.endm

phong:
        beq     r12, r13, ph_return
        spst    r31, r0, PH_LINK
        spst    r12, r0, PH_BEGIN
        spst    r13, r0, PH_END
        SHADE_STREAM r12, r13
        FRAME_LIGHT
        mov     r16, r12
ph_ambient:
        sfetch  vid, m1, r16, r13
        AMBIENT_ADD p, nf, vt
        blt     r16, r13, ph_ambient
        spst    r0, r0, PH_LIGHT
ph_light:
        spld    r1, r0, PH_LIGHT
        ld      r2, r0, SM_HDR_NLIGHTS
        bge     r1, r2, ph_bounce
        muli    r11, r1, SM_LIGHT_BYTES
        ld      r2, r0, SM_HDR_LIGHTS
        add     r11, r11, r2            ; the light's record
        ld      r2, r11, SM_LIGHT_KIND
        li      r9, 0.5                 ; (u, v) = (1/2, 1/2): a quad's centre
        li      r3, LIGHT_TRIANGLE
        bne     r2, r3, ph_centre
        li      r9, PHONG_TRI_U
ph_centre:
        spld    r12, r0, PH_BEGIN
        spld    r13, r0, PH_END
        SHADE_STREAM r12, r13
        li      r23, PH_SLOT0
        addi    r22, r19, PH_IDS
        mov     r16, r12
ph_chunk:
        sfetch  vid, m1, r16, r13
        vbcast  la, r11 @m1
        ; origin: the hit point moved off the surface on the incoming side
        GATHER3 p, F_PX, F_PY, F_PZ
        FACING_NORMAL nf, o, vt, vt2, m2
        OFFSET3 o, p, nf, vt, vt2, vz, m2
        vbcast  lu, r9 @m1
        vli     lv, 0.5 @m1
        LIGHT_SAMPLE
        ; highlight: ks max(0, refl . wi)^shininess, refl = the ray's direction mirrored about
        ; ns, shininess = max(2 / max(roughness^2, 0.001) - 2, PHONG_EXP_MIN)
        rgat    vt2, vid, r0, F_MAT @m2
        ldg     vt2, vt2, SM_MAT_ROUGHNESS @m2
        GLOSSY_EXP vt2, vt, m2
        vli     vt, PHONG_EXP_MIN @m2
        vfmax   vt2, vt2, vt @m2
        GATHER3 nf, F_DIRX, F_DIRY, F_DIRZ, m2
        REFLECT3 nf, nf, e2, nlx, vt, m2
        DOT3    nly, nf, wi, vt, m2
        POW_LOBE nly, nly, vt2, nlx, m3, m2
        PHONG_KS nlz, vt, m2
        vfmul   nly, nlz, nly @m2       ; ks x lobe
        GATHER3 p, F_BASER, F_BASEG, F_BASEB, m2
        PHONG_RAD px, e1x, F_THRR
        PHONG_RAD py, e1y, F_THRG
        PHONG_RAD pz, e1z, F_THRB
        EMIT    m2, o, lp, p, SHADOW_TMAX, KIND_SHADOW, 0, vt, vt2, rsct
        blt     r16, r13, ph_chunk
        ; the pass's shadow stream [r19 + PH_IDS, r22): set-up, traversal, shadow filter
        spst    r19, r0, PH_R19
        spst    r20, r0, PH_R20
        addi    r19, r19, PH_IDS
        mov     r20, r22
        beq     r19, r20, ph_next
        stage   STAGE_OTHER
        jal     r30, setup
        sub     r4, r20, r19
        shri    r4, r4, 2               ; rays traced: shadow rays of this generation
        spld    r3, r0, ST_SHADOW
        add     r3, r3, r4
        spst    r3, r0, ST_SHADOW
        shli    r2, r18, 2
        spld    r3, r2, ST_PER_GEN
        add     r3, r3, r4
        spst    r3, r2, ST_PER_GEN
        beq     r19, r20, ph_traced     ; everything dropped
        jal     r30, trace
        stage   STAGE_SHADING
        SHADE_STREAM r19, r20
        SHADOW_ADD r19, r20, kb, p, vt
ph_traced:
        stage   STAGE_SHADING
ph_next:
        spld    r19, r0, PH_R19
        spld    r20, r0, PH_R20
        spld    r1, r0, PH_LIGHT
        addi    r1, r1, 1
        spst    r1, r0, PH_LIGHT
        jmp     ph_light
ph_bounce:
        mov     r22, r21                ; (the next generation is still empty)
        li      r23, 0
        li      r1, BOUNCES
        bge     r18, r1, ph_done
        spld    r12, r0, PH_BEGIN
        spld    r13, r0, PH_END
        SHADE_STREAM r12, r13
        FRAME_PHONG_MIRROR
        mov     r16, r12
ph_mirror:
        sfetch  vid, m1, r16, r13
        GATHER3 th, F_THRR, F_THRG, F_THRB
        PHONG_KS vt, vt2
        SCALE3  th, vt
        MIRROR_EMIT th
        blt     r16, r13, ph_mirror
ph_done:
        spld    r31, r0, PH_LINK
ph_return:
        jr      r31
.endif
