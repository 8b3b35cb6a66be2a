; viota: va := lane index l, merge masking.
        .text
        viota   v1
        li      r1, 5
        mtail   m1, r1
        vli     v2, 99
        viota   v2 @m1                  ; lanes < 5
        rdn     r2
        addi    r2, r2, -1
        vext    r3, v1, 0               ; lane 0
        halt
;! v1[l] == l
;! v2[l] == (l < 5 ? l : 99)
;! r3 == 0
