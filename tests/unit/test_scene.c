/* tests/unit/test_scene.c -- the scene loader: every shared scene through its scene.ini
 * (triangle counts of ../shared/scenes/README.md, needs), the glTF material mapping, node
 * transforms, KHR_lights_punctual, cameras, scene.ini sections, and one test per class of
 * malformed input with the message it must give.
 *
 * The small glTF files are written by the tests themselves (JSON with base64 data URIs) into a
 * temporary folder, so each test shows the exact input it checks. */
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
#include "../support/shared.h"

/* ---- temporary files ------------------------------------------------------------------------ */

static char g_dir[64];
static char g_files[64][160];
static int g_nfiles;

static void tmp_setup(void)
{
    strcpy(g_dir, "/tmp/sfsim-scene-XXXXXX");
    cr_assert_not_null(mkdtemp(g_dir));
    g_nfiles = 0;
}

static void tmp_teardown(void)
{
    for (int i = 0; i < g_nfiles; i++)
        unlink(g_files[i]);
    rmdir(g_dir);
}

/* Writes text to DIR/name; returns the path (static storage). */
static const char *put_file(const char *name, const char *text)
{
    cr_assert_lt(g_nfiles, 64);
    char *path = g_files[g_nfiles++];
    snprintf(path, sizeof g_files[0], "%s/%s", g_dir, name);
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f, "cannot write %s", path);
    fwrite(text, 1, strlen(text), f);
    fclose(f);
    return path;
}

/* ---- glTF builder --------------------------------------------------------------------------- */

