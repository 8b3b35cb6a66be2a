; data and scratchpad images
        ld r1, r0, table + 4
        spld r2, r0, stack
        halt
        .data
        .byte 1, 2, 255
        .align 4
table:  .word 0x11223344, -1, end - table
        .float 1.5, -2, .25
        .space 7, 0xAB
end:
        .spad
stack:  .space 64
        .word .
