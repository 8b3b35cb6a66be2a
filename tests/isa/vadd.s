; vadd: va := vb + vc per lane, 32-bit wrapping, merge masking.
        .text
        viota   v0                      ; v0[l] = l
        vcvtif  v1, v0                  ; v1[l] = float(l)
        li      r1, 3
        mtail   m1, r1                  ; m1: lanes 0..2
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v2, v0, 0x9E3779B9      ; l * golden ratio, wrapping
        vli     v3, 0x7FFFFFFF
        vadd    v4, v2, v3              ; wraps past INT_MAX
        vli     v5, 1000
        vadd    v5, v0, v5 @m2          ; l + 1000 on odd lanes
        vadd    v6, v0, v0              ; 2l
        vadd    v0, v0, v0 @m1          ; destination is a source
        halt
;! v4[l] == l * 0x9E3779B9 + 0x7FFFFFFF
;! v5[l] == (l % 2 == 1 ? l + 1000 : 1000)
;! v6[l] == 2 * l
;! v0[l] == (l < 3 ? 2 * l : l)
