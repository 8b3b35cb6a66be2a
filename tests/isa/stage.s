; stage: attributes the instructions that follow to a statistics stage (0 other, 1 traversal,
; 2 intersection, 3 shading). The marker itself counts in the stage it executes in, the one
; before it (isa-design.md: "attributes all following instructions"). The program ends in
; shading, so the two possible readings give different counts.
        .text
        nop                     ; other
        stage   1               ; other
        li      r1, 3           ; traversal: integer
        mtail   m1, r1          ; traversal: compute, not a vector instruction
        vli     v1, 1.0         ; traversal: vector, N lanes
        vli     v2, 2.0 @m1     ; traversal: vector, min(3, N) lanes
        stage   2               ; traversal
        nop                     ; intersection
        nop
        nop
        stage   0               ; intersection
        nop                     ; other
        nop
        stage   3               ; other
        nop                     ; shading
        nop
        nop
        nop
        halt                    ; shading
;! stat instr.other == 5
;! stat instr.traversal == 5
;! stat instr.intersection == 4
;! stat instr.shading == 5
;! stat total == 19
;! stat vec.traversal == 2
;! stat lanes.traversal == N + min(3, N)
;! stat vec.other == 0
;! stat vec.shading == 0
;! stat lanes.other == 0
;! stat cat.traversal.integer == 1
;! stat cat.traversal.compute == 3
;! stat cat.traversal.control == 1
;! stat cat.other.control == 5
;! stat cat.intersection.control == 4
;! stat cat.shading.control == 5
;! stat op.stage == 4
;! v2[l] ==f l < 3 ? 2.0 : 0.0
