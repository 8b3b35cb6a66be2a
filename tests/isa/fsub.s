; fsub: ra := rb - rc.
        .text
        li      r1, 5.5
        li      r2, 2.25
        fsub    r3, r1, r2              ; 3.25
        fsub    r4, r2, r1              ; -3.25
        li      r5, 0x7F800000
        fsub    r6, r5, r5              ; inf - inf = NaN
        fsub    r7, r1, r1              ; x - x = +0
        li      r8, 0x80000000
        fsub    r9, r8, r0              ; -0 - +0 = -0
        li      r10, 1.0
        li      r11, 1e-8
        fsub    r12, r10, r11           ; below half an ulp: 1.0
        li      r13, 0.3
        li      r14, 0.1
        fsub    r15, r13, r14
        halt
;! r3 ==f 3.25
;! r4 ==f -3.25
;! r6 ==f nan
;! r7 == 0
;! r9 == 0x80000000
;! r12 ==f 1.0
;! r15 ==f float(float(0.3) - float(0.1))
