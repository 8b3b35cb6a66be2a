/* tests/io/test_heatmap.c -- heat-map images (sim/heatmap.h): the documented geometry, the
 * colormap's order, constant maps, text or its absence, every error path, and the pixels against
 * those OpenImageIO drew before sim/heatmap.c replaced it. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/heatmap.h"
#include "../../sim/img.h"
#include "../support/files.h"

#define DEJAVU "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"

static char dir[64];

static void mkdir_tmp(void)
{
    strcpy(dir, "/tmp/sfsim-heatmap-XXXXXX");
    cr_assert_not_null(mkdtemp(dir));
}

static void rm_tmp(void)
{
    tu_remove_tree(dir);
}

typedef struct Image {
    float *rgb;
    int w, h;
} Image;

static Image write_and_read(const char *name, const double *v, int w, int h, const char *title,
                            const char *unit)
{
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    cr_assert_eq(heatmap_write(NULL, path, v, w, h, title, unit, err, sizeof err), 0, "%s", err);
    Image im;
    cr_assert_eq(img_read(path, &im.rgb, &im.w, &im.h, err, sizeof err), 0, "%s", err);
    return im;
}

static const float *px(const Image *im, int x, int y)
{
    cr_assert(x >= 0 && x < im->w && y >= 0 && y < im->h, "(%d, %d) outside %dx%d", x, y, im->w,
              im->h);
    return im->rgb + 3 * ((size_t)y * im->w + x);
}

static float luma(const float *p)
{
    return 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
}

static int same(const float *a, const float *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* Pixels of [x0, x1) x [y0, y1) darker than 0.5: text (or a frame) was drawn there. */
static int dark_pixels(const Image *im, int x0, int x1, int y0, int y1)
{
    int n = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            n += luma(px(im, x, y)) < 0.5f;
    return n;
}

/* Map origin (16, 52) and legend bar origin, heatmap.h's layout. */
enum { MAP_X = 16, TOP = 52, BAR_GAP = 24, BAR_W = 24 };

Test(heatmap, gradient_geometry_and_colour_order, .init = mkdir_tmp, .fini = rm_tmp)
{
    /* 16 x 4, each row increasing, not linearly, with x: s = 32 -> map 512 x 128, bar 256. */
    double v[16 * 4];
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 16; x++)
            v[y * 16 + x] = 37.0 * x * x + y;
    Image im = write_and_read("grad.png", v, 16, 4, "gradient", "cycles");
    cr_assert_eq(im.w, 16 + 512 + 24 + 24 + 136 + 16);
    cr_assert_eq(im.h, 16 + 36 + 256 + 16);

    /* Blocks are sharp: all 32 x 32 pixels of block (5, 2) equal its first pixel. */
    const float *b = px(&im, MAP_X + 5 * 32, TOP + 2 * 32);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++)
            cr_assert(same(px(&im, MAP_X + 5 * 32 + x, TOP + 2 * 32 + y), b), "(%d, %d)", x, y);
    /* The map ends where documented: next to it is the frame, then background. */
    cr_expect(!same(px(&im, MAP_X + 511, TOP), px(&im, MAP_X + 512, TOP)));
    cr_expect_float_eq(luma(px(&im, MAP_X + 514, TOP + 10)), 1.0f, 1e-6f);

    /* Luminance rises strictly with the value along row 2; row 0's first block is the darkest. */
    for (int x = 1; x < 16; x++) {
        float l0 = luma(px(&im, MAP_X + (x - 1) * 32 + 16, TOP + 2 * 32 + 16));
        float l1 = luma(px(&im, MAP_X + x * 32 + 16, TOP + 2 * 32 + 16));
        cr_expect(l1 > l0, "block %d luma %f, block %d luma %f", x - 1, (double)l0, x, (double)l1);
    }
    float darkest = luma(px(&im, MAP_X + 16, TOP + 16));
    float brightest = luma(px(&im, MAP_X + 15 * 32 + 16, TOP + 3 * 32 + 16));
    cr_expect(darkest < 0.15f && brightest > 0.8f, "range %f..%f", (double)darkest,
              (double)brightest);

    /* The legend bar: top is the maximum's colour, bottom the minimum's, luminance falling
     * strictly down the bar. */
    int bar_x = MAP_X + 512 + BAR_GAP + BAR_W / 2;
    const float *top = px(&im, bar_x, TOP), *bottom = px(&im, bar_x, TOP + 255);
    const float *vmax = px(&im, MAP_X + 15 * 32, TOP + 3 * 32), *vmin = px(&im, MAP_X, TOP);
    for (int c = 0; c < 3; c++) {
        cr_expect_float_eq(top[c], vmax[c], 1.5f / 255.0f, "channel %d", c);
        cr_expect_float_eq(bottom[c], vmin[c], 1.5f / 255.0f, "channel %d", c);
    }
    for (int y = 16; y < 256; y += 16)
        cr_expect(luma(px(&im, bar_x, TOP + y)) < luma(px(&im, bar_x, TOP + y - 16)), "bar y %d", y);
    free(im.rgb);
}

