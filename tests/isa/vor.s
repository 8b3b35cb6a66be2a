; vor: va := vb | vc per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vli     v3, 0x80000001
        vor     v4, v2, v3
        vor     v5, v0, v11             ; identity
        vli     v6, 0x5A5A
        vor     v6, v2, v3 @m2
        halt
;! v4[l] == (l * 0x9E3779B9) | 0x80000001
;! v5[l] == l
;! v6[l] == (l % 2 == 1 ? (l * 0x9E3779B9) | 0x80000001 : 0x5A5A)
