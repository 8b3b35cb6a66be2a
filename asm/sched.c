/* asm/sched.c -- the scheduling pass (see sched.h; the rules: docs/assembler.md, "Instruction
 * scheduling").
 *
 * Owns: basic blocks, the dependency graph of a block, the list scheduler and its estimate.
 * Must not: know a mnemonic (every rule comes from the ISA table's columns), include sim/, or
 * change a word, a label or the number of instructions.
 *
 * A block is cut before every label, branch target and SCHED_MARK_LEADER, after every branch and
 * end, around every SIDE instruction and SCHED_MARK_FIXED one, and every SCHED_WINDOW
 * instructions. Inside it an instruction depends on an earlier one when they share a register
 * (read after write and write after write: the later waits the earlier's latency; write after
 * read: order only), touch one memory and one of them writes it (unless both address base + imm
 * from the same value of the same base register and the ranges are apart), or are both of the
 * AGU or both of the PART class (their units keep state between instructions); a block's branch
 * stays last. The scheduler then issues, cycle by cycle, the ready instruction with the longest
 * latency-weighted path to the block's end (ties: the earlier one), or when none is ready the one
 * ready first; the new order is kept only when its estimate is shorter.
 */
#include "sched.h"

#include <stdlib.h>
#include <string.h>

/* Register numbers: r0..r31, v0..v31, m0..m7 in one space (as the timing model's scoreboard). */
enum { SREG = 0, VREG = ISA_NUM_SREGS, MREG = ISA_NUM_SREGS + ISA_NUM_VREGS,
       NREGS = ISA_NUM_SREGS + ISA_NUM_VREGS + ISA_NUM_MREGS };
/* Memories, by the FLAGS column; the two ray buffers are RBc and RBn (SIDE rswap ends blocks). */
enum { MEM_NONE = -1, MEM_RBC, MEM_RBN, MEM_IDM, MEM_SPAD, MEM_SCENE, MEM_FB };

typedef struct Node {
    uint8_t nrd, nwr;
    uint8_t rd[ISA_MAX_OPERANDS + 1], wr[ISA_MAX_OPERANDS];
    int8_t mem;            /* MEM_* */
    uint8_t mwrite;        /* writes mem */
    uint8_t known;         /* address = base register + imm, width bytes */
    uint8_t base;
    uint8_t unit;
    uint32_t imm, width, basever;
    int lat, issue;
    uint32_t flags;
} Node;

static const char *const unit_lower[ISA_U_COUNT] = {
#define U(name, desc) #name,
    ISA_UNITS(U)
#undef U
};

int sched_unit_from_name(const char *name)
{
    for (int u = 0; u < ISA_U_COUNT; u++) {
        const char *a = unit_lower[u], *b = name;
        while (*a && *b && (*a | 0x20) == *b)
            a++, b++;
        if (!*a && !*b)
            return u;
    }
    return -1;
}

void sched_model_default(AsmSchedModel *m)
{
    /* configs/streamray.ini (sim/config.def's defaults); tests/unit/test_sched.c checks that
     * sim/run/schedmodel.c fills the same from that file */
    memset(m, 0, sizeof *m);
    for (int u = 0; u < ISA_U_COUNT; u++)
        m->lat[u] = m->issue[u] = 1;
    m->lat[ISA_U_SFPU] = 2;
    m->lat[ISA_U_SSPEC] = 8;
    m->lat[ISA_U_VADD] = 2;
    m->lat[ISA_U_VMUL] = 3;
    m->lat[ISA_U_VFMA] = 4;
    m->lat[ISA_U_VSPEC] = 8;
    m->lat[ISA_U_RBUF] = 2 + 1; /* raybuf.access_cycles + interconnect.latency */
    m->lat[ISA_U_SPAD] = 2;
    m->lat[ISA_U_SCENE] = m->lat[ISA_U_FB] = 2; /* scene.hit_latency */
    m->issue[ISA_U_SSPEC] = 4;
    m->issue[ISA_U_VSPEC] = 2;
    m->idm_load = 2;
    m->lanes = 16;
}

static int field_of(const IsaInstr *in, int f)
{
    return f == ISA_FIELD_A ? in->a : f == ISA_FIELD_B ? in->b : f == ISA_FIELD_C ? in->c : in->d;
}

