/* sim/ref_kd.c -- kd-tree traversal variants of seed 004, Appendix A (see ref_kd.h).
 *
 * Owns: the single-ray traversals (A.1-A.4, one loop with the variant's choices) and the
 * packetized short stack (A.5: start, next entry or restart, descent, leaf, advance), with their
 * counters. Must not: build or pack trees (scenes/kdtree.c, sim/run/accel.c), shade, or know the
 * simulated machine. */
#include "ref_kd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *const ref_kd_variant_names[REF_KD_VARIANTS] = {"stack", "restart", "pushdown", "shortstack"};

/* The deepest stack a tree needs: one entry per level. */
#define KD_MAX_STACK 64
/* Widening of a split distance: 2^-20 of it, several times its rounding error (a subtraction, a
 * multiplication and a reciprocal: at most 1.5 ulp = 1.8e-7 relative), plus a floor for 0. */
#define KD_WIDEN 9.5367431640625e-7f
#define KD_WIDEN_FLOOR 1e-30f

typedef struct Entry {
    uint32_t node;
    float tmin, tmax;  /* the segment of the ray in the node's voxel (ends widened) */
    float texit;       /* a lower bound of where the segment truly ends: the early-exit bound */
} Entry;

/* A bounded stack: with cap entries, a push onto a full stack drops the bottom entry. */
typedef struct KdStack {
    Entry e[KD_MAX_STACK];
    int bottom, n, cap;
} KdStack;

static void push(KdStack *s, Entry x, RefKdStats *st)
{
    if (s->n == s->cap) {
        s->bottom = (s->bottom + 1) % KD_MAX_STACK;
        s->n--;
        if (st)
            st->stack_overflows++;
    }
    s->e[(s->bottom + s->n) % KD_MAX_STACK] = x;
    s->n++;
}

static Entry pop(KdStack *s)
{
    s->n--;
    return s->e[(s->bottom + s->n) % KD_MAX_STACK];
}

/* The query; closest = 0 stops at the first hit. Returns 1 on a hit. With keep, a hit already in
 * *hit is kept and bounds the ray (the packet's fallback continues from its hits, as the kernel
 * does with the hit in its ray buffer). */
