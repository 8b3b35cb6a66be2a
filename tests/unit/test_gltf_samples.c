/* tests/unit/test_gltf_samples.c -- real glTF files: what a run reports about the parts of a file
 * it leaves out (skipped primitives and warnings in report.json, report.txt and on stderr), and
 * the 26 Khronos sample assets of ../shared/scenes/gltf-samples, each either rendered at its
 * scene.ini size by the kernel on the functional core bit for bit as the golden model renders it,
 * or refused with a message naming the file and the feature (docs/scenes.md). */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/reference.h"
#include "../../sim/render.h"
#include "../support/shared.h"
#include "../support/files.h"
#include "../support/report_run.h"

/* A golden-model run of `scene` at 8 x 8 into a fresh folder: report.json parsed, *txt receives
 * report.txt. */
static cJSON *run_reference(const char *scene, char **txt)
{
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = scene;
    o.mode = RUN_REFERENCE;
    o.width = o.height = 8;
    o.spp = 1;
    o.threads = 1;
    return tu_run_report(&o, "gltf", txt);
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

/* ---- the kernel against the golden model --------------------------------------------------- */

typedef struct Frame {
    float *rgb;
    int w, h;
} Frame;

static void load_packed(const char *path, Scene *s, PackedScene *p)
{
    char err[4096];
    cr_assert_eq(scene_load(path, s, err, sizeof err), 0, "%s", err);
    BvhParams bp;
    bvh_default_params(&bp);
    cr_assert_eq(pack_scene(s, &bp, 0, p, err, sizeof err), 0, "%s: %s", path, err);
}

static Frame golden(const Scene *s, const PackedScene *p, RefWorkload wl, int bounces)
{
    Frame f = {calloc(3 * (size_t)s->render.width * s->render.height, sizeof(float)), s->render.width,
               s->render.height};
    char err[1024];
    RefParams rp = {.tile = 64, .seed = 1, .threads = 2, .workload = wl, .bounces = bounces};
    cr_assert_eq(ref_render(p, &rp, f.rgb, NULL, err, sizeof err), 0, "%s", err);
    return f;
}

static Frame kernel(const Scene *s, const PackedScene *p, const CfgMachine *cfg, FuncStats *st)
{
    Frame f = {calloc(3 * (size_t)s->render.width * s->render.height, sizeof(float)), s->render.width,
               s->render.height};
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = s->needs, .seed = 1, .threads = 2};
    cr_assert_eq(func_render(p, &fp, f.rgb, st, err, sizeof err), 0, "%s", err);
    return f;
}

static int same_bits(const Frame *a, const Frame *b)
{
    return memcmp(a->rgb, b->rgb, sizeof(float) * 3 * (size_t)a->w * a->h) == 0;
}

static double mean(const Frame *f)
{
    double m = 0.0;
    for (size_t i = 0; i < 3 * (size_t)f->w * f->h; i++)
        m += f->rgb[i];
    return m / (3.0 * f->w * f->h);
}

/* Emissive textures (on their own coordinates, through a texture transform), vertex colours,
 * a sphere in a textured emitter's material: the kernel's image has the golden model's bits for
 * several machines and both traversals, and in the Phong workload, and it was built with the
 * shader parts these features need. */
Test(gltf_kernel, emissive_textures_and_vertex_colours_match_the_golden_model, .timeout = 300)
{
    Scene s;
    PackedScene p;
    load_packed("tests/scenes/ok_emissive_texture.ini", &s, &p);
    char needs[256];
    scene_needs_string(s.needs, needs, sizeof needs);
    cr_expect_str_eq(needs, "lambert,glossy,textures,spheres,area_lights,emissive_textures,vertex_colors");
    Frame g = golden(&s, &p, REF_WORKLOAD_PATH, 0);
    cr_expect_gt(mean(&g), 0.0);
    static const struct { int lanes, rays, packet; } m[] = {{16, 4096, 0}, {8, 1024, 0}, {16, 4096, 1}};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) {
        CfgMachine cfg;
        cfg_defaults(&cfg);
        cfg.core_simd_width = m[i].lanes;
        cfg.stream_rays = m[i].rays;
        cfg.stream_mode = m[i].packet ? CFG_STREAM_MODE_PACKET : CFG_STREAM_MODE_STREAM;
        FuncStats st;
        Frame k = kernel(&s, &p, &cfg, &st);
        cr_expect(same_bits(&k, &g), "N = %d, M = %d%s: the kernel's image differs from the golden model's",
                  m[i].lanes, m[i].rays, m[i].packet ? ", packets" : "");
        cr_expect(strstr(st.defines, "HAS_EMISSIVE_TEX=1") && strstr(st.defines, "HAS_COLORS=1"), "%s", st.defines);
        free(k.rgb);
        func_stats_free(&st);
    }
    free(g.rgb);
    /* the Phong workload samples each light once per hit: textured triangle lights at their centroid */
    g = golden(&s, &p, REF_WORKLOAD_PHONG, 1);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.workload_kind = CFG_WORKLOAD_PHONG;
    cfg.workload_bounces = 1;
    FuncStats st;
    Frame k = kernel(&s, &p, &cfg, &st);
    cr_expect(same_bits(&k, &g), "phong: the kernel's image differs from the golden model's");
    free(k.rgb);
    free(g.rgb);
    func_stats_free(&st);
    pack_free(&p);
    scene_free(&s);
}

