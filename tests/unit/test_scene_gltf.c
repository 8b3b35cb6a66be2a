/* tests/unit/test_scene_gltf.c -- the scene loader's glTF mapping: materials (ARCHITECTURE.md
 * Sec. 1), textures and their coordinates, vertex colours, emissive textures; node transforms,
 * index types, strips and fans, sparse accessors; KHR_lights_punctual and cameras.
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

/* ---- material mapping (ARCHITECTURE.md Sec. 1) --------------------------------------------- */

TestSuite(scene_materials, .init = st_tmp_setup, .fini = st_tmp_teardown);

static Scene one_material(const char *material, const char *top)
{
    Gl g = st_tri();
    g.material = material;
    g.top = top;
    Scene s;
    st_load_ok(st_put_gltf("m.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.ntris, 1);
    cr_assert_eq(s.nmaterials, 1);
    return s;
}

Test(scene_materials, lambert)
{
    Scene s = one_material("{\"name\": \"wall\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.5, 0.25, 0.125, 1],"
                           " \"metallicFactor\": 0, \"roughnessFactor\": 1}}",
                           NULL);
    const SceneMaterial *m = &s.materials[0];
    cr_expect_str_eq(m->name, "wall");
    cr_expect_eq(m->kind, SCENE_MAT_LAMBERT);
    expect_near(m->base_color[0], 0.5f, EPS);
    expect_near(m->base_color[1], 0.25f, EPS);
    expect_near(m->base_color[2], 0.125f, EPS);
    cr_expect_eq(m->base_texture, -1);
    expect_near(m->ior, 1.5f, EPS);
    cr_expect_str_eq(st_needs_of(&s), "lambert");
    cr_expect_eq(s.nemissive, 0);
    scene_free(&s);
}

/* glTF's defaults are metallic 1, roughness 1: a material that gives neither is glossy (metal). */
Test(scene_materials, gltf_defaults_are_metal)
{
    Scene s = one_material("{}", NULL);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    expect_near(s.materials[0].metallic, 1.0f, EPS);
    expect_near(s.materials[0].roughness, 1.0f, EPS);
    expect_near(s.materials[0].base_color[1], 1.0f, EPS);
    cr_expect_str_eq(s.materials[0].name, "material_0", "unnamed materials are named by index");
    cr_expect_str_eq(st_needs_of(&s), "glossy");
    scene_free(&s);
}

Test(scene_materials, glossy_by_metallic_or_roughness)
{
    Scene s = one_material("{\"pbrMetallicRoughness\": {\"metallicFactor\": 0.5, \"roughnessFactor\": 1}}", NULL);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    scene_free(&s);
    s = one_material("{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"roughnessFactor\": 0.3}}", NULL);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    expect_near(s.materials[0].roughness, 0.3f, EPS);
    scene_free(&s);
}

Test(scene_materials, dielectric_from_transmission_and_ior)
{
    Scene s = one_material("{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"roughnessFactor\": 0},"
                           " \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1},"
                           " \"KHR_materials_ior\": {\"ior\": 1.33}}}",
                           "\"extensionsUsed\": [\"KHR_materials_transmission\", \"KHR_materials_ior\"]");
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_DIELECTRIC);
    expect_near(s.materials[0].ior, 1.33f, EPS);
    expect_near(s.materials[0].transmission, 1.0f, EPS);
    cr_expect_str_eq(st_needs_of(&s), "dielectric");
    scene_free(&s);
    /* transmission wins over metallic/roughness; no KHR_materials_ior: 1.5 */
    s = one_material("{\"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 0.5}}}", NULL);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_DIELECTRIC);
    expect_near(s.materials[0].ior, 1.5f, EPS);
    scene_free(&s);
}

Test(scene_materials, emissive_triangles_are_area_lights)
{
    Scene s = one_material("{\"pbrMetallicRoughness\": {\"metallicFactor\": 0}, \"emissiveFactor\": [1, 0.5, 0.25],"
                           " \"extensions\": {\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 4}}}",
                           "\"extensionsUsed\": [\"KHR_materials_emissive_strength\"],"
                           " \"extensionsRequired\": [\"KHR_materials_emissive_strength\"]");
    expect_near(s.materials[0].emission[0], 4.0f, EPS);
    expect_near(s.materials[0].emission[1], 2.0f, EPS);
    expect_near(s.materials[0].emission[2], 1.0f, EPS);
    cr_expect_eq(s.nemissive, 1);
    cr_expect_eq(s.emissive_tris[0], 0);
    /* an emitter is a light, not a surface to shade: no material kind is needed for it */
    cr_expect_str_eq(st_needs_of(&s), "area_lights");
    scene_free(&s);
}

