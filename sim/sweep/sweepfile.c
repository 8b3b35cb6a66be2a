/* sim/sweep/sweepfile.c -- sweep files (configs/sweeps; docs/sweep.md): read through the one
 * INI reader (sim/ini.c), checked, and expanded into the manifest's points.
 *
 * Owns: the [sweep] and [point.NAME] sections and their keys, lists and ranges ("A..B step S"),
 * the duplicate and size checks, the cross product's order (the first key varies slowest), and
 * checking one value of a key (sweep_value_check). Must not: know what a machine key means
 * (cfg_set on a scratch config decides), read files (the caller gives the text), or print
 * (every problem goes into the caller's SweepErrs).
 */
#include "sweep_int.h"

#include <math.h>

#include "../config.h"
#include "../ini.h"
#include "../render.h"

/* The render keys `sfsim run --set` takes beside the machine keys: render_keys (sim/render.h). */
#define N_RENDER_KEYS RENDER_KEY_COUNT

/* Machine keys go through cfg_set on a scratch config. */
int sweep_value_check(const char *key, const char *value, int *unknown, char *msg, size_t len)
{
    *unknown = 0;
    for (int i = 0; i < N_RENDER_KEYS; i++) {
        if (strcmp(key, render_keys[i].key) != 0)
            continue;
        long long v;
        if (util_parse_int(value, render_keys[i].lo, render_keys[i].hi, &v)) {
            snprintf(msg, len, "expected an integer in %lld..%lld, got '%s'", render_keys[i].lo, render_keys[i].hi,
                     value);
            return -1;
        }
        return 0;
    }
    CfgMachine scratch;
    cfg_defaults(&scratch);
    CfgErrors ce = {0};
    char *assign = xasprintf("%s=%s", key, value);
    int rc = 0;
    if (cfg_set(&scratch, assign, &ce)) {
        const char *t = ce.text ? ce.text : "invalid value";
        size_t al = strlen(assign);
        if (!strncmp(t, "--set ", 6) && !strncmp(t + 6, assign, al) && !strncmp(t + 6 + al, ": ", 2))
            t += 8 + al;
        if (!strncmp(t, "unknown key", 11) || !strncmp(t, "expected section.key=value", 26)) {
            *unknown = 1;
            snprintf(msg, len, "unknown key (sfsim config --dump lists the machine keys; the render keys are "
                               "render.width, render.height, render.spp, render.max_depth, render.seed)");
        } else {
            snprintf(msg, len, "%.*s", (int)strcspn(t, "\n"), t);
        }
        rc = -1;
    }
    cfg_errors_free(&ce);
    free(assign);
    return rc;
}

static int key_known(const char *key)
{
    int unknown;
    char msg[512];
    sweep_value_check(key, "0", &unknown, msg, sizeof msg);
    return !unknown;
}

/* A range "A..B" or "A..B step S" (inclusive; S defaults to 1): integers exactly, floats with a
 * little slack so that 0..1 step 0.1 ends at 1. */
typedef struct Range {
    int ints;
    long long a, s;  /* integers */
    double af, sf;   /* floats */
    double count;    /* values it gives; may be huge, never computed by making them */
} Range;

/* -1 with msg when item is no good range. Overflow-safe: the count of a range of integers is
 * computed in unsigned arithmetic, of floats in double (inf is "too many"). */
static int range_parse(const char *item, Range *r, char *msg, size_t len)
{
    const char *dots = strstr(item, "..");
    char *a = xstrndup(item, (size_t)(dots - item));
    char *rest = xstrdup(dots + 2);
    char *step = strstr(rest, "step");
    char *b;
    const char *s;
    if (step) {
        *step = 0;
        b = sweep_trim(rest);
        s = sweep_trim(step + 4);
    } else {
        b = sweep_trim(rest);
        s = "1";
    }
    double av, bv, sv;
    int ai, bi, si, rc = -1;
    long long aii, bii, sii;
    memset(r, 0, sizeof *r);
    if (sweep_parse_number(sweep_trim(a), &av, &ai, &aii) || sweep_parse_number(b, &bv, &bi, &bii) ||
        sweep_parse_number(s, &sv, &si, &sii)) {
        snprintf(msg, len, "bad range '%s': expected A..B or A..B step S, with numbers", item);
    } else if (!(sv > 0)) {
        snprintf(msg, len, "bad range '%s': the step must be > 0", item);
    } else if (ai && bi && si ? bii < aii : bv < av) {
        snprintf(msg, len, "bad range '%s': its end is below its start", item);
    } else {
        r->ints = ai && bi && si;
        if (r->ints) {
            r->a = aii;
            r->s = sii;
            r->count = (double)(((unsigned long long)bii - (unsigned long long)aii) / (unsigned long long)sii) + 1;
        } else {
            r->af = av;
            r->sf = sv;
            r->count = floor((bv - av) / sv * (1 + 1e-12) + 1e-9) + 1;
        }
        if (!(r->count <= SWEEP_MAX_POINTS)) {
            if (r->count < 1e15)
                snprintf(msg, len, "range '%s' gives %.0f values, more than %d", item, r->count, SWEEP_MAX_POINTS);
            else
                snprintf(msg, len, "range '%s' gives more than %d values", item, SWEEP_MAX_POINTS);
        } else {
            rc = 0;
        }
    }
    free(a);
    free(rest);
    return rc;
}

