/* bench/bench_scenes.h -- which of a benchmark's scenes are at hand.
 *
 * Most benchmark scenes are glTF files in ../shared, the project's test data beside the
 * repository; a clone on its own has only the shipped Cornell box. A benchmark skips the scenes
 * it cannot have, saying which and why, and counts them in its summary line. Where ../shared
 * exists a missing file is an error, not a skip.
 */
#ifndef SFSIM_BENCH_SCENES_H
#define SFSIM_BENCH_SCENES_H

#include <stdio.h>

#include "../tests/support/shared.h"

/* 1: run the scene; 0: skip it (said on stdout, *skipped counted); -1: ../shared is there but
 * the scene's file is not (said on stderr). */
static inline int bench_scene_ok(const char *bench, const char *scene, int *skipped)
{
    char buf[4096];
    const char *need = shared_scene_need(scene, buf, sizeof buf);
    if (!need || shared_file_exists(need))
        return 1;
    if (shared_present()) {
        fprintf(stderr, "%s: %s: ../shared is present but %s is missing\n", bench, scene, need);
        return -1;
    }
    printf("%s: skipped %s: needs ../shared (absent): %s\n", bench, scene, need);
    ++*skipped;
    return 0;
}

/* The summary line: how many scenes were skipped. */
static inline void bench_scenes_summary(const char *bench, int skipped, int total)
{
    printf("%s: %d of %d scenes skipped (../shared absent)\n", bench, skipped, total);
}

#endif
