; rswap: exchange the current and next ray buffers.
        .text
        viota   v0
        vaddi   v1, v0, 500
        rsct    v1, v0, r0, 0           ; RB0[4l] = l + 500
        vaddi   v2, v0, 900
        rsctn   v2, v0, r0, 0           ; RB1[4l] = l + 900
        rswap                           ; RBc = RB1
        rgat    v3, v0, r0, 0           ; l + 900
        rgatn   v4, v0, r0, 0           ; l + 500
        vaddi   v5, v0, 2000
        rsct    v5, v0, r0, 1024        ; lands in RB1
        rswap                           ; RBc = RB0
        rgat    v6, v0, r0, 0           ; l + 500
        rgat    v7, v0, r0, 1024        ; 0: that went to RB1
        rswap                           ; three swaps: RBc = RB1
        halt
;! v3[l] == l + 900
;! v4[l] == l + 500
;! v6[l] == l + 500
;! v7[l] == 0
;! mem rb1[1024 + 4 * l] == l + 2000
;! mem rb0[1024 + 4 * l] == 0
;! mem rbc[4 * l] == l + 900
;! mem rbn[4 * l] == l + 500
;! stat op.rswap == 3
