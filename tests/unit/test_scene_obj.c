/* tests/unit/test_scene_obj.c -- Wavefront OBJ + MTL scenes (scenes/obj_load.cpp): the same Scene
 * as the same scene in glTF, the MTL material rules of docs/scenes.md, triangulation, relative
 * indices, textures, normals, placement, and every refused input with its message (the file and
 * the line).
 *
 * Small inputs are written by the tests into a temporary folder (tests/support/scene_fixture.h)
 * so each test shows what it checks; tests/scenes/obj/ holds the shipped ones the CLI tests use. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../../scenes/obj.h"
#include "../../scenes/scene.h"
#include "../../scenes/scene_file.h"
#include "../support/scene_fixture.h"

TestSuite(scene_obj, .init = st_tmp_setup, .fini = st_tmp_teardown);

/* ---- the same scene in both formats ---------------------------------------------------------- */

static void expect_same_material(const SceneMaterial *a, const SceneMaterial *b)
{
    cr_expect_str_eq(a->name, b->name);
    cr_expect_eq(a->kind, b->kind, "material %s: kind %d vs %d", a->name, a->kind, b->kind);
    cr_expect_eq(memcmp(a->base_color, b->base_color, sizeof a->base_color), 0, "material %s: base colour", a->name);
    cr_expect_eq(memcmp(a->emission, b->emission, sizeof a->emission), 0, "material %s: emission (%g %g %g vs %g %g %g)",
                 a->name, a->emission[0], a->emission[1], a->emission[2], b->emission[0], b->emission[1],
                 b->emission[2]);
    cr_expect_eq(a->metallic, b->metallic, "material %s: metallic", a->name);
    cr_expect_eq(a->roughness, b->roughness, "material %s: roughness", a->name);
    cr_expect_eq(a->ior, b->ior, "material %s: ior", a->name);
    cr_expect_eq(a->transmission, b->transmission, "material %s: transmission", a->name);
    cr_expect_eq(a->alpha, b->alpha, "material %s: alpha", a->name);
    cr_expect_eq(a->alpha_mode, b->alpha_mode, "material %s: alpha mode", a->name);
    cr_expect_eq(a->double_sided, b->double_sided, "material %s: double sided", a->name);
    cr_expect_eq(a->base_texture, b->base_texture, "material %s: texture", a->name);
    cr_expect_eq(a->emissive_texture, b->emissive_texture, "material %s: emissive texture", a->name);
}

/* cross-gltf.ini (the shipped Cornell box as glTF, red a mirror and green glass by [material.*])
 * and cross-obj.ini (cornell.obj + cornell.mtl, the MTL rules): the same triangles bit for bit,
 * the same materials field by field, the same needs. tests/cli/cases/obj.sh renders both. */
Test(scene_obj, same_scene_as_gltf)
{
    Scene g, o;
    st_load_ok("tests/scenes/obj/cross-gltf.ini", &g);
    st_load_ok("tests/scenes/obj/cross-obj.ini", &o);
    cr_assert_eq(o.ntris, 32);
    cr_assert_eq(g.ntris, o.ntris);
    cr_expect_eq(memcmp(g.pos, o.pos, sizeof(float) * 9 * g.ntris), 0, "vertex positions differ");
    cr_expect_eq(memcmp(g.tri_material, o.tri_material, sizeof(uint32_t) * g.ntris), 0, "triangle materials differ");
    cr_expect(!g.nrm && !o.nrm && !g.uv && !o.uv && !g.col && !o.col);
    cr_assert_eq(g.nmaterials, o.nmaterials);
    for (uint32_t i = 0; i < g.nmaterials; i++)
        expect_same_material(&g.materials[i], &o.materials[i]);
    cr_expect_eq(g.nemissive, 2);
    cr_expect_eq(g.nemissive, o.nemissive);
    cr_expect_eq(g.needs, o.needs);
    cr_expect_str_eq(st_needs_of(&o), "lambert,glossy,dielectric,area_lights");
    scene_free(&g);
    scene_free(&o);
}

/* ---- material rules (docs/scenes.md, OBJ and MTL) -------------------------------------------- */

static const SceneMaterial *mat_named(const Scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->nmaterials; i++)
        if (!strcmp(s->materials[i].name, name))
            return &s->materials[i];
    cr_assert_fail("no material '%s'", name);
    return NULL;
}

