; remu: ra := rb % rc, unsigned; rc = 0 traps.
        .text
        li      r1, 7
        li      r2, 2
        remu    r3, r1, r2      ; 1
        li      r4, -1
        li      r5, 10
        remu    r6, r4, r5      ; 4294967295 % 10 = 5
        li      r7, -8
        li      r8, 3
        remu    r9, r7, r8      ; 4294967288 % 3 = 2 (a signed remainder would be -2)
        li      r10, 5
        remu    r11, r10, r1    ; 5
        remu    r12, r1, r1     ; 0
        remu    r13, r1, r0     ; by zero: trap
        halt
;! r3 == 1
;! r6 == 5
;! r9 == 2
;! r11 == 5
;! r12 == 0
;! trap "trap:" "remu r13, r1, r0" "tests/isa/remu.s:15"
