; muli: ra := low 32 bits of rb * imm.
        .text
        li      r1, 3
        muli    r2, r1, -7      ; -21
        li      r3, 0x10000
        muli    r4, r3, 0x10000 ; 0
        li      r5, 0x9E3779B9
        muli    r6, r5, 3       ; 0xDAA66D2B (bits above 31 lost)
        muli    r7, r1, 0       ; 0
        muli    r1, r1, 100000  ; destination is the source
        halt
;! r2 == -21
;! r4 == 0
;! r6 == 0xDAA66D2B
;! r7 == 0
;! r1 == 300000