static int trace(const PackedScene *p, const KdTree *t, RefKdVariant v, int depth, const RefRay *r, RefHit *hit,
                 int closest, int keep, RefKdStats *st)
{
    RefRay q = *r;
    if (keep && hit->prim != REF_NO_HIT) {
        q.tmax = hit->t;
    } else {
        hit->prim = REF_NO_HIT;
        hit->t = r->tmax;
        hit->u = hit->v = 0.0f;
    }
    ref_sanitize_dir(q.dir);
    float inv[3];
    ref_inv_dir(q.dir, inv);
    RefRayPre pre;
    ref_ray_prepare(&pre, &q);
    /* The ray's segment inside the scene box (the slab test of the BVH traversal). */
    float t0 = 0.0f, t1 = q.tmax * REF_HIT_SCALE; /* widened as in ref_hit_box */
    for (int k = 0; k < 3; k++) {
        float a = (t->bmin[k] - q.org[k]) * inv[k], b = (t->bmax[k] - q.org[k]) * inv[k];
        t0 = ref_fmax(t0, ref_fmin(a, b));
        t1 = ref_fmin(t1, ref_fmax(a, b) * 1.00000072f);
    }
    if (!(t0 <= t1) || t->nnodes == 0)
        return 0;
    KdStack s = {.bottom = 0, .n = 0, .cap = v == REF_KD_SHORTSTACK ? depth : KD_MAX_STACK};
    if (s.cap < 1)
        s.cap = 1;
    if (s.cap > KD_MAX_STACK)
        s.cap = KD_MAX_STACK;
    const int stackful = v == REF_KD_STACK || v == REF_KD_SHORTSTACK;
    const int pushdown_on = v == REF_KD_PUSHDOWN || v == REF_KD_SHORTSTACK;
    uint32_t root = 0;
    Entry cur = {0, t0, t0, t1};
    int first = 1;
    if (v == REF_KD_STACK)
        push(&s, (Entry){0, t0, t1, t1}, st);
    for (;;) {
        int pushdown = 0;
        if (s.n > 0) {
            cur = pop(&s);
        } else if (v == REF_KD_STACK) {
            break;
        } else {
            /* Restart: the next segment starts where the last leaf's ended. */
            if (!first && !(cur.tmax < t1))
                break;
            if (!first && st) {
                st->restarts++;
                if (v == REF_KD_SHORTSTACK)
                    st->stack_underflows++;
            }
            cur = (Entry){root, cur.tmax, t1, t1};
            pushdown = pushdown_on;
        }
        first = 0;
        uint32_t node = cur.node;
        float tmin = cur.tmin, tmax = cur.tmax, texit = cur.texit;
        const KdNode *nd = &t->nodes[node];
        while (nd->axis != KD_LEAF) {
            if (st)
                st->nodes_visited++;
            uint32_t a = nd->axis;
            float o = q.org[a], d = q.dir[a];
            int below = o < nd->split || (o == nd->split && d < 0.0f);
            uint32_t near = below ? nd->a : nd->a + 1, far = below ? nd->a + 1 : nd->a;
            /* A.1 with the split distance widened to [lo, hi] (more than its rounding error):
             * entirely beyond the segment or behind the origin: the near child only; entirely
             * before it: the far child only; else both, the far one later, from hi -- where a
             * restart would resume, so every variant descends alike. Moving away from the plane
             * is "behind"; the sign test is exact where tSplit may round to 0. */
            float ts = (nd->split - o) * inv[a];
            float eps = fabsf(ts) * KD_WIDEN + KD_WIDEN_FLOOR, lo = ts - eps, hi = ts + eps;
            if (below == (d < 0.0f) || lo > tmax) {
                node = near;
            } else if (hi <= tmin) {
                node = far;
            } else {
                float nmax = hi < tmax ? hi : tmax;
                if (stackful)
                    push(&s, (Entry){far, nmax, tmax, texit}, st);
                node = near;
                tmax = nmax;
                texit = lo < texit ? lo : texit;
                pushdown = 0;
            }
            nd = &t->nodes[node];
            if (pushdown)
                root = node;
        }
        if (st) {
            st->nodes_visited++;
            st->leaves_visited++;
        }
        for (uint32_t i = nd->a; i < nd->a + nd->count; i++) {
            uint32_t pr = t->prims[i];
            float th, u, w;
            if (st)
                st->prims_tested++;
            /* An any-hit query returns at its first hit, so only a closest-hit query ever tests
             * with a hit in hand (the tie probe). */
            if (!ref_hit_prim_pre(p, pr, &pre, ref_hit_tmax(hit, q.tmax), &th, &u, &w))
                continue;
            ref_hit_keep(hit, th, u, w, pr);
            if (!closest)
                return 1;
        }
        /* Early exit: nothing unvisited can be closer than the segment's (lower) end. */
        if (hit->prim != REF_NO_HIT && hit->t * REF_HIT_SCALE < texit)
            break;
        cur.tmax = tmax;
    }
    return hit->prim != REF_NO_HIT;
}

void ref_kd_closest_hit(const PackedScene *p, const KdTree *t, RefKdVariant v, int stack_depth, const RefRay *r,
                        RefHit *hit, RefKdStats *st)
{
    trace(p, t, v, stack_depth, r, hit, 1, 0, st);
}

int ref_kd_any_hit(const PackedScene *p, const KdTree *t, RefKdVariant v, int stack_depth, const RefRay *r,
                   RefKdStats *st)
{
    RefHit h;
    return trace(p, t, v, stack_depth, r, &h, 0, 0, st);
}

