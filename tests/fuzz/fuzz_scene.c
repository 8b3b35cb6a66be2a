/* tests/fuzz/fuzz_scene.c -- libFuzzer target for the scene loader.
 *
 * Every input is read four ways: as a glTF document from memory (binary when it starts with
 * "glTF", JSON otherwise; odd-sized inputs go through a mirroring placement transform), as a
 * Wavefront OBJ from memory whose mtllib lines all read the same bytes as MTL (the OBJ shim,
 * scenes/obj_load.cpp: its own line checks and triangulation, then tinyobjloader), and as
 * a scene.ini written to a private folder that also holds a small valid glTF file (a.gltf) and
 * the Cornell box (box.glb) for the ini to name. A load must return 0 or -1 with a message; it
 * must not crash, leak, or read past a buffer.
 *
 * Build (clang; tinygltf and stb_image compiled in, so the sanitizers see inside them):
 *   for f in scenes/gltf_*.cpp; do clang++ -std=c++17 -g -O1 -fsanitize=fuzzer-no-link,address,undefined \
 *     -isystem /usr/include/stb -DSFSIM_TINYGLTF_IMPLEMENTATION -c $f -o build/fuzz/$(basename $f .cpp).o; done
 *   clang -std=c11 -g -O1 -D_GNU_SOURCE -fsanitize=fuzzer,address,undefined tests/fuzz/fuzz_scene.c \
 *     scenes/scene.c scenes/scene_file.c build/fuzz/gltf_*.o -o build/fuzz/fuzz_scene -linih -lstdc++ -lm
 * Run:  build/fuzz/fuzz_scene -max_len=65536 -timeout=10 build/fuzz/scene_corpus tests/scenes
 * Must not: depend on the working directory, or read devices (inputs naming /dev, /proc or /sys
 * are not read as ini files).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../scenes/gltf.h"
#include "../../scenes/obj.h"
#include "../../scenes/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

static char g_dir[64], g_ini[128];

/* A triangle with a material, its normals and a light: enough for an ini to override and place. */
static const char a_gltf[] =
    "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0, 1]}],"
    " \"nodes\": [{\"mesh\": 0},"
    " {\"translation\": [0, 2, 0], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}],"
    " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\", \"intensity\": 5}]}},"
    " \"meshes\": [{\"name\": \"tri\", \"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}],"
    " \"materials\": [{\"name\": \"paint\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0}}],"
    " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}],"
    " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],"
    " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,"
    "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}";

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    strcpy(g_dir, "/tmp/sfsim-fuzz-scene-XXXXXX");
    if (!mkdtemp(g_dir))
        abort();
    char path[128];
    snprintf(path, sizeof path, "%s/a.gltf", g_dir);
    FILE *f = fopen(path, "wb");
    if (!f)
        abort();
    fputs(a_gltf, f);
    fclose(f);
    /* box.glb: the Cornell box when the shared scenes are at hand (run from the repo root) */
    FILE *in = fopen("../shared/scenes/cornell-box/CornellBox-Original.glb", "rb");
    if (in) {
        snprintf(path, sizeof path, "%s/box.glb", g_dir);
        FILE *out = fopen(path, "wb");
        char buf[8192];
        size_t n;
        while (out && (n = fread(buf, 1, sizeof buf, in)) > 0)
            fwrite(buf, 1, n, out);
        if (out)
            fclose(out);
        fclose(in);
    }
    snprintf(g_ini, sizeof g_ini, "%s/fuzz.ini", g_dir);
    return 0;
}

static int names_device(const uint8_t *data, size_t size)
{
    static const char *const bad[] = {"/dev", "/proc", "/sys"};
    for (size_t b = 0; b < 3; b++)
        if (memmem(data, size, bad[b], strlen(bad[b])))
            return 1;
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[4096];
    Scene s;

    /* 1. glTF from memory */
    int binary = size >= 4 && memcmp(data, "glTF", 4) == 0;
    static const double mirror[16] = {-1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1};
    scene_init(&s, "fuzz");
    if (gltf_append_memory(data, size, binary ? "fuzz.glb" : "fuzz.gltf", size % 2 ? mirror : NULL, &s, err,
                           sizeof err) == 0) {
        if (scene_finish(&s, err, sizeof err) == 0) {
            char needs[256];
            scene_needs_string(s.needs, needs, sizeof needs);
        }
    } else if (!err[0]) {
        abort(); /* a failure must say why */
    }
    scene_free(&s);

    /* 2. OBJ (+ the same bytes as every MTL it names) from memory */
    scene_init(&s, "fuzz");
    if (obj_append_memory((const char *)data, size, (const char *)data, size, "fuzz.obj", size % 2 ? mirror : NULL,
                          &s, err, sizeof err) == 0) {
        if (scene_finish(&s, err, sizeof err) == 0) {
            char needs[256];
            scene_needs_string(s.needs, needs, sizeof needs);
        }
    } else if (!err[0]) {
        abort(); /* a failure must say why */
    }
    scene_free(&s);

    /* 3. scene.ini */
    if (names_device(data, size))
        return 0;
    FILE *f = fopen(g_ini, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    if (scene_load(g_ini, &s, err, sizeof err) == 0)
        scene_free(&s);
    else if (!err[0])
        abort();
    return 0;
}