static const char *const tri_obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";

/* An OBJ of one triangle per material named, with m.mtl holding mtl. */
static const char *put_obj_mats(const char *mtl, const char *const *names, int n)
{
    char obj[4096];
    size_t len = (size_t)snprintf(obj, sizeof obj, "%s", tri_obj);
    for (int i = 0; i < n; i++)
        len += (size_t)snprintf(obj + len, sizeof obj - len, "usemtl %s\nf 1 2 3\n", names[i]);
    st_put_file("m.mtl", mtl);
    return st_put_file("x.obj", obj);
}

Test(scene_obj, material_rules)
{
    static const char *const names[] = {"matte", "plastic", "dull", "mirror", "mirror5", "glass", "glass6",
                                        "lamp", "veil", "tr"};
    const char *p = put_obj_mats("newmtl matte\nKd 0.5 0.25 0.125\nillum 2\n"           /* Ks 0: Lambertian */
                                 "newmtl plastic\nKd 0.2 0.3 0.4\nKs 0.5 0.5 0.5\nNs 250\nillum 2\n"
                                 "newmtl dull\nKd 0.2 0.3 0.4\nKs 0.5 0.5 0.5\nNs 800\nillum 1\n" /* illum 1: no specular */
                                 "newmtl mirror\nKd 0.1 0.1 0.1\nKs 0.9 0.8 0.7\nillum 3\n"
                                 "newmtl mirror5\nKd 0.6 0.6 0.6\nillum 5\n"                   /* Ks 0: Kd */
                                 "newmtl glass\nKd 0.1 0.1 0.1\nNi 2.5\nTf 0.9 0.8 1\nillum 7\n"
                                 "newmtl glass6\nillum 6\n"                                    /* no Ni, no Tf */
                                 "newmtl lamp\nKd 0.8 0.8 0.8\nKe 17 12 4\n"
                                 "newmtl veil\nKd 1 1 1\nd 0.25\nillum 1\n"
                                 "newmtl tr\nKd 1 1 1\nTr 0.25\n",
                                 names, 10);
    Scene s;
    st_load_ok(p, &s);
    const SceneMaterial *m = mat_named(&s, "matte");
    cr_expect_eq(m->kind, SCENE_MAT_LAMBERT);
    cr_expect(m->base_color[0] == 0.5f && m->base_color[1] == 0.25f && m->base_color[2] == 0.125f);
    cr_expect_eq(m->roughness, 1.0f);
    m = mat_named(&s, "plastic");
    cr_expect_eq(m->kind, SCENE_MAT_GLOSSY);
    expect_near(m->roughness, 0.75f, EPS); /* 1 - Ns / 1000 */
    cr_expect_eq(m->metallic, 0.0f);
    expect_near(m->base_color[2], 0.4f, EPS);
    cr_expect_eq(mat_named(&s, "dull")->kind, SCENE_MAT_LAMBERT);
    m = mat_named(&s, "mirror");
    cr_expect_eq(m->kind, SCENE_MAT_GLOSSY);
    cr_expect(m->metallic == 1.0f && m->roughness == 0.0f);
    expect_near(m->base_color[0], 0.9f, EPS); /* Ks */
    expect_near(m->base_color[2], 0.7f, EPS);
    m = mat_named(&s, "mirror5");
    cr_expect(m->kind == SCENE_MAT_GLOSSY && m->metallic == 1.0f);
    expect_near(m->base_color[1], 0.6f, EPS); /* Kd when Ks is 0 */
    m = mat_named(&s, "glass");
    cr_expect_eq(m->kind, SCENE_MAT_DIELECTRIC);
    cr_expect_eq(m->transmission, 1.0f);
    expect_near(m->ior, 2.5f, EPS);
    expect_near(m->base_color[1], 0.8f, EPS); /* Tf */
    m = mat_named(&s, "glass6");
    cr_expect_eq(m->kind, SCENE_MAT_DIELECTRIC);
    cr_expect_eq(m->ior, 1.5f);
    cr_expect(m->base_color[0] == 1.0f && m->base_color[1] == 1.0f && m->base_color[2] == 1.0f);
    m = mat_named(&s, "lamp");
    cr_expect(m->emission[0] == 17.0f && m->emission[1] == 12.0f && m->emission[2] == 4.0f);
    m = mat_named(&s, "veil");
    cr_expect_eq(m->alpha_mode, SCENE_ALPHA_BLEND);
    cr_expect_eq(m->alpha, 0.25f);
    m = mat_named(&s, "tr");
    cr_expect_eq(m->alpha_mode, SCENE_ALPHA_BLEND);
    cr_expect_eq(m->alpha, 0.75f); /* Tr = 1 - d */
    cr_expect_eq(s.nemissive, 1);
    cr_expect_str_eq(st_needs_of(&s), "lambert,glossy,dielectric,area_lights,alpha");
    scene_free(&s);
}

