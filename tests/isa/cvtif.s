; cvtif: ra := (float) signed rb, round to nearest even.
        .text
        li      r1, -1
        cvtif   r2, r1                  ; -1.0
        li      r3, 0x7FFFFFFF
        cvtif   r4, r3                  ; 2147483648.0
        li      r5, 16777217
        cvtif   r6, r5                  ; ties to even: 16777216.0
        li      r7, 0x80000000
        cvtif   r8, r7                  ; -2147483648.0 (signed)
        li      r9, 3
        cvtif   r10, r9                 ; 3.0
        cvtif   r11, r0                 ; +0
        li      r12, 16777219
        cvtif   r13, r12                ; ties to even: 16777220.0
        halt
;! r2 ==f -1.0
;! r4 == 0x4F000000
;! r6 ==f 16777216.0
;! r8 ==f -2147483648.0
;! r10 ==f 3.0
;! r11 == 0
;! r13 ==f 16777220.0
