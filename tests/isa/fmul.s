; fmul: ra := rb * rc.
        .text
        li      r1, 1.5
        li      r2, -2.0
        fmul    r3, r1, r2              ; -3
        li      r4, -1.0
        fmul    r5, r0, r4              ; 0 * -1 = -0
        li      r6, 0x7F800000
        fmul    r7, r6, r0              ; inf * 0 = NaN
        li      r8, 1e20
        fmul    r9, r8, r8              ; overflow: +inf
        li      r10, 1e-30
        fmul    r11, r10, r10           ; underflow: +0
        li      r12, 0.1
        li      r13, 3.0
        fmul    r14, r12, r13
        fmul    r15, r6, r4             ; -inf
        halt
;! r3 ==f -3.0
;! r5 == 0x80000000
;! r7 ==f nan
;! r9 == 0x7F800000
;! r11 == 0
;! r14 ==f float(float(0.1) * 3)
;! r15 == 0xFF800000
