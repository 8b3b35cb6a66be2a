; jmp: pc := label, forward and backward.
        .text
        li      r1, 1
        jmp     skip
        li      r1, 2           ; skipped
skip:   addi    r1, r1, 10
        jmp     fwd
back:   addi    r1, r1, 100
        halt
fwd:    jmp     back
        li      r1, 0           ; skipped
;! r1 == 111
;! stat op.jmp == 3
;! stat total == 7
