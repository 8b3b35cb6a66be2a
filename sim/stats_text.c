/* sim/stats_text.c -- the statistics registry's text: report.txt's statistics lines, the
 * `sfsim exec --timing` print-out and stats.txt (gem5's form), from the walk over sim/stats.def.
 *
 * Owns: the layout (a line per row group, a table for 2-D rows, the headline sentences; stats.txt's
 * names and lines) and the number format of each unit. Must not: compute a figure (sim/stats.c
 * does) or name a counter.
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "stats.h"
#include "stats_walk.h"

typedef struct TextW {
    const StatsCtx *c;
    FILE *fp;              /* the exec print-out; else buf */
    char *buf;
    size_t cap, *len;
    int open, items;       /* a line is open; values on it */
    const char *label;     /* the open line's row label (a MORE row with a path and another label
                              starts its own line: a mode that lacks a group's LINE row) */
} TextW;

static void out(TextW *w, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void out(TextW *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (w->fp) {
        vfprintf(w->fp, fmt, ap);
    } else if (*w->len < w->cap) {
        int n = vsnprintf(w->buf + *w->len, w->cap - *w->len, fmt, ap);
        *w->len = n < 0 ? *w->len : *w->len + (size_t)n < w->cap ? *w->len + (size_t)n : w->cap - 1;
    }
    va_end(ap);
}

/* A frame rate with three significant digits below 1 fps (0.0794, not 0.08), else two decimals. */
static const char *fps_text(double v, char *buf, size_t len)
{
    snprintf(buf, len, v >= 1.0 || v <= 0.0 ? "%.2f" : "%.3g", v);
    return buf;
}

/* A value in its unit's format; "-" where it has no meaning. */
static const char *fmt_value(const StatsRow *r, double v, int na, char *buf, size_t len)
{
    if (na)
        return "-";
    switch (r->unit) {
    case STATS_U_RATIO: snprintf(buf, len, "%.1f%%", 100.0 * v); break;
    case STATS_U_PER_RAY: case STATS_U_CPI: snprintf(buf, len, "%.3f", v); break;
    case STATS_U_RAYS_PER_STREAM: snprintf(buf, len, "%.1f", v); break;
    case STATS_U_FPS: fps_text(v, buf, len); break;
    case STATS_U_MHZ: case STATS_U_NUMBER: snprintf(buf, len, "%g", v); break;
    case STATS_U_JOULES: case STATS_U_WATTS: case STATS_U_MM2: snprintf(buf, len, "%.4g", v); break;
    case STATS_U_FLAG: snprintf(buf, len, "%s", v != 0 ? "yes" : "no"); break;
    default: snprintf(buf, len, "%.0f", v); break;
    }
    return buf;
}

static const char *elem_text(TextW *w, const StatsRow *r, const int *idx, char *buf, size_t len)
{
    int na;
    double v = stats_row_value(w->c, r, idx, &na);
    return fmt_value(r, v, na, buf, len);
}

static void line_end(TextW *w)
{
    if (w->open)
        out(w, "\n");
    w->open = w->items = 0;
}

static void line_start(TextW *w, const char *head)
{
    line_end(w);
    out(w, "%-12s", head);
    w->open = 1;
}

static void line_item(TextW *w, const char *name, const char *value)
{
    out(w, "%s %s %s", w->items++ ? "," : "", name, value);
}

/* The headline: report.txt's first timing lines, the exec print-out's first line. */
static void headline(TextW *w, const StatsRow *r)
{
    const StatsCtx *c = w->c;
    const TimingStats *t = c->t;
    line_end(w);
    if (c->mode & STATS_M_EXEC) {
        out(w, "timing: %llu cycles = %llu busy + %llu stall\n", (unsigned long long)t->cycles,
            (unsigned long long)t->busy, (unsigned long long)(t->cycles - t->busy));
        return;
    }
    StatsFrame s = stats_frame_of(c);
    double mhz = c->cfg->core_clock_mhz;
    char f0[32], f1[32], f2[32], f3[32];
    fps_text(s.fps, f0, sizeof f0);
    fps_text(s.fps_no_stall, f3, sizeof f3);
    if (c->est)
        out(w, "%-12s ~%.0f (95%%: %.0f .. %.0f) = ~%.0f busy + ~%.0f stalled; estimated from %u of %u units\n"
            "fps          ~%s (95%%: %s .. %s) at %g MHz (%s fps with no stalls)\n"
            "sample       the shares and unit lines below are those of the %u sampled units (docs/sampling.md)\n",
            r->label, s.cycles, s.cycles_lo, s.cycles_hi, s.busy, s.cycles - s.busy, c->est->n, c->est->N, f0,
            fps_text(s.fps_lo, f1, sizeof f1), fps_text(s.fps_hi, f2, sizeof f2), mhz, f3, c->est->n);
    else if (c->f && c->f->chip_cores)
        out(w, "%-12s %llu, the makespan of %u cores (core-cycles: %llu busy + %llu stalled + %llu idle); %s fps "
            "at %g MHz (%s fps with no stalls and even load)\n", r->label, (unsigned long long)c->f->makespan,
            c->f->chip_cores, (unsigned long long)t->busy, (unsigned long long)(t->cycles - t->busy),
            (unsigned long long)((uint64_t)c->f->chip_cores * c->f->makespan - t->cycles), f0, mhz, f3);
    else
        out(w, "%-12s %llu = %llu busy + %llu stalled; %s fps at %g MHz (%s fps with no stalls)\n", r->label,
            (unsigned long long)t->cycles, (unsigned long long)t->busy, (unsigned long long)(t->cycles - t->busy),
            f0, mhz, f3);
}

/* A 2-D row as a table (kd counters per ray: a line per ray kind), or one more line of it. */
static void text_table(TextW *w, const StatsRow *r)
{
    char v[64];
    int idx[STATS_MAX_DIMS] = {0};
    StatsDim col = r->dims[r->ndims - 1];
    line_end(w);
    if (r->text == STATS_T_TABLE) {
        out(w, "%-12s %-8s", r->label, "");
        for (int j = 0; j < stats_dim_len(w->c, col); j++)
            out(w, " %10s", stats_dim_key(col, j));
        out(w, "\n");
    }
    int rows = r->text == STATS_T_TABLE ? stats_dim_len(w->c, r->dims[0]) : 1;
    for (int i = 0; i < rows; i++) {
        out(w, "%13s%-8s", "", r->text == STATS_T_TABLE ? stats_dim_key(r->dims[0], i) : r->label);
        for (int j = 0; j < stats_dim_len(w->c, col); j++) {
            idx[0] = r->text == STATS_T_TABLE ? i : j;
            idx[1] = j;
            out(w, " %10s", elem_text(w, r, idx, v, sizeof v));
        }
        out(w, "\n");
    }
}

static void text_row(void *wp, const StatsRow *r)
{
    TextW *w = wp;
    char name[96], v[64];
    if (!stats_row_present(r, w->c->mode) || r->text == STATS_T_NONE)
        return;
    if (r->text == STATS_T_HEAD) {
        headline(w, r);
        return;
    }
    if (r->text == STATS_T_TABLE || r->text == STATS_T_TROW) {
        text_table(w, r);
        return;
    }
    stats_leaf_name(r, name, sizeof name);
    int idx[STATS_MAX_DIMS] = {0}, na;
    if (r->text == STATS_T_LINE || !w->open || (r->path && w->label && strcmp(w->label, r->label) != 0)) {
        char head[160];
        int named = r->ndims && name[0] && !(r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z));
        snprintf(head, sizeof head, "%s%s%s", r->label, named ? " " : "", named ? name : "");
        line_start(w, head);
        w->label = r->label;
    }
    if (r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z)) {
        int any = 0;
        for (int ok = stats_idx_first(w->c, r, idx); ok; ok = stats_idx_next(w->c, r, idx))
            if ((stats_row_value(w->c, r, idx, &na) != 0) == !!(r->flags & STATS_F_LIST_NZ)) {
                out(w, " %s", stats_dim_key(r->dims[0], idx[0]));
                any = 1;
            }
        if (!any)
            out(w, " -");
    } else if (r->ndims == 0) {
        line_item(w, r->path ? name : r->label, elem_text(w, r, idx, v, sizeof v));
    } else {
        for (int ok = stats_idx_first(w->c, r, idx); ok; ok = stats_idx_next(w->c, r, idx))
            if (!(r->flags & STATS_F_SPARSE) || stats_row_value(w->c, r, idx, &na) != 0)
                line_item(w, stats_dim_key(r->dims[0], idx[0]), elem_text(w, r, idx, v, sizeof v));
    }
}

