/* sim/run/chipsampled.c -- sampled mode on a chip (chipsampled.h; docs/sampling.md, "Sampling a
 * chip"). */
#include "chipsampled.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../chip/chip.h"
#include "../chipmemest.h"
#include "../chipsampling.h"
#include "../sampling.h"
#include "../util.h"
#include "chipsampled_int.h"
#include "chipwarm.h"

uint32_t chipsampled_waves(uint32_t cores) { return cores > 64 ? 2u : 4u; }

int chipsampled_wanted(const CfgMachine *cfg)
{
    return cfg->chip_cores > 1 || cfg->chip_memory == CFG_CHIP_MEMORY_SHARED;
}

/* FuncParams.unit_warm and unit_warm_l1: the lists made for the unit before its batch ran. */
static const uint64_t *warm_of(void *ctx, uint32_t unit, size_t *n)
{
    const ChipSampler *s = ctx;
    *n = s->wlen[unit];
    return s->wl[unit];
}

const uint64_t *cs_warm1_of(void *ctx, uint32_t unit, size_t *n)
{
    const ChipSampler *s = ctx;
    *n = s->wlen1[unit];
    return s->wl1[unit];
}

/* The tiles (frame order) that start before cycle `at` of the current schedule: the list schedule
 * hands tiles out in frame order at nondecreasing starts, so they are a prefix. */
