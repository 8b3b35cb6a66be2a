/* sim/img_write.c -- the image writers of img.h: frame.exr and frame.partial.exr through
 * OpenEXR's C library (OpenEXRCore), frame.png and cost.png through libpng. Linked into
 * bin/sfsim itself: these libraries (with zlib) load in about a millisecond, where OpenImageIO,
 * which wrote the files until 2026-12, brought ~265 shared libraries and 120-250 ms of dynamic
 * loading into every `sfsim run` (docs/performance.md, "Start-up"). OpenImageIO is still the
 * reader (img_read, through the image library: sim/imglib.c).
 *
 * Owns: encoding into memory (EXR: float R, G, B, ZIP compression, scanlines, as OpenImageIO
 * wrote them; PNG: 8-bit RGB, row filter Sub, zlib level 1), the display transfer documented in
 * img.h, the 8-bit conversion. Must not: open files itself (the bytes go through
 * host/outfile.c, which writes them whole or not at all and counts the writes for its fault
 * hook), or exit.
 */
#include <errno.h>
#include <math.h>
#include <openexr.h>
#include <png.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "img.h"

/* A growing buffer the encoders write into. */
typedef struct Mem {
    unsigned char *data;
    size_t n, cap;
    int oom;
    char why[256]; /* the encoder's own message (OpenEXR's error handler, libpng's png_error) */
} Mem;

static int mem_put(Mem *m, size_t at, const void *bytes, size_t n)
{
    if (n > SIZE_MAX - at) {
        m->oom = 1;
        return -1;
    }
    if (at + n > m->cap) {
        size_t cap = m->cap ? m->cap : 1 << 16;
        while (cap < at + n)
            cap = cap > SIZE_MAX / 2 ? at + n : cap * 2;
        unsigned char *d = realloc(m->data, cap);
        if (!d) {
            m->oom = 1;
            return -1;
        }
        m->data = d;
        m->cap = cap;
    }
    memcpy(m->data + at, bytes, n);
    if (at + n > m->n)
        m->n = at + n;
    return 0;
}

static int fail(char *err, size_t errlen, const char *path, const char *why)
{
    snprintf(err, errlen, "%s: %s", path, why && *why ? why : "image error");
    return -1;
}

/* The file name's extension, compared without case: which encoder a path selects. */
static int has_ext(const char *path, const char *ext)
{
    size_t n = strlen(path), e = strlen(ext);
    return n > e && strcasecmp(path + n - e, ext) == 0 && path[n - e - 1] != '/';
}

/* Sizes every writer accepts: positive, and few enough pixels that the byte counts below fit. */
static int check_size(const char *path, int w, int h, char *err, size_t errlen)
{
    char why[160];
    if (w <= 0 || h <= 0) {
        snprintf(why, sizeof why, "image size %d x %d: width and height must be positive", w, h);
        return fail(err, errlen, path, why);
    }
    if ((uint64_t)w * (uint64_t)h > (uint64_t)(SIZE_MAX / 16) || (uint64_t)w * 16 > INT32_MAX) {
        snprintf(why, sizeof why, "image size %d x %d is too large to encode", w, h);
        return fail(err, errlen, path, why);
    }
    return 0;
}

/* ---- EXR (OpenEXRCore) ------------------------------------------------------------------------ */

static int64_t exr_mem_write(exr_const_context_t ctx, void *user, const void *buf, uint64_t sz, uint64_t offset,
                             exr_stream_error_func_ptr_t error_cb)
{
    Mem *m = user;
    if (offset > SIZE_MAX || sz > SIZE_MAX || mem_put(m, (size_t)offset, buf, (size_t)sz) != 0) {
        error_cb(ctx, EXR_ERR_OUT_OF_MEMORY, "out of memory encoding the image");
        return -1;
    }
    return (int64_t)sz;
}

