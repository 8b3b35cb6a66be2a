; vspst: SP[rb + imm + 4l] := va[l] on exec-mask lanes. Past the end traps (from N = 2 on).
        .spad
        .word   5, 5, 5, 5
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v1, v0, 3
        vaddi   v1, v1, 1
        li      r1, 4
        vspst   v1, r1, 8               ; SP[12 + 4l] = 3l + 1
        vaddi   v2, v0, 40
        vspst   v2, r0, 1024 @m2        ; odd lanes only
        vspst   v2, r0, 0 @m7           ; empty mask: the image's first words stay
        li      r2, 65532
        vspst   v1, r2, 0               ; lane 1 would be outside
        halt
;! mem spad[12 + 4 * l] == 3 * l + 1
;! mem spad[8] == 5
;! mem spad[0] == 5
;! mem spad[1024 + 4 * l] == (l % 2 == 1 ? 40 + l : 0)
;! if N == 1: mem spad[65532] == 1
;! if N >= 2: trap "vspst v1, r2, 0" "tests/isa/vspst.s:17"
