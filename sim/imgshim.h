/* sim/imgshim.h -- the interface between sfsim and its image library, libsfsim-img.so.
 *
 * The image library is sim/img.cpp, the only code that links OpenImageIO, and since 2026-12 it
 * only reads images (`sfsim compare`, img_read): sfsim writes its EXR and PNG files through
 * OpenEXR and libpng, and draws cost.png with FreeType's text, in code linked into bin/sfsim
 * (sim/img_write.c, sim/heatmap.c). bin/sfsim does not link OpenImageIO: it and the ~265 shared
 * libraries it pulls in cost 120-250 ms of CPU in dynamic loading, so sim/imglib.c loads the
 * library with dlopen when an image is first read, and a `sfsim run` never loads it
 * (docs/install.md, docs/performance.md "Start-up"). Test and tool binaries link its objects in
 * instead; sim/imglib.c then uses that copy.
 *
 * Owns: the table of entry points the library exports and its ABI number.
 * Must not: name anything of OpenImageIO (C callers include it) or reach back into the program:
 * the library links nothing of libsfsim.a.
 */
#ifndef SFSIM_IMGSHIM_H
#define SFSIM_IMGSHIM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Raised whenever a member changes, so that a library from another build is refused. 2: the
 * writers and the heat map left the table (2026-12). */
#define IMG_SHIM_ABI 2u
/* The name of the table in the library. */
#define IMG_SHIM_SYMBOL "img_shim"

/* The entry points; each has the meaning of the function of the same name in img.h. */
typedef struct ImgShim {
    unsigned abi;  /* IMG_SHIM_ABI */
    size_t size;   /* sizeof(ImgShim) */
    int (*read)(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen);
} ImgShim;

#ifdef __cplusplus
}
#endif

#endif