/* OpenEXR's messages would go to stderr by default; keep the first for the caller's message. */
static void exr_on_error(exr_const_context_t ctx, exr_result_t code, const char *msg)
{
    void *user = NULL;
    if (exr_get_user_data(ctx, &user) != EXR_ERR_SUCCESS || !user)
        return;
    Mem *m = user;
    if (!m->why[0])
        snprintf(m->why, sizeof m->why, "%s", msg ? msg : exr_get_default_error_message(code));
}

/* rgb (w x h float RGB) as a scanline EXR with float channels R, G, B and ZIP compression (16
 * scanlines per chunk), what OpenImageIO's EXR writer produced by default. 0, or -1 with m->why. */
static int encode_exr(Mem *m, const char *path, const float *rgb, int w, int h)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.user_data = m;
    init.write_fn = exr_mem_write;
    init.error_handler_fn = exr_on_error;
    exr_context_t ctx = NULL;
    exr_encode_pipeline_t enc;
    int have_enc = 0, part = 0, lines = 0, rc = -1;
    memset(&enc, 0, sizeof enc);
    /* With a write function the path only names the file in OpenEXR's messages. */
    exr_result_t r = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (r == EXR_ERR_SUCCESS)
        r = exr_add_part(ctx, "", EXR_STORAGE_SCANLINE, &part);
    if (r == EXR_ERR_SUCCESS)
        r = exr_initialize_required_attr_simple(ctx, part, w, h, EXR_COMPRESSION_ZIP);
    static const char *const names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3 && r == EXR_ERR_SUCCESS; c++)
        r = exr_add_channel(ctx, part, names[c], EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (r == EXR_ERR_SUCCESS)
        r = exr_write_header(ctx);
    if (r == EXR_ERR_SUCCESS)
        r = exr_get_scanlines_per_chunk(ctx, part, &lines);
    for (int y = 0; y < h && r == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t chunk;
        r = exr_write_scanline_chunk_info(ctx, part, y, &chunk);
        if (r != EXR_ERR_SUCCESS)
            break;
        r = have_enc ? exr_encoding_update(ctx, part, &chunk, &enc) : exr_encoding_initialize(ctx, part, &chunk, &enc);
        if (r != EXR_ERR_SUCCESS)
            break;
        /* The channels come sorted by name (B, G, R): each reads its own component of rgb. */
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *ch = &enc.channels[c];
            int k = ch->channel_name[0] == 'R' ? 0 : ch->channel_name[0] == 'G' ? 1 : 2;
            ch->encode_from_ptr = (const uint8_t *)(rgb + ((size_t)chunk.start_y * (size_t)w) * 3 + k);
            ch->user_pixel_stride = 3 * (int32_t)sizeof(float);
            ch->user_line_stride = 3 * (int32_t)sizeof(float) * w;
            ch->user_bytes_per_element = sizeof(float);
            ch->user_data_type = EXR_PIXEL_FLOAT;
        }
        if (!have_enc) {
            have_enc = 1;
            r = exr_encoding_choose_default_routines(ctx, part, &enc);
        }
        if (r == EXR_ERR_SUCCESS)
            r = exr_encoding_run(ctx, part, &enc);
    }
    if (have_enc)
        exr_encoding_destroy(ctx, &enc);
    if (r == EXR_ERR_SUCCESS)
        rc = 0;
    else if (!m->why[0])
        snprintf(m->why, sizeof m->why, "%s", exr_get_default_error_message(r));
    /* exr_finish writes the chunk offset table; a failure there is a failure of the file. */
    if (ctx && exr_finish(&ctx) != EXR_ERR_SUCCESS && rc == 0) {
        rc = -1;
        if (!m->why[0])
            snprintf(m->why, sizeof m->why, "cannot finish the EXR file");
    }
    if (m->oom) {
        snprintf(m->why, sizeof m->why, "out of memory encoding the image");
        rc = -1;
    }
    return rc;
}

/* ---- PNG (libpng) ----------------------------------------------------------------------------- */

static void png_mem_write(png_structp png, png_bytep data, size_t n)
{
    Mem *m = png_get_io_ptr(png);
    if (mem_put(m, m->n, data, n) != 0)
        png_error(png, "out of memory encoding the image");
}

