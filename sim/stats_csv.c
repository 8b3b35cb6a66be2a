/* sim/stats_csv.c -- the sweep CSV's figure columns, from the rows of sim/stats.def with a CSV
 * name, and reading them back from a point's report.json through the rows' paths.
 *
 * Owns: the column names and order (the rows' CSV numbers, each row's dimensions expanded) and
 * the reading rules (a finite number, or nothing; shares normalized), and which figures a run of a
 * mode must have (stats_csv_check, from the rows' modes). Must not: format the CSV
 * file or know the sweep's points (sim/sweep/csv.c does).
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "stats.h"
#include "stats_walk.h"

/* The sweep CSV has always listed the ray stages first. */
static const int stage_csv_order[ISA_STAGE_COUNT] = {ISA_STAGE_TRAVERSAL, ISA_STAGE_INTERSECTION, ISA_STAGE_SHADING,
                                                     ISA_STAGE_OTHER};


/* The rows with CSV columns, by their column order; their count. */
static int csv_rows(int *rows)
{
    int n = 0;
    for (int i = 0; i < stats_nrows; i++) {
        if (stats_rows[i].csv_order < 0)
            continue;
        int j = n++;
        for (; j > 0 && stats_rows[rows[j - 1]].csv_order > stats_rows[i].csv_order; j--)
            rows[j] = rows[j - 1];
        rows[j] = i;
    }
    return n;
}

static int row_elements(const StatsRow *r)
{
    int n = 1;
    for (int k = 0; k < r->ndims; k++)
        n *= stats_dim_size(r->dims[k]);
    return n;
}

/* Element e of a CSV row (row-major in the CSV's order of each dimension) as indices. */
static void csv_element(const StatsRow *r, int e, int *idx)
{
    for (int k = r->ndims - 1; k >= 0; k--) {
        int size = stats_dim_size(r->dims[k]), j = e % size;
        e /= size;
        idx[k] = r->dims[k] == STATS_D_STAGE ? stage_csv_order[j] : j;
    }
}

int stats_csv_count(void)
{
    int rows[STATS_MAX_ROWS], n = csv_rows(rows), cols = 0;
    for (int i = 0; i < n; i++)
        cols += row_elements(&stats_rows[rows[i]]);
    return cols;
}

/* The column name: the row's csv template with each "{dim}" replaced by the element's key. */
static void csv_name(const StatsRow *r, const int *idx, char *buf, size_t len)
{
    size_t o = 0;
    buf[0] = '\0';
    for (const char *p = r->csv; *p && o + 1 < len; p++) {
        const char *e = *p == '{' ? strchr(p, '}') : NULL;
        int k = 0;
        while (e && k < r->ndims && !stats_name_is(p + 1, (size_t)(e - p - 1), stats_dim_names[r->dims[k]]))
            k++;
        if (e && k < r->ndims) {
            o += (size_t)snprintf(buf + o, len - o, "%s", stats_dim_key(r->dims[k], idx[k]));
            p = e;
        } else {
            buf[o++] = *p;
            buf[o] = '\0';
        }
    }
    if (o >= len)
        buf[len - 1] = '\0';
}

const char *stats_csv_name(int col, char *buf, size_t len)
{
    int rows[STATS_MAX_ROWS], n = csv_rows(rows);
    buf[0] = '\0';
    for (int i = 0; i < n && col >= 0; i++) {
        const StatsRow *r = &stats_rows[rows[i]];
        int ne = row_elements(r);
        if (col < ne) {
            int idx[STATS_MAX_DIMS] = {0};
            csv_element(r, col, idx);
            csv_name(r, idx, buf, len);
            break;
        }
        col -= ne;
    }
    return buf;
}

/* What json_walk found at an element's path. */
enum { FOUND, ABSENT, WRONG };

static const char *json_kind(const cJSON *it)
{
    return cJSON_IsNull(it) ? "null" : cJSON_IsString(it) ? "a string" : cJSON_IsBool(it) ? "true/false"
         : cJSON_IsArray(it) ? "an array" : cJSON_IsObject(it) ? "an object" : "a number";
}

/* The report.json path of r's element idx, its first nseg segments: "stall_shares.control",
 * "fps_ci95[1]". */
static void element_key(const StatsRow *r, const int *idx, int nseg, char *key, size_t keylen)
{
    Seg seg[MAX_SEGS];
    int n = stats_path_parse(r, seg);
    size_t o = 0;
    key[0] = '\0';
    for (int s = 0; s < n && s < nseg && o < keylen; s++) {
        char k[128];
        if (seg[s].array)
            o += (size_t)snprintf(key + o, keylen - o, "[%d]", idx[seg[s].dim]);
        else
            o += (size_t)snprintf(key + o, keylen - o, "%s%s", s ? "." : "", stats_seg_key(&seg[s], r, idx, k, sizeof k));
    }
}

/* r's element idx in report: FOUND (*item: whatever is there), ABSENT (a key on the way is not
 * there) or WRONG (something on the way is not the object or array the path needs: *item). *at
 * gets the segments walked, the one where it stopped included; what (ABSENT, WRONG) what was
 * wrong there. */
