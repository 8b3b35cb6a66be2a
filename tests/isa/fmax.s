; fmax: ra := rc > rb ? rc : rb. A NaN in rc gives rb; a NaN in rb gives NaN; of two zeros, rb.
        .text
        li      r1, 1.0
        li      r2, 2.0
        fmax    r3, r1, r2              ; 2
        fmax    r4, r2, r1              ; 2
        li      r5, -3.0
        fmax    r6, r5, r2              ; 2
        li      r7, 0x7FC00000
        fmax    r8, r2, r7              ; NaN in rc: 2
        fmax    r9, r7, r2              ; NaN in rb: NaN
        li      r10, 0x80000000
        fmax    r11, r0, r10            ; rb = +0: +0
        fmax    r12, r10, r0            ; rb = -0, +0 > -0 is false: -0
        li      r13, 0x7F800000
        fmax    r14, r2, r13            ; +inf
        halt
;! r3 ==f 2.0
;! r4 ==f 2.0
;! r6 ==f 2.0
;! r8 ==f 2.0
;! r9 ==f nan
;! r11 == 0
;! r12 == 0x80000000
;! r14 == 0x7F800000
