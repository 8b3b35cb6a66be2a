; tests/cli/define.s -- VALUE comes from the command line (sfasm -D VALUE=1234).
        .text
        li      r1, VALUE
        halt
