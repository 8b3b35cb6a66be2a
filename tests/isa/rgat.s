; rgat: gather from the current ray buffer: va[l] := RBc[rc + imm + 4 * vb[l]], merge masking.
        .text
        viota   v0
        li      r1, 3
        mtail   m1, r1                  ; lanes < 3
        vmuli   v1, v0, 5
        vaddi   v1, v1, 2               ; 5l + 2
        rsct    v1, v0, r0, 256         ; RB0[256 + 4l] = 5l + 2
        rgat    v2, v0, r0, 256         ; identity
        rdn     r2
        addi    r2, r2, -1
        vbcast  v3, r2
        vsub    v4, v3, v0              ; reversed IDs
        li      r3, 128
        rgat    v5, v4, r3, 128         ; base + offset: 5(N-1-l) + 2
        vli     v6, 0x5A5A
        rgat    v6, v4, r0, 256 @m1
        rgat    v7, v11, r0, 256        ; every lane the same ID 0: 2
        rgat    v8, v0, r0, 8192        ; never written: 0
        rsctn   v1, v0, r0, 512         ; into the next buffer...
        rgat    v9, v0, r0, 512         ; ...is not visible in the current one
        halt
;! v2[l] == 5 * l + 2
;! v5[l] == 5 * (N - 1 - l) + 2
;! v6[l] == (l < 3 ? 5 * (N - 1 - l) + 2 : 0x5A5A)
;! v7[l] == 2
;! v8[l] == 0
;! v9[l] == 0
