; vext: ra := vb[imm]; an imm of N or more traps. N is the machine's width, so the same program
; traps on narrow machines and not on wide ones: each width tested traps exactly at imm = N.
        .text
        viota   v0
        vmuli   v1, v0, 11
        vaddi   v1, v1, 5               ; v1[l] = 11l + 5
        vext    r1, v1, 0               ; 5
        vext    r2, v1, 1               ; N = 1 traps here
        vext    r3, v1, 3
        vext    r4, v1, 4               ; N = 4 traps here
        vext    r5, v1, 11
        vext    r6, v1, 12              ; N = 12 traps here
        vext    r7, v1, 15
        vext    r8, v1, 16              ; N = 16 traps here
        vext    r9, v1, 63              ; the last lane of the widest machine
        vext    r10, v0, 63
        vext    r11, v1, 64             ; beyond every machine: N = 64 traps here
        halt
;! r1 == 5
;! if N > 1: r2 == 16
;! if N >= 4: r3 == 38
;! if N > 4: r4 == 49
;! if N >= 12: r5 == 126
;! if N > 12: r6 == 137
;! if N >= 16: r7 == 170
;! if N > 16: r8 == 181
;! if N == 64: r9 == 698
;! if N == 64: r10 == 63
;! if N == 1: r3 == 0
;! if N == 4: r4 == 0
;! if N == 1: trap "vext r2, v1, 1" "tests/isa/vext.s:8"
;! if N == 4: trap "vext r4, v1, 4" "tests/isa/vext.s:10"
;! if N == 12: trap "vext r6, v1, 12" "tests/isa/vext.s:12"
;! if N == 16: trap "vext r8, v1, 16" "tests/isa/vext.s:14"
;! if N == 64: trap "vext r11, v1, 64" "tests/isa/vext.s:17"
