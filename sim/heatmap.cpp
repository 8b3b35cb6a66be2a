// sim/heatmap.cpp -- heat-map images (cost.png) drawn with OpenImageIO's ImageBufAlgo (colour
// map, frame lines, text) and plain copies (background, enlarged map, bar); part of
// the image library libsfsim-img.so with sim/img.cpp (sim/imgshim.h).
//
// Owns: the colormap table, the layout documented in heatmap.h, the font search. Must not: open
// image files itself (imgshim_write_rgb8 in img.cpp does, so errors read the same everywhere) or
// know what the values measure.
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "imgshim.h"

namespace {

using OIIO::ImageBuf;
using OIIO::ImageSpec;
using OIIO::TypeDesc;
namespace IBA = OIIO::ImageBufAlgo;

// Layout of heatmap.h, in output pixels.
constexpr int MARGIN = 16, TITLE_H = 36, GAP = 24, BAR_W = 24, LABEL_W = 136, TICK = 6;
constexpr int MIN_MAP_W = 512, MAX_MAP_H = 2048, MIN_BAR_H = 256, MAX_SIDE = 8192;
constexpr int TITLE_PX = 18, LABEL_PX = 14, NTICKS = 5;

// Ten evenly spaced stops of a viridis-like ramp, 8-bit sRGB. Rec. 709 luma of the stops rises
// 21, 53, 76, 95, 111, 130, 151, 176, 200, 222, and linear interpolation keeps it monotone.
constexpr unsigned char RAMP[][3] = {
    {0x44, 0x01, 0x54}, {0x48, 0x28, 0x78}, {0x3e, 0x4a, 0x89}, {0x31, 0x68, 0x8e},
    {0x26, 0x82, 0x8e}, {0x1f, 0x9e, 0x89}, {0x35, 0xb7, 0x79}, {0x6d, 0xcd, 0x59},
    {0xb4, 0xde, 0x2c}, {0xfd, 0xe7, 0x25},
};
constexpr int NRAMP = sizeof RAMP / sizeof RAMP[0];

const float BACKGROUND[3] = {1.0f, 1.0f, 1.0f};
const float INK[3] = {0.1f, 0.1f, 0.1f};
const float FRAME[3] = {0.35f, 0.35f, 0.35f};

const char *const DEJAVU = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
bool font_overridden = false;
std::string font_override;

int fail(char *err, size_t errlen, const char *path, const std::string &why)
{
    std::snprintf(err, errlen, "%s: %s", path, why.c_str());
    return -1;
}

// The font to draw with ("" is OpenImageIO's own default), or none: then no text is drawn.
std::optional<std::string> pick_font()
{
    std::vector<std::string> candidates;
    if (font_overridden)
        candidates = {font_override};
    else
        candidates = {DEJAVU, "DejaVuSans", ""};
    for (const std::string &f : candidates)
        if (IBA::text_size("0", LABEL_PX, f).defined())
            return f;
    return std::nullopt;
}

// A label: the value to `digits` significant digits with an SI prefix, then the unit.
std::string format_value(double v, int digits, const char *unit)
{
    static const char *const PREFIX[] = {"", "k", "M", "G", "T", "P"};
    int p = 0;
    while (std::fabs(v) >= 999.5 && p < 5) {
        v /= 1000.0;
        p++;
    }
    char buf[96];
    std::snprintf(buf, sizeof buf, "%.*g%s%s%s", digits, v, PREFIX[p], unit && *unit ? " " : "",
                  unit ? unit : "");
    return buf;
}

// Tick labels for values[]: three significant digits, more while neighbours would read alike.
std::vector<std::string> tick_labels(const std::vector<double> &values, const char *unit)
{
    std::vector<std::string> labels;
    for (int digits = 3; digits <= 8; digits++) {
        labels.clear();
        for (double v : values)
            labels.push_back(format_value(v, digits, unit));
        if (std::adjacent_find(labels.begin(), labels.end()) == labels.end())
            break;
    }
    return labels;
}

bool draw_text(ImageBuf &img, const std::optional<std::string> &font, int x, int y,
               const std::string &text, int px, IBA::TextAlignY aligny)
{
    if (!font || text.empty())
        return true;
    return IBA::render_text(img, x, y, text, px, *font, INK, IBA::TextAlignX::Left, aligny);
}

// The body of heatmap_write once the arguments are checked: the picture, RGB floats, in px
// (cw x ch). OpenImageIO reports failures through the ImageBuf, which is what `why` carries back.
bool render(std::vector<float> &px, int &cw, int &ch, const std::vector<float> &t, int w, int h, double lo,
            double hi, const char *title, const char *unit, std::string &why)
{
    int s = w >= MIN_MAP_W ? 1 : (MIN_MAP_W + w - 1) / w;
    s = std::max(1, std::min(s, MAX_MAP_H / h));
    const int map_w = w * s, map_h = h * s, bar_h = std::max(map_h, MIN_BAR_H);
    const int map_x = MARGIN, top = MARGIN + TITLE_H, bar_x = map_x + map_w + GAP;
    cw = bar_x + BAR_W + LABEL_W + MARGIN;
    ch = top + bar_h + MARGIN;

    float knots[NRAMP * 3];
    for (int i = 0; i < NRAMP * 3; i++)
        knots[i] = RAMP[i / 3][i % 3] / 255.0f;

    ImageBuf norm(ImageSpec(w, h, 1, TypeDesc::FLOAT)), rgb;
    std::vector<float> cells((size_t)w * h * 3);
    if (!norm.set_pixels(OIIO::ROI::All(), TypeDesc::FLOAT, t.data()) ||
        !IBA::color_map(rgb, norm, 0, NRAMP, 3, knots) ||
        !rgb.get_pixels(OIIO::ROI::All(), TypeDesc::FLOAT, cells.data())) {
        why = norm.has_error() ? norm.geterror() : rgb.geterror();
        return false;
    }

    // The bar runs from 1 (top) to 0 (bottom); a constant map is the middle colour throughout.
    ImageBuf ramp(ImageSpec(BAR_W, bar_h, 1, TypeDesc::FLOAT)), bar;
    const bool flat = !(hi > lo);
    const float one = flat ? 0.5f : 1.0f, zero = flat ? 0.5f : 0.0f;
    std::vector<float> bar_px((size_t)BAR_W * bar_h * 3);
    if (!IBA::fill(ramp, {&one, 1}, {&zero, 1}) ||
        !IBA::color_map(bar, ramp, 0, NRAMP, 3, knots) ||
        !bar.get_pixels(OIIO::ROI::All(), TypeDesc::FLOAT, bar_px.data())) {
        why = ramp.has_error() ? ramp.geterror() : bar.geterror();
        return false;
    }

    // Background, the map (each cell an s x s block: what a nearest-neighbour resample gives,
    // since (x + 0.5) / s is never within rounding of a whole number) and the bar, copied into
    // a plain buffer: the same values as ImageBufAlgo's fill, resample and paste, which walked
    // the ~730 x 600 canvas pixel by pixel (11 ms of a 32 x 32 run's cost.png, now 5 ms; the
    // run's critical path, docs/performance.md "Start-up").
    px.assign((size_t)cw * ch * 3, 0.0f);
    for (size_t i = 0; i < px.size(); i += 3)
        std::copy(BACKGROUND, BACKGROUND + 3, &px[i]);
    for (int y = 0; y < map_h; y++)
        for (int x = 0; x < map_w; x++)
            std::copy_n(&cells[((size_t)(y / s) * w + x / s) * 3], 3, &px[((size_t)(top + y) * cw + map_x + x) * 3]);
    for (int y = 0; y < bar_h; y++)
        std::copy_n(&bar_px[(size_t)y * BAR_W * 3], BAR_W * 3, &px[((size_t)(top + y) * cw + bar_x) * 3]);

    // The lines and the text are drawn into px itself: the ImageBuf wraps it. A canvas of its
    // own (zeroed, then set_pixels from px, then get_pixels back) walked the whole picture three
    // times more, 18% of the heat map's instructions.
    ImageBuf canvas(ImageSpec(cw, ch, 3, TypeDesc::FLOAT), px.data());
    bool ok = IBA::render_box(canvas, map_x - 1, top - 1, map_x + map_w, top + map_h, FRAME) &&
              IBA::render_box(canvas, bar_x - 1, top - 1, bar_x + BAR_W, top + bar_h, FRAME);

    std::vector<double> tick_t, tick_v;
    if (flat) {
        tick_t = {0.5};
        tick_v = {lo};
    } else {
        for (int i = 0; i < NTICKS; i++) {
            tick_t.push_back((double)i / (NTICKS - 1));
            tick_v.push_back(i == NTICKS - 1 ? hi : lo + (hi - lo) * i / (NTICKS - 1));
        }
    }
    std::vector<std::string> labels = tick_labels(tick_v, unit);
    const std::optional<std::string> font = pick_font();
    for (size_t i = 0; ok && i < tick_t.size(); i++) {
        int y = top + (int)std::lround((1.0 - tick_t[i]) * (bar_h - 1));
        int x = bar_x + BAR_W;
        ok = IBA::render_line(canvas, x, y, x + TICK - 1, y, FRAME) &&
             draw_text(canvas, font, x + TICK + 4, y, labels[i], LABEL_PX,
                       IBA::TextAlignY::Center);
    }
    ok = ok && draw_text(canvas, font, MARGIN, MARGIN + TITLE_H / 2, title ? title : "",
                         TITLE_PX, IBA::TextAlignY::Center);
    if (!ok)
        why = canvas.geterror();
    return ok;
}

} // namespace

