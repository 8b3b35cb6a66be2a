/* tests/unit/test_sweep_plan.c -- a sweep's plan (sim/sweep/sweepfile.c, plan.c, folder.c): the
 * order sweep files expand in (cross products with the first key slowest, ranges, lists over
 * several lines, explicit points), the errors they collect, the manifest taken apart (key order,
 * folder names), what makes two sweeps differ, and resuming: which points are new, finished,
 * failed or unfinished, and which of them run again. tests/cli/sweep.sh runs the same end to end.
 *
 * Suites: sweep_expand, sweep_plan, sweep_diff, sweep_resume.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../sim/exitcodes.h"
#include "../../sim/sweep/sweep_int.h"
#include "../support/files.h"

/* ---- helpers ------------------------------------------------------------------------------------ */

/* The points a sweep file's text gives; NULL (with the messages in *errs) when it has errors. */
static cJSON *expand(const char *text, SweepErrs *errs, int *explicit_points)
{
    memset(errs, 0, sizeof *errs);
    *explicit_points = -1;
    return sweep_file_points("t.ini", text, strlen(text), errs, explicit_points);
}

/* Point p's value of key, or NULL. */
static const char *setting(const cJSON *points, int p, const char *key)
{
    const cJSON *set = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(points, p), "settings");
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(set, key);
    return cJSON_IsString(v) ? v->valuestring : NULL;
}

/* Point p's settings as "k=v k=v", in their order. */
static char *settings_line(const cJSON *points, int p)
{
    static char buf[512];
    buf[0] = 0;
    const cJSON *kv;
    cJSON_ArrayForEach(kv, cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(points, p), "settings"))
    {
        snprintf(buf + strlen(buf), sizeof buf - strlen(buf), "%s%s=%s", buf[0] ? " " : "", kv->string,
                 kv->valuestring);
    }
    return buf;
}

/* The manifest `sfsim sweep --sweep DIR/s.ini -s DIR/s.ini` builds for a sweep file's text, with
 * mode and --sets as given (the scene is only resolved to its path, so the sweep file serves). */
static cJSON *manifest(const char *dir, const char *text, const char *mode, const char **sets, int nsets)
{
    char path[256];
    snprintf(path, sizeof path, "%s/s.ini", dir);
    tu_write_file(path, text);
    SweepArgs a;
    memset(&a, 0, sizeof a);
    a.sweep = path;
    a.scene = path;
    a.mode = mode;
    a.sets = sets;
    a.nsets = nsets;
    cJSON *m = sweep_manifest_build(&a);
    cr_assert_not_null(m, "the manifest of\n%s", text);
    return m;
}

static void load(cJSON *json, SweepPlan *pl)
{
    char err[256] = "";
    cr_assert_eq(sweep_plan_load(json, pl, err, sizeof err), 0, "%s", err);
}

/* The lines of sweep_plan_diff(old, cur). */
static char *diff(const SweepPlan *old, const SweepPlan *cur)
{
    static char buf[4096];
    UtilBuf b = {0};
    sweep_plan_diff(old, cur, &b);
    snprintf(buf, sizeof buf, "%s", util_buf_str(&b));
    util_buf_free(&b);
    return buf;
}

/* ---- expansion ---------------------------------------------------------------------------------- */

Test(sweep_expand, a_cross_product_varies_the_first_key_slowest)
{
    SweepErrs e;
    int expl;
    cJSON *p = expand("[sweep]\ncore.simd_width = 4, 8, 16\nstream.rays = 1024, 4096\n", &e, &expl);
    cr_assert_not_null(p, "%s", util_buf_str(&e.text));
    cr_expect_eq(expl, 0);
    cr_assert_eq(cJSON_GetArraySize(p), 6);
    static const char *const want[] = {
        "core.simd_width=4 stream.rays=1024",  "core.simd_width=4 stream.rays=4096",
        "core.simd_width=8 stream.rays=1024",  "core.simd_width=8 stream.rays=4096",
        "core.simd_width=16 stream.rays=1024", "core.simd_width=16 stream.rays=4096"};
    for (int i = 0; i < 6; i++)
        cr_expect_str_eq(settings_line(p, i), want[i], "point %d", i);
    cr_expect_null(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(p, 0), "name"), "a cross product names no point");
    cJSON_Delete(p);
    util_buf_free(&e.text);
}

