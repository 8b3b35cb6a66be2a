; spst: SP[rb + imm] := ra; a misaligned address traps.
        .spad
        .word   1, 2, 3
        .text
        li      r1, 0x0BADCAFE
        spst    r1, r0, 4               ; overwrites the image's second word
        li      r2, 200
        spst    r2, r2, -100            ; SP[100] = 200
        li      r3, 65532
        spst    r1, r3, 0               ; the last word
        spld    r4, r0, 4               ; read back
        spst    r1, r0, 6               ; misaligned: trap
        halt
;! mem spad[0] == 1
;! mem spad[4] == 0x0BADCAFE
;! mem spad[8] == 3
;! mem spad[100] == 200
;! mem spad[65532] == 0x0BADCAFE
;! r4 == 0x0BADCAFE
;! trap "spst r1, r0, 6" "tests/isa/spst.s:12"
