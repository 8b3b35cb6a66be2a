; jal: ra := pc + 1 (the instruction after the call), pc := label. r0 is an ordinary register.
        .text
        li      r5, 0           ; 0
        jal     r31, sub        ; 1
ret1:   addi    r5, r5, 1       ; 2
        jal     r0, sub2        ; 3
ret2:   halt                    ; 4
sub:    addi    r5, r5, 10      ; 5
        jr      r31             ; 6
sub2:   mov     r6, r0          ; 7
        jr      r0              ; 8
;! r31 == 2
;! r31 == ret1
;! r0 == 4
;! r6 == ret2
;! r5 == 11
;! stat op.jal == 2
