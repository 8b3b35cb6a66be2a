/* sim/run/chipwarm.c -- a sampled chip's functional warming: the golden model's first-reader table
 * for the L2, its record of the units before a timed one on its core for the L1 (chipwarm.h). */
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

/* A host thread's lines of its current unit, each once (the first-reader pass tells the table a
 * line once a unit): an open-addressed set whose slots are current when their gen is. */
typedef struct Seen {
    uint32_t *key, *gen;
    size_t mask;               /* slots - 1 (a power of two) */
    uint32_t g, n, unit;
} Seen;

struct ChipWarm {
    const PackedScene *p;
    RefParams rp;
    uint32_t ntiles, spp, line;
    size_t l2cap, l1cap;
    /* the first-reader table, over the scene memory's lines [lo, lo + nlines) */
    uint64_t lo;
    uint32_t nlines;
    _Atomic uint32_t *first;   /* nlines: the earliest position that read the line (UINT32_MAX: none) */
    _Atomic uint32_t *reads;   /* nlines: units that read it */
    uint32_t *hot;             /* the lines read, least read first (ties: the earlier first) */
    uint32_t nhot;
    const uint32_t *pos;       /* during the pass: each unit's position */
    uint64_t call;             /* the pass's number among all (Seen slots are the pass's own) */
    Seen *seen;
    atomic_int nseen;
    int maxseen;
    /* the L1's record */
    Lines *rec;                /* N: each recorded unit's last l1cap distinct lines, oldest use first */
    uint8_t *state;            /* N: REC_* */
    float *rgb;                /* the golden model's image, thrown away */
    atomic_int oom;            /* a line could not be kept (set from the golden model's threads) */
    uint32_t recorded;
    double seconds;
};

ChipWarm *chipwarm_new(const PackedScene *p, const RefParams *rp, uint32_t ntiles, uint32_t spp, uint32_t line_bytes,
                       size_t l2_lines, size_t l1_lines)
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
    w->l2cap = l2_lines;
    w->l1cap = l1_lines;
    w->lo = p->base / w->line;
    w->nlines = (uint32_t)(((uint64_t)p->base + p->size + w->line - 1) / w->line - w->lo);
    w->rec = calloc(N ? N : 1, sizeof *w->rec);
    w->state = calloc(N ? N : 1, 1);
    w->rgb = calloc(3 * (size_t)sm_u32(p, sm_hdr(p, SM_HDR_WIDTH)) * sm_u32(p, sm_hdr(p, SM_HDR_HEIGHT)) + 1,
                    sizeof *w->rgb);
    atomic_init(&w->oom, 0);
    atomic_init(&w->nseen, 0);
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
    for (int i = 0; w->seen && i < w->maxseen; i++) {
        free(w->seen[i].key);
        free(w->seen[i].gen);
    }
    free(w->seen);
    free(w->rec);
    free(w->state);
    free(w->rgb);
    free(w->first);
    free(w->reads);
    free(w->hot);
    free(w);
}

uint32_t chipwarm_recorded(const ChipWarm *w) { return w->recorded; }
double chipwarm_seconds(const ChipWarm *w) { return w->seconds; }

/* ---- the first-reader table -------------------------------------------------------------------- */

static _Atomic uint64_t passes_run; /* every ChipWarm's passes, numbered (a thread's slot is its pass's) */
static _Thread_local struct {
    uint64_t call;
    Seen *s;
} tl;

static inline size_t slot_of(uint32_t key, size_t mask) { return (size_t)((key * 0x9E3779B1u) >> 7) & mask; }

