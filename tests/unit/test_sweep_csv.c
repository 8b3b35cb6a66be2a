/* tests/unit/test_sweep_csv.c -- sweep.csv (sim/sweep/csv.c; its figure columns are the rows of
 * sim/stats.def with a CSV name): the figure columns and their order as the sweep writes them,
 * finding them by name (sweep_col, the plots' columns), figures read back from a report.json
 * written in a temporary folder (shares, the confidence interval, values of the wrong type), and
 * the whole file: key columns, status and error, quoting, number formats, and the rows of failed,
 * unfinished and report-less points; a done point whose report.json is missing, not JSON, or lacks
 * or holds wrong a figure its mode writes (sweep_check) is failed. docs/sweep.md, "sweep.csv", is
 * the contract.
 *
 * Suites: sweep_columns, sweep_report, sweep_check, sweep_csv.
 */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../sim/sweep/sweep_int.h"
#include "../support/files.h"

/* ---- helpers ------------------------------------------------------------------------------------ */

static char *name_of(int m)
{
    static char buf[8][64];
    static int next;
    char *b = buf[next++ % 8];
    return (char *)stats_csv_name(m, b, 64);
}

static int starts_with(const char *s, const char *prefix)
{
    return !strncmp(s, prefix, strlen(prefix));
}

/* One comma per figure column: the figure cells of a row that has none. */
static const char *no_figures(void)
{
    static char buf[512];
    int n = stats_csv_count();
    cr_assert_lt(n, (int)sizeof buf);
    memset(buf, ',', (size_t)n);
    buf[n] = 0;
    return buf;
}

/* The column named name (a test fails when there is none). */
static int column(const char *name)
{
    char err[256] = "";
    int m = sweep_col(name, err, sizeof err);
    cr_assert_geq(m, 0, "%s", err);
    return m;
}

/* A report.json in dir, read into a fresh row (sweep_row_clear it). */
static SweepRow read_report(const char *dir, const char *json)
{
    char path[256], err[512] = "";
    snprintf(path, sizeof path, "%s/report.json", dir);
    tu_write_file(path, json);
    SweepRow row;
    sweep_row_init(&row);
    cr_assert_eq(sweep_row_read_report(&row, path, 0, err, sizeof err), 0, "%s", err);
    return row;
}

/* Sets key (a report.json path as stats_csv_key gives it: "a.b", "a[1]") in root to v (a number,
 * or the JSON text of v_json when not NULL), making the objects and arrays on the way. */
static void put_key(cJSON *root, const char *key, double v, const char *v_json)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", key);
    cJSON *node = root;
    char *save = NULL;
    for (char *part = strtok_r(buf, ".", &save); part; part = strtok_r(NULL, ".", &save)) {
        char *br = strchr(part, '[');
        int last = !save || !*save, index = br ? atoi(br + 1) : -1;
        if (br)
            *br = 0;
        cJSON *it = cJSON_GetObjectItemCaseSensitive(node, part);
        if (br) {
            if (!it)
                it = cJSON_AddArrayToObject(node, part);
            while (cJSON_GetArraySize(it) <= index)
                cJSON_AddItemToArray(it, cJSON_CreateNumber(0));
            cJSON_ReplaceItemInArray(it, index, v_json ? cJSON_Parse(v_json) : cJSON_CreateNumber(v));
            return;
        }
        if (last) {
            cJSON_DeleteItemFromObjectCaseSensitive(node, part);
            cJSON_AddItemToObject(node, part, v_json ? cJSON_Parse(v_json) : cJSON_CreateNumber(v));
            return;
        }
        node = it ? it : cJSON_AddObjectToObject(node, part);
    }
}

/* A report.json with every figure column's key at 0 (the kd ones and a kd block only when kd):
 * every mode's report, as far as the CSV goes. */
static cJSON *full_report(int kd)
{
    cJSON *j = cJSON_CreateObject();
    char key[128];
    for (int m = 0; m < stats_csv_count(); m++) {
        stats_csv_key(m, key, sizeof key);
        cr_assert(key[0], "column %d has no key", m);
        if (kd || !starts_with(key, "kd."))
            put_key(j, key, 0, NULL);
    }
    if (kd)
        put_key(j, "kd.structure", 0, "\"kd\"");
    return j;
}

