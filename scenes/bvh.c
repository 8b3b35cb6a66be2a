/* scenes/bvh.c -- binned SAH BVH builder (the checks of its input and of a built tree, and its
 * cost: scenes/bvh_check.c).
 *
 * Owns: BvhNode topology and prim_index order. Must not: look at primitive geometry beyond the
 * boxes it is given, or lay the tree out in simulated memory.
 *
 * Deterministic: the same boxes and parameters give the same tree, bit for bit (no threads, no
 * unstable sorts), so images and cycle counts do not change from run to run.
 *
 * The build is written for speed (primitives copied into build order as 32-byte boxes, one
 * binning pass for the three axes with their bin indices computed in the lanes of one vector and
 * kept for the partition, children's boxes grown during the partition, only non-empty bins swept,
 * a split's cost divided out only when it can win, large arrays on huge pages, large nodes binned
 * into several sets of bins, nodes of two primitives and of up to eight split without bin arrays,
 * with AVX2 the candidate splits costed eight at a time and the best picked without a branch)
 * and must give the
 * trees of the plain algorithm in tests/support/bvh_ref.c, bit for bit, zeros' signs included:
 * tests/unit/test_bvh.c compares them, on random and degenerate boxes and on real meshes.
 */
#include "bvh.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
#if defined(__linux__)
#include <sys/mman.h>
#endif

void bvh_default_params(BvhParams *p)
{
    p->max_leaf_size = 4;
    p->bins = 16;
    p->cost_traversal = 1.0f;
    p->cost_intersect = 1.0f;
}

/* A box in 8 lanes: lo in lanes 0-2 and the NEGATED hi in lanes 4-6 (lanes 3 and 7 are padding,
 * never read back). Negation is exact and turns the maximum into a minimum, so growing a box is
 * one 8-lane minimum (one AVX instruction). A primitive during the build is such a box, and so is
 * a centroid c as [c, -c].
 *
 * The minimum is the one the trees were first built with, bit for bit. That build called libm's
 * fminf(new, held) / fmaxf(new, held) (GCC orders the operands of these commutative calls so) and
 * glibc's x86-64 fminf / fmaxf (minss / maxss) return their second operand on a tie: so the value
 * already held stays, which decides between -0.0 and +0.0 and so the bytes stored. The negated
 * lanes keep that rule: -(x > h ? x : h) is (-x < -h ? -x : -h). No NaN reaches them: bvh_build
 * rejects NaN boxes, and centroids of finite boxes are finite or infinite. */
typedef struct Box { _Alignas(32) float v[8]; } Box;

static const Box box_none = {{INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY}};

/* A box in registers: one AVX register, or the struct where there is no AVX. */
#if defined(__AVX__)
typedef __m256 Vbox;
static inline Vbox vbox_load(const Box *b) { return _mm256_load_ps(b->v); }
static inline void vbox_store(Box *b, Vbox x) { _mm256_store_ps(b->v, x); }
/* x86 minps(a, b) is a < b ? a : b: on a tie, the second operand. */
static inline Vbox vbox_grow(Vbox held, Vbox x) { return _mm256_min_ps(x, held); }
static inline Vbox vbox_grow_backwards(Vbox held, Vbox x) { return _mm256_min_ps(held, x); }
/* The centroid box [c, -c] of primitive q: c = 0.5f * (lo + hi), computed as 0.5f * (lo - (-hi)),
 * which IEEE arithmetic defines to be the same value. */
static inline Vbox vbox_centroid(Vbox q)
{
    __m128 c = _mm_mul_ps(_mm_sub_ps(_mm256_castps256_ps128(q), _mm256_extractf128_ps(q, 1)), _mm_set1_ps(0.5f));
    return _mm256_insertf128_ps(_mm256_castps128_ps256(c), _mm_xor_ps(c, _mm_set1_ps(-0.0f)), 1);
}
/* Lane k (0..2) of a centroid box. */
static inline float vbox_lane(Vbox b, __m128i k) { return _mm_cvtss_f32(_mm_permutevar_ps(_mm256_castps256_ps128(b), k)); }
typedef __m128i Vlane;
static inline Vlane vbox_lane_index(int k) { return _mm_set1_epi32(k); }
/* c ? a : b, without a branch (c is 0 or 1) */
static inline Vbox vbox_select(uint32_t c, Vbox a, Vbox b)
{
    return _mm256_blendv_ps(b, a, _mm256_castsi256_ps(_mm256_set1_epi32(-(int)c)));
}
#else
typedef Box Vbox;
static inline Vbox vbox_load(const Box *b) { return *b; }
static inline void vbox_store(Box *b, Vbox x) { *b = x; }
static inline Vbox vbox_grow(Vbox held, Vbox x)
{
    for (int k = 0; k < 8; k++)
        held.v[k] = x.v[k] < held.v[k] ? x.v[k] : held.v[k];
    return held;
}
static inline Vbox vbox_grow_backwards(Vbox held, Vbox x)
{
    for (int k = 0; k < 8; k++)
        held.v[k] = held.v[k] < x.v[k] ? held.v[k] : x.v[k];
    return held;
}
static inline Vbox vbox_centroid(Vbox q)
{
    Vbox cc;
    for (int k = 0; k < 4; k++) {
        cc.v[k] = 0.5f * (q.v[k] - q.v[4 + k]);
        cc.v[4 + k] = -cc.v[k];
    }
    return cc;
}
typedef int Vlane;
static inline float vbox_lane(Vbox b, int k) { return b.v[k]; }
static inline Vlane vbox_lane_index(int k) { return k; }
static inline Vbox vbox_select(uint32_t c, Vbox a, Vbox b) { return c ? a : b; }
#endif

/* Grow b by x; on a tie b keeps the value it holds. */
static inline void box_grow(Box *restrict b, const Box *restrict x)
{
    vbox_store(b, vbox_grow(vbox_load(b), vbox_load(x)));
}

static inline float box_lo(const Box *b, int k) { return b->v[k]; }
static inline float box_hi(const Box *b, int k) { return -b->v[4 + k]; }

static inline float centroid_of(const Box *q, int axis) { return 0.5f * (q->v[axis] - q->v[4 + axis]); }

