/* sim/run/chipwarm.c -- a sampled chip's functional warming: the golden model's line record, made
 * on demand, and the warming lists (chipwarm.h). */
#include "chipwarm.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../util.h"

enum { REC_NONE = 0, REC_WANTED = 1, REC_DONE = 2 };

typedef struct Lines {
    uint64_t *a;
    size_t n, cap;
} Lines;

struct ChipWarm {
    const PackedScene *p;
    RefParams rp;
    uint32_t ntiles, spp, line;
    size_t cap;
    Lines *rec;              /* N: each unit's lines */
    uint8_t *state;          /* N: REC_* */
    float *rgb;              /* the golden model's image, thrown away */
    size_t rgb_floats;
    atomic_int oom;          /* a line could not be kept (set from the golden model's threads) */
    uint32_t recorded;
    double seconds;
    double lines_recorded;   /* summed over the recorded units (their mean guides the next record) */
};

ChipWarm *chipwarm_new(const PackedScene *p, const RefParams *rp, uint32_t ntiles, uint32_t spp, uint32_t line_bytes,
                       size_t cap)
{
    ChipWarm *w = calloc(1, sizeof *w);
    const size_t N = (size_t)ntiles * spp;
    if (!w)
        return NULL;
    w->p = p;
    w->rp = *rp;
    w->ntiles = ntiles;
    w->spp = spp;
    w->line = line_bytes ? line_bytes : 64;
    w->cap = cap;
    w->rec = calloc(N ? N : 1, sizeof *w->rec);
    w->state = calloc(N ? N : 1, 1);
    w->rgb_floats = 3 * (size_t)sm_u32(p, sm_hdr(p, SM_HDR_WIDTH)) * sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT));
    w->rgb = calloc(w->rgb_floats ? w->rgb_floats : 1, sizeof *w->rgb);
    atomic_init(&w->oom, 0);
    if (!w->rec || !w->state || !w->rgb) {
        chipwarm_free(w);
        return NULL;
    }
    return w;
}

void chipwarm_free(ChipWarm *w)
{
    if (!w)
        return;
    for (size_t u = 0; w->rec && u < (size_t)w->ntiles * w->spp; u++)
        free(w->rec[u].a);
    free(w->rec);
    free(w->state);
    free(w->rgb);
    free(w);
}

uint32_t chipwarm_recorded(const ChipWarm *w) { return w->recorded; }
double chipwarm_seconds(const ChipWarm *w) { return w->seconds; }

/* RefParams.unit_line: a wanted unit's lines kept (each unit's calls come from one thread). */
static void on_line(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes)
{
    ChipWarm *w = ctx;
    if (unit >= (size_t)w->ntiles * w->spp || w->state[unit] != REC_WANTED || bytes == 0)
        return;
    Lines *l = &w->rec[unit];
    for (uint64_t a = addr / w->line; a <= (addr + bytes - 1) / w->line; a++) {
        if (l->n == l->cap) {
            size_t cap = l->cap ? 2 * l->cap : 512;
            uint64_t *b = realloc(l->a, cap * sizeof *b);
            if (!b) {
                atomic_store(&w->oom, 1);
                return;
            }
            l->a = b;
            l->cap = cap;
        }
        l->a[l->n++] = a * w->line;
    }
}

