; vexp2: va := 2 ^ vb per lane (relative error within 1e-6 here), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vandi   v2, v0, 15
        vaddi   v2, v2, -8
        vcvtif  v3, v2                  ; x = l % 16 - 8
        vexp2   v4, v3                  ; 2^-8 .. 2^7
        vli     v5, 0.5
        vexp2   v6, v5                  ; sqrt(2)
        li      r2, 0xFF800000
        vbcast  v7, r2
        vexp2   v8, v7                  ; 2^-inf = 0
        li      r3, 0x7F800000
        vbcast  v9, r3
        vexp2   v10, v9                 ; +inf
        vli     v12, 200.0
        vexp2   v13, v12                ; overflow: +inf
        vli     v14, -200.0
        vexp2   v15, v14                ; underflow: 0
        vli     v16, 0.25
        vexp2   v16, v3 @m2
        halt
;! v4[l] ~= exp2(l % 16 - 8) exp2(l % 16 - 8) * 1e-6
;! v6[l] ~= 1.41421356 2e-6
;! v8[l] ~= 0 1e-30
;! v10[l] == 0x7F800000
;! v13[l] == 0x7F800000
;! v15[l] ~= 0 1e-30
;! v16[l] ~= l % 2 == 1 ? exp2(l % 16 - 8) : 0.25 1e-6
