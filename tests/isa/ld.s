; ld: ra := SM[rb + imm]. The .data section is loaded into scene memory at address 0.
        .data
tab:    .word   5, 6, 7
        .float  -2.5
        .word   0x80000000
        .text
        ld      r1, r0, 0               ; 5
        li      r2, 4
        ld      r3, r2, 4               ; SM[8] = 7
        ld      r4, r2, 8               ; -2.5
        ld      r5, r0, 16
        li      r6, tab                 ; a data label is its byte address
        ld      r7, r6, 4               ; 6
        li      r8, 1048576
        ld      r9, r8, -4              ; the last word of 1 MiB: 0
        ld      r10, r8, 0              ; one past the end: trap
        halt
;! r1 == 5
;! r3 == 7
;! r4 ==f -2.5
;! r5 == 0x80000000
;! r6 == 0
;! r7 == 6
;! r9 == 0
;! trap "ld r10, r8, 0" "tests/isa/ld.s:16"
