; mfirst: ra := lowest lane set in mb, or -1 when none.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mfirst  r10, m0                 ; 0
        mfirst  r11, m7                 ; -1
        mfirst  r12, m2                 ; 1, or -1 when N = 1
        mnot    m3, m1
        mfirst  r13, m3                 ; 5, or -1 when N <= 5
        rdn     r2
        addi    r2, r2, -1
        vbcast  v3, r2
        vieq    m4, v0, v3
        mfirst  r14, m4                 ; N - 1
        halt
;! r10 == 0
;! r11 == -1
;! r12 == (N >= 2 ? 1 : -1)
;! r13 == (N > 5 ? 5 : -1)
;! r14 == N - 1