void stats_text(char *buf, size_t cap, size_t *len, const StatsCtx *c)
{
    TextW w = {.c = c, .buf = buf, .cap = cap, .len = len};
    stats_walk(c, text_row, &w);
    line_end(&w);
}

/* The exec print-out: a line per value, "  label [keys] [name]  value"; elements that are 0 left out. */
static void exec_row(void *wp, const StatsRow *r)
{
    TextW *w = wp;
    if (!stats_row_present(r, w->c->mode))
        return;
    if (r->text == STATS_T_HEAD) {
        headline(w, r);
        return;
    }
    char name[96], v[64], left[256];
    stats_leaf_name(r, name, sizeof name);
    int idx[STATS_MAX_DIMS] = {0}, na;
    for (int ok = stats_idx_first(w->c, r, idx); ok; ok = stats_idx_next(w->c, r, idx)) {
        double x = stats_row_value(w->c, r, idx, &na);
        if (r->ndims && x == 0)
            continue;
        int n = snprintf(left, sizeof left, "%s", r->label);
        for (int k = 0; k < r->ndims; k++)
            n += snprintf(left + n, sizeof left - (size_t)n, " %s", stats_dim_key(r->dims[k], idx[k]));
        if (name[0])
            snprintf(left + n, sizeof left - (size_t)n, " %s", name);
        out(w, "  %-40s %12s\n", left, fmt_value(r, x, na, v, sizeof v));
    }
}