/* A scene.ini over tests/scenes/ok_emissive_texture.gltf (absolute path), with the given camera
 * and render sections; returns the ini's path. */
static const char *emissive_ini(char *dir, const char *sections)
{
    static char path[512];
    char cwd[256];
    cr_assert_not_null(getcwd(cwd, sizeof cwd));
    snprintf(path, sizeof path, "%s/s.ini", dir);
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fprintf(f, "[scene]\ngltf = %s/tests/scenes/ok_emissive_texture.gltf\n%s", cwd, sections);
    fclose(f);
    return path;
}

/* The golden model, looking straight at the emissive panel of ok_emissive_texture.gltf (x -1..1,
 * y 0..1.5 at z = -1; emissive coordinates u' = 2 u + 0.25 into 8 black, then 8 blue texels
 * (0, 64, 255); emission (1, 0.8, 0.6) x 4): the camera rays see (0, 3.2 x 0.0513, 2.4) plus a
 * little reflection where the texel is blue (x in [-0.75, -0.25) and [0.25, 0.75)), and almost
 * nothing where it is black. Without the emissive texture the whole panel glowed (4, 3.2, 2.4). */
Test(gltf_kernel, emission_follows_the_emissive_texture)
{
    char dir[] = "/tmp/sfsim-emit-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    const char *ini = emissive_ini(dir, "[camera]\nposition = 0 0.75 2\nlook_at = 0 0.75 -1\nfov_y = 18.92\n"
                                        "[render]\nwidth = 32\nheight = 16\nspp = 1\nmax_depth = 0\n");
    Scene s;
    PackedScene p;
    load_packed(ini, &s, &p);
    Frame g = golden(&s, &p, REF_WORKLOAD_PATH, 0);
    int lit = 0, dark = 0;
    for (int y = 4; y < 12; y++)
        for (int x = 0; x < 32; x++) {
            const float *px = &g.rgb[3 * (y * 32 + x)];
            double cx = (x + 0.5) / 16.0 - 1.0; /* the pixel's centre on the panel */
            int blue = (cx > -0.7 && cx < -0.3) || (cx > 0.3 && cx < 0.7);
            int black = (cx > -0.2 && cx < 0.2) || cx < -0.8 || cx > 0.8;
            if (blue) {
                cr_expect(px[2] >= 2.4f && px[2] < 2.9f && px[0] < 0.5f && px[1] > 0.1f && px[1] < 0.6f,
                          "pixel (%d, %d) on a blue texel: %g %g %g", x, y, (double)px[0], (double)px[1],
                          (double)px[2]);
                lit++;
            } else if (black) {
                cr_expect(px[2] < 0.5f, "pixel (%d, %d) on a black texel: blue %g", x, y, (double)px[2]);
                dark++;
            }
        }
    cr_expect_gt(lit, 40);
    cr_expect_gt(dark, 40);
    free(g.rgb);
    pack_free(&p);
    scene_free(&s);
    unlink(ini);
    rmdir(dir);
}

/* Light sampling sees the texture too: a white floor lit only by the panel's emitting triangles,
 * through shadow rays (max_depth 0), takes the blue of the texels (red 0); sampled with the
 * emission factor alone it would be warm, red above blue. */