Test(sweep_expand, three_keys_keep_the_order_of_the_file)
{
    SweepErrs e;
    int expl;
    cJSON *p = expand("[sweep]\nstream.rays = 4096, 1024\nrender.seed = 3, 1\ncore.simd_width = 16, 8\n", &e, &expl);
    cr_assert_not_null(p, "%s", util_buf_str(&e.text));
    cr_assert_eq(cJSON_GetArraySize(p), 8);
    /* list order, not sorted: 4096 before 1024, 3 before 1 */
    cr_expect_str_eq(settings_line(p, 0), "stream.rays=4096 render.seed=3 core.simd_width=16");
    cr_expect_str_eq(settings_line(p, 1), "stream.rays=4096 render.seed=3 core.simd_width=8");
    cr_expect_str_eq(settings_line(p, 2), "stream.rays=4096 render.seed=1 core.simd_width=16");
    cr_expect_str_eq(settings_line(p, 5), "stream.rays=1024 render.seed=3 core.simd_width=8");
    cr_expect_str_eq(settings_line(p, 7), "stream.rays=1024 render.seed=1 core.simd_width=8");
    cJSON_Delete(p);
    util_buf_free(&e.text);
}

Test(sweep_expand, ranges_and_lists_over_several_lines)
{
    SweepErrs e;
    int expl;
    cJSON *p = expand("[sweep]\ncore.simd_width = 4..12 step 4,\n    32\nkd.empty_bonus = 0.5..1 step 0.25\n", &e, &expl);
    cr_assert_not_null(p, "%s", util_buf_str(&e.text));
    cr_assert_eq(cJSON_GetArraySize(p), 12);
    static const char *const widths[] = {"4", "8", "12", "32"};
    static const char *const bonus[] = {"0.5", "0.75", "1"};
    for (int i = 0; i < 12; i++) {
        cr_expect_str_eq(setting(p, i, "core.simd_width"), widths[i / 3], "point %d", i);
        cr_expect_str_eq(setting(p, i, "kd.empty_bonus"), bonus[i % 3], "point %d", i);
    }
    cJSON_Delete(p);
    util_buf_free(&e.text);
}

Test(sweep_expand, explicit_points_in_file_order_with_their_names)
{
    SweepErrs e;
    int expl;
    cJSON *p = expand("[point.small]\ncore.simd_width = 4\n\n[point.big-2]\ncore.simd_width = 64\nstream.rays = 4096\n",
                      &e, &expl);
    cr_assert_not_null(p, "%s", util_buf_str(&e.text));
    cr_expect_eq(expl, 1);
    cr_assert_eq(cJSON_GetArraySize(p), 2);
    cr_expect_str_eq(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(p, 0), "name")->valuestring, "small");
    cr_expect_str_eq(cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(p, 1), "name")->valuestring, "big-2");
    cr_expect_str_eq(settings_line(p, 0), "core.simd_width=4");
    cr_expect_str_eq(settings_line(p, 1), "core.simd_width=64 stream.rays=4096");
    cJSON_Delete(p);
    util_buf_free(&e.text);
}

Test(sweep_expand, every_error_is_collected_and_nothing_expands)
{
    SweepErrs e;
    int expl;
    /* 04 is 4 again: values are compared as numbers */
    cJSON *p = expand("[sweep]\ncore.simd_width = 4, 8, 04\nbogus.key = 1\nstream.rays = 1024, 999\n", &e, &expl);
    cr_expect_null(p);
    cr_expect_eq(e.count, 3, "%s", util_buf_str(&e.text));
    const char *t = util_buf_str(&e.text);
    cr_expect_not_null(strstr(t, "t.ini:2: key 'core.simd_width': value 04 appears twice in the list"), "%s", t);
    cr_expect_not_null(strstr(t, "t.ini:3: key 'bogus.key': unknown key"), "%s", t);
    cr_expect_not_null(strstr(t, "t.ini:4: key 'stream.rays': value 999 out of range 1024..4096"), "%s", t);
    util_buf_free(&e.text);
}

Test(sweep_expand, too_many_points_is_refused_before_any_value_is_made)
{
    SweepErrs e;
    int expl;
    cJSON *p = expand("[sweep]\ncore.simd_width = 1..1000\nstream.rays = 1024, 4096\nrender.seed = 0..99\n", &e, &expl);
    cr_expect_null(p);
    cr_expect_eq(e.count, 1, "%s", util_buf_str(&e.text));
    cr_expect_str_eq(util_buf_str(&e.text),
                     "t.ini:1: [sweep]: 200000 points (1000 x 2 x 100 values), more than 100000 (split the sweep)\n");
    util_buf_free(&e.text);
}

/* ---- the manifest taken apart ------------------------------------------------------------------- */

