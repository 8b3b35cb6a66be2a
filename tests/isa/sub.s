; sub: ra := rb - rc, wrapping.
        .text
        li      r1, 1
        sub     r2, r0, r1      ; 0 - 1 = -1
        li      r3, 0x80000000
        sub     r4, r3, r1      ; INT_MIN - 1 wraps to INT_MAX
        li      r5, 5
        li      r6, 7
        sub     r7, r5, r6      ; -2
        sub     r8, r6, r5      ; 2
        sub     r9, r5, r5      ; 0
        li      r10, -3
        sub     r10, r10, r6    ; destination is a source: -10
        halt
;! r2 == -1
;! r4 == 0x7FFFFFFF
;! r7 == -2
;! r8 == 2
;! r9 == 0
;! r10 == -10
