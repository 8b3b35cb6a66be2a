; mpop: ra := number of lanes set in mb.
        .text
        viota   v0
        li      r1, 5
        mtail   m1, r1                  ; m1: lanes < 5
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        mpop    r10, m0                 ; N
        mpop    r11, m1                 ; min(5, N)
        mpop    r12, m2                 ; odd lanes: N / 2
        mpop    r13, m7                 ; 0
        mpop    r1, m1                  ; overwrites the source of m1's count
        halt
;! r10 == N
;! r11 == min(5, N)
;! r12 == N / 2
;! r13 == 0
;! r1 == min(5, N)
