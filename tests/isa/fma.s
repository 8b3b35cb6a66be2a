; fma: ra := rb * rc + rd with a single rounding. (1 + 2^-12)^2 - 1 = 2^-11 + 2^-24 exactly;
; rounding the product first would lose the 2^-24.
        .text
        li      r1, 0x3F800800          ; 1 + 2^-12
        li      r2, -1.0
        fma     r3, r1, r1, r2          ; 2^-11 + 2^-24 = 0x3A000400
        li      r4, 2.0
        li      r5, 3.0
        li      r6, 4.0
        fma     r7, r4, r5, r6          ; 10
        li      r8, 0x7F800000
        fma     r9, r8, r0, r4          ; inf * 0 + 2 = NaN
        fma     r10, r4, r5, r2         ; 2 * 3 - 1 = 5
        fma     r4, r4, r4, r4          ; destination is a source: 2 * 2 + 2 = 6
        halt
;! r3 == 0x3A000400
;! r3 ==f exp2(-11) + exp2(-24)
;! r7 ==f 10.0
;! r9 ==f nan
;! r10 ==f 5.0
;! r4 ==f 6.0