/* Value i of a range (i < r->count). a + i s stays within [A, B]: no overflow. */
static char *range_value(const Range *r, long long i)
{
    if (r->ints)
        return xasprintf("%lld", (long long)((unsigned long long)r->a + (unsigned long long)i * (unsigned long long)r->s));
    return xasprintf("%.10g", r->af + (double)i * r->sf);
}

/* ---- the sweep file ------------------------------------------------------------------------- */

/* The syntax is sim/ini.c's (docs/ini.md); this part knows [sweep] and [point.NAME] and their keys. */

typedef struct SfKey {
    const IniEntry *e;
    SweepStrs items;  /* a [sweep] key: its list's items (values or ranges) */
    double count;   /* the values they give */
    int bad;        /* reported */
    SweepStrs vals;   /* the values, once checked */
} SfKey;

static int point_name_ok(const char *s)
{
    if (!*s)
        return 0;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z') || (*s >= '0' && *s <= '9') || *s == '-' ||
              *s == '_'))
            return 0;
    return 1;
}

/* Split a [sweep] key's list into items and count its values (without making them). A list
 * continues on indented lines: a line break is a comma, and a comma may end the line before. */
static void sf_list_count(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    UtilBuf joined = {0};
    for (const char *p = e->value; *p;) {
        size_t n = strcspn(p, "\n");
        char *line = xstrndup(p, n);
        char *t = sweep_trim(line);
        size_t tl = strlen(t);
        if (tl && t[tl - 1] == ',')
            t[--tl] = 0;
        if (tl) {
            if (joined.len)
                util_buf_puts(&joined, ",");
            util_buf_puts(&joined, t);
        }
        free(line);
        p += n + (p[n] == '\n');
    }
    int empty = 0;
    for (const char *p = sweep_buf_text(&joined);;) {
        size_t n = strcspn(p, ",");
        char *item = xstrndup(p, n);
        char *t = sweep_trim(item);
        memmove(item, t, strlen(t) + 1);
        empty += !*item;
        sweep_strs_push(&k->items, item);
        if (!p[n])
            break;
        p += n + 1;
    }
    util_buf_free(&joined);
    if (empty) {
        inifile_error(f, e->line, "key '%s': %s", e->key, empty == k->items.n ? "empty list" : "an empty item in the list");
        k->bad = 1;
        return;
    }
    char msg[512];
    k->count = 0;
    for (int i = 0; i < k->items.n; i++) {
        Range r;
        if (!strstr(k->items.v[i], "..")) {
            k->count += 1;
        } else if (range_parse(k->items.v[i], &r, msg, sizeof msg) == 0) {
            k->count += r.count;
        } else {
            inifile_error(f, e->line, "key '%s': %s", e->key, msg);
            k->bad = 1;
        }
    }
}

/* For the duplicate check: a value as a number (8 and 8.0 are one value) or as text. */
typedef struct SfVal {
    int is_num;
    double num;
    const char *text;
    int pos;
} SfVal;

static int sfval_cmp(const void *a, const void *b)
{
    const SfVal *x = a, *y = b;
    if (x->is_num != y->is_num)
        return x->is_num ? -1 : 1;
    int c = x->is_num ? (x->num < y->num ? -1 : x->num > y->num) : strcmp(x->text, y->text);
    return c ? c : (x->pos > y->pos) - (x->pos < y->pos);
}

/* Make and check the values of a [sweep] key whose items are good: each value as `--set`
 * checks it, and no value twice (sorted, so a long list costs n log n). */
