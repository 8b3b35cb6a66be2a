; vmov: va := vb per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vmov    v3, v2
        vli     v4, 0x5A5A
        vmov    v4, v2 @m2
        vmov    v2, v2                  ; to itself
        vli     v5, 0x5A5A
        vmov    v5, v2 @m7              ; empty mask: nothing changes
        halt
;! v3[l] == l * 0x9E3779B9
;! v4[l] == (l % 2 == 1 ? l * 0x9E3779B9 : 0x5A5A)
;! v2[l] == l * 0x9E3779B9
;! v5[l] == 0x5A5A
