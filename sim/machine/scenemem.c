/* sim/machine/scenemem.c -- scene-memory timing: ports, cache tags, LRU, bus (see scenemem.h).
 *
 * Owns: what a scene or framebuffer access costs. Must not: charge stalls or hold data.
 */
#include "scenemem.h"

#include <stdlib.h>
#include <string.h>

#include "../timing.h"
#include "lines.h"

void mem_params(const CfgMachine *c, SceneMemParams *p)
{
    /* Assumptions (docs/model.md): a 64 KB 4-way cache of 64-byte lines suffices because a node
     * load serves a whole stream; DRAM at 500 MHz is 50 cycles away. */
    p->latency = c->scene_latency;
    p->bytes_per_cycle = c->scene_bytes_per_cycle;
    p->line_bytes = c->scene_line_bytes;
    p->hit_latency = c->scene_hit_latency;
    p->cache_bytes = c->scene_cache_kb * 1024;
    p->ways = c->scene_cache_ways;
    p->ports = c->scene_ports;
}

void mem_init(SceneMem *m, const SceneMemParams *p)
{
    memset(m, 0, sizeof *m);
    m->p = *p;
    int s = 0;
    while ((1 << s) < p->line_bytes)
        s++;
    m->line_shift = s;
    m->xfer = (p->line_bytes + p->bytes_per_cycle - 1) / p->bytes_per_cycle;
    m->sets = p->cache_bytes > 0 ? p->cache_bytes / (p->line_bytes * p->ways) : 0;
    m->set_mask = m->sets > 1 && (m->sets & (m->sets - 1)) == 0 ? (uint64_t)m->sets - 1 : 0;
}

void mem_free(SceneMem *m)
{
    free(m->tag);
    free(m->ready);
    free(m->lru);
    free(m->dirty);
    m->tag = m->ready = m->lru = NULL;
    m->dirty = NULL;
    m->instantiated = 0;
}

void mem_reset(SceneMem *m)
{
    if (m->instantiated) {
        size_t n = (size_t)m->sets * (size_t)m->p.ways;
        memset(m->tag, 0, n * sizeof *m->tag);
        memset(m->ready, 0, n * sizeof *m->ready);
        memset(m->lru, 0, n * sizeof *m->lru);
        memset(m->dirty, 0, n);
    }
    m->stamp = 0;
    m->bus_free = 0;
    m->last_way = 0;
}

static int instantiate(SceneMem *m)
{
    size_t n = (size_t)m->sets * (size_t)m->p.ways;
    m->tag = calloc(n, sizeof *m->tag);
    m->ready = calloc(n, sizeof *m->ready);
    m->lru = calloc(n, sizeof *m->lru);
    m->dirty = calloc(n, 1);
    if (!m->tag || !m->ready || !m->lru || !m->dirty) {
        mem_free(m);
        return -1;
    }
    m->instantiated = 1;
    return 0;
}

/* A line over the bus starting no earlier than t; returns when its data are there. */
static uint64_t bus_fill(SceneMem *m, uint64_t t)
{
    uint64_t s = t > m->bus_free ? t : m->bus_free;
    m->bus_free = s + (uint64_t)m->xfer;
    m->st.bus_bytes += (uint64_t)m->p.line_bytes;
    return s + (uint64_t)m->p.latency + (uint64_t)m->xfer;
}

/* A miss of line (in set) at cycle t: the least recently used way takes it. */
static uint64_t mem_miss(SceneMem *m, uint64_t line, size_t set, uint64_t t, int write)
{
    const size_t w = (size_t)m->p.ways;
    uint64_t *tag = m->tag + set * w;
    m->st.misses++;
    size_t victim = 0;
    for (size_t i = 1; i < w; i++)
        if (m->lru[set * w + i] < m->lru[set * w + victim])
            victim = i;
    size_t k = set * w + victim;
    if (tag[victim] && m->dirty[k]) { /* write the victim back: bus time, nobody waits */
        m->st.writebacks++;
        m->bus_free = (t > m->bus_free ? t : m->bus_free) + (uint64_t)m->xfer;
        m->st.bus_bytes += (uint64_t)m->p.line_bytes;
    }
    tag[victim] = line + 1;
    m->lru[k] = m->stamp;
    m->dirty[k] = (uint8_t)(write != 0);
    m->ready[k] = bus_fill(m, t);
    m->last_way = k;
    return m->ready[k];
}

