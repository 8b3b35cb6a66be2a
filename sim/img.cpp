// sim/img.cpp -- the OpenImageIO shim: reading image files (img_read; `sfsim compare`). It is
// the image library libsfsim-img.so, which bin/sfsim loads with dlopen when it first reads an
// image (sim/imglib.c); it exports one table, img_shim (sim/imgshim.h). sfsim's own outputs are
// written without it (sim/img_write.c, sim/heatmap.c), so that a run does not load OpenImageIO's
// ~265 shared libraries (docs/performance.md, "Start-up").
//
// Owns: decoding image files through OpenImageIO into float RGB. Must not: write files, or call
// into the program.
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "imgshim.h"

namespace {

int fail(char *err, size_t errlen, const char *path, const std::string &why)
{
    std::snprintf(err, errlen, "%s: %s", path, why.empty() ? "image error" : why.c_str());
    return -1;
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

// The one symbol the library exports (built with -fvisibility=hidden); sim/imglib.c looks it up.
extern "C" {
extern __attribute__((visibility("default"))) const ImgShim img_shim;
}

const ImgShim img_shim = {IMG_SHIM_ABI, sizeof(ImgShim), read_image};
