; sra: ra := rb >> (rc & 31), arithmetic (sign bit shifted in).
        .text
        li      r1, 0x80000000
        li      r2, 31
        sra     r3, r1, r2      ; -1
        li      r4, -16
        li      r5, 2
        sra     r6, r4, r5      ; -4
        li      r7, 32
        sra     r8, r4, r7      ; count 0: -16
        li      r9, 0x40000000
        li      r10, 30
        sra     r11, r9, r10    ; 1 (positive: zeros shifted in)
        li      r12, 33
        sra     r13, r4, r12    ; count 1: -8
        li      r14, -1
        sra     r15, r14, r2    ; -1
        halt
;! r3 == -1
;! r6 == -4
;! r8 == -16
;! r11 == 1
;! r13 == -8
;! r15 == -1
