; bmz: branch if mask ma has no lane set (only lanes < N exist). r10 collects the cases that
; did NOT branch.
        .text
        li      r10, 0
        bmz     m1, t1          ; m1 is empty at reset: taken
        ori     r10, r10, 1
t1:     bmz     m0, t2          ; m0 = all lanes at reset: not taken
        ori     r10, r10, 2
t2:     li      r1, 1
        mtail   m2, r1          ; lane 0 only
        bmz     m2, t3          ; not taken
        ori     r10, r10, 4
t3:     mnot    m3, m0          ; ~all within N lanes = none
        bmz     m3, t4          ; taken
        ori     r10, r10, 8
t4:     rdn     r2
        addi    r2, r2, -1
        li      r3, 0
        viota   v0
        vbcast  v1, r2
        vieq    m4, v0, v1      ; only the last lane, N - 1
        bmz     m4, t5          ; not taken
        ori     r10, r10, 16
t5:     halt
;! r10 == 2 | 4 | 16
;! m4[l] == (l == N - 1)
