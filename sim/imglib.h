/* sim/imglib.h -- finds and loads sfsim's image library, libsfsim-img.so (sim/imgshim.h), and
 * implements img.h's file functions and heatmap.h through it.
 *
 * Owns: where the library is looked for, loading it (at most once per process, possibly on a
 * background thread started early so that it overlaps other work), and the error when it cannot
 * be loaded. Must not: encode or decode images (the library does) or exit (callers decide).
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

/* Start loading the library on a background thread, for a command that will need images: the
 * load (about 0.2 s of dynamic linking) then overlaps scene loading and simulation, and the
 * first image call waits for it. Returns -1 with a message naming the path when the file is
 * not there (so a command can stop before its work), else 0; a library that is there but does
 * not load is reported by the first image call. The thread is joined at exit. Main thread only. */
int imglib_preload(char *err, size_t errlen);

/* 1 once this process has started loading the library with dlopen (imglib_preload, or a first
 * image call in a binary without the library's objects), else 0. Such a process may end with
 * _exit after flushing stdio, as bin/sfsim does (sim/main.c): exit would run the destructors of
 * OpenImageIO's ~260 libraries, or first wait for a load still running. */
int imglib_dlopened(void);

/* The loaded library (joining the background load if one runs, else loading now), or NULL with
 * "cannot load the image library PATH: why" in err; the answer is the same for the whole run. */
const ImgShim *imglib_get(char *err, size_t errlen);

/* Test hook: dlopen path and check its table; NULL with a message naming path and dlerror().
 * A library that loads is kept loaded. */
const ImgShim *imglib_open(const char *path, char *err, size_t errlen);

#endif
