; flt: ra := (rb < rc) ? 1 : 0, float order (NaN compares false, -0 == +0).
        .text
        li      r1, 1.0
        li      r2, 2.0
        flt     r3, r1, r2              ; 1
        flt     r4, r2, r1              ; 0
        flt     r5, r1, r1              ; 0
        li      r6, 0x7FC00000
        flt     r7, r6, r1              ; NaN: 0
        flt     r8, r1, r6              ; 0
        li      r9, 0x80000000
        flt     r10, r9, r0             ; -0 < +0: 0
        li      r11, -2.0
        flt     r12, r11, r1            ; 1 (a signed-int compare of the bits would say 0)
        li      r13, 0xFF800000
        li      r14, 0x7F800000
        flt     r15, r13, r14           ; 1
        halt
;! r3 == 1
;! r4 == 0
;! r5 == 0
;! r7 == 0
;! r8 == 0
;! r10 == 0
;! r12 == 1
;! r15 == 1