Test(scene_materials, no_material_gets_the_gltf_default)
{
    Gl g = st_tri();
    Scene s;
    st_load_ok(st_put_gltf("d.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.nmaterials, 1);
    cr_expect_eq(s.tri_material[0], 0);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    cr_expect_str_eq(s.materials[0].name, "(glTF default material)");
    scene_free(&s);
}

Test(scene_materials, alpha_modes)
{
    Scene s = one_material("{\"alphaMode\": \"MASK\", \"alphaCutoff\": 0.3, \"doubleSided\": true,"
                           " \"pbrMetallicRoughness\": {\"baseColorFactor\": [1, 1, 1, 0.75], \"metallicFactor\": 0}}",
                           NULL);
    cr_expect_eq(s.materials[0].alpha_mode, SCENE_ALPHA_MASK);
    expect_near(s.materials[0].alpha_cutoff, 0.3f, EPS);
    expect_near(s.materials[0].alpha, 0.75f, EPS);
    cr_expect_eq(s.materials[0].double_sided, 1);
    cr_expect_str_eq(st_needs_of(&s), "lambert,alpha");
    scene_free(&s);
    s = one_material("{\"alphaMode\": \"BLEND\"}", NULL);
    cr_expect_eq(s.materials[0].alpha_mode, SCENE_ALPHA_BLEND);
    cr_expect_neq(s.needs & SCENE_NEED_ALPHA, 0);
    scene_free(&s);
    s = one_material("{}", NULL);
    cr_expect_eq(s.materials[0].alpha_mode, SCENE_ALPHA_OPAQUE);
    expect_near(s.materials[0].alpha_cutoff, 0.5f, EPS);
    cr_expect_eq(s.needs & SCENE_NEED_ALPHA, 0);
    scene_free(&s);
}

static float srgb(int c)
{
    double v = c / 255.0;
    return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
}

Test(scene_materials, base_colour_texture_srgb_to_linear)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"name\": \"checker\", \"uri\": "
            "\"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    st_load_ok(st_put_gltf("t.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.ntextures, 1);
    const SceneTexture *t = &s.textures[0];
    cr_expect_str_eq(t->name, "checker");
    cr_assert_eq(t->width, 2);
    cr_assert_eq(t->height, 2);
    expect_near(t->rgba[0], srgb(128), 1e-6f);
    expect_near(t->rgba[1], 0.0f, 1e-6f);
    expect_near(t->rgba[2], 1.0f, 1e-6f);
    expect_near(t->rgba[3], 64 / 255.0f, 1e-6f); /* alpha stays linear */
    expect_near(t->rgba[12], srgb(64), 1e-6f);
    expect_near(t->rgba[15], 128 / 255.0f, 1e-6f);
    cr_expect_eq(s.materials[0].base_texture, 0);
    cr_assert_not_null(s.uv);
    expect_near(s.uv[2], 1.0f, EPS);
    expect_near(s.uv[5], 1.0f, EPS);
    cr_expect_str_eq(st_needs_of(&s), "lambert,textures");
    scene_free(&s);
}

/* KHR_texture_transform and texCoord are applied to the coordinates at load time, per texture:
 * the base-colour texture reads TEXCOORD_1 through offset (0.5, 0.25), rotation pi/2, scale
 * (2, 3) -- u' = 2 cos(r) u + 3 sin(r) v + 0.5, v' = -2 sin(r) u + 3 cos(r) v + 0.25 -- while
 * the emissive texture reads the same set through its own offset. */
