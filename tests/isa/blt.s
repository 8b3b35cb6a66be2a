; blt: branch if ra < rb, signed. r10 collects the cases that did NOT branch.
        .text
        li      r1, -1
        li      r2, 1
        li      r3, 0x80000000  ; INT32_MIN
        li      r4, 0x7FFFFFFF  ; INT32_MAX
        li      r10, 0
        blt     r1, r2, t1      ; -1 < 1: taken
        ori     r10, r10, 1
t1:     blt     r2, r1, t2      ; 1 < -1: not taken
        ori     r10, r10, 2
t2:     blt     r2, r2, t3      ; 1 < 1: not taken
        ori     r10, r10, 4
t3:     blt     r3, r4, t4      ; INT_MIN < INT_MAX: taken (unsigned would say no)
        ori     r10, r10, 8
t4:     blt     r4, r3, t5      ; not taken
        ori     r10, r10, 16
t5:     li      r11, -3         ; loop from -3 up to 4
loop:   addi    r11, r11, 1
        li      r12, 4
        blt     r11, r12, loop
        halt
;! r10 == 2 | 4 | 16
;! r11 == 4
