; vli: va := imm in every lane (integer or float bits), merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 42
        vli     v3, -1.5
        vli     v4, 0x80000000
        vmov    v5, v0
        vli     v5, 7 @m2
        vli     v6, -1
        halt
;! v2[l] == 42
;! v3[l] ==f -1.5
;! v3[l] == 0xBFC00000
;! v4[l] == 0x80000000
;! v5[l] == (l % 2 == 1 ? 7 : l)
;! v6[l] == -1
