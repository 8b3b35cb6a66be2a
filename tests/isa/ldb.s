; ldb: broadcast load: va[l] := SM[rb + imm] on every exec-mask lane.
        .data
        .word   10, 20, 30
        .float  0.25
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r1, 4
        ldb     v1, r1, 4               ; SM[8] = 30
        ldb     v2, r0, 12              ; 0.25
        vli     v3, 9
        ldb     v3, r0, 0 @m2           ; odd lanes: 10
        li      r2, 1048576
        ldb     v4, r2, -4              ; the last word: 0
        ldb     v5, r2, 0               ; outside: trap
        halt
;! v1[l] == 30
;! v2[l] ==f 0.25
;! v3[l] == (l % 2 == 1 ? 10 : 9)
;! v4[l] == 0
;! trap "ldb v5, r2, 0" "tests/isa/ldb.s:17"
