/* sim/run/chipsampled_int.h -- the sampled chip's state, shared by its files (chipsampled.c: the
 * frame, phase 1, the tail and the memory figures; chipwaves.c: phase 2, the waves). Not an
 * interface for anything else: sim/run/chipsampled.h is. */
#ifndef SFSIM_RUN_CHIPSAMPLED_INT_H
#define SFSIM_RUN_CHIPSAMPLED_INT_H

#include <stddef.h>
#include <stdint.h>

#include "../chipmemest.h"
#include "chipsampled.h"
#include "chipwarm.h"
#include "sampled.h"

enum { AUX_K = SAMPLED_AUX_K };

typedef struct ChipSampler {
    const RunScene *sc;
    const RunSpec *spec;
    RunFrame *fr;
    CfgMachine ucfg;           /* the units' machine: cfg, or one core on its bus for a chip of buses */
    FuncParams fp;             /* the chip's frame (the opening, the waves) */
    FuncParams up;             /* the units alone (a session keeps a pointer to it) */
    uint32_t N, ntiles, spp, K;
    int shared;                /* chip.memory = shared: units on the chip's levels, warmed; waves */
    double *x, *exact, *pred, *start; /* N each: auxiliaries (N x AUX_K), exact chip cycles (< 0:
                                         unknown), predicted cycles and start */
    uint32_t *order, *pos;     /* N each: units in predicted start order, each unit's position */
    uint32_t *wthr;            /* N: the units that start before each one in the first schedule (the
                                  L2 warming's position: warm_thresholds) */
    double *first;             /* N: the lines each unit reads first in that schedule (chipwarm.h) */
    double open_mem[CME_COUNT]; /* the opening's memory totals (chipmemest.h) */
    double *tile, *tstart;     /* ntiles each */
    uint32_t *tcore, *tprev;   /* ntiles each: its core, the tile before it there (UINT32_MAX: none) */
    ChipWarm *warm;
    uint64_t **wl, **wl1;      /* N: the L2's and the L1's warming lists of each unit being timed */
    size_t *wlen, *wlen1;
    FuncSession *fs;
    FuncUnit *units;           /* N: phase 1's units in sample order, n of them */
    double *instructions;      /* N: their instructions */
    uint32_t n, ntail;         /* phase 1's units (a simple random sample), the tail's after them */
    /* Phase 2's waves' second units (chipwaves.c): per wave and stratum (0 the rest, 1 the tiles'
     * first passes), their memory figures together less alone, summed, and how many (the memory
     * figures' correction: chipmemest.h's wave_diff and wave_units) */
    double wave_md[CHIPSAMPLED_MAX_WAVES * 2 * CME_COUNT];
    uint32_t wave_mn[CHIPSAMPLED_MAX_WAVES * 2], nwave_md;
    double started;
    char *err;
    size_t errlen;
} ChipSampler;

/* A progress note (RunSpec.note) with up to three numbers, and the seconds so far. */
void cs_note(const ChipSampler *s, const char *fmt, unsigned a, unsigned b, unsigned c);
/* The units alone (units[i] into out[i]), warmed as chipsampled.h says. 0, or -1 (err says). */
int cs_time_alone(ChipSampler *s, const uint32_t *units, uint32_t n, FuncUnit *out);
/* The tiles (frame order) that start before cycle `at` of the current schedule (a prefix). */
uint32_t cs_tiles_before(const ChipSampler *s, double at);
/* The L1 warming lists of units[0..n) (and the L2's, when l2), and their release. */
int cs_warm_lists(ChipSampler *s, const uint32_t *units, uint32_t n, int l2);
void cs_warm_drop(ChipSampler *s, const uint32_t *units, uint32_t n);
/* A unit's memory figures as chipmemest.h counts them (y[CME_COUNT]). */
void cs_unit_mem(const FuncUnit *u, double *y);
/* FuncParams.unit_warm_l1 on the lists made. */
const uint64_t *cs_warm1_of(void *ctx, uint32_t unit, size_t *n);

/* Phase 2 (chipwaves.c): the other cores' factor r over the waves and its relative variance. 0, or
 * -1 (err says). */
int chipwaves_run(ChipSampler *s, double *r, double *rel_var);

#endif
