/* sim/run/spec.c -- the modes and a RunSpec's defaults (spec.h). */
#include "spec.h"

#include <string.h>
#include <unistd.h>

#include "kernel.h"

const char *const run_mode_names[RUN_MODE_COUNT] = {"reference", "functional", "detailed", "sampled"};

int run_mode_parse(const char *name, RunMode *mode)
{
    for (int m = 0; m < RUN_MODE_COUNT; m++)
        if (name && !strcmp(name, run_mode_names[m])) {
            *mode = (RunMode)m;
            return 0;
        }
    return -1;
}

const CfgMachine *run_spec_machine(const RunSpec *spec, CfgMachine *defcfg)
{
    if (spec->cfg)
        return spec->cfg;
    cfg_defaults(defcfg);
    return defcfg;
}

int run_spec_threads(const RunSpec *spec)
{
    return spec->threads > 0 ? spec->threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
}

const char *run_spec_kernel(const RunSpec *spec, char *kpath, size_t len)
{
    return spec->kernel_path ? spec->kernel_path : kernel_default_path(kpath, len);
}