static int reg_id(int kind, int num)
{
    return kind == ISA_K_R ? SREG + num : kind == ISA_K_V ? VREG + num : MREG + num;
}

/* The memory an instruction touches, from its FLAGS, or MEM_NONE. */
static int mem_of(uint32_t fl)
{
    if (fl & ISA_FL_RB)
        return fl & ISA_FL_RBN ? MEM_RBN : MEM_RBC;
    if (fl & ISA_FL_IDM)
        return MEM_IDM;
    if (fl & ISA_FL_SPAD)
        return MEM_SPAD;
    if (fl & ISA_FL_SCENE)
        return MEM_SCENE;
    if (fl & ISA_FL_FB)
        return MEM_FB;
    return MEM_NONE;
}

/* The cycles until the result of an instruction of this row can be used. */
static int result_latency(const AsmSchedModel *m, const IsaOpInfo *oi)
{
    if (oi->unit == ISA_U_AGU && (oi->flags & ISA_FL_IDM)) /* ID fetch, append: by the next slot */
        return (oi->flags & (ISA_FL_VEC | ISA_FL_WRITE)) ? 1 : m->idm_load;
    return m->lat[oi->unit];
}

static void node_fill(Node *n, const IsaInstr *in, const AsmSchedModel *m)
{
    const IsaOpInfo *oi = &isa_ops[in->op];
    const IsaFormatInfo *fi = &isa_formats[oi->format];
    memset(n, 0, sizeof *n);
    int ri = 0, nscalar = 0, imm = 0;
    for (int i = 0; i < fi->nops; i++) {
        IsaOperandKind k = fi->ops[i].kind;
        if (k == ISA_K_IMM)
            imm = 1;
        if (k != ISA_K_R && k != ISA_K_V && k != ISA_K_M)
            continue;
        int r = reg_id(k, field_of(in, fi->ops[i].field));
        char acc = oi->access[ri++];
        if (acc == 'r' || acc == 'x')
            n->rd[n->nrd++] = (uint8_t)r;
        if (acc == 'w' || acc == 'x')
            n->wr[n->nwr++] = (uint8_t)r;
        nscalar += k == ISA_K_R && fi->ops[i].field == ISA_FIELD_B;
    }
    if (fi->masked)
        n->rd[n->nrd++] = (uint8_t)reg_id(ISA_K_M, in->mask);
    n->flags = oi->flags;
    n->unit = (uint8_t)oi->unit;
    n->mem = (int8_t)mem_of(oi->flags);
    n->mwrite = (oi->flags & ISA_FL_WRITE) != 0;
    /* base + imm addressing: a scalar base in field b and an immediate, no per-lane index (the
     * formats RRI and VRI); a vector access spans N words from there (at most: ldb reads one) */
    if (n->mem != MEM_NONE && imm && nscalar == 1 && (oi->format == ISA_F_RRI || oi->format == ISA_F_VRI)) {
        n->known = 1;
        n->base = (uint8_t)reg_id(ISA_K_R, in->b);
        n->imm = in->imm;
        n->width = (oi->flags & ISA_FL_VEC) ? 4u * (uint32_t)(m->lanes > 0 ? m->lanes : ISA_MAX_LANES) : 4u;
    }
    n->lat = result_latency(m, oi);
    n->issue = m->issue[oi->unit] > 1 ? m->issue[oi->unit] : 1;
}

/* Two base + imm accesses from the same value of one base register whose ranges are apart (the
 * distance taken both ways round 2^32, as the address arithmetic wraps). */
static int apart(const Node *x, const Node *y)
{
    if (!x->known || !y->known || x->base != y->base || x->basever != y->basever)
        return 0;
    uint32_t d = y->imm - x->imm;
    return d >= x->width && (uint32_t)(x->imm - y->imm) >= y->width;
}

/* ---- one region ------------------------------------------------------------------------------ */

typedef struct RdLink {
    int node, next;        /* a read of a register by node; the register's previous read */
} RdLink;

typedef struct Region {
    const AsmSchedModel *m;
    int n;
    RdLink *links;         /* n x (ISA_MAX_OPERANDS + 1) */
    int *memlist;          /* n */
    Node *node;            /* n */
    int16_t *lat;          /* n x n: the edge i -> j's latency, or -1 */
    int *height, *npred, *order, *ready;
} Region;

static void edge(Region *g, int i, int j, int lat)
{
    int16_t *e = &g->lat[i * g->n + j];
    if (*e < lat)
        *e = (int16_t)lat;
}