static void sf_list_values(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    char msg[512];
    for (int i = 0; i < k->items.n; i++) {
        const char *item = k->items.v[i];
        Range r;
        int is_range = strstr(item, "..") != NULL;
        long long n = 1;
        if (is_range) {
            range_parse(item, &r, msg, sizeof msg); /* good: sf_list_count said so */
            n = (long long)r.count;
        }
        for (long long j = 0; j < n; j++) {
            char *v = is_range ? range_value(&r, j) : xstrdup(item);
            int unknown;
            if (sweep_value_check(e->key, v, &unknown, msg, sizeof msg)) {
                if (is_range)
                    inifile_error(f, e->line, "key '%s': in %s: %s", e->key, item, msg);
                else
                    inifile_error(f, e->line, "key '%s': %s", e->key, msg);
                k->bad = 1;
                free(v);
                break;
            }
            sweep_strs_push(&k->vals, v);
        }
    }
    if (k->vals.n < 2)
        return;
    SfVal *sv = xrealloc(NULL, (size_t)k->vals.n * sizeof *sv);
    for (int i = 0; i < k->vals.n; i++) {
        sv[i].text = k->vals.v[i];
        sv[i].pos = i;
        sv[i].is_num = sweep_is_number(k->vals.v[i], &sv[i].num);
    }
    qsort(sv, (size_t)k->vals.n, sizeof *sv, sfval_cmp);
    /* Each value given more than once; say the one repeated first, and how many others are. */
    int first = -1, repeated = 0;
    for (int i = 1; i < k->vals.n; i++) {
        const SfVal *x = &sv[i - 1], *y = &sv[i];
        int same = x->is_num == y->is_num && (x->is_num ? x->num == y->num : !strcmp(x->text, y->text));
        int group_start = i < 2 || !(sv[i - 2].is_num == x->is_num &&
                                     (x->is_num ? sv[i - 2].num == x->num : !strcmp(sv[i - 2].text, x->text)));
        if (same && group_start) { /* y is the group's second occurrence */
            repeated++;
            if (first < 0 || y->pos < sv[first].pos)
                first = i;
        }
    }
    if (repeated) {
        inifile_error(f, e->line, "key '%s': value %s appears twice in the list%s", e->key, sv[first].text,
                      repeated > 1 ? " (and other values too)" : "");
        k->bad = 1;
    }
    free(sv);
}

/* A [point.NAME] key: one value. */
static void sf_point_value(IniFile *f, SfKey *k)
{
    const IniEntry *e = k->e;
    const char *v = e->value;
    char msg[512];
    int unknown;
    msg[0] = 0;
    if (!*v)
        snprintf(msg, sizeof msg, "empty value");
    else if (strchr(v, ',') || strchr(v, '\n'))
        snprintf(msg, sizeof msg, "a point takes one value, not a list ('%.*s')", (int)strcspn(v, "\n"), v);
    else if (strstr(v, ".."))
        snprintf(msg, sizeof msg, "a point takes one value, not a range ('%s')", v);
    else if (sweep_value_check(e->key, v, &unknown, msg, sizeof msg) == 0)
        sweep_strs_push(&k->vals, xstrdup(v));
    if (msg[0]) {
        inifile_error(f, e->line, "key '%s': %s", e->key, msg);
        k->bad = 1;
    }
}

/* The points of a sweep file (its text, read once) as the manifest's "points" array, or NULL
 * after adding every problem to errs. The number of points is known, and refused beyond
 * SWEEP_MAX_POINTS, before any value is made. */
