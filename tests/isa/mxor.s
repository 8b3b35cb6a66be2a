; mxor: ma := mb ^ mc.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mxor    m3, m1, m2
        mxor    m4, m2, m2              ; empty
        mxor    m5, m1, m0              ; complement of m1 within N lanes
        halt
;! m3[l] == ((l < 5) ^ (l % 2))
;! m4 == 0
;! m5[l] == (l >= 5)
;! m5 == (N == 64 ? -1 : (1 << N) - 1) & ~0x1F