static void png_mem_flush(png_structp png)
{
    (void)png;
}

static void png_on_error(png_structp png, png_const_charp msg)
{
    Mem *m = png_get_error_ptr(png);
    if (!m->why[0])
        snprintf(m->why, sizeof m->why, "%s", msg);
    png_longjmp(png, 1);
}

static void png_on_warning(png_structp png, png_const_charp msg)
{
    (void)png, (void)msg; /* nothing the caller could act on */
}

/* px (w x h 8-bit RGB) as a PNG. One row filter (Sub) rather than libpng's trial of all five per
 * row, and zlib's fastest level, the settings OpenImageIO's writer was given (png:filter,
 * png:compressionLevel): the pixels are what matter (the same-outputs table hashes pixels), and
 * the defaults took 170 M instructions of a 32 x 32 run's cost.png (docs/performance.md). */
static int encode_png(Mem *m, const unsigned char *px, int w, int h)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, m, png_on_error, png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_write_struct(&png, NULL);
        snprintf(m->why, sizeof m->why, "out of memory encoding the image");
        return -1;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return -1;
    }
    png_set_write_fn(png, m, png_mem_write, png_mem_flush);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
    png_set_compression_level(png, 1);
    png_write_info(png, info);
    for (int y = 0; y < h; y++)
        png_write_row(png, px + (size_t)y * (size_t)w * 3);
    png_write_end(png, info);
    png_destroy_write_struct(&png, &info);
    return 0;
}

/* ---- the writers ------------------------------------------------------------------------------ */

static int finish(OutSet *set, const char *path, Mem *m, int rc, char *err, size_t errlen)
{
    if (rc == 0)
        rc = outfile_write_file(set, path, m->data, m->n, err, errlen);
    else
        fail(err, errlen, path, m->why);
    free(m->data);
    return rc;
}

static int write_u8(OutSet *set, const char *path, const unsigned char *px, int w, int h, char *err, size_t errlen)
{
    Mem m = {0};
    return finish(set, path, &m, encode_png(&m, px, w, h), err, errlen);
}

/* The writers below accept the file names of the format they write; anything else is refused by
 * name before any work (OpenImageIO, the writer until 2026-12, chose its format by extension). */
static int check_png(const char *path, int w, int h, char *err, size_t errlen)
{
    if (!has_ext(path, ".png"))
        return fail(err, errlen, path, "no image writer for this file name (display images are written as .png)");
    if (check_size(path, w, h, err, errlen) != 0)
        return -1;
    if ((uint32_t)w > PNG_USER_WIDTH_MAX || (uint32_t)h > PNG_USER_HEIGHT_MAX) {
        char why[160];
        snprintf(why, sizeof why, "image size %d x %d is too large for PNG (at most %u x %u)", w, h,
                 (unsigned)PNG_USER_WIDTH_MAX, (unsigned)PNG_USER_HEIGHT_MAX);
        return fail(err, errlen, path, why);
    }
    return 0;
}

int img_write_linear(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                     size_t errlen)
{
    if (!has_ext(path, ".exr"))
        return fail(err, errlen, path, "no image writer for this file name (linear images are written as .exr)");
    if (check_size(path, width, height, err, errlen) != 0)
        return -1;
    Mem m = {0};
    return finish(set, path, &m, encode_exr(&m, path, rgb, width, height), err, errlen);
}

static float srgb_encode(float x)
{
    return x <= 0.0031308f ? 12.92f * x : 1.055f * powf(x, 1.0f / 2.4f) - 0.055f;
}

/* The 8-bit buffer of a width x height PNG at path, after its checks; NULL with a message. */
static unsigned char *png_pixels(const char *path, int width, int height, char *err, size_t errlen)
{
    if (check_png(path, width, height, err, errlen) != 0)
        return NULL;
    unsigned char *px = malloc((size_t)width * (size_t)height * 3);
    if (!px)
        fail(err, errlen, path, "out of memory encoding the image");
    return px;
}

