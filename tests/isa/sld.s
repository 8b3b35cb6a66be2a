; sld: ra := IDM[rb + imm] (32-bit word, byte address; outside IDM traps).
        .text
        li      r1, 0x11223344
        sst     r1, r0, 8
        li      r2, 16
        sst     r2, r2, -4              ; IDM[12] = 16
        sld     r3, r0, 8
        sld     r4, r2, -4              ; negative offset
        sld     r5, r0, 32764           ; the last word of the 32 KiB IDM: 0
        sld     r2, r2, -8              ; destination is the base: IDM[8]
        li      r6, 32768
        sld     r7, r6, 0               ; one past the end: trap
        halt
;! r3 == 0x11223344
;! r4 == 16
;! r5 == 0
;! r2 == 0x11223344
;! trap "sld r7, r6, 0" "tests/isa/sld.s:12"
