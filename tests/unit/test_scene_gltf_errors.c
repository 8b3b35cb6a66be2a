/* tests/unit/test_scene_gltf_errors.c -- malformed glTF: one test per class of malformed input
 * with the message it must give (the file and the element).
 *
 * The small glTF files are written by the tests themselves (JSON with base64 data URIs,
 * tests/support/scene_fixture.h) into a temporary folder, so each test shows the exact input it
 * checks. */
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../../scenes/gltf.h"
#include "../../scenes/scene.h"
#include "../support/scene_fixture.h"
#include "../support/shared.h"

/* ---- malformed glTF: each class names the file and the element ------------------------------ */

TestSuite(scene_gltf_errors, .init = st_tmp_setup, .fini = st_tmp_teardown);

Test(scene_gltf_errors, missing_file)
{
    st_load_fails("/nonexistent/x.glb", 2, "/nonexistent/x.glb", "cannot open");
}

Test(scene_gltf_errors, unknown_scene_type)
{
    /* .obj is a scene type now (scenes/obj_load.cpp); .ply is not */
    st_load_fails(st_put_file("x.ply", "ply\n"), 2, "x.ply", "unknown scene type");
}

Test(scene_gltf_errors, not_gltf)
{
    st_load_fails(st_put_file("junk.gltf", "{ this is not json"), 1, "junk.gltf: ");
    st_load_fails(st_put_file("junk.glb", "glTF but not really"), 1, "junk.glb: ");
}

/* A buffer whose external file does not exist: tinygltf's own message is kept. */
Test(scene_gltf_errors, missing_buffer)
{
    Gl g = st_tri();
    char *j = st_gl_json(&g);
    char *uri = strstr(j, "data:application");
    char *end = strchr(uri, '"');
    memmove(uri, "missing.bin", 11);
    memmove(uri + 11, end, strlen(end) + 1);
    const char *path = st_put_gltf("mb.gltf", j);
    st_load_fails(path, 2, "mb.gltf: ", "missing.bin");
}

/* A buffer whose data is shorter than its byteLength. */
Test(scene_gltf_errors, short_buffer)
{
    Gl g = st_tri();
    st_load_fails(st_put_gltf("sb.gltf", st_edit(st_gl_json(&g), "\"byteLength\": 36, \"uri\"", "\"byteLength\": 360, \"uri\"")), 1,
               "sb.gltf: ");
}

