/* sim/run/sampled.h -- sampled mode's frame (docs/sampling.md): the golden model renders the image
 * and counts each (tile, pass) unit's work; a random sample of units is timed on the kernel; the
 * frame's cycles and instructions are estimated with 95 % intervals (sim/sampling.h).
 *
 * Owns: which golden-model counts are the auxiliary variables, the pilot of --no-image, driving
 * the sequential rule. Must not: write files, or estimate, render or time anything itself.
 */
#ifndef SFSIM_RUN_SAMPLED_H
#define SFSIM_RUN_SAMPLED_H

#include <stddef.h>
#include <stdint.h>

#include "../reference.h"
#include "run.h"

/* --no-image: the golden model runs only the first passes of every tile (the pilot), and the
 * units of the other passes take their tile's pilot counts. */
#define SAMPLED_PILOT_PASSES 1u

/* The units a --target-error run times first, before the sequential rule (sim/sampling.h) grows
 * the sample: with fewer, the interval's coverage falls below its nominal 95 % (measured on the
 * conference room at 256 x 256 x 4 spp, 256 units, 400 seeds: 94.0 % from 30 units, 95.2 % from 60;
 * docs/sampling.md). */
#define SAMPLED_FIRST_UNITS 60u

/* The auxiliary variables of a unit: the golden model's node, leaf and ray SIMD steps. */
#define SAMPLED_AUX_K 3

struct RefUnitStats;
/* x[u * SAMPLED_AUX_K + j]: unit u's auxiliary j, from the golden model's unit counts (ntiles x spp,
 * unit u = tile * spp + pass). pilot > 0: only passes < pilot were counted, and a unit of a later
 * pass takes its tile's pilot counts (their mean): the passes of a tile do nearly the same work. */
void sampled_aux_matrix(const struct RefUnitStats *units, uint32_t ntiles, uint32_t spp, uint32_t pilot, double *x);

/* Sampled mode's frame of sc for spec on cfg; fp is the kernel's set-up (timed). Fills fr's
 * image (unless spec->no_image), run figures, estimates and counters. 0, -1 or -2 as run_frame. */
int sampled_frame(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, const FuncParams *fp,
                  RunFrame *fr, char *err, size_t errlen);

/* Sampled mode's and a sampled chip's golden model (sim/run/chipsampled.c): the frame's
 * RefParams for spec on cfg with fr's tile and threads (no units, passes or tiles chosen). */
RefParams sampled_ref_params(const RunSpec *spec, const CfgMachine *cfg, const RunFrame *fr);
/* The golden model over the frame (or the pilot of --no-image) into fr (image, run figures,
 * golden_seconds) and the N units' auxiliaries into x (N x SAMPLED_AUX_K). 0, or -1 with err. */
int sampled_golden(const RunScene *sc, const RunSpec *spec, const CfgMachine *cfg, RunFrame *fr, uint32_t N,
                   double *x, char *err, size_t errlen);
/* Sampled mode numbers a frame's (tile, pass) units in 32 bits: 0, or -1 with fs closed and a
 * message when the frame has more. */
int sampled_countable(struct FuncSession *fs, char *err, size_t errlen);

/* The whole population of a frame's units, for the tests and bench/speed_vs_error: every unit
 * timed on the kernel (its cycles are those of the full detailed run, tests/unit/test_units.c) and
 * its auxiliaries, from the golden model over every pass and from the --no-image pilot. */
typedef struct SampledPopulation {
    uint32_t N, ntiles, spp;
    double *cycles, *instructions;   /* N each, unit u = tile * spp + pass */
    double *x, *x_pilot;             /* N x SAMPLED_AUX_K each */
    double total_cycles, total_instructions;
    double kernel_seconds;           /* host time timing every unit */
} SampledPopulation;

/* sc's units for spec (its machine, kernel, seed and threads). 0, -1 or -2 as run_frame. */
int sampled_population(const RunScene *sc, const RunSpec *spec, SampledPopulation *pop, char *err, size_t errlen);
void sampled_population_free(SampledPopulation *pop);

#endif
