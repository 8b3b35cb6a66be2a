/* sim/core_state.c -- the functional core's state: building a core from a program (decoding it
 * once), its simulated memories (anonymous mappings) and the shared scene images, restarting and
 * freeing it, its counters (folded into CoreStats when read) and its accessors (see core.h).
 *
 * Owns: the memory layout of a core and its counters. Must not: execute an instruction
 * (sim/core.c does), count cycles or model latency.
 */
#include "core_int.h"

#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

const char *const core_mem_names[CORE_MEM_COUNT] = {"rb0", "rb1", "idm", "spad", "scene", "fb"};
const char *const core_mem_long[CORE_MEM_COUNT] = {"ray buffer 0", "ray buffer 1", "ID-stream memory",
                                                   "scratchpad", "scene memory", "framebuffer"};

/* ---- counters -------------------------------------------------------------------------------- */

/* Point row at the current (stage, gen) and mark it as holding counts. */
void core_count_select_row(Core *c)
{
    uint32_t r = (uint32_t)c->stage * CORE_GENERATIONS + c->gen;
    c->row = c->counts + (size_t)r * COUNT_COLS;
    c->rec_hi = core_record_word(0, c->stage, c->gen);
    c->touched[r / 64] |= 1ull << (r % 64);
}

/* Add every touched row into st and clear it: the same sums the step used to add one by one. */
static void count_fold(Core *c)
{
    for (uint32_t r = 0; r < COUNT_ROWS; r++) {
        if (!((c->touched[r / 64] >> (r % 64)) & 1u))
            continue;
        const uint32_t stage = r / CORE_GENERATIONS, gen = r % CORE_GENERATIONS;
        uint64_t *row = c->counts + (size_t)r * COUNT_COLS;
        for (int op = 0; op < ISA_OP_COUNT; op++) {
            uint64_t k = row[op];
            if (!k)
                continue;
            const IsaOpInfo *oi = &isa_ops[op];
            c->st.instructions[stage] += k;
            c->st.ops[stage][oi->category] += k;
            c->st.by_op[op] += k;
            c->st.gen_instructions[gen][stage] += k;
            if (oi->flags & ISA_FL_VEC) {
                c->st.vec_instructions[stage] += k;
                c->st.gen_vec_instructions[gen][stage] += k;
            }
        }
        c->st.active_lanes[stage] += row[ISA_OP_COUNT];
        c->st.gen_active_lanes[gen][stage] += row[ISA_OP_COUNT];
        memset(row, 0, sizeof(uint64_t) * COUNT_COLS);
    }
    memset(c->touched, 0, sizeof c->touched);
    core_count_select_row(c);
}

/* ---- construction ---------------------------------------------------------------------------- */

/* The simulated memories are anonymous mappings, not calloc: the kernel zeroes a page when it is
 * first touched, so the 256 MiB scene memory, the ray buffers and the framebuffer cost a page
 * fault per page a run uses instead of a memset of all of them (calloc of a block under malloc's
 * mmap threshold, which grows past the ray buffers' size once one is freed, clears it in full),
 * and the scene memory can take a shared image's pages (core_load_image). */
static size_t page_bytes(void)
{
    long pg = sysconf(_SC_PAGESIZE);
    return pg > 0 ? (size_t)pg : 4096;
}

static size_t mem_span(uint32_t bytes)
{
    size_t pg = page_bytes(), n = bytes ? bytes : 4;
    return (n + pg - 1) / pg * pg;
}

