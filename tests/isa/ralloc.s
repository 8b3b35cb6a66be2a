; ralloc: va[l] := rb + (number of exec-mask lanes below l); rb += popcount(E). Inactive lanes
; keep their values.
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r1, 7
        vli     v1, 0xAAAA
        ralloc  v1, r1 @m2              ; odd lanes get 7, 8, 9, ...
        mov     r2, r1
        ralloc  v2, r1                  ; all lanes: consecutive slots
        mov     r3, r1
        vli     v3, 0xBBBB
        ralloc  v3, r1 @m7              ; empty mask: nothing
        halt
;! v1[l] == (l % 2 == 1 ? 7 + l / 2 : 0xAAAA)
;! r2 == 7 + N / 2
;! v2[l] == 7 + N / 2 + l
;! r3 == 7 + N / 2 + N
;! v3[l] == 0xBBBB
;! r1 == 7 + N / 2 + N
