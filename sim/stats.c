/* sim/stats.c -- the statistics registry (sim/stats.def) and the one walk over it; report.json's
 * statistics; every derived figure. report.txt and the exec print-out: sim/stats_text.c; the sweep
 * CSV: sim/stats_csv.c.
 *
 * Owns: how a row's value is found (a field by offset, or a fig_* function below), the JSON
 * path syntax and how the walk builds report.json from it, the table's own rules.
 * Must not: count (the core, the timing model and the renderers do), know a counter by name
 * outside the table and its fig_* function, or write a non-statistics block (render.c does).
 */
#include "stats.h"

#include "chip/chip.h"
#include "energy/energy.h"
#include "stats_walk.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "reference.h"

_Static_assert(CORE_GENERATIONS == STATS_GENERATIONS && FUNC_MAX_GENERATIONS == STATS_GENERATIONS &&
                   REF_MAX_GENERATIONS == STATS_GENERATIONS,
               "one generation dimension for core, kernel, golden model and timing");
_Static_assert(offsetof(FuncStats, rays_indirect) == offsetof(FuncStats, rays_camera) + 8 * FUNC_KD_INDIRECT &&
                   offsetof(FuncStats, rays_shadow) == offsetof(FuncStats, rays_camera) + 8 * FUNC_KD_SHADOW,
               "kd.{kind}.rays reads rays_camera, rays_indirect, rays_shadow as an array in FUNC_KD_* order");
_Static_assert(FUNC_STAGES == 3 && ISA_STAGE_TRAVERSAL == 1 && ISA_STAGE_SHADING == 3,
               "the stream filters are the statistics stages traversal, intersection, shading");

/* ---- dimensions ----------------------------------------------------------------------------- */

const char *const stats_dim_names[STATS_D_COUNT] = {
#define STATS_DIM_NAME(name, key, desc) key,
    STATS_DIMS(STATS_DIM_NAME)
#undef STATS_DIM_NAME
};
const char *const stats_dim_descs[STATS_D_COUNT] = {
#define STATS_DIM_DESC(name, key, desc) desc,
    STATS_DIMS(STATS_DIM_DESC)
#undef STATS_DIM_DESC
};
const char *const stats_unit_names[STATS_U_COUNT] = {
#define STATS_UNIT_NAME(name, text) text,
    STATS_UNITS(STATS_UNIT_NAME)
#undef STATS_UNIT_NAME
};

static const char *const filter_keys[FUNC_STAGES] = {"traversal", "intersection", "shading"};
static const char *const bound_keys[2] = {"lo", "hi"};
int stats_dim_size(StatsDim d)
{
    switch (d) {
    case STATS_D_STAGE: return ISA_STAGE_COUNT;
    case STATS_D_FILTER: return FUNC_STAGES;
    case STATS_D_CAUSE: return TM_CAUSE_COUNT;
    case STATS_D_CATEGORY: return ISA_C_COUNT;
    case STATS_D_GEN: return STATS_GENERATIONS;
    case STATS_D_TILE: return 0;
    case STATS_D_OPCODE: return ISA_OP_COUNT;
    case STATS_D_UNIT: return ISA_U_COUNT;
    case STATS_D_KIND: return FUNC_KD_KINDS;
    case STATS_D_COUNTER: return FUNC_KD_COUNTERS;
    case STATS_D_BOUND: return 2;
    case STATS_D_CORE: return 0;
    case STATS_D_PASS: return 0;
    case STATS_D_PART: return EN_P_COUNT;
    case STATS_D_LEVEL: return EN_L_COUNT;
    case STATS_D_DRAMPART: return EN_D_COUNT;
    case STATS_D_AREA: return EN_A_COUNT;
    case STATS_D_COUNT: break;
    }
    return 0;
}

const char *stats_dim_key(StatsDim d, int i)
{
    switch (d) {
    case STATS_D_STAGE: return isa_stage_keys[i];
    case STATS_D_FILTER: return filter_keys[i];
    case STATS_D_CAUSE: return tm_cause_keys[i];
    case STATS_D_CATEGORY: return isa_category_keys[i];
    case STATS_D_OPCODE: return isa_ops[i].mnemonic;
    case STATS_D_UNIT: return isa_unit_names[i];
    case STATS_D_KIND: return func_kd_kind_keys[i];
    case STATS_D_COUNTER: return func_kd_counter_keys[i];
    case STATS_D_BOUND: return bound_keys[i];
    case STATS_D_PART: return energy_part_keys[i];
    case STATS_D_LEVEL: return energy_level_keys[i];
    case STATS_D_DRAMPART: return energy_dram_keys[i];
    case STATS_D_AREA: return energy_area_keys[i];
    case STATS_D_GEN: case STATS_D_TILE: case STATS_D_PASS: case STATS_D_CORE: case STATS_D_COUNT: break;
    }
    return "";
}

/* Elements of d in this run: generations reached, tiles rendered; the others are static. */
int stats_dim_len(const StatsCtx *c, StatsDim d)
{
    if (d == STATS_D_GEN) {
        uint64_t g = c->run ? c->run->generations : c->f ? c->f->generations : 0;
        return g < STATS_GENERATIONS ? (int)g : STATS_GENERATIONS;
    }
    if (d == STATS_D_TILE)
        return c->f ? (int)c->f->ntiles : 0;
    if (d == STATS_D_CORE)
        return c->f ? (int)c->f->chip_cores : 0;
    if (d == STATS_D_PASS)
        return c->f && c->f->pass_cycles ? (int)c->f->pass_spp : 0;
    return stats_dim_size(d);
}

void stats_run_from_func(StatsRun *run, const FuncStats *f)
{
    memset(run, 0, sizeof *run);
    run->primary = f->rays_camera;
    run->shadow = f->rays_shadow;
    run->indirect = f->rays_indirect;
    run->dropped = f->dropped;
    run->generations = f->generations;
    memcpy(run->per_gen, f->rays_per_generation, sizeof run->per_gen);
}

