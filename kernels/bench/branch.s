; kernels/bench/branch.s -- the bubble after a taken branch (branch.taken_penalty = 1).
;
;   0  li   r1, 3          ready 1
;   1  addi r1, r1, -1     (loop) r1 = 2            ready 2
;   2  bne  r1, r0, loop   taken: next fetch at 3 + 1 = 4, cycle 3 is a control stall
;   4  addi                r1 = 1
;   5  bne  taken          cycle 6 control
;   7  addi                r1 = 0
;   8  bne  not taken      no bubble
;   9  halt                cycles 10 = busy 8 + control 2
; With branch.taken_penalty = 3: each taken branch costs 3: cycles 14 = busy 8 + control 6.
;
;@ run default expect cycles=10 busy=8 control=2
;@ run penalty3 set branch.taken_penalty=3 expect cycles=14 busy=8 control=6

        .text
        li      r1, 3
loop:   addi    r1, r1, -1
        bne     r1, r0, loop
        halt
