/* scenes/gltf.h -- the C face of the tinygltf shim (scenes/gltf_*.cpp; gltf_load.cpp
 * holds these two functions, scenes/gltf_internal.hpp says what the other files read).
 *
 * Owns: reading glTF 2.0 (.gltf/.glb) into a Scene. Must not: decide defaults, bounds or needs
 * (scenes/scene.c does, once every source is loaded).
 */
#ifndef SFSIM_GLTF_H
#define SFSIM_GLTF_H

#include <stddef.h>

#include "scene.h"

/* Append the default scene of the glTF file at path to s: its triangles (every vertex through
 * xf, a column-major 4x4 matrix, NULL for identity), materials, textures, punctual lights, and
 * the first camera if s has none yet. Material indices of the new triangles point past the
 * materials s already had. 0, or -1 with "file: element: problem" in err. */
int gltf_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen);
/* The same from memory (the fuzzer, tests): GLB when data starts with "glTF", JSON otherwise;
 * name is used in messages; external files are not read (data URIs and the GLB chunk only). */
int gltf_append_memory(const unsigned char *data, size_t len, const char *name, const double *xf, Scene *s,
                       char *err, size_t errlen);

#endif
