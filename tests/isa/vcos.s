; vcos: va := cos(vb), radians, per lane (within 1e-6 here), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -32
        vcvtif  v2, v2
        vli     v3, 0.1
        vfmul   v4, v2, v3              ; x = (l - 32) * 0.1
        vcos    v5, v4
        vcos    v6, v11                 ; cos(0) = 1
        li      r2, 0x7FC00000
        vbcast  v7, r2
        vcos    v8, v7                  ; NaN
        vli     v9, 3.14159265
        vcos    v10, v9                 ; -1
        vli     v12, 9.0
        vcos    v12, v4 @m2
        halt
;! v5[l] ~= cos(float(float(l - 32) * float(0.1))) 1e-6
;! v6[l] ~= 1.0 1e-7
;! v8[l] ==f nan
;! v10[l] ~= -1.0 1e-6
;! v12[l] ~= l % 2 == 1 ? cos(float(float(l - 32) * float(0.1))) : 9.0 1e-6
