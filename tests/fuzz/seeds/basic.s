; straight-line code, labels, branches, masks
N = 16
start:  li r1, N * 4
        rdn r2
        viota v0
loop:   mtail m1, r1
        vfadd v1, v2, v3 @m1
        vfma v4, v1, v2, v3 @m1
        vflt m2, v1, v4 @m1
        bmnz m2, loop
        addi r1, r1, -4
        bne r1, r0, loop
        stage 3
        jal r31, sub
        halt
sub:    jr r31
