; beq: branch if ra == rb (all 32 bits). Each case skips `ori r10, r10, bit` when taken, so r10
; collects the cases that did NOT branch.
        .text
        li      r1, 5
        li      r2, 5
        li      r3, -5
        li      r4, 0x80000000
        li      r10, 0
        beq     r1, r2, t1      ; 5 == 5: taken
        ori     r10, r10, 1
t1:     beq     r1, r3, t2      ; 5 == -5: not taken
        ori     r10, r10, 2
t2:     beq     r3, r3, t3      ; same register: taken
        ori     r10, r10, 4
t3:     beq     r4, r0, t4      ; 0x80000000 == 0: not taken (only the sign bit differs)
        ori     r10, r10, 8
t4:     li      r11, 0          ; a counted loop ending on equality: 0, 1, ..., 6
loop:   addi    r11, r11, 1
        li      r12, 6
        beq     r11, r12, out
        jmp     loop
out:    halt
;! r10 == 2 | 8
;! r11 == 6
