; bltu: branch if ra < rb, unsigned. r10 collects the cases that did NOT branch.
        .text
        li      r1, -1          ; 0xFFFFFFFF: the largest unsigned value
        li      r2, 1
        li      r3, 0x80000000
        li      r4, 0x7FFFFFFF
        li      r10, 0
        bltu    r1, r2, t1      ; 0xFFFFFFFF < 1: not taken
        ori     r10, r10, 1
t1:     bltu    r2, r1, t2      ; taken
        ori     r10, r10, 2
t2:     bltu    r2, r2, t3      ; equal: not taken
        ori     r10, r10, 4
t3:     bltu    r4, r3, t4      ; 0x7FFFFFFF < 0x80000000: taken (signed would say no)
        ori     r10, r10, 8
t4:     bltu    r0, r2, t5      ; 0 < 1: taken
        ori     r10, r10, 16
t5:     halt
;! r10 == 1 | 4
