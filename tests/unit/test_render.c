/* tests/unit/test_render.c -- the run report (sim/render.c, docs/report.md): the kd section of
 * report.json and report.txt with accel.structure = kd, its figures per ray kind from the kernel's
 * counters (tests/unit/kd_stub.s stands in for the kd-tree kernel), and no kd section for the BVH;
 * the config block (every key), the files a report names, its tile and thread wording, and a
 * SAH cost that stays a number (or says why not) for a huge sphere; and the trace engine on a
 * batch of 0 rays.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <math.h>
#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/render.h"
#include "../../sim/run/run.h"
#include "../../sim/trace.h"
#include "../support/files.h"
#include "../support/report_run.h"

/* render_run(o) into a fresh folder; returns report.json parsed, *txt receives report.txt. */
static cJSON *run_opts(RenderOptions *o, char **txt) { return tu_run_report(o, "report", txt); }

/* A functional run of the Cornell box, 128 x 64 pixels in 8 tiles of 32 x 32, into a fresh
 * folder; returns report.json parsed, *txt receives report.txt. */
static cJSON *run(const CfgMachine *cfg, const char *kernel, char **txt)
{
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.mode = RUN_FUNCTIONAL;
    o.cfg = cfg;
    o.kernel_path = kernel;
    o.width = 128;
    o.height = 64;
    o.spp = 1;
    o.threads = 2;
    return run_opts(&o, txt);
}

static double num(const cJSON *o, const char *a, const char *b)
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(o, a), b);
    cr_assert(cJSON_IsNumber(x), "%s.%s is not a number", a, b);
    return x->valuedouble;
}

static const char *str(const cJSON *o, const char *a, const char *b)
{
    const cJSON *x = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(o, a), b);
    cr_assert(cJSON_IsString(x), "%s.%s is not a string", a, b);
    return x->valuestring;
}

Test(render, kd_section_of_the_report)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.accel_structure = CFG_ACCEL_KD;
    cfg.kd_traversal = CFG_KD_SHORTSTACK;
    cfg.kd_stack_depth = 2;
    cfg.stream_rays = 1024;
    char *txt;
    cJSON *j = run(&cfg, "tests/unit/kd_stub.s", &txt);
    const cJSON *kd = cJSON_GetObjectItemCaseSensitive(j, "kd");
    cr_assert(cJSON_IsObject(kd), "no kd section");
    cr_expect_str_eq(cJSON_GetObjectItemCaseSensitive(kd, "structure")->valuestring, "kd");
    cr_expect_str_eq(cJSON_GetObjectItemCaseSensitive(kd, "traversal")->valuestring, "shortstack");
    cr_expect_eq(cJSON_GetObjectItemCaseSensitive(kd, "stack_depth")->valuedouble, 2.0);
    /* The Cornell box's tree with the default keys (docs/kdtree.md). */
    cr_expect_eq(num(kd, "tree", "primitives"), 32.0); /* the shipped Cornell box: 16 quads */
    cr_expect(num(kd, "tree", "nodes") > 1 && num(kd, "tree", "leaves") == (num(kd, "tree", "nodes") + 1) / 2);
    cr_expect_eq(num(kd, "tree", "references_per_primitive"), num(kd, "tree", "references") / 32.0);
    cr_expect(num(kd, "tree", "depth") > 1 && num(kd, "tree", "largest_leaf") >= 1 && num(kd, "tree", "sah_cost") > 0);
    cr_expect(num(kd, "tree", "build_seconds") >= 0 && num(kd, "tree", "empty_leaves") >= 0);
    /* The stub adds (v + 1)(l + 1) to lane l of vector v = kind * 6 + counter, 16 lanes, 8 tiles,
     * and counts 2 camera and 3 indirect rays per tile. */
    const double tri = 8.0 * 16 * 17 / 2;
    static const char *const kinds[] = {"camera", "indirect", "shadow"};
    static const char *const counters[] = {"nodes", "leaves", "prims", "restarts", "overflows", "underflows"};
    const double rays[] = {16, 24, 0};
    for (int k = 0; k < 3; k++) {
        cr_expect_eq(num(kd, kinds[k], "rays"), rays[k], "%s rays", kinds[k]);
        for (int c = 0; c < 6; c++) {
            char per[64];
            snprintf(per, sizeof per, "%s_per_ray", counters[c]);
            double n = tri * (k * 6 + c + 1);
            cr_expect_eq(num(kd, kinds[k], counters[c]), n, "%s %s", kinds[k], counters[c]);
            cr_expect_eq(num(kd, kinds[k], per), rays[k] ? n / rays[k] : 0.0, "%s %s", kinds[k], per);
            if (k == 0) {
                double total = tri * (3 * c + 21);   /* (c + 1) + (c + 7) + (c + 13) */
                cr_expect_eq(num(kd, "total", counters[c]), total, "total %s", counters[c]);
                cr_expect_eq(num(kd, "total", per), total / 40.0, "total %s", per);
            }
        }
    }
    cr_expect_eq(num(kd, "total", "rays"), 40.0);
    cr_expect_str_eq(str(j, "config", "accel.structure"), "kd");
    cr_expect_str_eq(str(j, "config", "kd.traversal"), "shortstack");
    cr_expect_eq(num(j, "config", "kd.stack_depth"), 2.0);
    cr_expect(strstr(str(j, "kernel", "defines"), "ACCEL_KD=1 KD_VARIANT=3 KD_STACK_DEPTH=2"), "%s",
              str(j, "kernel", "defines"));
    cr_expect(strstr(txt, "kd-tree      shortstack traversal, stack depth 2;"), "%s", txt);
    cr_expect(strstr(txt, "\nkd per ray ") && strstr(txt, "\n             camera       68.000    136.000"), "%s", txt);
    free(txt);
    cJSON_Delete(j);
}