static inline float extent_of(float lo, float hi) { return hi > lo ? hi - lo : 0.0f; }

/* Written out: GCC -O2 does not unroll the three-axis loop, and the sweep calls this twice per
 * candidate split. */
static inline float box_area(const Box *b)
{
    float dx = extent_of(box_lo(b, 0), box_hi(b, 0));
    float dy = extent_of(box_lo(b, 1), box_hi(b, 1));
    float dz = extent_of(box_lo(b, 2), box_hi(b, 2));
    return 2.0f * (dx * dy + dy * dz + dz * dx);
}

/* box_area of a box in registers. With AVX the three extents are taken in the lanes of one
 * vector (hi > lo ? hi - lo : 0 as a mask on the difference) and their products and sums are
 * those of box_area, in its order. */
#if defined(__AVX__)
static inline float vbox_area(Vbox b)
{
    __m128 lo = _mm256_castps256_ps128(b);
    __m128 hi = _mm_xor_ps(_mm256_extractf128_ps(b, 1), _mm_set1_ps(-0.0f));
    __m128 d = _mm_and_ps(_mm_cmpgt_ps(hi, lo), _mm_sub_ps(hi, lo));
    __m128 p = _mm_mul_ps(d, _mm_shuffle_ps(d, d, _MM_SHUFFLE(3, 0, 2, 1))); /* dx dy, dy dz, dz dx */
    float sum = _mm_cvtss_f32(p) + _mm_cvtss_f32(_mm_shuffle_ps(p, p, 1));
    sum = sum + _mm_cvtss_f32(_mm_movehl_ps(p, p));
    return 2.0f * sum;
}
#else
static inline float vbox_area(Vbox b) { return box_area(&b); }
#endif

/* A node to build: its own box is already in nodes[node]; cb is its centroids' box. */
typedef struct Task {
    Box cb;
    uint32_t node, begin, end, depth;
} Task;

/* The bins of one axis: their boxes and primitive counts. */
typedef struct Bins {
    Box box[256];
    uint32_t count[256];
} Bins;

typedef struct Builder {
    const BvhParams *p;
    Box *prim;   /* n, in prim_index order (which the partition permutes with them) */
    Bins *bins;  /* BIN_SETS sets of one per axis, then a sink for the axes that give no split;
                  * empty (box_none, count 0) between nodes, except the sink, which is never read */
    uint8_t (*bin)[4]; /* n: each position's bin on the three axes in the last binning that
                        * covered it; partition reads the split axis's and does not move them
                        * (every node bins its own primitives again before it is split) */
    Bvh *b;
} Builder;

/* Binning a large node spreads its primitives over BIN_SETS sets of bins (primitive j into set j
 * mod BIN_SETS), merged before the sweep: growing one bin's box is a load, a minimum and a store,
 * and consecutive primitives, neighbours in the mesh, fall in the same bin so often that each
 * waited for the previous one's store. Order does not matter to a bin's box, up to the sign of
 * a zero (a minimum of the same values), and zeros' signs do not change the areas the sweep
 * computes (extent_of: hi > lo ? hi - lo : 0 is the same for -0 and +0), so the splits are the
 * same. Smaller nodes use set 0 alone. */
enum { BIN_SETS = 4, BIN_SETS_FROM = 64, BIN_SINK = 3 * BIN_SETS };

/* Bin of a centroid on one axis; the same expression is used to count and to partition, so
 * the two always agree. */
static inline int bin_of(float c, float cmin, float scale, int bins)
{
    int i = (int)((c - cmin) * scale);
    return i < 0 ? 0 : (i >= bins ? bins - 1 : i);
}

/* The best split so far: its cost, and x, the cost's numerator (left area x count + right area x
 * count), from which the cost is computed by a chain of operations that never decrease. */
typedef struct Split { int axis, bin; float cost, x; } Split;

/* The indices of the non-empty bins among the first nb, in increasing order; their number. */
static int list_nonempty(const uint32_t *count, int nb, int *list)
{
    int m = 0, i = 0;
#if defined(__SSE2__)
    for (; i + 4 <= nb; i += 4) {
        __m128i zero = _mm_cmpeq_epi32(_mm_loadu_si128((const __m128i *)&count[i]), _mm_setzero_si128());
        unsigned mask = ~(unsigned)_mm_movemask_ps(_mm_castsi128_ps(zero)) & 15u;
        for (; mask; mask &= mask - 1)
            list[m++] = i + __builtin_ctz(mask);
    }
#endif
    for (; i < nb; i++)
        if (count[i] > 0)
            list[m++] = i;
    return m;
}

/* The best split of one axis's bins into (best->bin and below, the rest), if it beats best.
 * Only non-empty bins are visited: a split after an empty bin has the same left box, right
 * box and counts, hence the same cost, as the split before it, and only a strictly lower cost
 * replaces best; growing a box by an empty bin leaves it unchanged, bit for bit. So the cost and
 * the bin found are those of sweeping every bin. The cost is cost_traversal + cost_intersect * x
 * / parea, each step non-decreasing in x (cost_intersect > 0, parea > 0): a candidate whose x is
 * not below the best's cannot cost strictly less, so its division is skipped (NaN costs, from an
 * infinite parea, compare false either way). */
static void sweep_axis(const BvhParams *p, Bins *bins, int axis, uint32_t total, float parea,
                       Split *best)
{
    int nonempty[256], m = list_nonempty(bins->count, p->bins, nonempty);
    /* right_area[r]: the area of the union of the non-empty bins r .. m-1, grown from the right */
    float right_area[256];
    Vbox none = vbox_load(&box_none), acc = none;
    for (int r = m - 1; r > 0; r--) {
        acc = vbox_grow(acc, vbox_load(&bins->box[nonempty[r]]));
        right_area[r] = vbox_area(acc);
    }
    Vbox left = none;
    uint32_t nleft = 0;
    for (int r = 0; r < m - 1; r++) {
        left = vbox_grow(left, vbox_load(&bins->box[nonempty[r]]));
        nleft += bins->count[nonempty[r]];
        uint32_t nright = total - nleft;
        float x = vbox_area(left) * (float)nleft + right_area[r + 1] * (float)nright;
        if (!(x < best->x))
            continue;
        float cost = p->cost_traversal + p->cost_intersect * x / parea;
        if (cost < best->cost) {
            best->axis = axis;
            best->bin = nonempty[r];
            best->cost = cost;
            best->x = x;
        }
    }
    /* empty the bins for the next node: only the non-empty ones need it */
    for (int r = 0; r < m; r++) {
        bins->box[nonempty[r]] = box_none;
        bins->count[nonempty[r]] = 0;
    }
}

