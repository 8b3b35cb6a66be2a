; tests/unit/pass_trap.s -- a stand-in kernel for the frame's (tile, pass) units (test_functional.c):
; each pass adds 1.0 to the first N floats of the framebuffer (so a tile's first pixels count
; the passes that ran on it, on whichever core), and the second pass of the tile at x0 = 32 traps.
.include "../../kernels/lib/abi.inc"

start:  spld    r1, r0, L_X0
        spld    r3, r0, L_PASS0
        viota   v0
        vshli   v1, v0, 2               ; 4l: float l of the framebuffer
        vli     v2, 1.0
        fbadd   v2, v1, 0
        li      r2, 32
        bne     r1, r2, ok
        li      r2, 1
        bne     r3, r2, ok
        li      r1, 0x7FFFFFF0
        ld      r2, r1, 0               ; out of scene memory: a trap
ok:     halt
