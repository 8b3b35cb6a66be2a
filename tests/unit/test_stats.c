/* tests/unit/test_stats.c -- the statistics registry (sim/stats.def, sim/stats.c): the table's
 * own rules; the sweep CSV's columns (today's names, in today's order) and reading them back from
 * a report.json, a fixture's and a real run's, with missing and malformed values; the JSON walk's
 * nulls, sparse objects and lists; and the exec print-out.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/config.h"
#include "../../sim/render.h"
#include "../../sim/stats.h"
#include "../support/files.h"
#include "../support/report_run.h"

/* docs/report.md's statistics tables are what tools/gen_reportdoc.c makes of the table today. */
Test(stats, docs_report_md_is_current)
{
    tu_expect_generated("gen_reportdoc", "SFSIM_GEN_REPORTDOC", "docs/report.md");
}

Test(stats, every_row_keeps_the_rules)
{
    char err[256];
    for (int i = 0; i < stats_nrows; i++)
        cr_expect_eq(stats_row_check(&stats_rows[i], err, sizeof err), 0, "%s", err);
}

/* Two rows of one mode never write the same key; CSV groups are numbered 0..n-1 once each. */
Test(stats, paths_and_csv_groups_are_unique)
{
    int seen[64] = {0}, groups = 0;
    for (int i = 0; i < stats_nrows; i++) {
        const StatsRow *a = &stats_rows[i];
        for (int j = i + 1; a->path && j < stats_nrows; j++) {
            const StatsRow *b = &stats_rows[j];
            unsigned both = a->modes & b->modes & ~(unsigned)STATS_M_KD;
            cr_expect(!(b->path && !strcmp(a->path, b->path) && both), "two rows write %s", a->path);
        }
        if (a->csv_order >= 0) {
            cr_assert_lt(a->csv_order, 64);
            cr_expect_eq(seen[a->csv_order]++, 0, "CSV group %d twice", a->csv_order);
            groups++;
        }
    }
    for (int g = 0; g < groups; g++)
        cr_expect_eq(seen[g], 1, "CSV group %d missing", g);
}

/* The sweep CSV's figure columns, exactly: sweep.csv is a published format (docs/sweep.md), and
 * scripts read its columns by position. A new CSV row's columns go after these, and this list and
 * docs/sweep.md grow with them. */
Test(stats, csv_header_starts_with_todays_columns)
{
    static const char *const want[] = {
        "cycles", "busy_cycles", "fps", "fps_no_stall", "fps_lo", "fps_hi",
        "utilization_traversal", "utilization_intersection", "utilization_shading", "utilization_other",
        "utilization_timed_traversal", "utilization_timed_intersection", "utilization_timed_shading",
        "utilization_timed_other",
        "stall_share_address_fetch", "stall_share_bank_conflict", "stall_share_alignment", "stall_share_interconnect",
        "stall_share_fu_busy", "stall_share_data_dependency", "stall_share_partition", "stall_share_scratchpad",
        "stall_share_scene_memory", "stall_share_control",
        "ops_share_load", "ops_share_store", "ops_share_compute", "ops_share_scatter_gather", "ops_share_partition",
        "ops_share_integer", "ops_share_control",
        "rays_total", "host_seconds",
        "kd_nodes_per_ray", "kd_leaves_per_ray", "kd_prims_per_ray", "kd_restarts_per_ray", "kd_overflows_per_ray",
        "kd_underflows_per_ray",
        "kd_camera_nodes_per_ray", "kd_camera_leaves_per_ray", "kd_camera_prims_per_ray", "kd_camera_restarts_per_ray",
        "kd_camera_overflows_per_ray", "kd_camera_underflows_per_ray",
        "kd_indirect_nodes_per_ray", "kd_indirect_leaves_per_ray", "kd_indirect_prims_per_ray",
        "kd_indirect_restarts_per_ray", "kd_indirect_overflows_per_ray", "kd_indirect_underflows_per_ray",
        "kd_shadow_nodes_per_ray", "kd_shadow_leaves_per_ray", "kd_shadow_prims_per_ray", "kd_shadow_restarts_per_ray",
        "kd_shadow_overflows_per_ray", "kd_shadow_underflows_per_ray",
    };
    /* sweep.csv is a published format: these columns keep their names and places; a new row of
     * stats.def with a CSV name adds its columns after them (a CSV number past the last). */
    int n = (int)(sizeof want / sizeof want[0]), all = stats_csv_count();
    cr_assert_geq(all, n, "%d columns, fewer than today's %d", all, n);
    char name[64];
    for (int i = 0; i < n; i++)
        cr_expect_str_eq(stats_csv_name(i, name, sizeof name), want[i], "column %d", i);
    for (int i = 0; i < all; i++)   /* every name once */
        for (int j = i + 1; j < all; j++) {
            char other[64];
            cr_expect_str_neq(stats_csv_name(i, name, sizeof name), stats_csv_name(j, other, sizeof other));
        }
    cr_expect_str_eq(stats_csv_name(all, name, sizeof name), "");
    cr_expect_str_eq(stats_csv_name(-1, name, sizeof name), "");
}

