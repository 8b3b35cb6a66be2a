/* sim/machine/raybuf.c -- ray-buffer banks and bank conflicts (see raybuf.h; the model and its
 * sources: docs/model.md, "Ray buffers").
 *
 * Owns: the bank count of one access. Must not: charge stalls.
 */
#include "raybuf.h"

#include <stdlib.h>
#include <string.h>
#if defined(__AVX512CD__) && defined(__AVX512VPOPCNTDQ__)
#include <immintrin.h>
#endif

#include "lines.h"

void rb_params(const CfgMachine *c, RbParams *p)
{
    /* Gribble & Ramani 2008, Sec. 3.3: 32 banks of 16 KB, two-cycle pipelined access. The
     * 64-byte line (16 words, one per lane at N = 16) is an assumption (docs/model.md). */
    p->banks = c->raybuf_banks;
    p->line = c->raybuf_line_bytes;
    p->access = c->raybuf_access_cycles;
    p->align_cycles = c->raybuf_align_cycles;
}

int rb_init(RayBufs *rb, const RbParams *p)
{
    memset(rb, 0, sizeof *rb);
    rb->p = *p;
    rb->shift = lines_log2(p->line);
    rb->bank_cnt = calloc((size_t)p->banks, sizeof *rb->bank_cnt);
    rb->bank_stamp = calloc((size_t)p->banks, sizeof *rb->bank_stamp);
    rb->bank_head = calloc((size_t)p->banks, sizeof *rb->bank_head);
    return rb->bank_cnt && rb->bank_stamp && rb->bank_head ? 0 : -1;
}

/* Nothing to make cold: the banks hold no state between accesses, and the last access kept
 * (rb_same_as_last) is a host-speed memo whose answer is the same from any state. */
void rb_reset(RayBufs *rb) { (void)rb; }

void rb_free(RayBufs *rb)
{
    free(rb->bank_cnt);
    free(rb->bank_stamp);
    free(rb->bank_head);
    rb->bank_cnt = NULL;
    rb->bank_stamp = NULL;
    rb->bank_head = NULL;
}

/* The common access first (71 % of the conference frame's gathers and scatters): lanes in
 * ascending ray-ID order, so their lines never go down, over a window of fewer lines than there
 * are banks. Lines in such a window fall in distinct banks, so no bank serves two and the access
 * takes one cycle; its distinct lines are where the line changes from one lane to the next. The
 * scan is branch-free, and a whole vector of N = 16 lanes is one block the compiler vectorizes.
 * Returns the distinct lines, or 0 when the access is not of that kind (then rb_access_bits or
 * rb_access_any). */
static inline int rb_ascending_lines(const RayBufs *rb, const uint32_t *addr, int naddr)
{
    const int s = rb->shift;
    uint32_t down = 0, changes = 0;
    if (naddr == 16) { /* two constant-count loops: lines, then neighbours compared */
        uint32_t l[17];
        for (int i = 0; i < 16; i++)
            l[i] = addr[i] >> s;
        l[16] = l[15];
        for (int i = 0; i < 16; i++) {
            down |= l[i + 1] < l[i];
            changes += l[i + 1] != l[i];
        }
    } else {
        for (int i = 1; i < naddr; i++) {
            const uint32_t a = addr[i - 1] >> s, b = addr[i] >> s;
            down |= b < a;
            changes += b != a;
        }
    }
    if (down || (addr[naddr - 1] >> s) - (addr[0] >> s) >= (uint32_t)rb->p.banks)
        return 0;
    return (int)changes + 1;
}

/* Any access, any bank count (rb_access_bits below takes the usual power-of-two counts up to 64):
 * each distinct line is found through its own bank's list of the lines seen so far
 * (usually empty or one long), so an access costs about one probe per lane rather than one per
 * pair of lines; the counts are those of the distinct lines, in any order. Returns the most lines
 * of one bank; *lines: the distinct lines. */
