/* sim/run/chipwaves.c -- a sampled chip's phase 2 (chipsampled.h, step 5): waves of the whole chip
 * at instants of the predicted schedule, their units also timed alone; the other cores' factor r
 * on the cycles (docs/sampling.md, "Sampling a chip"). */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>

#include "../sampling.h"
#include "chipsampled_int.h"

/* One wave at cycle `at` of the predicted schedule: its units' cycles together (*wsum) and alone
 * (*asum), over the units timed both ways. 0 (nothing running then: *wsum = *asum = 0), or -1. */
static int wave_at(ChipSampler *s, double at, double *wsum, double *asum)
{
    *wsum = *asum = 0.0;
    uint32_t *wave = malloc((size_t)s->K * sizeof *wave), nwave = 0, first = s->N;
    FuncUnit *alone = calloc(CHIPSAMPLED_WAVE_ALONE, sizeof *alone);
    if (!wave || !alone) {
        snprintf(s->err, s->errlen, "out of memory for a wave of %u units", s->K);
        free(wave);
        free(alone);
        return -1;
    }
    for (uint32_t i = 0; i < s->N && nwave < s->K; i++) { /* in start order: the earliest first */
        const uint32_t u = s->order[i];
        if (s->start[u] <= at && at < s->start[u] + s->pred[u]) {
            wave[nwave++] = u;
            if (first == s->N)
                first = i;
        }
    }
    int rc = 0;
    if (nwave) {
        uint64_t *lines = NULL;
        size_t nlines = 0;
        rc = chipwarm_l2(s->warm, s->wthr[s->order[first]], &lines, &nlines, s->err, s->errlen);
        if (rc == 0)
            rc = cs_warm_lists(s, wave, nwave, 0);
        FuncParams wp = s->fp;
        wp.wave = wave;
        wp.nwave = nwave;
        wp.wave_warm = lines;
        wp.nwave_warm = nlines;
        wp.wave_fb_hi = cs_tiles_before(s, s->start[s->order[first]]);
        wp.unit_warm_l1 = cs_warm1_of;
        wp.unit_warm_ctx = s;
        wp.progress = NULL;
        FuncStats st = {0};
        if (rc == 0)
            rc = func_render(&s->sc->p, &wp, NULL, &st, s->err, s->errlen);
        free(lines);
        cs_warm_drop(s, wave, nwave);
        const uint32_t m = nwave < CHIPSAMPLED_WAVE_ALONE ? nwave : CHIPSAMPLED_WAVE_ALONE;
        uint32_t pick[CHIPSAMPLED_WAVE_ALONE];
        for (uint32_t i = 0; i < m; i++) /* evenly over the wave's cores */
            pick[i] = wave[(uint32_t)((uint64_t)i * nwave / m)];
        if (rc == 0)
            rc = cs_time_alone(s, pick, m, alone);
        for (uint32_t i = 0; rc == 0 && i < m; i++) {
            *wsum += (double)st.pass_cycles[pick[i]];
            *asum += (double)alone[i].cycles;
        }
        if (rc == 0) {
            s->fr->chip.wave_units += nwave;
            s->fr->chip.alone_units += m;
        }
        func_stats_free(&st);
    }
    free(wave);
    free(alone);
    return rc;
}

/* The other cores' factor r over waves evenly spaced after the opening (a seeded offset), and its
 * relative variance (the delete-one jackknife over waves). No waves to time (the opening is the
 * frame): r = 1, exact. */
int chipwaves_run(ChipSampler *s, double *r, double *rel_var)
{
    *r = 1.0;
    *rel_var = 0.0;
    double first_end = 0.0, end = 0.0;
    for (uint32_t u = 0; u < s->N; u++) {
        if (s->exact[u] >= 0.0 && s->start[u] + s->pred[u] > first_end)
            first_end = s->start[u] + s->pred[u];
        if (s->start[u] + s->pred[u] > end)
            end = s->start[u] + s->pred[u];
    }
    const uint32_t w = chipsampled_waves(s->K);
    if (!s->shared || s->K < 2 || end <= first_end)
        return 0;
    double ws[8] = {0}, as[8] = {0}, W = 0.0, A = 0.0;
    uint64_t z = (uint64_t)s->spec->sample_seed * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    const double offset = (double)((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
    uint32_t got = 0;
    for (uint32_t i = 0; i < w; i++) {
        cs_note(s, "wave %u of %u: the units running then, on the whole chip and alone", i + 1, w, 0);
        const double at = first_end + (end - first_end) * ((double)i + offset) / (double)w;
        if (wave_at(s, at, &ws[got], &as[got]) != 0)
            return -1;
        if (as[got] > 0.0) {
            W += ws[got];
            A += as[got];
            got++;
        }
    }
    s->fr->chip.waves = got;
    if (!got || A <= 0.0)
        return 0;
    *r = W / A;
    if (got < 2) { /* one wave: no spread to tell; the interval says nothing of r */
        *rel_var = 0.0;
        return 0;
    }
    double jm[8], mean = 0.0, v = 0.0;
    for (uint32_t i = 0; i < got; i++) {
        jm[i] = (W - ws[i]) / (A - as[i]);
        mean += jm[i] / got;
    }
    for (uint32_t i = 0; i < got; i++)
        v += (jm[i] - mean) * (jm[i] - mean);
    v *= (double)(got - 1) / got;
    *rel_var = v / (*r * *r);
    const double h = sample_t975(got - 1) * sqrt(v);
    s->fr->chip.r_lo = *r - h;
    s->fr->chip.r_hi = *r + h;
    return 0;
}
