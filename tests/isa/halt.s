; halt: stops the program; nothing after it runs.
        .text
        li      r1, 1
        halt
        li      r1, 2           ; never executed
        halt
;! r1 == 1
;! stat total == 2
;! stat op.halt == 1
;! stat op.li == 1