static uint8_t *mem_alloc(uint32_t bytes)
{
    void *m = mmap(NULL, mem_span(bytes), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    return m == MAP_FAILED ? NULL : m;
}

static void mem_release(uint8_t *m, uint32_t bytes)
{
    if (m)
        munmap(m, mem_span(bytes));
}

/* ---- scene images ---------------------------------------------------------------------------- */

struct CoreImage {
    int fd;                   /* a sealed memfd holding the bytes (zero to the page's end), or -1 */
    const uint8_t *bytes;     /* the caller's bytes: the copy when there is no fd */
    uint32_t size;
};

CoreImage *core_image_new(const void *bytes, uint32_t size, int flags)
{
    CoreImage *im = calloc(1, sizeof *im);
    if (!im)
        return NULL;
    im->fd = -1;
    im->bytes = bytes;
    im->size = size;
#ifdef MFD_CLOEXEC
    if (!(flags & CORE_IMAGE_COPY) && size) {
        int fd = memfd_create("sfsim-scene", MFD_CLOEXEC | MFD_ALLOW_SEALING);
        size_t span = mem_span(size), done = 0;
        int ok = fd >= 0 && ftruncate(fd, (off_t)span) == 0;
        while (ok && done < size) {
            ssize_t w = pwrite(fd, (const uint8_t *)bytes + done, size - done, (off_t)done);
            ok = w > 0;
            done += ok ? (size_t)w : 0;
        }
        /* Sealed: nothing can change the image under the cores that map it. */
        if (ok && fcntl(fd, F_ADD_SEALS, F_SEAL_SHRINK | F_SEAL_GROW | F_SEAL_WRITE | F_SEAL_SEAL) != 0)
            ok = 0;
        if (ok)
            im->fd = fd;
        else if (fd >= 0)
            close(fd);
    }
#else
    (void)flags;
#endif
    return im;
}

void core_image_free(CoreImage *im)
{
    if (!im)
        return;
    if (im->fd >= 0)
        close(im->fd);
    free(im);
}

int core_image_shared(const CoreImage *im) { return im && im->fd >= 0; }

int core_load_image(Core *c, const CoreImage *im)
{
    uint32_t n = im->size;
    if (n > c->size[CORE_MEM_SCENE])
        return -1;
    uint8_t *sm = c->mem[CORE_MEM_SCENE];
    if (im->fd < 0 || !n) {
        if (n)
            memcpy(sm, im->bytes, n);
        return 0;
    }
    /* The image's pages replace the first span bytes of scene memory; the bytes of the last page
     * past n are put back as they were, so the result is that of the copy. */
    size_t span = mem_span(n), tail = span - n;
    uint8_t *keep = malloc(tail ? tail : 1);
    if (!keep)
        return -1;
    memcpy(keep, sm + n, tail);
    int rc = 0;
    if (mmap(sm, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_FIXED, im->fd, 0) == MAP_FAILED) {
        /* MAP_FIXED may have dropped the old pages: fresh zero pages and the copy. */
        if (mmap(sm, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_FIXED | MAP_ANONYMOUS, -1, 0) != MAP_FAILED)
            memcpy(sm, im->bytes, n);
        else
            rc = -1;
    }
    if (rc == 0 && tail && memcmp(sm + n, keep, tail) != 0)
        memcpy(sm + n, keep, tail);
    free(keep);
    return rc;
}

Core *core_new(const CoreParams *p, const AsmObject *obj, char *err, size_t errlen)
{
    if (p->lanes < 1 || p->lanes > ISA_MAX_LANES) {
        snprintf(err, errlen, "SIMD width %d out of range 1..%d", p->lanes, ISA_MAX_LANES);
        return NULL;
    }
    if (p->mem_bytes[CORE_MEM_RB0] != p->mem_bytes[CORE_MEM_RB1]) {
        snprintf(err, errlen, "the two ray buffers must have the same size (%u and %u bytes)",
                 p->mem_bytes[CORE_MEM_RB0], p->mem_bytes[CORE_MEM_RB1]);
        return NULL;
    }
    for (int m = 0; m < CORE_MEM_COUNT; m++) {
        if (p->mem_bytes[m] % 4 != 0) {
            snprintf(err, errlen, "%s size %u is not a multiple of 4 bytes", core_mem_long[m], p->mem_bytes[m]);
            return NULL;
        }
    }
    if (obj->ndata > p->mem_bytes[CORE_MEM_SCENE] || obj->nspad > p->mem_bytes[CORE_MEM_SPAD]) {
        snprintf(err, errlen, "program data does not fit: .data %u bytes (scene memory %u), .spad %u bytes (scratchpad %u)",
                 obj->ndata, p->mem_bytes[CORE_MEM_SCENE], obj->nspad, p->mem_bytes[CORE_MEM_SPAD]);
        return NULL;
    }
    Core *c = aligned_alloc(_Alignof(Core), sizeof *c); /* (sizeof is a multiple of the alignment) */
    if (c)
        memset(c, 0, sizeof *c);
    if (!c) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    core_set_follow(c, NULL);
    c->n = p->lanes;
    c->all = p->lanes == 64 ? ~0ull : (1ull << p->lanes) - 1;
    c->obj = obj;
    c->ncode = obj->ntext;
    c->code = calloc((size_t)obj->ntext + 1, sizeof(Dec)); /* + the end sentinel */
    int ok = c->code != NULL;
    for (int m = 0; ok && m < CORE_MEM_COUNT; m++) {
        c->size[m] = p->mem_bytes[m];
        c->last[m] = (int64_t)p->mem_bytes[m] - 4;
        c->mem[m] = mem_alloc(p->mem_bytes[m]);
        ok = c->mem[m] != NULL;
    }
    c->counts = ok ? calloc((size_t)COUNT_ROWS * COUNT_COLS, sizeof(uint64_t)) : NULL;
    ok = ok && c->counts;
    c->pq_cap = p->mem_bytes[CORE_MEM_IDM] / 4 + ISA_MAX_LANES;
    c->pq = ok ? malloc(c->pq_cap) : NULL;
    c->part_tmp = ok ? malloc(sizeof(uint32_t) * (p->mem_bytes[CORE_MEM_IDM] / 4 + 1)) : NULL;
    if (!ok || !c->pq || !c->part_tmp) {
        snprintf(err, errlen, "out of memory for the simulated memories");
        core_free(c);
        return NULL;
    }
    for (uint32_t i = 0; i < obj->ntext; i++) {
        char derr[256];
        if (isa_decode(obj->text[i], &c->code[i].in, derr, sizeof derr) != 0) {
            char where[256];
            asm_object_where(obj, i, where, sizeof where);
            snprintf(err, errlen, "instruction %u (%s): %s", i, where, derr);
            core_free(c);
            return NULL;
        }
        const IsaOpInfo *oi = &isa_ops[c->code[i].in.op];
        c->code[i].cat = (uint8_t)oi->category;
        c->code[i].vec = (oi->flags & ISA_FL_VEC) != 0;
        c->code[i].emask = isa_formats[oi->format].masked ? c->code[i].in.mask : CORE_MASK_ALL;
    }
    /* The sentinel after the last instruction: reaching it (pc == ncode: a fall-through or a
     * branch to the end) traps, so the run loop needs no bounds test of pc. */
    c->code[obj->ntext].in.op = ISA_OP_COUNT;
    if (obj->ndata)
        memcpy(c->mem[CORE_MEM_SCENE], obj->data, obj->ndata);
    if (obj->nspad)
        memcpy(c->mem[CORE_MEM_SPAD], obj->spad, obj->nspad);
    c->m[0] = c->all;
    c->m[CORE_MASK_ALL] = c->all;
    core_count_select_row(c);
    return c;
}

void core_restart(Core *c)
{
    memset(c->r, 0, sizeof c->r);
    memset(c->v, 0, sizeof c->v);
    memset(c->m, 0, sizeof c->m);
    c->m[0] = c->all;
    c->m[CORE_MASK_ALL] = c->all;
    c->pc = 0;
    c->stage = 0;
    c->gen = 0;
    c->cur_rb = 0;
    c->pq_len = 0;
    c->trap[0] = 0;
    core_count_select_row(c);
}

void core_free(Core *c)
{
    if (!c)
        return;
    for (int m = 0; m < CORE_MEM_COUNT; m++)
        mem_release(c->mem[m], c->size[m]);
    free(c->code);
    free(c->pq);
    free(c->part_tmp);
    free(c->counts);
    free(c);
}

void core_set_hook(Core *c, CoreHook hook, void *ctx)
{
    c->hook = hook;
    for (int op = 0; op < ISA_OP_COUNT; op++)
        c->hook_op[op] = hook;
    c->hook_ctx = ctx;
    core_set_follow(c, NULL);
}

void core_set_op_hook(Core *c, int op, CoreHook hook)
{
    if (c->hook && op >= 0 && op < ISA_OP_COUNT && hook)
        c->hook_op[op] = hook;
}

const CoreRecord *core_record(const Core *c) { return &c->rec; }

void core_set_follow(Core *c, CoreFollow *f)
{
    c->no_follow.where = CORE_FOLLOW_NONE;
    c->follow = f ? f : &c->no_follow;
}

int core_lanes(const Core *c) { return c->n; }
uint32_t core_pc(const Core *c) { return c->pc; }
uint32_t core_sreg(const Core *c, int r) { return c->r[r]; }
void core_set_sreg(Core *c, int r, uint32_t v) { c->r[r] = v; }
uint32_t core_vreg(const Core *c, int v, int lane) { return c->v[v].u[lane]; }
uint64_t core_mreg(const Core *c, int m) { return c->m[m]; }
int core_current_rb(const Core *c) { return c->cur_rb; }
const CoreStats *core_stats(Core *c)
{
    count_fold(c);
    return &c->st;
}
/* The instructions counted in st and in the rows not yet folded into it (the run loop keeps no
 * total of its own: one count an instruction fewer). */
uint64_t core_instructions(const Core *c)
{
    uint64_t n = 0;
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        n += c->st.instructions[s];
    for (uint32_t r = 0; r < COUNT_ROWS; r++)
        if ((c->touched[r / 64] >> (r % 64)) & 1u)
            for (int op = 0; op < ISA_OP_COUNT; op++)
                n += c->counts[(size_t)r * COUNT_COLS + (size_t)op];
    return n;
}

uint8_t *core_mem(Core *c, CoreMem m, uint32_t *bytes)
{
    if (bytes)
        *bytes = c->size[m];
    return c->mem[m];
}