/* ---- A.5: the packetized short stack ---------------------------------------------------------- */

#define KD_PACKET 64

static uint64_t live_rays(uint64_t live) { return (uint64_t)__builtin_popcountll(live); }

typedef struct PEntry {
    uint32_t node;
    uint64_t live;
    float tmin[KD_PACKET], tmax[KD_PACKET], texit[KD_PACKET];
} PEntry;

/* One packet's traversal: its rays, its short stack (cap entries, a ring from `bottom`), each
 * ray's progress point (where its next restart starts) and segment end, and the restart state. */
typedef struct Packet {
    const PackedScene *p;
    const KdTree *t;
    const RefRay *rays;
    RefHit *hits;
    RefKdStats *st;
    int n, cap, bottom, depth;
    PEntry *stack;
    RefRay q[KD_PACKET];          /* the rays, directions sanitized */
    RefRayPre pre[KD_PACKET];     /* their primitive tests' constants */
    float inv[KD_PACKET][3], t1[KD_PACKET], prog[KD_PACKET];
    uint64_t done, all;           /* rays finished; every ray of the packet */
    uint32_t root;                /* the push-down root restarts begin at */
    int first;                    /* no descent made yet */
    float last_prog[KD_PACKET];   /* prog and done at the last restart */
    uint64_t last_done;
} Packet;

/* Every hit empty, every ray clipped to the scene box (the slab test of the BVH traversal); a
 * ray that misses the box is done. */
static void packet_start(Packet *k)
{
    const KdTree *t = k->t;
    for (int i = 0; i < k->n; i++) {
        RefHit *h = &k->hits[i];
        h->prim = REF_NO_HIT;
        h->t = k->rays[i].tmax;
        h->u = h->v = 0.0f;
        k->q[i] = k->rays[i];
        ref_sanitize_dir(k->q[i].dir);
        ref_inv_dir(k->q[i].dir, k->inv[i]);
        ref_ray_prepare(&k->pre[i], &k->q[i]);
        float a0 = 0.0f, a1 = k->q[i].tmax * REF_HIT_SCALE;
        for (int c = 0; c < 3; c++) {
            float a = (t->bmin[c] - k->q[i].org[c]) * k->inv[i][c], b = (t->bmax[c] - k->q[i].org[c]) * k->inv[i][c];
            a0 = ref_fmax(a0, ref_fmin(a, b));
            a1 = ref_fmin(a1, ref_fmax(a, b) * 1.00000072f);
        }
        k->prog[i] = a0;
        k->t1[i] = a1;
        if (!(a0 <= a1) || t->nnodes == 0)
            k->done |= 1ull << i;
    }
    k->last_done = k->done;
    memcpy(k->last_prog, k->prog, sizeof k->prog);
}

/* The next entry to descend from into *cur: the top of the stack, or, on an empty stack, a
 * restart from the push-down root (*pushdown = 1) for every unfinished ray. Returns 1 to descend,
 * 0 when the popped entry has no live ray left, -1 when the packet is finished. */
