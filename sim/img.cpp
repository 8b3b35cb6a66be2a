// sim/img.cpp -- the OpenImageIO shim: the only place sfsim touches image files. With
// sim/heatmap.cpp it is the image library libsfsim-img.so, which bin/sfsim loads with dlopen
// when it first needs an image (sim/imglib.c); it exports one table, img_shim (sim/imgshim.h).
//
// Owns: encoding and reading image files through OpenImageIO. Must not: compute statistics or
// tone-map beyond the display transfer documented in img.h (that stays in C where it is tested);
// write files itself or call into the program (the bytes go to the caller's ImgSink).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "imgshim.h"

namespace {

int fail(char *err, size_t errlen, const char *path, const std::string &why)
{
    std::snprintf(err, errlen, "%s: %s", path, why.empty() ? "image error" : why.c_str());
    return -1;
}

// Encoded in memory, then written by the sink (sim/outfile.c in sfsim): OpenImageIO's PNG
// writer does not report a failed write (a full disk left a 0-byte cost.png behind a "wrote"
// line), and outfile checks every write, renames the file into place only when whole, and counts the writes for the fault
// hook like every other output.
int write_image(const ImgSink *sink, const char *path, int w, int h, OIIO::TypeDesc type, const void *pixels,
                char *err, size_t errlen)
{
    if (w <= 0 || h <= 0)
        return fail(err, errlen, path, "image size must be positive");
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        return fail(err, errlen, path, "no image writer for this file name: " + OIIO::geterror());
    if (!out->supports("ioproxy"))
        return fail(err, errlen, path, std::string("the ") + out->format_name() + " writer cannot encode in memory");
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput mem(bytes);
    OIIO::ImageSpec spec(w, h, 3, type);
    // PNG: one row filter (Sub, libpng's PNG_FILTER_SUB) rather than libpng's trial of all five
    // per row, and zlib's fastest level. The pixels are the same either way (the same-outputs
    // table hashes pixels, not file bytes); the defaults took 170 M instructions of a 32 x 32
    // run's cost.png, on the critical path of a small run (docs/performance.md, "Start-up").
    spec.attribute("png:filter", 0x10);
    spec.attribute("png:compressionLevel", 1);
    if (!out->set_ioproxy(&mem) || !out->open(path, spec))
        return fail(err, errlen, path, out->geterror());
    if (!out->write_image(type, pixels) || !out->close())
        return fail(err, errlen, path, out->geterror());
    return sink->write(sink->ctx, path, bytes.data(), bytes.size(), err, errlen);
}

float srgb_encode(float x)
{
    return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
}

int write_linear(const ImgSink *sink, const char *path, const float *rgb, int width, int height, char *err,
                 size_t errlen)
{
    return write_image(sink, path, width, height, OIIO::TypeDesc::FLOAT, rgb, err, errlen);
}

int write_display(const ImgSink *sink, const char *path, const float *rgb, int width, int height, float exposure,
                  char *err, size_t errlen)
{
    std::vector<unsigned char> px((size_t)width * height * 3);
    for (size_t i = 0; i < px.size(); i += 3) {
        bool bad = !std::isfinite(rgb[i]) || !std::isfinite(rgb[i + 1]) || !std::isfinite(rgb[i + 2]);
        for (int c = 0; c < 3; c++) {
            float v = bad ? (c == 1 ? 0.0f : 1.0f) : std::fmin(std::fmax(rgb[i + c] * exposure, 0.0f), 1.0f);
            px[i + c] = (unsigned char)std::lround((bad ? v : srgb_encode(v)) * 255.0f);
        }
    }
    return write_image(sink, path, width, height, OIIO::TypeDesc::UINT8, px.data(), err, errlen);
}

int read_image(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen)
{
    *rgb = nullptr;
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        return fail(err, errlen, path, OIIO::geterror());
    const OIIO::ImageSpec &spec = in->spec();
    int w = spec.width, h = spec.height, nc = spec.nchannels;
    if (w <= 0 || h <= 0 || nc <= 0)
        return fail(err, errlen, path, "empty image");
    std::vector<float> all((size_t)w * h * nc);
    if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data()))
        return fail(err, errlen, path, in->geterror());
    in->close();
    float *out = (float *)std::malloc(sizeof(float) * 3 * (size_t)w * h);
    if (!out)
        return fail(err, errlen, path, "out of memory");
    for (size_t p = 0; p < (size_t)w * h; p++)
        for (int c = 0; c < 3; c++)
            out[3 * p + c] = all[p * nc + (nc >= 3 ? c : 0)];
    *rgb = out;
    *width = w;
    *height = h;
    return 0;
}

} // namespace

