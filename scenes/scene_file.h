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

#endif
