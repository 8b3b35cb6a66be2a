; bgeu: branch if ra >= rb, unsigned. r10 collects the cases that did NOT branch.
        .text
        li      r1, -1
        li      r2, 1
        li      r3, 0x80000000
        li      r4, 0x7FFFFFFF
        li      r10, 0
        bgeu    r1, r2, t1      ; 0xFFFFFFFF >= 1: taken
        ori     r10, r10, 1
t1:     bgeu    r2, r1, t2      ; not taken
        ori     r10, r10, 2
t2:     bgeu    r2, r2, t3      ; equal: taken
        ori     r10, r10, 4
t3:     bgeu    r4, r3, t4      ; 0x7FFFFFFF >= 0x80000000: not taken
        ori     r10, r10, 8
t4:     bgeu    r0, r2, t5      ; 0 >= 1: not taken
        ori     r10, r10, 16
t5:     halt
;! r10 == 2 | 8 | 16
