; srai: ra := rb >> (imm & 31), arithmetic.
        .text
        li      r1, 0x80000000
        srai    r2, r1, 31      ; -1
        li      r3, -16
        srai    r4, r3, 2       ; -4
        srai    r5, r3, 32      ; count 0: -16
        li      r6, 0x40000000
        srai    r7, r6, 30      ; 1
        srai    r8, r3, 33      ; count 1: -8
        halt
;! r2 == -1
;! r4 == -4
;! r5 == -16
;! r7 == 1
;! r8 == -8
