; mnot: ma := ~mb within N lanes: bits at lanes >= N stay 0.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mnot    m3, m1                  ; lanes >= 5
        mnot    m4, m0                  ; none
        mnot    m5, m6                  ; m6 empty: all N lanes
        mnot    m2, m2                  ; in place: even lanes
        halt
;! m3 == (N == 64 ? -1 : (1 << N) - 1) & ~0x1F
;! m4 == 0
;! m5 == (N == 64 ? -1 : (1 << N) - 1)
;! m2[l] == (l % 2 == 0)
;! m2 == (N == 64 ? -1 : (1 << N) - 1) & 0x5555555555555555
