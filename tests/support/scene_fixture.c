/* tests/support/scene_fixture.c -- small scene inputs written by the scene tests (scene_fixture.h).
 *
 * Owns: the temporary folder and the files written into it, the glTF builder, the load helpers.
 * Must not: assert anything about what a load produces (each test does).
 */
#include "scene_fixture.h"

#include <criterion/criterion.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* ---- temporary files ------------------------------------------------------------------------ */

static char g_dir[64];
static char g_files[64][160];
static int g_nfiles;

const char *st_dir(void) { return g_dir; }

const char *st_last_file(void) { return g_files[g_nfiles - 1]; }

void st_tmp_setup(void)
{
    strcpy(g_dir, "/tmp/sfsim-scene-XXXXXX");
    cr_assert_not_null(mkdtemp(g_dir));
    g_nfiles = 0;
}

void st_tmp_teardown(void)
{
    for (int i = 0; i < g_nfiles; i++)
        unlink(g_files[i]);
    rmdir(g_dir);
}

const char *st_put_file(const char *name, const char *text)
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

char *st_b64(const unsigned char *p, size_t n)
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

char *st_gl_json(const Gl *g)
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
    char *data = st_b64(buf, len), *json = NULL;
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

char *st_edit(char *json, const char *from, const char *to)
{
    char *at = strstr(json, from);
    cr_assert_not_null(at, "'%s' not in the generated glTF", from);
    char *out = NULL;
    cr_assert_gt(asprintf(&out, "%.*s%s%s", (int)(at - json), json, to, at + strlen(from)), 0);
    free(json);
    return out;
}

const char *st_put_gltf(const char *name, char *json)
{
    const char *p = st_put_file(name, json);
    free(json);
    return p;
}

const float st_tri_pos[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};

Gl st_tri(void)
{
    Gl g;
    memset(&g, 0, sizeof g);
    g.nv = 3;
    g.pos = st_tri_pos;
    return g;
}

void st_load_ok(const char *path, Scene *s)
{
    char err[2048];
    int rc = scene_load(path, s, err, sizeof err);
    cr_assert_eq(rc, 0, "load failed: %s", err);
}

void st_load_fails(const char *path, int nsub, ...)
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

char *st_needs_of(const Scene *s)
{
    static char buf[256];
    scene_needs_string(s->needs, buf, sizeof buf);
    return buf;
}

/* A triangle whose POSITION accessor (0, 0, 0), (1, 0, 0), (0, 1, 0) carries a sparse part that
 * replaces vertices i0 and i1 by (5, 0, 0) and (0, 7, 0). Without a base bufferView (base = 0)
 * the accessor starts from zeros; vbytes is the sparse values' view length (24 = whole). */
char *st_sparse_json(unsigned i0, unsigned i1, int base, int vbytes)
{
    unsigned char buf[64];
    const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0}, v[6] = {5, 0, 0, 0, 7, 0};
    const uint16_t idx[2] = {(uint16_t)i0, (uint16_t)i1};
    memcpy(buf, p, 36);
    memcpy(buf + 36, idx, 4);
    memcpy(buf + 40, v, 24);
    char *data = st_b64(buf, sizeof buf), *json = NULL;
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
