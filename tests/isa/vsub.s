; vsub: va := vb - vc per lane, wrapping, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vsub    v2, v11, v0             ; -l
        vli     v3, 0x80000000
        vsub    v4, v3, v0              ; INT_MIN - l wraps
        vmuli   v5, v0, 0x9E3779B9
        vsub    v6, v5, v0
        vli     v7, 50
        vsub    v7, v7, v0 @m2          ; 50 - l on odd lanes
        halt
;! v2[l] == -l
;! v4[l] == 0x80000000 - l
;! v6[l] == l * 0x9E3779B9 - l
;! v7[l] == (l % 2 == 1 ? 50 - l : 50)