/* The dependencies of nodes 0..n-1, in program order (see the file's head): per register its last
 * writer and its readers since, per memory the instructions that touched it. */
static void build_edges(Region *g, int last_is_exit)
{
    int n = g->n, nlinks = 0, nmem = 0;
    int last_wr[NREGS], ver[NREGS], rd_head[NREGS], last_unit[ISA_U_COUNT];
    for (int r = 0; r < NREGS; r++)
        last_wr[r] = rd_head[r] = -1, ver[r] = 0;
    for (int u = 0; u < ISA_U_COUNT; u++)
        last_unit[u] = -1;
    memset(g->lat, 0xff, sizeof *g->lat * (size_t)n * (size_t)n);
    for (int j = 0; j < n; j++) {
        Node *b = &g->node[j];
        if (b->known)
            b->basever = (uint32_t)ver[b->base];
        for (int k = 0; k < b->nrd; k++) /* read after write */
            if (last_wr[b->rd[k]] >= 0)
                edge(g, last_wr[b->rd[k]], j, g->node[last_wr[b->rd[k]]].lat);
        for (int k = 0; k < b->nwr; k++) { /* write after read, write after write */
            int r = b->wr[k];
            for (int l = rd_head[r]; l >= 0; l = g->links[l].next)
                edge(g, g->links[l].node, j, 1);
            rd_head[r] = -1;
            if (last_wr[r] >= 0)
                edge(g, last_wr[r], j, g->node[last_wr[r]].lat);
        }
        for (int k = 0; k < b->nrd; k++) {
            g->links[nlinks] = (RdLink){j, rd_head[b->rd[k]]};
            rd_head[b->rd[k]] = nlinks++;
        }
        if (b->mem != MEM_NONE) {
            for (int q = 0; q < nmem; q++) {
                const Node *a = &g->node[g->memlist[q]];
                if (a->mem == b->mem && (a->mwrite || b->mwrite) && !apart(a, b))
                    edge(g, g->memlist[q], j, 1);
            }
            g->memlist[nmem++] = j;
        }
        if (b->unit == ISA_U_AGU || b->unit == ISA_U_PART) {
            if (last_unit[b->unit] >= 0)
                edge(g, last_unit[b->unit], j, 1);
            last_unit[b->unit] = j;
        }
        for (int k = 0; k < b->nwr; k++) {
            last_wr[b->wr[k]] = j;
            ver[b->wr[k]]++;
        }
    }
    if (last_is_exit) /* the branch or end stays last */
        for (int i = 0; i < n - 1; i++)
            edge(g, i, n - 1, 1);
}

/* The estimated cycles of nodes in order ord[0..n): in order, one a cycle, each when its sources,
 * exec mask and destinations have their results and its class is out of its issue interval; the
 * block ends when its last result lands. */
static int estimate(const Region *g, const int *ord)
{
    int ready[NREGS] = {0}, unit_free[ISA_U_COUNT] = {0}, t = 0, end = 0;
    for (int k = 0; k < g->n; k++) {
        const Node *x = &g->node[ord[k]];
        int at = t;
        for (int q = 0; q < x->nrd; q++)
            at = ready[x->rd[q]] > at ? ready[x->rd[q]] : at;
        for (int q = 0; q < x->nwr; q++)
            at = ready[x->wr[q]] > at ? ready[x->wr[q]] : at;
        at = unit_free[x->unit] > at ? unit_free[x->unit] : at;
        for (int q = 0; q < x->nwr; q++)
            ready[x->wr[q]] = at + x->lat;
        unit_free[x->unit] = at + x->issue;
        t = at + 1;
        end = end > t ? end : t;
        if (x->nwr && at + x->lat > end)
            end = at + x->lat;
    }
    return end;
}

/* Node j, which can issue at cycle at, before the best so far: ready now beats later; among the
 * ready, the longer path to the end; among the waiting, the earlier; then program order. */
static int better(const Region *g, int j, int at, int best, int best_at, int t)
{
    int now = at <= t, bnow = best_at <= t;
    if (now != bnow)
        return now;
    if (now || at == best_at)
        return g->height[j] > g->height[best];
    return at < best_at;
}

/* Heights (the longest latency-weighted path from a node to the region's end), the critical path
 * (the largest), then the list schedule into g->order. */
