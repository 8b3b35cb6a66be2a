/* tests/unit/test_scene_limits.c -- the limits of scene values (scenes/scene.h's SCENE_LIMITS,
 * docs/scenes.md "Limits of scene values"): every value that enters the renderers' binary32
 * arithmetic is checked where it is read and refused by name (file and glTF element, or
 * scene.ini line and key) beyond its limit, or warned about where refusal would be wrong; a node
 * matrix that is not affine and a GLB of header version other than 2 are refused.
 *
 * Each case also loads the value just inside the limit, so a check that refused everything
 * would fail here too. The inputs are written by the tests (tests/support/scene_fixture.h). */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/gltf.h"
#include "../../scenes/scene.h"
#include "../support/scene_fixture.h"

TestSuite(scene_limits, .init = st_tmp_setup, .fini = st_tmp_teardown);

/* ---- the table and its check ---------------------------------------------------------------- */

Test(scene_limits, table_and_check)
{
    cr_expect_eq(scene_limit(SCENE_LIMIT_COORD), 1e18);
    cr_expect_eq(scene_limit(SCENE_LIMIT_AREA), 1e18);
    cr_expect_eq(scene_limit(SCENE_LIMIT_INTENSITY), scene_limit(SCENE_LIMIT_RADIANCE) * scene_limit(SCENE_LIMIT_AREA));
    /* every product the limits promise stays finite in binary32 */
    float c = (float)scene_limit(SCENE_LIMIT_COORD), a = (float)scene_limit(SCENE_LIMIT_AREA);
    float d = 2.0f * c;
    cr_expect(isfinite(3.0f * d * d), "a squared distance between two points at the coordinate limit");
    cr_expect(isfinite(3.0f * a * a), "a squared |e1 x e2| at the area limit");
    cr_expect(isfinite((float)scene_limit(SCENE_LIMIT_INTENSITY) * 1.0f), "an intensity at its limit");
    cr_expect(isfinite((float)scene_limit(SCENE_LIMIT_RADIANCE) * powf(2.0f / 0.95f, 63.0f)),
              "the deepest Lambertian path's throughput times the radiance limit");

    char why[400];
    double ok[3] = {1e18, -1e18, 0}, far[3] = {0, 0, 1e30}, nan3[3] = {0, NAN, 0};
    cr_expect_eq(scene_limit_check(SCENE_LIMIT_COORD, ok, 3, why, sizeof why), 0);
    cr_expect_eq(scene_limit_check(SCENE_LIMIT_COORD, far, 3, why, sizeof why), -1);
    cr_expect_str_eq(why, "is (0, 0, 1e+30), beyond the limit of 1e+18 on scene coordinates (docs/scenes.md, Limits "
                          "of scene values)");
    cr_expect_eq(scene_limit_check(SCENE_LIMIT_COORD, nan3, 3, why, sizeof why), -1);
    cr_expect_str_eq(why, "is not finite (0, nan, 0)");
    cr_expect_eq(scene_limit_check1(SCENE_LIMIT_IOR, INFINITY, why, sizeof why), -1);
    cr_expect_str_eq(why, "is not finite (inf)");
    cr_expect_eq(scene_limit_check1(SCENE_LIMIT_IOR, 1.5, why, sizeof why), 0);
    /* a non-finite value is named as such even after one beyond the limit */
    double both[2] = {1e30, INFINITY};
    cr_expect_eq(scene_limit_check(SCENE_LIMIT_UV, both, 2, why, sizeof why), -1);
    cr_expect_str_eq(why, "is not finite (1e+30, inf)");
}

