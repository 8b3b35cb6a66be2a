; vsra: va := vb >> (vc & 31) per lane, arithmetic.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 0x80000001
        vsra    v3, v2, v0              ; sign bits shifted in
        vli     v4, 0x40000000
        vsra    v5, v4, v0              ; positive: zeros shifted in
        vli     v6, 0x5A5A
        vsra    v6, v2, v0 @m2
        halt
;! v3[l] == s32(0x80000001) >> (l & 31)
;! v5[l] == 0x40000000 >> (l & 31)
;! v6[l] == (l % 2 == 1 ? s32(0x80000001) >> (l & 31) : 0x5A5A)
