; viltu: ma := E & (vb < vc), unsigned integers.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8              ; l - 8: huge unsigned below lane 8
        vli     v3, 5
        viltu   m3, v2, v3              ; (l - 8) <u 5: lanes 8..12
        mall    m4
        viltu   m4, v2, v3 @m2
        li      r2, 0x80000000
        vbcast  v4, r2
        li      r3, 0x7FFFFFFF
        vbcast  v5, r3
        viltu   m5, v4, v5              ; 0x80000000 <u 0x7FFFFFFF: none
        viltu   m6, v5, v4              ; all
        halt
;! m3[l] == (l >= 8 && l < 13)
;! m4[l] == (l % 2 == 1 && l >= 8 && l < 13)
;! m5 == 0
;! m6[l] == 1