/* report.json in dir from j (deleted); sweep_row_read_report's result for mode, err its message. */
static int check_report(const char *dir, cJSON *j, unsigned mode, SweepRow *row, char *err, size_t errlen)
{
    char path[256];
    char *text = cJSON_Print(j);
    cJSON_Delete(j);
    snprintf(path, sizeof path, "%s/report.json", dir);
    tu_write_file(path, text);
    free(text);
    err[0] = 0;
    return sweep_row_read_report(row, path, mode, err, errlen);
}

/* The cells of one CSV line (quoted fields unquoted), into cells; returns how many. */
static int split_csv(const char *line, char cells[][256], int max)
{
    int n = 0;
    const char *p = line;
    for (;;) {
        cr_assert_lt(n, max);
        char *c = cells[n++];
        size_t k = 0;
        if (*p == '"') {
            for (p++; *p && !(*p == '"' && p[1] != '"'); p++) {
                if (*p == '"')
                    p++;
                c[k++] = *p;
            }
            p += *p == '"';
        } else {
            while (*p && *p != ',' && *p != '\n')
                c[k++] = *p++;
        }
        c[k] = 0;
        if (*p != ',')
            return n;
        p++;
    }
}

/* ---- the column list ---------------------------------------------------------------------------- */

Test(sweep_columns, names_in_the_documented_order)
{
    /* docs/sweep.md's table, in order */
    cr_expect_str_eq(name_of(0), "cycles");
    cr_expect_str_eq(name_of(1), "busy_cycles");
    cr_expect_str_eq(name_of(2), "fps");
    cr_expect_str_eq(name_of(3), "fps_no_stall");
    cr_expect_str_eq(name_of(4), "fps_lo");
    cr_expect_str_eq(name_of(5), "fps_hi");
    cr_expect_str_eq(name_of(6), "utilization_traversal");
    cr_expect_str_eq(name_of(7), "utilization_intersection");
    cr_expect_str_eq(name_of(8), "utilization_shading");
    cr_expect_str_eq(name_of(9), "utilization_other");
    cr_expect_str_eq(name_of(10), "utilization_timed_traversal");
    cr_expect_str_eq(name_of(13), "utilization_timed_other");
    cr_expect_str_eq(name_of(14), "stall_share_address_fetch");
    cr_expect_str_eq(name_of(14 + TM_CAUSE_COUNT), "ops_share_load");
    int rays = 14 + TM_CAUSE_COUNT + ISA_C_COUNT;
    cr_expect_str_eq(name_of(rays - 1), "ops_share_control");
    cr_expect_str_eq(name_of(rays), "rays_total");
    cr_expect_str_eq(name_of(rays + 1), "host_seconds");
    cr_expect_str_eq(name_of(rays + 2), "kd_nodes_per_ray");
    cr_expect_str_eq(name_of(rays + 7), "kd_underflows_per_ray");
    cr_expect_str_eq(name_of(rays + 8), "kd_camera_nodes_per_ray");
    cr_expect_str_eq(name_of(rays + 8 + 6), "kd_indirect_nodes_per_ray");
    const int chip = rays + 2 + 6 + 3 * 6; /* a chip's, after the kd counters (docs/chip.md) */
    cr_expect_str_eq(name_of(chip - 1), "kd_shadow_underflows_per_ray");
    cr_expect_str_eq(name_of(chip), "chip_cores");
    cr_expect_str_eq(name_of(chip + 1), "load_imbalance");
    cr_expect_str_eq(name_of(chip + 2), "memory_latency");
    cr_expect_str_eq(name_of(chip + 3), "l2_hit_rate");
    cr_expect_str_eq(name_of(chip + 4), "dram_gbs");
    cr_expect_str_eq(name_of(chip + 5), "dram_bandwidth_share");
    const int energy = chip + 6; /* energy, power and area (docs/energy.md) */
    cr_expect_str_eq(name_of(energy), "energy_j");
    cr_expect_str_eq(name_of(energy + 1), "energy_datapath_j");
    cr_expect_str_eq(name_of(energy + 7), "energy_dram_j");
    cr_expect_str_eq(name_of(energy + 8), "power_w");
    cr_expect_str_eq(name_of(energy + 9), "mrays_per_j");
    cr_expect_str_eq(name_of(energy + 10), "fps_per_w");
    cr_expect_str_eq(name_of(energy + 11), "area_simd_mm2");
    cr_expect_str_eq(name_of(energy + 20), "area_chip_mm2");
    cr_expect_str_eq(name_of(stats_csv_count() - 1), "fps_per_mm2");
    cr_expect_eq(stats_csv_count(), energy + 22);
}