#if defined(__AVX2__)
/* The candidate splits in 8 lanes (AVX2 builds), every bin's instead of the non-empty ones', with
 * no branch on a bin: lane by lane the operations of sweep_axis and box_area, so the same costs.
 * A candidate after an empty bin repeats the cost of the one before it, so the first of the lowest
 * costs, which is what the sweep keeps (only a strictly lower cost replaces the best), is a split
 * sweep_axis considers, at the same bin. */

/* The areas of boxes b[0 .. 7] in lanes 0 .. 7: the boxes transposed to one vector per
 * coordinate, then box_area's extents, products and sums. */
static inline __m256 area8(const Box *b)
{
    __m256 t0 = _mm256_unpacklo_ps(vbox_load(&b[0]), vbox_load(&b[1]));
    __m256 t1 = _mm256_unpackhi_ps(vbox_load(&b[0]), vbox_load(&b[1]));
    __m256 t2 = _mm256_unpacklo_ps(vbox_load(&b[2]), vbox_load(&b[3]));
    __m256 t3 = _mm256_unpackhi_ps(vbox_load(&b[2]), vbox_load(&b[3]));
    __m256 t4 = _mm256_unpacklo_ps(vbox_load(&b[4]), vbox_load(&b[5]));
    __m256 t5 = _mm256_unpackhi_ps(vbox_load(&b[4]), vbox_load(&b[5]));
    __m256 t6 = _mm256_unpacklo_ps(vbox_load(&b[6]), vbox_load(&b[7]));
    __m256 t7 = _mm256_unpackhi_ps(vbox_load(&b[6]), vbox_load(&b[7]));
    /* [x0..x3 | -X0..-X3] and so on: lo and negated hi of boxes 0-3, then of 4-7 */
    __m256 x03 = _mm256_shuffle_ps(t0, t2, 0x44), y03 = _mm256_shuffle_ps(t0, t2, 0xee), z03 = _mm256_shuffle_ps(t1, t3, 0x44);
    __m256 x47 = _mm256_shuffle_ps(t4, t6, 0x44), y47 = _mm256_shuffle_ps(t4, t6, 0xee), z47 = _mm256_shuffle_ps(t5, t7, 0x44);
    __m256 sign = _mm256_set1_ps(-0.0f), d[3];
    __m256 lo[3] = {_mm256_permute2f128_ps(x03, x47, 0x20), _mm256_permute2f128_ps(y03, y47, 0x20),
                    _mm256_permute2f128_ps(z03, z47, 0x20)};
    __m256 nhi[3] = {_mm256_permute2f128_ps(x03, x47, 0x31), _mm256_permute2f128_ps(y03, y47, 0x31),
                     _mm256_permute2f128_ps(z03, z47, 0x31)};
#pragma GCC unroll 3
    for (int k = 0; k < 3; k++) {
        __m256 hi = _mm256_xor_ps(nhi[k], sign);
        d[k] = _mm256_and_ps(_mm256_cmp_ps(hi, lo[k], _CMP_GT_OQ), _mm256_sub_ps(hi, lo[k]));
    }
    __m256 sum = _mm256_add_ps(_mm256_mul_ps(d[0], d[1]), _mm256_mul_ps(d[1], d[2]));
    sum = _mm256_add_ps(sum, _mm256_mul_ps(d[2], d[0]));
    return _mm256_mul_ps(_mm256_set1_ps(2.0f), sum);
}

/* Eight candidates: left areas and counts, right areas and counts, which lanes are splits (all
 * ones). The first of the lowest costs among them, if below best's, replaces it (but for its bin,
 * which the caller sets): its lane, or 8 when best stays. Without a branch: which axis wins is
 * not predictable. */
static inline int pick8(const BvhParams *p, __m256 larea, __m256 nleft, __m256 rarea, __m256 nright, __m256 ok,
                        float parea, int axis, Split *best)
{
    __m256 x = _mm256_add_ps(_mm256_mul_ps(larea, nleft), _mm256_mul_ps(rarea, nright));
    __m256 cost = _mm256_add_ps(_mm256_set1_ps(p->cost_traversal),
                                _mm256_div_ps(_mm256_mul_ps(_mm256_set1_ps(p->cost_intersect), x), _mm256_set1_ps(parea)));
    ok = _mm256_and_ps(ok, _mm256_cmp_ps(cost, _mm256_set1_ps(best->cost), _CMP_LT_OQ));
    /* no NaN among the lanes kept (cost < best->cost), the others at infinity */
    __m256 c = _mm256_blendv_ps(_mm256_set1_ps(INFINITY), cost, ok);
    __m256 low = _mm256_min_ps(c, _mm256_permute2f128_ps(c, c, 1));
    low = _mm256_min_ps(low, _mm256_shuffle_ps(low, low, _MM_SHUFFLE(1, 0, 3, 2)));
    low = _mm256_min_ps(low, _mm256_shuffle_ps(low, low, _MM_SHUFFLE(2, 3, 0, 1)));
    unsigned m = (unsigned)_mm256_movemask_ps(ok);
    int r = __builtin_ctz(((unsigned)_mm256_movemask_ps(_mm256_cmp_ps(c, low, _CMP_EQ_OQ)) & m) | 0x100u);
    _Alignas(32) float costs[9], xs[9];
    _mm256_store_ps(costs, cost);
    _mm256_store_ps(xs, x);
    costs[8] = best->cost;
    xs[8] = best->x;
    best->axis = m ? axis : best->axis;
    best->cost = costs[r];
    best->x = xs[r];
    return r;
}

/* sweep_axis over every bin, eight candidates at a time; empties the bins. total < 2^31 (the
 * counts are converted as signed integers). Inlined with nb a constant for the default 16 bins,
 * where its loops unroll. */
