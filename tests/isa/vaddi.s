; vaddi: va := vb + imm per lane, wrapping, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v2, v0, -5
        vaddi   v3, v0, 0xFFFFFFFF      ; -1
        vli     v4, 0x7FFFFFFF
        vaddi   v5, v4, 1               ; INT_MIN
        vli     v6, 0x5A5A
        vaddi   v6, v0, 100 @m2
        halt
;! v2[l] == l - 5
;! v3[l] == l - 1
;! v5[l] == 0x80000000
;! v6[l] == (l % 2 == 1 ? l + 100 : 0x5A5A)
