; fbadd: scatter-add into the framebuffer, lanes in order: FB[vb[l] + imm] += va[l] (float).
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vshli   v1, v0, 2               ; 4l
        vcvtif  v2, v0
        vli     v3, 0.5
        vfadd   v2, v2, v3              ; l + 0.5
        fbadd   v2, v1, 0               ; FB[4l] = l + 0.5
        fbadd   v2, v1, 0               ; again: 2l + 1
        fbadd   v2, v1, 1024 @m2        ; odd lanes only
        vli     v4, 1.0                 ; every lane adds 1.0 ...
        li      r1, 1
        mtail   m1, r1
        vli     v4, 16777216.0 @m1      ; ... except lane 0, which adds 2^24
        li      r2, 2048
        vbcast  v5, r2                  ; all lanes at FB[2052]
        fbadd   v4, v5, 4               ; in lane order each +1 rounds back to 2^24
        halt
;! mem fb[4 * l] ==f 2 * l + 1
;! mem fb[1024 + 4 * l] ==f (l % 2 == 1 ? l + 0.5 : 0.0)
;! mem fb[2052] ==f 16777216.0
;! mem fb[2048] == 0
;! mem fb[2056] == 0
