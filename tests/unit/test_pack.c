/* tests/unit/test_pack.c -- packing a scene into scene memory: every record read back through
 * the layout constants, and the generated layout files are current. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../scenes/pack.h"
#include "../../sim/ref_kd.h"
#include "../../sim/run/accel.h"

/* A hand-made scene: two triangles (one emissive), one sphere, two materials, a 2x1 texture,
 * a quad light; camera at the origin looking down -z, 90 degree fov, 2:1 image. */
static void tiny_scene(Scene *s)
{
    memset(s, 0, sizeof *s);
    static float pos[18] = {0, 0, -1, 1, 0, -1, 0, 1, -1, /* tri 0 */
                            2, 2, -3, 3, 2, -3, 2, 3, -3 /* tri 1, emissive */};
    static uint32_t tm[2] = {0, 1};
    static SceneMaterial mats[2];
    static SceneTexture tex[1];
    static float texels[8] = {1.0f, 0.0f, 0.5f, 1.0f, 0.0f, 0.21586f, 1.0f, 0.5f};
    static SceneLight light[1];
    static SceneSphere sph[1];
    static uint32_t emissive[1] = {1};
    memset(mats, 0, sizeof mats);
    mats[0].kind = SCENE_MAT_GLOSSY;
    mats[0].base_color[0] = 0.25f;
    mats[0].base_texture = 0;
    mats[0].roughness = 0.3f;
    mats[0].ior = 1.5f;
    mats[1].kind = SCENE_MAT_LAMBERT;
    mats[1].base_texture = -1;
    mats[1].emission[0] = mats[1].emission[1] = mats[1].emission[2] = 17.0f;
    tex[0] = (SceneTexture){"t", 2, 1, texels};
    memset(light, 0, sizeof light);
    light[0].kind = SCENE_LIGHT_QUAD;
    light[0].position[1] = 5.0f;
    light[0].edge_u[0] = 2.0f;
    light[0].edge_v[2] = 3.0f;
    light[0].color[0] = light[0].color[1] = light[0].color[2] = 1.0f;
    light[0].intensity = 4.0f;
    sph[0] = (SceneSphere){"s", {0, 0, -10}, 2.0f, 0};
    s->ntris = 2;
    s->pos = pos;
    s->tri_material = tm;
    s->materials = mats;
    s->nmaterials = 2;
    s->textures = tex;
    s->ntextures = 1;
    s->lights = light;
    s->nlights = 1;
    s->emissive_tris = emissive;
    s->nemissive = 1;
    s->spheres = sph;
    s->nspheres = 1;
    s->camera = (SceneCamera){{0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90.0f, 0.5f, 2.0f, SCENE_CAMERA_FILE};
    s->render = (SceneRender){64, 32, 4, 3, {0.1f, 0.2f, 0.3f}, {0, 0, 0}};
    float bmin[3] = {-2, -2, -12}, bmax[3] = {3, 3, 0};
    memcpy(s->bounds_min, bmin, sizeof bmin);
    memcpy(s->bounds_max, bmax, sizeof bmax);
    s->needs = SCENE_NEED_GLOSSY | SCENE_NEED_LAMBERT | SCENE_NEED_SPHERES;
}

Test(pack, header_and_records)
{
    Scene s;
    tiny_scene(&s);
    BvhParams bp;
    bvh_default_params(&bp);
    bp.max_leaf_size = 1;
    PackedScene p;
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 4096, &p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_MAGIC)), SM_MAGIC);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_NPRIMS)), 3u);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_NLIGHTS)), 2u);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_WIDTH)), 64u);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_SPP)), 4u);
    cr_expect_float_eq(sm_f32(&p, sm_hdr(&p, SM_HDR_BACKGROUND) + 8), 0.3f, 0.0f);
    cr_expect_float_eq(sm_f32(&p, sm_hdr(&p, SM_HDR_EPSILON)), 12.0f, 0.0f);

    /* Camera: forward -z at focus distance 2; 90 degrees: half height = 2, so CAM_V = 4 up and
     * CAM_U = 8 right (2:1); lens radius 0.25. */
    uint32_t a = sm_hdr(&p, SM_HDR_CAM_W);
    cr_expect_float_eq(sm_f32(&p, a + 8), -2.0f, 1e-6f);
    a = sm_hdr(&p, SM_HDR_CAM_V);
    cr_expect_float_eq(sm_f32(&p, a + 4), 4.0f, 1e-5f);
    a = sm_hdr(&p, SM_HDR_CAM_U);
    cr_expect_float_eq(sm_f32(&p, a), 8.0f, 1e-5f);
    a = sm_hdr(&p, SM_HDR_LENS_U);
    cr_expect_float_eq(sm_f32(&p, a), 0.25f, 1e-7f);

    /* Nodes: the packed tree is the BVH, leaves point at prims in leaf order. */
    uint32_t nodes = sm_u32(&p, sm_hdr(&p, SM_HDR_NODES)), prims = sm_u32(&p, sm_hdr(&p, SM_HDR_PRIMS));
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_NNODES)), p.bvh.nnodes);
    int seen[3] = {0, 0, 0};
    for (uint32_t i = 0; i < p.bvh.nnodes; i++) {
        uint32_t info = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_INFO));
        cr_expect_float_eq(sm_f32(&p, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_BMIN)), p.bvh.nodes[i].bmin[0], 0.0f);
        if (info & SM_NODE_INNER)
            continue;
        cr_expect_eq(info, 1u);
        uint32_t first = sm_u32(&p, sm_rec(nodes, SM_NODE_WORDS, i, SM_NODE_FIRST));
        uint32_t kind = sm_u32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_KIND));
        uint32_t src = sm_u32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_SRC));
        if (kind == 1) {
            seen[2]++;
            cr_expect_float_eq(sm_f32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_V1)), 2.0f, 0.0f);
            cr_expect_float_eq(sm_f32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_V0) + 8), -10.0f, 0.0f);
        } else {
            cr_assert_lt(src, 2u);
            seen[src]++;
            cr_expect_eq(sm_u32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_MAT)), src);
            cr_expect_float_eq(sm_f32(&p, sm_rec(prims, SM_PRIM_WORDS, first, SM_PRIM_V2) + 4), s.pos[9 * src + 7], 0.0f);
        }
    }
    cr_expect(seen[0] == 1 && seen[1] == 1 && seen[2] == 1);

    /* Materials and the texture (sRGB-encoded: linear 0.5 -> 188, 0.21586 -> 128; alpha 0.5 -> 127.5, rounded to even). */
    uint32_t mats = sm_u32(&p, sm_hdr(&p, SM_HDR_MATS));
    cr_expect_eq(sm_u32(&p, sm_rec(mats, SM_MAT_WORDS, 0, SM_MAT_KIND)), (uint32_t)SCENE_MAT_GLOSSY);
    cr_expect_float_eq(sm_f32(&p, sm_rec(mats, SM_MAT_WORDS, 0, SM_MAT_ROUGHNESS)), 0.3f, 0.0f);
    cr_expect_eq((int32_t)sm_u32(&p, sm_rec(mats, SM_MAT_WORDS, 1, SM_MAT_TEX)), -1);
    uint32_t texs = sm_u32(&p, sm_hdr(&p, SM_HDR_TEXS));
    uint32_t texels = sm_u32(&p, sm_rec(texs, SM_TEX_WORDS, 0, SM_TEX_TEXELS));
    cr_expect_eq(sm_u32(&p, sm_rec(texs, SM_TEX_WORDS, 0, SM_TEX_WIDTH)), 2u);
    cr_expect_eq(sm_u32(&p, texels), 255u | 0u << 8 | 188u << 16 | 255u << 24);
    cr_expect_eq(sm_u32(&p, texels + 4), 0u | 128u << 8 | 255u << 16 | 128u << 24);
    uint32_t lut = sm_u32(&p, sm_hdr(&p, SM_HDR_SRGB_LUT));
    cr_expect_float_eq(sm_f32(&p, lut + 4 * 255), 1.0f, 1e-6f);
    cr_expect_float_eq(sm_f32(&p, lut + 4 * 188), 0.5f, 0.003f);

    /* Lights: the quad first, then the emissive triangle with its material's radiance. */
    uint32_t lights = sm_u32(&p, sm_hdr(&p, SM_HDR_LIGHTS));
    cr_expect_eq(sm_u32(&p, sm_rec(lights, SM_LIGHT_WORDS, 0, SM_LIGHT_KIND)), (uint32_t)SM_LIGHT_QUAD);
    cr_expect_float_eq(sm_f32(&p, sm_rec(lights, SM_LIGHT_WORDS, 0, SM_LIGHT_AREA)), 6.0f, 1e-6f);
    cr_expect_float_eq(sm_f32(&p, sm_rec(lights, SM_LIGHT_WORDS, 0, SM_LIGHT_RADIANCE)), 4.0f, 0.0f);
    cr_expect_eq(sm_u32(&p, sm_rec(lights, SM_LIGHT_WORDS, 1, SM_LIGHT_KIND)), (uint32_t)SM_LIGHT_TRIANGLE);
    cr_expect_float_eq(sm_f32(&p, sm_rec(lights, SM_LIGHT_WORDS, 1, SM_LIGHT_AREA)), 0.5f, 1e-6f);
    cr_expect_float_eq(sm_f32(&p, sm_rec(lights, SM_LIGHT_WORDS, 1, SM_LIGHT_RADIANCE)), 17.0f, 0.0f);
    cr_expect_float_eq(sm_f32(&p, sm_rec(lights, SM_LIGHT_WORDS, 1, SM_LIGHT_E1)), 1.0f, 0.0f);
    pack_free(&p);
}