uint64_t mem_access(SceneMem *m, int space, uint32_t addr, uint64_t t, int write)
{
    m->st.accesses++;
    if (m->sets == 0) { /* no cache: every access is a memory access */
        m->st.misses++;
        return bus_fill(m, t);
    }
    if (!m->instantiated && instantiate(m))
        return UINT64_MAX;
    uint64_t line = mem_line(m, space, addr);
    m->stamp++;
    /* The way the last hit or fill used first: a kernel reads a node's words one after another,
     * so it usually still holds this line (a line is in at most one way, so that is the hit the
     * search would find). */
    size_t k = m->last_way;
    if (m->tag[k] != line + 1) {
        const size_t set = (size_t)(m->set_mask ? line & m->set_mask : line % (uint64_t)m->sets);
        const size_t w = (size_t)m->p.ways;
        const uint64_t *tag = m->tag + set * w;
        size_t i = 0;
        while (i < w && tag[i] != line + 1)
            i++;
        if (i == w)
            return mem_miss(m, line, set, t, write);
        k = set * w + i;
        m->last_way = k;
    }
    m->st.hits++;
    m->lru[k] = m->stamp;
    if (write) /* a load leaves the line as it was */
        m->dirty[k] = 1;
    const uint64_t r = t + (uint64_t)m->p.hit_latency;
    return r > m->ready[k] ? r : m->ready[k];
}

int mem_peek(const SceneMem *m, int space, uint32_t addr, size_t *way)
{
    if (m->sets == 0 || !m->instantiated)
        return 0;
    const uint64_t line = mem_line(m, space, addr);
    if (m->tag[m->last_way] == line + 1) {
        *way = m->last_way;
        return 1;
    }
    const size_t set = (size_t)(m->set_mask ? line & m->set_mask : line % (uint64_t)m->sets);
    const size_t w = (size_t)m->p.ways;
    for (size_t i = 0; i < w; i++)
        if (m->tag[set * w + i] == line + 1) {
            *way = set * w + i;
            return 1;
        }
    return 0;
}

void mem_hits(SceneMem *m, size_t way, uint64_t n)
{
    m->st.accesses += n;
    m->st.hits += n;
    m->stamp += n;
    m->lru[way] = m->stamp;
    m->last_way = way;
}

/* mem_issue of more than one lane: each distinct line is one access. */
static __attribute__((noinline)) uint64_t mem_issue_lanes(SceneMem *m, int space, int write, const uint32_t *addr,
                                                          int naddr, uint64_t at, uint64_t *ready, TimingStats *st)
{
    uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
    for (int i = 0; i < naddr; i++)
        lines[i] = mem_line(m, space, addr[i]);
    int k = lines_distinct(lines, naddr, d);
    *ready = 0;
    uint64_t slot = at;
    for (int i = 0, in_slot = 0; i < k; i++) { /* one line per port-slot: slot = at + i / ports */
        if (in_slot == m->p.ports) {
            slot++;
            in_slot = 0;
        }
        in_slot++;
        uint32_t a = (uint32_t)((d[i] << m->line_shift) & 0xffffffffu);
        uint64_t r = mem_access(m, space, a, slot, write);
        if (r > *ready)
            *ready = r;
    }
    st->scene_instr++;
    return ((uint64_t)k + (uint64_t)m->p.ports - 1) / (uint64_t)m->p.ports;
}

uint64_t mem_issue(SceneMem *m, uint32_t flags, const uint32_t *addr, int naddr, uint64_t at, uint64_t *ready,
                   TimingStats *st)
{
    const int space = (flags & ISA_FL_FB) ? 1 : 0, write = (flags & ISA_FL_WRITE) != 0;
    if (naddr != 1)
        return mem_issue_lanes(m, space, write, addr, naddr, at, ready, st);
    /* a scalar access: one line, no search for distinct lines */
    *ready = mem_access(m, space, addr[0], at, write);
    st->scene_instr++;
    return 1;
}
