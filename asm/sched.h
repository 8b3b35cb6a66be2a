/* asm/sched.h -- the scheduling pass: list scheduling inside the basic blocks of an assembled
 * program, by critical path, for the latencies and issue intervals of one machine.
 *
 * Owns: the machine model the pass schedules for (AsmSchedModel: the caller fills it; sfsim from
 * its machine config in sim/run/schedmodel.c, sfasm from sched_model_default and its options),
 * the basic blocks of a program, the dependencies between its instructions (taken only from
 * isa/opcodes.def's FMT, ACC, UNIT and FLAGS columns), the new order of each block and the
 * per-block report. Must not: include anything from sim/ or read a machine config; change what a
 * program computes (only the order inside a block changes: the same words, the same number of
 * them, every label at the same index); run after anything that depends on instruction indices
 * other than labels and branch targets (docs/assembler.md, "Instruction scheduling").
 */
#ifndef SFSIM_ASM_SCHED_H
#define SFSIM_ASM_SCHED_H

#include <stdint.h>
#include <stdio.h>

#include "../isa/isa.h"
#include "object.h"

/* What the timing model charges that an order can hide (docs/model.md, "SIMD execution unit"):
 * an in-order, single-issue machine; an instruction waits until its sources, its exec mask and
 * its destinations have their results, and until its class is out of its issue interval. */
typedef struct AsmSchedModel {
    int lat[ISA_U_COUNT];   /* cycles from issue until the result can be used; for the memory
                               classes a load's latency without conflicts: RBUF the ray buffers'
                               access plus the interconnect, SPAD the scratchpad's, SCENE and FB
                               a scene-cache hit */
    int issue[ISA_U_COUNT]; /* cycles between two issues of the class (1: pipelined) */
    int idm_load;           /* a scalar ID-stream read (sld): the ray buffers' access */
    int lanes;              /* N; 0 when unknown (a vector access is then taken to span 64 lanes) */
} AsmSchedModel;

/* The machine of configs/streamray.ini (the config's defaults; a test checks the two agree). */
void sched_model_default(AsmSchedModel *m);
/* A unit class by its lower-case name ("vfma"), or -1. */
int sched_unit_from_name(const char *name);

/* Marks the assembler adds to the blocks it finds in the text itself (labels, branches). */
enum {
    SCHED_MARK_LEADER = 1, /* a block starts at this instruction (.barrier) */
    SCHED_MARK_FIXED = 2   /* the instruction stays where it is, a block of its own (.sched off) */
};

/* Totals of one pass (the estimates are one pass through every block, not a run). */
typedef struct SchedStats {
    uint32_t blocks;        /* scheduling regions (basic blocks, cut at SCHED_WINDOW) */
    uint32_t reordered;     /* regions whose order changed */
    uint64_t moved;         /* instructions not at their old index */
    uint64_t before, after; /* estimated cycles, sum over the regions */
} SchedStats;

/* The longest region the pass schedules at once: longer blocks are cut (the cost of the
 * dependency matrix grows with its square). */
#define SCHED_WINDOW 1024

/* Schedules obj's text in place (obj->lines follows it). marks: obj->ntext bytes of SCHED_MARK_*
 * or NULL. With report, one line per region of two or more instructions and a total. Returns 0, or
 * -1 when out of memory (the text is then as it was). */
int sched_object(AsmObject *obj, const uint8_t *marks, const AsmSchedModel *m, FILE *report, SchedStats *st);

#endif
