/* tests/support/shared.h -- the project's test data beside the repository (../shared).
 *
 * A clone on its own has no ../shared: tests that need its scenes are skipped there, each with
 * the reason, and tests/run_criterion.sh counts the skips. Where ../shared exists (our checkouts,
 * CI) nothing is skipped: a file missing from it is a failure. Paths are relative to the
 * repository root, where the tests run.
 */
#ifndef SFSIM_TESTS_SHARED_H
#define SFSIM_TESTS_SHARED_H

#include <stddef.h>

/* 1 when ../shared/scenes/README.md exists. */
int shared_present(void);

/* 1 when the file exists. */
int shared_file_exists(const char *path);

/* The file in ../shared a scene needs: for a scene.ini whose `gltf =` names a file under a
 * `shared/` folder, that file's path (in buf); for a glTF path under `shared/`, the path itself;
 * NULL when the scene lives in the repository. */
const char *shared_scene_need(const char *scene_path, char *buf, size_t len);

/* In a Criterion test: skip it when ../shared is absent, naming what it needs; fail it when
 * ../shared is there but the file is not. */
#define NEEDS_SHARED(path)                                                                            \
    do {                                                                                              \
        if (!shared_present())                                                                        \
            cr_skip_test("needs ../shared (absent): %s", (path));                                     \
        cr_assert(shared_file_exists(path), "../shared is present but %s is missing", (path));        \
    } while (0)

/* NEEDS_SHARED for whatever a scene (scene.ini or glTF path) needs from ../shared, if anything. */
#define NEEDS_SCENE(scene_path)                                                                       \
    do {                                                                                              \
        char need_buf_[4096];                                                                         \
        const char *need_ = shared_scene_need((scene_path), need_buf_, sizeof need_buf_);            \
        if (need_)                                                                                    \
            NEEDS_SHARED(need_);                                                                      \
    } while (0)

#endif