void stats_run_from_ref(StatsRun *run, const RefStats *r)
{
    memset(run, 0, sizeof *run);
    run->primary = r->rays[REF_RAY_CAMERA];
    run->shadow = r->rays[REF_RAY_SHADOW];
    run->indirect = r->rays[REF_RAY_INDIRECT];
    run->dropped = r->dropped;
    run->generations = r->generations;
    memcpy(run->per_gen, r->rays_per_generation, sizeof run->per_gen);
    run->nodes_visited = r->nodes_visited;
    run->prims_tested = r->prims_tested;
}

/* ---- derived figures ------------------------------------------------------------------------ */

double stats_ratio(uint64_t a, uint64_t b) { return b ? (double)a / (double)b : 0.0; }

uint64_t stats_rays_total(const FuncStats *f) { return f->rays_camera + f->rays_indirect + f->rays_shadow; }

uint64_t stats_ops(const CoreStats *s, int category)
{
    uint64_t n = 0;
    for (int k = 0; k < ISA_STAGE_COUNT; k++)
        n += s->ops[k][category];
    return n;
}

double stats_utilization(const CoreStats *s, int lanes, int stage)
{
    return stats_ratio(s->active_lanes[stage], (uint64_t)lanes * s->vec_instructions[stage]);
}

double stats_utilization_gens(const CoreStats *s, int lanes, int stage, int g0, int g1)
{
    uint64_t act = 0, vec = 0;
    for (int g = g0; g < g1 && g < CORE_GENERATIONS; g++) {
        act += s->gen_active_lanes[g][stage];
        vec += s->gen_vec_instructions[g][stage];
    }
    return stats_ratio(act, (uint64_t)lanes * vec);
}

/* Stall cycles of a stage, all causes. */
static uint64_t stage_stalls(const TimingStats *t, int stage)
{
    uint64_t n = 0;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        n += t->stage_stalls[stage][c];
    return n;
}

double stats_utilization_timed(const FuncStats *f, int lanes, int stage)
{
    /* Lanes doing work over the lane-cycles of the stage's vector issue and stall cycles, of the
     * timed tiles (all in detailed mode, the sample in sampled mode): the paper's utilization
     * with the overheads of address fetch, alignment and partition counted as idle lanes. */
    uint64_t act = 0;
    for (uint32_t i = 0; i < f->ntiles; i++)
        if (f->tiles[i].sampled)
            act += f->tiles[i].active_lanes[stage];
    const TimingStats *t = &f->timing;
    return stats_ratio(act, (uint64_t)lanes * (t->stage_vec_busy[stage] + stage_stalls(t, stage)));
}

double stats_utilization_cycles(const FuncStats *f, int lanes, int stage)
{
    return stats_ratio(f->core.active_lanes[stage], (uint64_t)lanes * f->timing.stage_cycles[stage]);
}

double stats_stream_length(const FuncStats *f, int filter, int g0, int g1)
{
    uint64_t streams = 0, rays = 0;
    for (int g = g0; g < g1 && g < FUNC_MAX_GENERATIONS; g++) {
        streams += f->gen_streams[g][filter];
        rays += f->gen_rays[g][filter];
    }
    return stats_ratio(rays, streams);
}

double stats_stall_share(const TimingStats *t, int cause) { return stats_ratio(t->stalls[cause], t->cycles); }

static void kd_kind(const FuncStats *f, int kind, uint64_t counts[FUNC_KD_COUNTERS], uint64_t *rays)
{
    const uint64_t by_kind[FUNC_KD_KINDS] = {f->rays_camera, f->rays_indirect, f->rays_shadow};
    *rays = 0;
    for (int q = 0; q < FUNC_KD_COUNTERS; q++)
        counts[q] = 0;
    for (int k = 0; k < FUNC_KD_KINDS; k++)
        if (kind == FUNC_KD_KINDS || kind == k) {
            *rays += by_kind[k];
            for (int q = 0; q < FUNC_KD_COUNTERS; q++)
                counts[q] += f->kd_counts[k][q];
        }
}

double stats_kd_per_ray(const FuncStats *f, int kind, int counter)
{
    uint64_t counts[FUNC_KD_COUNTERS], rays;
    kd_kind(f, kind, counts, &rays);
    return stats_ratio(counts[counter], rays);
}

StatsFrame stats_frame(const TimingStats *t, double instructions, double clock_mhz, const SampleEstimate *est)
{
    StatsFrame s;
    double hz = clock_mhz * 1e6;
    s.cycles = est ? est->total : (double)t->cycles;
    s.busy = est ? instructions : (double)t->busy;   /* one issue cycle per instruction */
    s.cycles_lo = est ? est->lo : s.cycles;
    s.cycles_hi = est ? est->hi : s.cycles;
    s.fps = s.cycles > 0 ? hz / s.cycles : 0.0;
    s.fps_no_stall = s.busy > 0 ? hz / s.busy : 0.0;
    s.fps_lo = s.cycles_hi > 0 ? hz / s.cycles_hi : 0.0;
    s.fps_hi = s.cycles_lo > 0 ? hz / s.cycles_lo : 0.0;
    return s;
}

/* ---- the rows' figures (FN in stats.def): fig_<name>(ctx, element, na) ----------------------- */

#define FIG(name) static double fig_##name(const StatsCtx *c, const int *idx, int *na)
#define UNUSED_FIG_ARGS ((void)c, (void)idx, (void)na)

