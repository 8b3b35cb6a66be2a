; vsel: va := md ? vb : vc per lane, under the exec mask.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, 100             ; l + 100
        vaddi   v3, v0, 200             ; l + 200
        vsel    v4, v2, v3, m2          ; odd lanes from v2, even from v3
        li      r2, 5
        mtail   m3, r2                  ; lanes < 5
        vli     v5, 7
        vsel    v5, v2, v3, m2 @m3      ; only lanes < 5 change
        vsel    v6, v2, v3, m7          ; m7 empty: all from vc
        vsel    v2, v3, v2, m0          ; destination is a source: all from v3
        halt
;! v4[l] == (l % 2 == 1 ? l + 100 : l + 200)
;! v5[l] == (l < 5 ? (l % 2 == 1 ? l + 100 : l + 200) : 7)
;! v6[l] == l + 200
;! v2[l] == l + 200
