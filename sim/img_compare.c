/* sim/img_compare.c -- statistics between two images (sfsim compare, tests, benchmarks).
 *
 * Owns: RMSE, PSNR, max difference, means and NaN/Inf counts. Must not: read or write files.
 */
#include <math.h>

#include "img.h"

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
