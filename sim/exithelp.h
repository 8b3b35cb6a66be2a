/* sim/exithelp.h -- the exit-code table of sim/exitcodes.def as help text, for `sfsim --help`,
 * `sfsim help exit-codes` and `sfasm --help`.
 *
 * Owns: the plain-text layout of the table. Must not: hold any code or meaning (the .def does).
 * A header-only helper because sfasm links only the assembler library, not libsfsim.
 */
#ifndef SFSIM_EXITHELP_H
#define SFSIM_EXITHELP_H

#include <stdio.h>
#include <string.h>

#include "exitcodes.h"

/* One row: "  CODE  NAME     text", the text wrapped at 100 columns under itself. */
static inline void exithelp_row(FILE *out, int code, const char *name, const char *text)
{
    enum { INDENT = 17, WIDTH = 100 };
    int col = fprintf(out, "  %3d%s  %-8s ", code, code == EXIT_SIGNAL ? "+" : " ", name);
    while (*text) {
        size_t word = strcspn(text, " ");
        if (col > INDENT && col + 1 + (int)word > WIDTH) {
            col = fprintf(out, "\n%*s", INDENT, "") - 1;
        } else if (col > INDENT) {
            fputc(' ', out);
            col++;
        }
        col += fprintf(out, "%.*s", (int)word, text);
        text += word;
        while (*text == ' ')
            text++;
    }
    fputc('\n', out);
}

/* Every row of the table, in its order. */
static inline void exithelp_print(FILE *out)
{
#define EXITCODE(name, code, text) exithelp_row(out, code, #name, text);
#include "exitcodes.def"
#undef EXITCODE
}

#endif
