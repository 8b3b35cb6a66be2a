/* sim/run/chipunit.c -- one unit on one core of a chip's shared memory (chipunit.h). */
#include "chipunit.h"

#include <stdio.h>
#include <string.h>

#include "../../isa/isa.h"

int chipunit_open(ChipUnit *u, const CfgMachine *cfg, Timing *t, char *err, size_t errlen)
{
    memset(u, 0, sizeof *u);
    if (!(u->chip = chip_new(cfg, cfg->chip_cores, NULL, err, errlen)))
        return -1;
    if (chip_attach(u->chip, 0, t)) {
        chip_free(u->chip);
        u->chip = NULL;
        snprintf(err, errlen, "out of memory for the chip");
        return -1;
    }
    u->t = t;
    return 0;
}

void chipunit_close(ChipUnit *u)
{
    chip_free(u->chip);
    memset(u, 0, sizeof *u);
}

void chipunit_reset(ChipUnit *u) { chip_reset(u->chip); }

void chipunit_warm(ChipUnit *u, const uint64_t *lines, size_t n) { chip_warm(u->chip, lines, n); }

/* The shared memory steps until the record the core yielded at has its answers. 0, or -1 with
 * err. */
static int wait_answers(ChipUnit *u, const CoreRecord *rec, char *err, size_t errlen)
{
    static const int core0 = 0;
    chip_collect(u->chip, &core0, 1);
    while (timing_blocked(u->t, rec)) {
        const uint64_t e = chip_next(u->chip);
        if (e == UINT64_MAX) {
            snprintf(err, errlen, "chip unit: internal error: the core waits for memory that has nothing in flight");
            return -1;
        }
        /* One core, and it waits: the memory may do any cycle up to the answer's (docs/chip.md). */
        chip_step(u->chip, e, NULL, NULL);
        if (chip_error(u->chip)) {
            snprintf(err, errlen, "%s", chip_error(u->chip));
            return -1;
        }
    }
    return 0;
}

int chipunit_run(ChipUnit *u, Core *c, uint64_t limit, CoreExit *ex, char *err, size_t errlen)
{
    uint64_t done = 0;
    for (;;) {
        if (limit && done >= limit) { /* a yield at the limit's last instruction: the next would trap */
            *ex = CORE_EXIT_LIMIT;
            break;
        }
        const uint64_t left = limit ? limit - done : 0;
        *ex = core_run_slice(c, left, limit);
        done += core_slice_executed(c, left);
        if (*ex != CORE_EXIT_YIELD)
            break;
        const CoreRecord *rec = core_record(c);
        if (wait_answers(u, rec, err, errlen))
            return -1;
        timing_resume(u->t, rec);
        if (timing_yielded(u->t)) {
            snprintf(err, errlen, "chip unit: internal error: the core went on before its answers were in");
            return -1;
        }
        if (isa_ops[rec->in->op].flags & ISA_FL_END) {
            *ex = CORE_EXIT_HALT;
            break;
        }
    }
    return 0;
}
