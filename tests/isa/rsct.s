; rsct: conditional scatter into the current ray buffer: RBc[rc + imm + 4 * vb[l]] := va[l] on
; exec-mask lanes. RBc is RB0 after reset.
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v1, v0, 3
        vaddi   v1, v1, 1               ; 3l + 1
        li      r1, 64
        rsct    v1, v0, r1, 16          ; RB0[80 + 4l]
        vaddi   v2, v0, 1000
        rsct    v2, v0, r1, 1024 @m2    ; RB0[1088 + 4l], odd lanes only
        rdn     r2
        addi    r2, r2, -1
        vbcast  v3, r2
        vsub    v4, v3, v0              ; IDs N-1-l: reversed
        rsct    v0, v4, r0, 4096        ; RB0[4096 + 4(N-1-l)] = l
        halt
;! mem rb0[80 + 4 * l] == 3 * l + 1
;! mem rbc[80 + 4 * l] == 3 * l + 1
;! mem rb1[80 + 4 * l] == 0
;! mem rb0[1088 + 4 * l] == (l % 2 == 1 ? 1000 + l : 0)
;! mem rb0[4096 + 4 * l] == N - 1 - l
;! mem rb0[76] == 0
