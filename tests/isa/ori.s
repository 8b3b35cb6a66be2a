; ori: ra := rb | imm.
        .text
        li      r1, 0x12345678
        ori     r2, r1, 0xFF
        ori     r3, r0, 0x80000000
        ori     r4, r1, -1
        ori     r5, r1, 0
        halt
;! r2 == 0x123456FF
;! r3 == 0x80000000
;! r4 == -1
;! r5 == 0x12345678
