; mov: ra := rb. Registers are 0 at reset.
        .text
        li      r1, 0xDEADBEEF
        mov     r2, r1
        mov     r1, r1          ; to itself: unchanged
        mov     r0, r2          ; r0 is an ordinary register
        li      r3, 5
        mov     r3, r30         ; r30 is 0 at reset
        mov     r31, r0
        halt
;! r1 == 0xDEADBEEF
;! r2 == 0xDEADBEEF
;! r0 == 0xDEADBEEF
;! r3 == 0
;! r31 == 0xDEADBEEF