static inline __attribute__((always_inline)) void sweep_bins8(const BvhParams *p, Bins *bins, int nb, int axis,
                                                              uint32_t total, float parea, Split *best)
{
    int nc = nb - 1, nc8 = (nc + 7) / 8 * 8; /* candidate c: bins 0 .. c left */
    _Alignas(32) Box left[256], right[256];
    _Alignas(32) int32_t nleft[256];
    Vbox none = vbox_load(&box_none), acc = none;
#pragma GCC unroll 16
    for (int c = nc - 1; c >= 0; c--) {
        acc = vbox_grow(acc, vbox_load(&bins->box[c + 1]));
        vbox_store(&right[c], acc);
    }
    acc = none;
    uint32_t n = 0;
#pragma GCC unroll 16
    for (int c = 0; c < nc; c++) {
        acc = vbox_grow(acc, vbox_load(&bins->box[c]));
        vbox_store(&left[c], acc);
        n += bins->count[c];
        nleft[c] = (int32_t)n;
    }
#pragma GCC unroll 8
    for (int c = nc; c < nc8; c++) {
        vbox_store(&left[c], none);
        vbox_store(&right[c], none);
        nleft[c] = 0; /* not a split */
    }
    __m256i all = _mm256_set1_epi32((int)total), zero = _mm256_setzero_si256();
#pragma GCC unroll 2
    for (int c = 0; c < nc; c += 8) {
        __m256i nl = _mm256_load_si256((const __m256i *)&nleft[c]);
        __m256i nr = _mm256_sub_epi32(all, nl);
        /* a split has primitives on both sides */
        __m256i no = _mm256_or_si256(_mm256_cmpeq_epi32(nl, zero), _mm256_cmpeq_epi32(nr, zero));
        int r = pick8(p, area8(&left[c]), _mm256_cvtepi32_ps(nl), area8(&right[c]), _mm256_cvtepi32_ps(nr),
                      _mm256_castsi256_ps(_mm256_xor_si256(no, _mm256_set1_epi32(-1))), parea, axis, best);
        int won = -(r < 8); /* all ones when best changed (no branch) */
        best->bin = (best->bin & ~won) | ((c + r) & won);
    }
#pragma GCC unroll 16
    for (int i = 0; i < nb; i++) {
        vbox_store(&bins->box[i], none);
        bins->count[i] = 0;
    }
}

static void sweep_axis8(const BvhParams *p, Bins *bins, int axis, uint32_t total, float parea, Split *best)
{
    if (p->bins == 16)
        sweep_bins8(p, bins, 16, axis, total, parea, best);
    else
        sweep_bins8(p, bins, p->bins, axis, total, parea, best);
}
#endif

/* The axis scale of the binning, or 0 when the axis gives no split: no extent, a denormal
 * extent (scale infinite: binning along it would be meaningless), or an infinite one (scale 0:
 * every centroid would fall in bin 0). */
static float bin_scale(const Box *cbox, int axis, int bins)
{
    float extent = box_hi(cbox, axis) - box_lo(cbox, axis);
    if (!(extent > 0.0f))
        return 0.0f;
    float scale = (float)bins / extent;
    return isfinite(scale) ? scale : 0.0f;
}

static inline void bin_put(Bins *bins, int i, const Box *q)
{
    box_grow(&bins->box[i], q);
    bins->count[i]++;
}

#if defined(__SSE2__)
/* bin_of on the three axes at once, lane by lane the same operations (subtract, multiply,
 * truncate, clamp). A lane whose scale is 0 gets bin 0, or, from an infinite centroid (NaN,
 * which cvttps turns into INT_MIN), the clamp's 0: defined here, where the scalar conversion
 * would not be, and never used. */
static inline __m128i bin_of3(__m128 c, __m128 cmin, __m128 scale, __m128i top)
{
    __m128i i = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, cmin), scale));
#if defined(__SSE4_1__)
    return _mm_min_epi32(_mm_max_epi32(i, _mm_setzero_si128()), top);
#else
    i = _mm_andnot_si128(_mm_cmpgt_epi32(_mm_setzero_si128(), i), i);
    __m128i big = _mm_cmpgt_epi32(i, top);
    return _mm_or_si128(_mm_and_si128(big, top), _mm_andnot_si128(big, i));
#endif
}

/* One pass puts every primitive in its bin on each axis; each bin still grows in primitive order.
 * An axis that gives no split bins into the sink. With sets > 1, primitive j goes to set j mod sets
 * (sets is a power of 2). */
/* Primitive j into bins d (one per axis) and its bin bytes into bin[j]. The primitive is loaded
 * once and the arrays are restrict: the bin stores could otherwise alias it and the Builder, which
 * were read again after each. */
static inline void bin_one(const Box *restrict prim, uint8_t (*restrict bin)[4], uint32_t j, Bins *const *d,
                           __m128 cmin, __m128 sc, __m128i top)
{
    Vbox q = vbox_load(&prim[j]);
    __m128 c = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(prim[j].v), _mm_load_ps(prim[j].v + 4)), _mm_set1_ps(0.5f));
    __m128i bi = bin_of3(c, cmin, sc, top);
    uint32_t i0 = (uint32_t)_mm_cvtsi128_si32(bi);
    uint32_t i1 = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(bi, 1));
    uint32_t i2 = (uint32_t)_mm_cvtsi128_si32(_mm_shuffle_epi32(bi, 2));
    /* the four lanes (0..255) as bytes */
    uint32_t packed = (uint32_t)_mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(bi, bi), bi));
    memcpy(bin[j], &packed, 4);
    vbox_store(&d[0]->box[i0], vbox_grow(vbox_load(&d[0]->box[i0]), q));
    d[0]->count[i0]++;
    vbox_store(&d[1]->box[i1], vbox_grow(vbox_load(&d[1]->box[i1]), q));
    d[1]->count[i1]++;
    vbox_store(&d[2]->box[i2], vbox_grow(vbox_load(&d[2]->box[i2]), q));
    d[2]->count[i2]++;
}

