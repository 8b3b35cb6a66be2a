; mul: ra := low 32 bits of rb * rc (the same for signed and unsigned).
        .text
        li      r1, 0x10000
        mul     r2, r1, r1      ; 2^32: low bits 0
        li      r3, -3
        li      r4, 7
        mul     r5, r3, r4      ; -21
        li      r6, 0x12345678
        li      r7, 16
        mul     r8, r6, r7      ; 0x23456780 (the top nibble is lost)
        li      r9, -1
        mul     r10, r9, r9     ; 0xFFFFFFFF^2 = 1 mod 2^32
        li      r11, 46341
        mul     r12, r11, r11   ; 2147488281 = 0x80001219
        mul     r13, r4, r0     ; x 0
        halt
;! r2 == 0
;! r5 == -21
;! r8 == 0x23456780
;! r10 == 1
;! r12 == 0x80001219
;! r13 == 0
