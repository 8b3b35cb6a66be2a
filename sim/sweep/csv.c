/* sim/sweep/csv.c -- sweep.csv: a row per point, its keys, status and error, and the figures of
 * its report.json.
 *
 * Owns: reading the figures back from each point's report.json and writing the CSV (quoting,
 * number format, empty cells for figures a point does not have), both by one walk over the
 * column list of csv_columns.def. Must not: list a column anywhere but csv_columns.def, compute
 * a figure the report does not hold (beyond the SHARE rows' division), or decide a point's state
 * (folder.c reads its markers).
 */
#include "../outfile.h"
#include "sweep_int.h"

#include <math.h>

const int sweep_stages[SWEEP_N_STAGE] = {ISA_STAGE_TRAVERSAL, ISA_STAGE_INTERSECTION, ISA_STAGE_SHADING,
                                         ISA_STAGE_OTHER};

/* ---- the column list, expanded ------------------------------------------------------------- */

enum { SWEEP_AS_IS, SWEEP_SHARE };

typedef struct ColumnGroup {
    int first;               /* SWEEP_M_<ID> */
    const char *name, *path; /* formats: %s the dimensions' keys */
    SweepDim outer, inner;
    int how;
} ColumnGroup;

static const ColumnGroup groups[] = {
#define SWEEP_COLUMN(id, name, path, outer, inner, how) \
    {SWEEP_M_##id, name, path, SWEEP_D_##outer, SWEEP_D_##inner, SWEEP_##how},
#include "csv_columns.def"
#undef SWEEP_COLUMN
};
#define NGROUPS (int)(sizeof groups / sizeof groups[0])

static int dim_size(SweepDim d)
{
    switch (d) {
    case SWEEP_D_ONE:
        return SWEEP_N_ONE;
    case SWEEP_D_CI95:
        return SWEEP_N_CI95;
    case SWEEP_D_STAGE:
        return SWEEP_N_STAGE;
    case SWEEP_D_CAUSE:
        return SWEEP_N_CAUSE;
    case SWEEP_D_CATEGORY:
        return SWEEP_N_CATEGORY;
    case SWEEP_D_KD_KIND:
        return SWEEP_N_KD_KIND;
    case SWEEP_D_KD_COUNTER:
        return SWEEP_N_KD_COUNTER;
    }
    return 1;
}

/* Key i of a dimension, for the column names and the report paths. */
static const char *dim_key(SweepDim d, int i)
{
    static const char *const ci95[SWEEP_N_CI95] = {"lo", "hi"};
    switch (d) {
    case SWEEP_D_ONE:
        return "";
    case SWEEP_D_CI95:
        return ci95[i];
    case SWEEP_D_STAGE:
        return isa_stage_keys[sweep_stages[i]];
    case SWEEP_D_CAUSE:
        return tm_cause_keys[i];
    case SWEEP_D_CATEGORY:
        return isa_category_keys[i];
    case SWEEP_D_KD_KIND:
        return func_kd_kind_keys[i];
    case SWEEP_D_KD_COUNTER:
        return func_kd_counter_keys[i];
    }
    return "";
}

/* Column m's group and its place in the group's dimensions. */
static const ColumnGroup *column_of(int m, int *outer, int *inner)
{
    int g = NGROUPS - 1;
    while (g > 0 && groups[g].first > m)
        g--;
    int i = m - groups[g].first, ni = dim_size(groups[g].inner);
    *outer = i / ni;
    *inner = i % ni;
    return &groups[g];
}

void sweep_metric_name(int m, char *buf, size_t len)
{
    int o, i;
    const ColumnGroup *g = column_of(m, &o, &i);
    snprintf(buf, len, g->name, dim_key(g->outer, o), dim_key(g->inner, i));
}

/* ---- reading a report ---------------------------------------------------------------------- */

/* The value at a column's path in the report, or NULL. */
static const cJSON *report_value(const cJSON *j, const ColumnGroup *g, int o, int i)
{
    char path[256];
    snprintf(path, sizeof path, g->path, dim_key(g->outer, o), dim_key(g->inner, i));
    const cJSON *it = j;
    for (char *seg = path, *next; seg && it; seg = next) {
        next = strchr(seg, '/');
        if (next)
            *next++ = 0;
        if (!strcmp(seg, "[]"))
            it = cJSON_IsArray(it) && cJSON_GetArraySize(it) == dim_size(g->outer) ? cJSON_GetArrayItem(it, o) : NULL;
        else
            it = cJSON_GetObjectItemCaseSensitive(it, seg);
    }
    return it;
}

static void row_num(SweepRow *row, int m, const cJSON *it)
{
    if (cJSON_IsNumber(it) && isfinite(it->valuedouble)) {
        row->m[m] = it->valuedouble;
        row->has[m] = 1;
    }
}

int sweep_row_read_report(SweepRow *row, const char *path, char *err, size_t errlen)
{
    size_t len;
    char *text = util_file_read(path, &len, err, errlen);
    if (!text)
        return -1;
    cJSON *j = cJSON_Parse(text);
    free(text);
    if (!cJSON_IsObject(j)) {
        snprintf(err, errlen, "%s: not a JSON object", path);
        cJSON_Delete(j);
        return -1;
    }
    for (const ColumnGroup *g = groups; g < groups + NGROUPS; g++) {
        int no = dim_size(g->outer), ni = dim_size(g->inner), n = no * ni;
        for (int o = 0; o < no; o++)
            for (int i = 0; i < ni; i++)
                row_num(row, g->first + o * ni + i, report_value(j, g, o, i));
        if (g->how != SWEEP_SHARE)
            continue;
        double sum = 0;
        for (int m = g->first; m < g->first + n; m++)
            sum += row->has[m] ? row->m[m] : 0;
        for (int m = g->first; m < g->first + n; m++) {
            if (sum > 0)
                row->m[m] /= sum;
            else
                row->has[m] = 0;
        }
    }
    cJSON_Delete(j);
    return 0;
}

/* ---- the rows and the file ----------------------------------------------------------------- */

SweepRow *sweep_rows_collect(const SweepPlan *pl, const char *dir, int *ndone, int *nfailed, int *nunfinished)
{
    SweepRow *rows = xrealloc(NULL, (size_t)pl->npoints * sizeof *rows);
    memset(rows, 0, (size_t)pl->npoints * sizeof *rows);
    *ndone = *nfailed = *nunfinished = 0;
    for (int k = 0; k < pl->npoints; k++) {
        double secs;
        rows[k].state = sweep_point_state(pl, dir, k, &secs, &rows[k].error);
        if (rows[k].state == SWEEP_DONE) {
            (*ndone)++;
            char *pdir = sweep_point_dir(pl, dir, k);
            char *report = xasprintf("%s/report.json", pdir);
            char err[PATH_MAX + 64];
            if (sweep_row_read_report(&rows[k], report, err, sizeof err))
                fprintf(stderr, "sfsim sweep: warning: %s; its row has no figures\n", err);
            free(report);
            free(pdir);
        } else if (rows[k].state == SWEEP_FAILED) {
            (*nfailed)++;
        } else {
            (*nunfinished)++;
        }
    }
    return rows;
}

void sweep_rows_free(SweepRow *rows, int n)
{
    for (int i = 0; rows && i < n; i++)
        free(rows[i].error);
    free(rows);
}

static void csv_field(UtilBuf *b, const char *s, int quote)
{
    quote |= strpbrk(s, ",\"\n\r") != NULL;
    if (!quote) {
        util_buf_puts(b, s);
        return;
    }
    util_buf_puts(b, "\"");
    for (const char *c = s; *c; c++)
        util_buf_add(b, *c == '"' ? "\"\"" : c, *c == '"' ? 2 : 1);
    util_buf_puts(b, "\"");
}

void sweep_fmt_num(double v, char *buf, size_t len)
{
    if (v == floor(v) && fabs(v) < 1e15)
        snprintf(buf, len, "%.0f", v);
    else
        snprintf(buf, len, "%.10g", v);
}

static const char *state_name(int s)
{
    return s == SWEEP_DONE ? "ok" : s == SWEEP_FAILED ? "failed" : "unfinished";
}

int sweep_csv_write(const SweepPlan *pl, const SweepRow *rows, const char *path, char *err, size_t errlen)
{
    UtilBuf b = {0};
    char name[64];
    util_buf_puts(&b, "point");
    for (int k = 0; k < pl->nkeys; k++) {
        util_buf_puts(&b, ",");
        csv_field(&b, pl->keys[k], 0);
    }
    util_buf_puts(&b, ",status,error");
    for (int m = 0; m < SWEEP_M_COUNT; m++) {
        sweep_metric_name(m, name, sizeof name);
        util_buf_printf(&b, ",%s", name);
    }
    util_buf_puts(&b, "\n");
    for (int p = 0; p < pl->npoints; p++) {
        if (pl->points[p].name)
            csv_field(&b, pl->points[p].name, 0);
        else
            util_buf_printf(&b, "%d", p);
        for (int k = 0; k < pl->nkeys; k++) {
            const char *v = sweep_plan_value(pl, p, pl->keys[k]);
            util_buf_puts(&b, ",");
            csv_field(&b, v ? v : "", 0);
        }
        util_buf_printf(&b, ",%s,", state_name(rows[p].state));
        if (rows[p].error)
            csv_field(&b, rows[p].error, 1);
        for (int m = 0; m < SWEEP_M_COUNT; m++) {
            util_buf_puts(&b, ",");
            if (rows[p].has[m]) {
                sweep_fmt_num(rows[p].m[m], name, sizeof name);
                util_buf_puts(&b, name);
            }
        }
        util_buf_puts(&b, "\n");
    }
    int rc = outfile_write_file(NULL, path, sweep_buf_text(&b), b.len, err, errlen);
    util_buf_free(&b);
    return rc;
}