static char *b64(const unsigned char *p, size_t n)
{
    static const char t[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc(4 * ((n + 2) / 3) + 1), *q = o;
    for (size_t i = 0; i < n; i += 3) {
        uint32_t v = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        *q++ = t[v >> 18 & 63];
        *q++ = t[v >> 12 & 63];
        *q++ = i + 1 < n ? t[v >> 6 & 63] : '=';
        *q++ = i + 2 < n ? t[v & 63] : '=';
    }
    *q = 0;
    return o;
}

typedef struct Gl {
    int nv;
    const float *pos, *nrm, *uv; /* nv x 3, nv x 3, nv x 2; nrm and uv may be NULL */
    int nidx, ictype;            /* indices (5121, 5123 or 5125), none when nidx == 0 */
    const uint32_t *idx;
    const char *material;    /* materials[0] as JSON, or NULL: the primitive names no material */
    const char *prim;        /* extra members of the primitive, e.g. "\"mode\": 1" */
    const char *node;        /* extra members of node 0 (the mesh node) */
    const char *nodes;       /* further nodes, JSON objects after node 0 */
    const char *scene_nodes; /* the default scene's node list; "0" when NULL */
    const char *top;         /* extra top-level members */
} Gl;

/* A one-mesh glTF (mesh 0 'tri', one primitive) with its buffer as a data URI. */
static char *gl_json(const Gl *g)
{
    unsigned char buf[4096];
    size_t len = 0, off[4], blen[4];
    int nview = 0;
    char acc[1024] = "", views[1024] = "", attrs[256] = "";
    const void *src[3] = {g->pos, g->nrm, g->uv};
    const char *names[3] = {"POSITION", "NORMAL", "TEXCOORD_0"}, *types[3] = {"VEC3", "VEC3", "VEC2"};
    int comps[3] = {3, 3, 2};
    for (int a = 0; a < 3; a++) {
        if (!src[a])
            continue;
        size_t n = sizeof(float) * (size_t)comps[a] * (size_t)g->nv;
        memcpy(buf + len, src[a], n);
        off[nview] = len;
        blen[nview] = n;
        len += n;
        snprintf(acc + strlen(acc), sizeof acc - strlen(acc),
                 "%s{\"bufferView\": %d, \"componentType\": 5126, \"count\": %d, \"type\": \"%s\"}", nview ? ", " : "",
                 nview, g->nv, types[a]);
        snprintf(attrs + strlen(attrs), sizeof attrs - strlen(attrs), "%s\"%s\": %d", nview ? ", " : "", names[a],
                 nview);
        nview++;
    }
    int iacc = -1;
    if (g->nidx) {
        size_t cs = g->ictype == 5121 ? 1 : g->ictype == 5123 ? 2 : 4;
        off[nview] = len;
        for (int i = 0; i < g->nidx; i++) {
            uint32_t v = g->idx[i];
            memcpy(buf + len, &v, cs); /* little-endian host */
            len += cs;
        }
        blen[nview] = cs * (size_t)g->nidx;
        len = (len + 3) & ~(size_t)3;
        snprintf(acc + strlen(acc), sizeof acc - strlen(acc),
                 ", {\"bufferView\": %d, \"componentType\": %d, \"count\": %d, \"type\": \"SCALAR\"}", nview, g->ictype,
                 g->nidx);
        iacc = nview++;
    }
    for (int v = 0; v < nview; v++)
        snprintf(views + strlen(views), sizeof views - strlen(views),
                 "%s{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}", v ? ", " : "", off[v], blen[v]);
    char *data = b64(buf, len), *json = NULL;
    char idx[32] = "", mat[64] = "";
    if (iacc >= 0)
        snprintf(idx, sizeof idx, ", \"indices\": %d", iacc);
    if (g->material)
        snprintf(mat, sizeof mat, ", \"material\": 0");
    int n =
        asprintf(&json,
                 "{\"asset\": {\"version\": \"2.0\"},\n"
                 " \"scene\": 0, \"scenes\": [{\"nodes\": [%s]}],\n"
                 " \"nodes\": [{\"mesh\": 0%s%s}%s%s],\n"
                 " \"meshes\": [{\"name\": \"tri\", \"primitives\": [{\"attributes\": {%s}%s%s%s%s}]}],\n"
                 " %s%s%s\n"
                 " \"accessors\": [%s],\n"
                 " \"bufferViews\": [%s],\n"
                 " \"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}]%s%s}\n",
                 g->scene_nodes ? g->scene_nodes : "0", g->node ? ", " : "", g->node ? g->node : "",
                 g->nodes ? ", " : "", g->nodes ? g->nodes : "", attrs, idx, mat, g->prim ? ", " : "",
                 g->prim ? g->prim : "", g->material ? "\"materials\": [" : "", g->material ? g->material : "",
                 g->material ? "]," : "", acc, views, len, data, g->top ? ",\n " : "", g->top ? g->top : "");
    free(data);
    cr_assert_gt(n, 0);
    return json;
}

/* json with the first occurrence of `from` replaced by `to` (the input is freed). */
static char *edit(char *json, const char *from, const char *to)
{
    char *at = strstr(json, from);
    cr_assert_not_null(at, "'%s' not in the generated glTF", from);
    char *out = NULL;
    cr_assert_gt(asprintf(&out, "%.*s%s%s", (int)(at - json), json, to, at + strlen(from)), 0);
    free(json);
    return out;
}

static const char *put_gltf(const char *name, char *json)
{
    const char *p = put_file(name, json);
    free(json);
    return p;
}

static const float tri_pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

static Gl tri(void)
{
    Gl g;
    memset(&g, 0, sizeof g);
    g.nv = 3;
    g.pos = tri_pos;
    return g;
}

/* Loads a generated glTF; the load must succeed. */
static void load_ok(const char *path, Scene *s)
{
    char err[2048];
    int rc = scene_load(path, s, err, sizeof err);
    cr_assert_eq(rc, 0, "load failed: %s", err);
}

/* Loads; the load must fail with every one of the given substrings in the message. */
static void load_fails(const char *path, int nsub, ...)
{
    Scene s;
    char err[4096];
    err[0] = 0;
    int rc = scene_load(path, &s, err, sizeof err);
    cr_assert_neq(rc, 0, "loaded, but should have failed: %s", path);
    va_list ap;
    va_start(ap, nsub);
    for (int i = 0; i < nsub; i++) {
        const char *sub = va_arg(ap, const char *);
        cr_expect_not_null(strstr(err, sub), "message lacks '%s':\n%s", sub, err);
    }
    va_end(ap);
}

static char *needs_of(const Scene *s)
{
    static char buf[256];
    scene_needs_string(s->needs, buf, sizeof buf);
    return buf;
}

#define EPS 1e-5f
#define expect_near(a, b, eps)                                                                                         \
    cr_expect(fabsf((float)(a) - (float)(b)) <= (eps), "%s = %g, expected %g", #a, (double)(a), (double)(b))

/* ---- shipped scenes: every scene.ini of scenes/ (most name a glTF file in ../shared) --------- */

static void check_shipped(const char *ini, uint32_t tris, const char *needs, int camera_source)
{
    NEEDS_SCENE(ini);
    Scene s;
    load_ok(ini, &s);
    cr_expect_eq(s.ntris, tris, "%s: %u triangles, the README says %u", ini, s.ntris, tris);
    cr_expect_str_eq(needs_of(&s), needs, "%s: needs", ini);
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
    load_ok("scenes/cornell/scene.ini", &s);
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
    load_ok("scenes/conference/scene.ini", &s);
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
    load_ok("../shared/scenes/cornell-box/CornellBox-Original.glb", &s);
    cr_expect_eq(s.ntris, 36);
    cr_expect_str_eq(needs_of(&s), "lambert,area_lights");
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
    cr_expect_str_eq(needs_of(&s), "lambert,glossy,dielectric,area_lights");
    scene_free(&s);
    /* a truncated copy fails cleanly */
    scene_init(&s, "mem.glb");
    cr_expect_neq(gltf_append_memory(data, n / 2, "cut.glb", NULL, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "cut.glb: "), "%s", err);
    scene_free(&s);
    free(data);
}

/* ---- material mapping (ARCHITECTURE.md Sec. 1) --------------------------------------------- */

TestSuite(scene_materials, .init = tmp_setup, .fini = tmp_teardown);

static Scene one_material(const char *material, const char *top)
{
    Gl g = tri();
    g.material = material;
    g.top = top;
    Scene s;
    load_ok(put_gltf("m.gltf", gl_json(&g)), &s);
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
    cr_expect_str_eq(needs_of(&s), "lambert");
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
    cr_expect_str_eq(needs_of(&s), "glossy");
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
    cr_expect_str_eq(needs_of(&s), "dielectric");
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
    cr_expect_str_eq(needs_of(&s), "area_lights");
    scene_free(&s);
}

Test(scene_materials, no_material_gets_the_gltf_default)
{
    Gl g = tri();
    Scene s;
    load_ok(put_gltf("d.gltf", gl_json(&g)), &s);
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
    cr_expect_str_eq(needs_of(&s), "lambert,alpha");
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

/* 2 x 2 RGBA PNG: (128,0,255,64) (255,255,255,255) / (0,0,0,255) (64,64,64,128) */
#define PNG_2X2                                                                                                        \
    "iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAYAAABytg0kAAAAF0lEQVR4nGNoYPjv8B8IGIDgv4ODQwMAUJAH+ztHQuYAAAAASUVORK5CYII="
/* 16 x 1 RGB PNG: 8 black texels, then 8 white ones */
#define PNG_16X1 "iVBORw0KGgoAAAANSUhEUgAAABAAAAABCAIAAABYG7kIAAAADklEQVR4nGNgwAH+4wAAKxQX6dD14Y0AAAAASUVORK5CYII="

static float srgb(int c)
{
    double v = c / 255.0;
    return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
}

Test(scene_materials, base_colour_texture_srgb_to_linear)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}, \"metallicFactor\": 0}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"name\": \"checker\", \"uri\": "
            "\"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    load_ok(put_gltf("t.gltf", gl_json(&g)), &s);
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
    cr_expect_str_eq(needs_of(&s), "lambert,textures");
    scene_free(&s);
}

/* KHR_texture_transform and texCoord are applied to the coordinates at load time, per texture:
 * the base-colour texture reads TEXCOORD_1 through offset (0.5, 0.25), rotation pi/2, scale
 * (2, 3) -- u' = 2 cos(r) u + 3 sin(r) v + 0.5, v' = -2 sin(r) u + 3 cos(r) v + 0.25 -- while
 * the emissive texture reads the same set through its own offset. */
Test(scene_materials, texture_transform_and_texcoord_per_texture)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0, \"texCoord\": 1,"
                 " \"extensions\": {\"KHR_texture_transform\": {\"offset\": [0.5, 0.25], \"rotation\": 1.5707963267948966,"
                 " \"scale\": [2, 3]}}}}, \"emissiveFactor\": [1, 1, 1], \"emissiveTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"offset\": [0.125, 0], \"texCoord\": 1}}}}";
    g.top = "\"extensionsUsed\": [\"KHR_texture_transform\"], \"textures\": [{\"source\": 0}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    load_ok(put_gltf("tt.gltf", edit(gl_json(&g), "\"TEXCOORD_0\"", "\"TEXCOORD_1\"")), &s);
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
    load_ok(put_gltf("t0.gltf", gl_json(&g)), &s);
    cr_expect_null(s.uv);
    cr_expect_null(s.uv_emit);
    cr_expect_str_eq(needs_of(&s), "lambert");
    scene_free(&s);
    /* dequantization, as gltfpack writes it: integer coordinates scaled by the transform */
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0,"
                 " \"extensions\": {\"KHR_texture_transform\": {\"scale\": [0.001, 0.002]}}}}}";
    static const float big[6] = {0, 0, 1000, 0, 0, 500};
    g.uv = big;
    load_ok(put_gltf("tq.gltf", gl_json(&g)), &s);
    expect_near(s.uv[2], 1.0f, 1e-6f);
    expect_near(s.uv[5], 1.0f, 1e-6f);
    scene_free(&s);
}

