/* sim/heatmap.h -- heat-map images of a per-pixel quantity (cost.png: simulated cycles per
 * pixel), drawn by sim/heatmap.c (text through FreeType; the same pixels OpenImageIO's
 * ImageBufAlgo drew until 2026-12) and written like img_write_rgb8 (img.h: a PNG through libpng).
 *
 * Owns: the colormap, the layout of map, legend bar and labels, the choice of font.
 * Must not: measure anything or know where the values come from; tone-map (the colours are
 * display-ready 8-bit sRGB values and are written without any transfer).
 *
 * Layout, in output pixels (fixed, whether or not text can be drawn):
 *   s      = smallest integer with width * s >= 512, but at most max(1, 2048 / height) so that
 *            a tall thin map stays bounded; each value becomes an s x s block (nearest
 *            neighbour, so tile blocks stay sharp)
 *   map    = width * s x height * s, top-left corner at (16, 52) (16 margin + 36 title band)
 *   bar    = the legend bar, 24 wide and barh = max(height * s, 256) tall, top-aligned with
 *            the map, 24 px right of it; top is the maximum, bottom the minimum
 *   labels = 136 px column right of the bar: tick marks and values at min, max and three
 *            evenly spaced values between (e.g. "12.3k cycles"); one label when all values
 *            are equal (the map and bar then take the colormap's middle colour)
 *   image  = (16 + width * s + 24 + 24 + 136 + 16) x (16 + 36 + barh + 16), white background
 *
 * Colours: a viridis-like ramp (dark purple -> blue -> green -> yellow), luminance strictly
 * increasing with the value, linear between min and max of the values.
 *
 * Text: UTF-8, drawn with FreeType in DejaVu Sans, 18 px (title) and 14 px (labels):
 * /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf (fonts-dejavu-core, installed by
 * scripts/deps.sh), else DejaVuSans.ttf in ~/.fonts, /usr/share/fonts/{TTF,dejavu,truetype} or
 * /usr/local/share/fonts. If none loads, the map, bar and tick marks are still written, without
 * text, and that is not an error.
 */
#ifndef SFSIM_HEATMAP_H
#define SFSIM_HEATMAP_H

#include <stddef.h>

#include "../host/outfile.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Write values (width x height, each 1..8192; row-major, top row first; each finite and >= 0)
 * as a heat-map PNG (path ending in .png) laid out as above. title and
 * unit may be NULL or empty; keep unit short (about 8 characters fit the label column).
 * Returns 0, or -1 with "path: what was wrong" in err (the first pixel, in row-major order,
 * that is NaN, infinite or negative is named by its x and y; then no file is written). The file
 * goes through img_write_rgb8: set NULL writes it in place at once, a set stages it (img.h). */
int heatmap_write(OutSet *set, const char *path, const double *values, int width, int height,
                  const char *title, const char *unit, char *err, size_t errlen);

/* Test hook: use this font file instead of the search above; NULL restores the search. A path
 * that does not load means "no font" (the image is then written without text). */
void heatmap_set_font(const char *font_path);

#ifdef __cplusplus
}
#endif

#endif
