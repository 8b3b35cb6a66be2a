; vand: va := vb & vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vli     v3, 0xF0F0F0F0
        vand    v4, v2, v3
        vli     v5, -1
        vand    v6, v2, v5              ; identity
        vli     v7, 0x5A5A
        vand    v7, v2, v3 @m2
        halt
;! v4[l] == (l * 0x9E3779B9) & 0xF0F0F0F0
;! v6[l] == l * 0x9E3779B9
;! v7[l] == (l % 2 == 1 ? (l * 0x9E3779B9) & 0xF0F0F0F0 : 0x5A5A)
