; kernels/bench/scene.s -- scene memory: a miss, then a hit on the same line; the same without a
; cache; a gather over 16 lines. Defaults: latency 50, 16 bytes per cycle (a 64-byte line moves
; in 4 cycles), 64 KiB 4-way cache, hit latency 2, one line per cycle through the cache port.
; A miss at cycle t with the bus free: ready t + 50 + 4.
;
; PATTERN 0 (cache):
;   0 li r1, 4096   1 ld r2 (miss, bus 1..4, ready 55)   2 add waits 2..54 (scene_memory 53), issues 55
;   56 ld r4 (hit, ready 58)   57 add waits 57 (scene_memory 1), issues 58   59 halt:
;   cycles 60 = busy 6 + scene_memory 54; 1 hit, 1 miss
; PATTERN 0 with scene.cache_kb = 0: the second ld goes to memory too: ready 56 + 54 = 110, the add
;   waits 57..109 (53): halt at 111, cycles 112 = busy 6 + scene_memory 106; 2 misses
; PATTERN 1, ldg over 16 lines (lane l reads byte 4096 + 64 l), all misses:
;   0 viota  1 vshli v1, v1, 6 (ready 2)  2 ldg: one line per cycle, 2..17 (scene_memory 15);
;   line i goes over the bus from max(2 + i, 2 + 4i) = 2 + 4i: the last is ready 2 + 60 + 54 = 116
;   18 halt waits 18..115 (scene_memory 98): cycles 117 = busy 4 + scene_memory 113; 16 misses
;
;@ run miss_hit define PATTERN=0 set scene.size_mb=1 expect cycles=60 busy=6 scene_memory=54 scene_hits=1 scene_misses=1
;@ run nocache  define PATTERN=0 set scene.size_mb=1 set scene.cache_kb=0 expect cycles=112 busy=6 scene_memory=106 scene_hits=0 scene_misses=2
;@ run gather   define PATTERN=1 set scene.size_mb=1 set core.simd_width=16 expect cycles=117 busy=4 scene_memory=113 scene_hits=0 scene_misses=16

        .text
.if PATTERN == 0
        li      r1, 4096
        ld      r2, r1, 0
        add     r3, r2, r0
        ld      r4, r1, 4
        add     r5, r4, r0
.else
        viota   v1
        vshli   v1, v1, 6
        ldg     v2, v1, 4096
.endif
        halt
