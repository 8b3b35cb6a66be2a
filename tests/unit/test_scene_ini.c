/* tests/unit/test_scene_ini.c -- scene.ini: every section, defaults, several glTF files placed,
 * material overrides; and malformed files, with file, line and key in every message and every
 * error reported.
 *
 * The glTF files the ini files name are written by the tests themselves
 * (tests/support/scene_fixture.h) into a temporary folder. */
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

/* ---- scene.ini ------------------------------------------------------------------------------ */

TestSuite(scene_ini, .init = st_tmp_setup, .fini = st_tmp_teardown);

Test(scene_ini, every_section)
{
    Gl g = st_tri();
    g.material = "{\"name\": \"paint\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}}";
    st_put_gltf("a.gltf", st_gl_json(&g));
    const char *ini = st_put_file("s.ini", "; a comment\n"
                                        "[scene]\n"
                                        "gltf = a.gltf\n"
                                        "\n"
                                        "[camera]\n"
                                        "position = 0 0.5 5\n"
                                        "look_at = 0 0.5 0   ; inline comment\n"
                                        "up = 0 1 0\n"
                                        "fov_y = 40\n"
                                        "aperture = 0.1\n"
                                        "focus_distance = 4.5\n"
                                        "[render]\n"
                                        "width = 320\n"
                                        "height = 200\n"
                                        "spp = 8\n"
                                        "max_depth = 5\n"
                                        "background = 0.1 0.2 0.3\n"
                                        "ambient = 0.5 0.5 0.5\n"
                                        "[material.glass]\n"
                                        "kind = dielectric\n"
                                        "ior = 1.4\n"
                                        "base_color = 0.9 1 0.9\n"
                                        "[material.paint]\n"
                                        "roughness = 0.25\n"
                                        "[sphere.ball]\n"
                                        "center = 1 2 3\n"
                                        "radius = 0.5\n"
                                        "material = glass\n"
                                        "[sphere.red]\n"
                                        "  center = 0 0 0\n"
                                        "  radius = 1\n"
                                        "  material = paint\n"
                                        "[light.p]\n"
                                        "type = point\n"
                                        "position = 0 4 0\n"
                                        "color = 1 0.9 0.8\n"
                                        "intensity = 50\n"
                                        "[light.s]\n"
                                        "type = spot\n"
                                        "position = 0 4 0\n"
                                        "direction = 0 -2 0\n"
                                        "inner_cone = 10\n"
                                        "outer_cone = 30\n"
                                        "[light.d]\n"
                                        "type = directional\n"
                                        "direction = 1 -1 0\n"
                                        "[light.q]\n"
                                        "type = quad\n"
                                        "position = -1 3 -1\n"
                                        "edge_u = 2 0 0\n"
                                        "edge_v = 0 0 2\n"
                                        "intensity = 5\n");
    Scene s;
    st_load_ok(ini, &s);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_FILE);
    expect_near(s.camera.position[2], 5.0f, EPS);
    expect_near(s.camera.look_at[1], 0.5f, EPS);
    expect_near(s.camera.fov_y, 40.0f, EPS);
    expect_near(s.camera.aperture, 0.1f, EPS);
    expect_near(s.camera.focus_distance, 4.5f, EPS);
    cr_expect_eq(s.render.width, 320);
    cr_expect_eq(s.render.height, 200);
    cr_expect_eq(s.render.spp, 8);
    cr_expect_eq(s.render.max_depth, 5);
    expect_near(s.render.background[2], 0.3f, EPS);
    expect_near(s.render.ambient[0], 0.5f, EPS);
    cr_assert_eq(s.nmaterials, 2, "paint from the glTF (overridden), glass new");
    cr_expect_str_eq(s.materials[0].name, "paint");
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY, "roughness 0.25 makes paint glossy");
    expect_near(s.materials[0].roughness, 0.25f, EPS);
    cr_expect_str_eq(s.materials[1].name, "glass");
    cr_expect_eq(s.materials[1].kind, SCENE_MAT_DIELECTRIC);
    expect_near(s.materials[1].ior, 1.4f, EPS);
    expect_near(s.materials[1].transmission, 1.0f, EPS);
    cr_assert_eq(s.nspheres, 2);
    cr_expect_str_eq(s.spheres[0].name, "ball");
    cr_expect_eq(s.spheres[0].material, 1);
    expect_near(s.spheres[0].center[2], 3.0f, EPS);
    expect_near(s.spheres[0].radius, 0.5f, EPS);
    cr_expect_eq(s.spheres[1].material, 0, "indented keys are keys, not continuation lines");
    cr_assert_eq(s.nlights, 4);
    cr_expect_eq(s.lights[0].kind, SCENE_LIGHT_POINT);
    expect_near(s.lights[0].intensity, 50.0f, EPS);
    expect_near(s.lights[0].color[2], 0.8f, EPS);
    cr_expect_eq(s.lights[1].kind, SCENE_LIGHT_SPOT);
    expect_near(s.lights[1].direction[1], -1.0f, EPS);
    expect_near(s.lights[1].inner_cone, 10.0f * (float)M_PI / 180.0f, EPS);
    expect_near(s.lights[1].outer_cone, 30.0f * (float)M_PI / 180.0f, EPS);
    cr_expect_eq(s.lights[2].kind, SCENE_LIGHT_DIRECTIONAL);
    expect_near(s.lights[2].direction[0], 0.70710678f, 1e-5f);
    cr_expect_eq(s.lights[3].kind, SCENE_LIGHT_QUAD);
    expect_near(s.lights[3].edge_u[0], 2.0f, EPS);
    expect_near(s.lights[3].edge_v[2], 2.0f, EPS);
    cr_expect_str_eq(st_needs_of(&s), "glossy,dielectric,spheres,area_lights,punctual_lights,background,ambient");
    /* the bounds take in the spheres */
    expect_near(s.bounds_max[2], 3.5f, EPS);
    expect_near(s.bounds_min[0], -1.0f, EPS);
    scene_free(&s);
}

