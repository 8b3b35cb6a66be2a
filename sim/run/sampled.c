/* sim/run/sampled.c -- sampled mode (docs/sampling.md): the golden model renders the frame and
 * counts every (tile, pass) unit's work, a random sample of the units runs on the timed kernel,
 * and the frame's cycles and instructions are estimated from the sample with 95 % intervals.
 *
 * Owns: the auxiliary variables taken from the golden model's unit counts, the pilot of
 * --no-image, the rounds of the sequential rule and the figures sampled mode reports.
 * Must not: estimate anything itself (sim/sampling.c does), run the kernel (sim/run/engine.c) or
 * write files.
 */
#include "sampled.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../reference.h"
#include "../util.h"
#include "kernel.h"

/* The auxiliary variables of a unit, in their column order: the golden model's estimate of the
 * stream filters' SIMD steps (docs/golden-model.md), which follow the kernel's work closely
 * (docs/sampling.md has the measured correlations). */
#define SAMPLED_AUX(X) X(node_steps) X(leaf_steps) X(ray_steps)
#define AUX_COUNT(name) +1
enum { AUX_K = 0 SAMPLED_AUX(AUX_COUNT) };
_Static_assert(AUX_K == SAMPLED_AUX_K, "sampled.h's SAMPLED_AUX_K counts the columns of SAMPLED_AUX");

/* The sampled units' figures, kept in the order they were drawn. */
typedef struct Measured {
    FuncSession *fs;
    FuncUnit *units;           /* N entries, the first n in use */
    double *instructions;      /* N entries: y for the instruction estimate */
    uint32_t n, N;
    const RunSpec *spec;
    double started;
} Measured;

/* sim/sampling.h's SampleMeasure: the next slice of the order on the timed kernel. */
static int measure(void *ctx, const uint32_t *units, uint32_t count, double *ys)
{
    Measured *m = ctx;
    char err[1024];
    FuncUnit *out = &m->units[m->n];
    if (m->spec->note) {
        char line[200];
        snprintf(line, sizeof line, "timing units %u..%u of %u (%.1fs so far)", m->n + 1, m->n + count, m->N,
                 util_now() - m->started);
        m->spec->note(m->spec->progress_ctx, line);
    }
    if (func_units(m->fs, units, count, out, err, sizeof err) != 0)
        return -1;
    for (uint32_t i = 0; i < count; i++) {
        ys[i] = (double)out[i].cycles;
        m->instructions[m->n + i] = (double)out[i].instructions;
    }
    m->n += count;
    return 0;
}

RefParams sampled_ref_params(const RunSpec *spec, const CfgMachine *cfg, const RunFrame *fr)
{
    assert(run_workload_golden(cfg)); /* the options' check refused the others (sim/cli/runopts.c) */
    return (RefParams){.tile = fr->tile, .seed = spec->seed, .threads = fr->threads, .progress = spec->progress,
                       .progress_ctx = spec->progress_ctx, .bounces = cfg->workload_bounces,
                       .workload = cfg->workload_kind == CFG_WORKLOAD_PHONG ? REF_WORKLOAD_PHONG : REF_WORKLOAD_PATH,
                       .simd_width = cfg->core_simd_width};
}

/* The golden model over the frame (or, with no image, over its pilot passes): the image, the
 * rays, and each unit's counts. */
static int golden_units(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, RunFrame *fr,
                        RefUnitStats *units, RefStats *rs, char *err, size_t errlen)
{
    RefParams rp = sampled_ref_params(spec, cfg, fr);
    rp.units = units;
    rp.pass0 = 0;
    rp.pass1 = spec->no_image ? SAMPLED_PILOT_PASSES : 0;
    if (rp.pass1 >= (uint32_t)sc->s.render.spp)
        rp.pass1 = 0;
    return ref_render(&sc->p, &rp, fr->rgb, rs, err, errlen);
}

