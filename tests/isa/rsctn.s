; rsctn: scatter into the next ray buffer (RB1 after reset): RBn[rc + imm + 4 * vb[l]] := va[l].
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v1, v0, 7
        rsctn   v1, v0, r0, 32          ; RB1[32 + 4l] = 7l
        vaddi   v2, v0, 300
        li      r1, 2048
        rsctn   v2, v0, r1, -1024 @m2   ; RB1[1024 + 4l], odd lanes; negative offset
        halt
;! mem rb1[32 + 4 * l] == 7 * l
;! mem rbn[32 + 4 * l] == 7 * l
;! mem rb0[32 + 4 * l] == 0
;! mem rb1[1024 + 4 * l] == (l % 2 == 1 ? 300 + l : 0)