Test(scene_ini, defaults)
{
    Gl g = st_tri();
    st_put_gltf("a.gltf", st_gl_json(&g));
    Scene s;
    st_load_ok(st_put_file("s.ini", "[scene]\ngltf = a.gltf\n"), &s);
    cr_expect_eq(s.render.width, 512);
    cr_expect_eq(s.render.height, 512);
    cr_expect_eq(s.render.spp, 1);
    cr_expect_eq(s.render.max_depth, 3);
    expect_near(s.render.background[0], 0.0f, 0.0f);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_DEFAULT);
    cr_expect_str_eq(s.source, st_last_file());
    scene_free(&s);
}

/* Several glTF files placed with transforms; material indices of the second file follow the first's. */
Test(scene_ini, several_gltf_files_placed)
{
    Gl g = st_tri();
    g.material = "{\"name\": \"one\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}}";
    st_put_gltf("a.gltf", st_gl_json(&g));
    g.material = "{\"name\": \"two\"}";
    st_put_gltf("b.gltf", st_gl_json(&g));
    const char *ini = st_put_file("s.ini", "[scene]\n"
                                        "gltf = a.gltf\n"
                                        "[gltf.b]\n"
                                        "file = b.gltf\n"
                                        "translate = 10 0 0\n"
                                        "scale = 2\n"
                                        "rotate_y = 90\n"
                                        "[gltf.c]\n"
                                        "file = b.gltf\n"
                                        "scale = 1 3 1\n");
    Scene s;
    st_load_ok(ini, &s);
    cr_assert_eq(s.ntris, 3);
    cr_assert_eq(s.nmaterials, 3);
    cr_expect_eq(s.tri_material[0], 0);
    cr_expect_eq(s.tri_material[1], 1);
    cr_expect_eq(s.tri_material[2], 2);
    cr_expect_str_eq(s.materials[1].name, "two");
    /* (1,0,0) -> scale 2 -> rotate_y 90 -> (0,0,-2) -> translate (10,0,-2) */
    expect_near(s.pos[9 + 3], 10.0f, 1e-5f);
    expect_near(s.pos[9 + 5], -2.0f, 1e-5f);
    /* (0,1,0) scaled by (1,3,1) */
    expect_near(s.pos[18 + 7], 3.0f, 1e-5f);
    scene_free(&s);
}

/* No glTF at all: spheres and lights alone are a scene. */
Test(scene_ini, spheres_only)
{
    const char *ini = st_put_file("s.ini", "[material.white]\n"
                                        "base_color = 0.8 0.8 0.8\n"
                                        "[sphere.a]\n"
                                        "center = 0 0 0\n"
                                        "radius = 1\n"
                                        "material = white\n"
                                        "[light.sun]\n"
                                        "type = directional\n"
                                        "direction = 0 -1 0\n");
    Scene s;
    st_load_ok(ini, &s);
    cr_expect_eq(s.ntris, 0);
    cr_expect_eq(s.nspheres, 1);
    cr_expect_str_eq(st_needs_of(&s), "lambert,spheres,punctual_lights");
    expect_near(s.camera.look_at[1], 0.0f, EPS);
    scene_free(&s);
}

