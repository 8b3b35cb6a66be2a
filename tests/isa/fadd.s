; fadd: ra := rb + rc, binary32, round to nearest even.
        .text
        li      r1, 1.5
        li      r2, 2.25
        fadd    r3, r1, r2              ; 3.75
        li      r4, 0.1
        li      r5, 0.2
        fadd    r6, r4, r5              ; rounded once: 0x3E99999A
        li      r7, 0x7F800000          ; +inf
        li      r8, 0xFF800000          ; -inf
        fadd    r9, r7, r8              ; inf + -inf = NaN
        fadd    r10, r7, r1             ; inf
        li      r11, 0x80000000         ; -0
        fadd    r12, r11, r11           ; -0 + -0 = -0
        fadd    r13, r11, r0            ; -0 + +0 = +0
        li      r14, 16777216.0
        li      r15, 1.0
        fadd    r16, r14, r15           ; 2^24 + 1 ties to even: 2^24
        li      r17, 3.0e38
        fadd    r18, r17, r17           ; overflow: +inf
        li      r19, 0x7FC00000
        fadd    r20, r19, r1            ; NaN
        fadd    r1, r1, r1              ; destination is a source: 3
        halt
;! r3 ==f 3.75
;! r6 == 0x3E99999A
;! r6 ==f float(float(0.1) + float(0.2))
;! r9 ==f nan
;! r10 == 0x7F800000
;! r12 == 0x80000000
;! r13 == 0
;! r16 ==f 16777216.0
;! r18 == 0x7F800000
;! r20 ==f nan
;! r1 ==f 3.0
