; fdiv: ra := rb / rc, correctly rounded; IEEE results for zeros and infinities.
        .text
        li      r1, 1.0
        li      r2, 4.0
        fdiv    r3, r1, r2              ; 0.25
        li      r4, 3.0
        fdiv    r5, r1, r4              ; 1/3 = 0x3EAAAAAB
        fdiv    r6, r1, r0              ; 1 / +0 = +inf
        li      r7, -1.0
        fdiv    r8, r7, r0              ; -1 / +0 = -inf
        fdiv    r9, r0, r0              ; 0 / 0 = NaN
        li      r10, 0x80000000
        fdiv    r11, r1, r10            ; 1 / -0 = -inf
        li      r12, 0x7F800000
        fdiv    r13, r1, r12            ; 1 / inf = +0
        li      r14, 10.0
        fdiv    r15, r14, r4            ; 10/3
        halt
;! r3 ==f 0.25
;! r5 == 0x3EAAAAAB
;! r6 == 0x7F800000
;! r8 == 0xFF800000
;! r9 ==f nan
;! r11 == 0xFF800000
;! r13 == 0
;! r15 ==f 10.0 / 3.0
