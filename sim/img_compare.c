/* sim/img_compare.c -- statistics between two images (sfsim compare, tests, benchmarks).
 *
 * Owns: RMSE, PSNR, max difference, means and NaN/Inf counts, and which encoding a file's format
 * stores (from its first bytes). Must not: decode or write images (sim/img.cpp does).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "img.h"

ImgEncoding img_encoding(const char *path)
{
    unsigned char h[16] = {0};
    FILE *f = fopen(path, "rb");
    if (!f)
        return IMG_ENC_UNKNOWN;
    size_t n = fread(h, 1, sizeof h, f);
    fclose(f);
    static const struct { const char *magic; size_t len; ImgEncoding enc; } formats[] = {
        {"\x76\x2f\x31\x01", 4, IMG_ENC_LINEAR},               /* OpenEXR */
        {"#?RADIANCE", 10, IMG_ENC_LINEAR},                     /* Radiance HDR */
        {"#?RGBE", 6, IMG_ENC_LINEAR},
        {"PF\n", 3, IMG_ENC_LINEAR},                            /* PFM, colour and grey */
        {"Pf\n", 3, IMG_ENC_LINEAR},
        {"\x89PNG\r\n\x1a\n", 8, IMG_ENC_DISPLAY},               /* PNG: sRGB-encoded integers */
        {"\xff\xd8\xff", 3, IMG_ENC_DISPLAY},                    /* JPEG */
        {"GIF8", 4, IMG_ENC_DISPLAY},
        {"BM", 2, IMG_ENC_DISPLAY},
    };
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; i++)
        if (n >= formats[i].len && !memcmp(h, formats[i].magic, formats[i].len))
            return formats[i].enc;
    return IMG_ENC_UNKNOWN;
}

void img_compare(const float *a, const float *b, int width, int height, ImgCompare *out)
{
    double se = 0.0, sa = 0.0, sb = 0.0, maxd = 0.0;
    long n = 0, na = 0, nb = 0, nfa = 0, nfb = 0;
    long total = 3L * width * height;
    for (long i = 0; i < total; i++) {
        int fa = isfinite(a[i]), fb = isfinite(b[i]);
        na += !fa;
        nb += !fb;
        if (fa) {
            sa += a[i];
            nfa++;
        }
        if (fb) {
            sb += b[i];
            nfb++;
        }
        if (fa && fb) {
            double d = (double)a[i] - (double)b[i];
            se += d * d;
            if (fabs(d) > maxd)
                maxd = fabs(d);
            n++;
        }
    }
    out->rmse = n ? sqrt(se / (double)n) : 0.0;
    out->psnr = out->rmse > 0.0 ? 20.0 * log10(1.0 / out->rmse) : INFINITY;
    out->max_abs = maxd;
    out->mean_a = nfa ? sa / (double)nfa : 0.0;
    out->mean_b = nfb ? sb / (double)nfb : 0.0;
    out->nan_a = na;
    out->nan_b = nb;
}
