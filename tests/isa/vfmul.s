; vfmul: va := vb * vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 0.5
        vfmul   v3, v1, v2              ; l / 2
        vli     v4, -7.0
        vfmul   v4, v1, v1 @m2          ; l^2 on odd lanes
        vli     v5, -1.0
        vfmul   v6, v1, v5              ; -l, and -0 in lane 0
        li      r2, 0x7F800000
        vbcast  v7, r2
        vfmul   v8, v7, v11             ; inf * 0 = NaN
        vli     v9, 1e20
        vfmul   v10, v9, v9             ; +inf
        vli     v12, 1e-30
        vfmul   v13, v12, v12           ; +0
        vli     v14, 0.1
        vli     v15, 3.0
        vfmul   v16, v14, v15
        halt
;! v3[l] ==f l * 0.5
;! v4[l] ==f l % 2 == 1 ? l * l : -7.0
;! v6[l] ==f -(l * 1.0)
;! v6[0] == 0x80000000
;! v8[l] ==f nan
;! v10[l] == 0x7F800000
;! v13[l] == 0
;! v16[l] ==f float(float(0.1) * 3)
