; mand: ma := mb & mc (N bits; bits above N stay 0).
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mand    m3, m1, m2
        mand    m4, m1, m0              ; & all lanes: m1
        mand    m5, m2, m6              ; & empty: empty
        mand    m1, m1, m2              ; destination is a source
        halt
;! m3[l] == (l < 5 && l % 2 == 1)
;! m3 == 0xA & (N == 64 ? -1 : (1 << N) - 1)
;! m4 == 0x1F & (N == 64 ? -1 : (1 << N) - 1)
;! m5 == 0
;! m1 == 0xA & (N == 64 ? -1 : (1 << N) - 1)
