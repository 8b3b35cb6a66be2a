; vshri: va := vb >> (imm & 31) per lane, logical, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vshri   v3, v2, 16
        vshri   v4, v2, 32              ; count 0
        vli     v5, -1
        vshri   v6, v5, 31              ; 1 (logical)
        vli     v7, 0x5A5A
        vshri   v7, v2, 24 @m2
        halt
;! v3[l] == u32(l * 0x9E3779B9) >> 16
;! v4[l] == l * 0x9E3779B9
;! v6[l] == 1
;! v7[l] == (l % 2 == 1 ? u32(l * 0x9E3779B9) >> 24 : 0x5A5A)