Test(scene_materials, texture_transform_and_texcoord_per_texture)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0, \"texCoord\": 1,"
                 " \"extensions\": {\"KHR_texture_transform\": {\"offset\": [0.5, 0.25], \"rotation\": 1.5707963267948966,"
                 " \"scale\": [2, 3]}}}}, \"emissiveFactor\": [1, 1, 1], \"emissiveTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"offset\": [0.125, 0], \"texCoord\": 1}}}}";
    g.top = "\"extensionsUsed\": [\"KHR_texture_transform\"], \"textures\": [{\"source\": 0}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    st_load_ok(st_put_gltf("tt.gltf", st_edit(st_gl_json(&g), "\"TEXCOORD_0\"", "\"TEXCOORD_1\"")), &s);
    cr_assert_not_null(s.uv);
    static const float want[6] = {0.5f, 0.25f, 0.5f, -1.75f, 3.5f, 0.25f};
    for (int k = 0; k < 6; k++)
        expect_near(s.uv[k], want[k], 1e-6f);
    cr_assert_not_null(s.uv_emit, "the emissive texture's own coordinates");
    static const float want_e[6] = {0.125f, 0, 1.125f, 0, 0.125f, 1};
    for (int k = 0; k < 6; k++)
        expect_near(s.uv_emit[k], want_e[k], 0.0f);
    scene_free(&s);
    /* a texture reading a set the primitive does not have has no coordinates (not applied) */
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0, \"texCoord\": 1}}}";
    st_load_ok(st_put_gltf("t0.gltf", st_gl_json(&g)), &s);
    cr_expect_null(s.uv);
    cr_expect_null(s.uv_emit);
    cr_expect_str_eq(st_needs_of(&s), "lambert");
    scene_free(&s);
    /* dequantization, as gltfpack writes it: integer coordinates scaled by the transform */
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0,"
                 " \"extensions\": {\"KHR_texture_transform\": {\"scale\": [0.001, 0.002]}}}}}";
    static const float big[6] = {0, 0, 1000, 0, 0, 500};
    g.uv = big;
    st_load_ok(st_put_gltf("tq.gltf", st_gl_json(&g)), &s);
    expect_near(s.uv[2], 1.0f, 1e-6f);
    expect_near(s.uv[5], 1.0f, 1e-6f);
    scene_free(&s);
}

/* Textures repeat: a sampler asking for clamping is not applied, and a warning says so. */
Test(scene_materials, clamped_sampler_warns)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0}}}";
    g.top = "\"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{\"wrapS\": 33071, \"wrapT\": 10497}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    st_load_ok(st_put_gltf("cl.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect_not_null(strstr(s.warnings[0], "cl.gltf: 1 textures ask for CLAMP_TO_EDGE or MIRRORED_REPEAT wrapping, "
                                             "which is not applied: every texture repeats"), "%s", s.warnings[0]);
    scene_free(&s);
    g.top = "\"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    st_load_ok(st_put_gltf("rp.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.nwarnings, 0);
    scene_free(&s);
}

/* COLOR_0 (VEC3 or VEC4, float or normalized integers) is kept per vertex; triangles of a file
 * without it get white. */
Test(scene_materials, vertex_colours)
{
    static const float col[9] = {1, 0, 0, 0, 0.5f, 0, 0, 0, 0.25f};
    Gl g = st_tri();
    g.nrm = col;
    Scene s;
    st_load_ok(st_put_gltf("vc.gltf", st_edit(st_gl_json(&g), "\"NORMAL\"", "\"COLOR_0\"")), &s);
    cr_assert_not_null(s.col);
    for (int k = 0; k < 9; k++)
        expect_near(s.col[k], col[k], 0.0f);
    cr_expect_null(s.nrm);
    scene_free(&s);
    /* a second file without colours: white */
    st_put_gltf("a.gltf", st_edit(st_gl_json(&g), "\"NORMAL\"", "\"COLOR_0\""));
    g.nrm = NULL;
    st_put_gltf("b.gltf", st_gl_json(&g));
    st_load_ok(st_put_file("s.ini", "[scene]\ngltf = b.gltf\ngltf = a.gltf\n"), &s);
    cr_assert_eq(s.ntris, 2);
    cr_assert_not_null(s.col);
    for (int k = 0; k < 9; k++) {
        expect_near(s.col[k], 1.0f, 0.0f);
        expect_near(s.col[9 + k], col[k], 0.0f);
    }
    scene_free(&s);
    float neg[9] = {1, 0, 0, 0, -0.5f, 0, 0, 0, 0.25f};
    g.nrm = neg;
    st_load_fails(st_put_gltf("vn.gltf", st_edit(st_gl_json(&g), "\"NORMAL\"", "\"COLOR_0\"")), 1,
               "vn.gltf: mesh 0 'tri' primitive 0 COLOR_0: vertex 1 component 1 is negative or not finite");
}

