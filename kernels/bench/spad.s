; kernels/bench/spad.s -- vector scratchpad loads against the two ports (64 bytes each per cycle).
; A load of N words at byte OFF touches lines OFF/64 .. (OFF + 4N - 1)/64 and takes
; ceil(lines / 2) cycles (scratchpad: that - 1); its result is ready spad.latency (2) after its
; last cycle.
;   N16 at 0: 1 line, 1 cycle, ready 2; halt at 1 waits 1: cycles 3 = busy 2 + data_dependency 1
;   N16 at 32: lines 0, 1: one cycle on the two ports: cycles 3 as above
;   N32 at 32: bytes 32..159, lines 0..2: 2 cycles (0, 1), ready 3; halt at 2 waits 2:
;      cycles 4 = busy 2 + scratchpad 1 + data_dependency 1
;   N64 at 0: 4 lines: 2 cycles: cycles 4 = busy 2 + scratchpad 1 + data_dependency 1
;
;@ run n16_aligned define OFF=0 set core.simd_width=16 expect cycles=3 busy=2 data_dependency=1
;@ run n16_off32   define OFF=32 set core.simd_width=16 expect cycles=3 busy=2 data_dependency=1
;@ run n32_off32   define OFF=32 set core.simd_width=32 expect cycles=4 busy=2 scratchpad=1 data_dependency=1
;@ run n64_aligned define OFF=0 set core.simd_width=64 expect cycles=4 busy=2 scratchpad=1 data_dependency=1

        .text
        vspld   v1, r0, OFF
        halt
