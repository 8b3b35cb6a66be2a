/* tests/fuzz/fuzz_config.c -- libFuzzer target for the machine-config INI reader (sim/config.c,
 * through sim/ini.c and inih): any bytes must load into a config or produce messages that name
 * the file and line, never a crash, a leak, or a value outside its key's range. A config that
 * passes its checks must also build the timing model (sim/timing.c) and time a short program on
 * it. */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "../../sim/config.h"
#include "../../sim/timing.h"

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
        cfg.stream_mode < 0 || cfg.stream_mode > 1 || cfg.workload_kind < 0 || cfg.workload_kind > CFG_WORKLOAD_PHONG)
        __builtin_trap(); /* a value escaped its range */
    int bad = cfg_check(&cfg, &errs);
    cfg_errors_free(&errs);
    if (n == 0 && bad == 0) {
        /* Feed the timing model a few records by hand (no core: the scene memory of a fuzzed
         * config can be gigabytes): a gather, an ID fetch, a partition, a scene load, a halt. */
        TimingParams tp;
        timing_params(&cfg, &tp);
        char err[256];
        Timing *t = timing_new(&tp, err, sizeof err);
        if (!t)
            __builtin_trap();
        static const uint8_t ops[] = {ISA_OP_SFETCH, ISA_OP_RGAT, ISA_OP_PART, ISA_OP_LDG, ISA_OP_VFADD, ISA_OP_HALT};
        for (size_t i = 0; i < sizeof ops; i++) {
            IsaInstr in = {ops[i], 1, 2, 3, 4, 0, 0};
            CoreRecord rec;
            memset(&rec, 0, sizeof rec);
            rec.in = &in;
            rec.exec = 1;
            rec.count = 64;
            rec.naddr = (uint8_t)(ops[i] == ISA_OP_PART || ops[i] == ISA_OP_VFADD || ops[i] == ISA_OP_HALT ? 0 : 4);
            for (int l = 0; l < rec.naddr; l++)
                rec.addr[l] = 4096u * (uint32_t)l;
            timing_hook(t, &rec);
        }
        timing_end(t);
        if (timing_error(t) || timing_check(timing_stats(t), err, sizeof err))
            __builtin_trap();
        timing_free(t);
    }
    return 0;
}
