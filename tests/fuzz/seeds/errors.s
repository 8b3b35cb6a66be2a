; every line here is wrong
        vfadd v1, r2, v3
        add r1, r2
        li r1, 0x100000000
        add r32, r1, r2
        add r1, r2, r3 @m1
        jmp nowhere
        stage 7
        li r1, "unterminated
.endif
.macro open
