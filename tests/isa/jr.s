; jr: pc := ra, to a label's address and to a computed one.
        .text
        li      r1, target      ; a code label's value is its instruction index
        jr      r1
        li      r2, 99          ; skipped
target: li      r3, 7
        li      r4, 9           ; 9 = index of `done`, computed below as 6 + 3
        li      r4, 6
        addi    r4, r4, 3
        jr      r4
        li      r3, 8           ; skipped
done:   halt
;! r2 == 0
;! r3 == 7
;! r4 == done
;! r4 == 9
;! stat op.jr == 2
