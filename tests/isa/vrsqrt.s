; vrsqrt: va := 1 / sqrt(vb) per lane (accuracy: within 1e-6 here), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 1.0
        vfadd   v3, v1, v2              ; l + 1
        vrsqrt  v4, v3
        vrsqrt  v5, v11                 ; 1 / sqrt(+0) = +inf
        vli     v6, -1.0
        vrsqrt  v7, v6                  ; NaN
        li      r2, 0x7F800000
        vbcast  v8, r2
        vrsqrt  v9, v8                  ; +0
        vli     v10, 0.25
        vrsqrt  v12, v10                ; 2
        vli     v13, 5.0
        vrsqrt  v13, v3 @m2
        halt
;! v4[l] ~= 1 / sqrt(l + 1) 1e-6
;! v5[l] ~= inf 0
;! v7[l] ==f nan
;! v9[l] ~= 0 1e-30
;! v12[l] ~= 2.0 2e-6
;! v13[l] ~= l % 2 == 1 ? 1 / sqrt(l + 1) : 5.0 1e-6
