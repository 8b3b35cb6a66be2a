/* tools/sample41/warmbias.c -- issue 41's step 5 measured (docs/sampling.md, "What remains to
 * build"): how far a unit timed alone on one core of the chip's memory (sim/run/chipunit.h) is
 * from the same unit inside the chip's whole frame, cold and with the levels warmed from the
 * golden model's record of the units before it.
 *
 * Build (not part of make; after `make all`):
 *   gcc -O2 -I. -o build/warmbias tools/sample41/warmbias.c build/libsfsim.a -linih -ltinygltf \
 *       -ltinyobjloader -lcjson -lOpenEXRCore-3_1 -lpng16 -lfreetype -lgsl -lgslcblas -lstdc++ -lpthread -ldl -lm
 * usage: [WB_MODE=old|distinct|fb] warmbias SCENE.ini CONFIG.ini W H SPP [THREADS [WAVES]]
 * WB_MODE picks the L2's warming list: old (the last L2-capacity of lines counted with repeats:
 * the first sampler's), distinct (the latest distinct lines back to an L2's worth or the frame's
 * start), fb (distinct, and past a tile's first pass its framebuffer's lines), chipwarm (the
 * sampler's: sim/run/chipwarm.c's first readers for the L2, the unit before on its core for the
 * L1, with the framebuffer).
 *
 * 1. The chip's frame in detailed mode (stream.rays = 1024: 32 x 32 tiles): every unit's cycles
 *    (tiles[].passes[]) and its core; each unit's start is the sum of the units before it on its
 *    core (a core's units run back to back: busy + stall = finish, tests/unit/test_chip.c).
 * 2. The golden model's lines of every unit (RefParams.unit_line), each unit's distinct lines.
 * 3. Every unit timed alone on one core of the chip's memory (FuncParams.chip_unit): cold, and
 *    warmed with the lines of the units that started before it (those still running at its start
 *    whole: a little of what they read later), in the order they started, the last L2-capacity
 *    worth kept (chip_warm replays them oldest first). The frame's schedule is used, where a
 *    sampler would have only the predicted one.
 * Prints per unit and the mean and spread of (alone / in the frame - 1), cold and warm, over the
 * units after the first wave (the first K units start on a cold chip in the frame too).
 * 4. With WAVES: at WAVES instants evenly spaced over the frame after its first wave, the K units
 *    running then (one a core) timed together as a wave (FuncParams.wave), warmed with the lines
 *    of the units that started before the earliest of them; per wave, the wave's cycles over the
 *    same units' in the frame (the waves' alignment: they start together, the frame's do not) and
 *    over the same units alone and warmed (design C's factor r, against the frame's). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scenes/bvh.h"
#include "scenes/pack.h"
#include "scenes/scene.h"
#include "sim/config.h"
#include "sim/reference.h"
#include "sim/run/chipwarm.h"
#include "sim/run/engine.h"

typedef struct Lines {
    uint64_t *a;
    size_t n, cap;
} Lines;

static Lines *unit_lines;
static uint32_t nunits;

static void push(Lines *l, uint64_t v)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 256;
        l->a = realloc(l->a, l->cap * sizeof *l->a);
        if (!l->a)
            abort();
    }
    l->a[l->n++] = v;
}

/* RefParams.unit_line: each unit's lines (64-byte), repeats dropped later. Each unit's calls come
 * from one thread. */
static void on_line(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes)
{
    (void)ctx;
    if (unit >= nunits)
        abort();
    for (uint64_t l = addr / 64; l <= (addr + bytes - 1) / 64; l++)
        push(&unit_lines[unit], l * 64);
}

/* unit's warming lines, made before the units run */
static Lines *warm;
static const uint64_t *warm_of(void *ctx, uint32_t unit, size_t *n)
{
    (void)ctx;
    *n = warm[unit].n;
    return warm[unit].a;
}

/* WB_MODE=chipwarm: the L1's lists too */
static Lines *warm1;
static const uint64_t *warm1_of(void *ctx, uint32_t unit, size_t *n)
{
    (void)ctx;
    *n = warm1[unit].n;
    return warm1[unit].a;
}

