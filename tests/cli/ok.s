; tests/cli/ok.s -- a program that halts normally, with scene-memory and scratchpad data.
VALUE = 7
        .data
        .word   1, 2, 3
        .float  -0.5
        .spad
        .float  2.5
        .word   0xCAFE
        .text
        li      r1, 42
        rdn     r2
        ld      r3, r0, 8               ; 3
        spld    r4, r0, 0               ; 2.5
        addi    r5, r1, VALUE           ; 49
        viota   v1
        li      r6, 0x7FC00000
loop:   addi    r7, r7, 1
        blt     r7, r5, loop
        halt
