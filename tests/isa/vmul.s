; vmul: va := low 32 bits of vb * vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vaddi   v3, v0, 1
        vmul    v4, v2, v3              ; (l * 0x9E3779B9 mod 2^32) * (l + 1), low bits
        vli     v5, -3
        vmul    v6, v0, v5              ; -3l
        vli     v7, 0x10000
        vmul    v8, v7, v7              ; 2^32: 0
        vli     v9, 9
        vmul    v9, v0, v0 @m2
        halt
;! v4[l] == u32(l * 0x9E3779B9) * (l + 1)
;! v6[l] == -3 * l
;! v8[l] == 0
;! v9[l] == (l % 2 == 1 ? l * l : 9)
