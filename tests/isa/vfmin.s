; vfmin: va := vc < vb ? vc : vb per lane. NaN in vc gives vb; NaN in vb gives NaN; for two zeros,
; vb.
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
        vli     v3, 8.0
        vfsub   v3, v3, v1              ; 8 - l
        vfmin   v4, v2, v3              ; -|l - 8| (+0 at l = 8)
        li      r2, 0x7FC00000
        vbcast  v5, r2                  ; NaN
        vfmin   v6, v1, v5              ; NaN in vc: vb = l
        vfmin   v7, v5, v1              ; NaN in vb: NaN
        li      r3, 0x80000000
        vbcast  v8, r3                  ; -0
        vfmin   v9, v11, v8             ; vb = +0: +0
        vfmin   v10, v8, v11            ; vb = -0: -0
        vli     v12, 100.0
        vfmin   v12, v2, v3 @m2         ; odd lanes only
        halt
;! v4[l] ==f -abs(l - 8)
;! v6[l] ==f l
;! v7[l] ==f nan
;! v9[l] == 0
;! v10[l] == 0x80000000
;! v12[l] ==f l % 2 == 1 ? -abs(l - 8) : 100.0
