; macros, aliases, conditionals, expressions
.alias orgx, v3
.alias hit, m5
.macro vlerp d, a, b, t=v7
        vfsub \d, \b, \a
        vfma \d, \d, \t, \a
skip\@: bmz hit, skip\@
.endm
.ifdef HAS_DIELECTRIC
        li r1, 1
.elif (1 << 3) + 2 * 3 == 14 && !0
        li r1, 1.5e-3
.else
        .error "unreachable"
.endif
        vlerp v1, orgx, v2
        vlerp v4, v5, v6, v8
.set I, 0
.set I, I + 1
        li r2, I | 0x10 ^ 0b11
        li r3, 'a' % 7
        halt