void sampled_aux_matrix(const RefUnitStats *units, uint32_t ntiles, uint32_t spp, uint32_t pilot, double *x)
{
    for (uint32_t t = 0; t < ntiles; t++)
        for (uint32_t p = 0; p < spp; p++) {
            double *row = &x[((size_t)t * spp + p) * AUX_K];
            int j = 0;
            if (!pilot || p < pilot) {
                const RefUnitStats *u = &units[(size_t)t * spp + p];
#define AUX_ONE(name) row[j++] = (double)u->name;
                SAMPLED_AUX(AUX_ONE)
#undef AUX_ONE
                continue;
            }
            for (int k = 0; k < AUX_K; k++) {
                double s = 0.0;
                for (uint32_t q = 0; q < pilot; q++)
                    s += x[((size_t)t * spp + q) * AUX_K + k];
                row[k] = s / pilot;
            }
        }
}

/* The run's figures from the golden model: exact with the image; from the pilot, scaled to the
 * frame's passes, without it. */
static void golden_run_figures(const RefStats *rs, uint32_t spp, uint32_t pilot, StatsRun *run)
{
    stats_run_from_ref(run, rs);
    if (!pilot)
        return;
    double scale = (double)spp / pilot;
    uint64_t *c[] = {&run->primary, &run->shadow, &run->indirect, &run->dropped, &run->nodes_visited,
                     &run->prims_tested};
    for (size_t i = 0; i < sizeof c / sizeof c[0]; i++)
        *c[i] = (uint64_t)llround((double)*c[i] * scale);
    for (int g = 0; g < STATS_GENERATIONS; g++)
        run->per_gen[g] = (uint64_t)llround((double)run->per_gen[g] * scale);
}

/* The sample: its first units, then the rounds of the sequential rule. */
static int draw_sample(const RunSpec *spec, const double *x, uint32_t N, Measured *m, double *ys, RunFrame *fr,
                       char *err, size_t errlen)
{
    uint32_t *order = malloc((size_t)N * sizeof *order);
    if (!order) {
        snprintf(err, errlen, "out of memory for %u units", N);
        return -1;
    }
    sample_order(N, spec->sample_seed, order);
    uint32_t n0 = spec->target_error > 0.0 ? (N < SAMPLED_FIRST_UNITS ? N : SAMPLED_FIRST_UNITS)
                                           : sample_count(N, spec->sample);
    m->started = util_now();
    int rc = sample_sequential(x, AUX_K, order, N, n0, spec->target_error, measure, m, ys, &fr->est, &fr->rounds);
    if (rc == 0 && sample_regression_estimate(m->instructions, x, AUX_K, order, m->n, N, &fr->est_instructions) != 0)
        rc = -1;
    if (rc != 0 && !err[0])
        snprintf(err, errlen, "sampled mode: cannot estimate from %u of %u units (the frame needs at least 2; "
                 "use --mode detailed)", m->n, N);
    free(order);
    return rc;
}

/* Each tile's cycles: its measured units', plus the regression's prediction for the others. */
static double *tile_estimates(const SampleEstimate *e, const double *x, const Measured *m, uint32_t ntiles,
                              uint32_t spp)
{
    uint32_t N = ntiles * spp;
    double *tc = calloc(ntiles ? ntiles : 1, sizeof *tc), *y = malloc((N ? N : 1) * sizeof *y);
    uint8_t *measured = calloc(N ? N : 1, 1);
    if (tc && y && measured) {
        for (uint32_t i = 0; i < m->n; i++) {
            measured[m->units[i].unit] = 1;
            y[m->units[i].unit] = (double)m->units[i].cycles;
        }
        for (uint32_t u = 0; u < N; u++) {
            double pred = e->coef[0];
            for (int j = 0; j < AUX_K; j++)
                pred += e->coef[j + 1] * x[(size_t)u * AUX_K + j];
            tc[u / spp] += measured[u] ? y[u] : pred;
        }
    } else {
        free(tc);
        tc = NULL;
    }
    free(y);
    free(measured);
    return tc;
}

