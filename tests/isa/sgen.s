; sgen: selects the statistics generation whose counters the following instructions (and the
; sgen itself, like stage) add to; values above 63 count as generation 63. The per-stage totals
; do not change.
        .text
        li      r1, 2           ; gen 0: other
        sgen    r1              ; gen 0
        vli     v1, 1.0         ; gen 2: vector, N lanes
        stage   1               ; gen 2
        li      r2, 1           ; gen 2: traversal
        mtail   m1, r2          ; gen 2: traversal
        vli     v2, 2.0 @m1     ; gen 2: traversal, vector, 1 lane
        li      r1, 1000        ; gen 2
        sgen    r1              ; gen 2
        nop                     ; gen 63: traversal
        halt                    ; gen 63: traversal
;! stat gen0.instr.other == 2
;! stat gen2.instr.other == 2
;! stat gen2.vec.other == 1
;! stat gen2.lanes.other == N
;! stat gen2.instr.traversal == 5
;! stat gen2.vec.traversal == 1
;! stat gen2.lanes.traversal == 1
;! stat gen63.instr.traversal == 2
;! stat gen1.instr.other == 0
;! stat instr.other == 4
;! stat instr.traversal == 7
;! stat total == 11