/* Textures repeat: a sampler asking for clamping is not applied, and a warning says so. */
Test(scene_materials, clamped_sampler_warns)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"baseColorTexture\": {\"index\": 0}}}";
    g.top = "\"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{\"wrapS\": 33071, \"wrapT\": 10497}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    Scene s;
    load_ok(put_gltf("cl.gltf", gl_json(&g)), &s);
    cr_assert_eq(s.nwarnings, 1);
    cr_expect_not_null(strstr(s.warnings[0], "cl.gltf: 1 textures ask for CLAMP_TO_EDGE or MIRRORED_REPEAT wrapping, "
                                             "which is not applied: every texture repeats"), "%s", s.warnings[0]);
    scene_free(&s);
    g.top = "\"textures\": [{\"source\": 0, \"sampler\": 0}], \"samplers\": [{}],"
            " \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    load_ok(put_gltf("rp.gltf", gl_json(&g)), &s);
    cr_expect_eq(s.nwarnings, 0);
    scene_free(&s);
}

Test(scene_gltf_errors, texture_transform_checked)
{
    static const float uv[6] = {0, 0, 1, 0, 0, 1};
    Gl g = tri();
    g.uv = uv;
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"data:image/png;base64," PNG_2X2 "\"}]";
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1]}}}}}";
    load_fails(put_gltf("tx1.gltf", gl_json(&g)), 1,
               "tx1.gltf: material 0 'm' baseColorTexture: KHR_texture_transform: scale is not 2 numbers");
    g.material = "{\"name\": \"m\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, \"extensions\":"
                 " {\"KHR_texture_transform\": {\"scale\": [1e300, 1e300]}}}}}";
    load_fails(put_gltf("tx2.gltf", gl_json(&g)), 1,
               "tx2.gltf: mesh 0 'tri' primitive 0 TEXCOORD_0: vertex 1 is not finite after KHR_texture_transform");
}

/* COLOR_0 (VEC3 or VEC4, float or normalized integers) is kept per vertex; triangles of a file
 * without it get white. */
Test(scene_materials, vertex_colours)
{
    static const float col[9] = {1, 0, 0, 0, 0.5f, 0, 0, 0, 0.25f};
    Gl g = tri();
    g.nrm = col;
    Scene s;
    load_ok(put_gltf("vc.gltf", edit(gl_json(&g), "\"NORMAL\"", "\"COLOR_0\"")), &s);
    cr_assert_not_null(s.col);
    for (int k = 0; k < 9; k++)
        expect_near(s.col[k], col[k], 0.0f);
    cr_expect_null(s.nrm);
    scene_free(&s);
    /* a second file without colours: white */
    put_gltf("a.gltf", edit(gl_json(&g), "\"NORMAL\"", "\"COLOR_0\""));
    g.nrm = NULL;
    put_gltf("b.gltf", gl_json(&g));
    load_ok(put_file("s.ini", "[scene]\ngltf = b.gltf\ngltf = a.gltf\n"), &s);
    cr_assert_eq(s.ntris, 2);
    cr_assert_not_null(s.col);
    for (int k = 0; k < 9; k++) {
        expect_near(s.col[k], 1.0f, 0.0f);
        expect_near(s.col[9 + k], col[k], 0.0f);
    }
    scene_free(&s);
    float neg[9] = {1, 0, 0, 0, -0.5f, 0, 0, 0, 0.25f};
    g.nrm = neg;
    load_fails(put_gltf("vn.gltf", edit(gl_json(&g), "\"NORMAL\"", "\"COLOR_0\"")), 1,
               "vn.gltf: mesh 0 'tri' primitive 0 COLOR_0: vertex 1 component 1 is negative or not finite");
}

