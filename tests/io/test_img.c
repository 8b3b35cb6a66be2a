/* tests/unit/test_img.c -- image files through the OpenImageIO shim, and comparison statistics. */
#include <criterion/criterion.h>
#include <math.h>
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
