/* tests/unit/test_exitcodes.c -- the exit-code table (sim/exitcodes.def): docs/exit-codes.md is
 * what tools/gen_exitdoc.c prints today (as tests/unit/test_isa.c checks docs/isa.md), the codes
 * are distinct, and the help text walks every row.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/exithelp.h"
#include "../support/files.h"

Test(exitcodes, docs_exit_codes_md_is_current)
{
    tu_expect_generated("gen_exitdoc", "SFSIM_GEN_EXITDOC", "docs/exit-codes.md");
}

/* Each row once in the doc's table, and no two rows share a code. */
Test(exitcodes, every_row_in_the_doc_and_codes_distinct)
{
    static const struct { const char *name; int code; } rows[] = {
#define EXITCODE(name, code, text) {#name, code},
#include "../../sim/exitcodes.def"
#undef EXITCODE
    };
    size_t n = sizeof rows / sizeof rows[0];
    FILE *f = fopen("docs/exit-codes.md", "r");
    cr_assert_not_null(f, "docs/exit-codes.md is missing: run make docs");
    static char text[1 << 16];
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    for (size_t i = 0; i < n; i++) {
        char row[64];
        snprintf(row, sizeof row, "| %d%s | `EXIT_%s` |", rows[i].code, rows[i].code == EXIT_SIGNAL ? " + signal" : "",
                 rows[i].name);
        const char *hit = strstr(text, row);
        cr_expect_not_null(hit, "docs/exit-codes.md has no row %s", row);
        if (hit)
            cr_expect_null(strstr(hit + 1, row), "docs/exit-codes.md has two rows %s", row);
        for (size_t j = 0; j < i; j++)
            cr_expect_neq(rows[i].code, rows[j].code, "EXIT_%s and EXIT_%s share code %d", rows[i].name, rows[j].name,
                          rows[i].code);
    }
    cr_expect_eq(EXIT_OK, 0);
}

/* The help text has a line per row: code, name and the start of its meaning. */
Test(exitcodes, help_prints_every_row)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    cr_assert_not_null(m);
    exithelp_print(m);
    fclose(m);
#define EXITCODE(name, code, text)                                                                         \
    {                                                                                                      \
        char row[160];                                                                                     \
        snprintf(row, sizeof row, "%3d%s  %-8s %.20s", code, code == EXIT_SIGNAL ? "+" : " ", #name, text); \
        cr_expect_not_null(strstr(buf, row), "no help line '%s' in:\n%s", row, buf);                       \
    }
#include "../../sim/exitcodes.def"
#undef EXITCODE
    for (const char *line = buf; *line;) {
        const char *nl = strchr(line, '\n');
        cr_expect(nl && nl - line <= 100, "a help line longer than 100 columns: %.*s", (int)(nl ? nl - line : 200), line);
        line = nl ? nl + 1 : line + strlen(line);
    }
    free(buf);
}