/* An emissive texture that is black in places: only triangles that see lit texels emit. */
Test(scene_materials, emissive_texture_lights_only_lit_parts)
{
    static const float pos[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0};
    static const float uv[12] = {0.05f, 0.5f, 0.3f, 0.5f, 0.05f, 0.5f, 0.6f, 0.5f, 0.95f, 0.5f, 0.6f, 0.5f};
    Gl g = st_tri();
    g.nv = 6;
    g.pos = pos;
    g.uv = uv;
    g.material = "{\"name\": \"panel\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0},"
                 " \"emissiveFactor\": [2, 2, 2], \"emissiveTexture\": {\"index\": 0}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"data:image/png;base64," PNG_16X1 "\"}]";
    Scene s;
    st_load_ok(st_put_gltf("e.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.ntris, 2);
    cr_assert_eq(s.nmaterials, 2, "the material splits into a dark and a lit part");
    cr_expect_str_eq(s.materials[0].name, "panel");
    cr_expect_str_eq(s.materials[1].name, "panel");
    expect_near(s.materials[0].emission[0], 0.0f, 0.0f);
    expect_near(s.materials[1].emission[0], 2.0f, EPS);
    cr_expect_eq(s.materials[1].emissive_texture, 0);
    cr_expect_eq(s.tri_material[0], 0, "the triangle over black texels does not emit");
    cr_expect_eq(s.tri_material[1], 1);
    cr_assert_eq(s.nemissive, 1);
    cr_expect_eq(s.emissive_tris[0], 1);
    /* the lit part samples its texture, and is shaded too (its texture may be dark in places) */
    cr_expect_str_eq(st_needs_of(&s), "lambert,area_lights,emissive_textures");
    cr_assert_not_null(s.uv_emit);
    scene_free(&s);
}

/* ---- geometry: transforms, index types, strips and fans ----------------------------------- */

TestSuite(scene_geometry, .init = st_tmp_setup, .fini = st_tmp_teardown);

Test(scene_geometry, node_translation_moves_vertices)
{
    Gl g = st_tri();
    g.node = "\"translation\": [10, 20, 30]";
    Scene s;
    st_load_ok(st_put_gltf("t.gltf", st_gl_json(&g)), &s);
    expect_near(s.pos[0], 10.0f, EPS);
    expect_near(s.pos[1], 20.0f, EPS);
    expect_near(s.pos[2], 30.0f, EPS);
    expect_near(s.pos[3], 11.0f, EPS);
    expect_near(s.pos[7], 21.0f, EPS);
    expect_near(s.bounds_min[0], 10.0f, EPS);
    expect_near(s.bounds_max[1], 21.0f, EPS);
    scene_free(&s);
}

/* Parent TRS (rotation 90 degrees about y, then translation) composed with a child matrix
 * (uniform scale 2); normals follow the rotation. */
Test(scene_geometry, hierarchy_trs_and_matrix)
{
    static const float nrm[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.nrm = nrm;
    g.node = "\"matrix\": [2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1]";
    g.nodes = "{\"children\": [0], \"rotation\": [0, 0.70710678, 0, 0.70710678], \"translation\": [0, 0, 5]}";
    g.scene_nodes = "1";
    Scene s;
    st_load_ok(st_put_gltf("h.gltf", st_gl_json(&g)), &s);
    /* (1,0,0) -> scale (2,0,0) -> rot_y(90) (0,0,-2) -> translate (0,0,3) */
    expect_near(s.pos[3], 0.0f, 1e-5f);
    expect_near(s.pos[4], 0.0f, 1e-5f);
    expect_near(s.pos[5], 3.0f, 1e-5f);
    /* (0,1,0) -> (0,2,5) */
    expect_near(s.pos[7], 2.0f, 1e-5f);
    expect_near(s.pos[8], 5.0f, 1e-5f);
    /* normal +z -> +x */
    cr_assert_not_null(s.nrm);
    expect_near(s.nrm[0], 1.0f, 1e-5f);
    expect_near(s.nrm[2], 0.0f, 1e-5f);
    scene_free(&s);
}

/* Normals go through the inverse transpose: under scale (1, 4, 1) a 45-degree normal tilts. */
Test(scene_geometry, normals_inverse_transpose)
{
    static const float nrm[9] = {0.70710678f, 0.70710678f, 0, 0.70710678f, 0.70710678f, 0, 0.70710678f, 0.70710678f, 0};
    Gl g = st_tri();
    g.nrm = nrm;
    g.node = "\"scale\": [1, 4, 1]";
    Scene s;
    st_load_ok(st_put_gltf("n.gltf", st_gl_json(&g)), &s);
    /* M^-T n = (1, 1/4, 0) / |.| */
    float l = sqrtf(1.0f + 1.0f / 16.0f);
    expect_near(s.nrm[0], 1.0f / l, 1e-5f);
    expect_near(s.nrm[1], 0.25f / l, 1e-5f);
    scene_free(&s);
}

/* A mirroring transform keeps the front face: the winding is reversed (glTF 2.0 Sec. 3.7.4). */
Test(scene_geometry, mirror_keeps_front_face)
{
    Gl g = st_tri();
    g.node = "\"scale\": [-1, 1, 1]";
    Scene s;
    st_load_ok(st_put_gltf("m.gltf", st_gl_json(&g)), &s);
    const float *p = s.pos;
    float e1[3] = {p[3] - p[0], p[4] - p[1], p[5] - p[2]}, e2[3] = {p[6] - p[0], p[7] - p[1], p[8] - p[2]};
    float nz = e1[0] * e2[1] - e1[1] * e2[0];
    cr_expect_gt(nz, 0.0f, "the geometric normal still points to +z");
    expect_near(s.nrm ? s.nrm[2] : 1.0f, 1.0f, EPS);
    scene_free(&s);
}

Test(scene_geometry, every_index_type)
{
    static const float pos[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    static const uint32_t idx[6] = {0, 1, 2, 0, 2, 3};
    int types[3] = {5121, 5123, 5125};
    for (int i = 0; i < 3; i++) {
        Gl g = st_tri();
        g.nv = 4;
        g.pos = pos;
        g.nidx = 6;
        g.idx = idx;
        g.ictype = types[i];
        Scene s;
        st_load_ok(st_put_gltf(i == 0 ? "u8.gltf" : i == 1 ? "u16.gltf" : "u32.gltf", st_gl_json(&g)), &s);
        cr_expect_eq(s.ntris, 2);
        /* triangle 1 = vertices 0, 2, 3: its second vertex (1,1,0), its third (0,1,0) */
        expect_near(s.pos[9 + 3], 1.0f, EPS);
        expect_near(s.pos[9 + 4], 1.0f, EPS);
        expect_near(s.pos[9 + 6], 0.0f, EPS);
        expect_near(s.pos[9 + 7], 1.0f, EPS);
        scene_free(&s);
    }
}

Test(scene_geometry, strip_and_fan)
{
    static const float pos[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 0, 2, 0};
    Gl g = st_tri();
    g.nv = 5;
    g.pos = pos;
    g.prim = "\"mode\": 5";
    Scene s;
    st_load_ok(st_put_gltf("strip.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.ntris, 3);
    /* every strip triangle keeps the winding of the first: normals all +z */
    for (uint32_t t = 0; t < s.ntris; t++) {
        const float *p = &s.pos[9 * t];
        float nz = (p[3] - p[0]) * (p[7] - p[1]) - (p[4] - p[1]) * (p[6] - p[0]);
        cr_expect_gt(nz, 0.0f, "strip triangle %u is flipped", t);
    }
    scene_free(&s);
    g.prim = "\"mode\": 6";
    st_load_ok(st_put_gltf("fan.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.ntris, 3);
    scene_free(&s);
}

/* ---- KHR_lights_punctual and cameras ------------------------------------------------------- */

TestSuite(scene_lights_cameras, .init = st_tmp_setup, .fini = st_tmp_teardown);

Test(scene_lights_cameras, punctual_lights_with_node_transforms)
{
    Gl g = st_tri();
    g.nodes = "{\"translation\": [1, 2, 3], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
              " {\"rotation\": [-0.70710678, 0, 0, 0.70710678], \"translation\": [0, 5, 0],"
              "  \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},"
              " {\"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}}";
    g.scene_nodes = "0, 1, 2, 3";
    g.top = "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
            "{\"type\": \"point\", \"name\": \"bulb\", \"color\": [1, 0.5, 0.25], \"intensity\": 40},"
            "{\"type\": \"spot\", \"intensity\": 100, \"spot\": {\"innerConeAngle\": 0.2, \"outerConeAngle\": 0.5}},"
            "{\"type\": \"directional\", \"intensity\": 3}]}}";
    Scene s;
    st_load_ok(st_put_gltf("l.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.nlights, 3);
    const SceneLight *p = &s.lights[0], *sp = &s.lights[1], *d = &s.lights[2];
    cr_expect_eq(p->kind, SCENE_LIGHT_POINT);
    cr_expect_str_eq(p->name, "bulb");
    expect_near(p->position[0], 1.0f, EPS);
    expect_near(p->position[2], 3.0f, EPS);
    expect_near(p->color[1], 0.5f, EPS);
    expect_near(p->intensity, 40.0f, EPS);
    cr_expect_eq(sp->kind, SCENE_LIGHT_SPOT);
    cr_expect_str_eq(sp->name, "light_1");
    expect_near(sp->position[1], 5.0f, EPS);
    /* -z turned by -90 degrees about x points down */
    expect_near(sp->direction[1], -1.0f, 1e-5f);
    expect_near(sp->inner_cone, 0.2f, EPS);
    expect_near(sp->outer_cone, 0.5f, EPS);
    cr_expect_eq(d->kind, SCENE_LIGHT_DIRECTIONAL);
    expect_near(d->direction[2], -1.0f, EPS);
    cr_expect_str_eq(st_needs_of(&s), "glossy,punctual_lights");
    scene_free(&s);
}

Test(scene_lights_cameras, camera_from_gltf)
{
    Gl g = st_tri();
    /* a camera at (0, 1, 10) turned 90 degrees about y: it looks down -x */
    g.nodes = "{\"camera\": 0, \"translation\": [0, 1, 10], \"rotation\": [0, 0.70710678, 0, 0.70710678]},"
              " {\"camera\": 1, \"translation\": [7, 7, 7]}";
    g.scene_nodes = "0, 1, 2";
    g.top = "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, \"znear\": 0.01}},"
            " {\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.5, \"znear\": 0.01}}]";
    Scene s;
    st_load_ok(st_put_gltf("c.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_GLTF);
    expect_near(s.camera.fov_y, 0.8f * 180.0f / (float)M_PI, 1e-4f);
    expect_near(s.camera.position[1], 1.0f, EPS);
    expect_near(s.camera.position[2], 10.0f, EPS);
    expect_near(s.camera.look_at[0] - s.camera.position[0], -1.0f, 1e-5f);
    expect_near(s.camera.look_at[2] - s.camera.position[2], 0.0f, 1e-5f);
    expect_near(s.camera.up[1], 1.0f, 1e-5f);
    scene_free(&s);
}

/* No camera: look at the bounds' centre from +z, 45 degrees, the bounding sphere in view. */
Test(scene_lights_cameras, default_camera_frames_bounds)
{
    static const float pos[9] = {-2, 0, -1, 4, 0, -1, -2, 3, 1};
    Gl g = st_tri();
    g.pos = pos;
    Scene s;
    st_load_ok(st_put_gltf("d.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_DEFAULT);
    expect_near(s.camera.fov_y, 45.0f, EPS);
    expect_near(s.camera.look_at[0], 1.0f, EPS);
    expect_near(s.camera.look_at[1], 1.5f, EPS);
    expect_near(s.camera.look_at[2], 0.0f, EPS);
    expect_near(s.camera.position[0], 1.0f, EPS);
    expect_near(s.camera.position[1], 1.5f, EPS);
    float r = sqrtf(3 * 3 + 1.5f * 1.5f + 1 * 1), dist = s.camera.position[2] - s.camera.look_at[2];
    cr_expect_gt(dist * sinf(22.5f * (float)M_PI / 180.0f), r, "the bounding sphere fits the view");
    cr_expect_lt(dist * sinf(22.5f * (float)M_PI / 180.0f), 1.2f * r, "and fills most of it");
    expect_near(s.camera.up[1], 1.0f, EPS);
    scene_free(&s);
}

Test(scene_geometry, sparse_accessor_substitutes_values)
{
    for (int base = 1; base >= 0; base--) {
        Scene s;
        st_load_ok(st_put_gltf(base ? "sp.gltf" : "sp0.gltf", st_sparse_json(1, 2, base, 24)), &s);
        cr_assert_eq(s.ntris, 1);
        static const float want[9] = {0, 0, 0, 5, 0, 0, 0, 7, 0};
        for (int k = 0; k < 9; k++)
            cr_expect_eq(s.pos[k], want[k], "base %d: coordinate %d is %g, expected %g", base, k, (double)s.pos[k],
                         (double)want[k]);
        scene_free(&s);
    }
    /* only vertex 0 replaced: the others keep the base view's values */
    Scene s;
    st_load_ok(st_put_gltf("sp1.gltf", st_sparse_json(0, 2, 1, 24)), &s);
    expect_near(s.pos[0], 5.0f, 0.0f);
    expect_near(s.pos[3], 1.0f, 0.0f);
    expect_near(s.pos[7], 7.0f, 0.0f);
    scene_free(&s);
}
