; kernels/bench/gather_banks.s -- ray-buffer gathers (N = 16) with no, one and the worst-case
; bank conflicts. Ray buffer: 32 banks, 64-byte lines; line = address / 64, bank = line mod 32.
; A gather takes one cycle per distinct line in its busiest bank (bank_conflict: that - 1); its
; result is ready raybuf.access_cycles (2) + interconnect.latency (1) after its last cycle.
;
; PATTERN 0, no conflict: IDs 0..15 -> bytes 0..60 -> one line, one bank.
;   0 viota v1 (ready 1)   1 rgat: 1 cycle, ready 1 + 3 = 4   2 halt waits 2, 3 (data)
;   cycles 5 = busy 3 + data_dependency 2
; PATTERN 1, one conflict: IDs 0..14 and 512 (byte 2048: line 32, bank 0 like line 0).
;   0 viota  1 li r1, 15  2 mtail m1 (lanes 0..14)  3 mnot m2 (lane 15)  4 vli v1, 512 @m2 (ready 5)
;   5 rgat: bank 0 serves lines 0 and 32: 2 cycles (5, 6), bank_conflict 1, ready 6 + 3 = 9
;   7 halt waits 7, 8: cycles 10 = busy 7 + bank_conflict 1 + data_dependency 2
; PATTERN 2, worst case: ID of lane l = 512 l -> line 32 l, all in bank 0: 16 lines.
;   0 viota  1 vshli v1, v1, 9 (ready 2)  2 rgat: cycles 2..17, bank_conflict 15, ready 17 + 3 = 20
;   18 halt waits 18, 19: cycles 21 = busy 4 + bank_conflict 15 + data_dependency 2
; PATTERN 3, the worst case as a scatter (no result to wait for): halt at 18, cycles 19.
; PATTERN 2 with 3 banks (not a power of two): line 32 l is in bank 2 l mod 3, so bank 0 holds
;   lanes 0, 3, .., 15 (6 lines) and banks 1, 2 five each: rgat cycles 2..7, bank_conflict 5, ready
;   7 + 3 = 10; halt waits 8, 9: cycles 11 = busy 4 + bank_conflict 5 + data_dependency 2
;
;@ run none    define PATTERN=0 set core.simd_width=16 expect cycles=5 busy=3 data_dependency=2 rb_conflicted=0
;@ run one     define PATTERN=1 set core.simd_width=16 expect cycles=10 busy=7 bank_conflict=1 data_dependency=2 rb_conflicted=1
;@ run worst   define PATTERN=2 set core.simd_width=16 expect cycles=21 busy=4 bank_conflict=15 data_dependency=2 rb_conflicted=1
;@ run worst3  define PATTERN=2 set core.simd_width=16 set raybuf.banks=3 expect cycles=11 busy=4 bank_conflict=5 data_dependency=2 rb_conflicted=1
;@ run scatter define PATTERN=3 set core.simd_width=16 expect cycles=19 busy=4 bank_conflict=15 rb_conflicted=1

        .text
        viota   v1
.if PATTERN == 1
        li      r1, 15
        mtail   m1, r1
        mnot    m2, m1
        vli     v1, 512 @m2
.elif PATTERN >= 2
        vshli   v1, v1, 9
.endif
.if PATTERN == 3
        rsct    v2, v1, r0, 0
.else
        rgat    v2, v1, r0, 0
.endif
        halt