Test(gltf_kernel, light_sampling_follows_the_emissive_texture)
{
    char dir[] = "/tmp/sfsim-nee-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    const char *ini = emissive_ini(dir, "[camera]\nposition = 0 2 2\nlook_at = 0 0 0\nfov_y = 40\n"
                                        "[render]\nwidth = 16\nheight = 16\nspp = 16\nmax_depth = 0\n");
    Scene s;
    PackedScene p;
    load_packed(ini, &s, &p);
    cr_assert_not_null(s.col);
    for (size_t i = 0; i < 9 * (size_t)s.ntris; i++)
        s.col[i] = 1.0f; /* a white floor */
    pack_free(&p);
    BvhParams bp;
    bvh_default_params(&bp);
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    Frame g = golden(&s, &p, REF_WORKLOAD_PATH, 0);
    double r = 0, b = 0;
    for (int y = 10; y < 16; y++) /* the lower rows: floor */
        for (int x = 0; x < 16; x++) {
            r += g.rgb[3 * (y * 16 + x)];
            b += g.rgb[3 * (y * 16 + x) + 2];
        }
    cr_expect(b > 0.0 && r < 0.01 * b, "the floor: red %g, blue %g", r, b);
    free(g.rgb);
    pack_free(&p);
    scene_free(&s);
    unlink(ini);
    rmdir(dir);
}

/* COLOR_0 multiplies the base colour. Seen from above with direct light only (max_depth 0), a
 * pixel's radiance is linear in the base colour and its random numbers do not depend on it, so
 * the image over the image of the same scene with white vertex colours is, channel by channel,
 * the colour interpolated at the pixel: red at (-1, 1), green at (1, 1), blue at (1, -1), white
 * at (-1, -1) (the floor of ok_emissive_texture.gltf, two triangles split along x + z = 0). */
Test(gltf_kernel, vertex_colours_tint_the_base_colour)
{
    char dir[] = "/tmp/sfsim-col-XXXXXX";
    cr_assert_not_null(mkdtemp(dir));
    const char *ini = emissive_ini(dir, "[camera]\nposition = 0 3 0\nlook_at = 0 0 0\nup = 0 0 -1\nfov_y = 40\n"
                                        "[render]\nwidth = 16\nheight = 16\nspp = 4\nmax_depth = 0\n"
                                        "[light.top]\ntype = quad\nposition = -2 4 -2\nedge_u = 4 0 0\nedge_v = 0 0 4\n"
                                        "intensity = 2\n");
    Scene s;
    PackedScene p;
    load_packed(ini, &s, &p);
    cr_assert_not_null(s.col);
    Frame a = golden(&s, &p, REF_WORKLOAD_PATH, 0);
    pack_free(&p);
    for (size_t i = 0; i < 9 * (size_t)s.ntris; i++)
        s.col[i] = 1.0f;
    BvhParams bp;
    bvh_default_params(&bp);
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    Frame b = golden(&s, &p, REF_WORKLOAD_PATH, 0);
    static const float vc[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
    static const float vx[4] = {-1, 1, 1, -1}, vz[4] = {1, 1, -1, -1};
    double half = 3.0 * tan(20.0 * M_PI / 180.0);
    int checked = 0;
    for (int y = 0; y < 16; y++)
        for (int x = 0; x < 16; x++) {
            double wx = ((x + 0.5) / 16.0 - 0.5) * 2.0 * half, wz = ((y + 0.5) / 16.0 - 0.5) * 2.0 * half;
            if (fabs(wx) > 0.9 || fabs(wz) > 0.9 || fabs(wx + wz) < 0.2)
                continue;
            /* barycentrics in the triangle (0, 1, 2) or (0, 2, 3) */
            int t[3] = {0, wx + wz > 0 ? 1 : 2, wx + wz > 0 ? 2 : 3};
            double x0 = vx[t[0]], z0 = vz[t[0]], x1 = vx[t[1]] - x0, z1 = vz[t[1]] - z0, x2 = vx[t[2]] - x0,
                   z2 = vz[t[2]] - z0, d = x1 * z2 - x2 * z1;
            double u = ((wx - x0) * z2 - x2 * (wz - z0)) / d, v = (x1 * (wz - z0) - (wx - x0) * z1) / d;
            const float *pa = &a.rgb[3 * (y * 16 + x)], *pb = &b.rgb[3 * (y * 16 + x)];
            if (!(pb[0] > 1e-3f && pb[1] > 1e-3f && pb[2] > 1e-3f))
                continue; /* in shadow, or the light was not seen */
            for (int k = 0; k < 3; k++) {
                double want = (1 - u - v) * vc[t[0]][k] + u * vc[t[1]][k] + v * vc[t[2]][k];
                cr_expect(fabs(pa[k] / pb[k] - want) < 0.08, "pixel (%d, %d) at (%.2f, %.2f), channel %d: %g, expected %g",
                          x, y, wx, wz, k, (double)(pa[k] / pb[k]), want);
            }
            checked++;
        }
    printf("vertex colours: %d pixels checked\n", checked);
    cr_expect_gt(checked, 100);
    free(a.rgb);
    free(b.rgb);
    pack_free(&p);
    scene_free(&s);
    unlink(ini);
    rmdir(dir);
}

/* ---- ../shared/scenes/gltf-samples: every folder renders or is refused by name -------------- */

#define SAMPLES "../shared/scenes/gltf-samples"

/* The folders that must be refused, and the message (after the scene.ini's "FILE:LINE: key
 * 'scene.gltf': ") naming the file and the feature. Every other folder must render. */
static const struct {
    const char *dir, *refusal;
} refused[] = {
    {"box-draco", "/Box.gltf: requires extension KHR_draco_mesh_compression, which sfsim does not support"},
    {"unlit-required", "/UnlitTest.glb: requires extension KHR_materials_unlit, which sfsim does not support"},
};

static const char *expected_refusal(const char *dir)
{
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; i++)
        if (!strcmp(refused[i].dir, dir))
            return refused[i].refusal;
    return NULL;
}

