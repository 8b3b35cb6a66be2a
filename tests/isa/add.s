; add: ra := rb + rc, wrapping at 32 bits.
        .text
        li      r1, 0x7FFFFFFF
        li      r2, 1
        add     r3, r1, r2      ; INT_MAX + 1 wraps to INT_MIN
        li      r4, -1
        add     r5, r4, r2      ; -1 + 1 = 0
        li      r6, 5
        li      r7, -7
        add     r8, r6, r7      ; -2
        li      r9, 0x80000000
        add     r10, r9, r9     ; 0x80000000 + 0x80000000 = 0 (carry lost)
        li      r11, 21
        add     r11, r11, r11   ; destination is a source: 42
        add     r12, r4, r4     ; -2
        halt
;! r3 == 0x80000000
;! r5 == 0
;! r8 == -2
;! r10 == 0
;! r11 == 42
;! r12 == 0xFFFFFFFE