Test(scene_gltf_errors, accessor_outside_buffer)
{
    Gl g = st_tri();
    st_load_fails(st_put_gltf("ab.gltf", st_edit(st_gl_json(&g), "\"count\": 3", "\"count\": 300")), 3,
               "ab.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "300 elements",
               "run past the end of the bufferView");
    /* a view past its buffer */
    g = st_tri();
    st_load_fails(st_put_gltf("ab2.gltf", st_edit(st_gl_json(&g), "\"byteOffset\": 0, \"byteLength\": 36}",
                                         "\"byteOffset\": 8, \"byteLength\": 36}")),
               2, "ab2.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "bufferView lies outside its buffer");
}

Test(scene_gltf_errors, accessor_wrong_type)
{
    Gl g = st_tri();
    st_load_fails(st_put_gltf("wt.gltf", st_edit(st_gl_json(&g), "\"type\": \"VEC3\"", "\"type\": \"VEC2\"")), 2,
               "wt.gltf: mesh 0 'tri' primitive 0 POSITION", "is not VEC3");
    g = st_tri();
    st_load_fails(st_put_gltf("wt2.gltf", st_edit(st_gl_json(&g), "\"componentType\": 5126", "\"componentType\": 5123")), 2,
               "wt2.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "UNSIGNED_SHORT is not allowed here");
    g = st_tri();
    st_load_fails(st_put_gltf("wt3.gltf",
                        st_edit(st_gl_json(&g), "\"attributes\": {\"POSITION\": 0}", "\"attributes\": {\"POSITION\": 7}")),
               2, "wt3.gltf: mesh 0 'tri' primitive 0 POSITION", "accessor 7 does not exist");
}

/* The example of the issue: "x.glb: mesh 2 'chair' primitive 0: index 812 out of range (vertex count 500)". */
Test(scene_gltf_errors, index_out_of_range)
{
    static const uint32_t idx[3] = {0, 1, 7};
    Gl g = st_tri();
    g.nidx = 3;
    g.idx = idx;
    g.ictype = 5123;
    Scene s;
    char err[1024];
    const char *path = st_put_gltf("ir.gltf", st_gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    char want[512];
    snprintf(want, sizeof want, "%s: mesh 0 'tri' primitive 0: index 7 out of range (vertex count 3)", path);
    cr_expect_str_eq(err, want);
}

Test(scene_gltf_errors, indices_not_whole_triangles)
{
    static const uint32_t idx[4] = {0, 1, 2, 0};
    Gl g = st_tri();
    g.nidx = 4;
    g.idx = idx;
    g.ictype = 5125;
    st_load_fails(st_put_gltf("w.gltf", st_gl_json(&g)), 2, "w.gltf: mesh 0 'tri' primitive 0", "not a multiple of 3");
}

/* Points and lines are skipped and counted (one warning per file); a file of nothing else has no
 * geometry; a mode outside glTF's 0..6 is an error. */
Test(scene_gltf_errors, non_triangle_primitive)
{
    Gl g = st_tri();
    Scene s;
    st_load_ok(st_put_gltf("mixed.gltf",
                     st_edit(st_gl_json(&g), "{\"attributes\": {\"POSITION\": 0}}",
                          "{\"attributes\": {\"POSITION\": 0}, \"mode\": 1}, {\"attributes\": {\"POSITION\": 0}},"
                          " {\"attributes\": {\"POSITION\": 0}, \"mode\": 0}, {\"attributes\": {\"POSITION\": 0}, "
                          "\"mode\": 1}")),
            &s);
    cr_expect_eq(s.ntris, 1);
    cr_expect_eq(s.skipped_primitives, 3);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect_not_null(strstr(s.warnings[0], "mixed.gltf: skipped 3 of 4 primitives: not triangles (1 POINTS, 2 LINES)"),
                       "%s", s.warnings[0]);
    scene_free(&s);
    g.prim = "\"mode\": 3";
    st_load_fails(st_put_gltf("lines.gltf", st_gl_json(&g)), 2, "lines.gltf: the scene has no geometry",
               "its 1 glTF primitives that are not triangles were skipped");
    g.prim = "\"mode\": 9";
    st_load_fails(st_put_gltf("nine.gltf", st_gl_json(&g)), 1, "nine.gltf: mesh 0 'tri' primitive 0: mode 9 is not a glTF primitive mode");
}

Test(scene_gltf_errors, unsupported_required_extension)
{
    Gl g = st_tri();
    g.top = "\"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"extensionsRequired\": "
            "[\"KHR_materials_emissive_strength\", \"KHR_draco_mesh_compression\"]";
    const char *path = st_put_gltf("rx.gltf", st_gl_json(&g));
    Scene s;
    char err[1024], want[512];
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want, "%s: requires extension KHR_draco_mesh_compression, which sfsim does not support", path);
    cr_expect_str_eq(err, want);
    /* Draco's accessors have no bufferView, which tinygltf refuses ("accessor[1] invalid
     * bufferView") before its model says what the file requires: the extension is still named. */
    static const uint32_t idx[3] = {0, 1, 2};
    g.nidx = 3;
    g.idx = idx;
    g.ictype = 5123;
    st_load_fails(st_put_gltf("draco.gltf", st_edit(st_gl_json(&g), "{\"bufferView\": 1, \"componentType\": 5123",
                                           "{\"componentType\": 5123")),
               1, "draco.gltf: requires extension KHR_draco_mesh_compression, which sfsim does not support");
    /* the same in a GLB, from memory */
    g.nidx = 0;
    g.top = "\"extensionsRequired\": [\"KHR_materials_unlit\"]";
    char *json = st_gl_json(&g);
    size_t jl = (strlen(json) + 3) & ~(size_t)3, n = 20 + jl;
    unsigned char *glb = calloc(n, 1);
    uint32_t hdr[5] = {0x46546C67u, 2, (uint32_t)n, (uint32_t)jl, 0x4E4F534Au};
    memcpy(glb, hdr, sizeof hdr);
    memset(glb + 20, ' ', jl);
    memcpy(glb + 20, json, strlen(json));
    free(json);
    scene_init(&s, "unlit.glb");
    cr_expect_neq(gltf_append_memory(glb, n, "unlit.glb", NULL, &s, err, sizeof err), 0);
    cr_expect_str_eq(err, "unlit.glb: requires extension KHR_materials_unlit, which sfsim does not support");
    scene_free(&s);
    free(glb);
    /* the same extension only used (not required) is ignored */
    g.top = "\"extensionsUsed\": [\"KHR_materials_clearcoat\"]";
    st_load_ok(st_put_gltf("ux.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
}

/* Buffer and image uris stay inside the glTF file's folder: '../b.bin' is refused whether or not
 * it exists (neither its existence nor its size is told), a link inside the folder that points
 * out is refused too, a subfolder is fine, and SFSIM_ALLOW_OUTSIDE_URIS=1 lets the file out. */
Test(scene_gltf_errors, uris_stay_in_the_folder)
{
    char a[128], sub[128], bin[160], link[160], inner[160];
    snprintf(a, sizeof a, "%s/a", st_dir());
    snprintf(sub, sizeof sub, "%s/a/sub", st_dir());
    cr_assert_eq(mkdir(a, 0700), 0);
    cr_assert_eq(mkdir(sub, 0700), 0);
    snprintf(bin, sizeof bin, "%s/b.bin", st_dir());
    FILE *f = fopen(bin, "wb");
    cr_assert_not_null(f);
    fwrite(st_tri_pos, 1, sizeof st_tri_pos, f);
    fclose(f);
    snprintf(inner, sizeof inner, "%s/a/sub/c.bin", st_dir());
    f = fopen(inner, "wb");
    cr_assert_not_null(f);
    fwrite(st_tri_pos, 1, sizeof st_tri_pos, f);
    fclose(f);
    snprintf(link, sizeof link, "%s/a/link.bin", st_dir());
    cr_assert_eq(symlink("../b.bin", link), 0);
    static const char *const uris[] = {"../b.bin", "../nothere.bin", "link.bin", "sub/../../b.bin", "sub/c.bin"};
    unsetenv("SFSIM_ALLOW_OUTSIDE_URIS");
    for (int i = 0; i < 5; i++) {
        Gl g = st_tri();
        char *j = st_gl_json(&g), *uri = strstr(j, "data:application"), *end = strchr(uri, '"');
        char *json = NULL;
        cr_assert_gt(asprintf(&json, "%.*s%s%s", (int)(uri - j), j, uris[i], end), 0);
        free(j);
        char path[192], err[1024];
        snprintf(path, sizeof path, "%s/a/x.gltf", st_dir());
        f = fopen(path, "w");
        fputs(json, f);
        fclose(f);
        free(json);
        Scene s;
        int rc = scene_load(path, &s, err, sizeof err);
        if (i == 4) {
            cr_expect_eq(rc, 0, "%s: %s", uris[i], err);
            if (rc == 0)
                scene_free(&s);
        } else {
            char want[512];
            snprintf(want, sizeof want,
                     "%s: uri '%s' leads outside the folder of the glTF file, which sfsim does not read (set "
                     "SFSIM_ALLOW_OUTSIDE_URIS=1 to allow it)", path, uris[i]);
            cr_expect_eq(rc, -1, "%s loaded", uris[i]);
            cr_expect_str_eq(err, want);
        }
        /* allowed explicitly: the file outside is read (the missing one is then not found) */
        setenv("SFSIM_ALLOW_OUTSIDE_URIS", "1", 1);
        rc = scene_load(path, &s, err, sizeof err);
        unsetenv("SFSIM_ALLOW_OUTSIDE_URIS");
        if (i == 1) {
            cr_expect_eq(rc, -1);
            cr_expect_not_null(strstr(err, "nothere.bin"), "%s", err);
        } else {
            cr_expect_eq(rc, 0, "%s with SFSIM_ALLOW_OUTSIDE_URIS=1: %s", uris[i], err);
            if (rc == 0) {
                cr_expect_eq(s.ntris, 1);
                scene_free(&s);
            }
        }
        unlink(path);
    }
    /* an image uri: the same rule */
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"../../b.png\"}]";
    char path[192], err[1024];
    snprintf(path, sizeof path, "%s/a/img.gltf", st_dir());
    char *json = st_gl_json(&g);
    f = fopen(path, "w");
    fputs(json, f);
    fclose(f);
    free(json);
    Scene s;
    cr_expect_neq(scene_load(path, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "img.gltf: uri '../../b.png' leads outside the folder of the glTF file"), "%s", err);
    unlink(path);
    unlink(link);
    unlink(inner);
    unlink(bin);
    rmdir(sub);
    rmdir(a);
}

/* A vertex that is not finite in the accessor is named as such, with no transform involved (the
 * issue's (1, inf, 0) used to be "not finite after the node transforms", as 0 x inf made its x
 * NaN); a finite vertex beyond the coordinate limit (1e18) says so, in the accessor or after the
 * transforms. */
Test(scene_gltf_errors, nan_vertex)
{
    float pos[9] = {0, 0, 0, NAN, 0, 0, 0, 1, 0};
    Gl g = st_tri();
    g.pos = pos;
    st_load_fails(st_put_gltf("nan.gltf", st_gl_json(&g)), 1,
               "nan.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 0 is not finite (nan)");
    pos[3] = 1;
    pos[4] = INFINITY;
    Scene s;
    char err[1024], want[512];
    const char *path = st_put_gltf("inf.gltf", st_gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want, "%s: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 1 is not finite (inf)",
             path);
    cr_expect_str_eq(err, want);
    pos[4] = 1e30f;
    path = st_put_gltf("far.gltf", st_gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want,
             "%s: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 1 is 1e+30, beyond the limit of "
             "1e+18 on scene coordinates (docs/scenes.md, Limits of scene values)", path);
    cr_expect_str_eq(err, want);
    /* at the limit: loads; a node scale that carries it past: the transformed vertex is named */
    pos[4] = 1e18f * 0.999f;
    st_load_ok(st_put_gltf("edge.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
    g.node = "\"scale\": [1, 10, 1]";
    path = st_put_gltf("scaled.gltf", st_gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "scaled.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 after the node "
                                   "transforms is (1, 9.99e+18, 0), beyond the limit of 1e+18 on scene coordinates"),
                       "%s", err);
}

Test(scene_gltf_errors, texture_transform_checked)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1]}}}}}";
    st_load_fails(st_put_gltf("tx1.gltf", st_gl_json(&g)), 1,
               "tx1.gltf: material 0 'm' baseColorTexture: KHR_texture_transform: scale is not 2 numbers");
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1e300, 1e300]}}}}}";
    st_load_fails(st_put_gltf("tx2.gltf", st_gl_json(&g)), 1,
               "tx2.gltf: mesh 0 'tri' primitive 0 TEXCOORD_0: vertex 1 is not finite after KHR_texture_transform");
}

