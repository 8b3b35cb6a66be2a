; shli: ra := rb << (imm & 31).
        .text
        li      r1, 1
        shli    r2, r1, 31      ; 0x80000000
        li      r3, 0x12345678
        shli    r4, r3, 32      ; count 0
        shli    r5, r3, 33      ; count 1
        shli    r6, r3, 4
        shli    r7, r3, 0
        halt
;! r2 == 0x80000000
;! r4 == 0x12345678
;! r5 == 0x2468ACF0
;! r6 == 0x23456780
;! r7 == 0x12345678
