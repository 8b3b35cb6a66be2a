/* tools/sample41/chiprep.c -- issue 41's design study (docs/sampling.md, "Sampling a chip"):
 * the estimator of the chosen design replayed on measured cycles, over seeds.
 * Build (not part of make):  gcc -O2 -I. -o build/chiprep tools/sample41/chiprep.c build/libsfsim.a -lgsl -lgslcblas -lm
 * usage: chiprep UNITS.tsv TILES.txt K SPP TARGET N0 PILOT(0|1) SEEDS [TAIL [BC]]
 *   RHO: the draws' tile errors correlated in frame order, AR(1) with lag-1 correlation RHO
 *   (usage ... SEEDS TAIL BC RHO; default 0: independent).
 *   BC 1: the tile-effect makespan bias-corrected by its draws (2 M - mean of the draws).
 *   TAIL: up to 2 more units timed in each of the last TAIL tiles in frame order (a tail stratum for
 *   the tile-effect estimate only).
 *   TARGET > 0: today's sequential rule from N0 units to +-TARGET on the total; TARGET = 0: N0 units.
 *   PILOT 1: the --no-image pilot's counts as auxiliaries.
 * UNITS.tsv: bench/speed_vs_error's dump (paper machine's per-unit cycles and aux).
 * TILES.txt: per tile "paper_cycles chip_cycles" in frame order.
 * y of unit u (tile t) = paper_u * chip_t / paper_t (the chip's tile cycles spread over its passes
 * as on the paper machine). Estimates: the total (today's estimator, sequential rule), every tile's
 * cycles (measured units + the fit's predictions), the makespan = list schedule of those on K cores,
 * its interval (a) the total's relative interval, (b) the delete-one jackknife of the makespan;
 * (c) the tile-effect model: each tile's estimate corrected by its sampled units' mean relative
 * residual (shrunk by sigma_a^2 / (sigma_a^2 + sigma_e^2 / m), sigma_a^2 from same-tile pairs of
 * residuals), and an interval from the jackknife's variance plus a parametric bootstrap (400 draws)
 * of the unsampled units' tile effects through the list schedule. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sim/sampling.h"

static uint32_t N, T, K, SPP, KX = 3;
static double *y, *x, *tile_true;
static int measure(void *ctx, const uint32_t *units, uint32_t count, double *ys)
{
    (void)ctx;
    for (uint32_t i = 0; i < count; i++) ys[i] = y[units[i]];
    return 0;
}
static double ls(const double *tc)
{
    double fr[1024] = {0};
    for (uint32_t t = 0; t < T; t++) {
        uint32_t b = 0;
        for (uint32_t k = 1; k < K; k++) if (fr[k] < fr[b]) b = k;
        fr[b] += tc[t];
    }
    double m = 0;
    for (uint32_t k = 0; k < K; k++) if (fr[k] > m) m = fr[k];
    return m;
}
/* tile estimates from coefficients, sample[0..n) measured except `skip` (or none: skip = n) */
static double ms_from(const double *coef, const uint32_t *sample, uint32_t n, uint32_t skip, unsigned char *meas, double *tc)
{
    memset(meas, 0, N);
    for (uint32_t i = 0; i < n; i++) if (i != skip) meas[sample[i]] = 1;
    for (uint32_t t = 0; t < T; t++) tc[t] = 0;
    for (uint32_t u = 0; u < N; u++) {
        double p = coef[0];
        for (uint32_t j = 0; j < KX; j++) p += coef[j + 1] * x[(size_t)u * KX + j];
        tc[u / SPP] += meas[u] ? y[u] : p;
    }
    return ls(tc);
}
int main(int argc, char **argv)
{
    if (argc < 9) { fprintf(stderr, "usage\n"); return 2; }
    K = atoi(argv[3]); SPP = atoi(argv[4]);
    double target = atof(argv[5]); uint32_t n0 = atoi(argv[6]); int pilot = atoi(argv[7]); int seeds = atoi(argv[8]);
    uint32_t tail = argc > 9 ? (uint32_t)atoi(argv[9]) : 0, tail_units = 0; double tail_sum = 0;
    int bias_correct = argc > 10 ? atoi(argv[10]) : 0;
    double rho = argc > 11 ? atof(argv[11]) : 0.0;
    FILE *f = fopen(argv[2], "r");
    double pt[4096], ct[4096]; T = 0;
    while (fscanf(f, "%lf %lf", &pt[T], &ct[T]) == 2) T++;
    fclose(f);
    N = T * SPP;
    y = malloc(N * sizeof *y); x = malloc(N * KX * sizeof *x); tile_true = ct;
    f = fopen(argv[1], "r");
    char line[1024]; uint32_t u = 0;
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') continue;
        unsigned id; double c, ins, a[6];
        if (sscanf(line, "%u %lf %lf %lf %lf %lf %lf %lf %lf", &id, &c, &ins, a, a + 1, a + 2, a + 3, a + 4, a + 5) != 9) continue;
        y[id] = c * ct[id / SPP] / pt[id / SPP];
        for (uint32_t j = 0; j < KX; j++) x[(size_t)id * KX + j] = a[j + (pilot ? 3 : 0)];
        u++;
    }
    fclose(f);
    if (u != N) { fprintf(stderr, "units %u != %u\n", u, N); return 1; }
    double Y = 0; for (uint32_t i = 0; i < N; i++) Y += y[i];
    double M = ls(ct);
    uint32_t *order = malloc(N * sizeof *order), *sub = malloc(N * sizeof *sub);
    double *ys = malloc(N * sizeof *ys), *tc = malloc(T * sizeof *tc);
    unsigned char *meas = malloc(N);
    int covT = 0, covA = 0, covB = 0, covC = 0; double hwC = 0, errC = 0, sgnC = 0, sgnM = 0, sa_mean = 0, se_mean = 0; double errT = 0, errM = 0, maxM = 0, nsum = 0, hwA = 0, hwB = 0;
    for (int s = 1; s <= seeds; s++) {
        sample_order(N, s, order);
        SampleEstimate e;
        uint32_t n0s = target > 0 ? (N < n0 ? N : n0) : n0;
        if (target > 0) { if (sample_sequential(x, KX, order, N, n0s, target, measure, NULL, ys, &e, NULL)) return 1; }
        else { for (uint32_t i = 0; i < n0; i++) ys[i] = y[order[i]]; if (sample_regression_estimate(ys, x, KX, order, n0, N, &e)) return 1; }
        uint32_t n = e.n;
        double Mh = ms_from(e.coef, order, n, n, meas, tc);
        covT += e.lo <= Y && Y <= e.hi;
        errT += fabs(e.total / Y - 1);
        double em = fabs(Mh / M - 1); errM += em; if (em > maxM) maxM = em;
        double loA = Mh * e.lo / e.total, hiA = Mh * e.hi / e.total;
        covA += loA <= M && M <= hiA; hwA += (hiA - loA) / 2 / Mh;
        /* jackknife of the makespan */
        double jm[8192], mean = 0;
        for (uint32_t d = 0; d < n; d++) {
            uint32_t m2 = 0;
            for (uint32_t i = 0; i < n; i++) if (i != d) { sub[m2] = order[i]; m2++; }
            double yy[8192];
            for (uint32_t i = 0; i < m2; i++) yy[i] = y[sub[i]];
            SampleEstimate ed;
            if (sample_regression_estimate(yy, x, KX, sub, m2, N, &ed)) return 1;
            jm[d] = ms_from(ed.coef, order, n, d, meas, tc);
            mean += jm[d] / n;
        }
        double v = 0; for (uint32_t d = 0; d < n; d++) v += (jm[d] - mean) * (jm[d] - mean);
        v *= (1.0 - (double)n / N) * (n - 1.0) / n;
        double h = (n < N ? sample_t975(n - e.k - 1) : 0) * sqrt(v);
        covB += Mh - h <= M && M <= Mh + h; hwB += h / Mh;
        /* tile effects: relative residuals of the sampled units, their same-tile pair covariance */
        {
            static double r[8192]; static int tl[8192];
            double s2 = 0; for (uint32_t i = 0; i < n; i++) {
                uint32_t uu = order[i]; double p = e.coef[0];
                for (uint32_t j = 0; j < KX; j++) p += e.coef[j + 1] * x[(size_t)uu * KX + j];
                r[i] = (y[uu] - p) / p; tl[i] = uu / SPP; s2 += r[i] * r[i] / n; }
            double cov = 0; int np = 0;
            for (uint32_t i = 0; i < n; i++) for (uint32_t j = i + 1; j < n; j++) if (tl[i] == tl[j]) { cov += r[i] * r[j]; np++; }
            double sa2 = np ? cov / np : s2; if (sa2 < 0) sa2 = 0; if (sa2 > s2) sa2 = s2;
            double se2 = s2 - sa2;
            /* per tile: predicted unsampled cycles P_t, sampled count m_t, mean residual of sampled */
            static double Pt[4096], Mt[4096], Rt[4096], base[4096];
            for (uint32_t t = 0; t < T; t++) { Pt[t] = Mt[t] = Rt[t] = 0; }
            memset(meas, 0, N); for (uint32_t i = 0; i < n; i++) { meas[order[i]] = 1; Mt[tl[i]] += 1; Rt[tl[i]] += r[i]; }
            /* the tail stratum: up to 2 more units in each of the last TAIL tiles (for the tiles'
             * estimates and effects only; the total and the fit stay the simple random sample's) */
            tail_units = 0;
            for (uint32_t t = T > tail ? T - tail : 0; t < T; t++)
                for (uint32_t q = 0, want = SPP < 2 ? SPP : 2, got = 0; q < SPP && got < want; q++) {
                    uint32_t uu = t * SPP + (uint32_t)((q * 7u + (uint32_t)s * 3u + t) % SPP);
                    if (meas[uu]) { got++; continue; }
                    double pp = e.coef[0];
                    for (uint32_t j = 0; j < KX; j++)
                        pp += e.coef[j + 1] * x[(size_t)uu * KX + j];
                    meas[uu] = 1; Mt[t] += 1; Rt[t] += (y[uu] - pp) / pp; got++; tail_units++;
                }
            for (uint32_t uu = 0; uu < N; uu++) if (!meas[uu]) { double p = e.coef[0];
                for (uint32_t j = 0; j < KX; j++)
                    p += e.coef[j + 1] * x[(size_t)uu * KX + j];
                Pt[uu / SPP] += p; }
            double Mc;
            { for (uint32_t t = 0; t < T; t++) tc[t] = 0;
              for (uint32_t uu = 0; uu < N; uu++) { double p = e.coef[0];
                  for (uint32_t j = 0; j < KX; j++)
                      p += e.coef[j + 1] * x[(size_t)uu * KX + j];
                  tc[uu / SPP] += meas[uu] ? y[uu] : p; }
              for (uint32_t t = 0; t < T; t++) { double sh = Mt[t] > 0 ? Mt[t] * sa2 / (Mt[t] * sa2 + se2 + 1e-300) : 0;
                double ahat = Mt[t] > 0 ? sh * Rt[t] / Mt[t] : 0; base[t] = tc[t] + ahat * Pt[t];
                Pt[t] = Pt[t] * sqrt(sa2 * (1 - sh)); }
              Mc = ls(base); }
            /* bootstrap of the tile effects */
            uint64_t st = 12345 + s; double bs = 0, bs2 = 0, ar = 0; int B = 400;
            for (int b = 0; b < B; b++) {
                for (uint32_t t = 0; t < T; t++) {
                    st = st * 6364136223846793005ull + 1442695040888963407ull; double u1 = ((st >> 11) + 0.5) / 9007199254740992.0;
                    st = st * 6364136223846793005ull + 1442695040888963407ull; double u2 = ((st >> 11) + 0.5) / 9007199254740992.0;
                    double z = sqrt(-2 * log(u1)) * cos(6.283185307179586 * u2);
                    ar = t == 0 ? z : rho * ar + sqrt(1 - rho * rho) * z; /* AR(1) in frame order */
                    tc[t] = base[t] + Pt[t] * ar; }
                double mb = ls(tc); bs += mb / B; bs2 += mb * mb / B; }
            double vb = bs2 - bs * bs; if (vb < 0) vb = 0;
            double h2 = (n < N ? sample_t975(n - e.k - 1) : 0) * sqrt(v + vb);
            double c2 = bias_correct ? 2 * Mc - bs : Mc; /* centre: tile-corrected LS (bootstrap bias-corrected with BC=1) */
            covC += c2 - h2 <= M && M <= c2 + h2; hwC += h2 / c2; errC += fabs(c2 / M - 1); sgnC += c2 / M - 1; sgnM += Mh / M - 1;
            tail_sum += tail_units; sa_mean += sqrt(sa2) / seeds; se_mean += sqrt(se2) / seeds;
        }
        nsum += n;
    }
    printf("N=%u tiles=%u K=%u Y=%.0f M=%.0f M/(Y/K)=%.4f seeds=%d pilot=%d target=%g n0=%u: mean units %.1f | total: cover %d, mean|err| %.3f %% | makespan: mean|err| %.3f %%, max %.3f %%, cover (total's rel. interval) %d (mean half-width %.2f %%), cover (jackknife) %d (mean half-width %.2f %%)\n",
           N, T, K, Y, M, M / (Y / K), seeds, pilot, target, n0, nsum / seeds, covT, 100 * errT / seeds, 100 * errM / seeds, 100 * maxM, covA, 100 * hwA / seeds, covB, 100 * hwB / seeds);
    printf("  tail stratum: last %u tiles, %.1f more units (mean)\n", tail, tail_sum / seeds);
    printf("  makespan signed mean error %+.3f %%; tile-effect model: sigma_a %.2f %%, sigma_e %.2f %% (means); tile-corrected makespan mean|err| %.3f %% (signed %+.3f %%), interval (jackknife + tile-effect bootstrap) covers %d, mean half-width %.2f %%\n",
           100 * sgnM / seeds, 100 * sa_mean, 100 * se_mean, 100 * errC / seeds, 100 * sgnC / seeds, covC, 100 * hwC / seeds);
    return 0;
}
