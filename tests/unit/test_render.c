/* tests/unit/test_render.c -- the run report (sim/render.c, docs/report.md): the kd section of
 * report.json and report.txt with accel.structure = kd, its figures per ray kind from the kernel's
 * counters (tests/unit/kd_stub.s stands in for the kd-tree kernel), and no kd section for the BVH.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/config.h"
#include "../../sim/render.h"

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    cr_assert_not_null(f, "%s missing", path);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = calloc((size_t)n + 1, 1);
    cr_assert_not_null(buf);
    cr_assert_eq(fread(buf, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    return buf;
}

/* A functional run of the Cornell box, 128 x 64 pixels in 8 tiles of 32 x 32, into a fresh
 * folder; returns report.json parsed, *txt receives report.txt. */
static cJSON *run(const CfgMachine *cfg, const char *kernel, char **txt)
{
    char dir[] = "/tmp/sfsim-report-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.out_dir = dir;
    o.mode = "functional";
    o.cfg = cfg;
    o.kernel_path = kernel;
    o.stream_rays = cfg->stream_rays;
    o.width = 128;
    o.height = 64;
    o.spp = 1;
    o.threads = 2;
    char err[65536];
    cr_assert_eq(render_run(&o, err, sizeof err), 0, "%s", err);
    char path[256];
    snprintf(path, sizeof path, "%s/report.json", dir);
    char *json = slurp(path);
    snprintf(path, sizeof path, "%s/report.txt", dir);
    *txt = slurp(path);
    static const char *const files[] = {"report.json", "report.txt", "frame.exr", "frame.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, files[i]);
        unlink(path);
    }
    rmdir(dir);
    cJSON *j = cJSON_Parse(json);
    free(json);
    cr_assert(cJSON_IsObject(j), "report.json does not parse");
    return j;
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
    cr_expect_null(cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(j, "config"), "kd.traversal"));
    cr_expect(strstr(txt, "kd-tree") == NULL, "%s", txt);
    free(txt);
    cJSON_Delete(j);
}
