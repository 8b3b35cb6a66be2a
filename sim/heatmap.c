/* sim/heatmap.c -- heat-map images (cost.png): colour map, legend bar, frame lines and tick marks
 * drawn into a float canvas, text through FreeType, written by img_write_rgb8 (libpng). Linked
 * into bin/sfsim: until 2026-12 this was drawn with OpenImageIO's ImageBufAlgo, whose ~265
 * shared libraries were most of a small run's time (docs/performance.md, "Start-up").
 *
 * The pixels are those ImageBufAlgo drew (tests/io/test_heatmap.c compares with a stored
 * drawing of it), which fixes a few choices below that would otherwise be free: the colour map's
 * and the bar's interpolation formulas, the text's placement and its blending.
 *
 * Owns: the colormap table, the layout documented in heatmap.h, the font search, the text's
 * placement. Must not: open image files itself (img_write_rgb8 does, so errors read the same
 * everywhere) or know what the values measure.
 */
#include "heatmap.h"

#include <ft2build.h>
#include FT_FREETYPE_H
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "img.h"

/* Layout of heatmap.h, in output pixels. */
enum {
    MARGIN = 16, TITLE_H = 36, GAP = 24, BAR_W = 24, LABEL_W = 136, TICK = 6,
    MIN_MAP_W = 512, MAX_MAP_H = 2048, MIN_BAR_H = 256, MAX_SIDE = 8192,
    TITLE_PX = 18, LABEL_PX = 14, NTICKS = 5,
};

/* Ten evenly spaced stops of a viridis-like ramp, 8-bit sRGB. Rec. 709 luma of the stops rises
 * 21, 53, 76, 95, 111, 130, 151, 176, 200, 222, and linear interpolation keeps it monotone. */
static const unsigned char RAMP[][3] = {
    {0x44, 0x01, 0x54}, {0x48, 0x28, 0x78}, {0x3e, 0x4a, 0x89}, {0x31, 0x68, 0x8e},
    {0x26, 0x82, 0x8e}, {0x1f, 0x9e, 0x89}, {0x35, 0xb7, 0x79}, {0x6d, 0xcd, 0x59},
    {0xb4, 0xde, 0x2c}, {0xfd, 0xe7, 0x25},
};
enum { NRAMP = sizeof RAMP / sizeof RAMP[0] };

static const float BACKGROUND[3] = {1.0f, 1.0f, 1.0f};
static const float INK[3] = {0.1f, 0.1f, 0.1f};
static const float FRAME[3] = {0.35f, 0.35f, 0.35f};

#define DEJAVU "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf"
static int font_overridden;
static char font_override[4096];

static int fail(char *err, size_t errlen, const char *path, const char *why)
{
    snprintf(err, errlen, "%s: %s", path, why);
    return -1;
}

/* ---- the canvas ------------------------------------------------------------------------------- */

typedef struct Canvas {
    float *px; /* RGB, row-major */
    int w, h;
} Canvas;

static float *at(const Canvas *c, int x, int y)
{
    return c->px + ((size_t)y * (size_t)c->w + (size_t)x) * 3;
}

static void put(const Canvas *c, int x, int y, const float rgb[3])
{
    if (x >= 0 && y >= 0 && x < c->w && y < c->h)
        memcpy(at(c, x, y), rgb, 3 * sizeof(float));
}

/* The one-pixel outline of the rectangle with corners (x0, y0) and (x1, y1), both included. */
static void draw_box(const Canvas *c, int x0, int y0, int x1, int y1, const float rgb[3])
{
    for (int x = x0; x <= x1; x++) {
        put(c, x, y0, rgb);
        put(c, x, y1, rgb);
    }
    for (int y = y0; y <= y1; y++) {
        put(c, x0, y, rgb);
        put(c, x1, y, rgb);
    }
}

/* Value t in [0, 1] to colour: linear between the two stops around it, as ImageBufAlgo's
 * color_map computes it (a * (1 - f) + b * f in float: other spellings differ in the last bit,
 * which the 8-bit rounding can show). */
static void colour_of(float t, const float knots[NRAMP * 3], float out[3])
{
    float x = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    float s = x * (float)(NRAMP - 1);
    int lo = (int)s;
    if (lo > NRAMP - 2)
        lo = NRAMP - 2;
    float f = s - (float)lo;
    for (int c = 0; c < 3; c++)
        out[c] = knots[lo * 3 + c] * (1.0f - f) + knots[(lo + 1) * 3 + c] * f;
}

