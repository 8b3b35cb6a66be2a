/* scenes/obj.h -- the C face of the tinyobjloader shim (scenes/obj_load.cpp).
 *
 * Owns: reading Wavefront OBJ + MTL (the McGuire Computer Graphics Archive's and the Stanford
 * repository's format, which simtrax and Arches read) into a Scene, with the material rules of
 * docs/scenes.md ("OBJ and MTL"). Must not: decide defaults, bounds or needs (scenes/scene.c does,
 * once every source is loaded), or print anything.
 */
#ifndef SFSIM_OBJ_H
#define SFSIM_OBJ_H

#include <stddef.h>

#include "scene.h"

/* Append the faces of the OBJ file at path to s (triangulated; every vertex through xf, a
 * column-major 4x4 matrix, NULL for identity), the materials of the MTL files it names
 * (mtllib, relative to the OBJ file's folder) and their map_Kd textures. Material indices of the
 * new triangles point past the materials s already had. 0, or -1 with "file[:line]: problem" in
 * err; a failed file leaves s's counts as they were. */
int obj_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen);

/* The same from memory (tests, a fuzzer): obj is the OBJ text, mtl (may be NULL) the text every
 * mtllib line reads; name is used in messages. Textures are not read (a map_Kd is an error). */
int obj_append_memory(const char *obj, size_t obj_len, const char *mtl, size_t mtl_len, const char *name,
                      const double *xf, Scene *s, char *err, size_t errlen);

#endif