extern "C" int imgshim_write_rgb8(const ImgSink *sink, const char *path, const float *rgb, int width, int height,
                                  char *err, size_t errlen)
{
    std::vector<unsigned char> px((size_t)width * height * 3);
    imgshim_to_u8_n(rgb, px.data(), px.size());
    return write_image(sink, path, width, height, OIIO::TypeDesc::UINT8, px.data(), err, errlen);
}

// Equal to lround(fmin(fmax(x, 0), 1) * 255) for finite x, else 0, for every float x
// (tests/io/test_imglib.c), without the three library calls per channel. 0 < x <= FLT_MAX
// is b - 1 < 0x7f7fffff on x's bits (false for zeros, negatives, Inf and NaN). Rounding y (in
// [0, 255]) half up without leaving float: r = trunc(y), and y - r is exact (r >= y / 2 once
// y >= 1; r = 0 below), so r + (y - r >= 0.5) is what lround gives; y + 0.5f would not do,
// 0.49999997f + 0.5f rounds up to 1.
extern "C" unsigned char imgshim_to_u8(float x)
{
    uint32_t b;
    std::memcpy(&b, &x, sizeof b);
    float c = b - 1u < 0x7f7fffffu ? (x < 1.0f ? x : 1.0f) : 0.0f;
    float y = c * 255.0f;
    int r = (int)y;
    return (unsigned char)(r + (y - (float)r >= 0.5f));
}

// imgshim_to_u8 eight channels at a time, in GCC's vector extensions (SSE pairs in the portable
// build): -O2 leaves the scalar loop alone, and cost.png's ~1.3 M channels took 24 M
// instructions one at a time, 5 ms of the 32 x 32 run's critical path (docs/performance.md,
// "Start-up"). The same operations, lane by lane, so the same bytes (every float is checked
// in tests/io/test_imglib.c).
extern "C" void imgshim_to_u8_n(const float *x, unsigned char *out, size_t n)
{
    typedef float F8 __attribute__((vector_size(32)));
    typedef int32_t I8 __attribute__((vector_size(32)));
    typedef uint32_t U8 __attribute__((vector_size(32)));
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        F8 v;
        std::memcpy(&v, x + i, sizeof v);
        I8 keep = ((U8)v - 1u) < 0x7f7fffffu; // -1 where 0 < x <= FLT_MAX
        F8 c = v < 1.0f ? v : 1.0f;
        F8 y = (F8)((I8)c & keep) * 255.0f;
        I8 r = __builtin_convertvector(y, I8);
        r -= (y - __builtin_convertvector(r, F8)) >= 0.5f; // a true lane is -1
        for (int j = 0; j < 8; j++)
            out[i + j] = (unsigned char)r[j];
    }
    for (; i < n; i++)
        out[i] = imgshim_to_u8(x[i]);
}

// The one symbol the library exports (built with -fvisibility=hidden); sim/imglib.c looks it up.
extern "C" {
extern __attribute__((visibility("default"))) const ImgShim img_shim;
}

const ImgShim img_shim = {
    IMG_SHIM_ABI,         sizeof(ImgShim),       write_linear,          write_display,
    imgshim_write_rgb8,   read_image,            imgshim_heatmap_write, imgshim_heatmap_set_font,
};