/* The plots find their columns by name, once; each group's columns follow its first. */
Test(sweep_columns, the_plots_find_their_columns_by_name)
{
    SweepPlotCols c;
    char err[256] = "";
    cr_assert_eq(sweep_plot_cols(&c, err, sizeof err), 0, "%s", err);
    cr_expect_eq(c.fps, column("fps"));
    cr_expect_eq(c.fps_lo, column("fps_lo"));
    cr_expect_eq(c.fps_hi, column("fps_hi"));
    cr_expect_eq(c.util, column("utilization_traversal"));
    cr_expect_eq(c.util + 1, column("utilization_intersection"));
    cr_expect_eq(c.util + 2, column("utilization_shading"));
    cr_expect_eq(c.kd, column("kd_nodes_per_ray"));
    cr_expect_eq(c.kd_camera, column("kd_camera_nodes_per_ray"));
    char want[64];
    for (int i = 0; i < TM_CAUSE_COUNT; i++) {
        snprintf(want, sizeof want, "stall_share_%s", tm_cause_keys[i]);
        cr_expect_str_eq(name_of(c.stall + i), want);
    }
    for (int i = 0; i < ISA_C_COUNT; i++) {
        snprintf(want, sizeof want, "ops_share_%s", isa_category_keys[i]);
        cr_expect_str_eq(name_of(c.ops + i), want);
    }
}

Test(sweep_columns, a_missing_column_is_an_error_that_names_it)
{
    char err[256] = "";
    cr_expect_eq(sweep_col("fps_per_watt", err, sizeof err), -1);
    cr_expect(strstr(err, "'fps_per_watt'") != NULL, "%s", err);
    cr_expect_eq(sweep_col("", err, sizeof err), -1);
    cr_expect_eq(sweep_col("fps", err, sizeof err), 2);
}

Test(sweep_columns, every_name_is_different)
{
    int n = stats_csv_count();
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n; b++)
            cr_expect_str_neq(name_of(a), name_of(b), "columns %d and %d", a, b);
}

/* ---- reading a report --------------------------------------------------------------------------- */

Test(sweep_report, figures_are_read_at_their_paths)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    SweepRow row = read_report(dir, "{\"cycles\": 123456, \"busy_cycles\": 100000, \"fps\": 12.5,"
                                    " \"fps_ci95\": [11, 14],"
                                    " \"utilization\": {\"traversal\": 0.5, \"shading\": 0.25, \"other\": 1},"
                                    " \"stall_shares\": {\"bank_conflict\": 0.125},"
                                    " \"rays\": {\"primary\": 3, \"total\": 10}, \"host\": {\"seconds\": 0.75},"
                                    " \"kd\": {\"total\": {\"nodes_per_ray\": 7.5},"
                                    "          \"camera\": {\"nodes_per_ray\": 5, \"leaves_per_ray\": 2}}}");
    cr_expect_eq(row.has[column("cycles")], 1);
    cr_expect_float_eq(row.m[column("cycles")], 123456, 0);
    cr_expect_float_eq(row.m[column("busy_cycles")], 100000, 0);
    cr_expect_float_eq(row.m[column("fps")], 12.5, 0);
    cr_expect_eq(row.has[column("fps_no_stall")], 0, "not in the report: no value");
    cr_expect_float_eq(row.m[column("fps_lo")], 11, 0);
    cr_expect_float_eq(row.m[column("fps_hi")], 14, 0);
    cr_expect_float_eq(row.m[column("utilization_traversal")], 0.5, 0);
    cr_expect_eq(row.has[column("utilization_intersection")], 0);
    cr_expect_float_eq(row.m[column("utilization_shading")], 0.25, 0);
    cr_expect_float_eq(row.m[column("utilization_other")], 1, 0);
    cr_expect_eq(row.has[column("utilization_timed_traversal")], 0);
    cr_expect_float_eq(row.m[column("stall_share_bank_conflict")], 0.125, 0);
    cr_expect_float_eq(row.m[column("rays_total")], 10, 0);
    cr_expect_float_eq(row.m[column("host_seconds")], 0.75, 0);
    cr_expect_float_eq(row.m[column("kd_nodes_per_ray")], 7.5, 0);
    cr_expect_float_eq(row.m[column("kd_camera_nodes_per_ray")], 5, 0);
    cr_expect_float_eq(row.m[column("kd_camera_leaves_per_ray")], 2, 0);
    cr_expect_eq(row.has[column("kd_shadow_nodes_per_ray")], 0);
    int n = 0;
    for (int m = 0; m < stats_csv_count(); m++)
        n += row.has[m];
    cr_expect_eq(n, 14, "figures the report does not hold have no value"); /* the 14 checked above */
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

