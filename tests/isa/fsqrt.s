; fsqrt: ra := sqrt(rb), correctly rounded.
        .text
        li      r1, 4.0
        fsqrt   r2, r1                  ; 2
        li      r3, 2.0
        fsqrt   r4, r3                  ; 0x3FB504F3
        li      r5, -1.0
        fsqrt   r6, r5                  ; NaN
        li      r7, 0x80000000
        fsqrt   r8, r7                  ; sqrt(-0) = -0
        li      r9, 0x7F800000
        fsqrt   r10, r9                 ; inf
        fsqrt   r11, r0                 ; 0
        li      r12, 10.0
        fsqrt   r13, r12
        halt
;! r2 ==f 2.0
;! r4 == 0x3FB504F3
;! r6 ==f nan
;! r8 == 0x80000000
;! r10 == 0x7F800000
;! r11 == 0
;! r13 ==f sqrt(10)
