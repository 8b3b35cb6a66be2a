; kernels/bench/chains.s -- a dependent chain of K = 8 instructions of one latency class.
;
; CLASS selects the class (the op after `op` below). The chain starts from a register written by
; a latency-1 instruction at cycle 0, so the first chain op issues at cycle 1 without a stall.
; With latency L, op i (i = 0..7) issues at 1 + L*i and its result is ready at 1 + L*(i+1);
; halt waits for the last result: it issues at 1 + 8L, so
;     cycles = 2 + 8L,  busy = 10 (init, 8 ops, halt),  data_dependency = 8L - 8 = 8(L - 1).
; Defaults (docs/config.md): salu 1, sfpu 2, sspec 8, vadd 2, vmul 3, vfma 4, vspec 8, vcmp 1,
; vlogic 1, vsel 1, mask 1.
;     L = 1: cycles 10, dd 0      L = 2: cycles 18, dd 8     L = 3: cycles 26, dd 16
;     L = 4: cycles 34, dd 24     L = 8: cycles 66, dd 56
; The latency-1 classes run again with their latency set to 3 (cycles 26, dd 16), so the chain is
; seen to be a chain. For salu, vsel and mask the start instruction (li, vli, mall) is of the same
; class, so it has latency 3 too: the first op waits 2 cycles more (cycles 28, dd 18). vspec (L = 8) issues every 2 cycles, sspec (L = 8) every 4: the chain's
; latency hides both intervals (no fu_busy).
;
; CLASS = 12: eight *independent* vrcp (vspec: latency 8, one issue every 2 cycles):
;     vli v1 at 0; vrcp i at 1 + 2i (i = 0..7): 7 x 1 cycle fu_busy; the last issues at 15, its
;     result is ready at 23; halt waits 16..22 (7 cycles, data_dependency) and issues at 23:
;     cycles 24 = busy 10 + fu_busy 7 + data_dependency 7.
;
;@ run salu   define CLASS=1 expect cycles=10 busy=10
;@ run salu3  define CLASS=1 set latency.salu=3 expect cycles=28 busy=10 data_dependency=18
;@ run sfpu   define CLASS=2 expect cycles=18 busy=10 data_dependency=8
;@ run sspec  define CLASS=3 expect cycles=66 busy=10 data_dependency=56
;@ run vadd   define CLASS=4 expect cycles=18 busy=10 data_dependency=8
;@ run vmul   define CLASS=5 expect cycles=26 busy=10 data_dependency=16
;@ run vfma   define CLASS=6 expect cycles=34 busy=10 data_dependency=24
;@ run vspec  define CLASS=7 expect cycles=66 busy=10 data_dependency=56
;@ run vcmp   define CLASS=8 expect cycles=10 busy=10
;@ run vcmp3  define CLASS=8 set latency.vcmp=3 expect cycles=26 busy=10 data_dependency=16
;@ run vlogic define CLASS=9 expect cycles=10 busy=10
;@ run vlogic3 define CLASS=9 set latency.vlogic=3 expect cycles=26 busy=10 data_dependency=16
;@ run vsel   define CLASS=10 expect cycles=10 busy=10
;@ run vsel3  define CLASS=10 set latency.vsel=3 expect cycles=28 busy=10 data_dependency=18
;@ run mask   define CLASS=11 expect cycles=10 busy=10
;@ run mask3  define CLASS=11 set latency.mask=3 expect cycles=28 busy=10 data_dependency=18
;@ run vspec_busy define CLASS=12 expect cycles=24 busy=10 fu_busy=7 data_dependency=7

.macro op
.if CLASS == 1
        add     r1, r1, r2          ; salu
.elif CLASS == 2
        fadd    r1, r1, r2          ; sfpu
.elif CLASS == 3
        fdiv    r1, r1, r2          ; sspec
.elif CLASS == 4
        vfadd   v1, v1, v2          ; vadd
.elif CLASS == 5
        vfmul   v1, v1, v2          ; vmul
.elif CLASS == 6
        vfma    v1, v1, v2, v2      ; vfma
.elif CLASS == 7
        vrcp    v1, v1              ; vspec
.elif CLASS == 8
        vflt    m1, v1, v2 @m1      ; vcmp: reads m1 as its exec mask, writes m1
.elif CLASS == 9
        vadd    v1, v1, v2          ; vlogic
.elif CLASS == 10
        vmov    v1, v1 @m1          ; vsel: reads m1 and v1, writes v1
.elif CLASS == 11
        mand    m1, m1, m2          ; mask
.endif
.endm

        .text
.if CLASS == 12
        vli     v1, 0x40000000      ; 2.0
        vrcp    v2, v1
        vrcp    v3, v1
        vrcp    v4, v1
        vrcp    v5, v1
        vrcp    v6, v1
        vrcp    v7, v1
        vrcp    v8, v1
        vrcp    v9, v1
.else
.if CLASS == 11 || CLASS == 8
        mall    m1                  ; latency-1 start value
.elif CLASS <= 3
        li      r1, 0x3f800000
.else
        vli     v1, 0x3f800000
.endif
        op
        op
        op
        op
        op
        op
        op
        op
.endif
        halt
