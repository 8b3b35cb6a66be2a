; vsqrt: va := sqrt(vb) per lane, correctly rounded, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vsqrt   v2, v1                  ; sqrt(l)
        vli     v3, -1.0
        vsqrt   v4, v3                  ; NaN
        li      r2, 0x80000000
        vbcast  v5, r2
        vsqrt   v6, v5                  ; -0
        li      r3, 0x7F800000
        vbcast  v7, r3
        vsqrt   v8, v7                  ; +inf
        vli     v9, -2.0
        vsqrt   v9, v1 @m2
        halt
;! v2[l] ==f sqrt(l)
;! v4[l] ==f nan
;! v6[l] == 0x80000000
;! v8[l] == 0x7F800000
;! v9[l] ==f l % 2 == 1 ? sqrt(l) : -2.0