Test(scene_limits, camera_check)
{
    SceneCamera c = {{0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 45.0f, 0.0f, 0.0f, SCENE_CAMERA_FILE};
    char why[400];
    cr_expect_eq(scene_camera_check(&c, why, sizeof why), 0, "%s", why);
    cr_expect_eq(scene_camera_view_check(&c, 512, 512, why, sizeof why), 0, "%s", why);
    /* ray length d sqrt(1 + t^2 (1 + aspect^2)): 1e18 x 1.08 is inside; at 16384 x 1 it is
     * 1e18 x 6786 */
    c.focus_distance = 1e18f;
    cr_expect_eq(scene_camera_view_check(&c, 512, 512, why, sizeof why), 0, "%s", why);
    cr_expect_eq(scene_camera_view_check(&c, 16384, 1, why, sizeof why), -1);
    cr_expect(strstr(why, "ray length (focus distance 1e+18, fov_y 45, for a 16384 x 1 image) is 6.78") == why, "%s",
              why);
    cr_expect(strstr(why, "beyond the limit of 1e+19 on camera ray lengths") != NULL, "%s", why);
    c.focus_distance = 1e19f;
    cr_expect_eq(scene_camera_view_check(&c, 512, 512, why, sizeof why), -1);
    c.focus_distance = 0.0f;
    c.aperture = 3e18f; /* the lens reaches 1.5e18 from the position */
    cr_expect_eq(scene_camera_check(&c, why, sizeof why), -1);
    cr_expect(strstr(why, "the lens (position +- aperture / 2, aperture 3e+18) is (1.5e+18, 1.5e+18, 1.5e+18)") == why,
              "%s", why);
    c.aperture = 1e18f;
    cr_expect_eq(scene_camera_check(&c, why, sizeof why), 0, "%s", why);
    c.aperture = 0.0f;
    c.look_at[1] = NAN;
    cr_expect_eq(scene_camera_check(&c, why, sizeof why), -1);
    cr_expect_str_eq(why, "look_at is not finite (0, nan, 0)");
}

/* ---- scene.ini -------------------------------------------------------------------------------- */

static const char *ini_with(const char *body)
{
    Gl g = st_tri();
    st_put_gltf("a.gltf", st_gl_json(&g));
    char *text = NULL;
    cr_assert_geq(asprintf(&text, "[scene]\ngltf = a.gltf\n%s", body), 0);
    const char *path = st_put_file("s.ini", text);
    free(text);
    return path;
}

static void ini_loads(const char *body)
{
    Scene s;
    st_load_ok(ini_with(body), &s);
    scene_free(&s);
}

Test(scene_limits, ini_lights)
{
    st_load_fails(ini_with("[light.p]\ntype = point\nposition = 0 0 2\nintensity = 1e37\n"), 1,
                  "s.ini:6: key 'light.p.intensity': color x intensity is (1e+37, 1e+37, 1e+37), beyond the limit of "
                  "1e+36 on point and spot light intensities");
    ini_loads("[light.p]\ntype = point\nposition = 0 0 2\nintensity = 9e35\n");
    /* the product: neither colour nor intensity alone is beyond */
    st_load_fails(ini_with("[light.p]\ntype = spot\nposition = 0 0 2\ndirection = 0 0 -1\ncolor = 1e20 1 1\n"
                           "intensity = 1e20\n"),
                  1, "s.ini:8: key 'light.p.intensity': color x intensity is not finite (inf, 1e+20, 1e+20)");
    st_load_fails(ini_with("[light.p]\ntype = point\nposition = 0 1e30 2\n"), 1,
                  "s.ini:5: key 'light.p.position': the position is (0, 1e+30, 2), beyond the limit of 1e+18 on scene "
                  "coordinates");
    /* directional and quad lights give radiance: the lower limit */
    st_load_fails(ini_with("[light.sun]\ntype = directional\ndirection = 0 -1 0\nintensity = 2e18\n"), 1,
                  "s.ini:6: key 'light.sun.intensity': color x intensity is (2e+18, 2e+18, 2e+18), beyond the limit of "
                  "1e+18 on radiance");
    ini_loads("[light.sun]\ntype = directional\ndirection = 0 -1 0\nintensity = 9e17\n");
    /* a quad: each corner, and its area */
    st_load_fails(ini_with("[light.q]\ntype = quad\nposition = 0 5 0\nedge_u = 2e18 0 0\nedge_v = 0 0 1\n"), 1,
                  "s.ini:6: key 'light.q.edge_u': the corner position + edge_u is (2e+18, 5, 0), beyond the limit");
    st_load_fails(ini_with("[light.q]\ntype = quad\nposition = 0 5 0\nedge_u = 1 0 0\nedge_v = 0 0 -1e19\n"), 1,
                  "s.ini:7: key 'light.q.edge_v': the corner position + edge_v is (0, 5, -1e+19)");
    st_load_fails(ini_with("[light.q]\ntype = quad\nposition = 0 5 0\nedge_u = 2e9 0 0\nedge_v = 0 0 2e9\n"), 1,
                  "s.ini:3: section [light.q]: the area |edge_u x edge_v| is 4e+18, beyond the limit of 1e+18 on "
                  "areas");
    ini_loads("[light.q]\ntype = quad\nposition = 0 5 0\nedge_u = 9e8 0 0\nedge_v = 0 0 1e9\n");
}

Test(scene_limits, ini_camera)
{
    ini_loads("[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n");
    st_load_fails(ini_with("[camera]\nposition = 0 0 1e30\nlook_at = 0 0 0\n"), 1,
                  "s.ini:3: section [camera]: position is (0, 0, 1e+30), beyond the limit of 1e+18 on scene "
                  "coordinates");
    st_load_fails(ini_with("[camera]\nposition = 0 0 5\nlook_at = 0 -2e18 0\n"), 1,
                  "s.ini:3: section [camera]: look_at is (0, -2e+18, 0), beyond the limit");
    st_load_fails(ini_with("[camera]\nposition = 0 0 5\nlook_at = 0 0 0\nfocus_distance = 1e19\n"), 1,
                  "s.ini: [camera]: ray length (focus distance 1e+19, fov_y 45, for a 512 x 512 image) is 1.15894e+19, "
                  "beyond the limit of 1e+19");
    /* the scene's own image size counts: 1e16 away is fine for a square image, not 16384 x 1 */
    ini_loads("[camera]\nposition = 0 0 1e16\nlook_at = 0 0 0\n");
    st_load_fails(ini_with("[camera]\nposition = 0 0 1e16\nlook_at = 0 0 0\n[render]\nwidth = 16384\n"
                           "height = 1\n"),
                  1, "s.ini: [camera]: ray length (focus distance 1e+16, fov_y 45, for a 16384 x 1 image) is 6.78");
    /* a field of view near 180 degrees widens it too */
    st_load_fails(ini_with("[camera]\nposition = 0 0 1e14\nlook_at = 0 0 0\nfov_y = 179.9999\n"), 1,
                  "s.ini: [camera]: ray length (focus distance 1e+14, fov_y 180, for a 512 x 512 image) is "
                  "1.51722e+20");
}

Test(scene_limits, ini_spheres_radiance_reflectance)
{
    const char *mat = "[material.chalk]\nbase_color = 0.5 0.5 0.5\n";
    char body[512];
    snprintf(body, sizeof body, "%s[sphere.s]\ncenter = 0 0 -5\nradius = 1e20\nmaterial = chalk\n", mat);
    st_load_fails(ini_with(body), 1,
                  "s.ini:7: key 'sphere.s.radius': |center| + radius is (1e+20, 1e+20, 1e+20), beyond the limit of "
                  "1e+18 on scene coordinates");
    snprintf(body, sizeof body, "%s[sphere.s]\ncenter = 0 2e18 -5\nradius = 1\nmaterial = chalk\n", mat);
    st_load_fails(ini_with(body), 1, "s.ini:6: key 'sphere.s.center': center is (0, 2e+18, -5), beyond the limit");
    snprintf(body, sizeof body, "%s[sphere.s]\ncenter = 0 0 -5\nradius = 9e17\nmaterial = chalk\n"
             "[camera]\nposition = 0 0 1e17\nlook_at = 0 0 0\n", mat);
    ini_loads(body);
    st_load_fails(ini_with("[render]\nbackground = 0 2e18 0\n"), 1,
                  "s.ini:4: key 'render.background': radiance is (0, 2e+18, 0), beyond the limit of 1e+18 on radiance");
    st_load_fails(ini_with("[render]\nambient = 1e30 0 0\n"), 1, "s.ini:4: key 'render.ambient': radiance is (1e+30");
    st_load_fails(ini_with("[material.lamp]\nemission = 1e19 1 1\n"), 1,
                  "s.ini:4: key 'material.lamp.emission': radiance is (1e+19, 1, 1), beyond the limit");
    ini_loads("[render]\nbackground = 1 1 1\nambient = 0.1 0.1 0.1\n[material.lamp]\nemission = 9e17 1 1\n");
    /* a reflectance above 1 is a warning only */
    Scene s;
    st_load_ok(ini_with("[material.paint]\nbase_color = 1.5 0.5 0.5\n"), &s);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect(strstr(s.warnings[0], "s.ini:4: key 'material.paint.base_color': is (1.5, 0.5, 0.5), beyond the limit "
                                    "of 1 on reflectances") != NULL,
              "%s", s.warnings[0]);
    scene_free(&s);
    st_load_ok(ini_with("[material.paint]\nbase_color = 1 0.5 0.5\n"), &s);
    cr_expect_eq(s.nwarnings, 0);
    scene_free(&s);
}

/* ---- glTF ------------------------------------------------------------------------------------- */

#define LIGHTS_TOP(light)                                                                                              \
    "\"extensionsUsed\": [\"KHR_lights_punctual\"], \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [" light  \
    "]}}"

Test(scene_limits, gltf_lights)
{
    Gl g = st_tri();
    g.scene_nodes = "0, 1";
    g.nodes = "{\"name\": \"lamp\", \"translation\": [0, 0, 2], \"extensions\": {\"KHR_lights_punctual\": "
              "{\"light\": 0}}}";
    g.top = LIGHTS_TOP("{\"name\": \"bulb\", \"type\": \"point\", \"intensity\": 1e37}");
    st_load_fails(st_put_gltf("l1.gltf", st_gl_json(&g)), 1,
                  "l1.gltf: light 0 'bulb': color x intensity is (1e+37, 1e+37, 1e+37), beyond the limit of 1e+36");
    g.top = LIGHTS_TOP("{\"name\": \"bulb\", \"type\": \"point\", \"intensity\": 5, \"color\": [1e36, 1, 1]}");
    st_load_fails(st_put_gltf("l2.gltf", st_gl_json(&g)), 1, "l2.gltf: light 0 'bulb': color x intensity is (5e+36");
    g.top = LIGHTS_TOP("{\"name\": \"sun\", \"type\": \"directional\", \"intensity\": 1e19}");
    st_load_fails(st_put_gltf("l3.gltf", st_gl_json(&g)), 1,
                  "l3.gltf: light 0 'sun': color x intensity is (1e+19, 1e+19, 1e+19), beyond the limit of 1e+18 on "
                  "radiance");
    /* JSON holds no NaN or infinity; a number beyond binary64 is refused by the parser */
    g.top = LIGHTS_TOP("{\"name\": \"bulb\", \"type\": \"point\", \"intensity\": 1e400}");
    st_load_fails(st_put_gltf("l4.gltf", st_gl_json(&g)), 2, "l4.gltf: ", "number overflow parsing '1e400'");
    /* beyond binary32, where the renderers compute, it is not finite */
    g.top = LIGHTS_TOP("{\"name\": \"bulb\", \"type\": \"point\", \"intensity\": 1e39}");
    st_load_fails(st_put_gltf("l7.gltf", st_gl_json(&g)), 1, "l7.gltf: light 0 'bulb': intensity is negative or not "
                                                             "finite");
    Scene s;
    g.top = LIGHTS_TOP("{\"name\": \"bulb\", \"type\": \"point\", \"intensity\": 1e35}");
    st_load_ok(st_put_gltf("l5.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
    /* a light placed beyond the coordinates by its node */
    g.nodes = "{\"name\": \"lamp\", \"translation\": [0, 1e30, 2], \"extensions\": {\"KHR_lights_punctual\": "
              "{\"light\": 0}}}";
    st_load_fails(st_put_gltf("l6.gltf", st_gl_json(&g)), 1,
                  "l6.gltf: node 1 'lamp': KHR_lights_punctual light 0 'bulb': position is (0, 1e+30, 2), beyond the "
                  "limit of 1e+18 on scene coordinates");
}

Test(scene_limits, gltf_camera)
{
    Gl g = st_tri();
    g.scene_nodes = "0, 1";
    g.nodes = "{\"name\": \"far\", \"translation\": [0, 0, 1e30], \"camera\": 0}";
    g.top = "\"cameras\": [{\"name\": \"eye\", \"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, "
            "\"znear\": 0.01}}]";
    const char *path = st_put_gltf("c1.gltf", st_gl_json(&g));
    st_load_fails(path, 1,
                  "c1.gltf: node 1 'far': camera 0 'eye': position is (0, 0, 1e+30), beyond the limit of 1e+18 on "
                  "scene coordinates");
    /* a scene.ini [camera] that moves it is not refused for what the file said */
    char text[512];
    snprintf(text, sizeof text, "[scene]\ngltf = c1.gltf\n[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n");
    Scene s;
    st_load_ok(st_put_file("c.ini", text), &s);
    cr_expect_eq(s.camera.position[2], 5.0f);
    scene_free(&s);
    /* ... but one that keeps it is */
    snprintf(text, sizeof text, "[scene]\ngltf = c1.gltf\n[camera]\nfov_y = 30\n");
    st_load_fails(st_put_file("c2.ini", text), 1, "c2.ini:3: section [camera]: position is (0, 0, 1e+30)");
}

Test(scene_limits, default_camera)
{
    /* a needle from -9e17 to 9e17: inside every limit, but the camera that frames it stands
     * 2.5e18 away: within the headroom of the renderers' squares, so a warning (the file alone
     * cannot name another camera) */
    float pos[9] = {-9e17f, 0, 0, 9e17f, 0, 0, 0, 0.1f, 0};
    Gl g = st_tri();
    g.pos = pos;
    Scene s;
    st_load_ok(st_put_gltf("needle.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect(strstr(s.warnings[0], "needle.gltf: the default camera (the one that frames the scene's bounds): "
                                    "position is (0, 0.05, 2.4694e+18), beyond the limit of 1e+18 on scene "
                                    "coordinates") != NULL,
              "%s", s.warnings[0]);
    cr_expect(strstr(s.warnings[0], "give the scene a camera (scene.ini [camera])") != NULL, "%s", s.warnings[0]);
    scene_free(&s);
    /* its rays overflow for a 16384 x 1 image: refused */
    char text[256];
    snprintf(text, sizeof text, "[scene]\ngltf = needle.gltf\n[render]\nwidth = 16384\nheight = 1\n");
    st_load_fails(st_put_file("wide.ini", text), 2,
                  "wide.ini: the default camera (the one that frames the scene's bounds): ray length (focus distance",
                  "give the scene a camera (scene.ini [camera])");
    /* a small scene's default camera: no warning */
    g = st_tri();
    st_load_ok(st_put_gltf("small.gltf", st_gl_json(&g)), &s);
    cr_expect_eq(s.nwarnings, 0);
    scene_free(&s);
}

Test(scene_limits, gltf_materials)
{
    Gl g = st_tri();
    g.material = "{\"name\": \"lamp\", \"emissiveFactor\": [1, 1, 1], \"extensions\": "
                 "{\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 1e30}}}";
    st_load_fails(st_put_gltf("m1.gltf", st_gl_json(&g)), 1,
                  "m1.gltf: material 0 'lamp': emission (emissiveFactor x KHR_materials_emissive_strength) is (1e+30, "
                  "1e+30, 1e+30), beyond the limit of 1e+18 on radiance");
    g.material = "{\"name\": \"glass\", \"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, "
                 "\"KHR_materials_ior\": {\"ior\": 1e30}}}";
    st_load_fails(st_put_gltf("m2.gltf", st_gl_json(&g)), 1,
                  "m2.gltf: material 0 'glass': KHR_materials_ior ior is 1e+30, beyond the limit of 1e+18 on indices "
                  "of refraction");
    g.material = "{\"name\": \"glass\", \"extensions\": {\"KHR_materials_ior\": {\"ior\": 1e39}}}";
    st_load_fails(st_put_gltf("m3.gltf", st_gl_json(&g)), 1, "m3.gltf: material 0 'glass': KHR_materials_ior ior is "
                                                             "not finite (inf)");
    Scene s;
    g.material = "{\"name\": \"bright\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [2, 0.5, 0.5, 1]}}";
    st_load_ok(st_put_gltf("m4.gltf", st_gl_json(&g)), &s);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect(strstr(s.warnings[0], "m4.gltf: material 0 'bright': baseColorFactor is (2, 0.5, 0.5), beyond the limit "
                                    "of 1 on reflectances") != NULL,
              "%s", s.warnings[0]);
    scene_free(&s);
}

Test(scene_limits, gltf_nodes)
{
    Gl g = st_tri();
    g.node = "\"name\": \"proj\", \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0.5, 0, 0, 0, 1]";
    st_load_fails(st_put_gltf("n1.gltf", st_gl_json(&g)), 1,
                  "n1.gltf: node 0 'proj': matrix is not affine: its bottom row is (0, 0, 0.5, 1), not (0, 0, 0, 1) "
                  "within 1e-06");
    g.node = "\"name\": \"w\", \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]";
    st_load_fails(st_put_gltf("n2.gltf", st_gl_json(&g)), 1, "n2.gltf: node 0 'w': matrix is not affine: its bottom "
                                                             "row is (0, 0, 0, 2)");
    Scene s;
    g.node = "\"name\": \"ok\", \"matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1e-7, 0, 0, 0, 1.0000001]";
    st_load_ok(st_put_gltf("n3.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
    /* each node finite, their composition not */
    g.node = "\"name\": \"child\", \"scale\": [1e200, 1e200, 1e200]";
    g.nodes = "{\"name\": \"parent\", \"scale\": [1e200, 1e200, 1e200], \"children\": [0]}";
    g.scene_nodes = "1";
    st_load_fails(st_put_gltf("n4.gltf", st_gl_json(&g)), 1,
                  "n4.gltf: node 0 'child': transform composed with its parents' is not finite");
}

Test(scene_limits, triangle_area)
{
    Gl g = st_tri();
    g.node = "\"name\": \"huge\", \"scale\": [1e10, 1e10, 1e10]";
    st_load_fails(st_put_gltf("t1.gltf", st_gl_json(&g)), 1,
                  "t1.gltf: mesh 0 'tri' primitive 0: triangle 0 (vertices 0, 1, 2): |e1 x e2| is 1e+20, beyond the "
                  "limit of 1e+18 on areas");
    Scene s;
    g.node = "\"name\": \"big\", \"scale\": [9e8, 1e9, 1]";
    st_load_ok(st_put_gltf("t2.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
}

/* What another loader leaves unchecked, scene_finish refuses, naming the triangle. */
Test(scene_limits, finish_checks_every_loader)
{
    Scene s;
    char err[512];
    scene_init(&s, "other.obj");
    float tri[9] = {0, 0, 0, 1e10f, 0, 0, 0, 1e10f, 0};
    s.ntris = 1;
    s.pos = malloc(sizeof tri);
    memcpy(s.pos, tri, sizeof tri);
    s.tri_material = calloc(1, sizeof *s.tri_material);
    s.materials = calloc(1, sizeof *s.materials);
    s.nmaterials = 1;
    cr_assert_neq(scene_finish(&s, err, sizeof err), 0);
    cr_expect(strstr(err, "other.obj: triangle 0: |e1 x e2| is 1e+20, beyond the limit of 1e+18 on areas") == err,
              "%s", err);
    s.pos[3] = 2e18f;
    s.pos[7] = 1.0f;
    cr_assert_neq(scene_finish(&s, err, sizeof err), 0);
    cr_expect(strstr(err, "other.obj: triangle 0: vertex 1 is (2e+18, 0, 0), beyond the limit of 1e+18") == err, "%s",
              err);
    s.pos[3] = 1.0f;
    cr_expect_eq(scene_finish(&s, err, sizeof err), 0, "%s", err);
    scene_free(&s);
}

Test(scene_limits, texture_coordinates)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = st_tri();
    g.uv = uv;
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1e20, 1]}}}}}";
    st_load_fails(st_put_gltf("uv1.gltf", st_gl_json(&g)), 1,
                  "uv1.gltf: mesh 0 'tri' primitive 0 TEXCOORD_0: vertex 1 coordinate 0 after KHR_texture_transform "
                  "is 1e+20, beyond the limit of 1e+18 on texture coordinates");
    Scene s;
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1e17, 1]}}}}}";
    st_load_ok(st_put_gltf("uv2.gltf", st_gl_json(&g)), &s);
    scene_free(&s);
}

/* The GLB header's version, checked before tinygltf (which reads a version 1 container). */
Test(scene_limits, glb_version)
{
    FILE *f = fopen("tests/scenes/ok_textured.glb", "rb");
    cr_assert_not_null(f, "run from the repository root");
    unsigned char buf[4096];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    cr_assert_gt(n, 20);
    Scene s;
    char err[512];
    scene_init(&s, "v.glb");
    cr_expect_eq(gltf_append_memory(buf, n, "v.glb", NULL, &s, err, sizeof err), 0, "%s", err);
    scene_free(&s);
    static const uint32_t versions[] = {0, 1, 3};
    for (size_t i = 0; i < sizeof versions / sizeof versions[0]; i++) {
        uint32_t v = versions[i];
        memcpy(buf + 4, &v, 4);
        scene_init(&s, "v.glb");
        cr_expect_neq(gltf_append_memory(buf, n, "v.glb", NULL, &s, err, sizeof err), 0, "version %u loaded", v);
        char want[128];
        snprintf(want, sizeof want, "v.glb: GLB header version %u, not 2: sfsim reads glTF 2.0 only", v);
        cr_expect_str_eq(err, want);
        scene_free(&s);
    }
}