static int u64_order(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* A recorded unit's lines sorted and each kept once. */
static void distinct(Lines *l)
{
    qsort(l->a, l->n, sizeof *l->a, u64_order);
    size_t d = 0;
    for (size_t q = 0; q < l->n; q++)
        if (!d || l->a[q] != l->a[d - 1])
            l->a[d++] = l->a[q];
    l->n = d;
}

/* The wanted units (state REC_WANTED, listed in want[0..n)) recorded: one golden-model run per
 * pass among them over just their tiles. */
static int record(ChipWarm *w, const uint32_t *want, uint32_t n, int threads, char *err, size_t errlen)
{
    uint32_t *tiles = malloc((n ? n : 1) * sizeof *tiles);
    uint8_t *pass_done = calloc(w->spp, 1);
    int rc = 0;
    if (!tiles || !pass_done) {
        snprintf(err, errlen, "out of memory recording %u units' lines", n);
        rc = -1;
    }
    const double t0 = util_now();
    for (uint32_t i = 0; rc == 0 && i < n; i++) {
        const uint32_t pass = want[i] % w->spp;
        if (pass_done[pass])
            continue;
        pass_done[pass] = 1;
        uint32_t nt = 0;
        for (uint32_t q = i; q < n; q++) /* (want has each unit once, so each tile once a pass) */
            if (want[q] % w->spp == pass)
                tiles[nt++] = want[q] / w->spp;
        RefParams rp = w->rp;
        rp.units = NULL;
        rp.progress = NULL;
        rp.pass0 = pass;
        rp.pass1 = pass + 1;
        rp.tiles_only = tiles;
        rp.ntiles_only = nt;
        rp.unit_line = on_line;
        rp.unit_line_ctx = w;
        rp.threads = threads;
        if (ref_render(w->p, &rp, w->rgb, NULL, err, errlen) != 0)
            rc = -1;
    }
    if (rc == 0 && atomic_load(&w->oom)) {
        snprintf(err, errlen, "out of memory recording %u units' lines", n);
        rc = -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        Lines *l = &w->rec[want[i]];
        if (rc == 0) {
            distinct(l);
            w->state[want[i]] = REC_DONE;
            w->recorded++;
            w->lines_recorded += (double)l->n;
        } else {
            w->state[want[i]] = REC_NONE;
            l->n = 0;
        }
    }
    w->seconds += util_now() - t0;
    free(tiles);
    free(pass_done);
    return rc;
}

/* From position pos of order back: the first position j whose units j .. pos-1 hold cap lines (or
 * 0), when every one of them is recorded; else adds unrecorded units before pos to want (as many as
 * the recorded mean says the rest of cap needs) and returns UINT32_MAX. */
static uint32_t reach(ChipWarm *w, const uint32_t *order, uint32_t pos, uint32_t *want, uint32_t *nwant)
{
    size_t total = 0;
    uint32_t j = pos;
    while (j > 0 && total < w->cap) {
        const uint32_t u = order[j - 1];
        if (w->state[u] == REC_DONE) {
            total += w->rec[u].n;
            j--;
            continue;
        }
        const double mean = w->recorded ? w->lines_recorded / w->recorded : 2048.0;
        double more = (double)(w->cap - total) / (mean > 1.0 ? mean : 1.0) + 1.0;
        for (uint32_t q = j; q > 0 && more > 0.0; q--, more -= 1.0) {
            const uint32_t v = order[q - 1];
            if (w->state[v] == REC_NONE) {
                w->state[v] = REC_WANTED;
                want[(*nwant)++] = v;
            }
        }
        return UINT32_MAX;
    }
    return j;
}

int chipwarm_lists(ChipWarm *w, const uint32_t *order, const uint32_t *pos, uint32_t n, int threads,
                   uint64_t **lists, size_t *lens, char *err, size_t errlen)
{
    const size_t N = (size_t)w->ntiles * w->spp;
    uint32_t *want = malloc((N ? N : 1) * sizeof *want), *from = malloc((n ? n : 1) * sizeof *from);
    int rc = 0;
    if (!want || !from) {
        snprintf(err, errlen, "out of memory for %u warming lists", n);
        rc = -1;
    }
    for (;;) { /* record what the lists reach, until they all reach cap lines or the frame's start */
        if (rc != 0)
            break;
        uint32_t nwant = 0, open = 0;
        for (uint32_t i = 0; i < n; i++)
            if ((from[i] = reach(w, order, pos[i], want, &nwant)) == UINT32_MAX)
                open++;
        if (!open)
            break;
        rc = record(w, want, nwant, threads, err, errlen);
    }
    for (uint32_t i = 0; i < n; i++) {
        lists[i] = NULL;
        lens[i] = 0;
        if (rc != 0)
            continue;
        size_t total = 0;
        for (uint32_t j = from[i]; j < pos[i]; j++)
            total += w->rec[order[j]].n;
        if (!total)
            continue;
        if (!(lists[i] = malloc(total * sizeof **lists))) {
            snprintf(err, errlen, "out of memory for %u warming lists", n);
            rc = -1;
            continue;
        }
        for (uint32_t j = from[i]; j < pos[i]; j++) {
            const Lines *l = &w->rec[order[j]];
            memcpy(lists[i] + lens[i], l->a, l->n * sizeof *l->a);
            lens[i] += l->n;
        }
        if (lens[i] > w->cap) { /* the oldest beyond cap out */
            memmove(lists[i], lists[i] + (lens[i] - w->cap), w->cap * sizeof **lists);
            lens[i] = w->cap;
        }
    }
    if (rc != 0)
        for (uint32_t i = 0; i < n; i++) {
            free(lists[i]);
            lists[i] = NULL;
            lens[i] = 0;
        }
    free(want);
    free(from);
    return rc;
}