Test(pack, rejects_unaligned_base)
{
    Scene s;
    tiny_scene(&s);
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[256];
    cr_expect_eq(pack_scene(&s, &bp, 100, &p, err, sizeof err), -1);
    cr_expect_str_eq(err, "pack: base address 0x64 is not a multiple of 64");
}

/* The sRGB encoding of texels, computed once per distinct value by the packer, gives every texel
 * the byte the formula gives: 3 x 64 x 64 values, a third of them repeats, in slots that collide. */
static uint8_t encode_srgb(float lin)
{
    float x = lin <= 0.0f ? 0.0f : (lin >= 1.0f ? 1.0f : lin);
    float e = x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)lrintf(e * 255.0f);
}

Test(pack, every_texel_is_encoded_by_the_formula)
{
    enum { SIDE = 64 };
    static float texels[SIDE * SIDE * 4];
    uint32_t st = 99u;
    for (int i = 0; i < SIDE * SIDE * 4; i++) {
        st = st * 1664525u + 1013904223u;
        float v = (float)(st >> 8) / 16777216.0f * 1.2f - 0.1f;
        texels[i] = i % 3 == 2 && i > 0 ? texels[i / 2] : v;
    }
    Scene s;
    tiny_scene(&s);
    SceneTexture tex = {"big", SIDE, SIDE, texels};
    s.textures = &tex;
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[256];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    uint32_t texs = sm_u32(&p, sm_hdr(&p, SM_HDR_TEXS));
    uint32_t at = sm_u32(&p, sm_rec(texs, SM_TEX_WORDS, 0, SM_TEX_TEXELS));
    for (int i = 0; i < SIDE * SIDE; i++) {
        uint32_t word = sm_u32(&p, at + 4u * (uint32_t)i);
        for (int k = 0; k < 3; k++)
            cr_assert_eq(word >> (8 * k) & 0xffu, encode_srgb(texels[4 * i + k]), "texel %d channel %d (%g)", i, k,
                         (double)texels[4 * i + k]);
    }
    pack_free(&p);
}

