/* tests/unit/test_scene.c -- the scene loader on real inputs: every shared scene through its
 * scene.ini (triangle counts of ../shared/scenes/README.md, needs, cameras), the needs string,
 * and the small shipped inputs of tests/scenes/.
 *
 * The loader's other tests: the glTF mapping (materials, geometry, lights and cameras) in
 * test_scene_gltf.c, malformed glTF in test_scene_gltf_errors.c, scene.ini in test_scene_ini.c.
 * Their small glTF files are written by the tests themselves (tests/support/scene_fixture.h). */
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

/* ---- shipped scenes: every scene.ini of scenes/ (most name a glTF file in ../shared) --------- */

static void check_shipped(const char *ini, uint32_t tris, const char *needs, int camera_source)
{
    NEEDS_SCENE(ini);
    Scene s;
    st_load_ok(ini, &s);
    cr_expect_eq(s.ntris, tris, "%s: %u triangles, the README says %u", ini, s.ntris, tris);
    cr_expect_str_eq(st_needs_of(&s), needs, "%s: needs", ini);
    cr_expect_eq(s.camera.source, camera_source, "%s: camera source", ini);
    for (int k = 0; k < 3; k++)
        cr_expect(s.bounds_min[k] <= s.bounds_max[k] && isfinite(s.bounds_min[k]) && isfinite(s.bounds_max[k]));
    /* The camera looks at something inside the bounds' neighbourhood. */
    float d[3], len = 0.0f;
    for (int k = 0; k < 3; k++) {
        d[k] = s.camera.look_at[k] - s.camera.position[k];
        len += d[k] * d[k];
    }
    cr_expect_gt(len, 0.0f);
    scene_free(&s);
}

Test(scene_shipped, cornell)
{
    check_shipped("scenes/cornell/scene.ini", 32, "lambert,area_lights", SCENE_CAMERA_FILE);
}

/* The default scene is the repository's own: the published Cornell box measurements (mm). */
Test(scene_shipped, cornell_is_the_published_box)
{
    Scene s;
    st_load_ok("scenes/cornell/scene.ini", &s);
    cr_expect_eq(s.ntris, 32, "16 published quads");
    cr_expect_eq(s.nemissive, 2, "the light quad is two triangles");
    cr_expect_null(s.nrm);
    expect_near(s.bounds_min[0], 0.0f, 1e-3f);
    expect_near(s.bounds_min[1], 0.0f, 1e-3f);
    expect_near(s.bounds_min[2], 0.0f, 1e-3f);
    expect_near(s.bounds_max[0], 556.0f, 1e-3f);
    expect_near(s.bounds_max[1], 548.8f, 1e-3f);
    expect_near(s.bounds_max[2], 559.2f, 1e-3f);
    expect_near(s.camera.position[0], 278.0f, 1e-3f);
    expect_near(s.camera.position[2], -800.0f, 1e-3f);
    scene_free(&s);
}

