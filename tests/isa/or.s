; or: ra := rb | rc.
        .text
        li      r1, 0xF0F0F0F0
        li      r2, 0xFF00FF00
        or      r3, r1, r2
        or      r4, r1, r0      ; identity
        li      r5, 0x80000000
        li      r6, 1
        or      r7, r5, r6
        halt
;! r3 == 0xFFF0FFF0
;! r4 == 0xF0F0F0F0
;! r7 == 0x80000001