void stats_print_exec(FILE *fp, const StatsCtx *c)
{
    TextW w = {.c = c, .fp = fp};
    stats_walk(c, exec_row, &w);
}

/* ---- stats.txt: gem5's form (docs/report.md, "stats.txt") ------------------------------------ */

/* Elements of d add up to a whole, so that a vector over d gets gem5's "::total" (a kd counter's
 * elements are different counters; a bound's are the two ends of an interval). */
static int dim_sums(StatsDim d)
{
    switch (d) {
    case STATS_D_STAGE: case STATS_D_FILTER: case STATS_D_CAUSE: case STATS_D_CATEGORY: case STATS_D_GEN:
    case STATS_D_TILE: case STATS_D_PASS: case STATS_D_OPCODE: case STATS_D_UNIT: case STATS_D_KIND: return 1;
    case STATS_D_CORE: case STATS_D_PART: case STATS_D_LEVEL: case STATS_D_DRAMPART: return 1;
    case STATS_D_COUNTER: case STATS_D_BOUND: case STATS_D_AREA: case STATS_D_COUNT: break;
    }
    return 0;
}

/* A unit whose values add up (counts, cycles, bytes), unlike ratios, rates and per-ray means. */
static int unit_sums(StatsUnit u)
{
    switch (u) {
    case STATS_U_CYCLES: case STATS_U_INSTRUCTIONS: case STATS_U_RAYS: case STATS_U_STREAMS: case STATS_U_EVENTS:
    case STATS_U_TILES: case STATS_U_UNITS: case STATS_U_ACCESSES: case STATS_U_LINES: case STATS_U_IDS:
    case STATS_U_VECTORS: case STATS_U_TRANSFERS: case STATS_U_PARTITIONS: case STATS_U_BYTES: case STATS_U_JOULES: return 1;
    case STATS_U_RAYS_PER_STREAM: case STATS_U_PER_RAY: case STATS_U_RATIO: case STATS_U_FPS: case STATS_U_MHZ:
    case STATS_U_CPI: case STATS_U_NUMBER: case STATS_U_PIXELS: case STATS_U_SECONDS: case STATS_U_FLAG:
    case STATS_U_NAMES: case STATS_U_WATTS: case STATS_U_MM2: case STATS_U_COUNT: break;
    }
    return 0;
}

