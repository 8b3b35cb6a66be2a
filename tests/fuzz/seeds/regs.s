; register frames: consecutive registers, d:xyz a 3-vector
.regs   v1, tm, th:xyz, vt
.regs   m2, hit, miss
        vfadd   thx, thy, thz @hit
        vmov    tm, vt @miss
.regs   v28, a:bc, d
        vmov    ab, d
        halt