Test(render, no_kd_section_for_the_bvh, .timeout = 120)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    char *txt;
    cJSON *j = run(&cfg, "kernels/pathtrace.s", &txt);
    cr_expect_null(cJSON_GetObjectItemCaseSensitive(j, "kd"));
    cr_expect_str_eq(str(j, "config", "accel.structure"), "bvh");
    /* Every key is in the config block (docs/report.md), the kd keys too, with the values in force. */
    cr_expect_str_eq(str(j, "config", "kd.traversal"), "stack");
    cr_expect_eq(num(j, "config", "kd.stack_depth"), 3.0);
    cr_expect(strstr(txt, "kd-tree") == NULL, "%s", txt);
    free(txt);
    cJSON_Delete(j);
}

/* report.json's config block is every key of sim/config.def with the value in force: a changed
 * timing key shows (the report names the machine its cycles come from). */
Test(render, config_block_holds_every_key, .timeout = 120)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    CfgErrors errs = {0};
    cr_assert_eq(cfg_set(&cfg, "latency.vfma=7", &errs), 0, "%s", errs.text ? errs.text : "");
    cr_assert_eq(cfg_set(&cfg, "kd.empty_bonus=0.5", &errs), 0, "%s", errs.text ? errs.text : "");
    cfg_errors_free(&errs);
    char *txt;
    cJSON *j = run(&cfg, "kernels/pathtrace.s", &txt);
    const cJSON *cf = cJSON_GetObjectItemCaseSensitive(j, "config");
    cr_assert(cJSON_IsObject(cf));
    /* The keys cfg_dump lists, one "key = value" line each under its [section]. */
    char *dump = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&dump, &len);
    cr_assert_not_null(f);
    cfg_dump(&cfg, f);
    fclose(f);
    char section[64] = "";
    int keys = 0;
    for (char *save = NULL, *line = strtok_r(dump, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char key[64];
        if (sscanf(line, "[%63[^]]]", section) == 1 || line[0] == ' ' || sscanf(line, "%63s =", key) != 1)
            continue;
        char full[160];
        snprintf(full, sizeof full, "%s.%s", section, key);
        cr_expect_not_null(cJSON_GetObjectItemCaseSensitive(cf, full), "report.json config lacks %s", full);
        keys++;
    }
    free(dump);
    cr_expect_geq(keys, 60, "cfg_dump listed only %d keys", keys);
    cr_expect_eq(cJSON_GetArraySize(cf), keys, "config has %d members, the config %d keys", cJSON_GetArraySize(cf), keys);
    cr_expect_eq(num(j, "config", "latency.vfma"), 7.0);
    cr_expect_eq(num(j, "config", "kd.empty_bonus"), 0.5);
    cr_expect_eq(num(j, "config", "stream.rays"), 1024.0);
    cr_expect_str_eq(str(j, "config", "stream.mode"), "stream");
    cr_expect_eq(num(j, "config", "sim.max_instructions"), 1e10);
    free(txt);
    cJSON_Delete(j);
}

/* The report names the config file (as given, or built-in) and the scene file; a 32 x 32 image
 * is one partial tile of 64 x 64, not "tiles of 64 x 64"; one thread is "1 thread". */
