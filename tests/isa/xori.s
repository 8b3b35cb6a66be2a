; xori: ra := rb ^ imm.
        .text
        li      r1, 0x12345678
        xori    r2, r1, 0xFF
        xori    r3, r1, -1      ; complement
        xori    r4, r1, 0x12345678 ; 0
        xori    r5, r0, 0x80000000
        halt
;! r2 == 0x12345687
;! r3 == 0xEDCBA987
;! r4 == 0
;! r5 == 0x80000000
