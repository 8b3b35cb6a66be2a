; vfne: ma := E & !(vb == vc): true for NaN.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8
        vcvtif  v3, v2                  ; v3 = float(l - 8)
        li      r2, 0x7FC00000
        vbcast  v4, r2                  ; NaN
        li      r3, 0x80000000
        vbcast  v5, r3                  ; -0.0 (v11 is +0)
        vfne    m3, v3, v11             ; l != 8
        mall    m4
        vfne    m4, v4, v4 @m2          ; NaN: true, but only on odd lanes
        vfne    m5, v5, v11             ; -0 != +0: none
        vfne    m6, v4, v1              ; NaN vs anything: all
        halt
;! m3[l] == (l != 8)
;! m4[l] == (l % 2 == 1)
;! m5 == 0
;! m6[l] == 1
