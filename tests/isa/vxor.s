; vxor: va := vb ^ vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vli     v3, 0xFFFF0000
        vxor    v4, v2, v3
        vxor    v5, v2, v2              ; 0
        vli     v6, 0x5A5A
        vxor    v6, v2, v3 @m2
        halt
;! v4[l] == (l * 0x9E3779B9) ^ 0xFFFF0000
;! v5[l] == 0
;! v6[l] == (l % 2 == 1 ? (l * 0x9E3779B9) ^ 0xFFFF0000 : 0x5A5A)
