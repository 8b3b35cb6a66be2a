/* bench/bench_args.h -- the [WIDTH HEIGHT SPP] arguments the speed benchmarks share.
 *
 * Owns: their defaults (128 x 96, 4 spp) and ranges. Must not: measure anything.
 */
#ifndef SFSIM_BENCH_ARGS_H
#define SFSIM_BENCH_ARGS_H

#include <stdio.h>
#include <stdlib.h>

/* 0 with the size in w, h, spp; 2 (the exit status) after printing the usage of `name`. */
static inline int bench_size_args(int argc, char **argv, const char *name, int *w, int *h, int *spp)
{
    *w = 128;
    *h = 96;
    *spp = 4;
    if (argc == 4) {
        *w = atoi(argv[1]);
        *h = atoi(argv[2]);
        *spp = atoi(argv[3]);
    }
    if ((argc != 1 && argc != 4) || *w < 1 || *h < 1 || *spp < 1 || *w > 4096 || *h > 4096 || *spp > 4096) {
        fprintf(stderr, "usage: %s [WIDTH HEIGHT SPP]   (each 1..4096; default 128 96 4)\n", name);
        return 2;
    }
    return 0;
}

#endif
