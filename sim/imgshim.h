/* sim/imgshim.h -- the interface between sfsim and its image library, libsfsim-img.so.
 *
 * The image library is sim/img.cpp and sim/heatmap.cpp, the only code that links OpenImageIO.
 * bin/sfsim does not link it: OpenImageIO and the ~260 shared libraries it pulls in cost about
 * 0.2 s of dynamic loading at every start, even for commands that touch no image, so
 * sim/imglib.c loads the library with dlopen when an image is first needed (docs/install.md,
 * docs/performance.md). Test and tool binaries link its objects in instead; sim/imglib.c then
 * uses that copy.
 *
 * Owns: the table of entry points the library exports and its ABI number.
 * Must not: name anything of OpenImageIO (C callers include it) or reach back into the program:
 * the library writes its bytes through an ImgSink, so it links nothing of libsfsim.a.
 */
#ifndef SFSIM_IMGSHIM_H
#define SFSIM_IMGSHIM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Where an encoded file goes: write(ctx, path, bytes, n, err, errlen) returns 0, or -1 with
 * "path: why" in err. sim/imglib.c passes sim/outfile.c's writer with the caller's OutSet. */
typedef struct ImgSink {
    int (*write)(void *ctx, const char *path, const void *bytes, size_t n, char *err, size_t errlen);
    void *ctx;
} ImgSink;

/* Raised whenever a member changes, so that a library from another build is refused. */
#define IMG_SHIM_ABI 1u
/* The name of the table in the library. */
#define IMG_SHIM_SYMBOL "img_shim"

/* The entry points; each has the meaning of the function of the same name in img.h or
 * heatmap.h, with the OutSet replaced by a sink. */
typedef struct ImgShim {
    unsigned abi;  /* IMG_SHIM_ABI */
    size_t size;   /* sizeof(ImgShim) */
    int (*write_linear)(const ImgSink *sink, const char *path, const float *rgb, int width, int height, char *err,
                        size_t errlen);
    int (*write_display)(const ImgSink *sink, const char *path, const float *rgb, int width, int height,
                         float exposure, char *err, size_t errlen);
    int (*write_rgb8)(const ImgSink *sink, const char *path, const float *rgb, int width, int height, char *err,
                      size_t errlen);
    int (*read)(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen);
    int (*heatmap_write)(const ImgSink *sink, const char *path, const double *values, int width, int height,
                         const char *title, const char *unit, char *err, size_t errlen);
    void (*heatmap_set_font)(const char *font_path);
} ImgShim;

/* Inside the library only (img.cpp builds the table from heatmap.cpp's two functions, and
 * heatmap.cpp writes through img.cpp's 8-bit writer). */
int imgshim_write_rgb8(const ImgSink *sink, const char *path, const float *rgb, int width, int height, char *err,
                       size_t errlen);
int imgshim_heatmap_write(const ImgSink *sink, const char *path, const double *values, int width, int height,
                          const char *title, const char *unit, char *err, size_t errlen);
void imgshim_heatmap_set_font(const char *font_path);
/* A display-ready value in [0, 1] as 8 bits: lround(clamp(x, 0, 1) * 255), 0 for NaN and Inf. */
unsigned char imgshim_to_u8(float x);
/* out[i] = imgshim_to_u8(x[i]) for i < n (imgshim_write_rgb8's conversion, vectorized). */
void imgshim_to_u8_n(const float *x, unsigned char *out, size_t n);

#ifdef __cplusplus
}
#endif

#endif
