; vsin: va := sin(vb), radians, per lane (within 1e-6 here), merge masking.
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
        vfmul   v4, v2, v3              ; x = (l - 32) * 0.1 in binary32, -3.2 .. 3.1
        vsin    v5, v4
        vsin    v6, v11                 ; sin(0) = 0
        li      r2, 0x7F800000
        vbcast  v7, r2
        vsin    v8, v7                  ; sin(inf) = NaN
        vli     v9, 1.5707963
        vsin    v10, v9                 ; 1
        vli     v12, 9.0
        vsin    v12, v4 @m2
        halt
;! v5[l] ~= sin(float(float(l - 32) * float(0.1))) 1e-6
;! v6[l] == 0
;! v8[l] ==f nan
;! v10[l] ~= 1.0 1e-6
;! v12[l] ~= l % 2 == 1 ? sin(float(float(l - 32) * float(0.1))) : 9.0 1e-6