static int json_walk(const cJSON *report, const StatsRow *r, const int *idx, const cJSON **item, int *at, char *what,
                     size_t whatlen)
{
    Seg seg[MAX_SEGS];
    int n = stats_path_parse(r, seg);
    const cJSON *node = report;
    what[0] = '\0';
    *item = NULL;
    *at = 0;
    for (int s = 0; s < n; s++) {
        char k[128];
        if (seg[s].array) {
            int size = stats_dim_size(r->dims[seg[s].dim]);
            if (!cJSON_IsArray(node) || cJSON_GetArraySize(node) != size) {
                *item = node;
                if (cJSON_IsArray(node))
                    snprintf(what, whatlen, "is not an array of %d (an array of %d)", size, cJSON_GetArraySize(node));
                else
                    snprintf(what, whatlen, "is not an array of %d (%s)", size, json_kind(node));
                return WRONG;
            }
            *at = s + 1;
            node = cJSON_GetArrayItem(node, idx[seg[s].dim]);
            continue;
        }
        if (!cJSON_IsObject(node)) {
            *item = node;
            snprintf(what, whatlen, "is not an object (%s)", json_kind(node));
            return WRONG;
        }
        *at = s + 1;
        node = cJSON_GetObjectItemCaseSensitive(node, stats_seg_key(&seg[s], r, idx, k, sizeof k));
        if (!node) {
            snprintf(what, whatlen, "missing");
            return ABSENT;
        }
    }
    *item = node;
    return n > 0 ? FOUND : ABSENT;
}

const char *stats_csv_key(int col, char *buf, size_t len)
{
    int rows[STATS_MAX_ROWS], n = csv_rows(rows);
    buf[0] = '\0';
    for (int i = 0; i < n && col >= 0; i++) {
        const StatsRow *r = &stats_rows[rows[i]];
        int ne = row_elements(r);
        if (col < ne) {
            int idx[STATS_MAX_DIMS] = {0};
            csv_element(r, col, idx);
            element_key(r, idx, MAX_SEGS, buf, len);
            break;
        }
        col -= ne;
    }
    return buf;
}

/* The report's item at r's path for element idx, or NULL. An array must have the dimension's size. */
static const cJSON *json_find(const cJSON *report, const StatsRow *r, const int *idx)
{
    Seg seg[MAX_SEGS];
    int n = stats_path_parse(r, seg);
    const cJSON *node = report;
    for (int s = 0; s < n && node; s++) {
        char key[128];
        if (seg[s].array) {
            StatsDim d = r->dims[seg[s].dim];
            if (!cJSON_IsArray(node) || cJSON_GetArraySize(node) != stats_dim_size(d))
                return NULL;
            node = cJSON_GetArrayItem(node, idx[seg[s].dim]);
        } else {
            node = cJSON_GetObjectItemCaseSensitive(node, stats_seg_key(&seg[s], r, idx, key, sizeof key));
        }
    }
    return n > 0 ? node : NULL;
}

void stats_csv_read(const cJSON *report, double *value, unsigned char *has)
{
    int rows[STATS_MAX_ROWS], n = csv_rows(rows), col = 0;
    for (int i = 0; i < n; i++) {
        const StatsRow *r = &stats_rows[rows[i]];
        int ne = row_elements(r);
        double sum = 0;
        for (int e = 0; e < ne; e++) {
            int idx[STATS_MAX_DIMS] = {0};
            csv_element(r, e, idx);
            const cJSON *it = json_find(report, r, idx);
            has[col + e] = cJSON_IsNumber(it) && isfinite(it->valuedouble);
            value[col + e] = has[col + e] ? it->valuedouble : 0.0;
            sum += value[col + e];
        }
        /* shares: each element over the row's sum, none when the sum is not positive */
        for (int e = 0; e < ne && (r->flags & STATS_F_NORMALIZE); e++) {
            if (sum > 0)
                value[col + e] /= sum;
            else
                has[col + e] = 0;
        }
        col += ne;
    }
}

/* One element of a CSV row against the run's mode: 1 (and *p filled) when it is a problem. A row
 * the mode has must hold a finite number (a SPARSE row's element may be absent); one it does not
 * have may be absent or null (report.json nulls cycles in functional mode) or a number, but
 * nothing else. */
static int element_problem(const cJSON *report, const StatsRow *r, const int *idx, int present, StatsCsvProblem *p)
{
    const cJSON *it;
    int at;
    int got = json_walk(report, r, idx, &it, &at, p->what, sizeof p->what);
    if (got == ABSENT && (!present || (r->flags & STATS_F_SPARSE)))
        return 0;
    if (got == WRONG && !present && cJSON_IsNull(it))
        return 0;
    if (got == FOUND) {
        if (cJSON_IsNumber(it) && isfinite(it->valuedouble))
            return 0;
        if (!present && cJSON_IsNull(it))
            return 0;
        if (cJSON_IsNumber(it))
            snprintf(p->what, sizeof p->what, "is not a finite number");
        else
            snprintf(p->what, sizeof p->what, "is not a number (%s)", json_kind(it));
    }
    element_key(r, idx, at, p->key, sizeof p->key);
    return 1;
}

int stats_csv_check(const cJSON *report, unsigned mode, StatsCsvProblem *out, int max)
{
    int rows[STATS_MAX_ROWS], n = csv_rows(rows), col = 0, count = 0;
    StatsCsvProblem last = {.col = -1};
    for (int i = 0; i < n; i++) {
        const StatsRow *r = &stats_rows[rows[i]];
        int ne = row_elements(r), present = stats_row_present(r, mode);
        for (int e = 0; e < ne; e++) {
            int idx[STATS_MAX_DIMS] = {0};
            StatsCsvProblem p = {.col = col + e};
            csv_element(r, e, idx);
            if (!element_problem(report, r, idx, present, &p))
                continue;
            /* one problem on the way to a row's elements ("utilization" is a number) is one */
            if (last.col >= 0 && !strcmp(p.key, last.key) && !strcmp(p.what, last.what))
                continue;
            if (count < max)
                out[count] = p;
            count++;
            last = p;
        }
        col += ne;
    }
    return count;
}
