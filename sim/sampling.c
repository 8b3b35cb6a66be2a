/* sim/sampling.c -- tile sampling and the ratio estimator (see sampling.h, docs/sampling.md). */
#include "sampling.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

uint32_t sample_count(uint32_t ntiles, double fraction)
{
    if (ntiles == 0)
        return 0;
    double want = ceil(fraction * (double)ntiles - 1e-9);
    uint32_t n = want < 2.0 ? 2u : want > (double)ntiles ? ntiles : (uint32_t)want;
    return n > ntiles ? ntiles : n;
}

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

void sample_select(uint32_t ntiles, double fraction, uint32_t seed, uint8_t *selected)
{
    memset(selected, 0, ntiles);
    uint32_t n = sample_count(ntiles, fraction);
    if (n == ntiles) {
        memset(selected, 1, ntiles);
        return;
    }
    /* Partial Fisher-Yates over the tile indices: the first n places are the sample. */
    uint32_t *idx = malloc((size_t)ntiles * sizeof *idx);
    uint64_t s = 0x5f3759dfull ^ ((uint64_t)seed << 17) ^ seed;
    if (!idx) { /* no memory for the shuffle: a systematic sample with a seeded start instead */
        uint32_t step = ntiles / n, start = (uint32_t)(splitmix64(&s) % step);
        for (uint32_t k = 0; k < n; k++)
            selected[start + k * step] = 1;
        return;
    }
    for (uint32_t i = 0; i < ntiles; i++)
        idx[i] = i;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t j = i + (uint32_t)(splitmix64(&s) % (uint64_t)(ntiles - i));
        uint32_t t = idx[i];
        idx[i] = idx[j];
        idx[j] = t;
        selected[idx[i]] = 1;
    }
    free(idx);
}

double sample_t975(uint32_t df)
{
    static const double table[30] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228,
                                     2.201,  2.179, 2.160, 2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086,
                                     2.080,  2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042};
    if (df == 0)
        return INFINITY;
    if (df <= 30)
        return table[df - 1];
    /* Cornish-Fisher expansion around the normal quantile (Abramowitz & Stegun 26.7.5). */
    const double z = 1.959963984540054, d = (double)df;
    double z3 = z * z * z, z5 = z3 * z * z, z7 = z5 * z * z;
    double g1 = (z3 + z) / 4.0, g2 = (5 * z5 + 16 * z3 + 3 * z) / 96.0,
           g3 = (3 * z7 + 19 * z5 + 17 * z3 - 15 * z) / 384.0;
    return z + g1 / d + g2 / (d * d) + g3 / (d * d * d);
}

int sample_ratio_estimate(const double *y, const double *x, const uint8_t *selected, uint32_t ntiles,
                          SampleEstimate *out)
{
    memset(out, 0, sizeof *out);
    out->N = ntiles;
    double sy = 0.0, sx = 0.0, X = 0.0;
    uint32_t n = 0;
    for (uint32_t i = 0; i < ntiles; i++) {
        X += x[i];
        if (selected[i]) {
            sy += y[i];
            sx += x[i];
            n++;
        }
    }
    out->n = n;
    if (n == ntiles) { /* a census: exact */
        out->total = out->lo = out->hi = sy;
        out->ratio = sx > 0 ? sy / sx : 0.0;
        return 0;
    }
    if (n < 2 || !(sx > 0.0))
        return -1;
    double r = sy / sx, ss = 0.0;
    for (uint32_t i = 0; i < ntiles; i++)
        if (selected[i]) {
            double d = y[i] - r * x[i];
            ss += d * d;
        }
    double sd2 = ss / (double)(n - 1), N = (double)ntiles;
    double var = N * N * (1.0 - (double)n / N) / (double)n * sd2;
    out->ratio = r;
    out->total = r * X;
    out->std_error = sqrt(var);
    out->t = sample_t975(n - 1);
    out->lo = out->total - out->t * out->std_error;
    out->hi = out->total + out->t * out->std_error;
    if (out->lo < sy) /* the frame takes at least the cycles measured */
        out->lo = sy;
    return 0;
}
