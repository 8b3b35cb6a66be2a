; vshli: va := vb << (imm & 31) per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vshli   v2, v0, 28              ; high lanes lose bits
        vshli   v3, v0, 33              ; count 1
        vshli   v4, v0, 32              ; count 0
        vli     v5, 0x5A5A
        vshli   v5, v0, 4 @m2
        halt
;! v2[l] == l << 28
;! v3[l] == l << 1
;! v4[l] == l
;! v5[l] == (l % 2 == 1 ? l << 4 : 0x5A5A)