uint32_t cs_tiles_before(const ChipSampler *s, double at)
{
    uint32_t lo = 0, hi = s->ntiles;
    while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (s->tstart[mid] < at)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* FuncParams.unit_warm_tiles: the tiles whose framebuffers were written before the unit starts. */
static void warm_tiles_of(void *ctx, uint32_t unit, uint32_t *lo, uint32_t *hi)
{
    const ChipSampler *s = ctx;
    *lo = 0;
    *hi = cs_tiles_before(s, s->start[unit]);
}

void cs_note(const ChipSampler *s, const char *fmt, unsigned a, unsigned b, unsigned c)
{
    if (!s->spec->note)
        return;
    char line[240];
    snprintf(line, sizeof line, fmt, a, b, c);
    size_t len = strlen(line);
    snprintf(line + len, sizeof line - len, " (%.1fs so far)", util_now() - s->started);
    s->spec->note(s->spec->progress_ctx, line);
}

/* ---- the predicted schedule -------------------------------------------------------------------- */

typedef struct StartKey {
    double start;
    uint32_t unit;
} StartKey;

static int start_order(const void *a, const void *b)
{
    const StartKey *x = a, *y = b;
    if (x->start != y->start)
        return x->start < y->start ? -1 : 1;
    return (x->unit > y->unit) - (x->unit < y->unit);
}

/* Every unit's predicted cycles (exact where known, else coef's fit of the golden counts, at least
 * 1), the list schedule of the tiles, each unit's start, and the units in start order. */
static int schedule(ChipSampler *s, const double *coef)
{
    StartKey *keys = malloc((size_t)s->N * sizeof *keys);
    if (!keys) {
        snprintf(s->err, s->errlen, "out of memory for %u units' schedule", s->N);
        return -1;
    }
    for (uint32_t t = 0; t < s->ntiles; t++)
        s->tile[t] = 0.0;
    for (uint32_t u = 0; u < s->N; u++) {
        double p = coef[0];
        for (int j = 0; j < AUX_K; j++)
            p += coef[j + 1] * s->x[(size_t)u * AUX_K + j];
        s->pred[u] = s->exact[u] >= 0.0 ? s->exact[u] : p > 1.0 ? p : 1.0;
        s->tile[u / s->spp] += s->pred[u];
    }
    uint32_t *last = malloc((size_t)s->K * sizeof *last);
    if (!last || chip_list_schedule(s->tile, s->ntiles, s->K, s->tstart, s->tcore) < 0.0) {
        snprintf(s->err, s->errlen, "out of memory for %u cores' schedule", s->K);
        free(keys);
        free(last);
        return -1;
    }
    for (uint32_t k = 0; k < s->K; k++)
        last[k] = UINT32_MAX;
    for (uint32_t t = 0; t < s->ntiles; t++) { /* (a core's tiles come in the frame's order) */
        s->tprev[t] = last[s->tcore[t]];
        last[s->tcore[t]] = t;
    }
    free(last);
    for (uint32_t t = 0; t < s->ntiles; t++) {
        double at = s->tstart[t];
        for (uint32_t p = 0; p < s->spp; p++) {
            const uint32_t u = t * s->spp + p;
            s->start[u] = at;
            at += s->pred[u];
            keys[u] = (StartKey){s->start[u], u};
        }
    }
    qsort(keys, s->N, sizeof *keys, start_order);
    for (uint32_t i = 0; i < s->N; i++) {
        s->order[i] = keys[i].unit;
        s->pos[keys[i].unit] = i;
    }
    free(keys);
    return 0;
}

/* The first schedule's fit: the opening's exact units on their golden counts when there are enough
 * of them for the regression, else the counts' sum (only the order of the starts matters here). */
static void first_coef(const ChipSampler *s, double coef[AUX_K + 1])
{
    coef[0] = 0.0;
    for (int j = 0; j < AUX_K; j++)
        coef[j + 1] = 1.0;
    uint32_t *sample = malloc((size_t)s->N * sizeof *sample);
    double *ys = malloc((size_t)s->N * sizeof *ys);
    uint32_t n = 0;
    for (uint32_t u = 0; sample && ys && u < s->N; u++)
        if (s->exact[u] >= 0.0) {
            sample[n] = u;
            ys[n++] = s->exact[u];
        }
    SampleEstimate e;
    if (sample && ys && n >= AUX_K + 3 && n < s->N &&
        sample_regression_estimate(ys, s->x, AUX_K, sample, n, s->N, &e) == 0 && e.r2 > 0.5)
        memcpy(coef, e.coef, (AUX_K + 1) * sizeof *coef);
    free(sample);
    free(ys);
}

/* The L2 warming's positions, from the first schedule, whose start order (s->pos) ranks the first
 * readers: a line counts as read by a unit's start when its first reader started before it (a unit
 * still running then, whole: halfway through it instead, the units alone missed 45-140 % more DRAM
 * lines than the full run, against 12-26 % fewer this way: docs/sampling.md). wthr[u]: how many
 * units start strictly before u (units starting together see none of each other's lines). */
static void warm_thresholds(ChipSampler *s)
{
    for (uint32_t i = 0; i < s->N; i++) { /* s->order: the units by start (ties: by unit) */
        const uint32_t u = s->order[i];
        s->wthr[u] = i > 0 && s->start[s->order[i - 1]] == s->start[u] ? s->wthr[s->order[i - 1]] : i;
    }
}

/* Each unit's first-read lines (s->first) from the first-reader table, by its position in the
 * schedule the table was made with (s->pos, unchanged since). (A tile's first pass also touches
 * its framebuffer's lines first; as a second part of this auxiliary that made DRAM's intervals
 * narrower than the warming's own bias, docs/sampling.md step 8, so it is not.) 0, or -1. */
static int first_lines(ChipSampler *s)
{
    double *by_pos = malloc((size_t)(s->N ? s->N : 1) * sizeof *by_pos);
    if (!by_pos) {
        snprintf(s->err, s->errlen, "out of memory for %u units' first-read lines", s->N);
        return -1;
    }
    chipwarm_first_counts(s->warm, s->N, by_pos);
    for (uint32_t u = 0; u < s->N; u++)
        s->first[u] = by_pos[s->pos[u]];
    free(by_pos);
    return 0;
}

/* ---- timing units ------------------------------------------------------------------------------ */

/* The unit before u on its core in the current schedule (UINT32_MAX: none). */
static uint32_t core_prev(const ChipSampler *s, uint32_t u)
{
    if (u % s->spp)
        return u - 1;
    const uint32_t t = s->tprev[u / s->spp];
    return t == UINT32_MAX ? t : t * s->spp + s->spp - 1;
}

/* The L1 lists of units[0..n) into wl1 (and the L2's, when l2, into wl). 0, or -1. */
int cs_warm_lists(ChipSampler *s, const uint32_t *units, uint32_t n, int l2)
{
    uint32_t *prev = calloc(n ? n : 1, sizeof *prev);
    uint64_t **lists = calloc(n ? n : 1, sizeof *lists);
    size_t *lens = calloc(n ? n : 1, sizeof *lens);
    int rc = 0;
    if (!prev || !lists || !lens) {
        snprintf(s->err, s->errlen, "out of memory for %u units' warming", n);
        rc = -1;
    }
    for (uint32_t i = 0; rc == 0 && i < n; i++)
        prev[i] = core_prev(s, units[i]);
    if (rc == 0)
        rc = chipwarm_l1(s->warm, prev, n, run_spec_threads(s->spec), lists, lens, s->err, s->errlen);
    for (uint32_t i = 0; rc == 0 && i < n; i++) { /* (a unit twice in a batch: one list kept) */
        free(s->wl1[units[i]]);
        s->wl1[units[i]] = lists[i];
        s->wlen1[units[i]] = lens[i];
        lists[i] = NULL;
        if (l2 && !s->wl[units[i]])
            rc = chipwarm_l2(s->warm, s->wthr[units[i]], &s->wl[units[i]], &s->wlen[units[i]], s->err, s->errlen);
    }
    for (uint32_t i = 0; lists && i < n; i++)
        free(lists[i]);
    free(prev);
    free(lists);
    free(lens);
    return rc;
}

/* The lists of units[0..n) freed. */
void cs_warm_drop(ChipSampler *s, const uint32_t *units, uint32_t n)
{
    for (uint32_t i = 0; i < n; i++) {
        const uint32_t u = units[i];
        free(s->wl[u]);
        free(s->wl1[u]);
        s->wl[u] = s->wl1[u] = NULL;
        s->wlen[u] = s->wlen1[u] = 0;
    }
}

/* The units alone (units[i] into out[i]), each warmed as the first schedule's start says (the L2)
 * and from the unit before it on its core (the L1). */
int cs_time_alone(ChipSampler *s, const uint32_t *units, uint32_t n, FuncUnit *out)
{
    int rc = s->shared ? cs_warm_lists(s, units, n, 1) : 0;
    if (rc == 0)
        rc = func_units(s->fs, units, n, out, s->err, s->errlen);
    if (s->shared)
        cs_warm_drop(s, units, n);
    return rc;
}

/* sim/sampling.h's SampleMeasure: phase 1's next units. */
static int measure(void *ctx, const uint32_t *units, uint32_t count, double *ys)
{
    ChipSampler *s = ctx;
    cs_note(s, "timing units %u..%u of %u alone", s->n + 1, s->n + count, s->N);
    FuncUnit *out = &s->units[s->n];
    if (cs_time_alone(s, units, count, out) != 0)
        return -1;
    for (uint32_t i = 0; i < count; i++) {
        ys[i] = (double)out[i].cycles;
        s->instructions[s->n + i] = (double)out[i].instructions;
    }
    s->n += count;
    return 0;
}

/* The opening: the chip's frame until pass 0 of its first K tiles has ended; every unit that ended
 * by then is exact. */
static int opening(ChipSampler *s)
{
    FuncParams op = s->fp;
    op.opening = 1;
    op.progress = NULL;
    FuncStats st;
    cs_note(s, "the chip's opening: its first %u units in full", s->ntiles < s->K ? s->ntiles : s->K, 0, 0);
    int rc = func_render(&s->sc->p, &op, NULL, &st, s->err, s->errlen);
    if (rc == 0 && (!st.pass_cycles || st.pass_spp != s->spp)) {
        snprintf(s->err, s->errlen, "sampled chip: the opening reported no units' cycles");
        rc = -1;
    }
    for (uint32_t u = 0; rc == 0 && u < s->N; u++)
        if (st.pass_cycles[u] > 0) {
            s->exact[u] = (double)st.pass_cycles[u];
            s->fr->chip.opening_units++;
        }
    if (rc == 0 && st.chip_mem) { /* its memory traffic, the memory figures' exact stratum */
        const ChipMemStats *m = st.chip_mem;
        s->open_mem[CME_REQUESTS] = (double)m->requests;
        s->open_mem[CME_LATENCY] = (double)m->read_latency;
        s->open_mem[CME_L2_ACCESSES] = (double)(m->l2.reads + m->l2.writes);
        s->open_mem[CME_L2_HITS] = (double)m->l2.hits;
        s->open_mem[CME_DRAM_BYTES] = (double)m->dram.bytes;
    }
    func_stats_free(&st);
    return rc;
}

/* ---- the frame --------------------------------------------------------------------------------- */

static int sampler_open(ChipSampler *s, const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg,
                        const FuncParams *fp, RunFrame *fr, char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    *s = (ChipSampler){.sc = sc, .spec = spec, .fr = fr, .ucfg = *cfg, .fp = *fp, .err = err, .errlen = errlen,
                       .K = (uint32_t)cfg->chip_cores, .shared = cfg->chip_memory == CFG_CHIP_MEMORY_SHARED,
                       .started = util_now()};
    s->fp.timed = 1;
    s->up = s->fp;
    s->up.progress = NULL;
    if (s->shared) {
        s->up.chip_unit = 1;
        s->up.unit_warm = warm_of;
        s->up.unit_warm_tiles = warm_tiles_of;
        s->up.unit_warm_l1 = cs_warm1_of;
        s->up.unit_warm_ctx = s;
    } else { /* cores on buses of their own: a unit is the paper machine's */
        s->ucfg.chip_cores = 1;
        s->up.cfg = &s->ucfg;
    }
    if (func_open(&sc->p, &s->up, &s->fs, err, errlen) != 0)
        return -1;
    if (sampled_countable(s->fs, err, errlen) != 0) {
        s->fs = NULL;
        return -1;
    }
    s->spp = (uint32_t)sc->s.render.spp;
    s->N = (uint32_t)func_units_total(s->fs);
    s->ntiles = s->N / s->spp;
    const size_t N = s->N ? s->N : 1, T = s->ntiles ? s->ntiles : 1;
    s->x = malloc(N * AUX_K * sizeof *s->x);
    s->exact = malloc(N * sizeof *s->exact);
    s->pred = malloc(N * sizeof *s->pred);
    s->start = malloc(N * sizeof *s->start);
    s->order = malloc(N * sizeof *s->order);
    s->pos = malloc(N * sizeof *s->pos);
    s->wthr = malloc(N * sizeof *s->wthr);
    s->first = calloc(N, sizeof *s->first);
    s->tile = malloc(T * sizeof *s->tile);
    s->tstart = malloc(T * sizeof *s->tstart);
    s->tcore = malloc(T * sizeof *s->tcore);
    s->tprev = malloc(T * sizeof *s->tprev);
    s->wl = calloc(N, sizeof *s->wl);
    s->wlen = calloc(N, sizeof *s->wlen);
    s->wl1 = calloc(N, sizeof *s->wl1);
    s->wlen1 = calloc(N, sizeof *s->wlen1);
    s->units = calloc(N, sizeof *s->units);
    s->instructions = malloc(N * sizeof *s->instructions);
    if (!s->x || !s->exact || !s->pred || !s->start || !s->order || !s->pos || !s->wthr || !s->first || !s->tile || !s->tstart ||
        !s->tcore || !s->tprev || !s->wl || !s->wlen || !s->wl1 || !s->wlen1 || !s->units || !s->instructions) {
        snprintf(err, errlen, "out of memory for %u units", s->N);
        return -1;
    }
    for (uint32_t u = 0; u < s->N; u++)
        s->exact[u] = -1.0;
    if (s->shared) {
        const RefParams rp = sampled_ref_params(spec, cfg, fr);
        const size_t line = (size_t)cfg->scene_line_bytes;
        const size_t l2 = (size_t)cfg->l2_size_kb * 1024 / line, l1 = (size_t)cfg->scene_cache_kb * 1024 / line;
        if (!(s->warm = chipwarm_new(&sc->p, &rp, s->ntiles, s->spp, (uint32_t)line, l2, l1))) {
            snprintf(err, errlen, "out of memory for the warming's record");
            return -1;
        }
    }
    return 0;
}

/* Closes the units' session into fr->f (its failure is the cause when there is one). */
static int sampler_close(ChipSampler *s, int rc)
{
    if (s->fs) {
        char cerr[1024];
        const int crc = func_close(s->fs, &s->fr->f, cerr, sizeof cerr);
        if (crc != 0) {
            snprintf(s->err, s->errlen, "%s", cerr);
            rc = crc;
        }
    }
    if (s->warm) {
        s->fr->chip.warm_units = chipwarm_recorded(s->warm);
        s->fr->chip.warm_seconds = chipwarm_seconds(s->warm);
    }
    chipwarm_free(s->warm);
    for (uint32_t u = 0; s->wl && s->wl1 && u < s->N; u++) {
        free(s->wl[u]);
        free(s->wl1[u]);
    }
    free(s->x);
    free(s->exact);
    free(s->pred);
    free(s->start);
    free(s->order);
    free(s->pos);
    free(s->wthr);
    free(s->first);
    free(s->tile);
    free(s->tstart);
    free(s->tcore);
    free(s->tprev);
    free(s->wl);
    free(s->wlen);
    free(s->wl1);
    free(s->wlen1);
    free(s->units);
    free(s->instructions);
    return rc;
}

/* ---- the memory figures ------------------------------------------------------------------------ */

/* F's extra units (chipmemest.h): the tiles' first passes outside the opening and the sample,
 * drawn at random (a stream of the sample's seed of their own) until F has CHIPSAMPLED_FIRST_UNITS
 * in the sample, into extra (*m of them). */
static void first_extra(const ChipSampler *s, const uint32_t *order, const uint8_t *fpass, uint32_t *extra,
                        uint32_t *m, uint32_t *perm)
{
    uint32_t have = 0, NF = 0;
    for (uint32_t i = 0; i < s->n; i++)
        have += fpass[order[i]];
    for (uint32_t t = 0; t < s->ntiles; t++)
        NF += fpass[t * s->spp];
    *m = 0;
    if (have >= CHIPSAMPLED_FIRST_UNITS || NF == 0)
        return;
    uint8_t *in_srs = calloc(s->ntiles, 1);
    if (!in_srs)
        return; /* (the estimate then has too few units of F and gives no figures) */
    for (uint32_t i = 0; i < s->n; i++)
        if (fpass[order[i]])
            in_srs[order[i] / s->spp] = 1;
    sample_order(s->ntiles, s->spec->sample_seed ^ 0x5f1257u, perm);
    for (uint32_t i = 0; i < s->ntiles && have + *m < CHIPSAMPLED_FIRST_UNITS; i++) {
        const uint32_t t = perm[i];
        if (fpass[t * s->spp] && !in_srs[t])
            extra[(*m)++] = t * s->spp;
    }
    free(in_srs);
}

void cs_unit_mem(const FuncUnit *u, double *y)
{
    y[CME_REQUESTS] = (double)u->mem_requests;
    y[CME_LATENCY] = (double)u->mem_read_latency;
    y[CME_L2_ACCESSES] = (double)u->l2_accesses;
    y[CME_L2_HITS] = (double)u->l2_hits;
    y[CME_DRAM_BYTES] = (double)u->dram_bytes;
}

/* The memory figures of a chip with shared memory into fr->chip (chipmemest.h): the opening's
 * traffic exact, the rest from phase 1's units (a simple random sample: the tail's are chosen on
 * the estimate and left out) and F's extra units, timed here. 0; -1 when timing those fails (err
 * says). Without a fit (no request below the L1s, too few units) or with a partial record (step 4:
 * lines left unwarmed make DRAM's traffic read high) the figures stay unset and the report has none. */
static int memory_figures(ChipSampler *s, const uint32_t *order, const SampleEstimate *makespan)
{
    StatsChipSample *cs = &s->fr->chip;
    if (!s->shared || cs->record_step > 1)
        return 0;
    const uint32_t cap = s->n + CHIPSAMPLED_FIRST_UNITS;
    double *ys = malloc((size_t)cap * CME_COUNT * sizeof *ys);
    uint8_t *opened = malloc(s->N ? s->N : 1), *fpass = malloc(s->N ? s->N : 1);
    uint32_t *sample = malloc((size_t)cap * sizeof *sample);
    uint32_t *perm = malloc((size_t)(s->ntiles ? s->ntiles : 1) * sizeof *perm);
    FuncUnit *xu = calloc(CHIPSAMPLED_FIRST_UNITS, sizeof *xu);
    int rc = 0;
    if (!ys || !opened || !fpass || !sample || !perm || !xu) {
        snprintf(s->err, s->errlen, "out of memory for the memory figures of %u units", s->N);
        rc = -1;
        goto out;
    }
    for (uint32_t u = 0; u < s->N; u++) {
        opened[u] = s->exact[u] >= 0.0;
        fpass[u] = u % s->spp == 0 && !opened[u];
    }
    for (uint32_t i = 0; i < s->n; i++) {
        sample[i] = order[i];
        cs_unit_mem(&s->units[i], ys + (size_t)i * CME_COUNT);
    }
    uint32_t m;
    first_extra(s, order, fpass, sample + s->n, &m, perm);
    if (m) {
        cs_note(s, "timing %u more of the tiles' first passes alone (the memory figures' stratum of them)", m, 0, 0);
        if ((rc = cs_time_alone(s, sample + s->n, m, xu)) != 0)
            goto out;
        for (uint32_t i = 0; i < m; i++)
            cs_unit_mem(&xu[i], ys + (size_t)(s->n + i) * CME_COUNT);
        cs->first_units = m;
    }
    ChipMemIn in = {.N = s->N, .x = s->x, .k = AUX_K, .first = s->first, .opened = opened, .first_pass = fpass,
                    .sample = sample, .ys = ys, .n = s->n + m, .n_srs = s->n, .nwaves = s->nwave_md,
                    .wave_diff = s->wave_md, .wave_units = s->wave_mn, .makespan = makespan->total,
                    .makespan_se = makespan->std_error, .clock_mhz = s->ucfg.core_clock_mhz,
                    .has_l2 = s->ucfg.l2_size_kb > 0};
    memcpy(in.open, s->open_mem, sizeof in.open);
    ChipMemOut mo;
    if (chip_mem_estimate(&in, &mo) == 0) {
        cs->has_mem = mo.has_mem;
        cs->mem_waves = mo.waves;
        cs->has_l2 = mo.has_l2;
        memcpy(cs->latency, mo.latency, sizeof cs->latency);
        memcpy(cs->l2_hit_rate, mo.l2_hit_rate, sizeof cs->l2_hit_rate);
        memcpy(cs->dram_gbs, mo.dram_gbs, sizeof cs->dram_gbs);
    }
out:
    free(ys);
    free(opened);
    free(fpass);
    free(sample);
    free(perm);
    free(xu);
    return rc;
}

/* ---- the makespan, and its tail ------------------------------------------------------------------ */

/* What the makespan's estimate takes besides the sample: r and its relative variance, carried. */
typedef struct Carry {
    double r, r_rel_var;
} Carry;

/* The makespan from the n units samp[0..n) timed alone (ys), fit by regression: e, out, and the
 * tiles' estimates in fr->tile_cycles. 0, or -1 (err says). */
static int makespan(ChipSampler *s, const uint32_t *samp, const double *ys, uint32_t n, const Carry *c,
                    SampleEstimate *e, ChipSampleOut *out)
{
    if (sample_regression_estimate(ys, s->x, AUX_K, samp, n, s->N, e) != 0) {
        snprintf(s->err, s->errlen, "sampled mode: cannot estimate from %u of %u units (the frame needs at least 2; "
                                    "use --mode detailed)", n, s->N);
        return -1;
    }
    /* r's own t (its jackknife has waves - 1 degrees of freedom) carried into the makespan's
     * interval, which takes the regression's */
    const uint32_t wv = s->fr->chip.waves;
    const double tr = wv >= 2 ? sample_t975(wv - 1) : 0.0, tf = e->n < e->N ? sample_t975(e->df) : 1.959963985;
    ChipSampleIn in = {.ntiles = s->ntiles, .spp = s->spp, .cores = s->K, .x = s->x, .k = AUX_K,
                       .sample = samp, .ys = ys, .n = n, .fit = e, .exact = s->exact, .r = c->r,
                       .r_rel_var = c->r_rel_var * (tr / tf) * (tr / tf), .seed = s->spec->sample_seed};
    if (chip_sample_estimate(&in, s->fr->tile_cycles, out) != 0) {
        snprintf(s->err, s->errlen, "sampled chip: out of memory estimating the makespan of %u tiles", s->ntiles);
        return -1;
    }
    return 0;
}

/* The tail's next units into pick (at most CHIPSAMPLED_TAIL_CORES x CHIPSAMPLED_TAIL_UNITS): on
 * each of the cores that end last in the estimate's schedule (those that may end within 3 standard
 * errors of its makespan), the tile with the most cycles still predicted, up to
 * CHIPSAMPLED_TAIL_UNITS of its units neither timed nor exact (from a seeded pass on). Returns
 * how many (0: none left that could matter). */
static uint32_t tail_pick(ChipSampler *s, const uint8_t *timed, const ChipSampleOut *out, uint32_t *pick)
{
    double *start = malloc((size_t)s->ntiles * sizeof *start), *end = calloc(s->K, sizeof *end);
    uint32_t *core = malloc((size_t)s->ntiles * sizeof *core), n = 0;
    uint8_t *used = calloc(s->K, 1);
    if (start && end && core && used &&
        chip_list_schedule(s->fr->tile_cycles, s->ntiles, s->K, start, core) >= 0.0) {
        for (uint32_t t = 0; t < s->ntiles; t++)
            if (start[t] + s->fr->tile_cycles[t] > end[core[t]])
                end[core[t]] = start[t] + s->fr->tile_cycles[t];
        const double floor = out->makespan - 3.0 * out->std_error;
        for (uint32_t round = 0; round < CHIPSAMPLED_TAIL_CORES; round++) {
            uint32_t k = s->K; /* the latest core not yet looked at */
            for (uint32_t q = 0; q < s->K; q++)
                if (!used[q] && end[q] >= floor && (k == s->K || end[q] > end[k]))
                    k = q;
            if (k == s->K)
                break;
            used[k] = 1;
            uint32_t best = s->ntiles;
            double most = 0.0;
            for (uint32_t t = 0; t < s->ntiles; t++) {
                if (core[t] != k)
                    continue;
                double left = 0.0;
                for (uint32_t u = t * s->spp; u < (t + 1) * s->spp; u++)
                    if (!timed[u] && s->exact[u] < 0.0)
                        left += s->pred[u];
                if (left > most) {
                    most = left;
                    best = t;
                }
            }
            if (best == s->ntiles) { /* this core's tiles are all known: look at the next */
                round--;
                continue;
            }
            uint64_t z = (uint64_t)s->spec->sample_seed * 0x9e3779b97f4a7c15ull + best;
            const uint32_t from = (uint32_t)(sample_splitmix64(&z) % s->spp);
            uint32_t got = 0;
            for (uint32_t i = 0; i < s->spp && got < CHIPSAMPLED_TAIL_UNITS; i++) {
                const uint32_t u = best * s->spp + (from + i) % s->spp;
                if (!timed[u] && s->exact[u] < 0.0) {
                    pick[n++] = u;
                    got++;
                }
            }
        }
    }
    free(start);
    free(end);
    free(core);
    free(used);
    return n;
}

/* The makespan's tail, with --target-error: one round, then more while its interval is wider than
 * the target and not CHIPSAMPLED_TAIL_STILL rounds in a row moved the estimate by at most
 * CHIPSAMPLED_TAIL_MOVE standard errors: the units of the tiles the latest cores end with are
 * timed alone too (they join the sample the estimate fits: chosen on the schedule of the
 * estimate, never on their own cycles), up to twice phase 1's units. The first round is always
 * timed: phase 1's interval rests on the tile effects' spread, which its few same-tile pairs
 * estimate poorly, and the first round's same-tile units are what shows it. samp and ys (N each) hold phase 1's n units; e and out end as the last
 * estimate's. */
static int tail(ChipSampler *s, uint32_t *samp, double *ys, const Carry *c, SampleEstimate *e, ChipSampleOut *out)
{
    uint8_t *timed = calloc(s->N, 1);
    uint32_t pick[CHIPSAMPLED_TAIL_CORES * CHIPSAMPLED_TAIL_UNITS];
    int rc = timed ? makespan(s, samp, ys, s->n, c, e, out) : -1;
    if (!timed)
        snprintf(s->err, s->errlen, "out of memory for %u units", s->N);
    for (uint32_t i = 0; timed && i < s->n; i++)
        timed[samp[i]] = 1;
    const uint32_t budget = s->spec->target_error > 0.0 ? 2 * s->n : 0;
    uint32_t rounds = 0, still = 0; /* rounds timed; the last ones in a row that moved the estimate little */
    while (rc == 0 && s->ntail < budget && out->makespan > 0.0 &&
           (rounds == 0 || (out->hi - out->lo) / 2.0 > s->spec->target_error * out->makespan) &&
           still < CHIPSAMPLED_TAIL_STILL) {
        uint32_t m = tail_pick(s, timed, out, pick);
        if (m > budget - s->ntail)
            m = budget - s->ntail;
        if (!m)
            break;
        cs_note(s, rounds ? "timing the tail: units %u..%u (the makespan's interval +-%u per mille, wider than the target)"
                       : "timing the tail: units %u..%u (its first round; the makespan's interval +-%u per mille)",
             s->ntail + 1, s->ntail + m, (unsigned)(500.0 * (out->hi - out->lo) / out->makespan + 0.5));
        FuncUnit *got = &s->units[s->n + s->ntail];
        if ((rc = cs_time_alone(s, pick, m, got)) != 0)
            break;
        for (uint32_t i = 0; i < m; i++) {
            samp[s->n + s->ntail + i] = pick[i];
            ys[s->n + s->ntail + i] = (double)got[i].cycles;
            timed[pick[i]] = 1;
        }
        s->ntail += m;
        const double before = out->makespan;
        rc = makespan(s, samp, ys, s->n + s->ntail, c, e, out);
        rounds++;
        still = fabs(out->makespan - before) > CHIPSAMPLED_TAIL_MOVE * out->std_error ? 0 : still + 1;
    }
    free(timed);
    return rc;
}

/* Phase 1 (the sample and the regression), phase 2 (r), the tail and the makespan into fr. */
static int estimate(ChipSampler *s)
{
    RunFrame *fr = s->fr;
    uint32_t *order = malloc((size_t)s->N * sizeof *order);
    double *ys = malloc((size_t)s->N * sizeof *ys);
    int rc = -1;
    if (!order || !ys || !(fr->tile_cycles = malloc((s->ntiles ? s->ntiles : 1) * sizeof *fr->tile_cycles))) {
        snprintf(s->err, s->errlen, "out of memory for %u units", s->N);
        goto out;
    }
    sample_order(s->N, s->spec->sample_seed, order);
    const uint32_t n0 = s->spec->target_error > 0.0 ? (s->N < SAMPLED_FIRST_UNITS ? s->N : SAMPLED_FIRST_UNITS)
                                                    : sample_count(s->N, s->spec->sample);
    SampleEstimate e;
    if (sample_sequential(s->x, AUX_K, order, s->N, n0, s->spec->target_error, measure, s, ys, &e, &fr->rounds) != 0 ||
        sample_regression_estimate(s->instructions, s->x, AUX_K, order, s->n, s->N, &fr->est_instructions) != 0) {
        if (!s->err[0])
            snprintf(s->err, s->errlen, "sampled mode: cannot estimate from %u of %u units (the frame needs at "
                                        "least 2; use --mode detailed)", s->n, s->N);
        goto out;
    }
    Carry c;
    if (schedule(s, e.coef) != 0 || chipwaves_run(s, &c.r, &c.r_rel_var) != 0)
        goto out;
    ChipSampleOut out;
    if (tail(s, order, ys, &c, &e, &out) != 0)
        goto out;
    fr->est = e;
    fr->est.total = out.makespan;
    fr->est.lo = out.lo;
    fr->est.hi = out.hi;
    fr->est.std_error = out.std_error;
    fr->est.t = out.t;
    StatsChipSample *cs = &fr->chip;
    cs->r = c.r;
    if (cs->waves < 2)
        cs->r_lo = cs->r_hi = c.r;
    cs->tail_units = s->ntail;
    cs->plain = out.plain;
    cs->var_jack = out.var_jack;
    cs->var_draws = out.var_draws;
    cs->var_r = out.var_r;
    cs->sigma_a = out.sigma_a;
    cs->sigma_e = out.sigma_e;
    if (memory_figures(s, order, &fr->est) != 0)
        goto out;
    fr->has_est = 1;
    rc = 0;
out:
    free(order);
    free(ys);
    return rc;
}

/* The first-reader record's pass step: with --no-image every pass of the frame would cost the
 * golden model's whole image, which the user declined, so CHIPSAMPLED_RECORD_PASSES of each tile's
 * passes, evenly spaced, are recorded (docs/sampling.md, step 4, "The warming's record"). */
static uint32_t record_step(const RunSpec *spec, uint32_t spp)
{
    if (!spec->no_image || spp <= CHIPSAMPLED_RECORD_PASSES)
        return 1;
    return (spp + CHIPSAMPLED_RECORD_PASSES - 1) / CHIPSAMPLED_RECORD_PASSES;
}

int chipsampled_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, const FuncParams *fp,
                      RunFrame *fr, char *err, size_t errlen)
{
    err[0] = '\0';
    ChipSampler s;
    int rc = sampler_open(&s, sc, spec, cfg, fp, fr, err, errlen);
    fr->chip.on = 1;
    fr->chip.cores = (uint32_t)cfg->chip_cores;
    fr->chip.shared = cfg->chip_memory == CFG_CHIP_MEMORY_SHARED;
    if (rc == 0)
        rc = sampled_golden(sc, spec, cfg, fr, s.N, s.x, err, errlen);
    if (rc == 0)
        rc = opening(&s);
    double coef[AUX_K + 1];
    if (rc == 0) {
        first_coef(&s, coef);
        rc = schedule(&s, coef);
    }
    if (rc == 0 && s.warm) { /* the L2's warming: each line's first reader in this schedule */
        warm_thresholds(&s);
        cs_note(&s, "the warming's record: each line's first reader (the golden model, %u units)", s.N, 0, 0);
        s.fr->chip.record_step = record_step(spec, s.spp);
        rc = chipwarm_first_readers(s.warm, s.pos, s.fr->chip.record_step, run_spec_threads(spec), err, errlen);
        if (rc == 0)
            rc = first_lines(&s);
    }
    if (rc == 0)
        rc = estimate(&s);
    fr->units_sampled = s.n + s.ntail;
    return sampler_close(&s, rc);
}
