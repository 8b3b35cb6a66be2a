; tests/unit/kd_stub.s -- stands in for the kd-tree kernel in the host-side tests
; (test_functional.c, test_render.c), with counts known in advance: it checks the
; -D symbols the host passes with accel.structure = kd, then adds (v + 1) * (l + 1) to lane l of
; kd counter vector v = kind * KC_COUNTERS + counter, for all KC_LANES lanes (the host must sum
; only lanes 0..N-1, and must have cleared them: the counters are added to, not stored), and
; counts 2 camera rays and 3 indirect rays per run.
.include "../../kernels/lib/abi.inc"
.include "../../kernels/lib/kconst.inc"          ; KD_STACK .. KD_STREAM, which the host checks

.ifndef ACCEL_KD
        .error "built without ACCEL_KD"
.endif
.if !defined(KD_VARIANT) || !defined(KD_STACK_DEPTH)
        .error "built without KD_VARIANT or KD_STACK_DEPTH"
.endif

        .text
        li      r1, 0                           ; counter vector v
        li      r9, KC_KINDS * KC_COUNTERS
vec:    li      r2, 0                           ; lane l
        li      r10, KC_LANES
lane:   muli    r3, r1, KC_VEC_BYTES
        shli    r4, r2, 2
        add     r3, r3, r4
        spld    r5, r3, KC_BASE
        addi    r6, r1, 1
        addi    r7, r2, 1
        mul     r6, r6, r7
        add     r5, r5, r6
        spst    r5, r3, KC_BASE
        addi    r2, r2, 1
        blt     r2, r10, lane
        addi    r1, r1, 1
        blt     r1, r9, vec
        li      r1, 0
        li      r5, 2
        spst    r5, r1, ST_CAMERA
        li      r5, 3
        spst    r5, r1, ST_INDIRECT
        halt
