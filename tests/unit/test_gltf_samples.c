/* tests/unit/test_gltf_samples.c -- real glTF files: what a run reports about the parts of a file
 * it leaves out (skipped primitives and warnings in report.json, report.txt and on stderr), and
 * the 26 Khronos sample assets of ../shared/scenes/gltf-samples, each either rendered at its
 * scene.ini size by the kernel on the functional core bit for bit as the golden model renders it,
 * or refused with a message naming the file and the feature (docs/scenes.md). */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/functional.h"
#include "../../sim/reference.h"
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

/* A golden-model run of `scene` at 8 x 8 into a fresh folder: report.json parsed, *txt receives
 * report.txt. */
static cJSON *run_reference(const char *scene, char **txt)
{
    char dir[] = "/tmp/sfsim-gltf-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = scene;
    o.out_dir = dir;
    o.mode = "reference";
    o.width = o.height = 8;
    o.spp = 1;
    o.threads = 1;
    char err[4096];
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

/* stderr captured by Criterion, as one string. */
static char *captured_stderr(void)
{
    fflush(stderr);
    FILE *f = cr_get_redirected_stderr();
    size_t cap = 4096, n = 0;
    char *buf = malloc(cap);
    int c;
    while (buf && (c = fgetc(f)) != EOF) {
        if (n + 1 >= cap)
            buf = realloc(buf, cap *= 2);
        if (buf)
            buf[n++] = (char)c;
    }
    cr_assert_not_null(buf);
    buf[n] = 0;
    return buf;
}

/* One triangle beside a POINTS, a LINES and a LINE_LOOP primitive: the three are skipped, counted
 * in report.json's scene block and in report.txt, and named in one warning line on stderr and in
 * both reports. */
Test(gltf_report, skipped_primitives_are_counted_and_warned, .init = cr_redirect_stderr)
{
    char *txt;
    cJSON *j = run_reference("tests/scenes/ok_points_lines.gltf", &txt);
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(j, "scene");
    const cJSON *n = cJSON_GetObjectItemCaseSensitive(sc, "skipped_primitives");
    cr_assert(cJSON_IsNumber(n), "scene.skipped_primitives missing");
    cr_expect_eq(n->valueint, 3);
    const cJSON *w = cJSON_GetObjectItemCaseSensitive(sc, "warnings");
    cr_assert(cJSON_IsArray(w) && cJSON_GetArraySize(w) == 1, "scene.warnings: one line expected");
    const char *want = "tests/scenes/ok_points_lines.gltf: skipped 3 of 4 primitives: not triangles (1 POINTS, 1 LINES, "
                       "1 LINE_LOOP)";
    cr_expect_not_null(strstr(cJSON_GetArrayItem(w, 0)->valuestring, want), "%s",
                       cJSON_GetArrayItem(w, 0)->valuestring);
    cr_expect_not_null(strstr(txt, "skipped      3 glTF primitives that are not triangles\n"), "%s", txt);
    cr_expect_not_null(strstr(txt, want), "%s", txt);
    char *err = captured_stderr();
    char line[512];
    snprintf(line, sizeof line, "sfsim run: warning: %s", want);
    const char *at = strstr(err, line);
    cr_expect_not_null(at, "stderr:\n%s", err);
    cr_expect(at && strchr(at, '\n') && !strstr(strchr(at, '\n'), "skipped"), "one warning line, not several:\n%s",
              err);
    free(err);
    free(txt);
    cJSON_Delete(j);
}

/* A file with nothing left out says so: 0 skipped, no warnings. */
Test(gltf_report, nothing_skipped)
{
    char *txt;
    cJSON *j = run_reference("tests/scenes/ok_triangle.gltf", &txt);
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(j, "scene");
    cr_expect_eq(cJSON_GetObjectItemCaseSensitive(sc, "skipped_primitives")->valueint, 0);
    cr_expect_eq(cJSON_GetArraySize(cJSON_GetObjectItemCaseSensitive(sc, "warnings")), 0);
    cr_expect_null(strstr(txt, "skipped"), "%s", txt);
    cr_expect_null(strstr(txt, "warning"), "%s", txt);
    free(txt);
    cJSON_Delete(j);
}