Test(sweep_plan, keys_in_order_of_appearance_and_values_per_point)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    load(manifest(dir, "[point.a]\nstream.rays = 4096\n[point.b]\ncore.simd_width = 8\nstream.rays = 1024\n", "detailed",
                  NULL, 0),
         &pl);
    cr_expect_eq(pl.explicit_points, 1);
    cr_assert_eq(pl.npoints, 2);
    cr_assert_eq(pl.nkeys, 2);
    cr_expect_str_eq(pl.keys[0], "stream.rays");
    cr_expect_str_eq(pl.keys[1], "core.simd_width");
    cr_expect_str_eq(pl.points[0].name, "a");
    cr_expect_str_eq(sweep_plan_value(&pl, 0, "stream.rays"), "4096");
    cr_expect_null(sweep_plan_value(&pl, 0, "core.simd_width"), "point a does not set it");
    cr_expect_str_eq(sweep_plan_value(&pl, 1, "core.simd_width"), "8");
    cr_expect_str_eq(pl.mode, "detailed");
    cr_expect_null(pl.config);
    cr_expect_null(pl.sample);
    char *label = sweep_point_label(&pl, 1);
    cr_expect_str_eq(label, "point 1 (b)");
    free(label);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_plan, point_folders_have_enough_digits)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    load(manifest(dir, "[sweep]\nrender.seed = 1..1000\n", "functional", NULL, 0), &pl);
    cr_assert_eq(pl.npoints, 1000);
    char *p = sweep_point_dir(&pl, "/d", 999);
    cr_expect_str_eq(p, "/d/points/999");
    free(p);
    p = sweep_point_label(&pl, 7);
    cr_expect_str_eq(p, "point 7");
    free(p);
    sweep_plan_free(&pl);
    load(manifest(dir, "[sweep]\nrender.seed = 0..1000\n", "functional", NULL, 0), &pl);
    cr_assert_eq(pl.npoints, 1001);
    p = sweep_point_dir(&pl, "/d", 7);
    cr_expect_str_eq(p, "/d/points/0007");
    free(p);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_plan, a_manifest_of_another_kind_is_refused)
{
    char err[256] = "";
    SweepPlan pl;
    cJSON *j = cJSON_Parse("{\"format\": \"sfsim sweep 0\"}");
    cr_expect_eq(sweep_plan_load(j, &pl, err, sizeof err), -1);
    cr_expect_str_eq(err, "not a sweep manifest of this sfsim (its \"format\" is not \"sfsim sweep 1\")");
    sweep_plan_free(&pl);
    j = cJSON_Parse("{\"format\": \"sfsim sweep 1\", \"sweep_file\": \"s\", \"sweep_contents\": \"\", \"scene\": \"x\","
                    "\"mode\": \"detailed\", \"kind\": \"cross\", \"sets\": [], \"points\": []}");
    cr_expect_eq(sweep_plan_load(j, &pl, err, sizeof err), -1, "a sweep of no points");
    cr_expect_str_eq(err, "a field is missing or has the wrong type");
    sweep_plan_free(&pl);
}

/* ---- what differs ------------------------------------------------------------------------------- */

Test(sweep_diff, the_same_sweep_has_no_differences)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    const char *text = "[sweep]\ncore.simd_width = 4, 8\n";
    const char *sets[] = {"render.spp=1"};
    SweepPlan a, b;
    load(manifest(dir, text, "detailed", sets, 1), &a);
    load(manifest(dir, text, "detailed", sets, 1), &b);
    cr_expect_str_eq(diff(&a, &b), "");
    sweep_plan_free(&a);
    sweep_plan_free(&b);
    tu_remove_tree(dir);
}

Test(sweep_diff, each_defining_argument_is_named)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    const char *text = "[sweep]\ncore.simd_width = 4, 8\n";
    const char *sets[] = {"render.spp=1", "render.width=32"};
    SweepPlan a, b;
    load(manifest(dir, text, "detailed", sets, 1), &a);
    load(manifest(dir, text, "functional", sets + 1, 1), &b);
    cr_expect_str_eq(diff(&a, &b), "  --mode: detailed there, functional here\n"
                                   "  --set: render.spp=1 there; render.width=32 here\n");
    sweep_plan_free(&b);
    load(manifest(dir, text, "detailed", NULL, 0), &b);
    cr_expect_str_eq(diff(&a, &b), "  --set: render.spp=1 there; none here\n");
    sweep_plan_free(&b);
    /* the same sweep file, its contents edited since */
    load(manifest(dir, "[sweep]\ncore.simd_width = 4, 8, 16\n", "detailed", sets, 1), &b);
    char want[512];
    snprintf(want, sizeof want, "  the sweep file %s: its contents changed since the sweep began\n", b.sweep);
    cr_expect_str_eq(diff(&a, &b), want);
    sweep_plan_free(&a);
    sweep_plan_free(&b);
    tu_remove_tree(dir);
}

