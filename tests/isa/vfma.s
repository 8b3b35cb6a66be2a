; vfma: va := vb * vc + vd per lane with a single rounding, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r2, 0x3F800800          ; 1 + 2^-12
        vbcast  v2, r2
        vli     v3, -1.0
        vfma    v4, v2, v2, v3          ; 2^-11 + 2^-24 exactly (unfused: 2^-11)
        vli     v5, 2.0
        vli     v6, 0.5
        vfma    v7, v1, v5, v6          ; 2l + 0.5
        vli     v8, -7.0
        vfma    v8, v1, v1, v6 @m2      ; l^2 + 0.5 on odd lanes
        li      r3, 0x7F800000
        vbcast  v9, r3
        vfma    v10, v9, v11, v5        ; inf * 0 + 2 = NaN
        vli     v12, 1.0
        vfma    v12, v1, v5, v12        ; destination is the addend: 2l + 1
        halt
;! v4[l] == 0x3A000400
;! v7[l] ==f 2 * l + 0.5
;! v8[l] ==f l % 2 == 1 ? l * l + 0.5 : -7.0
;! v10[l] ==f nan
;! v12[l] ==f 2 * l + 1
