; kernels/bench/partition.s -- an in-place partition of a stream of 64 IDs (N = 16: 4 pmask).
; Cost = partition.setup_cycles (2) + ceil(64 / partition.ids_per_cycle (0 = N = 16)) = 6 cycles; its
; result register is ready when it ends (partition).
;   0 li r1, 0   1 li r2, 256   2 mall m1   3..6 pmask m1 (64 bits)
;   7 part r3: the unit works 7..12, r3 ready 13
;   8 add r4, r3, r0 waits 8..12 (partition 5), issues 13
;   14 halt: cycles 15 = busy 10 + partition 5
; ids_per_cycle = 4: cost 2 + 16 = 18, the unit works 7..24: the add waits 17 cycles:
;   cycles 27 = busy 10 + partition 17
;
; N8 (define N8=1): N = 8 needs 8 pmask for the 64 bits (cycles 3..10), and the unit moves N = 8
;   IDs per cycle: cost 2 + 8 = 10, the unit works 11..20; the add waits 12..20 (partition 9):
;   cycles 23 = busy 14 + partition 9
;
;@ run ipc16 define N8=0 set core.simd_width=16 expect cycles=15 busy=10 partition=5 partitions=1
;@ run ipc4  define N8=0 set core.simd_width=16 set partition.ids_per_cycle=4 expect cycles=27 busy=10 partition=17 partitions=1
;@ run n8    define N8=1 set core.simd_width=8 expect cycles=23 busy=14 partition=9 partitions=1

        .text
        li      r1, 0
        li      r2, 256
        mall    m1
        pmask   m1
        pmask   m1
        pmask   m1
        pmask   m1
.if N8
        pmask   m1
        pmask   m1
        pmask   m1
        pmask   m1
.endif
        part    r3, r1, r2
        add     r4, r3, r0
        halt