/* A triangle's box on an axis where two vertices hold zeros of opposite signs keeps the earlier
 * vertex's zero, as the first packer's libm calls did (the node box bytes depend on it): x ties at
 * the minimum (the third vertex at 1), y at the maximum (the third at -1). */
Test(pack, triangle_box_keeps_the_earlier_vertex_zero)
{
    static const int pairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int pr = 0; pr < 3; pr++)
        for (int neg_first = 0; neg_first < 2; neg_first++) {
            Scene s;
            tiny_scene(&s);
            float pos[9] = {1, -1, -1, 1, -1, -1, 1, -1, -1};
            int i = pairs[pr][0], j = pairs[pr][1];
            pos[3 * i] = pos[3 * i + 1] = neg_first ? -0.0f : 0.0f;
            pos[3 * j] = pos[3 * j + 1] = neg_first ? 0.0f : -0.0f;
            s.pos = pos;
            s.ntris = 1;
            s.nemissive = 0;
            s.nspheres = 0;
            BvhParams bp;
            bvh_default_params(&bp);
            PackedScene p;
            char err[256];
            cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
            uint32_t node = sm_u32(&p, sm_hdr(&p, SM_HDR_NODES));
            float lo_x = sm_f32(&p, sm_rec(node, SM_NODE_WORDS, 0, SM_NODE_BMIN));
            float hi_y = sm_f32(&p, sm_rec(node, SM_NODE_WORDS, 0, SM_NODE_BMAX + 1));
            cr_expect_eq(signbit(lo_x) != 0, neg_first, "vertices %d, %d: bmin.x %g", i, j, (double)lo_x);
            cr_expect_eq(signbit(hi_y) != 0, neg_first, "vertices %d, %d: bmax.y %g", i, j, (double)hi_y);
            pack_free(&p);
        }
}

