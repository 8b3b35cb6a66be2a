/* tests/support/asm_fixture.c -- assembling sources in memory for the assembler's tests
 * (asm_fixture.h). */
#include "asm_fixture.h"

#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "files.h"

char *ta_assemble(const char *name, const char *src, const AsmOptions *base, AsmObject *obj, int *nerr)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    cr_assert_not_null(m);
    AsmOptions opt = base ? *base : (AsmOptions){0};
    opt.diag = m;
    *nerr = asm_assemble_string(name, src, strlen(src), &opt, obj);
    fclose(m);
    return buf;
}

void ta_assemble_ok(const char *src, const AsmOptions *opt, AsmObject *obj)
{
    int nerr;
    char *diag = ta_assemble("ok.s", src, opt, obj, &nerr);
    cr_assert_eq(nerr, 0, "unexpected errors:\n%s\nfor:\n%s", diag, src);
    cr_assert_str_eq(diag, "");
    free(diag);
}

void ta_put_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    tu_write_file(path, text);
}
