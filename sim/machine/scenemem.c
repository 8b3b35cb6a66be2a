/* sim/scenemem.c -- scene-memory timing: cache tags, LRU, bus (see scenemem.h). */
#include "scenemem.h"

#include <stdlib.h>
#include <string.h>

void smem_init(SceneMem *m, const SceneMemParams *p)
{
    memset(m, 0, sizeof *m);
    m->p = *p;
    int s = 0;
    while ((1 << s) < p->line_bytes)
        s++;
    m->line_shift = s;
    m->xfer = (p->line_bytes + p->bytes_per_cycle - 1) / p->bytes_per_cycle;
    m->sets = p->cache_bytes > 0 ? p->cache_bytes / (p->line_bytes * p->ways) : 0;
}

void smem_free(SceneMem *m)
{
    free(m->tag);
    free(m->ready);
    free(m->lru);
    free(m->dirty);
    m->tag = m->ready = m->lru = NULL;
    m->dirty = NULL;
    m->instantiated = 0;
}

void smem_reset(SceneMem *m)
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
}

static int instantiate(SceneMem *m)
{
    size_t n = (size_t)m->sets * (size_t)m->p.ways;
    m->tag = calloc(n, sizeof *m->tag);
    m->ready = calloc(n, sizeof *m->ready);
    m->lru = calloc(n, sizeof *m->lru);
    m->dirty = calloc(n, 1);
    if (!m->tag || !m->ready || !m->lru || !m->dirty) {
        smem_free(m);
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

uint64_t smem_access(SceneMem *m, int space, uint32_t addr, uint64_t t, int write)
{
    m->st.accesses++;
    if (m->sets == 0) { /* no cache: every access is a memory access */
        m->st.misses++;
        return bus_fill(m, t);
    }
    if (!m->instantiated && instantiate(m))
        return UINT64_MAX;
    uint64_t line = smem_line(m, space, addr);
    size_t set = (size_t)(line % (uint64_t)m->sets), w = (size_t)m->p.ways;
    uint64_t *tag = m->tag + set * w;
    m->stamp++;
    for (size_t i = 0; i < w; i++)
        if (tag[i] == line + 1) {
            size_t k = set * w + i;
            m->st.hits++;
            m->lru[k] = m->stamp;
            m->dirty[k] |= (uint8_t)(write != 0);
            uint64_t r = t + (uint64_t)m->p.hit_latency;
            return r > m->ready[k] ? r : m->ready[k];
        }
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
    return m->ready[k];
}