static int col(const char *name)
{
    char buf[64];
    for (int i = 0; i < stats_csv_count(); i++)
        if (!strcmp(stats_csv_name(i, buf, sizeof buf), name))
            return i;
    cr_assert_fail("no CSV column %s", name);
    return -1;
}

/* A hand-made report: values found through the rows' paths, shares normalized, and whatever is
 * missing, null, a string or an interval of the wrong length left empty. */
Test(stats, csv_reads_a_fixture_report)
{
    const char *text =
        "{\"cycles\": 1000, \"busy_cycles\": null, \"fps\": \"fast\", \"fps_ci95\": [1, 2, 3],"
        " \"utilization\": {\"traversal\": 0.5, \"other\": 0.25},"
        " \"stall_shares\": {\"control\": 0.125},"
        " \"ops\": {\"load\": 30, \"store\": 10, \"compute\": 60},"
        " \"rays\": {\"total\": 4096}, \"host\": {\"seconds\": 1.5},"
        " \"kd\": {\"total\": {\"nodes_per_ray\": 7.5}, \"shadow\": {\"prims_per_ray\": 2}}}";
    cJSON *j = cJSON_Parse(text);
    cr_assert_not_null(j);
    int n = stats_csv_count();
    double *v = calloc((size_t)n, sizeof *v);
    unsigned char *has = calloc((size_t)n, 1);
    cr_assert(v && has);
    stats_csv_read(j, v, has);
    cr_expect(has[col("cycles")] && v[col("cycles")] == 1000);
    cr_expect(!has[col("busy_cycles")], "null is no value");
    cr_expect(!has[col("fps")], "a string is no value");
    cr_expect(!has[col("fps_lo")] && !has[col("fps_hi")], "an interval is two numbers");
    cr_expect(has[col("utilization_traversal")] && v[col("utilization_traversal")] == 0.5);
    cr_expect(has[col("utilization_other")] && v[col("utilization_other")] == 0.25);
    cr_expect(!has[col("utilization_shading")] && !has[col("utilization_timed_traversal")]);
    cr_expect(has[col("stall_share_control")] && v[col("stall_share_control")] == 0.125);
    cr_expect(!has[col("stall_share_fu_busy")]);
    cr_expect(has[col("ops_share_load")] && v[col("ops_share_load")] == 0.3);
    cr_expect(has[col("ops_share_compute")] && v[col("ops_share_compute")] == 0.6);
    cr_expect(!has[col("ops_share_control")], "a category the report lacks stays empty");
    cr_expect(has[col("rays_total")] && v[col("rays_total")] == 4096);
    cr_expect(has[col("host_seconds")] && v[col("host_seconds")] == 1.5);
    cr_expect(has[col("kd_nodes_per_ray")] && v[col("kd_nodes_per_ray")] == 7.5);
    cr_expect(has[col("kd_shadow_prims_per_ray")] && v[col("kd_shadow_prims_per_ray")] == 2);
    cr_expect(!has[col("kd_camera_nodes_per_ray")]);
    cJSON_Delete(j);

    /* shares of nothing are no shares; an empty report has no figure at all */
    j = cJSON_Parse("{\"ops\": {\"load\": 0, \"store\": 0}, \"fps_ci95\": [10, 20]}");
    stats_csv_read(j, v, has);
    cr_expect(!has[col("ops_share_load")] && !has[col("ops_share_store")]);
    cr_expect(has[col("fps_lo")] && v[col("fps_lo")] == 10 && has[col("fps_hi")] && v[col("fps_hi")] == 20);
    cJSON_Delete(j);
    j = cJSON_Parse("{}");
    stats_csv_read(j, v, has);
    for (int i = 0; i < n; i++)
        cr_expect(!has[i], "column %d has a value in an empty report", i);
    cJSON_Delete(j);
    free(v);
    free(has);
}