static int u64_order(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

static uint64_t *start;
static int start_order(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    if (start[x] != start[y])
        return start[x] < start[y] ? -1 : 1;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: warmbias SCENE.ini CONFIG.ini W H SPP [THREADS]\n");
        return 2;
    }
    const int W = atoi(argv[3]), H = atoi(argv[4]), S = atoi(argv[5]), threads = argc > 6 ? atoi(argv[6]) : 2;
    static char err[65536];
    Scene scene;
    PackedScene packed;
    if (scene_load(argv[1], &scene, err, sizeof err)) {
        fprintf(stderr, "%s: %s\n", argv[1], err);
        return 1;
    }
    scene.render.width = W;
    scene.render.height = H;
    scene.render.spp = S;
    BvhParams bp;
    bvh_default_params(&bp);
    if (pack_scene(&scene, &bp, 0, &packed, err, sizeof err)) {
        fprintf(stderr, "pack: %s\n", err);
        return 1;
    }
    CfgMachine cfg;
    cfg_defaults(&cfg);
    CfgErrors errs = {0};
    if (cfg_load(&cfg, argv[2], &errs)) {
        fprintf(stderr, "%s: %s\n", argv[2], errs.text ? errs.text : "?");
        return 1;
    }
    cfg_errors_free(&errs);
    cfg.stream_rays = 1024;

    /* 1. the chip's frame */
    FuncParams fp = {.cfg = &cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = threads, .timed = 1};
    FuncStats full;
    if (func_render(&packed, &fp, NULL, &full, err, sizeof err)) {
        fprintf(stderr, "frame: %s\n", err);
        return 1;
    }
    nunits = full.ntiles * (uint32_t)S;
    start = calloc(nunits, sizeof *start);
    uint64_t *core_at = calloc(full.chip_cores, sizeof *core_at);
    for (uint32_t t = 0; t < full.ntiles; t++) /* a core's tiles in frame order, passes in order */
        for (uint32_t p = 0; p < (uint32_t)S; p++) {
            const uint32_t u = t * (uint32_t)S + p, k = full.tiles[t].core;
            start[u] = core_at[k];
            core_at[k] += full.pass_cycles[u];
        }
    fprintf(stderr, "frame: %u units on %u cores, makespan %llu\n", nunits, full.chip_cores,
            (unsigned long long)full.makespan);

    /* 2. the golden model's lines */
    unit_lines = calloc(nunits, sizeof *unit_lines);
    float *rgb = calloc(3 * (size_t)W * H, sizeof *rgb);
    RefParams rp = {.tile = 32, .seed = 1, .threads = threads, .unit_line = on_line};
    if (ref_render(&packed, &rp, rgb, NULL, err, sizeof err)) {
        fprintf(stderr, "golden: %s\n", err);
        return 1;
    }
    for (uint32_t u = 0; u < nunits; u++) { /* each unit's distinct lines (in address order) */
        Lines *l = &unit_lines[u];
        qsort(l->a, l->n, sizeof *l->a, u64_order);
        size_t d = 0;
        for (size_t q = 0; q < l->n; q++)
            if (!d || l->a[q] != l->a[d - 1])
                l->a[d++] = l->a[q];
        l->n = d;
    }
    /* 3. warming lists: the units started before u (those still running when u starts too, whole),
     * in start order; the last `cap` lines kept */
    const size_t cap = (size_t)cfg.l2_size_kb * 1024 / 64;
    const char *mode = getenv("WB_MODE") ? getenv("WB_MODE") : "old"; /* old | distinct | fb */
    uint32_t *order = malloc(nunits * sizeof *order);
    for (uint32_t u = 0; u < nunits; u++)
        order[u] = u;
    qsort(order, nunits, sizeof *order, start_order);
    warm = calloc(nunits, sizeof *warm);
    const size_t hsize = (size_t)1 << 22; /* > 2 cap */
    uint64_t *hash = calloc(hsize, sizeof *hash);
    for (uint32_t i = 0; i < nunits; i++) {
        const uint32_t u = order[i];
        if (!strcmp(mode, "old")) {
            size_t total = 0;
            uint32_t j = i;
            while (j > 0 && total < cap) /* back from the latest start before u's */
                total += unit_lines[order[--j]].n;
            for (; j < i; j++)
                for (size_t q = 0; q < unit_lines[order[j]].n; q++)
                    push(&warm[u], unit_lines[order[j]].a[q]);
            if (warm[u].n > cap) { /* the oldest beyond the capacity out */
                memmove(warm[u].a, warm[u].a + (warm[u].n - cap), cap * sizeof *warm[u].a);
                warm[u].n = cap;
            }
        } else { /* distinct lines from the latest unit back until cap, most recent use kept */
            memset(hash, 0, hsize * sizeof *hash);
            Lines rev = {0};
            for (uint32_t j = i; j > 0 && rev.n < cap; j--) {
                const Lines *l = &unit_lines[order[j - 1]];
                for (size_t q = 0; q < l->n && rev.n < cap; q++) {
                    uint64_t h = (l->a[q] * 0x9E3779B97F4A7C15ull) >> 42;
                    while (hash[h] && hash[h] != l->a[q] + 1)
                        h = (h + 1) & (hsize - 1);
                    if (hash[h])
                        continue;
                    hash[h] = l->a[q] + 1;
                    push(&rev, l->a[q]);
                }
            }
            for (size_t q = rev.n; q > 0; q--) /* oldest first */
                push(&warm[u], rev.a[q - 1]);
            free(rev.a);
            if (!strcmp(mode, "fb") && u % (uint32_t)S) /* the tile's framebuffer, written by its passes before */
                for (uint64_t b = 0; b < 1024 * 12; b += 64)
                    push(&warm[u], ((uint64_t)1 << 32) + b);
        }
    }
    free(hash);
    if (!strcmp(mode, "chipwarm")) { /* sim/run/chipwarm.c's lists, on the frame's own schedule */
        uint32_t *pos = malloc(nunits * sizeof *pos), *prev = malloc(nunits * sizeof *prev),
                 *last = malloc(full.chip_cores * sizeof *last);
        for (uint32_t i = 0; i < nunits; i++)
            pos[order[i]] = i;
        for (uint32_t k = 0; k < full.chip_cores; k++)
            last[k] = UINT32_MAX;
        for (uint32_t t = 0; t < full.ntiles; t++) { /* each unit's predecessor on its core */
            const uint32_t k = full.tiles[t].core;
            for (uint32_t p = 0; p < (uint32_t)S; p++) {
                prev[t * S + p] = p ? t * S + p - 1 : last[k];
            }
            last[k] = t * S + S - 1;
        }
        ChipWarm *cw = chipwarm_new(&packed, &(RefParams){.tile = 32, .seed = 1}, full.ntiles, (uint32_t)S, 64, cap,
                                    (size_t)cfg.scene_cache_kb * 1024 / 64);
        uint64_t **l1 = calloc(nunits, sizeof *l1);
        size_t *n1 = calloc(nunits, sizeof *n1);
        warm1 = calloc(nunits, sizeof *warm1);
        if (!cw || chipwarm_first_readers(cw, pos, 1, threads, err, sizeof err) ||
            chipwarm_l1(cw, prev, nunits, threads, l1, n1, err, sizeof err)) {
            fprintf(stderr, "chipwarm: %s\n", err);
            return 1;
        }
        for (uint32_t u = 0; u < nunits; u++) {
            free(warm[u].a);
            warm[u] = (Lines){0};
            uint64_t *l2;
            size_t n2;
            if (chipwarm_l2(cw, pos[u], &l2, &n2, err, sizeof err)) {
                fprintf(stderr, "chipwarm: %s\n", err);
                return 1;
            }
            warm[u] = (Lines){l2, n2, n2};
            warm1[u] = (Lines){l1[u], n1[u], n1[u]};
        }
        fprintf(stderr, "chipwarm: %u units recorded, %.1f s\n", chipwarm_recorded(cw), chipwarm_seconds(cw));
        chipwarm_free(cw);
        free(l1);
        free(n1);
        free(pos);
        free(prev);
        free(last);
    }
    fprintf(stderr, "warming mode %s\n", mode);

    /* 4. every unit alone, cold and warm */
    uint32_t *all = malloc(nunits * sizeof *all);
    for (uint32_t u = 0; u < nunits; u++)
        all[u] = u;
    FuncUnit *cold = calloc(nunits, sizeof *cold), *hot = calloc(nunits, sizeof *hot);
    for (int pass = 0; pass < 2; pass++) {
        FuncParams up = fp;
        up.chip_unit = 1;
        up.unit_warm = pass ? warm_of : NULL;
        up.unit_warm_l1 = pass && warm1 ? warm1_of : NULL;
        FuncSession *s;
        FuncStats st;
        if (func_open(&packed, &up, &s, err, sizeof err) || func_units(s, all, nunits, pass ? hot : cold, err, sizeof err) ||
            func_close(s, &st, err, sizeof err)) {
            fprintf(stderr, "units: %s\n", err);
            return 1;
        }
        func_stats_free(&st);
    }
    double sc = 0, sc2 = 0, sw = 0, sw2 = 0;
    uint32_t n = 0;
    printf("unit\tcore\tstart\tframe\tcold\twarm\twarm_lines\n");
    for (uint32_t u = 0; u < nunits; u++) {
        printf("%u\t%u\t%llu\t%llu\t%llu\t%llu\t%zu\n", u, full.tiles[u / S].core, (unsigned long long)start[u],
               (unsigned long long)full.pass_cycles[u], (unsigned long long)cold[u].cycles,
               (unsigned long long)hot[u].cycles, warm[u].n);
        if (start[u] == 0) /* the first wave: a cold chip in the frame too */
            continue;
        const double c = (double)cold[u].cycles / (double)full.pass_cycles[u] - 1,
                     w = (double)hot[u].cycles / (double)full.pass_cycles[u] - 1;
        sc += c;
        sc2 += c * c;
        sw += w;
        sw2 += w * w;
        n++;
    }
    const int nw = argc > 7 ? atoi(argv[7]) : 0;
    uint64_t first_end = 0;
    for (uint32_t u = 0; u < nunits; u++)
        if (start[u] == 0 && full.pass_cycles[u] > first_end)
            first_end = full.pass_cycles[u];
    for (int wv = 0; wv < nw; wv++) {
        const uint64_t at = first_end + (full.makespan - first_end) * (uint64_t)(2 * wv + 1) / (uint64_t)(2 * nw);
        uint32_t wave[1024], nwave = 0;
        uint64_t earliest = UINT64_MAX;
        for (uint32_t u = 0; u < nunits && nwave < full.chip_cores; u++)
            if (start[u] <= at && at < start[u] + full.pass_cycles[u]) {
                wave[nwave++] = u;
                if (start[u] < earliest)
                    earliest = start[u];
            }
        Lines wl = {0};
        for (uint32_t i = 0; i < nunits; i++) /* the units started before the earliest, in order */
            if (start[order[i]] < earliest)
                for (size_t q = 0; q < unit_lines[order[i]].n; q++)
                    push(&wl, unit_lines[order[i]].a[q]);
        const size_t keep = wl.n > cap ? cap : wl.n;
        FuncParams wp = fp;
        wp.wave = wave;
        wp.nwave = nwave;
        wp.wave_warm = wl.a ? wl.a + (wl.n - keep) : NULL;
        wp.nwave_warm = keep;
        FuncStats ws;
        if (func_render(&packed, &wp, NULL, &ws, err, sizeof err)) {
            fprintf(stderr, "wave: %s\n", err);
            return 1;
        }
        double wsum = 0, fsum = 0, asum = 0;
        for (uint32_t i = 0; i < nwave; i++) {
            wsum += (double)ws.pass_cycles[wave[i]];
            fsum += (double)full.pass_cycles[wave[i]];
            asum += (double)hot[wave[i]].cycles;
        }
        printf("# wave %d at cycle %llu: %u units; wave / frame - 1 %+.3f %%; r: wave / alone %.4f, frame / alone %.4f\n",
               wv, (unsigned long long)at, nwave, 100 * (wsum / fsum - 1), wsum / asum, fsum / asum);
        func_stats_free(&ws);
        free(wl.a);
    }
    if (n) {
        const double mc = sc / n, mw = sw / n;
        printf("# %u units after the first wave: alone / in the frame - 1: cold mean %+.3f %% (sd %.3f %%), "
               "warm mean %+.3f %% (sd %.3f %%)\n",
               n, 100 * mc, 100 * sqrt(fmax(0, sc2 / n - mc * mc)), 100 * mw, 100 * sqrt(fmax(0, sw2 / n - mw * mw)));
    }
    return 0;
}