static void bin_prims(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, const float *scale, int live,
                      int sets)
{
    Bins *dst[BIN_SETS][3];
    for (int set = 0; set < sets; set++)
        for (int axis = 0; axis < 3; axis++)
            dst[set][axis] = &B->bins[live & 1 << axis ? 3 * set + axis : BIN_SINK];
    const Box *prim = B->prim;
    uint8_t(*bin)[4] = B->bin;
    __m128 cmin = _mm_setr_ps(box_lo(cbox, 0), box_lo(cbox, 1), box_lo(cbox, 2), 0.0f);
    __m128 sc = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
    __m128i top = _mm_set1_epi32(B->p->bins - 1);
    uint32_t j = begin;
    if (sets == BIN_SETS) {
        _Static_assert(BIN_SETS == 4, "the loop below is unrolled for 4 sets");
        for (; j + 4 <= end; j += 4) {
            bin_one(prim, bin, j, dst[0], cmin, sc, top);
            bin_one(prim, bin, j + 1, dst[1], cmin, sc, top);
            bin_one(prim, bin, j + 2, dst[2], cmin, sc, top);
            bin_one(prim, bin, j + 3, dst[3], cmin, sc, top);
        }
    }
    for (; j < end; j++)
        bin_one(prim, bin, j, dst[0], cmin, sc, top);
}
#else
static void bin_prims(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, const float *scale, int live,
                      int sets)
{
    (void)sets; /* one set: the sets exist to break the store-to-load chains of the vector loop */
    int nb = B->p->bins;
    for (uint32_t j = begin; j < end; j++) {
        for (int axis = 0; axis < 3; axis++) {
            if (live & 1 << axis) {
                int i = bin_of(centroid_of(&B->prim[j], axis), box_lo(cbox, axis), scale[axis], nb);
                B->bin[j][axis] = (uint8_t)i;
                bin_put(&B->bins[axis], i, &B->prim[j]);
            }
        }
    }
}
#endif

/* Grow bins `to` by bins `from` and empty `from` (an empty bin's box_none changes no box). */
static void merge_bins(Bins *restrict to, Bins *restrict from, int nb)
{
    for (int i = 0; i < nb; i++) {
        box_grow(&to->box[i], &from->box[i]);
        to->count[i] += from->count[i];
        from->box[i] = box_none;
        from->count[i] = 0;
    }
}

/* find_split of a node of at most SMALL_MAX primitives, without bin arrays: on each axis the
 * primitives are ranked by (bin, position), and the candidate splits are the ends of the runs of
 * one bin but the last, each with the left box grown over the ranks up to it and the right box
 * over the rest. These are the non-empty bins' unions, grown in another order, which can change
 * only the sign of a zero in a box and so no area (extent_of); the counts, the numerators x, the
 * costs and the order of the candidates (axis, then bin) are the sweep's, so the same split wins.
 * Fixed-size loops over SMALL_MAX ranks, the ranks past the node's own holding empty boxes, so
 * that no branch depends on the node: small nodes are most of the tree and their short
 * data-dependent loops were mispredicted. With AVX2 the seven candidates of an axis are costed
 * in the lanes of one vector and the best picked without a branch (area8, pick8). The chosen
 * axis's bins go to B->bin for partition. */
enum { SMALL_MAX = 8 };

