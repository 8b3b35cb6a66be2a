/* sim/run/chipwaves.c -- a sampled chip's phase 2 (chipsampled.h, step 5): waves of the whole chip
 * at instants of the predicted schedule, their units also timed alone; the other cores' factor r
 * on the cycles (docs/sampling.md, "Sampling a chip"). */
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

#include "../chip/chip.h"
#include "../sampling.h"
#include "chipsampled_int.h"

/* A unit's share of the shared memory's work, as chipmemest.h counts it. */
static void mem_of_core(const ChipCoreStats *c, double *y)
{
    y[CME_REQUESTS] = (double)c->requests;
    y[CME_LATENCY] = (double)c->read_latency;
    y[CME_L2_ACCESSES] = (double)c->l2_accesses;
    y[CME_L2_HITS] = (double)c->l2_hits;
    y[CME_DRAM_BYTES] = (double)c->dram_bytes;
}

/* One wave at cycle `at` of the predicted schedule: its units' cycles together (*wsum) and alone
 * (*asum), over the units timed both ways; and where the memory figures are estimated, each core's
 * next unit after its own (the wave's second units: from the state the first left, as in the
 * frame), whose memory figures together less alone are summed by stratum (0: R, 1: F, a tile's
 * first pass) into md[f] over mn[f] of them. 0 (nothing running then: all 0), or -1. */
static int wave_at(ChipSampler *s, double at, double *wsum, double *asum, double md[2][CME_COUNT], uint32_t mn[2])
{
    *wsum = *asum = 0.0;
    memset(md, 0, 2 * sizeof md[0]);
    mn[0] = mn[1] = 0;
    /* the second units only where the memory figures are estimated (chipsampled.c) */
    const int mem = s->shared && s->fr->chip.record_step <= 1;
    uint32_t *wave = malloc((size_t)s->K * sizeof *wave), nwave = 0, first = s->N;
    uint32_t *then = malloc((size_t)s->K * sizeof *then), *tnext = malloc((size_t)s->ntiles * sizeof *tnext);
    FuncUnit *alone = calloc(2 * CHIPSAMPLED_WAVE_ALONE, sizeof *alone);
    if (!wave || !then || !tnext || !alone) {
        snprintf(s->err, s->errlen, "out of memory for a wave of %u units", s->K);
        free(wave);
        free(then);
        free(tnext);
        free(alone);
        return -1;
    }
    for (uint32_t t = 0; t < s->ntiles; t++) /* each tile's successor on its core in the schedule */
        tnext[t] = UINT32_MAX;
    for (uint32_t t = 0; t < s->ntiles; t++)
        if (s->tprev[t] < s->ntiles)
            tnext[s->tprev[t]] = t;
    for (uint32_t i = 0; i < s->N && nwave < s->K; i++) { /* in start order: the earliest first */
        const uint32_t u = s->order[i];
        if (s->start[u] <= at && at < s->start[u] + s->pred[u]) {
            wave[nwave++] = u;
            if (first == s->N)
                first = i;
        }
    }
    for (uint32_t i = 0; i < nwave; i++) /* a tile's last pass: the core's next tile follows */
        then[i] = wave[i] % s->spp + 1 == s->spp ? tnext[wave[i] / s->spp] : UINT32_MAX;
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
        wp.wave_passes = mem ? 2 : 1;
        wp.wave_next = then;
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
        uint32_t pick[2 * CHIPSAMPLED_WAVE_ALONE], m2 = 0;
        for (uint32_t i = 0; i < m; i++) { /* evenly over the wave's cores, and their second units */
            const uint32_t c = (uint32_t)((uint64_t)i * nwave / m);
            pick[i] = wave[c];
            if (!mem || !st.pass_mem)
                continue;
            if (pick[i] % s->spp + 1 < s->spp)
                pick[m + m2++] = pick[i] + 1;
            else if (then[c] < s->ntiles)
                pick[m + m2++] = then[c] * s->spp;
        }
        if (rc == 0)
            rc = cs_time_alone(s, pick, m + m2, alone);
        for (uint32_t i = 0; rc == 0 && i < m; i++) {
            *wsum += (double)st.pass_cycles[pick[i]];
            *asum += (double)alone[i].cycles;
        }
        for (uint32_t i = 0; rc == 0 && i < m2; i++) { /* stratum 1: a tile's first pass; 0: the rest */
            const int f = pick[m + i] % s->spp == 0;
            double yt[CME_COUNT], ya[CME_COUNT];
            mem_of_core(&st.pass_mem[pick[m + i]], yt);
            cs_unit_mem(&alone[m + i], ya);
            for (int q = 0; q < CME_COUNT; q++)
                md[f][q] += yt[q] - ya[q];
            mn[f]++;
        }
        if (rc == 0) {
            s->fr->chip.wave_units += nwave;
            s->fr->chip.alone_units += m + m2;
        }
        func_stats_free(&st);
    }
    free(wave);
    free(then);
    free(tnext);
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
    double ws[CHIPSAMPLED_MAX_WAVES] = {0}, as[CHIPSAMPLED_MAX_WAVES] = {0}, W = 0.0, A = 0.0;
    uint64_t z = (uint64_t)s->spec->sample_seed * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    const double offset = (double)((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
    uint32_t got = 0;
    for (uint32_t i = 0; i < w; i++) {
        cs_note(s, "wave %u of %u: the units running then, on the whole chip and alone", i + 1, w, 0);
        const double at = first_end + (end - first_end) * ((double)i + offset) / (double)w;
        double md[2][CME_COUNT];
        uint32_t mn[2];
        if (wave_at(s, at, &ws[got], &as[got], md, mn) != 0)
            return -1;
        if (mn[0] + mn[1]) { /* the memory figures' correction (chipmemest.h) */
            memcpy(&s->wave_md[s->nwave_md * 2 * CME_COUNT], md, sizeof md);
            memcpy(&s->wave_mn[s->nwave_md * 2], mn, sizeof mn);
            s->nwave_md++;
        }
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
    double jm[CHIPSAMPLED_MAX_WAVES], mean = 0.0, v = 0.0;
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
