/* tools/gen_cornell.c -- writes the project's own Cornell box, scenes/cornell/cornell-box.gltf and
 * cornell-box.bin, from the published measurements (`make docs`; a test fails when they are stale).
 *
 * Source of the geometry: the Cornell University Program of Computer Graphics, "Cornell Box Data"
 * (https://www.graphics.cornell.edu/online/box/data.html): the room, the light and both blocks as
 * quads, in millimetres, camera at (278, 273, -800) looking along +z with a 35 mm lens on a
 * 25 x 25 mm film. Two deliberate departures, both documented in docs/scenes.md: the light sits
 * 0.1 mm below the ceiling (in the data both lie in the plane y = 548.8, which would make the two
 * surfaces coincide), and the block bottoms are left out as in the data (they rest on the floor).
 * The measured reflectance spectra are reduced to linear RGB with the values commonly used by
 * renderers (white 0.725 0.71 0.68, red 0.63 0.065 0.05, green 0.14 0.45 0.091) and the light's
 * spectrum to radiance (17, 12, 4).
 *
 * The glTF is written with cJSON: one mesh per surface group, non-indexed triangles (each quad
 * v0 v1 v2 v3 as v0 v1 v2 and v0 v2 v3, counter-clockwise seen from the side its normal faces),
 * no normals (flat shading uses the geometric normal), metallic 0 and roughness 1 (Lambertian).
 * Usage: gen_cornell OUT_DIR  -> OUT_DIR/cornell-box.gltf, OUT_DIR/cornell-box.bin
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct Quad { double v[4][3]; } Quad;

/* The published quads (mm). Light lowered by 0.1 mm, see above. */
static const Quad light[] = {
    {{{343.0, 548.7, 227.0}, {343.0, 548.7, 332.0}, {213.0, 548.7, 332.0}, {213.0, 548.7, 227.0}}},
};
static const Quad white[] = {
    /* floor */
    {{{552.8, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 559.2}, {549.6, 0.0, 559.2}}},
    /* ceiling */
    {{{556.0, 548.8, 0.0}, {556.0, 548.8, 559.2}, {0.0, 548.8, 559.2}, {0.0, 548.8, 0.0}}},
    /* back wall */
    {{{549.6, 0.0, 559.2}, {0.0, 0.0, 559.2}, {0.0, 548.8, 559.2}, {556.0, 548.8, 559.2}}},
    /* short block */
    {{{130.0, 165.0, 65.0}, {82.0, 165.0, 225.0}, {240.0, 165.0, 272.0}, {290.0, 165.0, 114.0}}},
    {{{290.0, 0.0, 114.0}, {290.0, 165.0, 114.0}, {240.0, 165.0, 272.0}, {240.0, 0.0, 272.0}}},
    {{{130.0, 0.0, 65.0}, {130.0, 165.0, 65.0}, {290.0, 165.0, 114.0}, {290.0, 0.0, 114.0}}},
    {{{82.0, 0.0, 225.0}, {82.0, 165.0, 225.0}, {130.0, 165.0, 65.0}, {130.0, 0.0, 65.0}}},
    {{{240.0, 0.0, 272.0}, {240.0, 165.0, 272.0}, {82.0, 165.0, 225.0}, {82.0, 0.0, 225.0}}},
    /* tall block */
    {{{423.0, 330.0, 247.0}, {265.0, 330.0, 296.0}, {314.0, 330.0, 456.0}, {472.0, 330.0, 406.0}}},
    {{{423.0, 0.0, 247.0}, {423.0, 330.0, 247.0}, {472.0, 330.0, 406.0}, {472.0, 0.0, 406.0}}},
    {{{472.0, 0.0, 406.0}, {472.0, 330.0, 406.0}, {314.0, 330.0, 456.0}, {314.0, 0.0, 456.0}}},
    {{{314.0, 0.0, 456.0}, {314.0, 330.0, 456.0}, {265.0, 330.0, 296.0}, {265.0, 0.0, 296.0}}},
    {{{265.0, 0.0, 296.0}, {265.0, 330.0, 296.0}, {423.0, 330.0, 247.0}, {423.0, 0.0, 247.0}}},
};
static const Quad red[] = { /* left wall, seen from the camera */
    {{{552.8, 0.0, 0.0}, {549.6, 0.0, 559.2}, {556.0, 548.8, 559.2}, {556.0, 548.8, 0.0}}},
};
static const Quad green[] = { /* right wall */
    {{{0.0, 0.0, 559.2}, {0.0, 0.0, 0.0}, {0.0, 548.8, 0.0}, {0.0, 548.8, 559.2}}},
};

