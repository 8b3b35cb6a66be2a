; slti: ra := (rb < imm, signed) ? 1 : 0.
        .text
        li      r1, -1
        slti    r2, r1, 0       ; -1 < 0: 1
        slti    r3, r0, -1      ; 0 < -1: 0
        slti    r4, r0, 0       ; 0
        li      r5, 0x80000000
        slti    r6, r5, 0x7FFFFFFF ; 1
        li      r7, 0x7FFFFFFF
        slti    r8, r7, 0x80000000 ; INT_MAX < INT_MIN: 0
        slti    r9, r1, 1       ; 1
        halt
;! r2 == 1
;! r3 == 0
;! r4 == 0
;! r6 == 1
;! r8 == 0
;! r9 == 1