Test(sweep_report, operation_counts_become_shares)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    SweepRow row = read_report(dir, "{\"ops\": {\"load\": 10, \"store\": 30, \"compute\": 60}}");
    cr_expect_float_eq(row.m[column("ops_share_load")], 0.1, 1e-15);
    cr_expect_float_eq(row.m[column("ops_share_store")], 0.3, 1e-15);
    cr_expect_float_eq(row.m[column("ops_share_compute")], 0.6, 1e-15);
    cr_expect_eq(row.has[column("ops_share_control")], 0, "a category the report lacks stays empty");
    sweep_row_clear(&row);
    /* no operations at all: no shares */
    row = read_report(dir, "{\"ops\": {\"load\": 0, \"store\": 0}}");
    for (int c = 0; c < ISA_C_COUNT; c++) {
        char name[64];
        snprintf(name, sizeof name, "ops_share_%s", isa_category_keys[c]);
        cr_expect_eq(row.has[column(name)], 0, "%s", name);
    }
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

Test(sweep_report, values_of_the_wrong_kind_are_left_out)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    /* an interval of 3 numbers is not one; a string or null is no number; utilization not an object */
    SweepRow row = read_report(dir, "{\"cycles\": \"12\", \"fps\": null, \"fps_ci95\": [1, 2, 3], \"utilization\": 0.5,"
                                    " \"rays\": [10]}");
    for (int m = 0; m < stats_csv_count(); m++)
        cr_expect_eq(row.has[m], 0, "%s has a value", name_of(m));
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