cJSON *sweep_file_points(const char *path, const char *text, size_t len, SweepErrs *errs, int *explicit_points)
{
    IniFile f;
    const IniOptions opt = {0, 1, NULL};
    inifile_parse(&f, path, text, len, &opt);
    cJSON *points = NULL;
    int nsec = f.nsections, sweep_line = 0, point_line = 0, npoints = 0;
    char *sec_ok = xrealloc(NULL, (size_t)nsec + 1);
    for (int i = 0; i < nsec; i++) {
        const IniSection *s = &f.sections[i];
        int is_sweep = !strcmp(s->name, "sweep"), is_point = !strncmp(s->name, "point.", 6);
        sec_ok[i] = 0;
        if (!is_sweep && !is_point) {
            inifile_error(&f, s->line, "unknown section [%s] (a sweep file has a [sweep] section or [point.NAME] "
                                       "sections)", s->name);
            continue;
        }
        if (is_point && !point_name_ok(s->name + 6)) {
            inifile_error(&f, s->line, "section [%s]: a point's name is letters, digits, '-' and '_'", s->name);
            continue;
        }
        if ((is_sweep && point_line) || (is_point && sweep_line && !point_line))
            inifile_error(&f, s->line, "[%s] in a file with %s (line %d): a sweep file has a [sweep] section or "
                          "[point.NAME] sections, not both", s->name, is_sweep ? "[point.NAME] sections" : "[sweep]",
                          is_sweep ? point_line : sweep_line);
        if (is_sweep)
            sweep_line = s->line;
        else if (!point_line)
            point_line = s->line;
        npoints += is_point;
        sec_ok[i] = 1;
        if (!s->nkeys && !s->nbad)
            inifile_error(&f, s->line, "[%s] has no keys", s->name);
    }
    if (!sweep_line && !point_line && (f.nsections || !f.nerrors)) /* (not for a binary file) */
        inifile_error(&f, 0, "no [sweep] section and no [point.NAME] section");
    if (npoints > SWEEP_MAX_POINTS)
        inifile_error(&f, 0, "%d points, more than %d (split the sweep)", npoints, SWEEP_MAX_POINTS);

    /* The keys: known ones, then a [sweep] key's list counted, a point's value checked. */
    SfKey *keys = xrealloc(NULL, ((size_t)f.nentries + 1) * sizeof *keys);
    memset(keys, 0, ((size_t)f.nentries + 1) * sizeof *keys);
    double total = 1;
    int nlists = 0;
    char factors[256] = "";
    for (int i = 0; i < f.nentries; i++) {
        SfKey *k = &keys[i];
        k->e = &f.entries[i];
        k->bad = 1;
        if (!sec_ok[k->e->sec])
            continue; /* its section is reported */
        char msg[512];
        int unknown;
        if (!key_known(k->e->key)) {
            sweep_value_check(k->e->key, "0", &unknown, msg, sizeof msg);
            inifile_error(&f, k->e->line, "key '%s': %s", k->e->key, msg);
            continue;
        }
        k->bad = 0;
        if (!strcmp(k->e->section, "sweep")) {
            sf_list_count(&f, k);
            if (!k->bad) {
                total *= k->count;
                size_t fl = strlen(factors);
                if (fl + 40 < sizeof factors)
                    snprintf(factors + fl, sizeof factors - fl, "%s%.0f", nlists ? " x " : "", k->count);
                else if (!strstr(factors, "..."))
                    strcat(factors, " x ...");
                nlists++;
            }
        } else if (npoints <= SWEEP_MAX_POINTS) {
            sf_point_value(&f, k);
        }
    }
    if (sweep_line && !point_line && total > SWEEP_MAX_POINTS) {
        if (total < 1e15)
            inifile_error(&f, sweep_line, "[sweep]: %.0f points (%s values), more than %d (split the sweep)", total,
                          factors, SWEEP_MAX_POINTS);
        else
            inifile_error(&f, sweep_line, "[sweep]: more than %d points (%s values; split the sweep)", SWEEP_MAX_POINTS,
                          factors);
    } else {
        for (int i = 0; i < f.nentries; i++)
            if (!keys[i].bad && !strcmp(keys[i].e->section, "sweep"))
                sf_list_values(&f, &keys[i]);
    }
    int n;
    const IniMessage *m = inifile_messages(&f, &n);
    for (int i = 0; i < n; i++)
        sweep_err_add(errs, "%s", m[i].text);
    errs->count += f.nerrors - n; /* a last "... and N more errors" line stands for N */
    if (f.nerrors)
        goto out;

    *explicit_points = point_line != 0;
    points = cJSON_CreateArray();
    if (*explicit_points) {
        int e = 0;
        for (int i = 0; i < nsec; i++) {
            cJSON *p = cJSON_CreateObject(), *set = cJSON_CreateObject();
            cJSON_AddStringToObject(p, "name", f.sections[i].name + 6);
            for (; e < f.nentries && keys[e].e->sec == i; e++)
                cJSON_AddStringToObject(set, keys[e].e->key, keys[e].vals.v[0]);
            cJSON_AddItemToObject(p, "settings", set);
            cJSON_AddItemToArray(points, p);
        }
        goto out;
    }
    /* The cross product, the first key varying slowest. */
    long long ntotal = (long long)total;
    for (long long p = 0; p < ntotal; p++) {
        cJSON *pt = cJSON_CreateObject(), *set = cJSON_CreateObject();
        long long rest = p, stride = ntotal;
        for (int j = 0; j < f.nentries; j++) {
            stride /= keys[j].vals.n;
            cJSON_AddStringToObject(set, keys[j].e->key, keys[j].vals.v[rest / stride]);
            rest %= stride;
        }
        cJSON_AddItemToObject(pt, "settings", set);
        cJSON_AddItemToArray(points, pt);
    }
out:
    for (int i = 0; i < f.nentries; i++) {
        sweep_strs_free(&keys[i].items);
        sweep_strs_free(&keys[i].vals);
    }
    free(keys);
    free(sec_ok);
    inifile_free(&f);
    return points;
}
