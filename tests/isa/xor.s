; xor: ra := rb ^ rc.
        .text
        li      r1, 0xF0F0F0F0
        li      r2, 0xFF00FF00
        xor     r3, r1, r2
        xor     r4, r1, r1      ; 0
        li      r5, -1
        xor     r6, r1, r5      ; complement
        halt
;! r3 == 0x0FF00FF0
;! r4 == 0
;! r6 == 0x0F0F0F0F