/* s twice as large, its current keys kept. 0, or -1 out of memory. */
static int seen_grow(Seen *s)
{
    const size_t slots = s->key ? 2 * (s->mask + 1) : (size_t)1 << 16;
    uint32_t *key = malloc(slots * sizeof *key), *gen = calloc(slots, sizeof *gen);
    if (!key || !gen) {
        free(key);
        free(gen);
        return -1;
    }
    for (size_t i = 0; s->key && i <= s->mask; i++)
        if (s->gen[i] == s->g) {
            size_t h = slot_of(s->key[i], slots - 1);
            while (gen[h] == 1)
                h = (h + 1) & (slots - 1);
            key[h] = s->key[i];
            gen[h] = 1;
        }
    free(s->key);
    free(s->gen);
    s->key = key;
    s->gen = gen;
    s->mask = slots - 1;
    s->g = 1;
    return 0;
}

/* RefParams.unit_line in the first-reader pass: each line the first time its unit reads it. */
static void on_first(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes)
{
    ChipWarm *w = ctx;
    if (unit >= (size_t)w->ntiles * w->spp || bytes == 0 || atomic_load_explicit(&w->oom, memory_order_relaxed))
        return;
    if (tl.call != w->call) { /* this thread's first line of the pass: a slot of its own */
        const int i = atomic_fetch_add(&w->nseen, 1);
        if (i >= w->maxseen) {
            atomic_store(&w->oom, 1);
            return;
        }
        tl.call = w->call;
        tl.s = &w->seen[i];
        tl.s->unit = UINT32_MAX;
    }
    Seen *s = tl.s;
    if (s->unit != unit) { /* a new unit: the set emptied */
        s->unit = unit;
        s->n = 0;
        if (!s->key || ++s->g == 0) {
            if (s->key)
                memset(s->gen, 0, (s->mask + 1) * sizeof *s->gen);
            if (!s->key && seen_grow(s) != 0) {
                atomic_store(&w->oom, 1);
                return;
            }
            s->g = 1;
        }
    }
    const uint32_t at = w->pos[unit];
    for (uint64_t l = addr / w->line; l <= (addr + bytes - 1) / w->line; l++) {
        if (l < w->lo || l - w->lo >= w->nlines)
            continue;
        const uint32_t k = (uint32_t)(l - w->lo);
        size_t h = slot_of(k, s->mask);
        while (s->gen[h] == s->g && s->key[h] != k)
            h = (h + 1) & s->mask;
        if (s->gen[h] == s->g)
            continue; /* read before in this unit */
        s->gen[h] = s->g;
        s->key[h] = k;
        atomic_fetch_add_explicit(&w->reads[k], 1, memory_order_relaxed);
        uint32_t f = atomic_load_explicit(&w->first[k], memory_order_relaxed);
        while (at < f && !atomic_compare_exchange_weak_explicit(&w->first[k], &f, at, memory_order_relaxed,
                                                                 memory_order_relaxed))
            ;
        if (2 * (size_t)++s->n > s->mask && seen_grow(s) != 0) {
            atomic_store(&w->oom, 1);
            return;
        }
    }
}

typedef struct HotKey {
    uint32_t reads, first, line;
} HotKey;

static int hot_order(const void *a, const void *b)
{
    const HotKey *x = a, *y = b;
    if (x->reads != y->reads)
        return x->reads < y->reads ? -1 : 1;
    if (x->first != y->first)
        return x->first < y->first ? -1 : 1;
    return (x->line > y->line) - (x->line < y->line);
}

