; vrcp: va := 1 / vb per lane (an exact IEEE reciprocal), merge masking.
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
        vrcp    v4, v3                  ; 1 / (l + 1)
        vrcp    v5, v11                 ; 1 / +0 = +inf
        li      r2, 0x80000000
        vbcast  v6, r2
        vrcp    v7, v6                  ; -inf
        li      r3, 0x7F800000
        vbcast  v8, r3
        vrcp    v9, v8                  ; +0
        vli     v10, 4.0
        vrcp    v12, v10                ; 0.25
        vli     v13, 3.0
        vrcp    v13, v3 @m2
        halt
;! v4[l] ==f 1.0 / (l + 1)
;! v5[l] == 0x7F800000
;! v7[l] == 0xFF800000
;! v9[l] == 0
;! v12[l] ==f 0.25
;! v13[l] ==f l % 2 == 1 ? 1.0 / (l + 1) : 3.0
