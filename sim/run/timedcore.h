/* sim/run/timedcore.h -- one core of the configured machine with its program loaded and, when
 * timed, the timing model hooked to it: the one set-up of a simulated core, used by the kernel
 * modes' workers (sim/run/engine.c) and `sfsim exec` (sim/main.c).
 *
 * Owns: turning the config into core and timing parameters and hooking them together.
 * Must not: run the program, or decide what is timed.
 */
#ifndef SFSIM_RUN_TIMEDCORE_H
#define SFSIM_RUN_TIMEDCORE_H

#include <stddef.h>

#include "../../asm/asm.h"
#include "../config.h"
#include "../core.h"
#include "../timing.h"

typedef struct TimedCore {
    Core *core;
    Timing *tm;                /* NULL unless timed */
} TimedCore;

/* obj on a core of cfg's machine, with the timing model when timed. 0; -1 when the core cannot be
 * made (the program does not fit: err says why), -2 when the timing model cannot (its parameters).
 * On failure nothing is left to close. */
int timedcore_open(TimedCore *tc, const CfgMachine *cfg, const AsmObject *obj, int timed, char *err, size_t errlen);
void timedcore_close(TimedCore *tc);

#endif
