; vilt: ma := E & (vb < vc), signed integers.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -8              ; l - 8
        vilt    m3, v2, v11             ; l - 8 < 0
        mall    m4
        vilt    m4, v2, v11 @m2
        li      r2, 0x80000000
        vbcast  v3, r2
        li      r3, 0x7FFFFFFF
        vbcast  v4, r3
        vilt    m5, v3, v4              ; INT_MIN < INT_MAX: all
        vilt    m6, v0, v0              ; none
        halt
;! m3[l] == (l < 8)
;! m4[l] == (l % 2 == 1 && l < 8)
;! m5[l] == 1
;! m6 == 0
