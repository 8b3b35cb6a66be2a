; bge: branch if ra >= rb, signed. r10 collects the cases that did NOT branch.
        .text
        li      r1, -1
        li      r2, 1
        li      r3, 0x80000000
        li      r4, 0x7FFFFFFF
        li      r10, 0
        bge     r1, r2, t1      ; -1 >= 1: not taken
        ori     r10, r10, 1
t1:     bge     r2, r1, t2      ; 1 >= -1: taken
        ori     r10, r10, 2
t2:     bge     r2, r2, t3      ; 1 >= 1: taken
        ori     r10, r10, 4
t3:     bge     r3, r4, t4      ; INT_MIN >= INT_MAX: not taken
        ori     r10, r10, 8
t4:     bge     r4, r3, t5      ; taken
        ori     r10, r10, 16
t5:     halt
;! r10 == 1 | 8
