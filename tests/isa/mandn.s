; mandn: ma := mb & ~mc.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mandn   m3, m1, m2              ; lanes < 5 that are even
        mandn   m4, m0, m1              ; lanes >= 5
        mandn   m5, m1, m1              ; empty
        mandn   m6, m2, m7              ; m7 empty: m2
        halt
;! m3[l] == (l < 5 && l % 2 == 0)
;! m4 == (N == 64 ? -1 : (1 << N) - 1) & ~0x1F
;! m5 == 0
;! m6[l] == (l % 2)
