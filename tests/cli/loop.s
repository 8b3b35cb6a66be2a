; tests/cli/loop.s -- never halts: stopped by --max-instructions (exit 3).
        .text
        li      r1, 0
again:  addi    r1, r1, 1
        jmp     again
