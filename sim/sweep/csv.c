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

#include <errno.h>
#include <math.h>
#include <unistd.h>

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

unsigned sweep_stats_mode(const char *mode)
{
    if (mode && !strcmp(mode, "functional"))
        return STATS_M_FUNC;
    if (mode && !strcmp(mode, "sampled"))
        return STATS_M_SAMP;
    return STATS_M_DET; /* the manifest's default, as sfsim sweep's */
}

/* The figures report.json lacks or holds wrong for a run of mode (STATS_M_*): their count, and
 * when there are any, "PATH: key 'K' what; key ..." in err (the first SWEEP_REPORT_PROBLEMS). */
#define SWEEP_REPORT_PROBLEMS 4
static int report_problems(const cJSON *j, unsigned mode, const char *path, char *err, size_t errlen)
{
    StatsCsvProblem p[SWEEP_REPORT_PROBLEMS];
    /* report.json has a kd block exactly when the kernel walked a kd-tree (sim/report.c), the
     * runs whose kd rows are written (STATS_M_KD) */
    const cJSON *kd = cJSON_GetObjectItemCaseSensitive(j, "kd");
    if (cJSON_IsObject(kd) && cJSON_IsString(cJSON_GetObjectItemCaseSensitive(kd, "structure")))
        mode |= STATS_M_KD;
    /* ... and a chip block exactly for a chip's run, a memory block with shared memory */
    if (cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(j, "chip")))
        mode |= STATS_M_CHIP;
    if (cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(j, "memory")))
        mode |= STATS_M_SHARED;
    int n = stats_csv_check(j, mode, p, SWEEP_REPORT_PROBLEMS);
    if (n == 0)
        return 0;
    size_t o = (size_t)snprintf(err, errlen, "%s:", path);
    for (int i = 0; i < n && i < SWEEP_REPORT_PROBLEMS && o < errlen; i++)
        o += (size_t)snprintf(err + o, errlen - o, "%s key '%s' %s", i ? ";" : "", p[i].key, p[i].what);
    if (n > SWEEP_REPORT_PROBLEMS && o < errlen)
        snprintf(err + o, errlen - o, " (and %d more)", n - SWEEP_REPORT_PROBLEMS);
    return n;
}

int sweep_row_read_report(SweepRow *row, const char *path, unsigned mode, char *err, size_t errlen)
{
    size_t len;
    if (access(path, F_OK) != 0 && errno == ENOENT) {
        snprintf(err, errlen, "%s: missing", path);
        return -1;
    }
    char *text = util_file_read(path, &len, err, errlen);
    if (!text)
        return -1;
    const char *end = NULL;
    cJSON *j = cJSON_ParseWithLengthOpts(text, len, &end, 0);
    if (!j) {
        size_t at = end && end >= text && end <= text + len ? (size_t)(end - text) : len;
        snprintf(err, errlen, "%s: not valid JSON at byte %zu of %zu%s", path, at, len,
                 len == 0 ? " (an empty file)" : at + 1 >= len ? " (the text ends there: truncated?)" : "");
        free(text);
        return -1;
    }
    free(text);
    if (!cJSON_IsObject(j)) {
        snprintf(err, errlen, "%s: not a JSON object", path);
        cJSON_Delete(j);
        return -1;
    }
    stats_csv_read(j, row->m, row->has);
    int rc = mode && report_problems(j, mode, path, err, errlen) > 0 ? -1 : 0;
    cJSON_Delete(j);
    return rc;
}

/* ---- the rows and the file ----------------------------------------------------------------- */

/* A done point whose report.json cannot give the figures its mode writes is failed: its row keeps
 * the figures that were read, the error names the file and what is wrong, and stderr says so. */
static void row_read_done(const SweepPlan *pl, const char *dir, int k, SweepRow *row)
{
    char *pdir = sweep_point_dir(pl, dir, k);
    char *report = xasprintf("%s/report.json", pdir);
    char err[PATH_MAX + 1024];
    if (sweep_row_read_report(row, report, sweep_stats_mode(pl->mode), err, sizeof err)) {
        char *label = sweep_point_label(pl, k);
        fprintf(stderr, "sweep: %s failed: %s\n", label, err);
        free(label);
        row->state = SWEEP_FAILED;
        free(row->error);
        /* the cell names the file inside the point's folder */
        const char *rel = strncmp(err, pdir, strlen(pdir)) || err[strlen(pdir)] != '/' ? err : err + strlen(pdir) + 1;
        row->error = xasprintf("%s", rel);
    }
    free(report);
    free(pdir);
}

SweepRow *sweep_rows_collect(const SweepPlan *pl, const char *dir, int *ndone, int *nfailed, int *nunfinished)
{
    SweepRow *rows = xrealloc(NULL, (size_t)pl->npoints * sizeof *rows);
    for (int k = 0; k < pl->npoints; k++)
        sweep_row_init(&rows[k]);
    *ndone = *nfailed = *nunfinished = 0;
    for (int k = 0; k < pl->npoints; k++) {
        double secs;
        rows[k].state = sweep_point_state(pl, dir, k, &secs, &rows[k].error);
        if (rows[k].state == SWEEP_DONE)
            row_read_done(pl, dir, k, &rows[k]);
        if (rows[k].state == SWEEP_DONE)
            (*ndone)++;
        else if (rows[k].state == SWEEP_FAILED)
            (*nfailed)++;
        else
            (*nunfinished)++;
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