Test(heatmap, constant_maps_show_one_colour, .init = mkdir_tmp, .fini = rm_tmp)
{
    /* One tile: s = 512, map and bar 512 tall. */
    double one = 4200.0;
    Image im = write_and_read("one.png", &one, 1, 1, "one tile", "cycles");
    cr_assert_eq(im.w, 16 + 512 + 24 + 24 + 136 + 16);
    cr_assert_eq(im.h, 16 + 36 + 512 + 16);
    const float *c = px(&im, MAP_X, TOP);
    cr_expect(isfinite(c[0]) && c[0] < 1.0f, "map colour %f is background", (double)c[0]);
    for (int y = 0; y < 512; y += 7)
        for (int x = 0; x < 512; x += 7)
            cr_assert(same(px(&im, MAP_X + x, TOP + y), c), "map (%d, %d)", x, y);
    for (int y = 0; y < 512; y += 7)
        cr_assert(same(px(&im, MAP_X + 512 + BAR_GAP + 3, TOP + y), c), "bar y %d", y);
    free(im.rgb);

    /* All zero, 3 x 2: s = ceil(512 / 3) = 171 -> map 513 x 342. */
    double zero[6] = {0};
    im = write_and_read("zero.png", zero, 3, 2, NULL, NULL);
    cr_assert_eq(im.w, 16 + 513 + 24 + 24 + 136 + 16);
    cr_assert_eq(im.h, 16 + 36 + 342 + 16);
    cr_expect(same(px(&im, MAP_X, TOP), px(&im, MAP_X + 512, TOP + 341)));
    free(im.rgb);
}

Test(heatmap, tall_maps_are_scaled_less, .init = mkdir_tmp, .fini = rm_tmp)
{
    /* 1 x 100: s would be 512 for the width but is capped at 2048 / 100 = 20. */
    double v[100];
    for (int i = 0; i < 100; i++)
        v[i] = i;
    Image im = write_and_read("tall.png", v, 1, 100, "tall", "cycles");
    cr_assert_eq(im.w, 16 + 20 + 24 + 24 + 136 + 16);
    cr_assert_eq(im.h, 16 + 36 + 2000 + 16);
    cr_expect(luma(px(&im, MAP_X + 10, TOP + 1990)) > luma(px(&im, MAP_X + 10, TOP + 10)));
    free(im.rgb);
}

Test(heatmap, title_and_labels_are_drawn_when_a_font_loads, .init = mkdir_tmp, .fini = rm_tmp)
{
    cr_assert_eq(access(DEJAVU, R_OK), 0, "fonts-dejavu-core is in scripts/deps.sh");
    double v[4] = {0, 1000, 2000, 12345};
    int label_x = MAP_X + 512 + BAR_GAP + BAR_W + 6 + 1, right = 16 + 512 + 24 + 24 + 136;
    /* The title band left of the label column (whose top label reaches into the band). */
    Image im = write_and_read("text.png", v, 4, 1, "cost: cycles per pixel", "cycles");
    cr_expect_gt(dark_pixels(&im, 0, MAP_X + 512, 0, TOP - 1), 50, "no title drawn");
    cr_expect_gt(dark_pixels(&im, label_x, right, 0, im.h), 100, "no labels drawn");
    free(im.rgb);

    im = write_and_read("notitle.png", v, 4, 1, NULL, "cycles");
    cr_expect_eq(dark_pixels(&im, 0, MAP_X + 512, 0, TOP - 1), 0, "title band not empty");
    free(im.rgb);
}

