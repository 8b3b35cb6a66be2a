; addi: ra := rb + imm, wrapping.
        .text
        li      r1, 0x7FFFFFFF
        addi    r2, r1, 1       ; INT_MIN
        addi    r3, r0, -5
        addi    r4, r3, 0xFFFFFFFF ; imm -1
        addi    r5, r0, 0x12345678
        addi    r5, r5, 0x11111111 ; destination is the source
        addi    r6, r3, 5       ; 0
        addi    r7, r0, -65537
        halt
;! r2 == 0x80000000
;! r3 == -5
;! r4 == -6
;! r5 == 0x23456789
;! r6 == 0
;! r7 == -65537