int chipwarm_first_readers(ChipWarm *w, const uint32_t *pos, uint32_t pass_step, int threads, char *err,
                           size_t errlen)
{
    const double t0 = util_now();
    w->maxseen = (threads < 1 ? 1 : threads) + 1; /* (the calling thread may render too) */
    w->first = malloc((size_t)w->nlines * sizeof *w->first);
    w->reads = calloc(w->nlines ? w->nlines : 1, sizeof *w->reads);
    w->seen = calloc((size_t)w->maxseen, sizeof *w->seen);
    if (!w->first || !w->reads || !w->seen) {
        snprintf(err, errlen, "out of memory for the warming's table of %u lines", w->nlines);
        return -1;
    }
    for (uint32_t i = 0; i < w->nlines; i++)
        atomic_init(&w->first[i], UINT32_MAX);
    w->pos = pos;
    w->call = atomic_fetch_add(&passes_run, 1) + 1;
    RefParams rp = w->rp;
    rp.units = NULL;
    rp.progress = NULL;
    rp.pass0 = 0;
    rp.pass1 = 0;
    rp.pass_step = pass_step;
    rp.tiles_only = NULL;
    rp.ntiles_only = 0;
    rp.unit_line = on_first;
    rp.unit_line_ctx = w;
    rp.threads = threads;
    int rc = ref_render(w->p, &rp, w->rgb, NULL, err, errlen);
    w->pos = NULL;
    if (rc == 0 && atomic_load(&w->oom)) {
        snprintf(err, errlen, "out of memory for the warming's table");
        rc = -1;
    }
    for (uint32_t i = 0; rc == 0 && i < w->nlines; i++)
        w->nhot += atomic_load(&w->reads[i]) > 0;
    if (rc == 0 && !(w->hot = malloc((w->nhot ? w->nhot : 1) * sizeof *w->hot))) {
        snprintf(err, errlen, "out of memory for the warming's %u lines", w->nhot);
        rc = -1;
    }
    HotKey *keys = rc == 0 ? malloc((w->nhot ? w->nhot : 1) * sizeof *keys) : NULL;
    if (rc == 0 && !keys) {
        snprintf(err, errlen, "out of memory for the warming's %u lines", w->nhot);
        rc = -1;
    }
    if (rc == 0) {
        uint32_t n = 0;
        for (uint32_t i = 0; i < w->nlines; i++)
            if (atomic_load(&w->reads[i]) > 0)
                keys[n++] = (HotKey){atomic_load(&w->reads[i]), atomic_load(&w->first[i]), i};
        qsort(keys, w->nhot, sizeof *keys, hot_order);
        for (uint32_t i = 0; i < w->nhot; i++)
            w->hot[i] = keys[i].line;
    }
    free(keys);
    w->seconds += util_now() - t0;
    return rc;
}

void chipwarm_first_counts(const ChipWarm *w, uint32_t npos, double *counts)
{
    memset(counts, 0, (size_t)npos * sizeof *counts);
    for (uint32_t i = 0; i < w->nhot; i++) {
        const uint32_t f = atomic_load_explicit(&w->first[w->hot[i]], memory_order_relaxed);
        if (f < npos)
            counts[f] += 1.0;
    }
}

int chipwarm_l2(const ChipWarm *w, uint32_t pos, uint64_t **list, size_t *len, char *err, size_t errlen)
{
    *list = NULL;
    *len = 0;
    size_t n = 0;
    for (uint32_t i = 0; i < w->nhot; i++)
        n += atomic_load_explicit(&w->first[w->hot[i]], memory_order_relaxed) < pos;
    const size_t skip = n > w->l2cap ? n - w->l2cap : 0; /* the least read beyond the L2's lines */
    if (n - skip == 0)
        return 0;
    if (!(*list = malloc((n - skip) * sizeof **list))) {
        snprintf(err, errlen, "out of memory for a warming list of %zu lines", n - skip);
        return -1;
    }
    size_t seen = 0;
    for (uint32_t i = 0; i < w->nhot; i++)
        if (atomic_load_explicit(&w->first[w->hot[i]], memory_order_relaxed) < pos && seen++ >= skip)
            (*list)[(*len)++] = (w->lo + w->hot[i]) * w->line;
    return 0;
}

/* ---- the L1's record --------------------------------------------------------------------------- */

/* RefParams.unit_line: a wanted unit's lines kept in the order read (each unit's calls come from
 * one thread; a line read again at once is kept once). */
