; vfsub: va := vb - vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 0.5
        vfsub   v3, v1, v2              ; l - 0.5
        vli     v4, -7.0
        vfsub   v4, v2, v1 @m2          ; 0.5 - l on odd lanes
        li      r2, 0x7F800000
        vbcast  v5, r2
        vfsub   v7, v5, v5              ; inf - inf = NaN
        vfsub   v8, v1, v1              ; x - x = +0
        li      r4, 0x80000000
        vbcast  v9, r4
        vfsub   v10, v9, v11            ; -0 - +0 = -0
        li      r5, 0.3
        vbcast  v12, r5
        li      r6, 0.1
        vbcast  v13, r6
        vfsub   v14, v12, v13
        halt
;! v3[l] ==f l - 0.5
;! v4[l] ==f l % 2 == 1 ? 0.5 - l : -7.0
;! v7[l] ==f nan
;! v8[l] == 0
;! v10[l] == 0x80000000
;! v14[l] ==f float(float(0.3) - float(0.1))