static Split find_split_small(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, float parea)
{
    const BvhParams *p = B->p;
    int nb = p->bins;
    uint32_t k = end - begin;
    Split best = {-1, 0, INFINITY, INFINITY};
    float scale[3];
    int live = 0;
    for (int axis = 0; axis < 3; axis++) {
        scale[axis] = bin_scale(cbox, axis, nb);
        live |= (scale[axis] > 0.0f) << axis;
    }
    if (!live)
        return best;
    Box q[SMALL_MAX];
    uint8_t bins[SMALL_MAX][4] = {{0}};
#if defined(__SSE2__)
    __m128 cmin = _mm_setr_ps(box_lo(cbox, 0), box_lo(cbox, 1), box_lo(cbox, 2), 0.0f);
    __m128 sc = _mm_setr_ps(scale[0], scale[1], scale[2], 0.0f);
    __m128i top = _mm_set1_epi32(nb - 1);
#endif
#pragma GCC unroll 8
    for (uint32_t j = 0; j < SMALL_MAX; j++) {
        /* the ranks past k hold empty boxes, binned as primitive 0 (and ranked last below) */
        uint32_t in = (j - k) >> 31; /* j < k, without a branch */
        const Box *pj = &B->prim[begin + j * in];
        vbox_store(&q[j], vbox_select(in, vbox_load(pj), vbox_load(&box_none)));
#if defined(__SSE2__)
        __m128 c = _mm_mul_ps(_mm_sub_ps(_mm_load_ps(pj->v), _mm_load_ps(pj->v + 4)), _mm_set1_ps(0.5f));
        __m128i bi = bin_of3(c, cmin, sc, top);
        uint32_t packed = (uint32_t)_mm_cvtsi128_si32(_mm_packus_epi16(_mm_packs_epi32(bi, bi), bi));
        memcpy(bins[j], &packed, 4);
#else
        for (int axis = 0; axis < 3; axis++)
            if (live & 1 << axis)
                bins[j][axis] = (uint8_t)bin_of(centroid_of(pj, axis), box_lo(cbox, axis), scale[axis], nb);
#endif
    }
    for (int axis = 0; axis < 3; axis++) {
        if (!(live & 1 << axis))
            continue;
        /* distinct keys (bin, position), the empty boxes' above every bin; a rank is the number
         * of smaller keys */
        _Alignas(16) uint16_t key[SMALL_MAX];
#if defined(__AVX2__)
        __m256i iota = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        __m256i kb = _mm256_and_si256(_mm256_srl_epi32(_mm256_loadu_si256((const __m256i *)bins), _mm_cvtsi32_si128(8 * axis)),
                                      _mm256_set1_epi32(0xff));
        kb = _mm256_or_si256(kb, _mm256_and_si256(_mm256_cmpgt_epi32(iota, _mm256_set1_epi32((int)k - 1)), _mm256_set1_epi32(1 << 9)));
        kb = _mm256_or_si256(_mm256_slli_epi32(kb, 3), iota);
        _mm_store_si128((__m128i *)key, _mm_packs_epi32(_mm256_castsi256_si128(kb), _mm256_extracti128_si256(kb, 1)));
#else
#pragma GCC unroll 8
        for (uint32_t j = 0; j < SMALL_MAX; j++)
            key[j] = (uint16_t)(((uint32_t)bins[j][axis] | (uint32_t)(j >= k) << 9) << 3 | j);
#endif
        uint32_t sorted_bin[SMALL_MAX + 1];
        sorted_bin[SMALL_MAX] = 1u << 12; /* above every key's bin, for the vector compare */
        Vbox sorted[SMALL_MAX];
#if defined(__SSE2__)
        _Static_assert(SMALL_MAX == 8, "the ranks are taken in one 8 x 16-bit vector");
        __m128i keys;
        memcpy(&keys, key, sizeof keys);
#endif
#pragma GCC unroll 8
        for (uint32_t j = 0; j < SMALL_MAX; j++) {
#if defined(__SSE2__)
            /* keys < 2^12: the signed 16-bit compare is the unsigned one */
            __m128i less = _mm_cmplt_epi16(keys, _mm_set1_epi16((short)key[j]));
            uint32_t r = (uint32_t)__builtin_popcount((unsigned)_mm_movemask_epi8(less)) / 2;
#else
            uint32_t r = 0;
            for (uint32_t i = 0; i < SMALL_MAX; i++)
                r += key[i] < key[j];
#endif
            sorted_bin[r] = (uint32_t)key[j] >> 3;
            sorted[r] = vbox_load(&q[j]);
        }
#if defined(__AVX2__)
        /* candidate r: ranks 0 .. r left; lane by lane the operations below (area8, pick8) */
        _Alignas(32) Box lbox[SMALL_MAX], rbox[SMALL_MAX];
        Vbox left = vbox_load(&box_none), right = left;
        vbox_store(&rbox[SMALL_MAX - 1], right);
#pragma GCC unroll 8
        for (int r = 0; r < SMALL_MAX - 1; r++) {
            left = vbox_grow(left, sorted[r]);
            vbox_store(&lbox[r], left);
            right = vbox_grow(right, sorted[SMALL_MAX - 1 - r]);
            vbox_store(&rbox[SMALL_MAX - 2 - r], right);
        }
        vbox_store(&lbox[SMALL_MAX - 1], left);
        __m256i rank1 = _mm256_setr_epi32(1, 2, 3, 4, 5, 6, 7, 8);
        __m256i sb = _mm256_loadu_si256((const __m256i *)sorted_bin);
        __m256i sb_next = _mm256_loadu_si256((const __m256i *)(sorted_bin + 1));
        /* r + 1 < k, and the end of a run of one bin */
        __m256i ok = _mm256_and_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32((int)k), rank1), _mm256_cmpgt_epi32(sb_next, sb));
        sorted_bin[SMALL_MAX] = (uint32_t)best.bin; /* lane 8: best stays (the compare has read it) */
        int r = pick8(p, area8(lbox), _mm256_cvtepi32_ps(rank1), area8(rbox),
                      _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_set1_epi32((int)k), rank1)), _mm256_castsi256_ps(ok),
                      parea, axis, &best);
        best.bin = (int)sorted_bin[r];
#else
        float left_area[SMALL_MAX], right_area[SMALL_MAX];
        Vbox left = vbox_load(&box_none), right = left;
#pragma GCC unroll 8
        for (int r = 0; r < SMALL_MAX - 1; r++) {
            left = vbox_grow(left, sorted[r]);
            left_area[r] = vbox_area(left);
            right = vbox_grow(right, sorted[SMALL_MAX - 1 - r]);
            right_area[SMALL_MAX - 1 - r] = vbox_area(right);
        }
#pragma GCC unroll 8
        for (uint32_t r = 0; r + 1 < SMALL_MAX; r++) {
            float x = left_area[r] * (float)(r + 1) + right_area[r + 1] * (float)(k - (r + 1));
            /* best.x is not needed to skip divisions here: a candidate whose x is not below the
             * best's cannot cost less (see sweep_axis) */
            float cost = p->cost_traversal + p->cost_intersect * x / parea;
            int wins = (r + 1 < k) & (sorted_bin[r] < sorted_bin[r + 1]) & (cost < best.cost);
            best.axis = wins ? axis : best.axis;
            best.bin = wins ? (int)sorted_bin[r] : best.bin;
            best.cost = wins ? cost : best.cost;
            best.x = wins ? x : best.x;
        }
#endif
    }
    /* partition reads the bytes of the node's own positions; those past it are the next nodes',
     * which bin them again before they read them */
    if (begin + SMALL_MAX <= B->b->nprims)
        memcpy(B->bin[begin], bins, sizeof bins);
    else
        memcpy(B->bin[begin], bins, 4 * (size_t)k);
    return best;
}

static Split find_split(const Builder *B, uint32_t begin, uint32_t end, const Box *cbox, float parea)
{
    const BvhParams *p = B->p;
    int nb = p->bins;
    Split best = {-1, 0, INFINITY, INFINITY};
    float scale[3];
    int live = 0;
    for (int axis = 0; axis < 3; axis++) {
        scale[axis] = bin_scale(cbox, axis, nb);
        if (scale[axis] > 0.0f)
            live |= 1 << axis;
    }
    if (!live)
        return best;
#if defined(__SSE2__)
    int sets = end - begin >= BIN_SETS_FROM ? BIN_SETS : 1;
#else
    int sets = 1;
#endif
    bin_prims(B, begin, end, cbox, scale, live, sets);
    for (int set = 1; set < sets; set++)
        for (int axis = 0; axis < 3; axis++)
            if (live & 1 << axis)
                merge_bins(&B->bins[axis], &B->bins[3 * set + axis], nb);
    for (int axis = 0; axis < 3; axis++) {
        if (!(live & 1 << axis))
            continue;
#if defined(__AVX2__)
        if (end - begin < (uint32_t)1 << 31) {
            sweep_axis8(p, &B->bins[axis], axis, end - begin, parea, &best);
            continue;
        }
#endif
        sweep_axis(p, &B->bins[axis], axis, end - begin, parea, &best);
    }
    return best;
}

