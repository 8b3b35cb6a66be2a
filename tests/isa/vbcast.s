; vbcast: va := rb in every lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r2, 0xDEADBEEF
        vbcast  v2, r2
        li      r3, 1.5
        vbcast  v3, r3
        vbcast  v4, r2 @m1
        vbcast  v5, r0                  ; r0 is 0 (not written yet)
        halt
;! v2[l] == 0xDEADBEEF
;! v3[l] ==f 1.5
;! v4[l] == (l < 3 ? 0xDEADBEEF : 0)
;! v5[l] == 0