/* Faces before any usemtl get the OBJ default material (Lambertian 0.8), as without an MTL file. */
Test(scene_obj, default_material)
{
    Scene s;
    st_load_ok(st_put_file("x.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), &s);
    cr_assert_eq(s.nmaterials, 1);
    cr_expect_str_eq(s.materials[0].name, "(OBJ default material)");
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_LAMBERT);
    cr_expect_eq(s.materials[0].base_color[0], 0.8f);
    scene_free(&s);
}

Test(scene_obj, bad_material_values)
{
    static const char *const one[] = {"m"};
    st_load_fails(put_obj_mats("newmtl m\nillum 11\n", one, 1), 2, "m.mtl: material 'm'", "illum 11");
    st_load_fails(put_obj_mats("newmtl m\nKd -1 0 0\n", one, 1), 2, "material 'm'", "negative or not finite");
    st_load_fails(put_obj_mats("newmtl m\nNi -2\nillum 7\n", one, 1), 2, "material 'm'", "Ni -2");
    st_load_fails(put_obj_mats("newmtl m\nd 2\n", one, 1), 2, "material 'm'", "d 2");
    st_load_fails(put_obj_mats("newmtl other\nKd 1 1 1\n", one, 1), 3, "x.obj:5:", "usemtl 'm'", "no material");
}

/* ---- geometry ---------------------------------------------------------------------------------- */

static double tri_area(const float *p)
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)p[3 + k] - p[k];
        e2[k] = (double)p[6 + k] - p[k];
    }
    double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    return 0.5 * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

/* A convex quad: the fan from its first corner, (1 2 3) (1 3 4), the winding kept. */
Test(scene_obj, quad_is_a_fan)
{
    Scene s;
    st_load_ok(st_put_file("q.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nf 1 2 3 4\n"), &s);
    cr_assert_eq(s.ntris, 2);
    static const float want[18] = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 0, 0, 2, 1, 0, 0, 1, 0};
    cr_expect_eq(memcmp(s.pos, want, sizeof want), 0);
    scene_free(&s);
}

/* A concave (L-shaped) hexagon: ear clipping, 4 triangles covering exactly its area (3), each
 * facing +z like the polygon; a fan from corner 1 would cover area outside it. */
Test(scene_obj, concave_polygon_ear_clipped)
{
    Scene s;
    st_load_ok(st_put_file("l.obj", "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nf 3 4 5 6 1 2\n"), &s);
    cr_assert_eq(s.ntris, 4);
    double area = 0.0;
    for (uint32_t t = 0; t < s.ntris; t++) {
        const float *p = &s.pos[9 * t];
        double z = ((double)p[3] - p[0]) * ((double)p[7] - p[1]) - ((double)p[4] - p[1]) * ((double)p[6] - p[0]);
        cr_expect(z > 0.0, "triangle %u faces -z or is degenerate", t);
        area += tri_area(p);
        for (int c = 0; c < 3; c++) /* no corner of the notch's inside */
            cr_expect(!(p[3 * c] > 1.0f && p[3 * c + 1] > 1.0f));
    }
    expect_near(area, 3.0, 1e-6);
    scene_free(&s);
}

