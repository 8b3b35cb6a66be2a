; tests/cli/errors.s -- four independent errors; sfasm must report every one with file:line:col.
        li      r1, 5
        frob    r2, r3                  ; unknown mnemonic
        add     r1, r2                  ; missing operand
        li      r40, 1                  ; no such register
        jmp     nowhere                 ; undefined label
        halt
