; vffloor: va := floor(vb) per lane, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8
        vcvtif  v2, v2
        vli     v3, 0.75
        vfmul   v4, v2, v3              ; (l - 8) * 0.75, exact
        vffloor v5, v4
        vli     v6, -0.5
        vffloor v7, v6                  ; -1
        li      r2, 0x80000000
        vbcast  v8, r2
        vffloor v9, v8                  ; -0
        vli     v10, 9.0
        vffloor v10, v4 @m2
        halt
;! v5[l] ==f floor((l - 8) * 0.75)
;! v7[l] ==f -1.0
;! v9[l] == 0x80000000
;! v10[l] ==f l % 2 == 1 ? floor((l - 8) * 0.75) : 9.0