/* An emissive texture that is black in places: only triangles that see lit texels emit. */
Test(scene_materials, emissive_texture_lights_only_lit_parts)
{
    static const float pos[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0};
    static const float uv[12] = {0.05f, 0.5f, 0.3f, 0.5f, 0.05f, 0.5f, 0.6f, 0.5f, 0.95f, 0.5f, 0.6f, 0.5f};
    Gl g = tri();
    g.nv = 6;
    g.pos = pos;
    g.uv = uv;
    g.material = "{\"name\": \"panel\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0},"
                 " \"emissiveFactor\": [2, 2, 2], \"emissiveTexture\": {\"index\": 0}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"data:image/png;base64," PNG_16X1 "\"}]";
    Scene s;
    load_ok(put_gltf("e.gltf", gl_json(&g)), &s);
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
    cr_expect_str_eq(needs_of(&s), "lambert,area_lights,emissive_textures");
    cr_assert_not_null(s.uv_emit);
    scene_free(&s);
}

/* ---- geometry: transforms, index types, strips and fans ----------------------------------- */

TestSuite(scene_geometry, .init = tmp_setup, .fini = tmp_teardown);

Test(scene_geometry, node_translation_moves_vertices)
{
    Gl g = tri();
    g.node = "\"translation\": [10, 20, 30]";
    Scene s;
    load_ok(put_gltf("t.gltf", gl_json(&g)), &s);
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
    Gl g = tri();
    g.nrm = nrm;
    g.node = "\"matrix\": [2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,0,1]";
    g.nodes = "{\"children\": [0], \"rotation\": [0, 0.70710678, 0, 0.70710678], \"translation\": [0, 0, 5]}";
    g.scene_nodes = "1";
    Scene s;
    load_ok(put_gltf("h.gltf", gl_json(&g)), &s);
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
    Gl g = tri();
    g.nrm = nrm;
    g.node = "\"scale\": [1, 4, 1]";
    Scene s;
    load_ok(put_gltf("n.gltf", gl_json(&g)), &s);
    /* M^-T n = (1, 1/4, 0) / |.| */
    float l = sqrtf(1.0f + 1.0f / 16.0f);
    expect_near(s.nrm[0], 1.0f / l, 1e-5f);
    expect_near(s.nrm[1], 0.25f / l, 1e-5f);
    scene_free(&s);
}

/* A mirroring transform keeps the front face: the winding is reversed (glTF 2.0 Sec. 3.7.4). */
Test(scene_geometry, mirror_keeps_front_face)
{
    Gl g = tri();
    g.node = "\"scale\": [-1, 1, 1]";
    Scene s;
    load_ok(put_gltf("m.gltf", gl_json(&g)), &s);
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
        Gl g = tri();
        g.nv = 4;
        g.pos = pos;
        g.nidx = 6;
        g.idx = idx;
        g.ictype = types[i];
        Scene s;
        load_ok(put_gltf(i == 0 ? "u8.gltf" : i == 1 ? "u16.gltf" : "u32.gltf", gl_json(&g)), &s);
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
    Gl g = tri();
    g.nv = 5;
    g.pos = pos;
    g.prim = "\"mode\": 5";
    Scene s;
    load_ok(put_gltf("strip.gltf", gl_json(&g)), &s);
    cr_expect_eq(s.ntris, 3);
    /* every strip triangle keeps the winding of the first: normals all +z */
    for (uint32_t t = 0; t < s.ntris; t++) {
        const float *p = &s.pos[9 * t];
        float nz = (p[3] - p[0]) * (p[7] - p[1]) - (p[4] - p[1]) * (p[6] - p[0]);
        cr_expect_gt(nz, 0.0f, "strip triangle %u is flipped", t);
    }
    scene_free(&s);
    g.prim = "\"mode\": 6";
    load_ok(put_gltf("fan.gltf", gl_json(&g)), &s);
    cr_expect_eq(s.ntris, 3);
    scene_free(&s);
}

/* ---- KHR_lights_punctual and cameras ------------------------------------------------------- */

TestSuite(scene_lights_cameras, .init = tmp_setup, .fini = tmp_teardown);

Test(scene_lights_cameras, punctual_lights_with_node_transforms)
{
    Gl g = tri();
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
    load_ok(put_gltf("l.gltf", gl_json(&g)), &s);
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
    cr_expect_str_eq(needs_of(&s), "glossy,punctual_lights");
    scene_free(&s);
}

