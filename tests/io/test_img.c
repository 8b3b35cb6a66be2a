/* tests/io/test_img.c -- image files: written by sfsim's own writers (OpenEXR, libpng:
 * sim/img_write.c) and read back through OpenImageIO (the image library's reader), the files'
 * encodings, the writers' errors, and comparison statistics. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/img.h"
#include "../support/files.h"

static char dir[64];

static void mkdir_tmp(void)
{
    strcpy(dir, "/tmp/sfsim-img-XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
}

static void rm_tmp(void)
{
    tu_remove_tree(dir);
}

Test(img_io, exr_round_trip_is_exact, .init = mkdir_tmp, .fini = rm_tmp)
{
    float px[2 * 3 * 3];
    for (int i = 0; i < 18; i++)
        px[i] = 0.1f * (float)i + 1e-7f * (float)(i * i) + (i == 5 ? 1000.5f : 0.0f);
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/a.exr", dir);
    cr_assert_eq(img_write_linear(NULL, path, px, 3, 2, err, sizeof err), 0, "%s", err);
    float *back;
    int w, h;
    cr_assert_eq(img_read(path, &back, &w, &h, err, sizeof err), 0, "%s", err);
    cr_assert_eq(w, 3);
    cr_assert_eq(h, 2);
    cr_expect_eq(memcmp(px, back, sizeof px), 0, "EXR must keep float bits");
    free(back);
}

/* The whole file, malloc'ed, its size in *n. */
static unsigned char *read_all(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    cr_assert_not_null(f, "%s", path);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    rewind(f);
    unsigned char *b = malloc((size_t)len);
    cr_assert(b && fread(b, 1, (size_t)len, f) == (size_t)len);
    fclose(f);
    *n = (size_t)len;
    return b;
}

/* Bits OpenImageIO's reader must give back exactly: every kind of float, over a size that is not
 * a whole number of ZIP chunks (16 scanlines) in either direction. */
Test(img_io, exr_keeps_every_float_bit_pattern, .init = mkdir_tmp, .fini = rm_tmp)
{
    enum { W = 37, H = 35 };
    static float px[W * H * 3];
    const float special[] = {0.0f, -0.0f, 1e-45f, -1e-40f, 1.17549435e-38f, 3.4028235e38f, -3.4028235e38f,
                             INFINITY, -INFINITY, NAN, 0.99999994f, 65504.0f, 65520.0f, 1e-8f};
    uint32_t state = 12345;
    for (size_t i = 0; i < sizeof px / sizeof px[0]; i++) {
        state = state * 1664525u + 1013904223u;
        uint32_t bits = state;
        if ((bits & 0x7f800000u) == 0x7f800000u)
            bits &= ~0x00800000u; /* keep NaNs to the special ones below: their payloads are not promised */
        memcpy(&px[i], &bits, sizeof bits);
        if (i % 53 == 0)
            px[i] = special[(i / 53) % (sizeof special / sizeof special[0])];
    }
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/bits.exr", dir);
    cr_assert_eq(img_write_linear(NULL, path, px, W, H, err, sizeof err), 0, "%s", err);
    float *back;
    int w, h;
    cr_assert_eq(img_read(path, &back, &w, &h, err, sizeof err), 0, "%s", err);
    cr_assert(w == W && h == H, "%d x %d", w, h);
    for (size_t i = 0; i < sizeof px / sizeof px[0]; i++) {
        if (isnan(px[i]))
            cr_assert(isnan(back[i]), "channel %zu: NaN read as %g", i, (double)back[i]);
        else
            cr_assert_eq(memcmp(&px[i], &back[i], sizeof(float)), 0, "channel %zu: %.9g read as %.9g", i,
                         (double)px[i], (double)back[i]);
    }
    free(back);

    /* The header says what OpenImageIO's writer said: ZIP compression (3) of float channels. */
    size_t n;
    unsigned char *bytes = read_all(path, &n);
    cr_assert_not_null(bytes);
    static const char comp[] = "compression\0compression\0\1\0\0\0";
    unsigned char *at = memmem(bytes, n, comp, sizeof comp - 1);
    cr_assert_not_null(at, "no compression attribute");
    cr_expect_eq(at[sizeof comp - 1], 3, "compression %d, not ZIP (3)", at[sizeof comp - 1]);
    cr_expect_not_null(memmem(bytes, n, "channels\0chlist\0", 16));
    free(bytes);
}

/* Every 8-bit value through img_write_rgb8 comes back; the file is 8-bit RGB, its
 * zlib stream at the fastest level (the writer's setting since docs/performance.md's round). */
Test(img_io, png_holds_every_byte_value, .init = mkdir_tmp, .fini = rm_tmp)
{
    enum { W = 256, H = 3 };
    static float px[W * H * 3];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++)
                px[(y * W + x) * 3 + c] = (float)((x + 85 * c + 7 * y) % 256) / 255.0f;
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/bytes.png", dir);
    cr_assert_eq(img_write_rgb8(NULL, path, px, W, H, err, sizeof err), 0, "%s", err);
    float *back;
    int w, h;
    cr_assert_eq(img_read(path, &back, &w, &h, err, sizeof err), 0, "%s", err);
    cr_assert(w == W && h == H, "%d x %d", w, h);
    for (size_t i = 0; i < sizeof px / sizeof px[0]; i++)
        cr_assert_eq(lroundf(back[i] * 255.0f), lroundf(px[i] * 255.0f), "channel %zu: %.9g read as %.9g", i,
                     (double)px[i], (double)back[i]);
    free(back);

    size_t n;
    unsigned char *bytes = read_all(path, &n);
    cr_assert(bytes && n > 33 && memcmp(bytes + 12, "IHDR", 4) == 0);
    cr_expect_eq(bytes[24], 8, "bit depth %d", bytes[24]);
    cr_expect_eq(bytes[25], 2, "colour type %d (2 is RGB)", bytes[25]);
    unsigned char *idat = memmem(bytes, n, "IDAT", 4);
    cr_assert(idat && idat + 6 <= bytes + n);
    cr_expect((idat[4] & 0x0f) == 8 && (idat[5] >> 6) == 0, "zlib header %02x %02x: not the fastest level", idat[4], idat[5]);
    free(bytes);
}