Test(render, report_names_files_tiles_and_threads, .timeout = 120)
{
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.mode = RUN_REFERENCE;
    o.width = 32;
    o.height = 32;
    o.spp = 1;
    o.threads = 1;
    char *txt;
    cJSON *j = run_opts(&o, &txt);
    cr_expect(strstr(txt, "\nscene        scenes/cornell/scene.ini\n"), "%s", txt);
    cr_expect(strstr(txt, "\nconfig       built-in"), "%s", txt);
    cr_expect(strstr(txt, "one partial tile (tiles are 64 x 64 pixels)"), "%s", txt);
    cr_expect(strstr(txt, "tiles of") == NULL, "%s", txt);
    cr_expect(strstr(txt, " on 1 thread ("), "%s", txt);
    cr_expect(strstr(txt, "1 threads") == NULL, "%s", txt);
    const cJSON *cf = cJSON_GetObjectItemCaseSensitive(j, "config_file");
    cr_expect(cJSON_IsString(cf) && !strcmp(cf->valuestring, "built-in"));
    cr_expect_str_eq(str(j, "scene", "file"), "scenes/cornell/scene.ini");
    /* The reference mode reports the machine too (its BVH keys shape the golden model's run). */
    cr_expect_eq(num(j, "config", "bvh.leaf_size"), 4.0);
    free(txt);
    cJSON_Delete(j);

    o.config_path = "configs/streamray.ini";
    o.width = 100;
    o.height = 64;
    o.threads = 2;
    j = run_opts(&o, &txt);
    cr_expect(strstr(txt, "\nconfig       configs/streamray.ini\n"), "%s", txt);
    cr_expect(strstr(txt, "2 tiles of 64 x 64 pixels, the last column partial"), "%s", txt);
    cr_expect(strstr(txt, " on 2 threads ("), "%s", txt);
    cf = cJSON_GetObjectItemCaseSensitive(j, "config_file");
    cr_expect(cJSON_IsString(cf) && !strcmp(cf->valuestring, "configs/streamray.ini"));
    free(txt);
    cJSON_Delete(j);
}

/* A scene whose BVH surface areas overflow single precision (a sphere of radius 1e30) is refused
 * by the loader now (docs/scenes.md, "Limits of scene values"; tests/unit/test_scene_limits.c);
 * the SAH cost's handling of such areas is tested on the BVH itself
 * (bvh_build/sah_cost_of_boxes_whose_areas_overflow_is_a_number in test_bvh.c). */

/* sfsim trace's engine on a batch of 0 rays, in every mode: 0, no hits, no instructions (the
 * functional and detailed modes crashed: the thread pool capped its threads at the tile count, 0,
 * and ran a worker with no job). The CLI test covers the files; this one runs under ASan. */
Test(render, trace_of_zero_rays_in_every_mode, .timeout = 120)
{
    Scene s;
    PackedScene p;
    char err[4096];
    cr_assert_eq(scene_load("scenes/cornell/scene.ini", &s, err, sizeof err), 0, "%s", err);
    BvhParams bp;
    bvh_default_params(&bp);
    memset(&p, 0, sizeof p);
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    static const unsigned char header[16] = "SFRAYS1";
    static const char *const sources[] = {"", "# comments only\n\n  # and blanks\n"};
    static const RunMode modes[] = {RUN_FUNCTIONAL, RUN_DETAILED, RUN_REFERENCE};
    for (int k = 0; k < 3; k++) {
        RayBatch b;
        memset(&b, 0, sizeof b);
        const unsigned char *data = k < 2 ? (const unsigned char *)sources[k] : header;
        size_t len = k < 2 ? strlen(sources[k]) : sizeof header;
        cr_assert_eq(raybatch_parse("rays", data, len, &b, err, sizeof err), 0, "%s", err);
        cr_assert_eq(b.count, 0u);
        BatchHit hit;
        for (int m = 0; m < 3; m++) {
            RunTrace rt;
            memset(&rt, 0xff, sizeof rt);
            RunSpec spec = {.mode = modes[m], .cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .threads = 2};
            int rc = run_trace(&p, NULL, s.needs, &spec, &b, &hit, &rt, err, sizeof err);
            const char *mn = run_mode_names[modes[m]];
            cr_expect_eq(rc, 0, "input %d, %s: %s", k, mn, err);
            cr_expect_eq(rt.instructions, 0u, "input %d, %s: %llu instructions", k, mn,
                         (unsigned long long)rt.instructions);
            if (m == 1)
                cr_expect_eq(rt.timing.cycles, 0u, "0 rays, %llu cycles", (unsigned long long)rt.timing.cycles);
        }
        raybatch_free(&b);
    }
    pack_free(&p);
    scene_free(&s);
}