/* pack_add_kd: the Cornell box's kd-tree read back word by word through the layout constants. */
Test(pack, kd_tree_round_trip)
{
    Scene s;
    PackedScene p;
    char err[1024];
    cr_assert_eq(pack_load_file("scenes/cornell/scene.ini", 0, 0, 0, &s, &p, err, sizeof err), 0, "%s", err);
    KdParams kp;
    kd_default_params(&kp);
    KdTree t;
    cr_assert_eq(accel_kd_build(&p, &kp, &t, err, sizeof err), 0, "%s", err);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NODES)), 0u, "no kd-tree before pack_add_kd");
    uint32_t old_size = p.size;
    uint8_t *before = malloc(old_size);
    cr_assert_not_null(before);
    memcpy(before, p.mem, old_size);
    cr_assert_eq(pack_add_kd(&p, &t, err, sizeof err), 0, "%s", err);
    /* Only the header's KD_* words change in the old image. */
    for (uint32_t w = 0; w < old_size / 4; w++)
        if (w < (uint32_t)SM_HDR_KD_NODES || w > (uint32_t)SM_HDR_KD_BMAX + 2)
            cr_expect(memcmp(before + 4 * w, p.mem + 4 * w, 4) == 0, "word %u of the image changed", w);
    free(before);

    uint32_t nodes = sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NODES)), prims = sm_u32(&p, sm_hdr(&p, SM_HDR_KD_PRIMS));
    cr_expect(nodes >= old_size && nodes % 64 == 0, "KDNODE array at 0x%x", nodes);
    cr_expect(prims >= nodes + 8u * t.nnodes && prims % 64 == 0, "leaf lists at 0x%x", prims);
    cr_expect_eq(p.size, prims + 4u * t.nrefs);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NNODES)), t.nnodes);
    cr_expect_eq(p.kd_depth, t.depth);
    for (int k = 0; k < 3; k++) {
        cr_expect_eq(sm_f32(&p, sm_hdr(&p, SM_HDR_KD_BMIN + k)), t.bmin[k]);
        cr_expect_eq(sm_f32(&p, sm_hdr(&p, SM_HDR_KD_BMAX + k)), t.bmax[k]);
    }
    uint32_t leaves = 0;
    for (uint32_t i = 0; i < t.nnodes; i++) {
        const KdNode *n = &t.nodes[i];
        uint32_t info = sm_u32(&p, sm_rec(nodes, SM_KDNODE_WORDS, i, SM_KDNODE_INFO));
        uint32_t split = sm_rec(nodes, SM_KDNODE_WORDS, i, SM_KDNODE_SPLIT);
        cr_expect_eq(info & 3u, n->axis, "node %u: tag %u, axis %u", i, info & 3u, n->axis);
        cr_expect_eq(info >> 2, n->a, "node %u: index %u, expected %u", i, info >> 2, n->a);
        if (n->axis == KD_LEAF) {
            leaves++;
            cr_expect_eq(sm_u32(&p, split), n->count, "leaf %u: count", i);
        } else {
            cr_expect_eq(sm_f32(&p, split), n->split, "node %u: split", i);
        }
    }
    cr_expect_eq(leaves, t.nleaves);
    for (uint32_t r = 0; r < t.nrefs; r++)
        cr_expect_eq(sm_u32(&p, prims + 4u * r), t.prims[r], "leaf-list entry %u", r);
    /* One tree per scene. */
    cr_expect_eq(pack_add_kd(&p, &t, err, sizeof err), -1);
    cr_expect(strstr(err, "already has a kd-tree"), "%s", err);
    kd_free(&t);
    pack_free(&p);
    scene_free(&s);
}