Test(img_io, png_is_clamped_srgb_and_marks_nan, .init = mkdir_tmp, .fini = rm_tmp)
{
    /* linear 0, 0.5, 2.0 (clamps to 1), NaN pixel */
    float px[4 * 3] = {0, 0, 0, 0.5f, 0.5f, 0.5f, 2.0f, 2.0f, 2.0f, NAN, 0, 0};
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/a.png", dir);
    cr_assert_eq(img_write_display(NULL, path, px, 4, 1, 1.0f, err, sizeof err), 0, "%s", err);
    float *back;
    int w, h;
    cr_assert_eq(img_read(path, &back, &w, &h, err, sizeof err), 0, "%s", err);
    cr_assert_eq(w, 4);
    cr_expect_float_eq(back[0], 0.0f, 1e-6f);
    /* sRGB(0.5) = 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> 188/255 */
    cr_expect_float_eq(back[3], 188.0f / 255.0f, 1e-6f, "%f", (double)back[3]);
    cr_expect_float_eq(back[6], 1.0f, 1e-6f);
    cr_expect_float_eq(back[9], 1.0f, 1e-6f);   /* magenta: 1, 0, 1 */
    cr_expect_float_eq(back[10], 0.0f, 1e-6f);
    cr_expect_float_eq(back[11], 1.0f, 1e-6f);
    free(back);
}

Test(img_io, errors_name_the_file)
{
    float px[3] = {0, 0, 0};
    char err[256];
    cr_expect_eq(img_write_linear(NULL, "/nonexistent-dir/x.exr", px, 1, 1, err, sizeof err), -1);
    cr_expect(strncmp(err, "/nonexistent-dir/x.exr: ", 24) == 0, "%s", err);
    cr_expect_eq(img_write_linear(NULL, "/tmp/x.unknownformat", px, 1, 1, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.unknownformat: ") == err, "%s", err);
    /* each writer writes its one format */
    cr_expect_eq(img_write_linear(NULL, "/tmp/x.png", px, 1, 1, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.png: no image writer") == err, "%s", err);
    cr_expect_eq(img_write_display(NULL, "/tmp/x.exr", px, 1, 1, 1.0f, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.exr: no image writer") == err, "%s", err);
    cr_expect_eq(img_write_rgb8(NULL, "/nonexistent-dir/x.png", px, 1, 1, err, sizeof err), -1);
    cr_expect(strncmp(err, "/nonexistent-dir/x.png: ", 24) == 0, "%s", err);
    /* sizes, refused before any pixel is read (px is far too small for them) */
    cr_expect_eq(img_write_linear(NULL, "/tmp/x.exr", px, 0, 1, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.exr: image size 0 x 1") == err, "%s", err);
    cr_expect_eq(img_write_linear(NULL, "/tmp/x.exr", px, 200000000, 1, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.exr: ") == err && strstr(err, "too large"), "%s", err);
    cr_expect_eq(img_write_display(NULL, "/tmp/x.png", px, 2000000, 1, 1.0f, err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/x.png: ") == err && strstr(err, "too large for PNG"), "%s", err);
    cr_expect_eq(access("/tmp/x.png", F_OK), -1);
    float *back;
    int w, h;
    cr_expect_eq(img_read("/nonexistent-dir/y.png", &back, &w, &h, err, sizeof err), -1);
    cr_expect(strstr(err, "/nonexistent-dir/y.png: ") == err, "%s", err);
    cr_expect_null(back);
}

Test(img_compare, statistics)
{
    float a[6] = {0, 0, 0, 1, 1, 1};
    float b[6] = {0, 0, 0, 1, 1, 1};
    ImgCompare c;
    img_compare(a, b, 2, 1, &c);
    cr_expect_eq(c.rmse, 0.0);
    cr_expect(isinf(c.psnr));
    b[3] = 0.5f; /* one channel off by 0.5: mse = 0.25 / 6 */
    b[0] = NAN;
    img_compare(a, b, 2, 1, &c);
    /* the NaN pair is left out: 5 finite pairs, squared error 0.25 */
    cr_expect_float_eq(c.rmse, sqrt(0.25 / 5.0), 1e-12);
    cr_expect_float_eq(c.psnr, 20.0 * log10(1.0 / sqrt(0.05)), 1e-9);
    cr_expect_float_eq(c.max_abs, 0.5, 1e-12);
    cr_expect_eq(c.nan_a, 0);
    cr_expect_eq(c.nan_b, 1);
    cr_expect_float_eq(c.mean_a, 0.5, 1e-12);
    cr_expect_float_eq(c.mean_b, 2.5 / 5.0, 1e-12);
}