static void on_line(void *ctx, uint32_t unit, uint64_t addr, uint64_t bytes)
{
    ChipWarm *w = ctx;
    if (unit >= (size_t)w->ntiles * w->spp || w->state[unit] != REC_WANTED || bytes == 0)
        return;
    Lines *l = &w->rec[unit];
    for (uint64_t a = addr / w->line; a <= (addr + bytes - 1) / w->line; a++) {
        if (l->n && l->a[l->n - 1] == a * w->line)
            continue;
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

/* A recorded unit's lines each kept once, at its last read, the last cap of them. 0, or -1 out of
 * memory. */
static int last_uses(Lines *l, size_t cap)
{
    size_t slots = 64;
    while (slots < 2 * l->n)
        slots *= 2;
    uint64_t *set = calloc(slots, sizeof *set);
    if (!set)
        return -1;
    size_t d = 0;
    for (size_t q = l->n; q > 0 && d < cap; q--) { /* from the last read back; kept at the end */
        const uint64_t a = l->a[q - 1];
        size_t h = (size_t)((a * 0x9E3779B97F4A7C15ull) >> 20) & (slots - 1);
        while (set[h] && set[h] != a + 1)
            h = (h + 1) & (slots - 1);
        if (set[h])
            continue;
        set[h] = a + 1;
        l->a[l->n - 1 - d++] = a; /* (position n-1-d is at or after q-1: nothing unread is lost) */
    }
    free(set);
    memmove(l->a, l->a + (l->n - d), d * sizeof *l->a);
    l->n = d;
    uint64_t *b = realloc(l->a, (d ? d : 1) * sizeof *b);
    if (b) {
        l->a = b;
        l->cap = d ? d : 1;
    }
    return 0;
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
    for (uint32_t i = 0; rc == 0 && i < n; i++)
        if (last_uses(&w->rec[want[i]], w->l1cap) != 0)
            atomic_store(&w->oom, 1);
    if (rc == 0 && atomic_load(&w->oom)) {
        snprintf(err, errlen, "out of memory recording %u units' lines", n);
        rc = -1;
    }
    for (uint32_t i = 0; i < n; i++) {
        if (rc == 0) {
            w->state[want[i]] = REC_DONE;
            w->recorded++;
        } else {
            w->state[want[i]] = REC_NONE;
            w->rec[want[i]].n = 0;
        }
    }
    w->seconds += util_now() - t0;
    free(tiles);
    free(pass_done);
    return rc;
}

int chipwarm_l1(ChipWarm *w, const uint32_t *prev, uint32_t n, int threads, uint64_t **lists, size_t *lens, char *err,
                size_t errlen)
{
    const size_t N = (size_t)w->ntiles * w->spp;
    uint32_t *want = malloc((n ? n : 1) * sizeof *want), nwant = 0;
    int rc = 0;
    if (!want) {
        snprintf(err, errlen, "out of memory for %u warming lists", n);
        rc = -1;
    }
    for (uint32_t i = 0; rc == 0 && i < n; i++)
        if (prev[i] < N && w->state[prev[i]] == REC_NONE) {
            w->state[prev[i]] = REC_WANTED;
            want[nwant++] = prev[i];
        }
    if (rc == 0 && nwant)
        rc = record(w, want, nwant, threads, err, errlen);
    for (uint32_t i = 0; i < n; i++) {
        lists[i] = NULL;
        lens[i] = 0;
        if (rc != 0 || prev[i] >= N || !w->rec[prev[i]].n)
            continue;
        const Lines *l = &w->rec[prev[i]];
        if (!(lists[i] = malloc(l->n * sizeof **lists))) {
            snprintf(err, errlen, "out of memory for %u warming lists", n);
            rc = -1;
            continue;
        }
        memcpy(lists[i], l->a, l->n * sizeof **lists);
        lens[i] = l->n;
    }
    if (rc != 0)
        for (uint32_t i = 0; i < n; i++) {
            free(lists[i]);
            lists[i] = NULL;
            lens[i] = 0;
        }
    free(want);
    return rc;
}