static int rb_access_any(RayBufs *rb, const uint32_t *addr, int naddr, int *lines)
{
    uint32_t line_of[ISA_MAX_LANES];
    int8_t next[ISA_MAX_LANES];
    if (++rb->stamp == 0) {
        memset(rb->bank_stamp, 0, (size_t)rb->p.banks * sizeof *rb->bank_stamp);
        rb->stamp = 1;
    }
    const uint32_t banks = (uint32_t)rb->p.banks;
    const int pow2 = (banks & (banks - 1)) == 0; /* the usual case: a mask, not a division */
    int k = 0, worst = 0; /* lanes in one line share an access; lines of one bank serialize */
    for (int i = 0; i < naddr; i++) {
        const uint32_t line = addr[i] >> rb->shift;
        if (k && line_of[k - 1] == line) /* the lane before's line: neighbouring IDs */
            continue;
        const uint32_t b = pow2 ? line & (banks - 1) : line % banks;
        if (rb->bank_stamp[b] != rb->stamp) {
            rb->bank_stamp[b] = rb->stamp;
            rb->bank_cnt[b] = 0;
            rb->bank_head[b] = -1;
        }
        int seen = 0;
        for (int e = rb->bank_head[b]; e >= 0; e = next[e])
            if (line_of[e] == line) {
                seen = 1;
                break;
            }
        if (seen)
            continue;
        line_of[k] = line;
        next[k] = rb->bank_head[b];
        rb->bank_head[b] = (int8_t)k;
        k++;
        if (++rb->bank_cnt[b] > worst)
            worst = rb->bank_cnt[b];
    }
    *lines = k;
    return worst;
}

/* Any access with a power-of-two count of at most 64 banks (the default 32): the banks holding a
 * line so far are bits of one word, each with its first line and its count in small arrays read
 * only where the bit is set (no clearing per access). A second, different line in a bank (a
 * conflict) is looked up among the access's few other such lines. The same counts as
 * rb_access_any. */
static int rb_access_bits(const RayBufs *rb, const uint32_t *addr, int naddr, int *lines)
{
    uint32_t first[64], more_line[ISA_MAX_LANES];
    uint8_t cnt[64];
    const uint32_t bmask = (uint32_t)rb->p.banks - 1u;
    uint64_t used = 0;
    int k = 0, worst = 1, nmore = 0;
    uint32_t prev = 0;
    for (int i = 0; i < naddr; i++) {
        const uint32_t line = addr[i] >> rb->shift;
        if (i && line == prev) /* the lane before's line: neighbouring IDs */
            continue;
        prev = line;
        const uint32_t b = line & bmask;
        const uint64_t bit = 1ull << b;
        if (!(used & bit)) {
            used |= bit;
            first[b] = line;
            cnt[b] = 1;
            k++;
            continue;
        }
        if (first[b] == line)
            continue;
        int seen = 0;
        for (int j = 0; j < nmore; j++)
            seen |= more_line[j] == line; /* (the same line: the same bank) */
        if (seen)
            continue;
        more_line[nmore++] = line;
        k++;
        if (++cnt[b] > worst)
            worst = cnt[b];
    }
    *lines = k;
    return worst;
}

/* rb_access_bits for N = 16 lanes, branch-free: a lane's line is new when no lower lane has it, and
 * a bank's count is that of the new lines in it (a lane's bank is its line's, so the most over all
 * lanes is the most over the banks). Each inner loop is one block of 16 comparisons the compiler
 * vectorizes; the branchy scan of rb_access_bits mispredicts on the random banks of a gather. */
