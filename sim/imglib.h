/* sim/imglib.h -- finds and loads sfsim's image library, libsfsim-img.so (sim/imgshim.h: the
 * OpenImageIO reader), and implements img.h's img_read through it. The image writers do not
 * need it (sim/img_write.c, sim/heatmap.c), so a `sfsim run` never loads it.
 *
 * Owns: where the library is looked for, loading it (at most once per process), and the error
 * when it cannot be loaded. Must not: encode or decode images (the library does) or exit
 * (callers decide).
 *
 * Where: a binary that links the library's objects in (tests, tools) uses that copy. Otherwise
 * $SFSIM_IMG_LIB if set and not empty, else <binary's folder>/../lib/sfsim/libsfsim-img.so: in a
 * build tree lib/sfsim/ beside bin/ (build/portable/lib/sfsim/ for the portable build), in an
 * installed tree PREFIX/lib/sfsim/ (docs/install.md).
 */
#ifndef SFSIM_IMGLIB_H
#define SFSIM_IMGLIB_H

#include <stddef.h>

#include "imgshim.h"

#define IMGLIB_FILE "libsfsim-img.so"
#define IMGLIB_REL "../lib/sfsim/" IMGLIB_FILE /* from the binary's folder */

/* The library's path into buf (see above). NULL with a message when the binary's own path
 * cannot be read. */
const char *imglib_locate(char *buf, size_t len, char *err, size_t errlen);

/* 1 once this process has started loading the library with dlopen (a first img_read in a binary
 * without the library's objects: `sfsim compare`), else 0. Such a process may end with _exit
 * after flushing stdio, as bin/sfsim does (sim/main.c): exit would run the destructors of
 * OpenImageIO's ~265 libraries. */
int imglib_dlopened(void);

/* The loaded library (loading it now the first time), or NULL with
 * "cannot load the image library PATH: why" in err; the answer is the same for the whole run. */
const ImgShim *imglib_get(char *err, size_t errlen);

/* Test hook: dlopen path and check its table; NULL with a message naming path and dlerror().
 * A library that loads is kept loaded. */
const ImgShim *imglib_open(const char *path, char *err, size_t errlen);

#endif
