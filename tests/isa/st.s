; st: SM[rb + imm] := ra; a misaligned address traps.
        .data
        .word   1, 2, 3
        .text
        li      r1, 0x600DF00D
        st      r1, r0, 4               ; overwrites the second word of the image
        li      r2, 4096
        st      r2, r2, -96             ; SM[4000] = 4096
        li      r3, 1048572
        st      r1, r3, 0               ; the last word
        ld      r4, r0, 4
        st      r1, r0, 1               ; misaligned: trap
        halt
;! mem scene[0] == 1
;! mem scene[4] == 0x600DF00D
;! mem scene[8] == 3
;! mem scene[4000] == 4096
;! mem scene[1048572] == 0x600DF00D
;! r4 == 0x600DF00D
;! trap "st r1, r0, 1" "tests/isa/st.s:12"
