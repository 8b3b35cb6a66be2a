; rdn: ra := N, the machine's SIMD width (a run-time parameter, not in the program).
        .text
        rdn     r1
        shli    r2, r1, 2       ; bytes in one vector: 4N
        rdn     r0
        mpop    r3, m0          ; m0 has all N lanes at reset
        halt
;! r1 == N
;! r2 == 4 * N
;! r0 == N
;! r3 == N