static int list_schedule(Region *g)
{
    int n = g->n, cp = 0;
    for (int i = n - 1; i >= 0; i--) {
        int h = g->node[i].nwr ? g->node[i].lat : 1;
        for (int j = i + 1; j < n; j++)
            if (g->lat[i * n + j] >= 0 && g->lat[i * n + j] + g->height[j] > h)
                h = g->lat[i * n + j] + g->height[j];
        g->height[i] = h;
        cp = h > cp ? h : cp;
    }
    for (int j = 0; j < n; j++) {
        g->npred[j] = 0;
        g->ready[j] = 0;
        for (int i = 0; i < j; i++)
            g->npred[j] += g->lat[i * n + j] >= 0;
    }
    int unit_free[ISA_U_COUNT] = {0}, t = 0;
    for (int k = 0; k < n; k++) {
        int best = -1, best_at = 0;
        for (int j = 0; j < n; j++) {
            if (g->npred[j] != 0)
                continue;
            int at = g->ready[j] > t ? g->ready[j] : t;
            at = unit_free[g->node[j].unit] > at ? unit_free[g->node[j].unit] : at;
            if (best < 0 || better(g, j, at, best, best_at, t))
                best = j, best_at = at;
        }
        g->order[k] = best;
        g->npred[best] = -1;
        const Node *x = &g->node[best];
        for (int j = best + 1; j < n; j++)
            if (g->lat[best * n + j] >= 0) {
                g->npred[j]--;
                int r = best_at + g->lat[best * n + j];
                g->ready[j] = r > g->ready[j] ? r : g->ready[j];
            }
        unit_free[x->unit] = best_at + x->issue;
        t = best_at + 1;
    }
    return cp;
}

/* ---- the program ----------------------------------------------------------------------------- */

typedef struct Pass {
    AsmObject *obj;
    const AsmSchedModel *m;
    FILE *report;
    SchedStats *st;
    IsaInstr *in;          /* decoded text */
    Region g;
    uint64_t *tmp_text;
    AsmLine *tmp_lines;
} Pass;

static void report_region(const Pass *p, uint32_t lo, uint32_t hi, int cp, int before, int after)
{
    const AsmObject *o = p->obj;
    char where[512] = "?";
    if (o->lines && o->lines[lo].file < o->nfiles)
        snprintf(where, sizeof where, "%s:%u", o->files[o->lines[lo].file], o->lines[lo].line);
    fprintf(p->report, "block %u-%u (%s): %u instructions, critical path %d, cycles %d -> %d\n", lo, hi - 1, where,
            hi - lo, cp, before, after);
}

/* Schedules text[lo, hi): a region with no label, target, branch or mark inside it. */
static void region(Pass *p, uint32_t lo, uint32_t hi)
{
    Region *g = &p->g;
    g->n = (int)(hi - lo);
    p->st->blocks++;
    for (int k = 0; k < g->n; k++)
        node_fill(&g->node[k], &p->in[lo + (uint32_t)k], p->m);
    if (g->n < 2) {
        int ord0 = 0, e = g->n ? estimate(g, &ord0) : 0;
        p->st->before += (uint64_t)e;
        p->st->after += (uint64_t)e;
        return;
    }
    uint32_t lastfl = isa_ops[p->in[hi - 1].op].flags;
    build_edges(g, (lastfl & (ISA_FL_BRANCH | ISA_FL_END)) != 0);
    int cp = list_schedule(g);
    int *ident = g->height; /* heights are spent: reuse for the source order */
    for (int k = 0; k < g->n; k++)
        ident[k] = k;
    int before = estimate(g, ident), after = estimate(g, g->order);
    if (after >= before) {
        after = before;
    } else {
        AsmObject *o = p->obj;
        p->st->reordered++;
        for (int k = 0; k < g->n; k++) {
            p->tmp_text[k] = o->text[lo + (uint32_t)g->order[k]];
            if (o->lines)
                p->tmp_lines[k] = o->lines[lo + (uint32_t)g->order[k]];
            p->st->moved += g->order[k] != k;
        }
        memcpy(o->text + lo, p->tmp_text, sizeof *o->text * (size_t)g->n);
        if (o->lines)
            memcpy(o->lines + lo, p->tmp_lines, sizeof *o->lines * (size_t)g->n);
    }
    p->st->before += (uint64_t)before;
    p->st->after += (uint64_t)after;
    if (p->report)
        report_region(p, lo, hi, cp, before, after);
}

