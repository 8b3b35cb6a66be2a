; ffloor: ra := floor(rb), toward -inf; zeros, infinities and NaN pass through.
        .text
        li      r1, 1.5
        ffloor  r2, r1                  ; 1
        li      r3, -1.5
        ffloor  r4, r3                  ; -2
        li      r5, -0.5
        ffloor  r6, r5                  ; -1
        li      r7, 2.0
        ffloor  r8, r7                  ; 2
        li      r9, 0x80000000
        ffloor  r10, r9                 ; -0
        li      r11, 0.5
        ffloor  r12, r11                ; +0
        li      r13, 1e10
        ffloor  r14, r13                ; already an integer
        li      r15, 0x7FC00000
        ffloor  r16, r15                ; NaN
        li      r17, 0xFF800000
        ffloor  r18, r17                ; -inf
        li      r19, 8388607.5
        ffloor  r20, r19                ; 8388607
        halt
;! r2 ==f 1.0
;! r4 ==f -2.0
;! r6 ==f -1.0
;! r8 ==f 2.0
;! r10 == 0x80000000
;! r12 == 0
;! r14 ==f 1e10
;! r16 ==f nan
;! r18 == 0xFF800000
;! r20 ==f 8388607.0
