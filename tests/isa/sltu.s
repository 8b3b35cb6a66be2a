; sltu: ra := (rb < rc, unsigned) ? 1 : 0.
        .text
        li      r1, -1
        li      r2, 1
        li      r3, 0x80000000
        li      r4, 0x7FFFFFFF
        sltu    r5, r1, r2      ; 0xFFFFFFFF < 1: 0
        sltu    r6, r2, r1      ; 1
        sltu    r7, r2, r2      ; 0
        sltu    r8, r3, r4      ; 0x80000000 < 0x7FFFFFFF: 0
        sltu    r9, r4, r3      ; 1
        sltu    r10, r0, r2     ; 0 < 1: 1
        halt
;! r5 == 0
;! r6 == 1
;! r7 == 0
;! r8 == 0
;! r9 == 1
;! r10 == 1
