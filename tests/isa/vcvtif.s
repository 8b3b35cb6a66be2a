; vcvtif: va := (float) signed vb per lane, round to nearest even, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vcvtif  v2, v0                  ; l
        vmuli   v3, v0, 16777217
        vcvtif  v4, v3                  ; l * (2^24 + 1), rounded
        vmuli   v5, v0, -16777217
        vcvtif  v6, v5                  ; negative
        li      r2, 0x80000000
        vbcast  v7, r2
        vcvtif  v8, v7                  ; -2^31 (signed, not 2^31)
        li      r3, 0x7FFFFFFF
        vbcast  v9, r3
        vcvtif  v10, v9                 ; 2^31
        vli     v12, 5
        vcvtif  v12, v0 @m2             ; odd lanes converted, the rest keep the integer 5
        halt
;! v2[l] ==f l
;! v4[l] ==f l * 16777217
;! v6[l] ==f -l * 16777217
;! v8[l] ==f -2147483648.0
;! v10[l] == 0x4F000000
;! v12[l] == (l % 2 == 1 ? f(l) : 5)
