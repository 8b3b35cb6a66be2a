/* sim/machine/raybuf.c -- ray-buffer banks and bank conflicts (see raybuf.h; the model and its
 * sources: docs/model.md, "Ray buffers").
 *
 * Owns: the bank count of one access. Must not: charge stalls.
 */
#include "raybuf.h"

#include <stdlib.h>
#include <string.h>

#include "../timing.h"
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
    return rb->bank_cnt && rb->bank_stamp ? 0 : -1;
}

void rb_free(RayBufs *rb)
{
    free(rb->bank_cnt);
    free(rb->bank_stamp);
    rb->bank_cnt = NULL;
    rb->bank_stamp = NULL;
}

int rb_access(RayBufs *rb, const uint32_t *addr, int naddr, TimingStats *st)
{
    uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
    for (int i = 0; i < naddr; i++)
        lines[i] = addr[i] >> rb->shift;
    int k = lines_distinct(lines, naddr, d);
    if (++rb->stamp == 0) {
        memset(rb->bank_stamp, 0, (size_t)rb->p.banks * sizeof *rb->bank_stamp);
        rb->stamp = 1;
    }
    int worst = 0; /* lanes in one line share an access; lines of one bank serialize */
    for (int i = 0; i < k; i++) {
        uint32_t b = (uint32_t)(d[i] % (uint64_t)rb->p.banks);
        if (rb->bank_stamp[b] != rb->stamp) {
            rb->bank_stamp[b] = rb->stamp;
            rb->bank_cnt[b] = 0;
        }
        if (++rb->bank_cnt[b] > worst)
            worst = rb->bank_cnt[b];
    }
    st->rb_accesses++;
    st->rb_lines += (uint64_t)k;
    st->rb_conflicted += worst > 1;
    return worst;
}
