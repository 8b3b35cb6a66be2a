; vieq: ma := E & (vb == vc), integer (bit) equality.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 5
        vieq    m3, v0, v2              ; l == 5
        mall    m4
        vieq    m4, v0, v0 @m1          ; lanes < 3 only
        li      r2, 0x80000000
        vbcast  v3, r2
        vieq    m5, v3, v11             ; -0.0 bits vs 0: none (bits differ)
        li      r3, 0x7FC00000
        vbcast  v4, r3
        vieq    m6, v4, v4              ; NaN bits are equal as integers: all
        halt
;! m3[l] == (l == 5)
;! m4[l] == (l < 3)
;! m4 == (N < 3 ? (1 << N) - 1 : 7)
;! m5 == 0
;! m6[l] == 1