Test(scene_obj, relative_indices)
{
    Scene s;
    st_load_ok("tests/scenes/obj/relative.obj", &s);
    cr_assert_eq(s.ntris, 3);
    static const float first[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    cr_expect_eq(memcmp(s.pos, first, sizeof first), 0);
    cr_expect_eq(s.pos[9 * 1 + 2], 1.0f); /* the quad's corners are vertices 4..7, at z = 1 */
    scene_free(&s);
}

/* box.obj: quads, an emitter quad, a glass octahedron; every material rule at once. */
Test(scene_obj, shipped_box)
{
    Scene s;
    st_load_ok("tests/scenes/obj/box.ini", &s);
    cr_expect_eq(s.ntris, 2 * 5 + 2 + 8);
    cr_expect_eq(s.nemissive, 2);
    cr_expect_eq(mat_named(&s, "glass")->kind, SCENE_MAT_DIELECTRIC);
    cr_expect_eq(mat_named(&s, "green")->kind, SCENE_MAT_GLOSSY);
    cr_expect_eq(mat_named(&s, "red")->kind, SCENE_MAT_LAMBERT);
    cr_expect_str_eq(st_needs_of(&s), "lambert,glossy,dielectric,area_lights");
    scene_free(&s);
}

/* Vertex normals are normalized; a corner without one gets the geometric normal. */
Test(scene_obj, normals)
{
    Scene s;
    st_load_ok(st_put_file("n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn 1 0 1\nf 1//1 2//2 3\n"), &s);
    cr_assert_not_null(s.nrm);
    expect_near(s.nrm[2], 1.0f, EPS);
    expect_near(s.nrm[3], (float)M_SQRT1_2, EPS);
    expect_near(s.nrm[5], (float)M_SQRT1_2, EPS);
    expect_near(s.nrm[8], 1.0f, EPS); /* geometric: (1,0,0) x (0,1,0) = +z */
    scene_free(&s);
}

/* map_Kd: decoded as glTF base-colour textures are (sRGB colour, linear alpha); OBJ's v grows from
 * the image's bottom row, so the loader stores 1 - v. */
Test(scene_obj, texture)
{
    static const unsigned char png[] = { /* 1 x 1 RGB (255, 0, 0) */
        0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52, 0x00, 0x00,
        0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00, 0x00, 0x90, 0x77, 0x53, 0xde, 0x00, 0x00, 0x00,
        0x0c, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0x00, 0x00, 0x03, 0x01, 0x01, 0x00, 0xc9,
        0xfe, 0x92, 0xef, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
    char path[4096];
    snprintf(path, sizeof path, "%s/t.png", st_dir());
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f);
    fwrite(png, 1, sizeof png, f);
    fclose(f);
    st_put_file("t.mtl", "newmtl tex\nKd 1 1 1\nmap_Kd t.png\n");
    Scene s;
    st_load_ok(st_put_file("t.obj", "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0.25\nvt 0 1\n"
                                    "usemtl tex\nf 1/1 2/2 3/3\n"),
               &s);
    cr_assert_eq(s.ntextures, 1);
    cr_expect(s.textures[0].width == 1 && s.textures[0].height == 1);
    cr_expect_eq(s.textures[0].rgba[0], 1.0f); /* (255, 0, 0): sRGB 1 is linear 1 */
    cr_expect_eq(s.textures[0].rgba[1], 0.0f);
    cr_expect_eq(s.materials[0].base_texture, 0);
    cr_assert_not_null(s.uv);
    cr_expect(s.uv[1] == 1.0f && s.uv[2] == 1.0f && s.uv[3] == 0.75f && s.uv[5] == 0.0f);
    cr_expect_str_eq(st_needs_of(&s), "lambert,textures");
    scene_free(&s);
}

/* [gltf.NAME] places an OBJ as it places a glTF: translate, and a mirroring scale keeps the front
 * face (the winding is reversed). */
Test(scene_obj, placed_by_scene_ini)
{
    st_put_file("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    Scene s;
    st_load_ok(st_put_file("s.ini", "[gltf.a]\nfile = t.obj\ntranslate = 10 0 0\nscale = -1 1 1\n"
                                    "[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n"),
               &s);
    cr_assert_eq(s.ntris, 1);
    static const float want[9] = {10, 0, 0, 10, 1, 0, 9, 0, 0};
    cr_expect_eq(memcmp(s.pos, want, sizeof want), 0, "got (%g %g %g) (%g %g %g) (%g %g %g)", s.pos[0], s.pos[1],
                 s.pos[2], s.pos[3], s.pos[4], s.pos[5], s.pos[6], s.pos[7], s.pos[8]);
    scene_free(&s);
}

/* ---- refused inputs: the file, the line, what is wrong --------------------------------------- */

Test(scene_obj, missing_mtl_file)
{
    st_load_fails("tests/scenes/obj/bad_missing_mtl.obj", 4, "tests/scenes/obj/bad_missing_mtl.obj:2:",
                  "mtllib 'nothere.mtl'", "cannot open: No such file", "materials are required");
}

Test(scene_obj, missing_texture)
{
    st_load_fails("tests/scenes/obj/bad_missing_texture.obj", 3, "bad_missing_texture.mtl: material 'textured'",
                  "map_Kd 'nothere.png'", "cannot open: No such file");
}

Test(scene_obj, face_without_vertices)
{
    st_load_fails("tests/scenes/obj/bad_empty_face.obj", 2, "tests/scenes/obj/bad_empty_face.obj:5:",
                  "face with 0 vertices");
    st_load_fails(st_put_file("two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), 2, "two.obj:3:", "face with 2 vertices");
}

Test(scene_obj, face_of_1000_vertices)
{
    st_load_fails("tests/scenes/obj/bad_1000_face.obj", 3, "tests/scenes/obj/bad_1000_face.obj:1002:",
                  "face with 1000 vertices", "255");
}

/* 255 vertices, the most a face may have: a regular polygon of 253 triangles and the circle's area. */
Test(scene_obj, face_of_255_vertices)
{
    char *obj = malloc(64 * 256 + 8 * 256);
    cr_assert_not_null(obj);
    size_t n = 0;
    for (int i = 0; i < 255; i++)
        n += (size_t)sprintf(obj + n, "v %.9f %.9f 0\n", cos(2 * M_PI * i / 255), sin(2 * M_PI * i / 255));
    n += (size_t)sprintf(obj + n, "f");
    for (int i = 0; i < 255; i++)
        n += (size_t)sprintf(obj + n, " %d", i + 1);
    sprintf(obj + n, "\n");
    Scene s;
    st_load_ok(st_put_file("c.obj", obj), &s);
    free(obj);
    cr_assert_eq(s.ntris, 253);
    double area = 0.0;
    for (uint32_t t = 0; t < s.ntris; t++)
        area += tri_area(&s.pos[9 * t]);
    expect_near(area, 0.5 * 255 * sin(2 * M_PI / 255), 1e-4);
    scene_free(&s);
}

Test(scene_obj, index_out_of_range)
{
    st_load_fails("tests/scenes/obj/bad_index_out_of_range.obj", 3, "tests/scenes/obj/bad_index_out_of_range.obj:5:",
                  "vertex index 4 out of range", "has 3");
    st_load_fails(st_put_file("z.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"), 2, "z.obj:4:", "index 0");
    st_load_fails(st_put_file("r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 -2 -1\n"), 3, "r.obj:4:", "relative vertex",
                  "reaches before the first one (3 so far)");
    st_load_fails(st_put_file("t.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/2 2/1 3/1\n"), 2, "t.obj:5:",
                  "texture coordinate index 2 out of range");
    st_load_fails(st_put_file("w.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n"), 2, "w.obj:4:", "face vertex 'x'");
}

Test(scene_obj, no_faces)
{
    st_load_fails("tests/scenes/obj/bad_no_faces.obj", 2, "tests/scenes/obj/bad_no_faces.obj: no faces",
                  "lines and points are not surfaces");
    st_load_fails(st_put_file("empty.obj", ""), 2, "empty.obj: no faces", "nothing to ray trace");
}

Test(scene_obj, not_a_regular_file)
{
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/folder.obj", st_dir());
    cr_assert_eq(mkdir(dir, 0700), 0);
    st_load_fails(dir, 2, "folder.obj", "not a regular file");
    Scene s;
    char err[1024];
    scene_init(&s, "/dev/zero");
    cr_expect_neq(obj_append("/dev/zero", NULL, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "/dev/zero: not a regular file"), "%s", err);
    scene_free(&s);
    /* an MTL that is a folder (inside the OBJ's), or a device (outside it: refused first) */
    st_load_fails(st_put_file("d.obj", "mtllib folder.obj\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), 3, "d.obj:1:",
                  "mtllib 'folder.obj'", "not a regular file");
    st_load_fails(st_put_file("z.obj", "mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), 2, "z.obj:1:",
                  "leads outside the folder of the OBJ file");
}

Test(scene_obj, coordinates_refused)
{
    st_load_fails(st_put_file("i.obj", "v 0 0 0\nv 1 inf 0\nv 0 1 0\nf 1 2 3\n"), 2, "i.obj:2:",
                  "coordinate 1 is not finite (inf)");
    st_load_fails(st_put_file("n.obj", "v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), 2, "n.obj:1:",
                  "coordinate 2 is not finite");
    st_load_fails(st_put_file("b.obj", "v 0 0 0\nv 1 1e30 0\nv 0 1 0\nf 1 2 3\n"), 2, "b.obj:2:",
                  "is 1e+30, beyond the limit of 1e+18 on scene coordinates");
    st_load_fails(st_put_file("h.obj", "v 0 0 0\nv 1 1e39 0\nv 0 1 0\nf 1 2 3\n"), 2, "h.obj:2:",
                  "beyond the limit of 1e+18");
    st_load_fails(st_put_file("vt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 1e40\nf 1/1 2/1 3/1\n"), 2, "vt.obj:4:",
                  "not finite");
    /* put there by the placement */
    st_put_file("p.obj", "v 0 0 0\nv 1 1e17 0\nv 0 1 0\nf 1 2 3\n");
    st_load_fails(st_put_file("p.ini", "[gltf.a]\nfile = p.obj\nscale = 100\n[camera]\nposition = 0 0 5\n"
                                       "look_at = 0 0 0\n"),
                  2, "p.ini:2: key 'gltf.a.file':", "p.obj: vertex 2 is (100, 1e+19, 0) after the placement, beyond the limit");
}

/* From memory (what a fuzzer feeds): the MTL text given beside the OBJ. */
Test(scene_obj, from_memory)
{
    const char obj[] = "mtllib any.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl g\nf 1 2 3\n";
    const char mtl[] = "newmtl g\nillum 4\nNi 1.33\n";
    Scene s;
    char err[1024];
    scene_init(&s, "mem.obj");
    cr_assert_eq(obj_append_memory(obj, sizeof obj - 1, mtl, sizeof mtl - 1, "mem.obj", NULL, &s, err, sizeof err), 0,
                 "%s", err);
    cr_expect_eq(s.ntris, 1);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_DIELECTRIC);
    expect_near(s.materials[0].ior, 1.33f, EPS);
    scene_free(&s);
    scene_init(&s, "mem.obj");
    cr_expect_neq(obj_append_memory(obj, sizeof obj - 1, NULL, 0, "mem.obj", NULL, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "mem.obj:1: mtllib 'any.mtl': no MTL text given"), "%s", err);
    scene_free(&s);
}

/* ---- scene_file_check: what sfsim sweep asks before any point runs ----------------------------- */

Test(scene_obj, check_missing_mesh_says_where_to_get_it)
{
    char err[4096];
    cr_expect_eq(scene_file_check("tests/scenes/obj/cross-obj.ini", err, sizeof err), 0, "%s", err);
    cr_expect_eq(scene_file_check("tests/scenes/obj/cornell.obj", err, sizeof err), 0, "%s", err);
    cr_expect_neq(scene_file_check("tests/scenes/obj/missing-mesh.ini", err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "tests/scenes/obj/missing-mesh.ini:4: key 'scene.gltf': "), "%s", err);
    cr_expect_not_null(strstr(err, "not-downloaded/conference.obj: cannot open: No such file"), "%s", err);
    cr_expect_not_null(strstr(err, "where to get the scene: McGuire Computer Graphics Archive, "
                                   "https://casual-effects.com/data/"),
                       "%s", err);
    cr_expect_neq(scene_file_check("tests/scenes/obj/nothere.ini", err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "nothere.ini: cannot open"), "%s", err);
    cr_expect_neq(scene_file_check("tests/scenes/obj", err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "tests/scenes/obj: not a regular file"), "%s", err);
    /* a mesh that is a folder */
    st_put_file("f.ini", "[scene]\ngltf = .\n");
    char ini[4096];
    snprintf(ini, sizeof ini, "%s/f.ini", st_dir());
    cr_expect_neq(scene_file_check(ini, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "f.ini:2: key 'scene.gltf': "), "%s", err);
    cr_expect_not_null(strstr(err, "not a regular file"), "%s", err);
}

/* Loading says the same (sfsim run -s). */
Test(scene_obj, load_missing_mesh_says_where_to_get_it)
{
    st_load_fails("tests/scenes/obj/missing-mesh.ini", 3, "missing-mesh.ini:4: key 'scene.gltf': ",
                  "cannot open: No such file", "where to get the scene: McGuire Computer Graphics Archive");
}