StatsFrame stats_frame_of(const StatsCtx *c)
{
    double instructions = c->est_instructions ? c->est_instructions->total : c->f ? (double)c->f->instructions : 0.0;
    const double mhz = c->cfg ? c->cfg->core_clock_mhz : 0.0;
    StatsFrame s = stats_frame(c->t, instructions, mhz, c->est);
    if (c->f && c->f->chip_cores && !c->est) { /* a chip: the makespan; busy over the K cores */
        const double hz = mhz * 1e6, k = (double)c->f->chip_cores;
        s.cycles = s.cycles_lo = s.cycles_hi = (double)c->f->makespan;
        s.busy = (double)c->t->busy / k;
        s.fps = s.fps_lo = s.fps_hi = s.cycles > 0 ? hz / s.cycles : 0.0;
        s.fps_no_stall = s.busy > 0 ? hz / s.busy : 0.0;
    } else if (c->est && c->cfg && c->cfg->chip_cores > 1) { /* a sampled chip: its busy over the K cores */
        s.busy /= (double)c->cfg->chip_cores;
        s.fps_no_stall = s.busy > 0 ? mhz * 1e6 / s.busy : 0.0;
    }
    return s;
}
/* A ratio, and whether it has a meaning (its denominator is not 0). */
static double defined_if(double v, int ok, int *na)
{
    *na = !ok;
    return v;
}
static int lanes(const StatsCtx *c) { return c->cfg->core_simd_width; }

FIG(frame_cycles) { UNUSED_FIG_ARGS; return stats_frame_of(c).cycles; }
FIG(frame_busy) { UNUSED_FIG_ARGS; return stats_frame_of(c).busy; }
FIG(fps) { UNUSED_FIG_ARGS; return stats_frame_of(c).fps; }
FIG(fps_no_stall) { UNUSED_FIG_ARGS; return stats_frame_of(c).fps_no_stall; }
FIG(clock_mhz) { UNUSED_FIG_ARGS; return c->cfg->core_clock_mhz; }
FIG(cycles_ci95) { UNUSED_FIG_ARGS; return idx[0] ? stats_frame_of(c).cycles_hi : stats_frame_of(c).cycles_lo; }
FIG(fps_ci95) { UNUSED_FIG_ARGS; return idx[0] ? stats_frame_of(c).fps_hi : stats_frame_of(c).fps_lo; }
FIG(sample_units) { UNUSED_FIG_ARGS; return c->est->N; }
FIG(sample_units_sampled) { UNUSED_FIG_ARGS; return c->est->n; }
FIG(sample_rounds) { UNUSED_FIG_ARGS; return c->rounds; }
FIG(sample_t) { UNUSED_FIG_ARGS; return c->est->t; }
FIG(sample_std_error) { UNUSED_FIG_ARGS; return c->est->std_error; }
FIG(sample_r2) { UNUSED_FIG_ARGS; return c->est->r2; }
FIG(sample_instr) { UNUSED_FIG_ARGS; return c->est_instructions ? c->est_instructions->total : 0.0; }
static const StatsChipSample *cs(const StatsCtx *c) { return c->chip_sample; }
FIG(cs_opening_units) { UNUSED_FIG_ARGS; return cs(c)->opening_units; }
FIG(cs_waves) { UNUSED_FIG_ARGS; return cs(c)->waves; }
FIG(cs_wave_units) { UNUSED_FIG_ARGS; return cs(c)->wave_units; }
FIG(cs_alone_units) { UNUSED_FIG_ARGS; return cs(c)->alone_units; }
FIG(cs_r) { UNUSED_FIG_ARGS; return cs(c)->r; }
FIG(cs_r_ci95) { UNUSED_FIG_ARGS; return idx[0] ? cs(c)->r_hi : cs(c)->r_lo; }
FIG(cs_plain) { UNUSED_FIG_ARGS; return cs(c)->plain; }
FIG(cs_var_jack) { UNUSED_FIG_ARGS; return cs(c)->var_jack; }
FIG(cs_var_draws) { UNUSED_FIG_ARGS; return cs(c)->var_draws; }
FIG(cs_var_r) { UNUSED_FIG_ARGS; return cs(c)->var_r; }
FIG(cs_sigma_a) { UNUSED_FIG_ARGS; return cs(c)->sigma_a; }
FIG(cs_sigma_e) { UNUSED_FIG_ARGS; return cs(c)->sigma_e; }
FIG(cs_tail_units) { UNUSED_FIG_ARGS; return cs(c)->tail_units; }
FIG(cs_first_units) { UNUSED_FIG_ARGS; return cs(c)->first_units; }
FIG(cs_mem_waves) { UNUSED_FIG_ARGS; return cs(c)->mem_waves; }
FIG(cs_warm_units) { UNUSED_FIG_ARGS; return cs(c)->warm_units; }
FIG(cs_record_step) { UNUSED_FIG_ARGS; return cs(c)->record_step; }
FIG(cs_warm_seconds) { UNUSED_FIG_ARGS; return cs(c)->warm_seconds; }
FIG(rays_total) { UNUSED_FIG_ARGS; return (double)(c->run->primary + c->run->shadow + c->run->indirect); }
FIG(instructions) { UNUSED_FIG_ARGS; return (double)c->f->instructions; }
FIG(ops) { UNUSED_FIG_ARGS; return (double)stats_ops(&c->f->core, idx[0]); }
FIG(ops_share)
{
    uint64_t all = 0;
    for (int k = 0; k < ISA_C_COUNT; k++)
        all += stats_ops(&c->f->core, k);
    return defined_if(stats_ratio(stats_ops(&c->f->core, idx[0]), all), all > 0, na);
}
FIG(utilization)
{
    return defined_if(stats_utilization(&c->f->core, lanes(c), idx[0]), c->f->core.vec_instructions[idx[0]] > 0, na);
}
FIG(utilization_primary)
{
    UNUSED_FIG_ARGS;
    return stats_utilization_gens(&c->f->core, lanes(c), idx[0], 0, 1);
}
FIG(utilization_secondary)
{
    UNUSED_FIG_ARGS;
    /* Primary rays are generation 0 (camera rays only); the rest are secondary (001 Tables 2, 3). */
    return stats_utilization_gens(&c->f->core, lanes(c), idx[0], 1, stats_dim_len(c, STATS_D_GEN));
}
FIG(utilization_gen)
{
    UNUSED_FIG_ARGS;
    return stats_utilization_gens(&c->f->core, lanes(c), idx[1], idx[0], idx[0] + 1);
}
FIG(streams)
{
    UNUSED_FIG_ARGS;
    const FuncStats *f = c->f;
    return (double)(idx[0] == 0 ? f->trav_streams : idx[0] == 1 ? f->isect_streams : f->shade_streams);
}
FIG(stream_length)
{
    const FuncStats *f = c->f;
    uint64_t streams = idx[0] == 0 ? f->trav_streams : idx[0] == 1 ? f->isect_streams : f->shade_streams;
    uint64_t rays = idx[0] == 0 ? f->trav_rays : idx[0] == 1 ? f->isect_rays : f->shade_rays;
    return defined_if(stats_ratio(rays, streams), streams > 0, na);
}
FIG(stream_length_secondary)
{
    UNUSED_FIG_ARGS;
    return stats_stream_length(c->f, idx[0], 1, stats_dim_len(c, STATS_D_GEN));
}
FIG(stream_length_gen)
{
    UNUSED_FIG_ARGS;
    return stats_stream_length(c->f, idx[1], idx[0], idx[0] + 1);
}
FIG(stalls)
{
    UNUSED_FIG_ARGS;
    /* Sampled mode: the sample's share of the estimated cycles. */
    if (c->est)
        return round(stats_stall_share(c->t, idx[0]) * stats_frame_of(c).cycles);
    return (double)c->t->stalls[idx[0]];
}
FIG(stall_share) { return defined_if(stats_stall_share(c->t, idx[0]), c->t->cycles > 0, na); }
FIG(utilization_timed) { UNUSED_FIG_ARGS; return stats_utilization_timed(c->f, lanes(c), idx[0]); }
FIG(scene_cache) { UNUSED_FIG_ARGS; return c->cfg->scene_cache_kb > 0; }
FIG(hit_rate)
{
    (void)idx;
    return defined_if(stats_ratio(c->t->l1.hits, c->t->l1.accesses), c->t->l1.accesses > 0, na);
}
FIG(kd_per_ray)
{
    uint64_t counts[FUNC_KD_COUNTERS], rays;
    kd_kind(c->f, idx[0], counts, &rays);
    return defined_if(stats_ratio(counts[idx[1]], rays), rays > 0, na);
}
FIG(rays_total_kd) { UNUSED_FIG_ARGS; return (double)stats_rays_total(c->f); }
FIG(kd_total)
{
    UNUSED_FIG_ARGS;
    uint64_t counts[FUNC_KD_COUNTERS], rays;
    kd_kind(c->f, FUNC_KD_KINDS, counts, &rays);
    return (double)counts[idx[0]];
}
FIG(kd_total_per_ray)
{
    uint64_t counts[FUNC_KD_COUNTERS], rays;
    kd_kind(c->f, FUNC_KD_KINDS, counts, &rays);
    return defined_if(stats_ratio(counts[idx[0]], rays), rays > 0, na);
}

