/* tests/support/scene_fixture.h -- small scene inputs for the scene loader's tests
 * (tests/unit/test_scene*.c): a temporary folder per test, one-mesh glTF documents written as JSON
 * with base64 data URIs (so each test shows the exact input it checks), and load helpers.
 *
 * Owns: writing test inputs and loading them with the checks every test makes (the load succeeds,
 * or fails naming what it must). Must not: hold a test's expectations about a loaded scene.
 */
#ifndef SFSIM_TESTS_SCENE_FIXTURE_H
#define SFSIM_TESTS_SCENE_FIXTURE_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "../../scenes/scene.h"

/* ---- temporary files ------------------------------------------------------------------------ */

/* A Criterion suite's .init and .fini: a fresh folder under /tmp, removed with its files. */
void st_tmp_setup(void);
void st_tmp_teardown(void);
/* The folder, and the path of the file written last. */
const char *st_dir(void);
const char *st_last_file(void);
/* Writes text to DIR/name; returns the path (static storage). */
const char *st_put_file(const char *name, const char *text);

/* ---- glTF builder --------------------------------------------------------------------------- */

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

/* Base64 of n bytes (malloc'd). */
char *st_b64(const unsigned char *p, size_t n);
/* A one-mesh glTF (mesh 0 'tri', one primitive) with its buffer as a data URI (malloc'd). */
char *st_gl_json(const Gl *g);
/* json with the first occurrence of `from` replaced by `to` (the input is freed). */
char *st_edit(char *json, const char *from, const char *to);
/* Writes json (freed) to DIR/name; returns the path. */
const char *st_put_gltf(const char *name, char *json);
/* The triangle (0, 0, 0), (1, 0, 0), (0, 1, 0), and a Gl of it alone. */
extern const float st_tri_pos[9];
Gl st_tri(void);
/* A triangle whose POSITION accessor (0, 0, 0), (1, 0, 0), (0, 1, 0) carries a sparse part that
 * replaces vertices i0 and i1 by (5, 0, 0) and (0, 7, 0). Without a base bufferView (base = 0)
 * the accessor starts from zeros; vbytes is the sparse values' view length (24 = whole). */
char *st_sparse_json(unsigned i0, unsigned i1, int base, int vbytes);

/* 2 x 2 RGBA PNG: (128,0,255,64) (255,255,255,255) / (0,0,0,255) (64,64,64,128) */
#define PNG_2X2                                                                                                        \
    "iVBORw0KGgoAAAANSUhEUgAAAAIAAAACCAYAAABytg0kAAAAF0lEQVR4nGNoYPjv8B8IGIDgv4ODQwMAUJAH+ztHQuYAAAAASUVORK5CYII="
/* 16 x 1 RGB PNG: 8 black texels, then 8 white ones */
#define PNG_16X1 "iVBORw0KGgoAAAANSUhEUgAAABAAAAABCAIAAABYG7kIAAAADklEQVR4nGNgwAH+4wAAKxQX6dD14Y0AAAAASUVORK5CYII="


/* ---- loading -------------------------------------------------------------------------------- */

/* Loads a generated glTF; the load must succeed. */
void st_load_ok(const char *path, Scene *s);
/* Loads; the load must fail with every one of the given substrings in the message. */
void st_load_fails(const char *path, int nsub, ...);
/* The scene's needs as a string (static storage). */
char *st_needs_of(const Scene *s);

#define EPS 1e-5f
#define expect_near(a, b, eps)                                                                                         \
    cr_expect(fabsf((float)(a) - (float)(b)) <= (eps), "%s = %g, expected %g", #a, (double)(a), (double)(b))

#endif