Test(heatmap, without_a_font_the_map_is_still_written, .init = mkdir_tmp, .fini = rm_tmp)
{
    heatmap_set_font("/nonexistent-dir/no-font.ttf");
    double v[4] = {0, 1000, 2000, 12345};
    int label_x = MAP_X + 512 + BAR_GAP + BAR_W + 6 + 1;
    Image im = write_and_read("nofont.png", v, 4, 1, "cost: cycles per pixel", "cycles");
    heatmap_set_font(NULL);
    cr_assert_eq(im.w, 16 + 512 + 24 + 24 + 136 + 16);
    cr_expect_eq(dark_pixels(&im, 0, im.w, 0, TOP - 1), 0, "text drawn without a font");
    cr_expect_eq(dark_pixels(&im, label_x, im.w, 0, im.h), 0, "text drawn without a font");
    cr_expect(luma(px(&im, MAP_X + 3 * 128 + 64, TOP + 64)) > luma(px(&im, MAP_X + 64, TOP + 64)));
    /* Tick marks do not need a font: at the top of the bar (maximum) and the bottom. */
    cr_expect_lt(luma(px(&im, label_x - 3, TOP)), 0.5f);
    cr_expect_lt(luma(px(&im, label_x - 3, TOP + 255)), 0.5f);
    free(im.rgb);
}

Test(heatmap, bad_values_name_the_first_bad_pixel, .init = mkdir_tmp, .fini = rm_tmp)
{
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/bad.png", dir);
    double v[4 * 3] = {1, 2, 3, 4, 5, 6, NAN, 8, -1, 10, 11, 12};
    cr_expect_eq(heatmap_write(NULL, path, v, 4, 3, "t", "cycles", err, sizeof err), -1);
    cr_expect(strncmp(err, path, strlen(path)) == 0, "%s", err);
    cr_expect(strstr(err, "pixel (2, 1)") && strstr(err, "NaN"), "%s", err);
    cr_expect_neq(access(path, F_OK), 0, "nothing may be written");

    v[6] = 7;
    cr_expect_eq(heatmap_write(NULL, path, v, 4, 3, "t", "cycles", err, sizeof err), -1);
    cr_expect(strstr(err, "pixel (0, 2)") && strstr(err, "negative"), "%s", err);
    v[8] = INFINITY;
    cr_expect_eq(heatmap_write(NULL, path, v, 4, 3, "t", "cycles", err, sizeof err), -1);
    cr_expect(strstr(err, "pixel (0, 2)") && strstr(err, "infinite"), "%s", err);
    cr_expect_neq(access(path, F_OK), 0, "nothing may be written");

    cr_expect_eq(heatmap_write(NULL, path, v, 0, 3, "t", "cycles", err, sizeof err), -1);
    cr_expect(strstr(err, "0 x 3"), "%s", err);
    cr_expect_eq(heatmap_write(NULL, path, NULL, 4, 3, "t", "cycles", err, sizeof err), -1);
    cr_expect(strstr(err, "no values"), "%s", err);
}

Test(heatmap, unwritable_paths_are_errors)
{
    double v[2] = {1, 2};
    char err[256];
    cr_expect_eq(heatmap_write(NULL, "/nonexistent-dir/cost.png", v, 2, 1, "t", "u", err, sizeof err), -1);
    cr_expect(strncmp(err, "/nonexistent-dir/cost.png: ", 27) == 0, "%s", err);
    cr_expect_eq(heatmap_write(NULL, "/tmp/cost.unknownformat", v, 2, 1, "t", "u", err, sizeof err), -1);
    cr_expect(strstr(err, "/tmp/cost.unknownformat: ") == err, "%s", err);
}

/* ---- the pixels OpenImageIO drew ------------------------------------------------------------ */

/* FNV-1a over an image's 8-bit values, as read back. */
static uint64_t pixel_hash(const Image *im)
{
    uint64_t x = 1469598103934665603ull;
    for (size_t i = 0; i < (size_t)im->w * im->h * 3; i++) {
        x ^= (uint64_t)lroundf(im->rgb[i] * 255.0f);
        x *= 1099511628211ull;
    }
    return x;
}

/* Values for the cases below. */
static void fill_case(double *v, int w, int h, int kind)
{
    for (int i = 0; i < w * h; i++) {
        int x = i % w, y = i / w;
        v[i] = kind == 0   ? 1000.0 + 37.0 * x * x + 11.0 * y * y + (i % 7) * 13.0
               : kind == 1 ? 4200.0
               : kind == 2 ? 0.0
               : kind == 3 ? 37.0 * x * x + y
               : kind == 4 ? 1e6 + 12345.678 * x + y
                           : 1000.0 + 0.1 * i;
    }
}