/* The children's boxes and centroid boxes, as a scan of each child's primitives in order gives. */
typedef struct Halves { Box box[2], cbox[2]; } Halves;

/* Partition [begin, end) so primitives whose bin <= split.bin come first; returns mid. The
 * halves' boxes are grown on the way: a left position is final once passed, in increasing order;
 * a right position once filled, in decreasing order (hence vbox_grow_backwards). */
static uint32_t partition(Builder *B, uint32_t begin, uint32_t end, Split s, Halves *h)
{
    Box *restrict prim = B->prim;
    uint32_t *restrict id = B->b->prim_index;
    const uint8_t(*restrict bins)[4] = B->bin;
    int axis = s.axis;
    Vbox none = vbox_load(&box_none);
    Vbox box0 = none, cbox0 = none, box1 = none, cbox1 = none;
    uint32_t i = begin, j = end;
    /* the primitive at i and its bin, kept in registers: after a swap it is the one just read
     * from j - 1, which is not read back from memory (nor its bin byte written to i: no one reads
     * it again) */
    Vbox q = vbox_load(&prim[i]);
    uint32_t qb = bins[i][axis];
    while (i < j) {
        Vbox cc = vbox_centroid(q);
        if (qb <= (uint32_t)s.bin) {
            box0 = vbox_grow(box0, q);
            cbox0 = vbox_grow(cbox0, cc);
            i++;
            uint32_t next = i < j ? i : i - 1; /* the read past the last is not used */
            q = vbox_load(&prim[next]);
            qb = bins[next][axis];
        } else {
            j--;
            Vbox r = vbox_load(&prim[j]);
            uint32_t rb = bins[j][axis];
            vbox_store(&prim[i], r);
            vbox_store(&prim[j], q);
            uint32_t qi = id[i];
            id[i] = id[j];
            id[j] = qi;
            box1 = vbox_grow_backwards(box1, q);
            cbox1 = vbox_grow_backwards(cbox1, cc);
            q = r;
            qb = rb;
        }
    }
    vbox_store(&h->box[0], box0);
    vbox_store(&h->box[1], box1);
    vbox_store(&h->cbox[0], cbox0);
    vbox_store(&h->cbox[1], cbox1);
    return i;
}

/* The box and centroid box of [begin, end), scanned in order. */
static void scan_bounds(const Box *prim, uint32_t begin, uint32_t end, Box *box, Box *cbox)
{
    Vbox b = vbox_load(&box_none), cb = b;
    for (uint32_t j = begin; j < end; j++) {
        Vbox q = vbox_load(&prim[j]);
        b = vbox_grow(b, q);
        cb = vbox_grow(cb, vbox_centroid(q));
    }
    vbox_store(box, b);
    vbox_store(cbox, cb);
}

static void set_box(BvhNode *n, const Box *b)
{
    for (int k = 0; k < 3; k++) {
        n->bmin[k] = box_lo(b, k);
        n->bmax[k] = box_hi(b, k);
    }
}

static void make_leaf(BvhNode *n, uint32_t begin, uint32_t end)
{
    n->first = begin;
    n->count = end - begin;
    n->axis = 0;
}

/* split_node of two primitives, without bins: what binning them would find. On an axis with a
 * split (bin_scale > 0: their centroids differ and the extent is finite, not denormal) the lower
 * centroid lands in bin 0 ((c - cmin) * scale = 0) and the other in the last bin (extent x
 * (bins / extent) rounds to within 2 ulp of bins >= 2, at least bins - 1 once truncated and
 * clamped). So each such axis has the one candidate split, at bin 0, whose numerator
 * area(lower) x 1 + area(upper) x 1 is the same sum on every axis (IEEE addition commutes):
 * only the first such axis can win, when the cost is finite; the partition puts the lower
 * centroid first, and the halves are the two primitives' own boxes. */
static uint32_t split_two(Builder *B, const Task *t, float parea, Halves *h, uint32_t *axis)
{
    const BvhParams *p = B->p;
    uint32_t i = t->begin;
    int a = 0;
    while (a < 3 && !(bin_scale(&t->cb, a, p->bins) > 0.0f))
        a++;
    float cost = INFINITY;
    if (a < 3) {
        float x = box_area(&B->prim[i]) * 1.0f + box_area(&B->prim[i + 1]) * 1.0f;
        if (x < INFINITY)
            cost = p->cost_traversal + p->cost_intersect * x / parea;
    }
    if (cost < INFINITY && (cost < p->cost_intersect * 2.0f || 2 > p->max_leaf_size)) {
        *axis = (uint32_t)a;
        if (centroid_of(&B->prim[i], a) > centroid_of(&B->prim[i + 1], a)) {
            Box q = B->prim[i];
            B->prim[i] = B->prim[i + 1];
            B->prim[i + 1] = q;
            uint32_t *id = B->b->prim_index, qi = id[i];
            id[i] = id[i + 1];
            id[i + 1] = qi;
        }
    } else if (!(cost < INFINITY) && 2 > p->max_leaf_size) {
        *axis = 0; /* all centroids coincide: halved by index */
    } else {
        return 0;
    }
    for (int k = 0; k < 2; k++) {
        Vbox q = vbox_load(&B->prim[i + (uint32_t)k]);
        vbox_store(&h->box[k], q);
        vbox_store(&h->cbox[k], vbox_centroid(q));
    }
    return i + 1;
}

/* Where node t with box nb splits: mid, or 0 for a leaf; the halves' bounds in h, the axis in
 * *axis. */
