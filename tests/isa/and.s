; and: ra := rb & rc.
        .text
        li      r1, 0xF0F0F0F0
        li      r2, 0xFF00FF00
        and     r3, r1, r2
        li      r4, -1
        and     r5, r1, r4      ; identity
        and     r6, r1, r0      ; 0
        and     r1, r1, r1      ; itself
        halt
;! r3 == 0xF000F000
;! r5 == 0xF0F0F0F0
;! r6 == 0
;! r1 == 0xF0F0F0F0
