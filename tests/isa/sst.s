; sst: IDM[rb + imm] := ra; a misaligned address traps.
        .text
        li      r1, 0xCAFEF00D
        sst     r1, r0, 0
        li      r2, 100
        sst     r2, r2, 4               ; IDM[104] = 100
        sst     r1, r2, -4              ; IDM[96]
        li      r3, 32764
        sst     r1, r3, 0               ; the last word
        sst     r1, r0, 2               ; misaligned: trap
        halt
;! mem idm[0] == 0xCAFEF00D
;! mem idm[104] == 100
;! mem idm[96] == 0xCAFEF00D
;! mem idm[100] == 0
;! mem idm[32764] == 0xCAFEF00D
;! mem idm[4] == 0
;! trap "sst r1, r0, 2" "tests/isa/sst.s:10"
