; vfadd: va := vb + vc per lane, under the exec mask (merge masking).
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vli     v2, 0.5
        vfadd   v3, v1, v2              ; l + 0.5
        vli     v4, -7.0
        vfadd   v4, v1, v1 @m2          ; 2l on odd lanes, the rest keep -7
        li      r2, 0x7F800000
        vbcast  v5, r2                  ; +inf
        li      r3, 0xFF800000
        vbcast  v6, r3                  ; -inf
        vfadd   v7, v5, v6              ; NaN
        li      r4, 0x80000000
        vbcast  v8, r4                  ; -0
        vfadd   v9, v8, v8              ; -0 + -0 = -0
        vfadd   v10, v8, v11            ; -0 + +0 = +0 (v11 is 0 from reset)
        li      r5, 0.1
        vbcast  v12, r5
        li      r6, 0.2
        vbcast  v13, r6
        vfadd   v14, v12, v13           ; 0x3E99999A
        vli     v15, 16777216.0
        vli     v16, 1.0
        vfadd   v17, v15, v16           ; ties to even: 2^24
        vfadd   v1, v1, v1 @m1          ; destination is a source, lanes < 3 only
        halt
;! v3[l] ==f l + 0.5
;! v4[l] ==f l % 2 == 1 ? 2 * l : -7.0
;! v7[l] ==f nan
;! v9[l] == 0x80000000
;! v10[l] == 0
;! v11[l] == 0
;! v14[l] == 0x3E99999A
;! v17[l] ==f 16777216.0
;! v1[l] ==f l < 3 ? 2 * l : l
