; spld: ra := SP[rb + imm]. The .spad section is loaded into the scratchpad at address 0.
        .spad
        .word   11, 22, 33, 44
        .word   0xDEADBEEF
        .float  1.5
        .text
        spld    r1, r0, 0               ; 11
        li      r2, 8
        spld    r3, r2, 4               ; SP[12] = 44
        spld    r4, r2, -4              ; SP[4] = 22
        spld    r5, r0, 16
        spld    r6, r0, 20              ; 1.5
        spld    r7, r0, 24              ; past the image: 0
        spld    r8, r0, 65532           ; the last word of 64 KiB: 0
        li      r9, 65536
        spld    r10, r9, 0              ; one past the end: trap
        halt
;! r1 == 11
;! r3 == 44
;! r4 == 22
;! r5 == 0xDEADBEEF
;! r6 ==f 1.5
;! r7 == 0
;! r8 == 0
;! trap "spld r10, r9, 0" "tests/isa/spld.s:16"