Test(scene_gltf_errors, sparse_accessor_checked)
{
    st_load_fails(st_put_gltf("sd.gltf", st_sparse_json(2, 1, 1, 24)), 3, "sd.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 1, not greater than the one before (2)", "increase strictly");
    st_load_fails(st_put_gltf("se.gltf", st_sparse_json(1, 1, 1, 24)), 2, "se.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 1, not greater");
    st_load_fails(st_put_gltf("so.gltf", st_sparse_json(1, 3, 0, 24)), 2, "so.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 3, out of range (accessor count 3)");
    st_load_fails(st_put_gltf("sv.gltf", st_sparse_json(1, 2, 1, 20)), 2,
               "sv.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: sparse values",
               "2 elements at offset 0 run past the end of the bufferView");
}

Test(scene_gltf_errors, broken_hierarchy)
{
    Gl g = st_tri();
    g.nodes = "{\"children\": [0]}, {\"children\": [0]}";
    g.scene_nodes = "1, 2";
    st_load_fails(st_put_gltf("two.gltf", st_gl_json(&g)), 2, "two.gltf: node 0", "more than one parent");
    g.nodes = "{\"children\": [9]}";
    g.scene_nodes = "0, 1";
    st_load_fails(st_put_gltf("nine.gltf", st_gl_json(&g)), 2, "nine.gltf: node 1", "child 9 does not exist");
    /* a cycle is unreachable from the roots, not an endless walk */
    g.nodes = "{\"children\": [2]}, {\"children\": [1]}";
    g.scene_nodes = "0";
    Scene s;
    st_load_ok(st_put_gltf("cycle.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.ntris, 1);
    scene_free(&s);
}

/* tinygltf 2.7 parses "extras" recursively: deep nesting would overflow the stack. */
Test(scene_gltf_errors, json_nested_too_deep)
{
    size_t n = 40000;
    char *j = malloc(2 * n + 64);
    strcpy(j, "{\"asset\": {\"version\": \"2.0\"}, \"extras\": ");
    size_t at = strlen(j);
    memset(j + at, '[', n);
    memset(j + at + n, ']', n);
    strcpy(j + at + 2 * n, "}");
    st_load_fails(st_put_gltf("deep.gltf", j), 2, "deep.gltf: ", "JSON nested deeper than 512 levels");
    /* the same limit holds from memory, and brackets inside strings do not count */
    Scene s;
    char err[512];
    const char *ok = "{\"asset\": {\"version\": \"2.0\", \"generator\": \"[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[\"}}";
    scene_init(&s, "m");
    cr_expect_eq(gltf_append_memory((const unsigned char *)ok, strlen(ok), "m.gltf", NULL, &s, err, sizeof err), 0,
                 "%s", err);
    scene_free(&s);
}

Test(scene_gltf_errors, bad_material_reference)
{
    Gl g = st_tri();
    g.prim = "\"material\": 3";
    st_load_fails(st_put_gltf("bm.gltf", st_gl_json(&g)), 2, "bm.gltf: mesh 0 'tri' primitive 0", "material 3 does not exist");
}
