; andi: ra := rb & imm (all 32 immediate bits).
        .text
        li      r1, 0x12345678
        andi    r2, r1, 0xFF
        andi    r3, r1, 0xFFFF0000
        andi    r4, r1, -1
        andi    r5, r1, 0
        halt
;! r2 == 0x78
;! r3 == 0x12340000
;! r4 == 0x12345678
;! r5 == 0