Test(sweep_diff, changed_points_alone_are_named_too)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan a, b;
    cJSON *m = manifest(dir, "[sweep]\ncore.simd_width = 4, 8\n", "detailed", NULL, 0);
    cJSON *m2 = cJSON_Duplicate(m, 1);
    load(m, &a);
    /* every argument the same, the points not: a manifest of another sfsim version */
    cJSON *set = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(cJSON_GetObjectItemCaseSensitive(m2, "points"), 1),
                                                  "settings");
    cJSON_ReplaceItemInObjectCaseSensitive(set, "core.simd_width", cJSON_CreateString("12"));
    load(m2, &b);
    cr_expect_str_eq(diff(&a, &b), "  the points (the sweep was begun by another version of sfsim)\n");
    sweep_plan_free(&a);
    sweep_plan_free(&b);
    tu_remove_tree(dir);
}

Test(sweep_diff, a_folder_holding_another_sweep_is_refused)
{
    char dir[64], out[128];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    snprintf(out, sizeof out, "%s/out", dir);
    const char *text = "[sweep]\ncore.simd_width = 4, 8\n";
    SweepPlan a, b;
    load(manifest(dir, text, "detailed", NULL, 0), &a);
    int fd;
    char *abs = NULL;
    cr_assert_eq(sweep_dir_open(out, &a, 1, &fd, &abs), EXIT_OK, "a new folder");
    cr_expect_not_null(abs);
    close(fd);
    free(abs);
    char path[256];
    snprintf(path, sizeof path, "%s/sweep.json", out);
    cr_expect(sweep_file_exists(path), "no sweep.json written");
    cr_expect_eq(sweep_dir_open(out, &a, 1, &fd, &abs), EXIT_OK, "the same sweep again (a resume)");
    close(fd);
    free(abs);
    load(manifest(dir, text, "functional", NULL, 0), &b);
    tu_stderr_begin();
    int rc = sweep_dir_open(out, &b, 1, &fd, &abs);
    char *said = tu_stderr_end();
    cr_expect_eq(rc, EXIT_INPUT, "another sweep in the folder");
    cr_expect(strstr(said, "holds another sweep") && strstr(said, "--mode: detailed there, functional here"),
              "the refusal says what differs: %s", said);
    free(said);
    cr_expect_eq(fd, -1);
    cr_expect_null(abs);
    sweep_plan_free(&a);
    sweep_plan_free(&b);
    tu_remove_tree(dir);
}

/* ---- resuming ----------------------------------------------------------------------------------- */

/* A sweep folder of 6 points: 0 done (2.5 s), 1 failed (1 s), 2 begun and unfinished (a folder
 * with a log, no marker), 3 new (no folder), 4 done (3.5 s), 5 failed without an error line. */
static void resume_folder(const char *dir, SweepPlan *pl)
{
    load(manifest(dir, "[sweep]\nrender.seed = 0..5\n", "functional", NULL, 0), pl);
    cr_assert_eq(pl->npoints, 6);
    char path[256];
    for (int k = 0; k < 6; k++) {
        if (k == 3)
            continue;
        snprintf(path, sizeof path, "%s/points/%03d", dir, k);
        char err[512];
        cr_assert_eq(util_mkdir_p(path, err, sizeof err), 0, "%s", err);
    }
    snprintf(path, sizeof path, "%s/points/000/done", dir);
    tu_write_file(path, "exit_status 0\nhost_seconds 2.500\n");
    snprintf(path, sizeof path, "%s/points/001/failed", dir);
    tu_write_file(path, "exit_status 1\nhost_seconds 1.000\nerror exit 1: boom\n--- the last lines of log.txt ---\n"
                     "error not this line\n");
    snprintf(path, sizeof path, "%s/points/002/log.txt", dir);
    tu_write_file(path, "rendering...\n");
    snprintf(path, sizeof path, "%s/points/004/done", dir);
    tu_write_file(path, "exit_status 0\nhost_seconds 3.500\n");
    snprintf(path, sizeof path, "%s/points/005/failed", dir);
    tu_write_file(path, "exit_status signal 9\n");
}