/* ---- text ------------------------------------------------------------------------------------- */

/* The next code point of UTF-8 text at *s (advancing it); a malformed byte stands for itself. */
static uint32_t next_code_point(const unsigned char **s)
{
    const unsigned char *p = *s;
    uint32_t c = *p++;
    int more = c >= 0xf0 && c < 0xf8 ? 3 : c >= 0xe0 ? 2 : c >= 0xc0 ? 1 : 0;
    if (c >= 0xf8)
        more = 0;
    uint32_t cp = more == 3 ? c & 0x07 : more == 2 ? c & 0x0f : more == 1 ? c & 0x1f : c;
    for (int i = 0; i < more; i++) {
        if ((p[i] & 0xc0) != 0x80) {
            *s = *s + 1;
            return c;
        }
        cp = (cp << 6) | (p[i] & 0x3f);
    }
    *s = p + more;
    return cp;
}

/* The text's ink box relative to its origin (pen at x = 0 on the baseline, y down): the union
 * of the glyphs' bitmaps, spaces included as empty boxes at the pen, as ImageBufAlgo's
 * text_size measures it. Half-open: [x0, x1) x [y0, y1). */
typedef struct TextBox {
    int x0, x1, y0, y1;
} TextBox;

static TextBox measure(FT_Face face, const char *text)
{
    TextBox b = {INT32_MAX, INT32_MIN, INT32_MAX, INT32_MIN};
    int pen = 0;
    for (const unsigned char *s = (const unsigned char *)text; *s;) {
        if (FT_Load_Char(face, next_code_point(&s), FT_LOAD_RENDER) != 0)
            continue;
        FT_GlyphSlot g = face->glyph;
        int x0 = pen + g->bitmap_left, y0 = -g->bitmap_top;
        b.x0 = x0 < b.x0 ? x0 : b.x0;
        b.y0 = y0 < b.y0 ? y0 : b.y0;
        int x1 = x0 + (int)g->bitmap.width, y1 = y0 + (int)g->bitmap.rows;
        b.x1 = x1 > b.x1 ? x1 : b.x1;
        b.y1 = y1 > b.y1 ? y1 : b.y1;
        pen += (int)(g->advance.x >> 6);
    }
    /* One past the last column and row that may hold ink, as text_size reports it. */
    b.x1++;
    b.y1++;
    return b;
}

/* text in INK, px pixels tall (FT_Set_Pixel_Sizes), its pen starting at x, centred on row y
 * (ImageBufAlgo's TextAlignY::Center: the baseline goes -y0 - height / 2 below y, height of the
 * box above, integer division). The glyphs' 8-bit coverage goes into one alpha plane, each glyph
 * overwriting what the previous ones left where their bitmaps overlap (not their maximum or
 * sum), and the plane is then composited over the canvas: c * (1 - a) + ink * a. Both choices
 * are what render_text does; they were found by comparing its pixels (tests/io/test_heatmap.c).
 * 0, or -1 when out of memory. */
static int draw_text(const Canvas *c, FT_Face face, int x, int y, const char *text, int px)
{
    if (!face || !text || !*text)
        return 0;
    if (FT_Set_Pixel_Sizes(face, 0, (FT_UInt)px) != 0)
        return 0;
    TextBox b = measure(face, text);
    if (b.x0 >= b.x1 || b.y0 >= b.y1)
        return 0;
    y += -b.y0 - (b.y1 - b.y0) / 2;
    int aw = b.x1 - b.x0, ah = b.y1 - b.y0;
    float *alpha = calloc((size_t)aw * (size_t)ah, sizeof *alpha);
    if (!alpha)
        return -1;
    int pen = 0;
    for (const unsigned char *s = (const unsigned char *)text; *s;) {
        if (FT_Load_Char(face, next_code_point(&s), FT_LOAD_RENDER) != 0)
            continue;
        FT_GlyphSlot g = face->glyph;
        for (int j = 0; j < (int)g->bitmap.rows; j++)
            for (int i = 0; i < (int)g->bitmap.width; i++) {
                int ax = pen + g->bitmap_left + i - b.x0, ay = j - g->bitmap_top - b.y0;
                alpha[(size_t)ay * (size_t)aw + (size_t)ax] = g->bitmap.buffer[g->bitmap.pitch * j + i] / 255.0f;
            }
        pen += (int)(g->advance.x >> 6);
    }
    for (int ay = 0; ay < ah; ay++)
        for (int ax = 0; ax < aw; ax++) {
            int cx = x + b.x0 + ax, cy = y + b.y0 + ay;
            float a = alpha[(size_t)ay * (size_t)aw + (size_t)ax];
            if (a == 0.0f || cx < 0 || cy < 0 || cx >= c->w || cy >= c->h)
                continue;
            float *p = at(c, cx, cy);
            for (int k = 0; k < 3; k++)
                p[k] = p[k] * (1.0f - a) + INK[k] * a;
        }
    free(alpha);
    return 0;
}

