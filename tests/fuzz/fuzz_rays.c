/* tests/fuzz/fuzz_rays.c -- libFuzzer target for the ray-file parser of `sfsim trace`
 * (sim/raybatch.c): any bytes must give either a batch or one clear message naming the file
 * and line or byte, never a crash, a leak or an unbounded allocation. */
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "../../sim/raybatch.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    RayBatch b;
    char err[512];
    err[0] = 0;
    if (raybatch_parse("fuzz.rays", data, size, &b, err, sizeof err) == 0) {
        for (uint32_t i = 0; i < b.count; i++)
            if (b.rays[i].query > RAY_ANY || !(b.rays[i].tmax > 0.0f))
                __builtin_trap(); /* the parser promised these */
        raybatch_free(&b);
    } else if (strncmp(err, "fuzz.rays", 9) != 0) {
        __builtin_trap(); /* every message names the file */
    }
    return 0;
}