/* ---- a chip's figures (docs/chip.md) -------------------------------------------------------- */

static const ChipMemStats *mem_of(const StatsCtx *c) { return c->f->chip_mem; }
/* busy (0), stall (1), idle (2) cycles summed over the cores */
static double chip_sum(const StatsCtx *c, int which)
{
    double s = 0;
    for (uint32_t k = 0; k < c->f->chip_cores; k++)
        s += (double)(which == 0 ? c->f->cores[k].busy : which == 1 ? c->f->cores[k].stall : c->f->cores[k].idle);
    return s;
}
FIG(chip_cores) { UNUSED_FIG_ARGS; return c->f->chip_cores; }
FIG(tile_pass_cycles)
{
    UNUSED_FIG_ARGS; /* (PASS has no elements without the array: stats_dim_len) */
    return (double)c->f->pass_cycles[(uint64_t)idx[0] * c->f->pass_spp + (uint64_t)idx[1]];
}
FIG(chip_busy) { UNUSED_FIG_ARGS; return chip_sum(c, 0); }
FIG(chip_stall) { UNUSED_FIG_ARGS; return chip_sum(c, 1); }
FIG(chip_idle) { UNUSED_FIG_ARGS; return chip_sum(c, 2); }
FIG(chip_imbalance)
{
    (void)idx;
    double most = 0, sum = 0;
    for (uint32_t k = 0; k < c->f->chip_cores; k++) {
        const double a = (double)(c->f->cores[k].busy + c->f->cores[k].stall);
        sum += a;
        if (a > most)
            most = a;
    }
    return defined_if(sum > 0 ? most * c->f->chip_cores / sum : 0.0, sum > 0, na);
}
FIG(chip_unused)
{
    UNUSED_FIG_ARGS;
    double n = 0;
    for (uint32_t k = 0; k < c->f->chip_cores; k++)
        n += c->f->cores[k].tiles == 0;
    return n;
}
/* A sampled chip's memory figure (sim/chipmemest.h) `which` (CHIP_FIG_*); bound -1 the estimate,
 * 0 / 1 its interval's low / high end. */
static double cs_mem(const StatsCtx *c, int which, int bound, int *na)
{
    const StatsChipSample *s = cs(c);
    if (!s)
        return defined_if(0.0, 0, na);
    const double *f = which == CHIP_FIG_LATENCY ? s->latency : which == CHIP_FIG_L2_HIT_RATE ? s->l2_hit_rate : s->dram_gbs;
    return defined_if(f[1 + bound], which == CHIP_FIG_L2_HIT_RATE ? s->has_l2 : s->has_mem, na);
}
static int sampled(const StatsCtx *c) { return (c->mode & STATS_M_SAMP) != 0; }

