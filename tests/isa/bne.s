; bne: branch if ra != rb. r10 collects the cases that did NOT branch.
        .text
        li      r1, 5
        li      r2, 5
        li      r3, -5
        li      r4, 0x80000000
        li      r10, 0
        bne     r1, r2, t1      ; 5 != 5: not taken
        ori     r10, r10, 1
t1:     bne     r1, r3, t2      ; taken
        ori     r10, r10, 2
t2:     bne     r3, r3, t3      ; same register: not taken
        ori     r10, r10, 4
t3:     bne     r4, r0, t4      ; sign bit only: taken
        ori     r10, r10, 8
t4:     li      r11, 10         ; backward loop: 10 down to 0
        li      r12, 0
loop:   addi    r11, r11, -1
        addi    r12, r12, 1
        bne     r11, r0, loop
        halt
;! r10 == 1 | 4
;! r11 == 0
;! r12 == 10
;! stat op.bne == 14
