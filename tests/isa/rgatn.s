; rgatn: gather from the next ray buffer: va[l] := RBn[rc + imm + 4 * vb[l]], merge masking.
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vaddi   v1, v0, 40
        rsctn   v1, v0, r0, 0           ; RB1[4l] = l + 40
        rgatn   v2, v0, r0, 0
        vli     v3, 0x5A5A
        rgatn   v3, v0, r0, 0 @m2
        vaddi   v4, v0, 80
        rsct    v4, v0, r0, 768         ; into the current buffer...
        rgatn   v5, v0, r0, 768         ; ...is not visible in the next one
        halt
;! v2[l] == l + 40
;! v3[l] == (l % 2 == 1 ? l + 40 : 0x5A5A)
;! v5[l] == 0
;! mem rb0[768 + 4 * l] == l + 80