/* render_run(o) into a fresh folder; report.json parsed. */
static cJSON *run_report(RenderOptions *o) { return tu_run_report(o, "stats", NULL); }

static double at(const cJSON *j, const char *a, const char *b)
{
    const cJSON *x = b ? cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, a), b)
                       : cJSON_GetObjectItemCaseSensitive(j, a);
    cr_assert(cJSON_IsNumber(x), "%s.%s is not a number", a, b ? b : "");
    return x->valuedouble;
}

/* A real detailed run (the kd stub kernel of test_render.c, so that the kd columns are there too):
 * every column the mode has is read, and is the report's own figure. */
Test(stats, csv_reads_a_real_report)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.accel_structure = CFG_ACCEL_KD;
    cfg.kd_traversal = CFG_KD_SHORTSTACK;
    cfg.stream_rays = 1024;
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.mode = RUN_DETAILED;
    o.cfg = &cfg;
    o.kernel_path = "tests/unit/kd_stub.s";
    o.width = o.height = 64;
    o.spp = 1;
    o.threads = 2;
    cJSON *j = run_report(&o);
    int n = stats_csv_count();
    double *v = calloc((size_t)n, sizeof *v);
    unsigned char *has = calloc((size_t)n, 1);
    cr_assert(v && has);
    stats_csv_read(j, v, has);
    char name[64];
    static const char *const chip_only[] = {"chip_cores", "load_imbalance", "memory_latency", "l2_hit_rate",
                                             "dram_gbs", "dram_bandwidth_share"};
    for (int i = 0; i < n; i++) {   /* detailed mode: everything but the sampled interval and a chip's */
        stats_csv_name(i, name, sizeof name);
        int chip = 0;
        for (size_t k = 0; k < sizeof chip_only / sizeof chip_only[0]; k++)
            chip |= !strcmp(name, chip_only[k]);
        cr_expect(has[i] == (strcmp(name, "fps_lo") && strcmp(name, "fps_hi") && !chip), "%s", name);
    }
    cr_expect_eq(v[col("cycles")], at(j, "cycles", NULL));
    cr_expect_eq(v[col("fps_no_stall")], at(j, "fps_no_stall", NULL));
    cr_expect_eq(v[col("utilization_intersection")], at(j, "utilization", "intersection"));
    cr_expect_eq(v[col("utilization_timed_other")], at(j, "utilization_timed", "other"));
    cr_expect_eq(v[col("stall_share_data_dependency")], at(j, "stall_shares", "data_dependency"));
    cr_expect_eq(v[col("rays_total")], at(j, "rays", "total"));
    cr_expect_eq(v[col("host_seconds")], at(j, "host", "seconds"));
    cr_expect_eq(v[col("kd_indirect_leaves_per_ray")], at(cJSON_GetObjectItemCaseSensitive(j, "kd"), "indirect",
                                                           "leaves_per_ray"));
    double sum = 0;
    for (int i = col("ops_share_load"); i <= col("ops_share_control"); i++)
        sum += v[i];
    cr_expect(fabs(sum - 1.0) < 1e-12, "operation shares sum to %.17g", sum);
    double ops = at(j, "ops", "load") + at(j, "ops", "store") + at(j, "ops", "compute") + at(j, "ops", "scatter_gather") +
                 at(j, "ops", "partition") + at(j, "ops", "integer") + at(j, "ops", "control");
    cr_expect_eq(v[col("ops_share_compute")], at(j, "ops", "compute") / ops);
    free(v);
    free(has);
    cJSON_Delete(j);
}

/* A functional-mode walk over made-up counters: the timing keys are null, by_opcode holds only
 * what ran, the generation arrays are as long as the run's generations, tiles carry their fields. */
