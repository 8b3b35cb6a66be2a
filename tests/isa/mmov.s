; mmov: ma := mb. Moving into m0 changes the default exec mask of later vector instructions.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mmov    m3, m2
        mmov    m4, m7                  ; empty
        mmov    m0, m1                  ; default exec mask: lanes < 5
        vli     v5, 9                   ; no @mK: uses m0
        halt
;! m3[l] == (l % 2)
;! m4 == 0
;! m0 == 0x1F & (N == 64 ? -1 : (1 << N) - 1)
;! v5[l] == (l < 5 ? 9 : 0)
