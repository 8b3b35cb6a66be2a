/* tests/unit/test_kernel_src.c -- the shape of the path-tracing kernel's source (docs/kernel.md):
 * every register assignment made once (no name given the same register by two `.alias` or `.regs`
 * lines anywhere in kernels/pathtrace.s, kernels/lib/ and kernels/filters/), register frames
 * instead of alias lists, and statistics stages written by name. Reads the sources as text; the
 * program they assemble to is checked by tests/kernel_identity.sh and the functional tests. */
#include <criterion/criterion.h>
#include <ctype.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_PAIRS 1024

typedef struct Pair {
    char name[48], reg[8], where[160];
} Pair;

typedef struct Scan {
    Pair pairs[MAX_PAIRS];
    int npairs, naliases, nregs, numeric_stages;
    char first_numeric_stage[160];
} Scan;

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

static void add_pair(Scan *sc, const char *name, char kind, int num, const char *where)
{
    cr_assert_lt(sc->npairs, MAX_PAIRS);
    Pair *p = &sc->pairs[sc->npairs++];
    snprintf(p->name, sizeof p->name, "%s", name);
    snprintf(p->reg, sizeof p->reg, "%c%d", kind, num);
    snprintf(p->where, sizeof p->where, "%s", where);
}

/* `.regs v3, a, d:xyz`: a = v3, dx = v4, ... (docs/assembler.md, "Register frames"). */
static void scan_regs(Scan *sc, char *args, const char *where)
{
    char *save = NULL, *tok = strtok_r(args, ",", &save);
    cr_assert_not_null(tok, "%s: .regs without a register", where);
    tok = trim(tok);
    char kind = tok[0];
    int num = atoi(tok + 1);
    while ((tok = strtok_r(NULL, ",", &save))) {
        tok = trim(tok);
        char *colon = strchr(tok, ':');
        if (!colon) {
            add_pair(sc, tok, kind, num++, where);
            continue;
        }
        *colon = '\0';
        for (const char *s = trim(colon + 1); *s; s++) {
            char name[48];
            snprintf(name, sizeof name, "%s%c", tok, *s);
            add_pair(sc, name, kind, num++, where);
        }
    }
}

static void scan_file(Scan *sc, const char *path)
{
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "%s missing", path);
    char line[512];
    for (int ln = 1; fgets(line, sizeof line, f); ln++) {
        char *semi = strchr(line, ';');
        if (semi)
            *semi = '\0';
        char *s = trim(line), where[160];
        snprintf(where, sizeof where, "%s:%d", path, ln);
        if (!strncmp(s, ".alias", 6) && isspace((unsigned char)s[6])) {
            char name[48], reg[16];
            cr_assert_eq(sscanf(s + 6, " %47[A-Za-z0-9_] , %15s", name, reg), 2, "%s: %s", where, s);
            add_pair(sc, name, reg[0], atoi(reg + 1), where);
            sc->naliases++;
        } else if (!strncmp(s, ".regs", 5) && isspace((unsigned char)s[5])) {
            scan_regs(sc, s + 5, where);
            sc->nregs++;
        } else if (!strncmp(s, "stage", 5) && isspace((unsigned char)s[5])) {
            if (isdigit((unsigned char)*trim(s + 5)) && sc->numeric_stages++ == 0)
                snprintf(sc->first_numeric_stage, sizeof sc->first_numeric_stage, "%s", where);
        }
    }
    fclose(f);
}

static void scan_dir(Scan *sc, const char *dir)
{
    DIR *d = opendir(dir);
    cr_assert_not_null(d, "%s missing", dir);
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t n = strlen(e->d_name);
        if (n > 4 && !strcmp(e->d_name + n - 4, ".inc")) {
            char path[512];
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            scan_file(sc, path);
        }
    }
    closedir(d);
}

static Scan *scan_kernel(void)
{
    static Scan sc;
    memset(&sc, 0, sizeof sc);
    scan_file(&sc, "kernels/pathtrace.s");
    scan_dir(&sc, "kernels/lib");
    scan_dir(&sc, "kernels/filters");
    return &sc;
}

Test(kernel_src, each_register_assignment_is_made_once)
{
    Scan *sc = scan_kernel();
    cr_assert_gt(sc->nregs, 10, "the register frames (kernels/lib/frames.inc) were not found");
    for (int i = 0; i < sc->npairs; i++)
        for (int j = i + 1; j < sc->npairs; j++)
            cr_expect(strcmp(sc->pairs[i].name, sc->pairs[j].name) || strcmp(sc->pairs[i].reg, sc->pairs[j].reg),
                      "'%s' is given %s twice: %s and %s (define the frame once, kernels/lib/frames.inc)",
                      sc->pairs[i].name, sc->pairs[i].reg, sc->pairs[i].where, sc->pairs[j].where);
}

Test(kernel_src, frames_not_alias_lists)
{
    Scan *sc = scan_kernel();
    /* vid, kb, vm2, vz and the kd-tree leaves' pidx: every other name comes from a frame */
    cr_expect_leq(sc->naliases, 8, "%d .alias lines in the kernel: name registers with .regs frames", sc->naliases);
}

Test(kernel_src, stages_are_named)
{
    Scan *sc = scan_kernel();
    cr_expect_eq(sc->numeric_stages, 0, "`stage` with a number at %s: use STAGE_* (kernels/lib/kconst.inc)",
                 sc->first_numeric_stage);
}
