; mclr: ma := no lanes. Clearing m0 disables every vector instruction that uses the default
; exec mask.
        .text
        mall    m3
        mclr    m3
        viota   v1
        mclr    m0
        vli     v1, 77                  ; no lane changes
        vli     v2, 77
        mall    m4
        vli     v3, 5 @m4               ; an explicit mask still works
        halt
;! m3 == 0
;! m0 == 0
;! v1[l] == l
;! v2[l] == 0
;! v3[l] == 5
