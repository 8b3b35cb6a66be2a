/* sim/run/timedcore.c -- a core with its program and, when timed, its timing model (timedcore.h). */
#include "timedcore.h"

#include <string.h>

int timedcore_open(TimedCore *tc, const CfgMachine *cfg, const AsmObject *obj, int timed, char *err, size_t errlen)
{
    memset(tc, 0, sizeof *tc);
    CoreParams cp;
    cfg_core_params(cfg, &cp);
    tc->core = core_new(&cp, obj, err, errlen);
    if (!tc->core)
        return -1;
    if (timed) {
        TimingParams tp;
        timing_params(cfg, &tp);
        tc->tm = timing_new(&tp, err, errlen);
        if (!tc->tm) {
            core_free(tc->core);
            tc->core = NULL;
            return -2;
        }
        timing_attach(tc->tm, tc->core);
    }
    return 0;
}

void timedcore_close(TimedCore *tc)
{
    timing_free(tc->tm);
    core_free(tc->core);
    memset(tc, 0, sizeof *tc);
}