/* The font to draw with, or NULL: then no text is drawn. The override alone when one is set;
 * else DejaVu Sans where fonts-dejavu-core puts it (scripts/deps.sh installs it), then as
 * DejaVuSans.ttf in the other usual font folders. */
static FT_Face open_font(FT_Library lib)
{
    char home[4096] = "";
    const char *h = getenv("HOME");
    if (h && *h)
        snprintf(home, sizeof home, "%s/.fonts/DejaVuSans.ttf", h);
    const char *candidates[] = {
        DEJAVU,
        home,
        "/usr/share/fonts/TTF/DejaVuSans.ttf",
        "/usr/share/fonts/dejavu/DejaVuSans.ttf",
        "/usr/share/fonts/truetype/DejaVuSans.ttf",
        "/usr/local/share/fonts/DejaVuSans.ttf",
    };
    size_t n = sizeof candidates / sizeof candidates[0];
    if (font_overridden) {
        candidates[0] = font_override;
        n = 1;
    }
    for (size_t i = 0; i < n; i++) {
        FT_Face face;
        if (*candidates[i] && FT_New_Face(lib, candidates[i], 0, &face) == 0)
            return face;
    }
    return NULL;
}

/* ---- labels ----------------------------------------------------------------------------------- */

/* A label: the value to `digits` significant digits with an SI prefix, then the unit. */
static void format_value(char *buf, size_t len, double v, int digits, const char *unit)
{
    static const char *const PREFIX[] = {"", "k", "M", "G", "T", "P"};
    int p = 0;
    while (fabs(v) >= 999.5 && p < 5) {
        v /= 1000.0;
        p++;
    }
    snprintf(buf, len, "%.*g%s%s%s", digits, v, PREFIX[p], unit && *unit ? " " : "", unit ? unit : "");
}

enum { LABEL_LEN = 96 };

/* Tick labels for values[]: three significant digits, more while neighbours would read alike. */
static void tick_labels(const double *values, int n, const char *unit, char labels[][LABEL_LEN])
{
    for (int digits = 3; digits <= 8; digits++) {
        int alike = 0;
        for (int i = 0; i < n; i++) {
            format_value(labels[i], LABEL_LEN, values[i], digits, unit);
            alike |= i > 0 && strcmp(labels[i], labels[i - 1]) == 0;
        }
        if (!alike)
            break;
    }
}

/* ---- the picture ------------------------------------------------------------------------------ */

/* The picture of heatmap.h into *c (allocated here) from t (w x h, each in [0, 1]). 0, or -1 when
 * out of memory. */
