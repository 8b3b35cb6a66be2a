; vcvtfi: va := (int) vb per lane, truncated; NaN gives 0; saturates at the int32 range.
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
        vfmul   v4, v2, v3              ; (l - 8) * 0.75
        vcvtfi  v5, v4                  ; truncated toward zero
        li      r2, 0x7FC00000
        vbcast  v6, r2
        vcvtfi  v7, v6                  ; 0
        vli     v8, 3.0e9
        vcvtfi  v9, v8                  ; INT32_MAX
        vli     v10, -3.0e9
        vcvtfi  v12, v10                ; INT32_MIN
        li      r3, 0xFF800000
        vbcast  v13, r3
        vcvtfi  v14, v13                ; -inf: INT32_MIN
        vli     v15, 77
        vcvtfi  v15, v4 @m2
        halt
;! v5[l] == int((l - 8) * 0.75)
;! v7[l] == 0
;! v9[l] == 0x7FFFFFFF
;! v12[l] == 0x80000000
;! v14[l] == 0x80000000
;! v15[l] == (l % 2 == 1 ? int((l - 8) * 0.75) : 77)