Test(scene_ini, glossy_override_of_a_gltf_material_keeps_the_rest)
{
    Gl g = st_tri();
    g.material = "{\"name\": \"floor\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.7, 0.6, 0.5, 1],"
                 " \"metallicFactor\": 0}}";
    st_put_gltf("a.gltf", st_gl_json(&g));
    Scene s;
    st_load_ok(
        st_put_file("s.ini", "[scene]\ngltf = a.gltf\n[material.floor]\nkind = glossy\nroughness = 0.2\nmetallic = 0.3\n"),
        &s);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    expect_near(s.materials[0].metallic, 0.3f, EPS);
    expect_near(s.materials[0].base_color[0], 0.7f, EPS);
    scene_free(&s);
}

/* ---- malformed scene.ini: file, line and key in every message; every error reported ---------- */

TestSuite(scene_ini_errors, .init = st_tmp_setup, .fini = st_tmp_teardown);

static void ini_fails(const char *text, int nsub, ...)
{
    Gl g = st_tri();
    st_put_gltf("a.gltf", st_gl_json(&g));
    const char *path = st_put_file("bad.ini", text);
    Scene s;
    char err[4096];
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0, "loaded:\n%s", text);
    va_list ap;
    va_start(ap, nsub);
    for (int i = 0; i < nsub; i++) {
        const char *sub = va_arg(ap, const char *);
        char want[512];
        snprintf(want, sizeof want, "%s%s", sub[0] == ':' ? path : "", sub);
        cr_expect_not_null(strstr(err, want), "message lacks '%s':\n%s", want, err);
    }
    va_end(ap);
}

/* The example of the brief, exactly. */
Test(scene_ini_errors, bad_number)
{
    Gl g = st_tri();
    st_put_gltf("a.gltf", st_gl_json(&g));
    const char *path = st_put_file("scene.ini", "[scene]\ngltf = a.gltf\n[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n"
                                             "up = 0 1 0\nfov_y = wide\n");
    Scene s;
    char err[1024], want[512];
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want, "%s:7: key 'camera.fov_y': expected a number, got 'wide'", path);
    cr_expect_str_eq(err, want);
}

Test(scene_ini_errors, values)
{
    ini_fails("[scene]\n"
              "gltf = a.gltf\n"
              "[camera]\n"
              "position = 0 0\n"
              "look_at = 0 0 0\n"
              "fov_y = 180\n"
              "[render]\n"
              "width = 0\n"
              "spp = 2.5\n"
              "background = 1 -1 1\n"
              "max_depth = many\n",
              6, ":4: key 'camera.position': expected 3 numbers, got '0 0'",
              ":6: key 'camera.fov_y': expected an angle between 0 and 180 degrees",
              ":8: key 'render.width': expected an integer from 1 to 16384, got '0'",
              ":9: key 'render.spp': expected an integer, got '2.5'",
              ":10: key 'render.background': expected 3 numbers, none negative, got '1 -1 1'",
              ":11: key 'render.max_depth': expected an integer, got 'many'");
}

Test(scene_ini_errors, unknown_keys_and_sections)
{
    ini_fails("[scene]\n"
              "gltf = a.gltf\n"
              "file = b.gltf\n"
              "[camra]\n"
              "position = 0 0 1\n"
              "[render]\n"
              "samples = 4\n"
              "[light]\n"
              "type = point\n",
              4, ":3: key 'scene.file': unknown key (scene takes: gltf source)", ":4: unknown section [camra]",
              ":7: key 'render.samples': unknown key", ":8: unknown section [light]");
}

Test(scene_ini_errors, syntax_and_duplicates)
{
    ini_fails("x = 1\n"
              "[scene]\n"
              "gltf = a.gltf\n"
              "just words\n"
              "[render\n"
              "[render]\n"
              "spp = 4\n"
              "spp = 8\n"
              "[render]\n",
              5, ":1: key 'x': outside any section", ":4: syntax error: expected 'key = value'",
              ":5: syntax error: a section header", ":8: key 'render.spp': given twice (first at line 7)",
              ":9: section [render] appears twice (first at line 6)");
}

