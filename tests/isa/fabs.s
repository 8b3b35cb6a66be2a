; fabs: ra := |rb| (the sign cleared).
        .text
        li      r1, -1.5
        fabs    r2, r1                  ; 1.5
        li      r3, 0x80000000
        fabs    r4, r3                  ; |-0| = +0
        li      r5, 0xFF800000
        fabs    r6, r5                  ; +inf
        li      r7, 2.5
        fabs    r8, r7                  ; 2.5
        li      r9, 0xFFC00000          ; a NaN with the sign set
        fabs    r10, r9
        halt
;! r2 ==f 1.5
;! r4 == 0
;! r6 == 0x7F800000
;! r8 ==f 2.5
;! r10 ==f nan
