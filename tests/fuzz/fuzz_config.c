/* tests/fuzz/fuzz_config.c -- libFuzzer target for the machine-config INI reader (sim/config.c,
 * through inih): any bytes must load into a config or produce messages that name the file and
 * line, never a crash, a leak, or a value outside its key's range. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "../../sim/config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    FILE *f = fmemopen((void *)data, size ? size : 1, "r");
    if (!f)
        return 0;
    if (!size) {
        fclose(f);
        return 0;
    }
    CfgMachine cfg;
    cfg_defaults(&cfg);
    CfgErrors errs = {0};
    int n = cfg_load_stream(&cfg, f, "fuzz.ini", &errs);
    fclose(f);
    if (n && (!errs.text || strncmp(errs.text, "fuzz.ini", 8) != 0))
        __builtin_trap(); /* every message names the file */
    if (cfg.core_simd_width < 1 || cfg.core_simd_width > 64 || (cfg.stream_rays != 1024 && cfg.stream_rays != 4096) ||
        cfg.stream_mode < 0 || cfg.stream_mode > 1 || cfg.workload_kind < 0 || cfg.workload_kind > 2)
        __builtin_trap(); /* a value escaped its range */
    cfg_check(&cfg, &errs);
    cfg_errors_free(&errs);
    return 0;
}
