; vfabs: va := |vb| per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8
        vcvtif  v2, v2                  ; l - 8
        vfabs   v3, v2                  ; |l - 8|
        li      r2, 0x80000000
        vbcast  v4, r2
        vfabs   v5, v4                  ; +0
        li      r3, 0xFF800000
        vbcast  v6, r3
        vfabs   v7, v6                  ; +inf
        vli     v8, -3.5
        vfabs   v8, v8 @m2              ; 3.5 on odd lanes, -3.5 elsewhere
        halt
;! v3[l] ==f abs(l - 8)
;! v5[l] == 0
;! v7[l] == 0x7F800000
;! v8[l] ==f l % 2 == 1 ? 3.5 : -3.5
