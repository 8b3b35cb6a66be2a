; fle: ra := (rb <= rc) ? 1 : 0.
        .text
        li      r1, 1.0
        li      r2, 2.0
        fle     r3, r1, r1              ; 1
        fle     r4, r2, r1              ; 0
        fle     r5, r1, r2              ; 1
        li      r6, 0x7FC00000
        fle     r7, r6, r6              ; NaN: 0
        li      r9, 0x80000000
        fle     r10, r9, r0             ; -0 <= +0: 1
        fle     r11, r0, r9             ; +0 <= -0: 1
        li      r12, -1.0
        li      r13, -2.0
        fle     r14, r12, r13           ; -1 <= -2: 0
        halt
;! r3 == 1
;! r4 == 0
;! r5 == 1
;! r7 == 0
;! r10 == 1
;! r11 == 1
;! r14 == 0