static int packet_next(Packet *k, PEntry *cur, int *pushdown)
{
    *pushdown = 0;
    if (k->depth > 0) {
        k->depth--;
        *cur = k->stack[(k->bottom + k->depth) % k->cap];
        cur->live &= ~k->done;
        if (!cur->live)
            return 0;
    } else {
        cur->node = k->root;
        cur->live = 0;
        for (int i = 0; i < k->n; i++)
            if (!((k->done >> i) & 1u) && (k->first || k->prog[i] < k->t1[i])) {
                cur->live |= 1ull << i;
                cur->tmin[i] = k->prog[i];
                cur->tmax[i] = cur->texit[i] = k->t1[i];
            } else if (!((k->done >> i) & 1u)) {
                k->done |= 1ull << i; /* the whole segment was visited */
            }
        if (!cur->live)
            return -1;
        if (!k->first) {
            if (k->st) {
                k->st->restarts += live_rays(cur->live);
                k->st->stack_underflows += live_rays(cur->live);
            }
            /* No ray advanced since the last restart (rays of opposite directions keep pushing
             * each other's near sides off a short stack): the rays left finish one by one,
             * each continuing from its hit so far. */
            if (memcmp(k->last_prog, k->prog, sizeof k->prog) == 0 && k->last_done == k->done) {
                for (int i = 0; i < k->n; i++)
                    if ((cur->live >> i) & 1u)
                        trace(k->p, k->t, REF_KD_SHORTSTACK, k->cap, &k->rays[i], &k->hits[i], 1, 1, k->st);
                return -1;
            }
        }
        memcpy(k->last_prog, k->prog, sizeof k->prog);
        k->last_done = k->done;
        *pushdown = 1;
    }
    k->first = 0;
    return 1;
}

/* Sorts the live rays of *cur at inner node nd into the packet's first child (fe: the lead ray's
 * near child) and second (se), each with its segment; returns 1 when some ray's far side was left
 * to a restart. */
static int packet_split(const Packet *k, const KdNode *nd, const PEntry *cur, int lead_below, PEntry *fe, PEntry *se)
{
    uint32_t a = nd->axis;
    int deferred = 0;
    for (int i = 0; i < k->n; i++) {
        if (!((cur->live >> i) & 1u))
            continue;
        float o = k->q[i].org[a], d = k->q[i].dir[a], tmin = cur->tmin[i], tmax = cur->tmax[i], tx = cur->texit[i];
        int below = o < nd->split || (o == nd->split && d < 0.0f);
        int near_is_first = below == lead_below;
        float ts = (nd->split - o) * k->inv[i][a];
        float eps = fabsf(ts) * KD_WIDEN + KD_WIDEN_FLOOR, lo = ts - eps, hi = ts + eps;
        int want_near = 1, want_far = 1;
        float nmax = tmax;
        if (below == (d < 0.0f) || lo > tmax)
            want_far = 0;
        else if (hi <= tmin)
            want_near = 0;
        else
            nmax = hi < tmax ? hi : tmax;
        PEntry *ne = near_is_first ? fe : se, *fa = near_is_first ? se : fe;
        if (want_near) {
            ne->live |= 1ull << i;
            ne->tmin[i] = tmin;
            ne->tmax[i] = want_far ? nmax : tmax;
            ne->texit[i] = want_far ? (lo < tx ? lo : tx) : tx;
        }
        /* A ray whose near child is the packet's second goes there only: its far side
         * is left to a restart, so every ray still meets its space front to back. */
        if (want_far && (near_is_first || !want_near)) {
            fa->live |= 1ull << i;
            fa->tmin[i] = want_near ? nmax : tmin;
            fa->tmax[i] = tmax;
            fa->texit[i] = tx;
        } else if (want_far) {
            deferred = 1;
        }
    }
    return deferred;
}

/* Descends from *cur to a leaf, following the first live ray's near child and pushing the other
 * child when rays go both ways (a full stack drops its bottom entry); moves the push-down root
 * while no ray has a side left behind. Returns the leaf; *cur holds its rays. */
