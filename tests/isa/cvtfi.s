; cvtfi: ra := (int) rb, truncated toward zero; NaN gives 0; out of range saturates.
        .text
        li      r1, 1.9
        cvtfi   r2, r1                  ; 1
        li      r3, -1.9
        cvtfi   r4, r3                  ; -1
        li      r5, 0x7FC00000
        cvtfi   r6, r5                  ; NaN: 0
        li      r7, 3.0e9
        cvtfi   r8, r7                  ; INT32_MAX
        li      r9, -3.0e9
        cvtfi   r10, r9                 ; INT32_MIN
        li      r11, 0x7F800000
        cvtfi   r12, r11                ; +inf: INT32_MAX
        li      r13, 0xFF800000
        cvtfi   r14, r13                ; -inf: INT32_MIN
        li      r15, 2147483520.0       ; the largest float below 2^31
        cvtfi   r16, r15
        li      r17, -2147483648.0
        cvtfi   r18, r17                ; exactly INT32_MIN
        li      r19, 2147483648.0
        cvtfi   r20, r19                ; 2^31: saturates
        li      r21, 0x80000000
        cvtfi   r22, r21                ; -0: 0
        li      r23, -0.5
        cvtfi   r24, r23                ; 0
        halt
;! r2 == 1
;! r4 == -1
;! r6 == 0
;! r8 == 0x7FFFFFFF
;! r10 == 0x80000000
;! r12 == 0x7FFFFFFF
;! r14 == 0x80000000
;! r16 == 2147483520
;! r18 == 0x80000000
;! r20 == 0x7FFFFFFF
;! r22 == 0
;! r24 == 0
