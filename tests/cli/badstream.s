; tests/cli/badstream.s -- sfetch with a stream begin after its end: trap (exit 3).
        .text
        li      r1, 64
        li      r2, 32
        sfetch  v1, m1, r1, r2
        halt