static int rb_access_bits16(const RayBufs *rb, const uint32_t *addr, int *lines)
{
#if defined(__AVX512CD__) && defined(__AVX512VPOPCNTDQ__)
    /* The same counts from the host's conflict detection: each lane's mask of the lower lanes
     * with its line (none: a new line) and with its bank; a new line's count of the new lines up
     * to it in its bank, the highest over the new lines, is the busiest bank's. */
    const __m512i line = _mm512_srl_epi32(_mm512_loadu_si512((const void *)addr), _mm_cvtsi32_si128(rb->shift));
    const __mmask16 fresh = _mm512_cmpeq_epi32_mask(_mm512_conflict_epi32(line), _mm512_setzero_si512());
    const __m512i bank = _mm512_and_si512(line, _mm512_set1_epi32(rb->p.banks - 1));
    const __m512i below = _mm512_and_si512(_mm512_conflict_epi32(bank), _mm512_set1_epi32((int)fresh));
    *lines = __builtin_popcount(fresh);
    return (int)_mm512_mask_reduce_max_epu32(fresh, _mm512_popcnt_epi32(below)) + 1;
#else
    uint32_t line[16], bank[16], fresh[16];
    const uint32_t bmask = (uint32_t)rb->p.banks - 1u;
    for (int i = 0; i < 16; i++) {
        line[i] = addr[i] >> rb->shift;
        bank[i] = line[i] & bmask;
    }
    int k = 0;
    for (int i = 0; i < 16; i++) {
        uint32_t seen = 0;
        for (int j = 0; j < 16; j++)
            seen |= (uint32_t)(j < i) & (uint32_t)(line[j] == line[i]);
        fresh[i] = seen ^ 1u;
        k += (int)fresh[i];
    }
    uint32_t worst = 0;
    for (int i = 0; i < 16; i++) {
        uint32_t cnt = 0;
        for (int j = 0; j < 16; j++)
            cnt += fresh[j] & (uint32_t)(bank[j] == bank[i]);
        worst = cnt > worst ? cnt : worst;
    }
    *lines = k;
    return (int)worst;
#endif
}

/* Whether addr[0..naddr) is the last access's lanes moved by one whole number of lines (see
 * RayBufs.last_addr; the caller checks the bank count is a power of two). The lanes are compared
 * in one branch-free pass the compiler vectorizes. */
static inline int rb_same_as_last(const RayBufs *rb, const uint32_t *addr, int naddr)
{
    if (naddr != rb->last_n)
        return 0;
    const uint32_t d = addr[0] - rb->last_addr[0];
    if (d & (uint32_t)(rb->p.line - 1))
        return 0;
    uint32_t diff = 0;
    if (naddr == 16) { /* N = 16: a constant count, one vector block */
        for (int i = 0; i < 16; i++)
            diff |= (addr[i] - rb->last_addr[i]) ^ d;
    } else {
        for (int i = 0; i < naddr; i++)
            diff |= (addr[i] - rb->last_addr[i]) ^ d;
    }
    return diff == 0;
}

static inline void rb_note_last(RayBufs *rb, const uint32_t *addr, int naddr)
{
    if (naddr <= 16) /* a fixed 16 (the lanes past naddr are never compared): no call to memcpy */
        memcpy(rb->last_addr, addr, 16 * sizeof *addr);
    else
        memcpy(rb->last_addr, addr, sizeof *addr * (size_t)naddr);
    rb->last_n = naddr;
}

/* An access that is not the last one moved (rb_same_as_last): its lines and bank cycles worked
 * out into last_lines and last_cycles. Out of line: its 16-lane paths keep aligned vector arrays on
 * the stack, which the usual access (the last one moved, about 90 % of a kernel's) would set up
 * a frame for at every call. */
static __attribute__((noinline)) void rb_access_new(RayBufs *rb, const uint32_t *addr, int naddr, int pow2)
{
    int lines = rb_ascending_lines(rb, addr, naddr);
    const int cycles = lines                         ? 1
                       : pow2 && naddr == 16        ? rb_access_bits16(rb, addr, &lines)
                       : pow2 && rb->p.banks <= 64 ? rb_access_bits(rb, addr, naddr, &lines)
                                                   : rb_access_any(rb, addr, naddr, &lines);
    rb->last_cycles = cycles;
    rb->last_lines = lines;
}

int rb_cycles(RayBufs *rb, const uint32_t *addr, int naddr)
{
    const int pow2 = (rb->p.banks & (rb->p.banks - 1)) == 0;
    if (!(pow2 && rb_same_as_last(rb, addr, naddr)))
        rb_access_new(rb, addr, naddr, pow2);
    rb_note_last(rb, addr, naddr);
    return rb->last_cycles;
}

void rb_count(RayBufs *rb, uint64_t n)
{
    rb->st.accesses += n;
    rb->st.lines += n * (uint64_t)rb->last_lines;
    rb->st.conflicted += rb->last_cycles > 1 ? n : 0;
}

int rb_access(RayBufs *rb, const uint32_t *addr, int naddr)
{
    const int cycles = rb_cycles(rb, addr, naddr);
    rb_count(rb, 1);
    return cycles;
}