Test(scene_shipped, cornell_mcguire)
{
    check_shipped("scenes/cornell/mcguire.ini", 36, "lambert,area_lights", SCENE_CAMERA_FILE);
}
Test(scene_shipped, cornell_spheres)
{
    check_shipped("scenes/cornell/spheres.ini", 2188, "lambert,glossy,dielectric,area_lights", SCENE_CAMERA_FILE);
}
Test(scene_shipped, cornell_glossy)
{
    check_shipped("scenes/cornell/glossy.ini", 32, "lambert,glossy,area_lights", SCENE_CAMERA_FILE);
}
Test(scene_shipped, glass_vase_flowers)
{
    check_shipped("scenes/glass-vase-flowers/scene.ini", 14036,
                  "lambert,glossy,dielectric,textures,area_lights,alpha,background", SCENE_CAMERA_FILE);
}
Test(scene_shipped, lights_punctual_lamp)
{
    check_shipped("scenes/lights-punctual-lamp/scene.ini", 6000,
                  "glossy,dielectric,textures,area_lights,punctual_lights,alpha,background,emissive_textures",
                  SCENE_CAMERA_FILE);
}
Test(scene_shipped, sponza)
{
    check_shipped("scenes/sponza-dabrovic/scene.ini", 66450, "lambert,glossy,textures,punctual_lights,background",
                  SCENE_CAMERA_FILE);
}
Test(scene_shipped, toy_car)
{
    check_shipped("scenes/toy-car/scene.ini", 108936,
                  "lambert,glossy,dielectric,textures,area_lights,background,emissive_textures", SCENE_CAMERA_FILE);
}
Test(scene_shipped, transmission_test)
{
    /* no [camera]: the file's own */
    check_shipped("scenes/transmission-test/scene.ini", 128775,
                  "glossy,dielectric,textures,area_lights,alpha,background,emissive_textures", SCENE_CAMERA_GLTF);
}
Test(scene_shipped, stanford_bunny)
{
    check_shipped("scenes/stanford-bunny/scene.ini", 144046, "lambert,area_lights,background", SCENE_CAMERA_FILE);
}
Test(scene_shipped, lamborghini, .timeout = 60)
{
    check_shipped("scenes/lamborghini/scene.ini", 145917,
                  "lambert,glossy,textures,area_lights,alpha,background,vertex_colors", SCENE_CAMERA_FILE);
}
Test(scene_shipped, lost_empire, .timeout = 60)
{
    check_shipped("scenes/lost-empire/scene.ini", 224998,
                  "lambert,textures,area_lights,punctual_lights,alpha,background", SCENE_CAMERA_FILE);
}
Test(scene_shipped, conference)
{
    check_shipped("scenes/conference/scene.ini", 331179, "glossy,area_lights", SCENE_CAMERA_FILE);
    Scene s;
    st_load_ok("scenes/conference/scene.ini", &s);
    cr_expect_eq(s.nlights, 72, "the papers' 72 lights");
    for (uint32_t i = 0; i < s.nlights; i++) {
        cr_expect_eq(s.lights[i].kind, SCENE_LIGHT_QUAD);
        /* below the ceiling, facing down: edge_u x edge_v points to -y */
        const float *u = s.lights[i].edge_u, *v = s.lights[i].edge_v;
        cr_expect_lt(u[2] * v[0] - u[0] * v[2], 0.0f);
        cr_expect_lt(s.lights[i].position[1], s.bounds_max[1]);
    }
    cr_expect_null(s.nrm, "the conference room has no normals");
    scene_free(&s);
}
Test(scene_shipped, metal_rough_spheres, .timeout = 60)
{
    check_shipped("scenes/metal-rough-spheres/scene.ini", 1040409, "lambert,glossy,area_lights,background",
                  SCENE_CAMERA_FILE);
}

/* A .glb given directly: the default camera frames the bounds. */
Test(scene_shipped, cornell_glb_default_camera)
{
    NEEDS_SHARED("../shared/scenes/cornell-box/CornellBox-Original.glb");
    Scene s;
    st_load_ok("../shared/scenes/cornell-box/CornellBox-Original.glb", &s);
    cr_expect_eq(s.ntris, 36);
    cr_expect_str_eq(st_needs_of(&s), "lambert,area_lights");
    cr_expect_eq(s.nemissive, 2, "the ceiling light is two triangles");
    cr_expect_eq(s.camera.source, SCENE_CAMERA_DEFAULT);
    cr_expect_null(s.nrm);
    cr_expect_null(s.uv);
    /* the README: about 2 units wide centred near x = 0, y from 0 to 2 */
    expect_near(s.bounds_min[1], 0.0f, 1e-4f);
    expect_near(s.bounds_max[1], 1.99f, 1e-4f);
    scene_free(&s);
}