/* starts[i]: a block starts at instruction i (i <= ntext). */
static void find_leaders(const Pass *p, const uint8_t *marks, uint8_t *starts)
{
    const AsmObject *o = p->obj;
    uint32_t n = o->ntext;
    starts[0] = 1;
    for (uint32_t s = 0; s < o->nsyms; s++)
        if (o->syms[s].section == ASM_SEC_TEXT && o->syms[s].value <= n)
            starts[o->syms[s].value] = 1;
    for (uint32_t i = 0; i < n; i++) {
        const IsaOpInfo *oi = &isa_ops[p->in[i].op];
        const IsaFormatInfo *fi = &isa_formats[oi->format];
        for (int k = 0; k < fi->nops; k++)
            if (fi->ops[k].kind == ISA_K_LABEL && p->in[i].imm <= n)
                starts[p->in[i].imm] = 1;
        if (oi->flags & (ISA_FL_BRANCH | ISA_FL_END | ISA_FL_SIDE))
            starts[i + 1] = 1;
        if ((oi->flags & ISA_FL_SIDE) || (marks && (marks[i] & SCHED_MARK_FIXED)))
            starts[i] = starts[i + 1] = 1;
        if (marks && (marks[i] & SCHED_MARK_LEADER))
            starts[i] = 1;
    }
}

static int pass_alloc(Pass *p)
{
    size_t w = SCHED_WINDOW, n = p->obj->ntext ? p->obj->ntext : 1;
    p->in = malloc(sizeof *p->in * n);
    p->g.node = malloc(sizeof *p->g.node * w);
    p->g.lat = malloc(sizeof *p->g.lat * w * w);
    p->g.height = malloc(sizeof(int) * w);
    p->g.npred = malloc(sizeof(int) * w);
    p->g.order = malloc(sizeof(int) * w);
    p->g.ready = malloc(sizeof(int) * w);
    p->g.links = malloc(sizeof *p->g.links * w * (ISA_MAX_OPERANDS + 1));
    p->g.memlist = malloc(sizeof(int) * w);
    p->tmp_text = malloc(sizeof *p->tmp_text * w);
    p->tmp_lines = malloc(sizeof *p->tmp_lines * w);
    return p->in && p->g.node && p->g.lat && p->g.height && p->g.npred && p->g.order && p->g.ready && p->g.links && p->g.memlist && p->tmp_text &&
                   p->tmp_lines
               ? 0
               : -1;
}

static void pass_free(Pass *p)
{
    free(p->in);
    free(p->g.node);
    free(p->g.lat);
    free(p->g.height);
    free(p->g.npred);
    free(p->g.order);
    free(p->g.ready);
    free(p->g.links);
    free(p->g.memlist);
    free(p->tmp_text);
    free(p->tmp_lines);
}

int sched_object(AsmObject *obj, const uint8_t *marks, const AsmSchedModel *m, FILE *report, SchedStats *st)
{
    SchedStats local;
    Pass p = {obj, m, report, st ? st : &local, NULL, {0}, NULL, NULL};
    memset(p.st, 0, sizeof *p.st);
    uint8_t *starts = calloc((size_t)obj->ntext + 1, 1);
    int rc = -1;
    if (!starts || pass_alloc(&p) != 0)
        goto done;
    for (uint32_t i = 0; i < obj->ntext; i++) {
        char err[128];
        if (isa_decode(obj->text[i], &p.in[i], err, sizeof err) != 0)
            goto done; /* an assembled word always decodes */
    }
    find_leaders(&p, marks, starts);
    for (uint32_t lo = 0; lo < obj->ntext;) {
        uint32_t hi = lo + 1;
        while (hi < obj->ntext && !starts[hi] && hi - lo < SCHED_WINDOW)
            hi++;
        region(&p, lo, hi);
        lo = hi;
    }
    if (report)
        fprintf(report, "total: %u blocks, %u reordered, %llu instructions moved, cycles %llu -> %llu "
                        "(estimates: each block once, every result of a block landed)\n",
                p.st->blocks, p.st->reordered, (unsigned long long)p.st->moved, (unsigned long long)p.st->before,
                (unsigned long long)p.st->after);
    rc = 0;
done:
    pass_free(&p);
    free(starts);
    return rc;
}