Test(sweep_resume, each_point_state_is_read_from_its_markers)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    resume_folder(dir, &pl);
    static const int want[] = {SWEEP_DONE, SWEEP_FAILED, SWEEP_UNFINISHED, SWEEP_UNFINISHED, SWEEP_DONE, SWEEP_FAILED};
    static const double want_secs[] = {2.5, 1.0, 0, 0, 3.5, 0};
    for (int k = 0; k < 6; k++) {
        double secs = -1;
        char *error = NULL;
        cr_expect_eq(sweep_point_state(&pl, dir, k, &secs, &error), want[k], "point %d", k);
        cr_expect_float_eq(secs, want_secs[k], 1e-9, "point %d", k);
        if (k == 1)
            cr_expect_str_eq(error, "exit 1: boom", "the error line before the log tail");
        else if (k == 5)
            cr_expect_str_eq(error, "(no error line in the failed marker)");
        else
            cr_expect_null(error, "point %d", k);
        free(error);
    }
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_resume, unfinished_and_new_points_run_finished_ones_are_kept)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    resume_folder(dir, &pl);
    int todo[6];
    SweepTally t = {0};
    int n = sweep_plan_todo(&pl, dir, 0, todo, &t);
    cr_assert_eq(n, 2);
    cr_expect_eq(todo[0], 2);
    cr_expect_eq(todo[1], 3);
    cr_expect_eq(t.done, 2);
    cr_expect_eq(t.failed, 2);
    cr_expect_float_eq(t.secs_sum, 7.0, 1e-9, "the host seconds of every finished point that has them");
    cr_expect_eq(t.secs_n, 3);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_resume, retry_failed_runs_the_failed_points_again)
{
    char dir[64];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    resume_folder(dir, &pl);
    int todo[6];
    SweepTally t = {0};
    int n = sweep_plan_todo(&pl, dir, 1, todo, &t);
    cr_assert_eq(n, 4);
    static const int want[] = {1, 2, 3, 5};
    for (int i = 0; i < 4; i++)
        cr_expect_eq(todo[i], want[i], "todo[%d]", i);
    cr_expect_eq(t.done, 2);
    cr_expect_eq(t.failed, 0);
    cr_expect_float_eq(t.secs_sum, 6.0, 1e-9);
    cr_expect_eq(t.secs_n, 2);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

Test(sweep_resume, a_done_marker_wins_over_a_failed_one)
{
    char dir[64], path[256];
    tu_make_tmpdir(dir, sizeof dir, "sweeptest");
    SweepPlan pl;
    resume_folder(dir, &pl);
    snprintf(path, sizeof path, "%s/points/001/done", dir);
    tu_write_file(path, "exit_status 0\nhost_seconds 4\n");
    double secs;
    cr_expect_eq(sweep_point_state(&pl, dir, 1, &secs, NULL), SWEEP_DONE);
    cr_expect_float_eq(secs, 4.0, 1e-9);
    sweep_plan_free(&pl);
    tu_remove_tree(dir);
}

/* The progress line's estimate of the time left (sweep_eta): with points of one length (10 s), 7
 * of them on 2 slots, the sweep ends at 40 s; at every moment the estimate is the time to then.
 * The fluid estimate it replaced ((work left) / jobs) said 5 s left at 29.9 s and rose as points
 * finished. */
Test(sweep_eta, falls_second_for_second_with_points_of_one_length)
{
    const double len = 10.0, end = 40.0;
    for (double t = 0.0; t < end; t += 0.25) {
        /* The runner's state at t: points start in pairs at 0, 10, 20; the 7th alone at 30. */
        int started = t < 10 ? 2 : t < 20 ? 4 : t < 30 ? 6 : 7;
        int finished = t < 10 ? 0 : t < 20 ? 2 : t < 30 ? 4 : 6;
        int running = started - finished;
        double elapsed[2];
        for (int i = 0; i < running; i++)
            elapsed[i] = t - 10.0 * (int)(t / 10.0);
        double eta = sweep_eta(len, elapsed, running, 7 - started, 2);
        cr_expect(fabs(eta - (end - t)) < 1e-9, "at %g s: %g s left, expected %g", t, eta, end - t);
    }
}

Test(sweep_eta, idle_slots_and_overrun_points)
{
    double el[3] = {25.0, 3.0, 0.0};
    /* a point that ran past the mean is taken to end now; the queued 4 go to the 3 slots */
    cr_expect_float_eq(sweep_eta(10.0, el, 3, 4, 3), 20.0, 1e-9);
    cr_expect_float_eq(sweep_eta(10.0, NULL, 0, 5, 8), 10.0, 1e-9, "5 points on 8 idle slots take one length");
    cr_expect_float_eq(sweep_eta(10.0, NULL, 0, 0, 2), 0.0, 1e-9);
}