static int render(Canvas *c, const float *t, int w, int h, double lo, double hi, const char *title,
                  const char *unit)
{
    int s = w >= MIN_MAP_W ? 1 : (MIN_MAP_W + w - 1) / w;
    int s_max = MAX_MAP_H / h;
    s = s < s_max ? s : s_max;
    s = s > 1 ? s : 1;
    const int map_w = w * s, map_h = h * s, bar_h = map_h > MIN_BAR_H ? map_h : MIN_BAR_H;
    const int map_x = MARGIN, top = MARGIN + TITLE_H, bar_x = map_x + map_w + GAP;
    c->w = bar_x + BAR_W + LABEL_W + MARGIN;
    c->h = top + bar_h + MARGIN;
    c->px = malloc((size_t)c->w * (size_t)c->h * 3 * sizeof(float));
    if (!c->px)
        return -1;

    float knots[NRAMP * 3];
    for (int i = 0; i < NRAMP * 3; i++)
        knots[i] = RAMP[i / 3][i % 3] / 255.0f;

    for (size_t i = 0; i < (size_t)c->w * (size_t)c->h; i++)
        memcpy(c->px + 3 * i, BACKGROUND, sizeof BACKGROUND);
    /* The map: each value an s x s block (nearest neighbour). */
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float rgb[3];
            colour_of(t[(size_t)y * (size_t)w + (size_t)x], knots, rgb);
            for (int dy = 0; dy < s; dy++)
                for (int dx = 0; dx < s; dx++)
                    memcpy(at(c, map_x + x * s + dx, top + y * s + dy), rgb, sizeof rgb);
        }
    /* The bar runs from 1 (top) to 0 (bottom), row y at 1 * (1 - f) + 0 * f, f = y / (bar_h - 1)
     * (ImageBufAlgo's vertical fill); a constant map is the middle colour throughout. */
    const int flat = !(hi > lo);
    const float one = flat ? 0.5f : 1.0f, zero = flat ? 0.5f : 0.0f;
    for (int y = 0; y < bar_h; y++) {
        float f = (float)y / (float)(bar_h - 1);
        float rgb[3];
        colour_of(one * (1.0f - f) + zero * f, knots, rgb);
        for (int x = 0; x < BAR_W; x++)
            memcpy(at(c, bar_x + x, top + y), rgb, sizeof rgb);
    }
    draw_box(c, map_x - 1, top - 1, map_x + map_w, top + map_h, FRAME);
    draw_box(c, bar_x - 1, top - 1, bar_x + BAR_W, top + bar_h, FRAME);

    double tick_t[NTICKS], tick_v[NTICKS];
    int nticks = flat ? 1 : NTICKS;
    if (flat) {
        tick_t[0] = 0.5;
        tick_v[0] = lo;
    } else {
        for (int i = 0; i < NTICKS; i++) {
            tick_t[i] = (double)i / (NTICKS - 1);
            tick_v[i] = i == NTICKS - 1 ? hi : lo + (hi - lo) * i / (NTICKS - 1);
        }
    }
    char labels[NTICKS][LABEL_LEN];
    tick_labels(tick_v, nticks, unit, labels);

    FT_Library lib = NULL;
    FT_Face face = NULL;
    if (FT_Init_FreeType(&lib) == 0)
        face = open_font(lib);
    int rc = 0;
    for (int i = 0; rc == 0 && i < nticks; i++) {
        int y = top + (int)lround((1.0 - tick_t[i]) * (bar_h - 1));
        int x = bar_x + BAR_W;
        for (int k = 0; k < TICK; k++)
            put(c, x + k, y, FRAME);
        rc = draw_text(c, face, x + TICK + 4, y, labels[i], LABEL_PX);
    }
    if (rc == 0)
        rc = draw_text(c, face, MARGIN, MARGIN + TITLE_H / 2, title, TITLE_PX);
    if (face)
        FT_Done_Face(face);
    if (lib)
        FT_Done_FreeType(lib);
    return rc;
}

void heatmap_set_font(const char *font_path)
{
    font_overridden = font_path != NULL;
    snprintf(font_override, sizeof font_override, "%s", font_path ? font_path : "");
}

int heatmap_write(OutSet *set, const char *path, const double *values, int width, int height, const char *title,
                  const char *unit, char *err, size_t errlen)
{
    char why[200];
    if (width <= 0 || height <= 0 || width > MAX_SIDE || height > MAX_SIDE) {
        snprintf(why, sizeof why, "heat map size %d x %d is outside 1..8192", width, height);
        return fail(err, errlen, path, why);
    }
    if (!values)
        return fail(err, errlen, path, "no values");
    size_t n = (size_t)width * (size_t)height;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        double v = values[i];
        if (isfinite(v) && v >= 0.0) {
            lo = v < lo ? v : lo;
            hi = v > hi ? v : hi;
            continue;
        }
        snprintf(why, sizeof why, "pixel (%zu, %zu) is %s (%g); values must be finite and >= 0", i % (size_t)width,
                 i / (size_t)width, isnan(v) ? "NaN" : isinf(v) ? "infinite" : "negative", v);
        return fail(err, errlen, path, why);
    }
    float *t = malloc(n * sizeof *t);
    Canvas c = {0};
    int rc = -1;
    if (t)
        for (size_t i = 0; i < n; i++)
            t[i] = hi > lo ? (float)((values[i] - lo) / (hi - lo)) : 0.5f;
    if (!t || render(&c, t, width, height, lo, hi, title, unit) != 0) {
        fail(err, errlen, path, "drawing the heat map: out of memory");
    } else {
        rc = img_write_rgb8(set, path, c.px, c.w, c.h, err, errlen);
    }
    free(c.px);
    free(t);
    return rc;
}