int sampled_countable(FuncSession *fs, char *err, size_t errlen)
{
    if (func_units_total(fs) <= UINT32_MAX)
        return 0;
    snprintf(err, errlen, "sampled mode: the frame has %llu (tile, pass) units, more than the %llu it can count; "
             "lower render.spp or the image size", (unsigned long long)func_units_total(fs),
             (unsigned long long)UINT32_MAX);
    FuncStats st;
    char ignored[256];
    func_close(fs, &st, ignored, sizeof ignored);
    func_stats_free(&st);
    return -1;
}

int sampled_golden(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, RunFrame *fr, uint32_t N,
                   double *x, char *err, size_t errlen)
{
    const uint32_t spp = (uint32_t)sc->s.render.spp, ntiles = N / spp;
    const uint32_t pilot = spec->no_image && spp > SAMPLED_PILOT_PASSES ? SAMPLED_PILOT_PASSES : 0;
    RefUnitStats *units = calloc(N ? N : 1, sizeof *units);
    if (!units) {
        snprintf(err, errlen, "out of memory for %u units", N);
        return -1;
    }
    const double t0 = util_now();
    RefStats rs;
    int rc = golden_units(sc, spec, cfg, fr, units, &rs, err, errlen);
    fr->golden_seconds = util_now() - t0;
    if (rc == 0 && rs.tiles != ntiles) {
        snprintf(err, errlen, "sampled mode: the golden model has %llu tiles, the kernel %u",
                 (unsigned long long)rs.tiles, ntiles);
        rc = -1;
    }
    if (rc == 0) {
        if (spec->no_image) /* the pilot's passes are not the frame's image */
            memset(fr->rgb, 0, 3 * sizeof(float) * (size_t)sc->s.render.width * (size_t)sc->s.render.height);
        golden_run_figures(&rs, spp, pilot, &fr->run);
        sampled_aux_matrix(units, ntiles, spp, pilot, x);
    }
    free(units);
    return rc;
}

int sampled_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, const FuncParams *fp,
                  RunFrame *fr, char *err, size_t errlen)
{
    err[0] = '\0';
    uint32_t spp = (uint32_t)sc->s.render.spp;
    FuncSession *fs = NULL;
    if (func_open(&sc->p, fp, &fs, err, errlen) != 0)
        return -1;
    if (sampled_countable(fs, err, errlen) != 0)
        return -1;
    uint32_t N = (uint32_t)func_units_total(fs), ntiles = N / spp;
    double *x = malloc((size_t)N * AUX_K * sizeof *x), *ys = malloc((size_t)N * sizeof *ys);
    Measured m = {.fs = fs, .units = calloc(N, sizeof(FuncUnit)), .instructions = malloc((size_t)N * sizeof(double)),
                  .spec = spec};
    int rc = -1;
    if (!x || !ys || !m.units || !m.instructions) {
        snprintf(err, errlen, "out of memory for %u units", N);
        goto out;
    }
    if (sampled_golden(sc, spec, cfg, fr, N, x, err, errlen) != 0)
        goto out;
    m.N = N;
    rc = draw_sample(spec, x, N, &m, ys, fr, err, errlen);
    if (rc == 0 && !(fr->tile_cycles = tile_estimates(&fr->est, x, &m, ntiles, spp))) {
        snprintf(err, errlen, "out of memory for %u tiles", ntiles);
        rc = -1;
    }
    fr->has_est = rc == 0;
out:;
    char cerr[1024];
    int crc = func_close(fs, &fr->f, cerr, sizeof cerr);
    if (crc != 0) { /* the kernel's or the timing model's failure is the cause */
        snprintf(err, errlen, "%s", cerr);
        rc = crc;
    }
    fr->units_sampled = m.n;
    free(x);
    free(ys);
    free(m.units);
    free(m.instructions);
    return rc;
}

