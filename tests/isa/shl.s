; shl: ra := rb << (rc & 31): counts of 32 and more use their low 5 bits.
        .text
        li      r1, 1
        li      r2, 31
        shl     r3, r1, r2      ; 0x80000000
        li      r4, 0x12345678
        li      r5, 32
        shl     r6, r4, r5      ; 32 & 31 = 0: unchanged
        li      r7, 33
        shl     r8, r4, r7      ; by 1
        li      r9, -1
        shl     r10, r1, r9     ; -1 & 31 = 31
        li      r11, 4
        shl     r12, r4, r11    ; 0x23456780
        li      r13, 0x80000000
        shl     r14, r13, r1    ; the bit falls off: 0
        halt
;! r3 == 0x80000000
;! r6 == 0x12345678
;! r8 == 0x2468ACF0
;! r10 == 0x80000000
;! r12 == 0x23456780
;! r14 == 0
