; shr: ra := rb >> (rc & 31), logical (zeros shifted in).
        .text
        li      r1, 0x80000000
        li      r2, 31
        shr     r3, r1, r2      ; 1
        li      r4, -1
        li      r5, 4
        shr     r6, r4, r5      ; 0x0FFFFFFF
        li      r7, 32
        shr     r8, r4, r7      ; count 0: unchanged
        li      r9, 36
        shr     r10, r4, r9     ; count 4
        li      r11, 0x12345678
        li      r12, 8
        shr     r13, r11, r12   ; 0x00123456
        halt
;! r3 == 1
;! r6 == 0x0FFFFFFF
;! r8 == 0xFFFFFFFF
;! r10 == 0x0FFFFFFF
;! r13 == 0x00123456
