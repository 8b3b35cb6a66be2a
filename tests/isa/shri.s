; shri: ra := rb >> (imm & 31), logical.
        .text
        li      r1, 0x80000000
        shri    r2, r1, 31      ; 1
        li      r3, -1
        shri    r4, r3, 4       ; 0x0FFFFFFF
        shri    r5, r3, 32      ; count 0
        shri    r6, r3, 63      ; count 31: 1
        halt
;! r2 == 1
;! r4 == 0x0FFFFFFF
;! r5 == -1
;! r6 == 1
