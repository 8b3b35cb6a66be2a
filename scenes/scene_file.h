/* scenes/scene_file.h -- the scene.ini format (docs/scenes.md): glTF files placed with
 * transforms, camera, render settings, lights, spheres, material overrides.
 *
 * Owns: reading scene.ini into a Scene prepared by scene_init. Must not: finish the scene
 * (scene_finish does).
 */
#ifndef SFSIM_SCENE_FILE_H
#define SFSIM_SCENE_FILE_H

#include <stddef.h>

#include "scene.h"

/* Every problem is reported (one per line in err) as "FILE:LINE: key 'section.key': message";
 * returns 0, or -1 when there was any. */
int scene_file_load(const char *path, Scene *s, char *err, size_t errlen);

/* Whether a scene can be loaded at all, cheaply (sfsim sweep asks before any point runs): the
 * scene file is a regular file and, for a scene.ini, so is every mesh file it names ([scene] gltf,
 * [gltf.NAME] file). 0, or -1 with one line per missing file ("FILE:LINE: key 'scene.gltf': PATH:
 * cannot open: ...") ending with where to get the scene when [scene] source says. */
int scene_file_check(const char *path, char *err, size_t errlen);

#endif
