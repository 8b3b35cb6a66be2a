; sapp: append the exec-mask lanes of vb, in lane order, to IDM[ra], IDM[ra + 4], ...;
; ra += 4 * popcount(E).
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vmuli   v1, v0, 10
        vaddi   v1, v1, 1               ; 10l + 1
        li      r1, 100
        sapp    r1, v1 @m2              ; the odd lanes, packed
        mov     r2, r1
        sapp    r1, v1                  ; all N lanes
        mov     r3, r1
        sapp    r1, v1 @m7              ; empty mask: nothing, pointer unchanged
        halt
;! r2 == 100 + 4 * (N / 2)
;! if l < N / 2: mem idm[100 + 4 * l] == 10 * (2 * l + 1) + 1
;! mem idm[100 + 4 * (N / 2) + 4 * l] == 10 * l + 1
;! r3 == 100 + 4 * (N / 2) + 4 * N
;! r1 == 100 + 4 * (N / 2) + 4 * N
;! mem idm[100 + 4 * (N / 2 + N)] == 0
;! mem idm[96] == 0