/* The golden model's auxiliaries of every unit into x (pilot 0: every pass). */
static int population_aux(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, uint32_t ntiles,
                          uint32_t pilot, double *x, char *err, size_t errlen)
{
    uint32_t spp = (uint32_t)sc->s.render.spp;
    RunFrame fr = {.threads = run_spec_threads(spec), .tile = (int)lrint(sqrt(cfg->stream_rays))};
    fr.rgb = calloc(3 * (size_t)sc->s.render.width * (size_t)sc->s.render.height, sizeof(float));
    RefUnitStats *units = calloc((size_t)ntiles * spp, sizeof *units);
    RunSpec gs = *spec;
    gs.no_image = pilot > 0;
    RefStats rs;
    int rc = -1;
    if (!fr.rgb || !units)
        snprintf(err, errlen, "out of memory for %u units", ntiles * spp);
    else if ((rc = golden_units(sc, &gs, cfg, &fr, units, &rs, err, errlen)) == 0)
        sampled_aux_matrix(units, ntiles, spp, pilot, x);
    free(fr.rgb);
    free(units);
    return rc;
}

int sampled_population(const RunScene *sc, const RunSpec *spec, SampledPopulation *pop, char *err, size_t errlen)
{
    memset(pop, 0, sizeof *pop);
    CfgMachine defcfg;
    const CfgMachine *cfg = run_spec_machine(spec, &defcfg);
    char kpath[4200];
    FuncParams fp = {.cfg = cfg,
                     .kernel_path = run_spec_kernel(spec, kpath, sizeof kpath), .image = sc->image,
                     .needs = sc->s.needs, .seed = spec->seed, .threads = spec->threads, .timed = 1};
    FuncSession *fs;
    if (func_open(&sc->p, &fp, &fs, err, errlen) != 0)
        return -1;
    if (sampled_countable(fs, err, errlen) != 0)
        return -1;
    pop->N = (uint32_t)func_units_total(fs);
    pop->spp = (uint32_t)sc->s.render.spp;
    pop->ntiles = pop->N / pop->spp;
    size_t N = pop->N;
    pop->cycles = malloc(N * sizeof(double));
    pop->instructions = malloc(N * sizeof(double));
    pop->x = malloc(N * SAMPLED_AUX_K * sizeof(double));
    pop->x_pilot = malloc(N * SAMPLED_AUX_K * sizeof(double));
    uint32_t *all = malloc(N * sizeof *all);
    FuncUnit *out = calloc(N ? N : 1, sizeof *out);
    int rc = -1;
    if (!pop->cycles || !pop->instructions || !pop->x || !pop->x_pilot || !all || !out) {
        snprintf(err, errlen, "out of memory for %zu units", N);
        goto out;
    }
    for (uint32_t u = 0; u < pop->N; u++)
        all[u] = u;
    double t0 = util_now();
    if ((rc = func_units(fs, all, pop->N, out, err, errlen)) != 0)
        goto out;
    pop->kernel_seconds = util_now() - t0;
    for (uint32_t u = 0; u < pop->N; u++) {
        pop->cycles[u] = (double)out[u].cycles;
        pop->instructions[u] = (double)out[u].instructions;
        pop->total_cycles += pop->cycles[u];
        pop->total_instructions += pop->instructions[u];
    }
    /* With one pass per tile the pilot is the whole frame: its auxiliaries are the same. */
    uint32_t pilot = pop->spp > SAMPLED_PILOT_PASSES ? SAMPLED_PILOT_PASSES : 0;
    rc = population_aux(sc, spec, cfg, pop->ntiles, 0, pop->x, err, errlen);
    if (rc == 0 && pilot)
        rc = population_aux(sc, spec, cfg, pop->ntiles, pilot, pop->x_pilot, err, errlen);
    else if (rc == 0)
        memcpy(pop->x_pilot, pop->x, N * SAMPLED_AUX_K * sizeof(double));
out:;
    FuncStats st;
    char cerr[1024];
    int crc = func_close(fs, &st, cerr, sizeof cerr);
    func_stats_free(&st);
    if (crc != 0) {
        snprintf(err, errlen, "%s", cerr);
        rc = crc;
    }
    free(all);
    free(out);
    if (rc != 0)
        sampled_population_free(pop);
    return rc;
}

void sampled_population_free(SampledPopulation *pop)
{
    free(pop->cycles);
    free(pop->instructions);
    free(pop->x);
    free(pop->x_pilot);
    memset(pop, 0, sizeof *pop);
}