Test(stats, json_walk_of_made_up_counters)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    static FuncStats f;
    memset(&f, 0, sizeof f);
    FuncTile tiles[2] = {{.x0 = 0, .w = 32, .h = 32, .instructions = 7, .rays = 3},
                         {.x0 = 32, .w = 16, .h = 32, .instructions = 9, .rays = 4}};
    f.tiles = tiles;
    f.ntiles = 2;
    f.instructions = 16;
    f.rays_camera = 5;
    f.rays_shadow = 2;
    f.generations = 2;
    f.core.by_op[3] = 11;
    f.core.active_lanes[ISA_STAGE_TRAVERSAL] = 24;
    f.core.vec_instructions[ISA_STAGE_TRAVERSAL] = 2;
    StatsRun run;
    stats_run_from_func(&run, &f);
    StatsCtx c = {.mode = STATS_M_FUNC, .cfg = &cfg, .run = &run, .f = &f};
    cJSON *j = cJSON_CreateObject();
    cr_assert_eq(stats_json(j, &c), 0);
    cr_expect(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(j, "cycles")));
    cr_expect(cJSON_IsNull(cJSON_GetObjectItemCaseSensitive(j, "fps_no_stall")));
    cr_expect_null(cJSON_GetObjectItemCaseSensitive(j, "stalls"), "no timing in functional mode");
    cr_expect_null(cJSON_GetObjectItemCaseSensitive(j, "kd"), "no kd section for the BVH");
    const cJSON *byop = cJSON_GetObjectItemCaseSensitive(j, "by_opcode");
    cr_expect_eq(cJSON_GetArraySize(byop), 1);
    cr_expect_eq(at(byop, isa_ops[3].mnemonic, NULL), 11);
    cr_expect_eq(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(j, "utilization_by_generation")), 2);
    cr_expect_eq(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(j, "rays_per_generation")), 2);
    cr_expect_eq(at(j, "utilization", "traversal"), 24.0 / (16 * 2));
    cr_expect_eq(at(j, "utilization", "shading"), 0.0, "a ratio over nothing is 0");
    cr_expect_eq(at(j, "rays", "total"), 7);
    const cJSON *t = cJSON_GetObjectItemCaseSensitive(j, "tiles");
    cr_assert_eq(cJSON_GetArraySize(t), 2);
    cr_expect_eq(at(cJSON_GetArrayItem(t, 1), "x", NULL), 32);
    cr_expect_eq(at(cJSON_GetArrayItem(t, 1), "width", NULL), 16);
    cr_expect_eq(at(cJSON_GetArrayItem(t, 1), "instructions", NULL), 9);
    cr_expect_eq(cJSON_GetArraySize(cJSON_GetArrayItem(t, 0)), 6, "tiles have no timing in functional mode");
    cJSON_Delete(j);
}

/* The exec print-out: the headline tests grep, a line per non-zero stall and stage value, the
 * units always; the lists and unit classes are the timed report's. */
Test(stats, exec_print_out)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    TimingStats t;
    memset(&t, 0, sizeof t);
    t.cycles = 10;
    t.busy = 8;
    t.stalls[TM_CONTROL] = 2;
    t.stage_cycles[ISA_STAGE_TRAVERSAL] = 10;
    t.stage_busy[ISA_STAGE_TRAVERSAL] = 8;
    t.rb.accesses = 3;
    StatsCtx c = {.mode = STATS_M_EXEC, .cfg = &cfg, .t = &t};
    char *text = NULL;
    size_t len = 0;
    FILE *fp = open_memstream(&text, &len);
    cr_assert_not_null(fp);
    stats_print_exec(fp, &c);
    fclose(fp);
    cr_expect(!strncmp(text, "timing: 10 cycles = 8 busy + 2 stall\n", 37), "%s", text);
    cr_expect(strstr(text, "\n  stall control ") && !strstr(text, "stall fu_busy"), "%s", text);
    cr_expect(strstr(text, "\n  stage traversal cycles ") && !strstr(text, "stage other"), "%s", text);
    cr_expect(strstr(text, "\n  ray buffers accesses ") && strstr(text, "\n  scratchpad lines "), "%s", text);
    cr_expect(!strstr(text, "utilization") && !strstr(text, "not used"), "%s", text);
    free(text);
}
