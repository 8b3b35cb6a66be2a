; vspld: va[l] := SP[rb + imm + 4l], merge masking. The table below is SP word i = 1000 + i.
; A vector that runs past the end of the scratchpad traps (from N = 2 on, here).
        .spad
        .word   1000, 1001, 1002, 1003, 1004, 1005, 1006, 1007
        .word   1008, 1009, 1010, 1011, 1012, 1013, 1014, 1015
        .word   1016, 1017, 1018, 1019, 1020, 1021, 1022, 1023
        .word   1024, 1025, 1026, 1027, 1028, 1029, 1030, 1031
        .word   1032, 1033, 1034, 1035, 1036, 1037, 1038, 1039
        .word   1040, 1041, 1042, 1043, 1044, 1045, 1046, 1047
        .word   1048, 1049, 1050, 1051, 1052, 1053, 1054, 1055
        .word   1056, 1057, 1058, 1059, 1060, 1061, 1062, 1063
        .word   1064, 1065, 1066, 1067, 1068, 1069, 1070, 1071
        .word   1072, 1073, 1074, 1075, 1076, 1077, 1078, 1079
        .text
        viota   v0
        vandi   v30, v0, 1
        vli     v31, 1
        vieq    m2, v30, v31            ; m2: odd lanes
        li      r1, 4
        vspld   v1, r1, 8               ; SP[12 + 4l] = 1003 + l
        vli     v2, 7
        vspld   v2, r0, 0 @m2           ; odd lanes
        vspld   v3, r0, 316             ; SP word 79 + l: 1079, then zeros
        li      r2, 65532
        vspld   v4, r2, 0               ; lane 0 is the last word; lane 1 is outside
        halt
;! v1[l] == 1003 + l
;! v2[l] == (l % 2 == 1 ? 1000 + l : 7)
;! v3[l] == (l == 0 ? 1079 : 0)
;! if N == 1: v4[0] == 0
;! if N >= 2: trap "vspld v4, r2, 0" "tests/isa/vspld.s:25"
