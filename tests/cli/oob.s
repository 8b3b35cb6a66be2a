; tests/cli/oob.s -- reads past the end of scene memory: trap (exit 3).
        .text
        li      r1, 0x7FFFFFF0
        ld      r2, r1, 0
        halt
