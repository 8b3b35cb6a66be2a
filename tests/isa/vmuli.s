; vmuli: va := low 32 bits of vb * imm per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vmuli   v3, v0, -7
        vmuli   v4, v0, 0
        vli     v5, 0x5A5A
        vmuli   v5, v0, 3 @m2
        halt
;! v2[l] == l * 0x9E3779B9
;! v3[l] == -7 * l
;! v4[l] == 0
;! v5[l] == (l % 2 == 1 ? 3 * l : 0x5A5A)