Test(pack, kd_tree_errors)
{
    Scene s;
    tiny_scene(&s);
    BvhParams bp;
    bvh_default_params(&bp);
    PackedScene p;
    char err[512];
    cr_assert_eq(pack_scene(&s, &bp, 0, &p, err, sizeof err), 0, "%s", err);
    uint32_t size = p.size;
    KdParams kp;
    kd_default_params(&kp);
    KdTree t;
    cr_assert_eq(accel_kd_build(&p, &kp, &t, err, sizeof err), 0, "%s", err);
    /* An index past 30 bits cannot be encoded. */
    uint32_t a = t.nodes[0].a;
    t.nodes[0].a = 1u << 30;
    cr_expect_eq(pack_add_kd(&p, &t, err, sizeof err), -1);
    cr_expect(strstr(err, "node 0") && strstr(err, "30 bits"), "%s", err);
    t.nodes[0].a = a;
    /* A tree over other primitives. */
    t.nprims++;
    cr_expect_eq(pack_add_kd(&p, &t, err, sizeof err), -1);
    cr_expect(strstr(err, "primitives"), "%s", err);
    t.nprims--;
    cr_expect_eq(p.size, size);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NODES)), 0u);
    pack_free(&p);
    /* Packed right below 4 GiB, the scene fits but its kd-tree does not. */
    uint32_t base = (uint32_t)(0x100000000ull - ((size + 63u) & ~63u) - 64u);
    cr_assert_eq(pack_scene(&s, &bp, base, &p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(pack_add_kd(&p, &t, err, sizeof err), -1);
    cr_expect(strstr(err, "4 GiB"), "%s", err);
    cr_expect_eq(p.size, size);
    cr_expect_eq(sm_u32(&p, sm_hdr(&p, SM_HDR_KD_NODES)), 0u);
    kd_free(&t);
    pack_free(&p);
}

/* The generated includes and docs must match their sources (`make docs` writes them). */
static void expect_generated(const char *tool, const char *path)
{
    const char *build = getenv("SFSIM_BUILD") ? getenv("SFSIM_BUILD") : "build";
    char cmd[512];
    snprintf(cmd, sizeof cmd, "%s/%s", build, tool);
    FILE *gen = popen(cmd, "r");
    cr_assert_not_null(gen);
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "%s missing", path);
    int a, b;
    long at = 0;
    do {
        a = fgetc(gen);
        b = fgetc(f);
        at++;
    } while (a == b && a != EOF);
    int rc = pclose(gen);
    fclose(f);
    cr_assert_eq(rc, 0, "%s failed (build it with make)", cmd);
    cr_expect_eq(a, b, "%s is stale at byte %ld: run make docs", path, at);
}

Test(pack, generated_layout_files_are_current)
{
    expect_generated("gen_layout inc", "kernels/lib/layout.inc");
    expect_generated("gen_layout md", "docs/scene-memory.md");
}

/* The kernel's shared numbers (stages, workloads, kd variants, material and light kinds) must match
 * the C tables: kernels/lib/kconst.inc is generated by tools/gen_kconst.c. */
Test(pack, generated_kernel_constants_are_current)
{
    expect_generated("gen_kconst", "kernels/lib/kconst.inc");
}
