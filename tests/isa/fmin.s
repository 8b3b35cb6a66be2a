; fmin: ra := rc < rb ? rc : rb. A NaN in rc gives rb; a NaN in rb gives rb (NaN); of two
; zeros the answer is rb (-0 < +0 is false).
        .text
        li      r1, 1.0
        li      r2, 2.0
        fmin    r3, r1, r2              ; 1
        fmin    r4, r2, r1              ; 1
        li      r5, -3.0
        fmin    r6, r2, r5              ; -3
        li      r7, 0x7FC00000          ; NaN
        fmin    r8, r2, r7              ; NaN in rc: rb = 2
        fmin    r9, r7, r2              ; NaN in rb: NaN
        li      r10, 0x80000000         ; -0
        fmin    r11, r0, r10            ; rb = +0, rc = -0: +0
        fmin    r12, r10, r0            ; rb = -0, rc = +0: -0
        li      r13, 0xFF800000         ; -inf
        fmin    r14, r2, r13            ; -inf
        halt
;! r3 ==f 1.0
;! r4 ==f 1.0
;! r6 ==f -3.0
;! r8 ==f 2.0
;! r9 ==f nan
;! r11 == 0
;! r12 == 0x80000000
;! r14 == 0xFF800000
