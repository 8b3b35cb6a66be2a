; mor: ma := mb | mc.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mor     m3, m1, m2
        mor     m4, m1, m6              ; | empty: m1
        mor     m5, m2, m0              ; | all: all
        halt
;! m3[l] == (l < 5 || l % 2 == 1)
;! m4 == 0x1F & (N == 64 ? -1 : (1 << N) - 1)
;! m5 == (N == 64 ? -1 : (1 << N) - 1)