Test(sweep_report, a_report_that_is_no_object_is_an_error)
{
    char dir[64], path[256], err[512] = "", want[512];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    snprintf(path, sizeof path, "%s/report.json", dir);
    tu_write_file(path, "[1, 2]");
    SweepRow row;
    sweep_row_init(&row);
    cr_expect_eq(sweep_row_read_report(&row, path, 0, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: not a JSON object", path);
    cr_expect_str_eq(err, want);
    unlink(path);
    cr_expect_eq(sweep_row_read_report(&row, path, 0, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: missing", path);
    cr_expect_str_eq(err, want);
    for (int m = 0; m < stats_csv_count(); m++)
        cr_expect_eq(row.has[m], 0, "%s has a value", name_of(m));
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

/* ---- a report that does not tell the truth ------------------------------------------------------ */

Test(sweep_check, a_report_with_every_figure_passes_in_every_mode)
{
    char dir[64], err[2048];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    static const unsigned modes[] = {STATS_M_FUNC, STATS_M_DET, STATS_M_SAMP};
    for (int kd = 0; kd < 2; kd++)
        for (int i = 0; i < 3; i++) {
            SweepRow row;
            sweep_row_init(&row);
            cr_expect_eq(check_report(dir, full_report(kd), modes[i], &row, err, sizeof err), 0, "mode %u kd %d: %s",
                         modes[i], kd, err);
            cr_expect_eq(row.has[column("cycles")], 1);
            sweep_row_clear(&row);
        }
    cr_expect_eq(sweep_stats_mode("functional"), STATS_M_FUNC);
    cr_expect_eq(sweep_stats_mode("sampled"), STATS_M_SAMP);
    cr_expect_eq(sweep_stats_mode("detailed"), STATS_M_DET);
    cr_expect_eq(sweep_stats_mode(NULL), STATS_M_DET, "the manifest's default mode");
    tu_remove_tree(dir);
}

/* A figure of the run's mode that is missing, null, a string, or under a key that is no object
 * is named (the file, the key, what is wrong); the figures that were read stay in the row. */
Test(sweep_check, a_missing_or_wrong_figure_of_the_mode_is_named)
{
    char dir[64], err[2048], want[2048];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    static const struct {
        const char *key, *json, *what;
    } cases[] = {
        {"cycles", "\"abc\"", "key 'cycles' is not a number (a string)"},
        {"cycles", "null", "key 'cycles' is not a number (null)"},
        {"busy_cycles", "true", "key 'busy_cycles' is not a number (true/false)"},
        {"stall_shares", "3", "key 'stall_shares' is not an object (a number)"},
        {"fps", "{}", "key 'fps' is not a number (an object)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cJSON *j = full_report(0);
        put_key(j, "fps_no_stall", 2.5, NULL);
        put_key(j, cases[i].key, 0, cases[i].json);
        SweepRow row;
        sweep_row_init(&row);
        cr_expect_eq(check_report(dir, j, STATS_M_DET, &row, err, sizeof err), -1, "%s", cases[i].what);
        snprintf(want, sizeof want, "%s/report.json: %s", dir, cases[i].what);
        cr_expect_str_eq(err, want);
        cr_expect(row.has[column("fps_no_stall")] && row.m[column("fps_no_stall")] == 2.5,
                  "the figures read are kept (%s)", cases[i].what);
        sweep_row_clear(&row);
    }
    /* a key missing, and several problems at once: the first four, and how many more */
    cJSON *j = full_report(0);
    cJSON_DeleteItemFromObjectCaseSensitive(j, "cycles");
    SweepRow row;
    sweep_row_init(&row);
    cr_expect_eq(check_report(dir, j, STATS_M_DET, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'cycles' missing", dir);
    cr_expect_str_eq(err, want);
    cr_expect_eq(row.has[column("cycles")], 0);
    cr_expect_eq(row.has[column("busy_cycles")], 1);
    j = full_report(0);
    for (const char *const *k = (const char *const[]){"cycles", "busy_cycles", "fps", "fps_no_stall", "utilization", NULL};
         *k; k++)
        cJSON_DeleteItemFromObjectCaseSensitive(j, *k);
    cr_expect_eq(check_report(dir, j, STATS_M_DET, &row, err, sizeof err), -1);
    snprintf(want, sizeof want,
             "%s/report.json: key 'cycles' missing; key 'busy_cycles' missing; key 'fps' missing; key 'fps_no_stall' "
             "missing (and 1 more)",
             dir);
    cr_expect_str_eq(err, want, "the utilization object, named once for its four stages, is the fifth");
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

/* The registry's modes: what the run's mode does not write may be absent or null (cycles is null
 * in functional mode, there are no stall shares), but not something else; the kd figures are
 * needed when the report has a kd block. */
Test(sweep_check, figures_the_mode_does_not_write_may_be_absent_or_null)
{
    char dir[64], err[2048], want[2048];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    SweepRow row;
    sweep_row_init(&row);
    cJSON *j = full_report(0);
    put_key(j, "cycles", 0, "null");
    put_key(j, "stall_shares", 0, "null");
    for (const char *const *k = (const char *const[]){"busy_cycles", "fps_ci95", "utilization_timed", NULL}; *k; k++)
        cJSON_DeleteItemFromObjectCaseSensitive(j, *k);
    cJSON *same = cJSON_Duplicate(j, 1);
    cr_expect_eq(check_report(dir, j, STATS_M_FUNC, &row, err, sizeof err), 0, "%s", err);
    cr_expect_eq(check_report(dir, same, STATS_M_DET, &row, err, sizeof err), -1, "detailed mode writes them");
    snprintf(want, sizeof want, "%s/report.json: key 'cycles' is not a number (null)", dir);
    cr_expect(starts_with(err, want), "%s", err);
    /* fps_ci95 is sampled mode's only */
    j = full_report(0);
    cJSON_DeleteItemFromObjectCaseSensitive(j, "fps_ci95");
    same = cJSON_Duplicate(j, 1);
    cr_expect_eq(check_report(dir, j, STATS_M_DET, &row, err, sizeof err), 0, "%s", err);
    cr_expect_eq(check_report(dir, same, STATS_M_SAMP, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'fps_ci95' missing", dir);
    cr_expect_str_eq(err, want);
    j = full_report(0);
    put_key(j, "fps_ci95", 0, "[1, 2, 3]");
    cr_expect_eq(check_report(dir, j, STATS_M_SAMP, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'fps_ci95' is not an array of 2 (an array of 3)", dir);
    cr_expect_str_eq(err, want);
    /* a figure the mode does not write holding a string is still wrong */
    j = full_report(0);
    put_key(j, "cycles", 0, "\"abc\"");
    cr_expect_eq(check_report(dir, j, STATS_M_FUNC, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'cycles' is not a number (a string)", dir);
    cr_expect_str_eq(err, want);
    /* the kernel's figures are functional mode's too */
    j = full_report(0);
    cJSON_DeleteItemFromObjectCaseSensitive(j, "ops");
    cr_expect_eq(check_report(dir, j, STATS_M_FUNC, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'ops' missing", dir);
    cr_expect_str_eq(err, want, "a missing object on the way to several figures is named once");
    /* kd: needed with the kd block, not without */
    j = full_report(0);
    put_key(j, "kd.structure", 0, "\"kd\"");
    cr_expect_eq(check_report(dir, j, STATS_M_FUNC, &row, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s/report.json: key 'kd.total' missing; key 'kd.camera' missing; key 'kd.indirect' missing; "
             "key 'kd.shadow' missing", dir);
    cr_expect_str_eq(err, want);
    char key[128];
    cr_expect_str_eq(stats_csv_key(column("kd_nodes_per_ray"), key, sizeof key), "kd.total.nodes_per_ray");
    cr_expect_str_eq(stats_csv_key(column("fps_hi"), key, sizeof key), "fps_ci95[1]");
    cr_expect_str_eq(stats_csv_key(column("stall_share_control"), key, sizeof key), "stall_shares.control");
    cr_expect_str_eq(stats_csv_key(stats_csv_count(), key, sizeof key), "");
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

Test(sweep_check, a_truncated_report_names_the_byte)
{
    char dir[64], path[256], err[2048], want[2048];
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    snprintf(path, sizeof path, "%s/report.json", dir);
    SweepRow row;
    sweep_row_init(&row);
    tu_write_file(path, "{\"cycles\": 12, \"fps\": ");
    cr_expect_eq(sweep_row_read_report(&row, path, STATS_M_DET, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: not valid JSON at byte 21 of 22 (the text ends there: truncated?)", path);
    cr_expect_str_eq(err, want);
    tu_write_file(path, "{\"cycles\": 12,, \"fps\": 1}");
    cr_expect_eq(sweep_row_read_report(&row, path, 0, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: not valid JSON at byte 15 of 25", path); /* cJSON's offset, past the second comma */
    cr_expect_str_eq(err, want);
    tu_write_file(path, "");
    cr_expect_eq(sweep_row_read_report(&row, path, STATS_M_DET, err, sizeof err), -1);
    snprintf(want, sizeof want, "%s: not valid JSON at byte 0 of 0 (an empty file)", path);
    cr_expect_str_eq(err, want);
    sweep_row_clear(&row);
    tu_remove_tree(dir);
}

/* ---- the file ----------------------------------------------------------------------------------- */

/* A sweep of four points in dir, written by hand (keys need not be machine keys here):
 * 0 done, its report in its folder (every figure of detailed mode); 1 failed, an error with a
 * comma and quotes; 2 unfinished; 3 done but its report.json is missing (so it is failed). Point
 * 0's value of "k.a" holds a quote; only point 1 sets "k.b". */
static void csv_sweep(const char *dir, SweepPlan *pl)
{
    cJSON *m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "format", SWEEP_MANIFEST_FORMAT);
    cJSON_AddNullToObject(m, "config");
    cJSON_AddNullToObject(m, "config_contents");
    cJSON_AddStringToObject(m, "sweep_file", "/s.ini");
    cJSON_AddStringToObject(m, "sweep_contents", "");
    cJSON_AddStringToObject(m, "scene", "/scene.ini");
    cJSON_AddStringToObject(m, "mode", "detailed");
    cJSON_AddNullToObject(m, "sample");
    cJSON_AddArrayToObject(m, "sets");
    cJSON_AddStringToObject(m, "kind", "cross");
    cJSON *points = cJSON_AddArrayToObject(m, "points");
    static const char *const a[] = {"x\"y", "2", "3", "4"};
    for (int k = 0; k < 4; k++) {
        cJSON *p = cJSON_CreateObject(), *set = cJSON_AddObjectToObject(p, "settings");
        cJSON_AddStringToObject(set, "k.a", a[k]);
        if (k == 1)
            cJSON_AddStringToObject(set, "k.b", "only");
        cJSON_AddItemToArray(points, p);
    }
    char err[256] = "";
    cr_assert_eq(sweep_plan_load(m, pl, err, sizeof err), 0, "%s", err);
    char path[256];
    for (int k = 0; k < 4; k++) {
        snprintf(path, sizeof path, "%s/points/%03d", dir, k);
        cr_assert_eq(util_mkdir_p(path, err, sizeof err), 0, "%s", err);
    }
    snprintf(path, sizeof path, "%s/points/000/done", dir);
    tu_write_file(path, "exit_status 0\nhost_seconds 1.5\n");
    cJSON *r = full_report(0); /* every figure of detailed mode, at 0 but these; no interval */
    cJSON_DeleteItemFromObjectCaseSensitive(r, "fps_ci95");
    put_key(r, "cycles", 1234567, NULL);
    put_key(r, "fps", 12.345678901234, NULL);
    put_key(r, "utilization.traversal", 0.5, NULL);
    put_key(r, "ops.load", 1, NULL);
    put_key(r, "ops.store", 3, NULL);
    put_key(r, "host.seconds", 1.25, NULL);
    char *text = cJSON_Print(r);
    cJSON_Delete(r);
    snprintf(path, sizeof path, "%s/points/000/report.json", dir);
    tu_write_file(path, text);
    free(text);
    snprintf(path, sizeof path, "%s/points/001/failed", dir);
    tu_write_file(path, "exit_status 1\nhost_seconds 0.5\nerror exit 1: bad value, \"8\" is no width\n");
    snprintf(path, sizeof path, "%s/points/001/report.json", dir); /* a failed point's figures are not read */
    tu_write_file(path, "{\"cycles\": 99}");
    snprintf(path, sizeof path, "%s/points/003/done", dir);
    tu_write_file(path, "exit_status 0\nhost_seconds 1\n");
}

Test(sweep_csv, rows_hold_keys_status_error_and_figures)
{
    char dir[64], path[256], err[512] = "";
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    SweepPlan pl;
    csv_sweep(dir, &pl);
    int nd, nf, nu;
    tu_stderr_begin();
    SweepRow *rows = sweep_rows_collect(&pl, dir, &nd, &nf, &nu);
    char *said = tu_stderr_end();
    cr_expect(strstr(said, "sweep: point 3 failed: ") && strstr(said, "points/003/report.json: missing"),
              "the point without its report is named: %s", said);
    free(said);
    cr_expect_eq(nd, 1);
    cr_expect_eq(nf, 2, "point 3, done without its report.json, is failed");
    cr_expect_eq(nu, 1);
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    cr_assert_eq(sweep_csv_write(&pl, rows, path, err, sizeof err), 0, "%s", err);
    sweep_rows_free(rows, pl.npoints);
    char *text = tu_slurp(path);

    /* five lines: the header and a row per point */
    char *line[6] = {0};
    int nl = 0;
    for (char *p = text; *p && nl < 6; nl++) {
        line[nl] = p;
        p = strchr(p, '\n');
        cr_assert_not_null(p, "the last line has no line end");
        *p++ = 0;
    }
    cr_assert_eq(nl, 5, "%d lines", nl);
    static char cells[5][200][256];
    int want_cells = 1 + 2 + 2 + stats_csv_count();
    for (int i = 0; i < 5; i++)
        cr_expect_eq(split_csv(line[i], cells[i], 200), want_cells, "line %d: %s", i, line[i]);
    cr_expect(starts_with(line[0], "point,k.a,k.b,status,error,cycles,busy_cycles,fps,fps_no_stall,fps_lo,fps_hi,"),
              "%s", line[0]);
    for (int m = 0; m < stats_csv_count(); m++)
        cr_expect_str_eq(cells[0][5 + m], name_of(m));

    /* point 0: done; its value with a quote is quoted, its figures read and formatted */
    cr_expect(starts_with(line[1], "0,\"x\"\"y\",,ok,,1234567,0,12.3456789,0,,,0.5,0,0,0,"), "%s", line[1]);
    cr_expect_str_eq(cells[1][5 + column("ops_share_load")], "0.25");
    cr_expect_str_eq(cells[1][5 + column("ops_share_store")], "0.75");
    cr_expect_str_eq(cells[1][5 + column("host_seconds")], "1.25");
    cr_expect_str_eq(cells[1][5 + column("rays_total")], "0");
    cr_expect_str_eq(cells[1][5 + column("ops_share_control")], "0");
    /* point 1: failed, the error always quoted, no figures */
    char want[1024];
    snprintf(want, sizeof want, "1,2,only,failed,\"exit 1: bad value, \"\"8\"\" is no width\"%s", no_figures());
    cr_expect_str_eq(line[2], want);
    /* point 2: unfinished; point 3: done, but without its report: failed, and why */
    snprintf(want, sizeof want, "2,3,,unfinished,%s", no_figures());
    cr_expect_str_eq(line[3], want);
    snprintf(want, sizeof want, "3,4,,failed,\"report.json: missing\"%s", no_figures());
    cr_expect_str_eq(line[4], want);
    tu_remove_tree(dir);
    free(text);
    sweep_plan_free(&pl);
}

/* A done point whose report holds "cycles": "abc" is failed in the CSV, with the reason, its
 * other figures kept and the bad one empty; the point's files stay. */
Test(sweep_csv, a_done_point_with_a_wrong_figure_is_failed_and_keeps_the_rest)
{
    char dir[64], path[256], err[512] = "";
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    SweepPlan pl;
    csv_sweep(dir, &pl);
    cJSON *r = full_report(0);
    put_key(r, "cycles", 0, "\"abc\"");
    put_key(r, "fps", 2.5, NULL);
    char *text = cJSON_Print(r);
    cJSON_Delete(r);
    snprintf(path, sizeof path, "%s/points/000/report.json", dir);
    tu_write_file(path, text);
    free(text);
    int nd, nf, nu;
    tu_stderr_begin();
    SweepRow *rows = sweep_rows_collect(&pl, dir, &nd, &nf, &nu);
    char *said = tu_stderr_end();
    cr_expect(strstr(said, "sweep: point 0 failed: ") && strstr(said, "points/000/report.json: key 'cycles' is not a number"),
              "the failed point is named: %s", said);
    cr_expect(strstr(said, "sweep: point 3 failed: ") && strstr(said, "points/003/report.json: missing"), "%s", said);
    free(said);
    cr_expect_eq(nd, 0);
    cr_expect_eq(nf, 3);
    cr_expect_eq(rows[0].state, SWEEP_FAILED);
    cr_expect_str_eq(rows[0].error, "report.json: key 'cycles' is not a number (a string)");
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    cr_assert_eq(sweep_csv_write(&pl, rows, path, err, sizeof err), 0, "%s", err);
    sweep_rows_free(rows, pl.npoints);
    text = tu_slurp(path);
    char *row0 = strchr(text, '\n') + 1;
    cr_expect(starts_with(row0, "0,\"x\"\"y\",,failed,\"report.json: key 'cycles' is not a number (a string)\",,0,2.5,0,"),
              "%s", row0);
    free(text);
    snprintf(path, sizeof path, "%s/points/000/report.json", dir);
    cr_expect_eq(access(path, F_OK), 0, "the report stays");
    snprintf(path, sizeof path, "%s/points/000/done", dir);
    cr_expect_eq(access(path, F_OK), 0, "the done marker stays");
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_csv, named_points_give_their_name_and_numbers_keep_their_precision)
{
    char buf[64];
    sweep_fmt_num(1234567, buf, sizeof buf);
    cr_expect_str_eq(buf, "1234567");
    sweep_fmt_num(-3, buf, sizeof buf);
    cr_expect_str_eq(buf, "-3");
    sweep_fmt_num(0.1, buf, sizeof buf);
    cr_expect_str_eq(buf, "0.1");
    sweep_fmt_num(2.0 / 3.0, buf, sizeof buf);
    cr_expect_str_eq(buf, "0.6666666667");
    sweep_fmt_num(1e15, buf, sizeof buf);
    cr_expect_str_eq(buf, "1e+15", "integers from 1e15 on are printed as other numbers");

    char dir[64], path[256], err[512] = "";
    tu_make_tmpdir(dir, sizeof dir, "sweepcsv");
    cJSON *m = cJSON_Parse("{\"format\": \"sfsim sweep 1\", \"config\": null, \"config_contents\": null,"
                           " \"sweep_file\": \"/s.ini\", \"sweep_contents\": \"\", \"scene\": \"/x\", \"mode\": \"detailed\","
                           " \"sample\": null, \"sets\": [], \"kind\": \"points\", \"points\": ["
                           " {\"name\": \"small\", \"settings\": {\"core.simd_width\": \"4\"}},"
                           " {\"name\": \"big\", \"settings\": {\"core.simd_width\": \"64\"}}]}");
    SweepPlan pl;
    cr_assert_eq(sweep_plan_load(m, &pl, err, sizeof err), 0, "%s", err);
    int nd, nf, nu;
    SweepRow *rows = sweep_rows_collect(&pl, dir, &nd, &nf, &nu);
    cr_expect_eq(nu, 2);
    snprintf(path, sizeof path, "%s/sweep.csv", dir);
    cr_assert_eq(sweep_csv_write(&pl, rows, path, err, sizeof err), 0, "%s", err);
    sweep_rows_free(rows, pl.npoints);
    char *text = tu_slurp(path);
    char *row1 = strchr(text, '\n') + 1;
    cr_expect(starts_with(row1, "small,4,unfinished,,"), "%s", row1);
    char *row2 = strchr(row1, '\n') + 1;
    cr_expect(starts_with(row2, "big,64,unfinished,,"), "%s", row2);
    cr_expect(starts_with(text, "point,core.simd_width,status,error,cycles,"), "%s", text);
    free(text);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}