/* The frame's seconds: the makespan at the cores' clock. */
static double frame_seconds(const StatsCtx *c) { return (double)c->f->makespan / (c->cfg->core_clock_mhz * 1e6); }
/* A chip's memory figure `which` (CHIP_FIG_*) of its counters, or the sampled chip's estimate. */
static double mem_fig(const StatsCtx *c, int which, int *na)
{
    if (sampled(c))
        return cs_mem(c, which, -1, na);
    double f[CHIP_FIG_COUNT];
    chip_mem_figures(mem_of(c), frame_seconds(c), f);
    return defined_if(f[which] >= 0.0 ? f[which] : 0.0, f[which] >= 0.0, na);
}
FIG(mem_read_latency) { (void)idx; return mem_fig(c, CHIP_FIG_LATENCY, na); }
FIG(mem_read_latency_ci95) { return cs_mem(c, CHIP_FIG_LATENCY, idx[0], na); }
FIG(scene_stall_l1)
{
    UNUSED_FIG_ARGS;
    return (double)(c->t->stalls[TM_SCENE_MEMORY] - c->t->scene_from[0] - c->t->scene_from[1]);
}
FIG(l2_present) { UNUSED_FIG_ARGS; return mem_of(c)->has_l2; }
FIG(noc_present) { UNUSED_FIG_ARGS; return mem_of(c)->has_noc; }
FIG(l2_hit_rate) { (void)idx; return mem_fig(c, CHIP_FIG_L2_HIT_RATE, na); }
FIG(l2_mpki)
{
    (void)idx;
    return defined_if(1000.0 * stats_ratio(mem_of(c)->l2.misses, c->f->instructions),
                      mem_of(c)->has_l2 && c->f->instructions > 0, na);
}
FIG(l2_read_latency)
{
    (void)idx;
    const L2Stats *l = &mem_of(c)->l2;
    return defined_if(stats_ratio(l->read_latency, l->reads), l->reads > 0, na);
}
FIG(l2_hit_rate_ci95) { return cs_mem(c, CHIP_FIG_L2_HIT_RATE, idx[0], na); }
FIG(dram_bandwidth) { (void)idx; return mem_fig(c, CHIP_FIG_DRAM_GBS, na); }
FIG(dram_bandwidth_ci95) { return cs_mem(c, CHIP_FIG_DRAM_GBS, idx[0], na); }
FIG(dram_peak) { UNUSED_FIG_ARGS; return mem_of(c)->dram_peak_gbs; }
FIG(dram_utilization)
{
    const double s = frame_seconds(c), peak = mem_of(c)->dram_peak_gbs;
    (void)idx;
    return defined_if(s > 0 && peak > 0 ? (double)mem_of(c)->dram.bytes / s / 1e9 / peak : 0.0, s > 0 && peak > 0, na);
}
FIG(dram_read_latency_ns)
{
    (void)idx;
    const DramChanStats *d = &mem_of(c)->dram;
    return defined_if(stats_ratio(d->read_latency, d->reads) * 1000.0 / mem_of(c)->dram_clock_mhz, d->reads > 0, na);
}
FIG(dram_row_hit_rate)
{
    (void)idx;
    const DramChanStats *d = &mem_of(c)->dram;
    const uint64_t all = d->row_hits + d->row_misses + d->row_conflicts;
    return defined_if(stats_ratio(d->row_hits, all), all > 0, na);
}
FIG(dram_queue_avg)
{
    (void)idx;
    const DramChanStats *d = &mem_of(c)->dram;
    return defined_if(stats_ratio(d->occupancy_sum, d->cycles) / (mem_of(c)->dram_channels ? mem_of(c)->dram_channels : 1),
                      d->cycles > 0, na);
}

/* ---- energy, power and area (sim/energy/energy.h computes them once after the run) ---------- */

/* A view with no energy computed (a report built without report_energy, or a run whose energy is
 * not estimated: a sampled chip with shared memory, docs/energy.md) reads zeros marked as having no
 * meaning (null in report.json, "-" in report.txt). */
static const EnergyReport *en(const StatsCtx *c, int *na)
{
    static const EnergyReport none;
    if (!c->energy)
        *na = 1;
    return c->energy ? c->energy : &none;
}
FIG(energy_total) { UNUSED_FIG_ARGS; return en(c, na)->total_j; }
FIG(energy_events) { UNUSED_FIG_ARGS; return en(c, na)->events_j; }
FIG(energy_leakage) { UNUSED_FIG_ARGS; return en(c, na)->leakage_j; }
FIG(energy_ci95) { UNUSED_FIG_ARGS; return idx[0] ? en(c, na)->total_hi : en(c, na)->total_lo; }
FIG(energy_part_events) { UNUSED_FIG_ARGS; return en(c, na)->events[idx[0]]; }
FIG(energy_part_leakage) { UNUSED_FIG_ARGS; return en(c, na)->leakage[idx[0]]; }
FIG(energy_level) { UNUSED_FIG_ARGS; return en(c, na)->level[idx[0]]; }
FIG(energy_dram) { return defined_if(en(c, na)->dram[idx[0]], c->energy && (en(c, na)->dram_known || idx[0] == EN_D_IO), na); }
FIG(energy_dram_pj_bit) { (void)idx; return defined_if(en(c, na)->dram_pj_per_bit, c->energy && en(c, na)->dram_known, na); }
FIG(power_average) { UNUSED_FIG_ARGS; return en(c, na)->average_w; }
FIG(power_leakage) { UNUSED_FIG_ARGS; return en(c, na)->leakage_w; }
FIG(mrays_per_j) { (void)idx; return defined_if(en(c, na)->mrays_per_j, en(c, na)->total_j > 0, na); }
FIG(fps_per_w) { (void)idx; return defined_if(en(c, na)->fps_per_w, en(c, na)->total_j > 0, na); }
FIG(area) { UNUSED_FIG_ARGS; return en(c, na)->area[idx[0]]; }
FIG(fps_per_mm2) { (void)idx; return defined_if(en(c, na)->fps_per_mm2, en(c, na)->fps_per_mm2 > 0, na); }
FIG(energy_node) { UNUSED_FIG_ARGS; return en(c, na)->node_nm; }

