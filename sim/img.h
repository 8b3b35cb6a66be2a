/* sim/img.h -- images out (EXR through OpenEXR, PNG through libpng: sim/img_write.c, linked into
 * bin/sfsim), images in (through OpenImageIO, in sim/img.cpp, reached through the image library
 * that sim/imglib.c loads when first needed) and image comparison (sim/img_compare.c). img_read
 * fails, with "path: cannot load the image library ..." in err, when that library cannot be
 * loaded (sim/imglib.h); the writers never need it.
 *
 * Owns: file formats, tone mapping for display images, comparison statistics.
 * Must not: render or know about the simulated machine.
 *
 * Pixels are float RGB, row-major, top row first, linear radiance unless said otherwise.
 */
#ifndef SFSIM_IMG_H
#define SFSIM_IMG_H

#include <stddef.h>

#include "../host/outfile.h"

/* The writers below encode in memory and write through host/outfile.c: set NULL puts the file in
 * place at once (whole, or not at all); a set stages it until outset_commit. Errors name path:
 * a file name of another format than the writer's, a size that is not positive or too large to
 * encode, no memory, or the write itself (a full disk, an unwritable folder). */

/* Write linear float RGB as-is: an EXR (path ending in .exr) with float channels R, G, B and
 * ZIP compression, so full float precision. */
int img_write_linear(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                     size_t errlen);
/* Write a display image (a PNG: path ending in .png): value x exposure, clamped to [0, 1],
 * sRGB-encoded, 8 bits per channel; NaN pixels become magenta so they cannot hide. */
int img_write_display(OutSet *set, const char *path, const float *rgb, int width, int height, float exposure,
                      char *err, size_t errlen);
/* Write already display-ready RGB in [0, 1] (a heat map, say) as an 8-bit PNG without any
 * transfer (img_to_u8_n). */
int img_write_rgb8(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                   size_t errlen);
/* A display-ready value in [0, 1] as 8 bits: lround(clamp(x, 0, 1) * 255), 0 for NaN and Inf. */
unsigned char img_to_u8(float x);
/* out[i] = img_to_u8(x[i]) for i < n (img_write_rgb8's conversion, vectorized). */
void img_to_u8_n(const float *x, unsigned char *out, size_t n);
/* Read any format OpenImageIO knows into float RGB (*rgb malloc'ed; grey is replicated, alpha
 * dropped). Values are as stored: linear for EXR, encoded 0..1 for PNG. Only a regular file of at
 * most IMG_MAX_FILE_BYTES is opened (host/infile.h). */
#define IMG_MAX_FILE_BYTES (16ull << 30)
int img_read(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen);

typedef struct ImgCompare {
    double rmse;          /* over all channels of finite pixel pairs */
    double psnr;          /* dB, peak 1.0; INFINITY when identical */
    double max_abs;       /* largest channel difference */
    double mean_a, mean_b;/* image means (finite values) */
    long nan_a, nan_b;    /* channel values that are NaN or Inf */
} ImgCompare;

/* Compare two images of the same size. */
void img_compare(const float *a, const float *b, int width, int height, ImgCompare *out);

/* What a file's values are, from its format's magic bytes: linear radiance (EXR, HDR, PFM),
 * display-encoded (PNG, JPEG, GIF, BMP: sRGB transfer, clamped to 0..1), or unknown (TIFF and
 * the rest, which may hold either; also unreadable files). */
typedef enum ImgEncoding { IMG_ENC_UNKNOWN, IMG_ENC_LINEAR, IMG_ENC_DISPLAY } ImgEncoding;
ImgEncoding img_encoding(const char *path);

#endif
