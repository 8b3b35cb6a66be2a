; vlog2: va := log2(vb) per lane (within 1e-6 here), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vandi   v2, v0, 15
        vaddi   v2, v2, 119
        vshli   v3, v2, 23              ; binary32 bits of 2^(l % 16 - 8)
        vlog2   v4, v3                  ; l % 16 - 8
        vlog2   v5, v11                 ; log2(+0) = -inf
        vli     v6, -1.0
        vlog2   v7, v6                  ; NaN
        li      r2, 0x7F800000
        vbcast  v8, r2
        vlog2   v9, v8                  ; +inf
        vli     v10, 1.0
        vlog2   v12, v10                ; 0
        vli     v13, 10.0
        vlog2   v14, v13
        vli     v15, 0.5
        vlog2   v15, v3 @m2
        halt
;! v4[l] ~= l % 16 - 8 1e-6
;! v5[l] == 0xFF800000
;! v7[l] ==f nan
;! v9[l] == 0x7F800000
;! v12[l] ~= 0 1e-7
;! v14[l] ~= log2(10) 1e-6
;! v15[l] ~= l % 2 == 1 ? l % 16 - 8 : 0.5 1e-6