/* The segment is an element of a dimension alone ("{stage}", "[gen]"), not a key around one. */
static int seg_is_element(const Seg *g) { return g->array || (g->dim >= 0 && g->prelen == 0 && g->postlen == 0); }

/* Element idx's stats.txt name: the report.json path with dots, an array index as its number (or
 * the dimension's key: lo, hi), and a last segment that is an element written gem5's "::key". With
 * total, that last segment is "total". */
static const char *gem5_name(const Seg *seg, int nseg, const StatsRow *r, const int *idx, int total, char *buf, size_t len)
{
    size_t n = 0;
    char key[128];
    buf[0] = '\0';
    for (int s = 0; s < nseg && n < len; s++) {
        const Seg *g = &seg[s];
        int last = s == nseg - 1 && seg_is_element(g);
        const char *k = g->array ? stats_dim_key(r->dims[g->dim], idx[g->dim]) : stats_seg_key(g, r, idx, key, sizeof key);
        if (g->array && !k[0]) {
            snprintf(key, sizeof key, "%d", idx[g->dim]);
            k = key;
        }
        int w = snprintf(buf + n, len - n, "%s%s", last ? "::" : s ? "." : "", last && total ? "total" : k);
        n += w > 0 ? (size_t)w : 0;
    }
    return buf;
}

/* v as report.json writes it, by cJSON itself (15 digits when they read back within an epsilon,
 * else 17), so that the two files hold the same number to the last bit. */
static const char *gem5_number(double v, char *buf, size_t len)
{
    cJSON *n = cJSON_CreateNumber(v);
    char *s = n ? cJSON_PrintUnformatted(n) : NULL;
    if (s)
        snprintf(buf, len, "%s", s);
    else   /* (out of memory: 17 digits read back exactly, if not as report.json prints them) */
        snprintf(buf, len, "%.17g", v);
    cJSON_free(s);
    cJSON_Delete(n);
    return buf;
}

static void gem5_line(FILE *fp, const char *name, double v, const StatsRow *r)
{
    char num[40];
    fprintf(fp, "%-40s %12s  # %s (%s)\n", name, gem5_number(v, num, sizeof num), r->desc, stats_unit_names[r->unit]);
}

/* One row: a line per element report.json holds (the same skipped: a sparse row's zeros), then
 * "::total" after each run of a summing last dimension. Lists of names and nulls are not numbers. */
static void gem5_row(void *wp, const StatsRow *r)
{
    TextW *w = wp;
    Seg seg[MAX_SEGS];
    int nseg = r->path ? stats_path_parse(r, seg) : -1, idx[STATS_MAX_DIMS] = {0}, na;
    if (nseg < 0 || !stats_row_present(r, w->c->mode) || (r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z)))
        return;
    const Seg *lastseg = &seg[nseg - 1];
    int totals = seg_is_element(lastseg) && unit_sums(r->unit) && dim_sums(r->dims[lastseg->dim]);
    double sum = 0.0;
    char name[512];
    for (int ok = stats_idx_first(w->c, r, idx); ok; ok = stats_idx_next(w->c, r, idx)) {
        double v = stats_row_report_value(w->c, r, idx);
        int shown = !(r->flags & STATS_F_SPARSE) || stats_row_value(w->c, r, idx, &na) != 0;
        if (shown && isfinite(v))   /* (report.json would hold null) */
            gem5_line(w->fp, gem5_name(seg, nseg, r, idx, 0, name, sizeof name), v, r);
        sum += v;
        if (totals && idx[lastseg->dim] == stats_dim_len(w->c, r->dims[lastseg->dim]) - 1) {
            if (isfinite(sum))
                gem5_line(w->fp, gem5_name(seg, nseg, r, idx, 1, name, sizeof name), sum, r);
            sum = 0.0;
        }
    }
}

int stats_gem5(FILE *fp, const StatsCtx *c)
{
    TextW w = {.c = c, .fp = fp};
    fprintf(fp, "\n---------- Begin Simulation Statistics ----------\n");
    stats_walk(c, gem5_row, &w);
    fprintf(fp, "\n---------- End Simulation Statistics   ----------\n");
    return ferror(fp) ? -1 : 0;
}
