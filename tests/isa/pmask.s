; pmask: feeds N mask bits, lane 0 first, to the partition unit's queue; part consumes them in
; order. A stream of 2N IDs (0 .. 2N-1) is partitioned by two blocks of bits; then three blocks
; for a two-block stream (N bits too many) trap.
        .text
        rdn     r1
        viota   v0
        li      r4, 0
        sapp    r4, v0                  ; IDs 0 .. N-1
        vbcast  v1, r1
        vadd    v2, v0, v1
        sapp    r4, v2                  ; IDs N .. 2N-1; r4 = 8N
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r5, 1
        mtail   m3, r5                  ; lane 0 only
        pmask   m2                      ; block 0: keep the odd IDs
        pmask   m3                      ; block 1: keep ID N
        part    r6, r0, r4
        pmask   m0
        pmask   m0
        pmask   m0
        part    r7, r0, r4              ; 3N bits for 2N IDs: trap
        halt
;! r6 == 4 * (N / 2 + 1)
;! mem idm[4 * l] == (l < N / 2 ? 2 * l + 1 : l == N / 2 ? N : 2 * (l - N / 2 - 1))
;! mem idm[4 * (N + l)] == (l == 0 ? 2 * (N - N / 2 - 1) : N + l)
;! trap "part r7, r0, r4" "tests/isa/pmask.s:23"