/* Each folder's scene.ini at its own size: the kernel on the functional core (N = 16, M = 4096)
 * gives the golden model's image bit for bit, or the load fails with the expected message. */
Test(gltf_samples, every_sample_renders_as_the_golden_model_or_is_refused_by_name, .timeout = 300)
{
    NEEDS_SHARED(SAMPLES "/SOURCES.md");
    struct stat st;
    struct dirent **names;
    int n = scandir(SAMPLES, &names, NULL, alphasort);
    cr_assert_gt(n, 0, "cannot list " SAMPLES);
    int rendered = 0, refusals = 0;
    for (int i = 0; i < n; i++) {
        const char *dir = names[i]->d_name;
        char ini[512];
        snprintf(ini, sizeof ini, SAMPLES "/%s/scene.ini", dir);
        if (dir[0] == '.' || stat(ini, &st) != 0) {
            free(names[i]);
            continue;
        }
        const char *want = expected_refusal(dir);
        Scene s;
        char err[4096];
        int rc = scene_load(ini, &s, err, sizeof err);
        if (want) {
            cr_expect_neq(rc, 0, "%s: loaded, but must be refused", dir);
            if (rc == 0) {
                scene_free(&s);
            } else {
                char full[512];
                snprintf(full, sizeof full, SAMPLES "/%s%s", dir, want);
                cr_expect_not_null(strstr(err, full), "%s: the message does not name the file and the feature:\n%s",
                                   dir, err);
                printf("gltf-samples %-22s refused, as expected: %s\n", dir, err);
                refusals++;
            }
            free(names[i]);
            continue;
        }
        cr_expect_eq(rc, 0, "%s: %s", dir, err);
        if (rc != 0) {
            free(names[i]);
            continue;
        }
        PackedScene p;
        BvhParams bp;
        bvh_default_params(&bp);
        cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s: %s", dir, err);
        Frame g = golden(&s, &p, REF_WORKLOAD_PATH, 0);
        CfgMachine cfg;
        cfg_defaults(&cfg);
        FuncStats fs;
        Frame k = kernel(&s, &p, &cfg, &fs);
        char needs[256];
        scene_needs_string(s.needs, needs, sizeof needs);
        int same = same_bits(&k, &g);
        cr_expect(same, "%s: the kernel's image differs from the golden model's", dir);
        cr_expect_gt(mean(&g), 0.0, "%s: black image", dir);
        cr_expect_eq(fs.rays_camera, (uint64_t)s.render.width * s.render.height * s.render.spp, "%s", dir);
        printf("gltf-samples %-22s %dx%d %d spp, %u triangles, mean %.5f, %s  [%s]%s\n", dir, s.render.width,
               s.render.height, s.render.spp, s.ntris, mean(&g), same ? "kernel = golden" : "DIFFERENT", needs,
               s.nwarnings ? " (with warnings)" : "");
        rendered++;
        free(g.rgb);
        free(k.rgb);
        func_stats_free(&fs);
        pack_free(&p);
        scene_free(&s);
        free(names[i]);
    }
    free(names);
    printf("gltf-samples: %d rendered, %d refused\n", rendered, refusals);
    cr_expect_eq(refusals, (int)(sizeof refused / sizeof refused[0]), "every expected refusal was seen");
    cr_expect_geq(rendered + refusals, 26, "the folder holds 26 samples");
}
