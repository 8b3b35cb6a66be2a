; vxori: va := vb ^ imm per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vxori   v2, v0, 0x55
        vxori   v3, v0, -1              ; ~l
        vli     v4, 0x5A5A
        vxori   v4, v0, 0x80000000 @m2
        halt
;! v2[l] == l ^ 0x55
;! v3[l] == ~l
;! v4[l] == (l % 2 == 1 ? l ^ 0x80000000 : 0x5A5A)
