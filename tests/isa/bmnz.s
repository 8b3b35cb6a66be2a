; bmnz: branch if mask ma has any lane set. r10 collects the cases that did NOT branch.
        .text
        li      r10, 0
        bmnz    m1, t1          ; m1 empty at reset: not taken
        ori     r10, r10, 1
t1:     bmnz    m0, t2          ; all lanes: taken
        ori     r10, r10, 2
t2:     li      r1, 1
        mtail   m2, r1          ; lane 0 only
        bmnz    m2, t3          ; taken
        ori     r10, r10, 4
t3:     mnot    m3, m0          ; none
        bmnz    m3, t4          ; not taken
        ori     r10, r10, 8
t4:     rdn     r2
        addi    r2, r2, -1
        viota   v0
        vbcast  v1, r2
        vieq    m4, v0, v1      ; the last lane only
        bmnz    m4, t5          ; taken
        ori     r10, r10, 16
t5:     li      r4, 0           ; loop: shrink a tail mask until it is empty
        li      r5, 3
loop:   mtail   m5, r5
        addi    r5, r5, -1
        addi    r4, r4, 1
        bmnz    m5, loop        ; lanes < 3, < 2, < 1 non-empty; < 0 empty
        halt
;! r10 == 1 | 8
;! r4 == 4
;! r5 == -1
