; fneg: ra := -rb (the sign flipped, zeros included).
        .text
        li      r1, 1.5
        fneg    r2, r1                  ; -1.5
        fneg    r3, r0                  ; -(+0) = -0
        li      r4, 0x80000000
        fneg    r5, r4                  ; -(-0) = +0
        li      r6, 0x7F800000
        fneg    r7, r6                  ; -inf
        fneg    r8, r2                  ; 1.5
        li      r9, 0x7FC00000
        fneg    r10, r9                 ; NaN
        halt
;! r2 ==f -1.5
;! r3 == 0x80000000
;! r5 == 0
;! r7 == 0xFF800000
;! r8 ==f 1.5
;! r10 ==f nan
