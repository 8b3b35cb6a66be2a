; part: stable in-place partition of the IDs in IDM[rb, rc) by the queued mask bits, set bits
; first; ra := rb + 4 * (number set); clears the queue. A queue shorter than the stream traps.
; The filter loop of Gribble & Ramani 2008, Fig. 5: fetch, test, pmask; then one part.
        .text
        li      r1, 64                  ; the stream: IDs 7i + 3, i = 0..10, at IDM[64, 108)
        li      r2, 3
        li      r3, 108
fill:   sst     r2, r1, 0
        addi    r1, r1, 4
        addi    r2, r2, 7
        blt     r1, r3, fill
        li      r4, 64                  ; begin
        li      r5, 108                 ; end
        mov     r6, r4
        li      r7, 0
        vli     v10, 2
filt:   sfetch  v1, m1, r6, r5
        vand    v2, v1, v10 @m1
        vieq    m2, v2, v10 @m1         ; keep IDs with bit 1 set (tail lanes cleared)
        pmask   m2
        mpop    r8, m2
        add     r7, r7, r8
        blt     r6, r5, filt
        part    r9, r4, r5
        part    r13, r4, r4             ; empty stream, empty queue: fine
        li      r14, 200                ; a stream of one ID, [200, 204)
        li      r15, 204
        li      r16, 99
        sst     r16, r14, 0
        pmask   m0                      ; N bits for one ID: L + N - 1, the most allowed
        part    r17, r14, r15           ; the ID is kept
        li      r10, 64
        li      r11, 72
        part    r12, r10, r11           ; 2 IDs, the queue was cleared: trap
        halt
;! r7 == 6
;! r9 == 88
;! r13 == 64
;! r17 == 204
;! mem idm[200] == 99
;! mem idm[64] == 3
;! mem idm[68] == 10
;! mem idm[72] == 31
;! mem idm[76] == 38
;! mem idm[80] == 59
;! mem idm[84] == 66
;! mem idm[88] == 17
;! mem idm[92] == 24
;! mem idm[96] == 45
;! mem idm[100] == 52
;! mem idm[104] == 73
;! mem idm[108] == 0
;! mem idm[60] == 0
;! trap "part r12, r10, r11" "tests/isa/part.s:34"
