/* tests/support/files.h -- file helpers the Criterion tests share: read a whole file, and check
 * that a generated document is current (its generator's output, byte for byte). */
#ifndef SFSIM_TESTS_FILES_H
#define SFSIM_TESTS_FILES_H

#include <stddef.h>

/* The whole file, NUL-terminated (the test fails when it cannot be read); free() it. */
char *tu_slurp(const char *path);

/* Fails the test unless running the generator `name` (a program in the build folder:
 * $ENV_VAR, else $SFSIM_BUILD/name, else next to the test binary's folder, else build/name)
 * prints exactly the file `doc`. */
void tu_expect_generated(const char *name, const char *env_var, const char *doc);

/* A new empty folder /tmp/sfsim-TAG-XXXXXX (the test fails when it cannot be made); dir must hold
 * len >= 32 + strlen(tag) bytes. Remove it with tu_remove_tree. */
void tu_make_tmpdir(char *dir, size_t len, const char *tag);

/* Writes text to path, replacing it (the test fails when it cannot be written). */
void tu_write_file(const char *path, const char *text);

/* Removes a test's temporary folder and everything in it (a missing folder is fine). */
void tu_remove_tree(const char *dir);

/* A negative test's expected messages: tu_stderr_begin() sends stderr into a temporary file,
 * tu_stderr_end() puts it back and returns what was written meanwhile (free() it), for the test
 * to assert on. The messages are checked, and do not reach make test's output, where they would
 * read as failures. */
void tu_stderr_begin(void);
char *tu_stderr_end(void);

#endif
