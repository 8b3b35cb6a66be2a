; kernels/bench/align.s -- ID-vector fetches by the address-generation units; one of them at
; N = 12 starts off a line boundary (alignment).
;
; An sfetch of n IDs that the AGUs have not fetched ahead starts a fetch: ceil(n / 8) cycles of
; transfer (agu.ids_per_cycle = 8) plus agu.latency (1) of address computation; the data path
; waits for it (address_fetch). After each sfetch the AGUs fetch the stream's next vectors ahead,
; up to agu.queue_depth (2). A vector whose first ID is not at a multiple of raybuf.line_bytes
; (64) takes raybuf.align_cycles (1) more to rotate into the lanes (alignment).
;
; N12: a stream of 24 IDs at IDM 0 (bytes 0..95), two sfetch of 12.
;   0 li r1, 0   1 li r2, 96
;   2 sfetch: fetch IDs 0..11 in cycles 2, 3, ready 2 + 2 + 1 = 5: address_fetch 2, 3, 4.
;     Issues at 5; the AGU fetches IDs 12..23 ahead from cycle 5 (it is free from 4): ready 8.
;   6 sfetch: waits 6, 7 (address_fetch); issues at 8; byte 48 is off a 64-byte line: cycle 9
;     is alignment.
;   10 halt: cycles 11 = busy 5 + address_fetch 5 + alignment 1
; N16: 32 IDs (bytes 0..127), two sfetch of 16: as above but the second starts at byte 64:
;   cycles 10 = busy 5 + address_fetch 5
; N16WORK: four independent adds between the two sfetch (cycles 6..9): the vector fetched
;   ahead is ready at 8, the second sfetch issues at 10 without a wait; halt at 11:
;   cycles 12 = busy 9 + address_fetch 3
; N16NOAHEAD: agu.queue_depth = 0: the second sfetch starts its own fetch at 6, ready 9:
;   cycles 11 = busy 5 + address_fetch 6
;
;@ run n12 define WORK=0 define END=96 set core.simd_width=12 expect cycles=11 busy=5 address_fetch=5 alignment=1 agu_fetches=2 agu_ahead=1
;@ run n16 define WORK=0 define END=128 set core.simd_width=16 expect cycles=10 busy=5 address_fetch=5 agu_fetches=2 agu_ahead=1
;@ run n16work define WORK=1 define END=128 set core.simd_width=16 expect cycles=12 busy=9 address_fetch=3 agu_fetches=2 agu_ahead=1
;@ run n16noahead define WORK=0 define END=128 set core.simd_width=16 set agu.queue_depth=0 expect cycles=11 busy=5 address_fetch=6 agu_fetches=2 agu_ahead=0

        .text
        li      r1, 0
        li      r2, END
        sfetch  v1, m1, r1, r2
.if WORK
        add     r5, r5, r6
        add     r7, r7, r6
        add     r8, r8, r6
        add     r9, r9, r6
.endif
        sfetch  v2, m2, r1, r2
        halt
