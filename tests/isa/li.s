; li: ra := imm, integers of every size, float immediates as binary32 bits, expressions and
; constants. r0 is an ordinary register.
K = 123
        .text
        li      r0, 7
        li      r1, -1
        li      r2, 0x80000000
        li      r3, 1.5
        li      r4, -0.0
        li      r5, 65537
        li      r6, -2147483648
        li      r7, 2 * 3 + 1
        li      r8, K
        li      r9, 0.1
        li      r10, 0xFFFFFFFF
        li      r11, -65536
        li      r31, 0x12345678
        halt
;! r0 == 7
;! r1 == -1
;! r1 == 0xFFFFFFFF
;! r2 == 0x80000000
;! r3 == 0x3FC00000
;! r3 ==f 1.5
;! r4 == 0x80000000
;! r5 == 65537
;! r6 == 0x80000000
;! r7 == 7
;! r8 == 123
;! r8 == K
;! r9 == 0x3DCCCCCD
;! r10 == -1
;! r11 == 0xFFFF0000
;! r31 == 0x12345678
;! r12 == 0
