; feq: ra := (rb == rc) ? 1 : 0, float equality (not bit equality).
        .text
        li      r1, 1.0
        li      r2, 2.0
        feq     r3, r1, r1              ; 1
        feq     r4, r1, r2              ; 0
        li      r5, 0x80000000
        feq     r6, r5, r0              ; -0 == +0: 1
        li      r7, 0x7FC00000
        feq     r8, r7, r7              ; NaN != NaN: 0
        li      r9, 1                   ; the smallest subnormal
        feq     r10, r9, r0             ; 0
        halt
;! r3 == 1
;! r4 == 0
;! r6 == 1
;! r8 == 0
;! r10 == 0