static const KdNode *packet_descend(Packet *k, PEntry *cur, int pushdown)
{
    RefKdStats *st = k->st;
    const KdNode *nd = &k->t->nodes[cur->node];
    while (nd->axis != KD_LEAF) {
        if (st) {
            st->nodes_visited += live_rays(cur->live);
            st->packet_steps++;
        }
        uint32_t a = nd->axis;
        int lead = __builtin_ctzll(cur->live);
        int lead_below = k->q[lead].org[a] < nd->split || (k->q[lead].org[a] == nd->split && k->q[lead].dir[a] < 0.0f);
        uint32_t firstc = lead_below ? nd->a : nd->a + 1, second = lead_below ? nd->a + 1 : nd->a;
        PEntry fe, se;
        fe.live = se.live = 0;
        int deferred = packet_split(k, nd, cur, lead_below, &fe, &se); /* some ray's far side was left to a restart */
        if (!se.live) {
            fe.node = firstc;
            *cur = fe;
        } else if (!fe.live) {
            se.node = second;
            *cur = se;
        } else {
            se.node = second;
            if (k->depth == k->cap) { /* full: drop the bottom entry */
                k->bottom = (k->bottom + 1) % k->cap;
                k->depth--;
                if (st)
                    st->stack_overflows += live_rays(cur->live);
            }
            k->stack[(k->bottom + k->depth) % k->cap] = se;
            k->depth++;
            fe.node = firstc;
            *cur = fe;
            pushdown = 0;
        }
        if (deferred) /* a restart must be able to reach the deferred side */
            pushdown = 0;
        nd = &k->t->nodes[cur->node];
        if (pushdown)
            k->root = cur->node;
    }
    return nd;
}

/* Leaf nd's primitives against every live ray of *cur (closest hit, the lower primitive at equal t). */
static void packet_leaf(Packet *k, const KdNode *nd, const PEntry *cur)
{
    RefKdStats *st = k->st;
    if (st) {
        st->nodes_visited += live_rays(cur->live);
        st->leaves_visited += live_rays(cur->live);
        st->packet_steps++;
    }
    for (uint32_t c = nd->a; c < nd->a + nd->count; c++) {
        uint32_t pr = k->t->prims[c];
        for (int i = 0; i < k->n; i++) {
            if (!((cur->live >> i) & 1u))
                continue;
            RefHit *h = &k->hits[i];
            float th, u, w;
            if (st)
                st->prims_tested++;
            if (ref_hit_prim_pre(k->p, pr, &k->pre[i], ref_hit_tmax(h, k->q[i].tmax), &th, &u, &w))
                ref_hit_keep(h, th, u, w, pr);
        }
    }
}

/* A ray whose segment started at its progress point has visited everything before the
 * segment's end: it advances, and is done when its hit lies before the segment's (lower) end. */
static void packet_advance(Packet *k, const PEntry *cur)
{
    for (int i = 0; i < k->n; i++) {
        if (!((cur->live >> i) & 1u) || cur->tmin[i] > k->prog[i])
            continue;
        if (cur->tmax[i] > k->prog[i])
            k->prog[i] = cur->tmax[i];
        if (k->hits[i].prim != REF_NO_HIT && k->hits[i].t * REF_HIT_SCALE < cur->texit[i])
            k->done |= 1ull << i;
    }
}

void ref_kd_packet_closest_hit(const PackedScene *p, const KdTree *t, int stack_depth, const RefRay *rays, int n,
                               RefHit *hits, RefKdStats *st)
{
    if (n < 1)
        return;
    if (n > KD_PACKET)
        n = KD_PACKET;
    Packet k = {.p = p, .t = t, .rays = rays, .hits = hits, .st = st, .n = n, .first = 1};
    k.cap = stack_depth < 1 ? 1 : stack_depth > KD_MAX_STACK ? KD_MAX_STACK : stack_depth;
    k.stack = malloc((size_t)k.cap * sizeof *k.stack);
    if (!k.stack)
        abort(); /* out of memory for a few kilobytes of stack: nothing sensible to return */
    k.all = n >= 64 ? ~0ull : (1ull << n) - 1;
    packet_start(&k);
    PEntry cur;
    while (k.done != k.all || k.depth > 0) {
        int pushdown, next = packet_next(&k, &cur, &pushdown);
        if (next < 0)
            break;
        if (next == 0)
            continue;
        const KdNode *nd = packet_descend(&k, &cur, pushdown);
        packet_leaf(&k, nd, &cur);
        packet_advance(&k, &cur);
    }
    free(k.stack);
}