/* px (from png_pixels) encoded and written, then freed. */
static int write_png_pixels(OutSet *set, const char *path, unsigned char *px, int width, int height, char *err,
                            size_t errlen)
{
    int rc = write_u8(set, path, px, width, height, err, errlen);
    free(px);
    return rc;
}

int img_write_display(OutSet *set, const char *path, const float *rgb, int width, int height, float exposure,
                      char *err, size_t errlen)
{
    unsigned char *px = png_pixels(path, width, height, err, errlen);
    if (!px)
        return -1;
    size_t n = (size_t)width * (size_t)height * 3;
    for (size_t i = 0; i < n; i += 3) {
        int bad = !isfinite(rgb[i]) || !isfinite(rgb[i + 1]) || !isfinite(rgb[i + 2]);
        for (int c = 0; c < 3; c++) {
            float v = bad ? (c == 1 ? 0.0f : 1.0f) : fminf(fmaxf(rgb[i + c] * exposure, 0.0f), 1.0f);
            px[i + c] = (unsigned char)lroundf((bad ? v : srgb_encode(v)) * 255.0f);
        }
    }
    return write_png_pixels(set, path, px, width, height, err, errlen);
}

int img_write_rgb8(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                   size_t errlen)
{
    unsigned char *px = png_pixels(path, width, height, err, errlen);
    if (!px)
        return -1;
    img_to_u8_n(rgb, px, (size_t)width * (size_t)height * 3);
    return write_png_pixels(set, path, px, width, height, err, errlen);
}

/* ---- the 8-bit conversion --------------------------------------------------------------------- */

/* Equal to lround(fmin(fmax(x, 0), 1) * 255) for finite x, else 0, for every float x
 * (tests/io/test_imglib.c), without the three library calls per channel. 0 < x <= FLT_MAX
 * is b - 1 < 0x7f7fffff on x's bits (false for zeros, negatives, Inf and NaN). Rounding y (in
 * [0, 255]) half up without leaving float: r = trunc(y), and y - r is exact (r >= y / 2 once
 * y >= 1; r = 0 below), so r + (y - r >= 0.5) is what lround gives; y + 0.5f would not do,
 * 0.49999997f + 0.5f rounds up to 1. */
unsigned char img_to_u8(float x)
{
    uint32_t b;
    memcpy(&b, &x, sizeof b);
    float c = b - 1u < 0x7f7fffffu ? (x < 1.0f ? x : 1.0f) : 0.0f;
    float y = c * 255.0f;
    int r = (int)y;
    return (unsigned char)(r + (y - (float)r >= 0.5f));
}

/* img_to_u8 eight channels at a time, in GCC's vector extensions (SSE pairs in the portable
 * build): -O2 leaves the scalar loop alone, and cost.png's ~1.3 M channels took 24 M
 * instructions one at a time (docs/performance.md, "Start-up"). The same operations, lane by
 * lane, so the same bytes (every float is checked in tests/io/test_imglib.c). */
void img_to_u8_n(const float *x, unsigned char *out, size_t n)
{
    typedef float F8 __attribute__((vector_size(32)));
    typedef int32_t I8 __attribute__((vector_size(32)));
    typedef uint32_t U8 __attribute__((vector_size(32)));
    const F8 ones = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        F8 v;
        memcpy(&v, x + i, sizeof v);
        I8 keep = ((U8)v - 1u) < 0x7f7fffffu; /* -1 where 0 < x <= FLT_MAX */
        I8 below = v < ones; /* C has no vector ?:, so min(v, 1) as a select */
        I8 c = ((I8)v & below) | ((I8)ones & ~below);
        F8 y = (F8)(c & keep) * 255.0f;
        I8 r = __builtin_convertvector(y, I8);
        r -= (y - __builtin_convertvector(r, F8)) >= 0.5f; /* a true lane is -1 */
        for (int j = 0; j < 8; j++)
            out[i + j] = (unsigned char)r[j];
    }
    for (; i < n; i++)
        out[i] = img_to_u8(x[i]);
}