/* ---- the table ------------------------------------------------------------------------------ */

#define RUN(f) STATS_SRC_RUN, offsetof(StatsRun, f), NULL, 0
#define CORE(f) STATS_SRC_CORE, offsetof(CoreStats, f), NULL, 0
#define FUNC(f) STATS_SRC_FUNC, offsetof(FuncStats, f), NULL, 0
#define TIMING(f) STATS_SRC_TIMING, offsetof(TimingStats, f), NULL, 0
#define TILE(f) STATS_SRC_TILE, offsetof(FuncTile, f), NULL, 0
#define TILE32(f) STATS_SRC_TILE, offsetof(FuncTile, f), NULL, 1
#define CHIPCORE(f) STATS_SRC_CHIPCORE, offsetof(FuncCore, f), NULL, 0
#define CHIPMEM(f) STATS_SRC_CHIPMEM, offsetof(ChipMemStats, f), NULL, 0
#define FN(name) STATS_SRC_FN, 0, fig_##name, 0
#define EXTERNAL STATS_SRC_EXTERNAL, 0, NULL, 0
#define D0 0, {0}
#define D1(a) 1, {STATS_D_##a}
#define D2(a, b) 2, {STATS_D_##a, STATS_D_##b}
#define M(x) STATS_M_##x
#define F(x) STATS_F_##x
#define CSV(n, name) n, name
#define NOCSV -1, NULL
#define TXT(style, label) STATS_T_##style, label
#define STAT(path, src, dims, unit, modes, flags, csv, text, desc) \
    {path, src, dims, STATS_U_##unit, modes, flags, csv, text, desc},

const StatsRow stats_rows[] = {
#include "stats.def"
};
const int stats_nrows = (int)(sizeof stats_rows / sizeof stats_rows[0]);
_Static_assert(sizeof stats_rows / sizeof stats_rows[0] <= STATS_MAX_ROWS, "stats.def has more rows than STATS_MAX_ROWS");

#undef STAT
#undef RUN
#undef CORE
#undef FUNC
#undef TIMING
#undef TILE
#undef TILE32
#undef CHIPCORE
#undef CHIPMEM
#undef FN
#undef EXTERNAL
#undef D0
#undef D1
#undef D2
#undef M
#undef F
#undef CSV
#undef NOCSV
#undef TXT

/* ---- reading a row ------------------------------------------------------------------------ */

double stats_row_value(const StatsCtx *c, const StatsRow *r, const int *idx, int *na)
{
    *na = 0;
    const unsigned char *base;
    int d0 = 0;
    switch (r->src) {
    case STATS_SRC_FN: return r->fn(c, idx, na);
    case STATS_SRC_RUN: base = (const unsigned char *)c->run; break;
    case STATS_SRC_CORE: base = (const unsigned char *)&c->f->core; break;
    case STATS_SRC_FUNC: base = (const unsigned char *)c->f; break;
    case STATS_SRC_TIMING: base = (const unsigned char *)c->t; break;
    case STATS_SRC_TILE: base = (const unsigned char *)&c->f->tiles[idx[0]]; d0 = 1; break;
    case STATS_SRC_CHIPCORE: base = (const unsigned char *)&c->f->cores[idx[0]]; d0 = 1; break;
    case STATS_SRC_CHIPMEM: base = (const unsigned char *)c->f->chip_mem; break;
    case STATS_SRC_EXTERNAL: default: return 0.0;
    }
    size_t el = 0;   /* row-major over the dimensions' static sizes: the C array's layout */
    for (int k = d0; k < r->ndims; k++)
        el = el * (size_t)stats_dim_size(r->dims[k]) + (size_t)idx[k];
    if (r->u32) {
        uint32_t v;
        memcpy(&v, base + r->offset + 4 * el, 4);
        return (double)v;
    }
    uint64_t v;
    memcpy(&v, base + r->offset + 8 * el, 8);
    return (double)v;
}

int stats_row_present(const StatsRow *r, unsigned mode)
{
    if (!(r->modes & mode & ~(unsigned)STATS_M_QUALIFIERS))
        return 0;
    return (r->modes & STATS_M_QUALIFIERS & ~mode) == 0; /* each qualifier the row has, the run has */
}

/* Every mode has the key: null where the row is not (cycles in functional mode). */
static int row_nulled(const StatsRow *r, unsigned mode)
{
    return (r->flags & STATS_F_NULLED) && !stats_row_present(r, mode) && (mode & STATS_M_ALL);
}

/* The first element (all 0); 0 when the row has none in this run. */
int stats_idx_first(const StatsCtx *c, const StatsRow *r, int *idx)
{
    for (int k = 0; k < r->ndims; k++) {
        idx[k] = 0;
        if (stats_dim_len(c, r->dims[k]) == 0)
            return 0;
    }
    return 1;
}

/* The next element, row-major; 0 after the last. */
int stats_idx_next(const StatsCtx *c, const StatsRow *r, int *idx)
{
    for (int k = r->ndims - 1; k >= 0; k--) {
        if (++idx[k] < stats_dim_len(c, r->dims[k]))
            return 1;
        idx[k] = 0;
    }
    return 0;
}

/* ---- paths: "a.b", "{dim}" (with text around it), "[dim]" ---------------------------------- */


int stats_name_is(const char *s, size_t n, const char *name) { return strlen(name) == n && !strncmp(s, name, n); }

/* The segments of r's path; -1 when the path does not name r's dimensions in order (a list
 * row's one dimension is the list's contents). */
int stats_path_parse(const StatsRow *r, Seg *seg)
{
    const char *p = r->path;
    int n = 0, nd = 0;
    while (p && *p) {
        if (n == MAX_SEGS)
            return -1;
        Seg *g = &seg[n++];
        memset(g, 0, sizeof *g);
        g->dim = -1;
        if (*p == '[') {
            const char *e = strchr(p, ']');
            if (!e || nd >= r->ndims || !stats_name_is(p + 1, (size_t)(e - p - 1), stats_dim_names[r->dims[nd]]))
                return -1;
            g->array = 1;
            g->dim = nd++;
            p = e + 1;
        } else {
            const char *e = p + strcspn(p, ".[");
            const char *b = memchr(p, '{', (size_t)(e - p));
            g->pre = p;
            g->prelen = (int)(e - p);
            if (b) {
                const char *cb = memchr(b, '}', (size_t)(e - b));
                if (!cb || nd >= r->ndims || !stats_name_is(b + 1, (size_t)(cb - b - 1), stats_dim_names[r->dims[nd]]))
                    return -1;
                g->prelen = (int)(b - p);
                g->post = cb + 1;
                g->postlen = (int)(e - cb - 1);
                g->dim = nd++;
            }
            if (e == p)
                return -1;
            p = e;
        }
        if (*p == '.')
            p++;
    }
    /* a list's dimension is its contents, not a key */
    return n > 0 && nd == r->ndims - ((r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z)) ? 1 : 0) ? n : -1;
}

