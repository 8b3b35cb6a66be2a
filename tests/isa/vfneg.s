; vfneg: va := -vb per lane (sign flip, zeros included), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8
        vcvtif  v2, v2                  ; l - 8
        vfneg   v3, v2                  ; 8 - l, and -0 where l = 8
        vfneg   v4, v11                 ; -0
        li      r2, 0x7F800000
        vbcast  v5, r2
        vfneg   v6, v5                  ; -inf
        vli     v7, 2.5
        vfneg   v7, v7 @m2
        halt
;! v3[l] ==f -((l - 8) * 1.0)
;! v4[l] == 0x80000000
;! v6[l] == 0xFF800000
;! v7[l] ==f l % 2 == 1 ? -2.5 : 2.5
