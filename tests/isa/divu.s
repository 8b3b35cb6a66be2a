; divu: ra := rb / rc, unsigned; rc = 0 traps.
        .text
        li      r1, 7
        li      r2, 2
        divu    r3, r1, r2      ; 3
        li      r4, -1
        divu    r5, r4, r2      ; 0xFFFFFFFF / 2 = 0x7FFFFFFF (unsigned)
        li      r6, -8
        divu    r7, r6, r2      ; 0xFFFFFFF8 / 2 = 0x7FFFFFFC
        li      r8, 5
        divu    r9, r8, r1      ; 5 / 7 = 0
        divu    r10, r4, r4     ; 1
        divu    r11, r0, r1     ; 0
        li      r12, 77
        divu    r12, r1, r0     ; division by zero: trap
        halt
;! r3 == 3
;! r5 == 0x7FFFFFFF
;! r7 == 0x7FFFFFFC
;! r9 == 0
;! r10 == 1
;! r11 == 0
;! trap "trap:" "divu r12, r1, r0" "tests/isa/divu.s:15"
