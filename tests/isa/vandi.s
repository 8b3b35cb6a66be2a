; vandi: va := vb & imm per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9
        vandi   v3, v2, 0xFFFF
        vandi   v4, v2, 0xFFFF0000
        vandi   v5, v0, 1               ; l % 2
        vli     v6, 0x5A5A
        vandi   v6, v2, 0xFF @m2
        halt
;! v3[l] == (l * 0x9E3779B9) & 0xFFFF
;! v4[l] == (l * 0x9E3779B9) & 0xFFFF0000
;! v5[l] == l % 2
;! v6[l] == (l % 2 == 1 ? (l * 0x9E3779B9) & 0xFF : 0x5A5A)
