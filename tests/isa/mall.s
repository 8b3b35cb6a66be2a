; mall: ma := all N lanes.
        .text
        mall    m3
        mall    m7
        mclr    m0
        vli     v1, 5                   ; m0 empty: no lane changes
        mall    m0                      ; back to all lanes
        vli     v2, 6
        halt
;! m3 == (N == 64 ? -1 : (1 << N) - 1)
;! m7[l] == 1
;! m0 == (N == 64 ? -1 : (1 << N) - 1)
;! v1[l] == 0
;! v2[l] == 6
