; ldg: per-lane gather from scene memory: va[l] := SM[vb[l] + imm], merge masking. The table
; below is SM word i = 2000 + i.
        .data
        .word   2000, 2001, 2002, 2003, 2004, 2005, 2006, 2007
        .word   2008, 2009, 2010, 2011, 2012, 2013, 2014, 2015
        .word   2016, 2017, 2018, 2019, 2020, 2021, 2022, 2023
        .word   2024, 2025, 2026, 2027, 2028, 2029, 2030, 2031
        .word   2032, 2033, 2034, 2035, 2036, 2037, 2038, 2039
        .word   2040, 2041, 2042, 2043, 2044, 2045, 2046, 2047
        .word   2048, 2049, 2050, 2051, 2052, 2053, 2054, 2055
        .word   2056, 2057, 2058, 2059, 2060, 2061, 2062, 2063
        .word   2064, 2065, 2066, 2067, 2068, 2069, 2070, 2071
        .word   2072, 2073, 2074, 2075, 2076, 2077, 2078, 2079
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        vshli   v1, v0, 2               ; 4l
        ldg     v2, v1, 0               ; 2000 + l
        rdn     r1
        addi    r1, r1, -1
        vbcast  v3, r1
        vsub    v3, v3, v0
        vshli   v3, v3, 2               ; 4(N-1-l): reversed
        ldg     v4, v3, 8               ; 2002 + N-1-l
        vli     v5, 3
        ldg     v5, v1, 4 @m2           ; odd lanes: 2001 + l
        vli     v6, 12
        ldg     v7, v6, 0               ; every lane the same word: 2003
        vaddi   v8, v1, 2               ; misaligned in every lane
        ldg     v9, v8, 0               ; trap
        halt
;! v2[l] == 2000 + l
;! v4[l] == 2002 + N - 1 - l
;! v5[l] == (l % 2 == 1 ? 2001 + l : 3)
;! v7[l] == 2003
;! trap "ldg v9, v8, 0" "tests/isa/ldg.s:32"