/* cost.png was drawn by OpenImageIO 2.4's ImageBufAlgo (color_map, fill, render_box, render_line,
 * render_text with FreeType and DejaVu Sans) until 2026-12; sim/heatmap.c draws it itself. These
 * hashes are of the old library's pictures of the same values (libsfsim-img.so at 60f9603, which
 * the new code matched pixel for pixel in all of them): the geometry, the colour map and the
 * bar's interpolation, frames, ticks, and the text's placement, coverage and blending, at both
 * text sizes, with long titles, SI prefixes and extra digits. They depend on the font file and
 * FreeType's rasterizer (Debian 12's fonts-dejavu-core 2.37, libfreetype6 2.12): a different
 * version moves label pixels, not the map. */
Test(heatmap, pixels_are_those_openimageio_drew, .init = mkdir_tmp, .fini = rm_tmp)
{
    if (access(DEJAVU, R_OK) != 0)
        cr_skip_test("%s is missing (fonts-dejavu-core, scripts/deps.sh)", DEJAVU);
    static const struct {
        int w, h;
        const char *title, *unit;
        int kind, cw, ch;
        uint64_t hash;
    } cases[] = {
        {32, 32, "simulated cycles per pixel (tiles of 8 x 8)", "cycles", 0, 728, 580, 0x1512b7ded91b5822ull},
        {1, 1, "one tile", "cycles", 1, 728, 580, 0x9dee4a6137af6920ull},
        {3, 2, NULL, NULL, 2, 729, 410, 0x7c77ee1e27ab3b7bull},
        {1, 100, "tall", "cycles", 0, 236, 2068, 0x713de1f0151a1354ull},
        {16, 4, "gradient", "cycles", 3, 728, 324, 0xbba5f97703e58bdeull},
        {600, 3, "simulated cycles per pixel (tiles of 16 x 16; estimated from the sampled units)", "cycles", 4, 816,
         324, 0xa306b729f574f2f1ull},
        {4, 1, "close values", "cycles", 5, 728, 324, 0x9754cde8f68cc718ull},
        {2048, 2, "wide", "", 0, 2264, 324, 0xcffb9f1d83099c66ull},
    };
    static double v[2048 * 2];
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char name[32];
        snprintf(name, sizeof name, "case%zu.png", k);
        fill_case(v, cases[k].w, cases[k].h, cases[k].kind);
        Image im = write_and_read(name, v, cases[k].w, cases[k].h, cases[k].title, cases[k].unit);
        cr_expect(im.w == cases[k].cw && im.h == cases[k].ch, "case %zu: %d x %d", k, im.w, im.h);
        cr_expect_eq(pixel_hash(&im), cases[k].hash, "case %zu: pixels differ from OpenImageIO's (hash %016llx)", k,
                     (unsigned long long)pixel_hash(&im));
        free(im.rgb);
    }
}

/* Text is UTF-8. OpenImageIO 2.4's render_text kept only the last byte's low six bits of a
 * multi-byte character ("é" came out as ")", "µ" as "5"); sim/heatmap.c draws the character. */
Test(heatmap, text_is_decoded_as_utf8, .init = mkdir_tmp, .fini = rm_tmp)
{
    if (access(DEJAVU, R_OK) != 0)
        cr_skip_test("%s is missing (fonts-dejavu-core, scripts/deps.sh)", DEJAVU);
    double v[2] = {1, 2};
    Image a = write_and_read("a.png", v, 2, 1, "caf\xc3\xa9", NULL);
    Image b = write_and_read("b.png", v, 2, 1, "caf)", NULL);
    Image c = write_and_read("c.png", v, 2, 1, "caf", NULL);
    /* the title's last letter: é differs from ")", and both add ink to "caf" */
    int ink_a = dark_pixels(&a, 0, MAP_X + 512, 0, TOP - 1), ink_b = dark_pixels(&b, 0, MAP_X + 512, 0, TOP - 1),
        ink_c = dark_pixels(&c, 0, MAP_X + 512, 0, TOP - 1);
    cr_expect(ink_a > ink_c && ink_b > ink_c, "ink %d, %d, %d", ink_a, ink_b, ink_c);
    cr_expect_neq(memcmp(a.rgb, b.rgb, sizeof(float) * 3 * (size_t)a.w * a.h), 0, "é drawn as )");
    free(a.rgb);
    free(b.rgb);
    free(c.rgb);
    /* malformed UTF-8 is drawn byte by byte, not an error */
    Image d = write_and_read("d.png", v, 2, 1, "bad \xc3 \xff\xfe end", NULL);
    free(d.rgb);
}