const char *stats_seg_key(const Seg *g, const StatsRow *r, const int *idx, char *buf, size_t len)
{
    snprintf(buf, len, "%.*s%s%.*s", g->prelen, g->pre, g->dim < 0 ? "" : stats_dim_key(r->dims[g->dim], idx[g->dim]),
             g->postlen, g->post ? g->post : "");
    return buf;
}

/* The row's last key if it is a literal ("accesses_with_bank_conflict" -> "accesses with bank
 * conflict"), else "": report.txt's and the exec print-out's name of a value. */
const char *stats_leaf_name(const StatsRow *r, char *buf, size_t len)
{
    Seg seg[MAX_SEGS];
    int n = r->path ? stats_path_parse(r, seg) : -1;
    buf[0] = '\0';
    if (n > 0 && !seg[n - 1].array && seg[n - 1].dim < 0)
        snprintf(buf, len, "%.*s", seg[n - 1].prelen, seg[n - 1].pre);
    for (char *s = buf; *s; s++)
        if (*s == '_')
            *s = ' ';
    return buf;
}

/* ---- the walk ------------------------------------------------------------------------------- */

/* Every row of c's mode (and the rows that are null in it), in table order. */
void stats_walk(const StatsCtx *c, void (*visit)(void *w, const StatsRow *r), void *w)
{
    for (int i = 0; i < stats_nrows; i++) {
        const StatsRow *r = &stats_rows[i];
        if (r->src != STATS_SRC_EXTERNAL && (stats_row_present(r, c->mode) || row_nulled(r, c->mode)))
            visit(w, r);
    }
}

/* ---- report.json ---------------------------------------------------------------------------- */

/* The number report.json holds (stats.txt prints the same): rounded for F(ROUND); a flag 1 or 0. */
double stats_row_report_value(const StatsCtx *c, const StatsRow *r, const int *idx)
{
    int na;
    double v = stats_row_value(c, r, idx, &na);
    if (r->unit == STATS_U_FLAG)
        return v != 0;
    return r->flags & STATS_F_ROUND ? round(v) : v;
}

typedef struct JsonW {
    const StatsCtx *c;
    cJSON *root;
    const StatsRow *r;
    Seg seg[MAX_SEGS];
    int nseg, idx[STATS_MAX_DIMS], oom;
} JsonW;

static cJSON *json_value(JsonW *w)
{
    const StatsRow *r = w->r;
    if (!stats_row_present(r, w->c->mode))
        return cJSON_CreateNull();
    if (r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z)) {
        cJSON *a = cJSON_CreateArray();
        int idx[STATS_MAX_DIMS] = {0}, na;
        for (int ok = stats_idx_first(w->c, r, idx); ok && a; ok = stats_idx_next(w->c, r, idx)) {
            int nz = stats_row_value(w->c, r, idx, &na) != 0;
            if (nz == !!(r->flags & STATS_F_LIST_NZ) && !cJSON_AddItemToArray(a, cJSON_CreateString(stats_dim_key(r->dims[0], idx[0]))))
                w->oom = 1;
        }
        return a;
    }
    double v = stats_row_report_value(w->c, r, w->idx);
    return r->unit == STATS_U_FLAG ? cJSON_CreateBool(v != 0) : cJSON_CreateNumber(v);
}

/* The container a key holds: an array when the next segment indexes one. */
static cJSON *json_child(JsonW *w, cJSON *node, const char *key, int next)
{
    cJSON *x = cJSON_GetObjectItemCaseSensitive(node, key);
    if (!x) {
        x = w->seg[next].array ? cJSON_CreateArray() : cJSON_CreateObject();
        if (!cJSON_AddItemToObject(node, key, x))
            x = NULL;
    }
    return x;
}

