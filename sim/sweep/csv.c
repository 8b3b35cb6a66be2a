/* sim/sweep/csv.c -- sweep.csv: a row per point, its keys, status and error, and the figures of
 * its report.json.
 *
 * Owns: each point's row (its state, and its figures read back from its report.json through the
 * statistics registry, stats_csv_read), finding a figure column by name (sweep_col, for the
 * plots), and writing the CSV (quoting, number format, empty cells for figures a point does not
 * have). Must not: name, order or compute a figure column: they are the rows of sim/stats.def
 * with a CSV name, expanded by sim/stats_csv.c; nor decide a point's state (folder.c reads its
 * markers).
 */
#include "../../host/outfile.h"
#include "sweep_int.h"

#include <math.h>

/* ---- the figure columns -------------------------------------------------------------------- */

int sweep_col(const char *name, char *err, size_t errlen)
{
    char buf[128];
    for (int m = 0, n = stats_csv_count(); m < n; m++)
        if (!strcmp(stats_csv_name(m, buf, sizeof buf), name))
            return m;
    snprintf(err, errlen, "sweep.csv has no column '%s' (its figure columns are the CSV names of sim/stats.def)",
             name);
    return -1;
}

/* ---- a point's row ------------------------------------------------------------------------- */

void sweep_row_init(SweepRow *row)
{
    size_t n = (size_t)stats_csv_count();
    memset(row, 0, sizeof *row);
    row->m = xrealloc(NULL, n * sizeof *row->m);
    row->has = xrealloc(NULL, n);
    memset(row->m, 0, n * sizeof *row->m);
    memset(row->has, 0, n);
}

void sweep_row_clear(SweepRow *row)
{
    free(row->error);
    free(row->m);
    free(row->has);
    memset(row, 0, sizeof *row);
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
    stats_csv_read(j, row->m, row->has);
    cJSON_Delete(j);
    return 0;
}

/* ---- the rows and the file ----------------------------------------------------------------- */

SweepRow *sweep_rows_collect(const SweepPlan *pl, const char *dir, int *ndone, int *nfailed, int *nunfinished)
{
    SweepRow *rows = xrealloc(NULL, (size_t)pl->npoints * sizeof *rows);
    for (int k = 0; k < pl->npoints; k++)
        sweep_row_init(&rows[k]);
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
        sweep_row_clear(&rows[i]);
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
    int ncols = stats_csv_count();
    util_buf_puts(&b, "point");
    for (int k = 0; k < pl->nkeys; k++) {
        util_buf_puts(&b, ",");
        csv_field(&b, pl->keys[k], 0);
    }
    util_buf_puts(&b, ",status,error");
    for (int m = 0; m < ncols; m++)
        util_buf_printf(&b, ",%s", stats_csv_name(m, name, sizeof name));
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
        for (int m = 0; m < ncols; m++) {
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