Test(scene_ini_errors, lights_spheres_materials)
{
    ini_fails("[scene]\n"
              "gltf = a.gltf\n"
              "[light.a]\n"
              "type = spot\n"
              "position = 0 1 0\n"
              "edge_u = 1 0 0\n"
              "[light.b]\n"
              "type = laser\n"
              "[light.c]\n"
              "type = quad\n"
              "position = 0 0 0\n"
              "edge_u = 1 0 0\n"
              "edge_v = 2 0 0\n"
              "[sphere.s]\n"
              "radius = -1\n"
              "material = nope\n"
              "[material.m]\n"
              "kind = metal\n"
              "roughness = 2\n"
              "[light.d]\n"
              "position = 1 1 1\n",
              9, ":3: section [light.a]: key 'direction' is required for a spot light",
              ":6: key 'light.a.edge_u': does not apply to a spot light",
              ":8: key 'light.b.type': expected point, spot, directional or quad, got 'laser'",
              ":9: section [light.c]: edge_u and edge_v must span a non-zero area",
              ":14: section [sphere.s]: key 'center' is required",
              ":15: key 'sphere.s.radius': expected a positive number",
              ":16: key 'sphere.s.material': no [material.nope] section and no glTF material called 'nope'",
              ":18: key 'material.m.kind': expected lambert, glossy or dielectric, got 'metal'",
              ":20: section [light.d]: key 'type' is required");
}

Test(scene_ini_errors, camera_needs_position_and_look_at)
{
    ini_fails("[scene]\ngltf = a.gltf\n[camera]\nfov_y = 30\n", 2, ":3: section [camera]: key 'position' is required",
              ":3: section [camera]: key 'look_at' is required");
    ini_fails("[scene]\ngltf = a.gltf\n[camera]\nposition = 0 0 0\nlook_at = 0 5 0\n", 1,
              ":3: section [camera]: up must not be zero or parallel to the view direction");
}

/* The missing glTF file is named with the ini line that refers to it. */
Test(scene_ini_errors, missing_gltf_file)
{
    ini_fails("[scene]\ngltf = a.gltf\n[gltf.more]\nfile = nothere.glb\ntranslate = 1 2 3\n", 2,
              ":4: key 'gltf.more.file': ", "nothere.glb: cannot open: No such file or directory");
}

/* A broken glTF named by an ini: both locations in the message. */
Test(scene_ini_errors, broken_gltf_inside)
{
    Gl g = st_tri();
    g.prim = "\"mode\": 9";
    st_put_gltf("nine.gltf", st_gl_json(&g));
    ini_fails("[scene]\ngltf = nine.gltf\n", 2, ":2: key 'scene.gltf': ",
              "nine.gltf: mesh 0 'tri' primitive 0: mode 9 is not a glTF primitive mode");
}

/* A directory is not a scene file (tinygltf would size it as 2^63 bytes; found by fuzzing). */
Test(scene_ini_errors, directory_as_file)
{
    ini_fails("[scene]\ngltf = .\n", 2, ":2: key 'scene.gltf': ", "not a regular file");
    ini_fails("[scene]\ngltf =\n", 1, ":2: key 'scene.gltf': expected the path of a .gltf, .glb or .obj file, got ''");
    const char *names[2] = {"dir.gltf", "dir.ini"};
    for (int i = 0; i < 2; i++) {
        char path[128];
        snprintf(path, sizeof path, "%s/%s", st_dir(), names[i]);
        cr_assert_eq(mkdir(path, 0700), 0);
        st_load_fails(path, 2, names[i], "not a regular file");
        rmdir(path);
    }
    /* a buffer whose uri names a directory */
    Gl g = st_tri();
    char *j = st_gl_json(&g);
    char *uri = strstr(j, "data:application");
    char *end = strchr(uri, '"');
    memmove(uri, ".", 1);
    memmove(uri + 1, end, strlen(end) + 1);
    st_load_fails(st_put_gltf("dirbuf.gltf", j), 1, "dirbuf.gltf: ");
}

Test(scene_ini_errors, no_geometry)
{
    ini_fails("[light.a]\ntype = point\nposition = 0 0 0\n", 1, ": the scene has no geometry");
}

Test(scene_ini_errors, missing_ini)
{
    st_load_fails("/nonexistent/scene.ini", 2, "/nonexistent/scene.ini", "cannot open");
}

/* Many errors in a small buffer: the ones that fit, then a count of the rest. */
Test(scene_ini_errors, all_errors_reported_or_counted)
{
    char text[8192] = "[render]\n";
    for (int i = 0; i < 100; i++)
        snprintf(text + strlen(text), sizeof text - strlen(text), "bad%d = 1\n", i);
    const char *path = st_put_file("many.ini", text);
    Scene s;
    char err[512];
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "key 'render.bad0': unknown key"), "%s", err);
    cr_expect_not_null(strstr(err, "more errors"), "%s", err);
    char big[65536];
    cr_assert_neq(scene_load(path, &s, big, sizeof big), 0);
    cr_expect_not_null(strstr(big, "key 'render.bad99': unknown key"), "%s", big);
}