static uint32_t split_node(Builder *B, const Task *t, const Box *nb, Halves *h, uint32_t *axis)
{
    const BvhParams *p = B->p;
    uint32_t count = t->end - t->begin;
    *axis = 0;
    if (count < 2)
        return 0;
    if (count == 2) {
        float parea = box_area(nb);
        return split_two(B, t, parea > 0.0f ? parea : 1.0f, h, axis);
    }
    float parea = box_area(nb);
    parea = parea > 0.0f ? parea : 1.0f;
    Split s = count <= SMALL_MAX ? find_split_small(B, t->begin, t->end, &t->cb, parea)
                                 : find_split(B, t->begin, t->end, &t->cb, parea);
    float leaf_cost = p->cost_intersect * (float)count;
    if (s.axis >= 0 && (s.cost < leaf_cost || count > (uint32_t)p->max_leaf_size)) {
        *axis = (uint32_t)s.axis;
        return partition(B, t->begin, t->end, s, h);
    }
    if (s.axis < 0 && count > (uint32_t)p->max_leaf_size) {
        /* All centroids coincide: no box split can separate them; halve by index so leaves
         * stay within the size limit. */
        uint32_t mid = t->begin + count / 2;
        scan_bounds(B->prim, t->begin, mid, &h->box[0], &h->cbox[0]);
        scan_bounds(B->prim, mid, t->end, &h->box[1], &h->cbox[1]);
        return mid;
    }
    return 0;
}

/* The build's copy of the primitives: [lo, 0, -hi, 0] each, in prim_index order (the identity). */
static void load_prims(Builder *B, const float *bmin, const float *bmax, uint32_t n)
{
    uint32_t i = 0;
#if defined(__SSE2__)
    /* four floats read from 3i (the fourth is the next primitive's: the last primitive is left to
     * the loop below), lane 3 cleared, hi negated by its sign bit: the same values */
    __m128 keep = _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0));
    __m128 sign = _mm_castsi128_ps(_mm_setr_epi32(INT32_MIN, INT32_MIN, INT32_MIN, 0));
    for (; i + 1 < n; i++) {
        B->b->prim_index[i] = i;
        _mm_store_ps(B->prim[i].v, _mm_and_ps(_mm_loadu_ps(bmin + 3 * (size_t)i), keep));
        _mm_store_ps(B->prim[i].v + 4, _mm_and_ps(_mm_xor_ps(_mm_loadu_ps(bmax + 3 * (size_t)i), sign), keep));
    }
#endif
    for (; i < n; i++) {
        Box *q = &B->prim[i];
        B->b->prim_index[i] = i;
        for (int k = 0; k < 3; k++) {
            q->v[k] = bmin[3 * i + k];
            q->v[4 + k] = -bmax[3 * i + k];
        }
        q->v[3] = q->v[7] = 0.0f;
    }
    for (int a = 0; a <= BIN_SINK; a++) {
        for (int k = 0; k < 256; k++)
            B->bins[a].box[k] = box_none;
        memset(B->bins[a].count, 0, sizeof B->bins[a].count);
    }
}

/* Node t's box, read back from the node written when its parent was split. */
static void node_box(const BvhNode *n, Box *b)
{
    *b = box_none;
    for (int k = 0; k < 3; k++) {
        b->v[k] = n->bmin[k];
        b->v[4 + k] = -n->bmax[k];
    }
}

/* Split or close every node, depth first, left child first. */
static void build_nodes(Builder *B, Task *stack, uint32_t n)
{
    Bvh *out = B->b;
    Box root;
    uint32_t sp = 0;
    stack[sp] = (Task){box_none, 0, 0, n, 1};
    scan_bounds(B->prim, 0, n, &root, &stack[sp].cb);
    set_box(&out->nodes[0], &root);
    sp++;
    out->nnodes = 1;
    while (sp > 0) {
        Task t = stack[--sp];
        BvhNode *node = &out->nodes[t.node];
        if (t.depth > out->depth)
            out->depth = t.depth;
        Box nb;
        node_box(node, &nb);
        Halves h;
        uint32_t axis;
        uint32_t mid = split_node(B, &t, &nb, &h, &axis);
        if (mid == 0) {
            make_leaf(node, t.begin, t.end);
            out->nleaves++;
            continue;
        }
        uint32_t left = out->nnodes;
        out->nnodes += 2;
        node->first = left;
        node->count = 0;
        node->axis = axis;
        set_box(&out->nodes[left], &h.box[0]);
        set_box(&out->nodes[left + 1], &h.box[1]);
        stack[sp++] = (Task){h.cbox[1], left + 1, mid, t.end, t.depth + 1};
        stack[sp++] = (Task){h.cbox[0], left, t.begin, mid, t.depth + 1};
    }
}

void *bvh_big_alloc(size_t size)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const size_t huge = (size_t)2 << 20;
    if (size >= huge) {
        size_t rounded = (size + huge - 1) & ~(huge - 1);
        void *m = aligned_alloc(huge, rounded);
        if (m)
            madvise(m, rounded, MADV_HUGEPAGE);
        return m;
    }
#endif
    return aligned_alloc(32, (size + 31) & ~(size_t)31);
}

int bvh_build(const BvhParams *p, const float *bmin, const float *bmax, uint32_t n, Bvh *out,
              char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (bvh_check_input(p, bmin, bmax, n, err, errlen) != 0)
        return -1;
    out->nprims = n;
    if (n == 0)
        return 0;

    Builder B = {p, bvh_big_alloc(sizeof(Box) * n), aligned_alloc(32, sizeof(Bins) * (BIN_SINK + 1)), bvh_big_alloc(4 * (size_t)n), out};
    out->prim_index = bvh_big_alloc(sizeof(uint32_t) * n);
    out->nodes = bvh_big_alloc(sizeof(BvhNode) * (2 * (size_t)n - 1));
    /* Every task on the stack is the right sibling pending at a distinct depth of the path
     * being built, and a tree of n primitives has at most n levels. */
    Task *stack = aligned_alloc(32, sizeof(Task) * ((size_t)n + 1));
    if (!B.prim || !B.bins || !B.bin || !out->prim_index || !out->nodes || !stack) {
        snprintf(err, errlen, "bvh: out of memory for %u primitives", n);
        free(B.prim);
        free(B.bins);
        free(B.bin);
        free(stack);
        bvh_free(out);
        return -1;
    }
    load_prims(&B, bmin, bmax, n);
    build_nodes(&B, stack, n);
    free(stack);
    free(B.prim);
    free(B.bins);
    free(B.bin);
    out->sah_cost = bvh_sah_cost(out, p);
    return 0;
}

void bvh_free(Bvh *b)
{
    free(b->nodes);
    free(b->prim_index);
    memset(b, 0, sizeof *b);
}
