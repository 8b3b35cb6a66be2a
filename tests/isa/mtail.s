; mtail: ma := lanes l < rb, rb signed: <= 0 gives none, >= N gives all.
        .text
        li      r1, 3
        mtail   m1, r1
        li      r2, -1
        mtail   m2, r2                  ; none
        mtail   m3, r0                  ; 0: none
        rdn     r4
        mtail   m4, r4                  ; N: all
        li      r5, 1000
        mtail   m5, r5                  ; all
        li      r6, 0x80000000
        mtail   m6, r6                  ; INT_MIN (not 2^31): none
        li      r7, 64
        mtail   m7, r7                  ; all, also at N = 64
        halt
;! m1[l] == (l < 3)
;! m1 == (1 << min(3, N)) - 1
;! m2 == 0
;! m3 == 0
;! m4 == (N == 64 ? -1 : (1 << N) - 1)
;! m5 == (N == 64 ? -1 : (1 << N) - 1)
;! m6 == 0
;! m7 == (N == 64 ? -1 : (1 << N) - 1)
