; kernels/bench/contention.s -- the partition unit against the AGUs (PATTERN 0) or against a
; ray-buffer gather (PATTERN 1) on the interconnect. N = 16.
;
; Stream A: 64 IDs at IDM 0, partitioned (cost 2 + 64/16 = 6 cycles, holding one interconnect
; port while it works). Stream B: 16 IDs at IDM 1024.
;   0..3 li   4 mall m1   5..8 pmask   9 part: the partition unit works 9..14, one port
; PATTERN 0, interconnect.ports = 1:
;   10 sfetch from B: the AGU needs the port for 2 cycles; it is taken until 15, so the fetch runs
;      15, 16 and is ready at 18: the data path waits 10..17: interconnect 5 (the AGU's wait for
;      the port), address_fetch 3 (the fetch itself). Issues at 18.
;   19 halt: cycles 20 = busy 12 + interconnect 5 + address_fetch 3; the AGU waited 5 (icn_unit_delay)
; PATTERN 0, two ports (default): the fetch runs 10, 11, ready 13: address_fetch 3. Halt at 14
;   waits for the partition to end (it works until 14; partition 1) and issues at 15:
;   cycles 16 = busy 12 + address_fetch 3 + partition 1
; PATTERN 1, one port: 10 rgat (all lanes read byte 0: one line) waits for the port 10..14
;   (interconnect 5), issues 15, ready 15 + 3 = 18; 16 halt waits 16, 17:
;   cycles 19 = busy 12 + interconnect 5 + data_dependency 2
; PATTERN 1, two ports: rgat at 10, ready 13; halt at 11 waits for the partition unit (busy until
;   14) and for the gather; the partition ranks first (docs/model.md): 11..14 are partition:
;   cycles 16 = busy 12 + partition 4
;
;@ run agu_1port  define PATTERN=0 set core.simd_width=16 set interconnect.ports=1 expect cycles=20 busy=12 interconnect=5 address_fetch=3 icn_unit_delay=5
;@ run agu_2ports define PATTERN=0 set core.simd_width=16 expect cycles=16 busy=12 address_fetch=3 partition=1 icn_unit_delay=0
;@ run dp_1port   define PATTERN=1 set core.simd_width=16 set interconnect.ports=1 expect cycles=19 busy=12 interconnect=5 data_dependency=2
;@ run dp_2ports  define PATTERN=1 set core.simd_width=16 expect cycles=16 busy=12 partition=4

        .text
        li      r1, 0
        li      r2, 256
        li      r5, 1024
        li      r6, 1088
        mall    m1
        pmask   m1
        pmask   m1
        pmask   m1
        pmask   m1
        part    r3, r1, r2
.if PATTERN == 0
        sfetch  v1, m2, r5, r6
.else
        rgat    v1, v7, r0, 0
.endif
        halt
