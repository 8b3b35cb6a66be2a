; slt: ra := (rb < rc, signed) ? 1 : 0.
        .text
        li      r1, -1
        li      r2, 1
        li      r3, 0x80000000
        li      r4, 0x7FFFFFFF
        slt     r5, r1, r2      ; 1
        slt     r6, r2, r1      ; 0
        slt     r7, r2, r2      ; 0
        slt     r8, r3, r4      ; INT_MIN < INT_MAX: 1
        slt     r9, r4, r3      ; 0
        li      r10, 55
        slt     r10, r10, r10   ; destination is a source: 0
        halt
;! r5 == 1
;! r6 == 0
;! r7 == 0
;! r8 == 1
;! r9 == 0
;! r10 == 0