/* The same bytes through the memory entry point (the fuzzer's). */
Test(scene_shipped, glb_from_memory)
{
    NEEDS_SHARED("../shared/scenes/cornell-box/CornellBox-Sphere.glb");
    FILE *f = fopen("../shared/scenes/cornell-box/CornellBox-Sphere.glb", "rb");
    cr_assert_not_null(f);
    unsigned char *data = malloc(1 << 20);
    size_t n = fread(data, 1, 1 << 20, f);
    fclose(f);
    Scene s;
    char err[1024];
    scene_init(&s, "mem.glb");
    cr_assert_eq(gltf_append_memory(data, n, "mem.glb", NULL, &s, err, sizeof err), 0, "%s", err);
    cr_assert_eq(scene_finish(&s, err, sizeof err), 0, "%s", err);
    cr_expect_eq(s.ntris, 2188);
    cr_expect_str_eq(st_needs_of(&s), "lambert,glossy,dielectric,area_lights");
    scene_free(&s);
    /* a truncated copy fails cleanly */
    scene_init(&s, "mem.glb");
    cr_expect_neq(gltf_append_memory(data, n / 2, "cut.glb", NULL, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "cut.glb: "), "%s", err);
    scene_free(&s);
    free(data);
}

/* ---- needs string ---------------------------------------------------------------------------- */

Test(scene_needs, string)
{
    char buf[256];
    scene_needs_string(0, buf, sizeof buf);
    cr_expect_str_eq(buf, "");
    scene_needs_string(SCENE_NEED_LAMBERT | SCENE_NEED_AREA_LIGHTS, buf, sizeof buf);
    cr_expect_str_eq(buf, "lambert,area_lights");
    scene_needs_string(0x3FF, buf, sizeof buf);
    cr_expect_str_eq(buf,
                     "lambert,glossy,dielectric,textures,spheres,area_lights,punctual_lights,alpha,background,ambient");
    scene_needs_string(SCENE_NEED_EMISSIVE_TEXTURES | SCENE_NEED_VERTEX_COLORS, buf, sizeof buf);
    cr_expect_str_eq(buf, "emissive_textures,vertex_colors");
    scene_needs_string(0x3FF, buf, 10); /* truncates, terminated */
    cr_expect_eq(strlen(buf), 9);
}

/* ---- tests/scenes: the small shipped inputs (also the fuzzer's seeds) ---------------------- */

/* ok_* files load; bad_* files fail with a message that starts with their path. */
Test(scene_files, ok_and_bad)
{
    DIR *d = opendir("tests/scenes");
    cr_assert_not_null(d, "run from the repository root");
    struct dirent *e;
    int nok = 0, nbad = 0;
    while ((e = readdir(d)) != NULL) {
        char path[512], err[4096];
        snprintf(path, sizeof path, "tests/scenes/%s", e->d_name);
        Scene s;
        if (!strncmp(e->d_name, "ok_", 3)) {
            int rc = scene_load(path, &s, err, sizeof err);
            cr_expect_eq(rc, 0, "%s: %s", path, err);
            if (rc == 0)
                scene_free(&s);
            nok++;
        } else if (!strncmp(e->d_name, "bad_", 4)) {
            cr_expect_neq(scene_load(path, &s, err, sizeof err), 0, "%s loaded", path);
            cr_expect_eq(strncmp(err, path, strlen(path)), 0, "%s: message does not name the file: %s", path, err);
            nbad++;
        }
    }
    closedir(d);
    cr_expect_geq(nok, 4);
    cr_expect_geq(nbad, 10);
}

/* A GLB whose image bufferView runs past its buffer: tinygltf 2.7 does not check it; we must. */
Test(scene_files, image_view_outside_buffer)
{
    st_load_fails("tests/scenes/bad_image_view.glb", 2, "tests/scenes/bad_image_view.glb: image 0",
               "bufferView 2 lies outside buffer 0");
}

Test(scene_files, everything)
{
    Scene s;
    st_load_ok("tests/scenes/ok_everything.gltf", &s);
    cr_expect_eq(s.ntris, 6);
    cr_expect_eq(s.nlights, 3);
    cr_expect_eq(s.ntextures, 2);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_GLTF);
    cr_expect_eq(s.nemissive, 1, "one of the two lamp triangles sees lit texels");
    cr_expect_str_eq(st_needs_of(&s), "lambert,glossy,dielectric,textures,area_lights,punctual_lights,alpha,"
                                   "emissive_textures");
    scene_free(&s);
}
