; sfetch: n := min(N, (rd - rc) / 4); va[l] := IDM[rc + 4l] for l < n, lanes >= n repeat the
; last ID; mb := lanes < n; rc += 4N capped at rd; rc > rd traps.
        .text
        li      r1, 0                   ; the stream: IDs 100, 103, ..., 127 at IDM[0, 40)
        li      r2, 100
        li      r3, 40
fill:   sst     r2, r1, 0
        addi    r1, r1, 4
        addi    r2, r2, 3
        blt     r1, r3, fill
        li      r4, 0                   ; stream pointer
        li      r5, 40                  ; stream end
        sfetch  v1, m1, r4, r5          ; first block
        mov     r6, r4
        sfetch  v2, m2, r4, r5          ; second block (empty when N >= 10)
        mov     r7, r4
        li      r8, 0                   ; the usual loop: count IDs and blocks
        li      r9, 0
        li      r10, 0
loop:   sfetch  v3, m3, r8, r5
        mpop    r11, m3
        add     r9, r9, r11
        addi    r10, r10, 1
        blt     r8, r5, loop
        li      r12, 40
        sfetch  v4, m4, r12, r5         ; at the end: no lanes, pointer stays
        li      r13, 8                  ; a stream not at 0: [8, 20) = IDs 106, 109, 112
        li      r14, 20
        sfetch  v5, m5, r13, r14
        li      r15, 8
        li      r16, 4
        sfetch  v6, m6, r15, r16        ; begin > end: trap
        halt
;! v1[l] == 100 + 3 * min(l, min(N, 10) - 1)
;! m1[l] == (l < 10)
;! m1 == (1 << min(N, 10)) - 1
;! r6 == min(4 * N, 40)
;! if N < 10: v2[l] == 100 + 3 * (N + min(l, min(N, 10 - N) - 1))
;! m2[l] == (l < max(0, min(N, 10 - N)))
;! r7 == min(8 * N, 40)
;! r8 == 40
;! r9 == 10
;! r10 == (10 + N - 1) / N
;! m4 == 0
;! r12 == 40
;! v5[l] == 106 + 3 * min(l, min(N, 3) - 1)
;! m5 == (1 << min(N, 3)) - 1
;! r13 == min(8 + 4 * N, 20)
;! r15 == 8
;! trap "sfetch v6, m6, r15, r16" "tests/isa/sfetch.s:32"