Test(scene_lights_cameras, camera_from_gltf)
{
    Gl g = tri();
    /* a camera at (0, 1, 10) turned 90 degrees about y: it looks down -x */
    g.nodes = "{\"camera\": 0, \"translation\": [0, 1, 10], \"rotation\": [0, 0.70710678, 0, 0.70710678]},"
              " {\"camera\": 1, \"translation\": [7, 7, 7]}";
    g.scene_nodes = "0, 1, 2";
    g.top = "\"cameras\": [{\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.8, \"znear\": 0.01}},"
            " {\"type\": \"perspective\", \"perspective\": {\"yfov\": 0.5, \"znear\": 0.01}}]";
    Scene s;
    load_ok(put_gltf("c.gltf", gl_json(&g)), &s);
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
    Gl g = tri();
    g.pos = pos;
    Scene s;
    load_ok(put_gltf("d.gltf", gl_json(&g)), &s);
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

/* ---- malformed glTF: each class names the file and the element ------------------------------ */

TestSuite(scene_gltf_errors, .init = tmp_setup, .fini = tmp_teardown);

Test(scene_gltf_errors, missing_file)
{
    load_fails("/nonexistent/x.glb", 2, "/nonexistent/x.glb", "cannot open");
}

Test(scene_gltf_errors, unknown_scene_type)
{
    load_fails(put_file("x.obj", "v 0 0 0\n"), 2, "x.obj", "unknown scene type");
}

Test(scene_gltf_errors, not_gltf)
{
    load_fails(put_file("junk.gltf", "{ this is not json"), 1, "junk.gltf: ");
    load_fails(put_file("junk.glb", "glTF but not really"), 1, "junk.glb: ");
}

/* A buffer whose external file does not exist: tinygltf's own message is kept. */
Test(scene_gltf_errors, missing_buffer)
{
    Gl g = tri();
    char *j = gl_json(&g);
    char *uri = strstr(j, "data:application");
    char *end = strchr(uri, '"');
    memmove(uri, "missing.bin", 11);
    memmove(uri + 11, end, strlen(end) + 1);
    const char *path = put_gltf("mb.gltf", j);
    load_fails(path, 2, "mb.gltf: ", "missing.bin");
}

/* A buffer whose data is shorter than its byteLength. */
Test(scene_gltf_errors, short_buffer)
{
    Gl g = tri();
    load_fails(put_gltf("sb.gltf", edit(gl_json(&g), "\"byteLength\": 36, \"uri\"", "\"byteLength\": 360, \"uri\"")), 1,
               "sb.gltf: ");
}

Test(scene_gltf_errors, accessor_outside_buffer)
{
    Gl g = tri();
    load_fails(put_gltf("ab.gltf", edit(gl_json(&g), "\"count\": 3", "\"count\": 300")), 3,
               "ab.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "300 elements",
               "run past the end of the bufferView");
    /* a view past its buffer */
    g = tri();
    load_fails(put_gltf("ab2.gltf", edit(gl_json(&g), "\"byteOffset\": 0, \"byteLength\": 36}",
                                         "\"byteOffset\": 8, \"byteLength\": 36}")),
               2, "ab2.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "bufferView lies outside its buffer");
}

Test(scene_gltf_errors, accessor_wrong_type)
{
    Gl g = tri();
    load_fails(put_gltf("wt.gltf", edit(gl_json(&g), "\"type\": \"VEC3\"", "\"type\": \"VEC2\"")), 2,
               "wt.gltf: mesh 0 'tri' primitive 0 POSITION", "is not VEC3");
    g = tri();
    load_fails(put_gltf("wt2.gltf", edit(gl_json(&g), "\"componentType\": 5126", "\"componentType\": 5123")), 2,
               "wt2.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0", "UNSIGNED_SHORT is not allowed here");
    g = tri();
    load_fails(put_gltf("wt3.gltf",
                        edit(gl_json(&g), "\"attributes\": {\"POSITION\": 0}", "\"attributes\": {\"POSITION\": 7}")),
               2, "wt3.gltf: mesh 0 'tri' primitive 0 POSITION", "accessor 7 does not exist");
}

/* The example of the issue: "x.glb: mesh 2 'chair' primitive 0: index 812 out of range (vertex count 500)". */
Test(scene_gltf_errors, index_out_of_range)
{
    static const uint32_t idx[3] = {0, 1, 7};
    Gl g = tri();
    g.nidx = 3;
    g.idx = idx;
    g.ictype = 5123;
    Scene s;
    char err[1024];
    const char *path = put_gltf("ir.gltf", gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    char want[512];
    snprintf(want, sizeof want, "%s: mesh 0 'tri' primitive 0: index 7 out of range (vertex count 3)", path);
    cr_expect_str_eq(err, want);
}

Test(scene_gltf_errors, indices_not_whole_triangles)
{
    static const uint32_t idx[4] = {0, 1, 2, 0};
    Gl g = tri();
    g.nidx = 4;
    g.idx = idx;
    g.ictype = 5125;
    load_fails(put_gltf("w.gltf", gl_json(&g)), 2, "w.gltf: mesh 0 'tri' primitive 0", "not a multiple of 3");
}

/* Points and lines are skipped and counted (one warning per file); a file of nothing else has no
 * geometry; a mode outside glTF's 0..6 is an error. */
Test(scene_gltf_errors, non_triangle_primitive)
{
    Gl g = tri();
    Scene s;
    load_ok(put_gltf("mixed.gltf",
                     edit(gl_json(&g), "{\"attributes\": {\"POSITION\": 0}}",
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
    load_fails(put_gltf("lines.gltf", gl_json(&g)), 2, "lines.gltf: the scene has no geometry",
               "its 1 glTF primitives that are not triangles were skipped");
    g.prim = "\"mode\": 9";
    load_fails(put_gltf("nine.gltf", gl_json(&g)), 1, "nine.gltf: mesh 0 'tri' primitive 0: mode 9 is not a glTF primitive mode");
}

Test(scene_gltf_errors, unsupported_required_extension)
{
    Gl g = tri();
    g.top = "\"extensionsUsed\": [\"KHR_draco_mesh_compression\"], \"extensionsRequired\": "
            "[\"KHR_materials_emissive_strength\", \"KHR_draco_mesh_compression\"]";
    const char *path = put_gltf("rx.gltf", gl_json(&g));
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
    load_fails(put_gltf("draco.gltf", edit(gl_json(&g), "{\"bufferView\": 1, \"componentType\": 5123",
                                           "{\"componentType\": 5123")),
               1, "draco.gltf: requires extension KHR_draco_mesh_compression, which sfsim does not support");
    /* the same in a GLB, from memory */
    g.nidx = 0;
    g.top = "\"extensionsRequired\": [\"KHR_materials_unlit\"]";
    char *json = gl_json(&g);
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
    load_ok(put_gltf("ux.gltf", gl_json(&g)), &s);
    scene_free(&s);
}

/* Buffer and image uris stay inside the glTF file's folder: '../b.bin' is refused whether or not
 * it exists (neither its existence nor its size is told), a link inside the folder that points
 * out is refused too, a subfolder is fine, and SFSIM_ALLOW_OUTSIDE_URIS=1 lets the file out. */
Test(scene_gltf_errors, uris_stay_in_the_folder)
{
    char a[128], sub[128], bin[160], link[160], inner[160];
    snprintf(a, sizeof a, "%s/a", g_dir);
    snprintf(sub, sizeof sub, "%s/a/sub", g_dir);
    cr_assert_eq(mkdir(a, 0700), 0);
    cr_assert_eq(mkdir(sub, 0700), 0);
    snprintf(bin, sizeof bin, "%s/b.bin", g_dir);
    FILE *f = fopen(bin, "wb");
    cr_assert_not_null(f);
    fwrite(tri_pos, 1, sizeof tri_pos, f);
    fclose(f);
    snprintf(inner, sizeof inner, "%s/a/sub/c.bin", g_dir);
    f = fopen(inner, "wb");
    cr_assert_not_null(f);
    fwrite(tri_pos, 1, sizeof tri_pos, f);
    fclose(f);
    snprintf(link, sizeof link, "%s/a/link.bin", g_dir);
    cr_assert_eq(symlink("../b.bin", link), 0);
    static const char *const uris[] = {"../b.bin", "../nothere.bin", "link.bin", "sub/../../b.bin", "sub/c.bin"};
    unsetenv("SFSIM_ALLOW_OUTSIDE_URIS");
    for (int i = 0; i < 5; i++) {
        Gl g = tri();
        char *j = gl_json(&g), *uri = strstr(j, "data:application"), *end = strchr(uri, '"');
        char *json = NULL;
        cr_assert_gt(asprintf(&json, "%.*s%s%s", (int)(uri - j), j, uris[i], end), 0);
        free(j);
        char path[192], err[1024];
        snprintf(path, sizeof path, "%s/a/x.gltf", g_dir);
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
    Gl g = tri();
    g.uv = uv;
    g.material = "{\"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}}}";
    g.top = "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"../../b.png\"}]";
    char path[192], err[1024];
    snprintf(path, sizeof path, "%s/a/img.gltf", g_dir);
    char *json = gl_json(&g);
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
    Gl g = tri();
    g.pos = pos;
    load_fails(put_gltf("nan.gltf", gl_json(&g)), 1,
               "nan.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 0 is not finite (nan)");
    pos[3] = 1;
    pos[4] = INFINITY;
    Scene s;
    char err[1024], want[512];
    const char *path = put_gltf("inf.gltf", gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want, "%s: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 1 is not finite (inf)",
             path);
    cr_expect_str_eq(err, want);
    pos[4] = 1e30f;
    path = put_gltf("far.gltf", gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    snprintf(want, sizeof want,
             "%s: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 coordinate 1 is 1e+30, beyond the limit of "
             "1e+18 on scene coordinates (docs/scenes.md, Limits)", path);
    cr_expect_str_eq(err, want);
    /* at the limit: loads; a node scale that carries it past: the transformed vertex is named */
    pos[4] = 1e18f * 0.999f;
    load_ok(put_gltf("edge.gltf", gl_json(&g)), &s);
    scene_free(&s);
    g.node = "\"scale\": [1, 10, 1]";
    path = put_gltf("scaled.gltf", gl_json(&g));
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "scaled.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: vertex 1 is (1, 9.99e+18, 0) "
                                   "after the node transforms, beyond the limit of 1e+18 on scene coordinates"),
                       "%s", err);
}

/* ---- sparse accessors (glTF 2.0 Sec. 3.6.2.3) -------------------------------------------- */

/* A triangle whose POSITION accessor (0, 0, 0), (1, 0, 0), (0, 1, 0) carries a sparse part that
 * replaces vertices i0 and i1 by (5, 0, 0) and (0, 7, 0). Without a base bufferView (base = 0)
 * the accessor starts from zeros; vbytes is the sparse values' view length (24 = whole). */
static char *sparse_json(unsigned i0, unsigned i1, int base, int vbytes)
{
    unsigned char buf[64];
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, v[6] = {5, 0, 0, 0, 7, 0};
    const uint16_t idx[2] = {(uint16_t)i0, (uint16_t)i1};
    memcpy(buf, p, 36);
    memcpy(buf + 36, idx, 4);
    memcpy(buf + 40, v, 24);
    char *data = b64(buf, sizeof buf), *json = NULL;
    cr_assert_gt(asprintf(&json,
                          "{\"asset\": {\"version\": \"2.0\"}, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"mesh\": 0}],\n"
                          " \"meshes\": [{\"name\": \"tri\", \"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],\n"
                          " \"accessors\": [{%s\"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\",\n"
                          "   \"sparse\": {\"count\": 2, \"indices\": {\"bufferView\": 1, \"componentType\": 5123},\n"
                          "              \"values\": {\"bufferView\": 2}}}],\n"
                          " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}, {\"buffer\": 0, \"byteOffset\": 36, "
                          "\"byteLength\": 4},\n"
                          "                 {\"buffer\": 0, \"byteOffset\": 40, \"byteLength\": %d}],\n"
                          " \"buffers\": [{\"byteLength\": 64, \"uri\": \"data:application/octet-stream;base64,%s\"}]}\n",
                          base ? "\"bufferView\": 0, " : "", vbytes, data),
                 0);
    free(data);
    return json;
}

Test(scene_geometry, sparse_accessor_substitutes_values)
{
    for (int base = 1; base >= 0; base--) {
        Scene s;
        load_ok(put_gltf(base ? "sp.gltf" : "sp0.gltf", sparse_json(1, 2, base, 24)), &s);
        cr_assert_eq(s.ntris, 1);
        static const float want[9] = {0, 0, 0, 5, 0, 0, 0, 7, 0};
        for (int k = 0; k < 9; k++)
            cr_expect_eq(s.pos[k], want[k], "base %d: coordinate %d is %g, expected %g", base, k, (double)s.pos[k],
                         (double)want[k]);
        scene_free(&s);
    }
    /* only vertex 0 replaced: the others keep the base view's values */
    Scene s;
    load_ok(put_gltf("sp1.gltf", sparse_json(0, 2, 1, 24)), &s);
    expect_near(s.pos[0], 5.0f, 0.0f);
    expect_near(s.pos[3], 1.0f, 0.0f);
    expect_near(s.pos[7], 7.0f, 0.0f);
    scene_free(&s);
}

Test(scene_gltf_errors, sparse_accessor_checked)
{
    load_fails(put_gltf("sd.gltf", sparse_json(2, 1, 1, 24)), 3, "sd.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 1, not greater than the one before (2)", "increase strictly");
    load_fails(put_gltf("se.gltf", sparse_json(1, 1, 1, 24)), 2, "se.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 1, not greater");
    load_fails(put_gltf("so.gltf", sparse_json(1, 3, 0, 24)), 2, "so.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0",
               "sparse index 1 is 3, out of range (accessor count 3)");
    load_fails(put_gltf("sv.gltf", sparse_json(1, 2, 1, 20)), 2,
               "sv.gltf: mesh 0 'tri' primitive 0 POSITION: accessor 0: sparse values",
               "2 elements at offset 0 run past the end of the bufferView");
}

Test(scene_gltf_errors, broken_hierarchy)
{
    Gl g = tri();
    g.nodes = "{\"children\": [0]}, {\"children\": [0]}";
    g.scene_nodes = "1, 2";
    load_fails(put_gltf("two.gltf", gl_json(&g)), 2, "two.gltf: node 0", "more than one parent");
    g.nodes = "{\"children\": [9]}";
    g.scene_nodes = "0, 1";
    load_fails(put_gltf("nine.gltf", gl_json(&g)), 2, "nine.gltf: node 1", "child 9 does not exist");
    /* a cycle is unreachable from the roots, not an endless walk */
    g.nodes = "{\"children\": [2]}, {\"children\": [1]}";
    g.scene_nodes = "0";
    Scene s;
    load_ok(put_gltf("cycle.gltf", gl_json(&g)), &s);
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
    load_fails(put_gltf("deep.gltf", j), 2, "deep.gltf: ", "JSON nested deeper than 512 levels");
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
    Gl g = tri();
    g.prim = "\"material\": 3";
    load_fails(put_gltf("bm.gltf", gl_json(&g)), 2, "bm.gltf: mesh 0 'tri' primitive 0", "material 3 does not exist");
}

/* ---- scene.ini ------------------------------------------------------------------------------ */

TestSuite(scene_ini, .init = tmp_setup, .fini = tmp_teardown);

Test(scene_ini, every_section)
{
    Gl g = tri();
    g.material = "{\"name\": \"paint\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}}";
    put_gltf("a.gltf", gl_json(&g));
    const char *ini = put_file("s.ini", "; a comment\n"
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
    load_ok(ini, &s);
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
    cr_expect_str_eq(needs_of(&s), "glossy,dielectric,spheres,area_lights,punctual_lights,background,ambient");
    /* the bounds take in the spheres */
    expect_near(s.bounds_max[2], 3.5f, EPS);
    expect_near(s.bounds_min[0], -1.0f, EPS);
    scene_free(&s);
}

Test(scene_ini, defaults)
{
    Gl g = tri();
    put_gltf("a.gltf", gl_json(&g));
    Scene s;
    load_ok(put_file("s.ini", "[scene]\ngltf = a.gltf\n"), &s);
    cr_expect_eq(s.render.width, 512);
    cr_expect_eq(s.render.height, 512);
    cr_expect_eq(s.render.spp, 1);
    cr_expect_eq(s.render.max_depth, 3);
    expect_near(s.render.background[0], 0.0f, 0.0f);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_DEFAULT);
    cr_expect_str_eq(s.source, g_files[g_nfiles - 1]);
    scene_free(&s);
}

/* Several glTF files placed with transforms; material indices of the second file follow the first's. */
Test(scene_ini, several_gltf_files_placed)
{
    Gl g = tri();
    g.material = "{\"name\": \"one\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}}";
    put_gltf("a.gltf", gl_json(&g));
    g.material = "{\"name\": \"two\"}";
    put_gltf("b.gltf", gl_json(&g));
    const char *ini = put_file("s.ini", "[scene]\n"
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
    load_ok(ini, &s);
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
    const char *ini = put_file("s.ini", "[material.white]\n"
                                        "base_color = 0.8 0.8 0.8\n"
                                        "[sphere.a]\n"
                                        "center = 0 0 0\n"
                                        "radius = 1\n"
                                        "material = white\n"
                                        "[light.sun]\n"
                                        "type = directional\n"
                                        "direction = 0 -1 0\n");
    Scene s;
    load_ok(ini, &s);
    cr_expect_eq(s.ntris, 0);
    cr_expect_eq(s.nspheres, 1);
    cr_expect_str_eq(needs_of(&s), "lambert,spheres,punctual_lights");
    expect_near(s.camera.look_at[1], 0.0f, EPS);
    scene_free(&s);
}

Test(scene_ini, glossy_override_of_a_gltf_material_keeps_the_rest)
{
    Gl g = tri();
    g.material = "{\"name\": \"floor\", \"pbrMetallicRoughness\": {\"baseColorFactor\": [0.7, 0.6, 0.5, 1],"
                 " \"metallicFactor\": 0}}";
    put_gltf("a.gltf", gl_json(&g));
    Scene s;
    load_ok(
        put_file("s.ini", "[scene]\ngltf = a.gltf\n[material.floor]\nkind = glossy\nroughness = 0.2\nmetallic = 0.3\n"),
        &s);
    cr_expect_eq(s.materials[0].kind, SCENE_MAT_GLOSSY);
    expect_near(s.materials[0].metallic, 0.3f, EPS);
    expect_near(s.materials[0].base_color[0], 0.7f, EPS);
    scene_free(&s);
}

/* ---- malformed scene.ini: file, line and key in every message; every error reported ---------- */

TestSuite(scene_ini_errors, .init = tmp_setup, .fini = tmp_teardown);

static void ini_fails(const char *text, int nsub, ...)
{
    Gl g = tri();
    put_gltf("a.gltf", gl_json(&g));
    const char *path = put_file("bad.ini", text);
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
    Gl g = tri();
    put_gltf("a.gltf", gl_json(&g));
    const char *path = put_file("scene.ini", "[scene]\ngltf = a.gltf\n[camera]\nposition = 0 0 5\nlook_at = 0 0 0\n"
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
              4, ":3: key 'scene.file': unknown key (scene takes: gltf)", ":4: unknown section [camra]",
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
    Gl g = tri();
    g.prim = "\"mode\": 9";
    put_gltf("nine.gltf", gl_json(&g));
    ini_fails("[scene]\ngltf = nine.gltf\n", 2, ":2: key 'scene.gltf': ",
              "nine.gltf: mesh 0 'tri' primitive 0: mode 9 is not a glTF primitive mode");
}

/* A directory is not a scene file (tinygltf would size it as 2^63 bytes; found by fuzzing). */
Test(scene_ini_errors, directory_as_file)
{
    ini_fails("[scene]\ngltf = .\n", 2, ":2: key 'scene.gltf': ", "not a regular file");
    ini_fails("[scene]\ngltf =\n", 1, ":2: key 'scene.gltf': expected the path of a .gltf or .glb file, got ''");
    const char *names[2] = {"dir.gltf", "dir.ini"};
    for (int i = 0; i < 2; i++) {
        char path[128];
        snprintf(path, sizeof path, "%s/%s", g_dir, names[i]);
        cr_assert_eq(mkdir(path, 0700), 0);
        load_fails(path, 2, names[i], "not a regular file");
        rmdir(path);
    }
    /* a buffer whose uri names a directory */
    Gl g = tri();
    char *j = gl_json(&g);
    char *uri = strstr(j, "data:application");
    char *end = strchr(uri, '"');
    memmove(uri, ".", 1);
    memmove(uri + 1, end, strlen(end) + 1);
    load_fails(put_gltf("dirbuf.gltf", j), 1, "dirbuf.gltf: ");
}

Test(scene_ini_errors, no_geometry)
{
    ini_fails("[light.a]\ntype = point\nposition = 0 0 0\n", 1, ": the scene has no geometry");
}

Test(scene_ini_errors, missing_ini)
{
    load_fails("/nonexistent/scene.ini", 2, "/nonexistent/scene.ini", "cannot open");
}

/* Many errors in a small buffer: the ones that fit, then a count of the rest. */
Test(scene_ini_errors, all_errors_reported_or_counted)
{
    char text[8192] = "[render]\n";
    for (int i = 0; i < 100; i++)
        snprintf(text + strlen(text), sizeof text - strlen(text), "bad%d = 1\n", i);
    const char *path = put_file("many.ini", text);
    Scene s;
    char err[512];
    cr_assert_neq(scene_load(path, &s, err, sizeof err), 0);
    cr_expect_not_null(strstr(err, "key 'render.bad0': unknown key"), "%s", err);
    cr_expect_not_null(strstr(err, "more errors"), "%s", err);
    char big[65536];
    cr_assert_neq(scene_load(path, &s, big, sizeof big), 0);
    cr_expect_not_null(strstr(big, "key 'render.bad99': unknown key"), "%s", big);
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
    load_fails("tests/scenes/bad_image_view.glb", 2, "tests/scenes/bad_image_view.glb: image 0",
               "bufferView 2 lies outside buffer 0");
}

Test(scene_files, everything)
{
    Scene s;
    load_ok("tests/scenes/ok_everything.gltf", &s);
    cr_expect_eq(s.ntris, 6);
    cr_expect_eq(s.nlights, 3);
    cr_expect_eq(s.ntextures, 2);
    cr_expect_eq(s.camera.source, SCENE_CAMERA_GLTF);
    cr_expect_eq(s.nemissive, 1, "one of the two lamp triangles sees lit texels");
    cr_expect_str_eq(needs_of(&s), "lambert,glossy,dielectric,textures,area_lights,punctual_lights,alpha,"
                                   "emissive_textures");
    scene_free(&s);
}
