; pclr: discards the partition unit's queue. Without it the part below would see 3N bits for N
; IDs and trap.
        .text
        rdn     r1
        viota   v0
        li      r4, 0
        sapp    r4, v0                  ; IDs 0 .. N-1 at IDM[0, 4N)
        pmask   m0
        pmask   m0
        pclr
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        pmask   m2                      ; odd lanes first
        part    r5, r0, r4
        pclr                            ; on an empty queue: nothing
        part    r6, r0, r0              ; empty stream, empty queue
        halt
;! r5 == 4 * (N / 2)
;! mem idm[4 * l] == (l < N / 2 ? 2 * l + 1 : 2 * (l - N / 2))
;! r6 == 0
