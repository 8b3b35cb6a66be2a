/* sim/machine/lines.h -- the distinct lines of one access, for the units whose cost counts lines
 * (ray-buffer banks, scratchpad ports, scene-memory ports).
 *
 * Owns: two small pure helpers. Must not: know any unit's parameters or state, or any cost:
 * each unit file says what its lines cost (docs/model.md).
 */
#ifndef SFSIM_MACHINE_LINES_H
#define SFSIM_MACHINE_LINES_H

#include <stdint.h>

/* Distinct values among v[0..n) (small n: the lanes of one access), in first-seen order, written
 * to out; returns how many. */
static inline int lines_distinct(const uint64_t *v, int n, uint64_t *out)
{
    int k = 0;
    for (int i = 0; i < n; i++) {
        if (k && out[k - 1] == v[i])
            continue;
        int seen = 0;
        for (int j = 0; j < k; j++)
            if (out[j] == v[i]) {
                seen = 1;
                break;
            }
        if (!seen)
            out[k++] = v[i];
    }
    return k;
}

/* The smallest s with 2^s >= v: the shift from a byte address to its line (v a power of two). */
static inline int lines_log2(int v)
{
    int s = 0;
    while ((1 << s) < v)
        s++;
    return s;
}

#endif