typedef struct Group {
    const char *name;
    const Quad *quads;
    int nquads;
    double color[3];
    double emissive[3]; /* radiance; 0 = not an emitter */
} Group;

#define N(a) (int)(sizeof a / sizeof a[0])
static const Group groups[] = {
    {"white", white, N(white), {0.725, 0.71, 0.68}, {0, 0, 0}},
    {"red", red, N(red), {0.63, 0.065, 0.05}, {0, 0, 0}},
    {"green", green, N(green), {0.14, 0.45, 0.091}, {0, 0, 0}},
    {"light", light, N(light), {0.78, 0.78, 0.78}, {17.0, 12.0, 4.0}},
};

static cJSON *numbers(const double *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; i < n; i++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(v[i]));
    return a;
}

static int write_all(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        return -1;
    }
    int bad = fwrite(data, 1, n, f) != n;
    bad |= fclose(f) != 0;
    if (bad)
        fprintf(stderr, "gen_cornell: %s: write failed\n", path);
    return bad ? -1 : 0;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: gen_cornell OUT_DIR\n");
        return 2;
    }
    int ntri = 0;
    for (int g = 0; g < N(groups); g++)
        ntri += 2 * groups[g].nquads;
    float *pos = malloc((size_t)ntri * 9 * sizeof *pos);
    if (!pos)
        return 1;

    cJSON *root = cJSON_CreateObject();
    cJSON *asset = cJSON_AddObjectToObject(root, "asset");
    cJSON_AddStringToObject(asset, "version", "2.0");
    cJSON_AddStringToObject(asset, "generator", "sfsim tools/gen_cornell.c");
    cJSON_AddStringToObject(asset, "copyright",
                            "Geometry: Cornell University Program of Computer Graphics, Cornell Box Data");
    cJSON *used = cJSON_AddArrayToObject(root, "extensionsUsed");
    cJSON_AddItemToArray(used, cJSON_CreateString("KHR_materials_emissive_strength"));
    cJSON_AddNumberToObject(root, "scene", 0);
    cJSON *scenes = cJSON_AddArrayToObject(root, "scenes");
    cJSON *scene = cJSON_CreateObject();
    cJSON_AddItemToArray(scenes, scene);
    cJSON_AddStringToObject(scene, "name", "Cornell box");
    cJSON *snodes = cJSON_AddArrayToObject(scene, "nodes");
    cJSON *nodes = cJSON_AddArrayToObject(root, "nodes");
    cJSON *meshes = cJSON_AddArrayToObject(root, "meshes");
    cJSON *mats = cJSON_AddArrayToObject(root, "materials");
    cJSON *accs = cJSON_AddArrayToObject(root, "accessors");
    cJSON *views = cJSON_AddArrayToObject(root, "bufferViews");

    int t = 0;
    for (int g = 0; g < N(groups); g++) {
        const Group *gr = &groups[g];
        int first = t;
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (int q = 0; q < gr->nquads; q++) {
            static const int tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
            for (int k = 0; k < 2; k++, t++)
                for (int c = 0; c < 3; c++)
                    for (int a = 0; a < 3; a++) {
                        double x = gr->quads[q].v[tri[k][c]][a];
                        pos[9 * t + 3 * c + a] = (float)x;
                        lo[a] = fmin(lo[a], x);
                        hi[a] = fmax(hi[a], x);
                    }
        }
        int n = t - first;

        cJSON *view = cJSON_CreateObject();
        cJSON_AddNumberToObject(view, "buffer", 0);
        cJSON_AddNumberToObject(view, "byteOffset", (double)first * 36);
        cJSON_AddNumberToObject(view, "byteLength", (double)n * 36);
        cJSON_AddNumberToObject(view, "target", 34962);
        cJSON_AddItemToArray(views, view);

        cJSON *acc = cJSON_CreateObject();
        cJSON_AddNumberToObject(acc, "bufferView", g);
        cJSON_AddNumberToObject(acc, "componentType", 5126);
        cJSON_AddNumberToObject(acc, "count", (double)n * 3);
        cJSON_AddStringToObject(acc, "type", "VEC3");
        cJSON_AddItemToObject(acc, "min", numbers(lo, 3));
        cJSON_AddItemToObject(acc, "max", numbers(hi, 3));
        cJSON_AddItemToArray(accs, acc);

        cJSON *mat = cJSON_CreateObject();
        cJSON_AddStringToObject(mat, "name", gr->name);
        cJSON *pbr = cJSON_AddObjectToObject(mat, "pbrMetallicRoughness");
        double rgba[4] = {gr->color[0], gr->color[1], gr->color[2], 1.0};
        cJSON_AddItemToObject(pbr, "baseColorFactor", numbers(rgba, 4));
        cJSON_AddNumberToObject(pbr, "metallicFactor", 0);
        cJSON_AddNumberToObject(pbr, "roughnessFactor", 1);
        double strength = fmax(gr->emissive[0], fmax(gr->emissive[1], gr->emissive[2]));
        if (strength > 0) {
            double e[3] = {gr->emissive[0] / strength, gr->emissive[1] / strength, gr->emissive[2] / strength};
            cJSON_AddItemToObject(mat, "emissiveFactor", numbers(e, 3));
            cJSON *ext = cJSON_AddObjectToObject(mat, "extensions");
            cJSON *es = cJSON_AddObjectToObject(ext, "KHR_materials_emissive_strength");
            cJSON_AddNumberToObject(es, "emissiveStrength", strength);
        }
        cJSON_AddItemToArray(mats, mat);

        cJSON *mesh = cJSON_CreateObject();
        cJSON_AddStringToObject(mesh, "name", gr->name);
        cJSON *prims = cJSON_AddArrayToObject(mesh, "primitives");
        cJSON *prim = cJSON_CreateObject();
        cJSON *attrs = cJSON_AddObjectToObject(prim, "attributes");
        cJSON_AddNumberToObject(attrs, "POSITION", g);
        cJSON_AddNumberToObject(prim, "material", g);
        cJSON_AddNumberToObject(prim, "mode", 4);
        cJSON_AddItemToArray(prims, prim);
        cJSON_AddItemToArray(meshes, mesh);

        cJSON *node = cJSON_CreateObject();
        cJSON_AddStringToObject(node, "name", gr->name);
        cJSON_AddNumberToObject(node, "mesh", g);
        cJSON_AddItemToArray(nodes, node);
        cJSON_AddItemToArray(snodes, cJSON_CreateNumber(g));
    }

    cJSON *buffers = cJSON_AddArrayToObject(root, "buffers");
    cJSON *buf = cJSON_CreateObject();
    cJSON_AddStringToObject(buf, "uri", "cornell-box.bin");
    cJSON_AddNumberToObject(buf, "byteLength", (double)ntri * 36);
    cJSON_AddItemToArray(buffers, buf);

    char *json = cJSON_Print(root);
    char path[4096];
    int rc = 0;
    snprintf(path, sizeof path, "%s/cornell-box.gltf", argv[1]);
    size_t len = strlen(json);
    char *text = malloc(len + 2);
    if (!text)
        return 1;
    memcpy(text, json, len);
    text[len] = '\n';
    if (write_all(path, text, len + 1))
        rc = 1;
    free(text);
    snprintf(path, sizeof path, "%s/cornell-box.bin", argv[1]);
    if (write_all(path, pos, (size_t)ntri * 36))
        rc = 1;
    cJSON_free(json);
    cJSON_Delete(root);
    free(pos);
    return rc;
}
