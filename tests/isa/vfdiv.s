; vfdiv: va := vb / vc per lane, correctly rounded, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 4.0
        vfdiv   v3, v1, v2              ; l / 4
        vli     v4, 1.0
        vfadd   v5, v1, v4              ; l + 1
        vfdiv   v6, v4, v5              ; 1 / (l + 1)
        vfdiv   v7, v1, v11             ; l / +0: NaN in lane 0, +inf elsewhere
        vli     v8, -7.0
        vfdiv   v8, v5, v2 @m2          ; (l + 1) / 4 on odd lanes
        li      r2, 0x80000000
        vbcast  v9, r2
        vfdiv   v10, v4, v9             ; 1 / -0 = -inf
        halt
;! v3[l] ==f l / 4.0
;! v6[l] ==f 1.0 / (l + 1)
;! v7[l] ==f l == 0 ? nan : inf
;! v8[l] ==f l % 2 == 1 ? (l + 1) / 4.0 : -7.0
;! v10[l] == 0xFF800000
