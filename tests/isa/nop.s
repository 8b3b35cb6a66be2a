; nop: no operation. Registers, masks and the stream of instructions are unchanged; the pc
; simply moves on.
        .text
        li      r1, 5
        nop
        nop
        addi    r1, r1, 1
        halt
;! r1 == 6
;! r2 == 0
;! stat op.nop == 2
;! stat total == 5
;! m0 == (N == 64 ? -1 : (1 << N) - 1)
;! stat cat.other.control == 3