extern "C" void imgshim_heatmap_set_font(const char *font_path)
{
    font_overridden = font_path != nullptr;
    font_override = font_path ? font_path : "";
}

extern "C" int imgshim_heatmap_write(const ImgSink *sink, const char *path, const double *values, int width,
                                     int height, const char *title, const char *unit, char *err, size_t errlen)
{
    if (width <= 0 || height <= 0 || width > MAX_SIDE || height > MAX_SIDE)
        return fail(err, errlen, path, "heat map size " + std::to_string(width) + " x " +
                                           std::to_string(height) + " is outside 1..8192");
    if (!values)
        return fail(err, errlen, path, "no values");
    size_t n = (size_t)width * height;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; i++) {
        double v = values[i];
        if (std::isfinite(v) && v >= 0.0) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            continue;
        }
        char why[160];
        std::snprintf(why, sizeof why, "pixel (%zu, %zu) is %s (%g); values must be finite and >= 0",
                      i % width, i / width,
                      std::isnan(v) ? "NaN" : std::isinf(v) ? "infinite" : "negative", v);
        return fail(err, errlen, path, why);
    }
    try {
        std::vector<float> t(n);
        for (size_t i = 0; i < n; i++)
            t[i] = hi > lo ? (float)((values[i] - lo) / (hi - lo)) : 0.5f;
        std::vector<float> px;
        int cw = 0, ch = 0;
        std::string why;
        if (!render(px, cw, ch, t, width, height, lo, hi, title, unit, why))
            return fail(err, errlen, path, "drawing the heat map: " + why);
        return imgshim_write_rgb8(sink, path, px.data(), cw, ch, err, errlen);
    } catch (const std::exception &e) {
        return fail(err, errlen, path, std::string("drawing the heat map: ") + e.what());
    }
}