/* Segment s of the row's path under node, for every element of its dimension. */
static void json_at(JsonW *w, cJSON *node, int s)
{
    const Seg *g = &w->seg[s];
    const StatsRow *r = w->r;
    int leaf = s == w->nseg - 1, n = g->dim < 0 ? 1 : stats_dim_len(w->c, r->dims[g->dim]), na;
    cJSON *item = g->array ? node->child : NULL;
    for (int i = 0; i < n && !w->oom; i++) {
        if (g->dim >= 0)
            w->idx[g->dim] = i;
        if (leaf && (r->flags & STATS_F_SPARSE) && stats_row_value(w->c, r, w->idx, &na) == 0)
            continue;
        char key[128];
        cJSON *x;
        if (g->array) {
            /* rows sharing an array (tiles[tile].x, tiles[tile].y) share its items */
            x = leaf ? json_value(w) : item ? item : w->seg[s + 1].array ? cJSON_CreateArray() : cJSON_CreateObject();
            if (x && x != item && !cJSON_AddItemToArray(node, x))
                x = NULL;
            item = x ? x->next : NULL;
        } else if (leaf) {
            x = json_value(w);
            if (x && !cJSON_AddItemToObject(node, stats_seg_key(g, r, w->idx, key, sizeof key), x))
                x = NULL;
        } else {
            x = json_child(w, node, stats_seg_key(g, r, w->idx, key, sizeof key), s + 1);
        }
        if (!x)
            w->oom = 1;
        else if (!leaf)
            json_at(w, x, s + 1);
    }
}

static void json_row(void *wp, const StatsRow *r)
{
    JsonW *w = wp;
    if (!r->path)
        return;
    w->r = r;
    w->nseg = stats_path_parse(r, w->seg);
    if (w->nseg < 0) {   /* a table error the unit test rules out */
        w->oom = 1;
        return;
    }
    memset(w->idx, 0, sizeof w->idx);
    json_at(w, w->root, 0);
}

int stats_json(cJSON *root, const StatsCtx *c)
{
    JsonW w = {.c = c, .root = root};
    stats_walk(c, json_row, &w);
    return w.oom ? -1 : 0;
}

/* ---- the table's own rules (tests/unit/test_stats.c) ----------------------------------------- */

/* Bytes of a field source struct. */
static size_t src_size(StatsSrc s)
{
    return s == STATS_SRC_RUN ? sizeof(StatsRun) : s == STATS_SRC_CORE ? sizeof(CoreStats) : s == STATS_SRC_FUNC ? sizeof(FuncStats)
         : s == STATS_SRC_TIMING ? sizeof(TimingStats) : s == STATS_SRC_TILE ? sizeof(FuncTile)
         : s == STATS_SRC_CHIPCORE ? sizeof(FuncCore) : s == STATS_SRC_CHIPMEM ? sizeof(ChipMemStats) : 0;
}

int stats_row_check(const StatsRow *r, char *err, size_t errlen)
{
    Seg seg[MAX_SEGS];
    const char *what = NULL;
    int list = (r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z)) != 0;
    if (r->path && stats_path_parse(r, seg) < 0)
        what = "its path does not name its dimensions in order";
    else if (!r->path && (r->text == STATS_T_NONE || r->csv))
        what = "a row without a path is a report.txt line and nothing else";
    else if ((r->src == STATS_SRC_FN) != (r->fn != NULL))
        what = "FN rows, and only they, have a function";
    else if (r->src == STATS_SRC_TILE && (r->ndims == 0 || r->dims[0] != STATS_D_TILE))
        what = "a TILE field's first dimension is the tile";
    else if (r->src != STATS_SRC_TILE && r->src != STATS_SRC_FN && r->ndims && r->dims[0] == STATS_D_TILE)
        what = "the tile dimension indexes FuncTile fields (or a figure's function)";
    else if ((r->src == STATS_SRC_CHIPCORE) != (r->ndims && r->dims[0] == STATS_D_CORE) && r->src != STATS_SRC_FN)
        what = "a CHIPCORE field's first dimension is the core, and the core dimension indexes FuncCore fields";
    else if ((r->src == STATS_SRC_CHIPCORE || r->src == STATS_SRC_CHIPMEM) && !(r->modes & STATS_M_CHIP))
        what = "a chip's field is in a chip's run only (M(CHIP))";
    else if (list && (r->ndims != 1 || r->text == STATS_T_MORE))
        what = "a list has one dimension";
    else if ((r->text == STATS_T_MORE && r->ndims) || (r->text == STATS_T_LINE && r->ndims > 1 && !list))
        what = "report.txt lines hold scalars or one dimension (MORE: scalars)";
    else if ((r->text == STATS_T_TABLE && r->ndims != 2) || (r->text == STATS_T_TROW && r->ndims != 1))
        what = "a TABLE row has two dimensions, a TROW one";
    else if (r->text == STATS_T_HEAD && r->ndims)
        what = "the headline is a scalar";
    else if (r->src == STATS_SRC_EXTERNAL && (r->text != STATS_T_NONE || (r->modes & STATS_M_EXEC)))
        what = "an EXTERNAL row is written by its owner only";
    else if ((r->modes & (STATS_M_ALL | STATS_M_EXEC)) == 0)
        what = "the row appears in no mode";
    if (!what && src_size(r->src)) {
        size_t n = r->u32 ? 4 : 8;
        for (int k = r->src == STATS_SRC_TILE || r->src == STATS_SRC_CHIPCORE; k < r->ndims; k++)
            n *= (size_t)stats_dim_size(r->dims[k]);
        if (r->offset + n > src_size(r->src))
            what = "its field and dimensions reach past the end of the struct";
    }
    if (!what && r->csv) {
        for (int k = 0; k < r->ndims && !what; k++) {
            char ph[32];
            snprintf(ph, sizeof ph, "{%s}", stats_dim_names[r->dims[k]]);
            if (!strstr(r->csv, ph) || r->dims[k] == STATS_D_GEN || r->dims[k] == STATS_D_TILE ||
                r->dims[k] == STATS_D_CORE)
                what = "its CSV name does not name each (static) dimension";
        }
    }
    if (what)
        snprintf(err, errlen, "stats.def row %s: %s", r->path ? r->path : r->label, what);
    return what ? -1 : 0;
}
