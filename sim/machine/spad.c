/* sim/machine/spad.c -- scratchpad ports (see spad.h; the model and its sources: docs/model.md,
 * "Scratchpad").
 *
 * Owns: the port cycles of one access. Must not: charge stalls.
 */
#include "spad.h"

#include <string.h>

#include "lines.h"

void spad_params(const CfgMachine *c, SpadParams *p)
{
    p->ports = c->spad_ports; /* Gribble & Ramani 2008, Sec. 3.3: dual-ported */
    p->latency = c->spad_latency;
    p->line = c->spad_line_bytes;
}

int spad_init(Spad *s, const SpadParams *p)
{
    memset(s, 0, sizeof *s);
    s->p = *p;
    s->shift = lines_log2(p->line);
    return 0;
}

void spad_reset(Spad *s) { (void)s; }

void spad_free(Spad *s) { (void)s; }

uint64_t spad_access(Spad *s, const uint32_t *addr, int naddr)
{
    int k = 1; /* a scalar access (spld, spst): one line, no search */
    if (naddr > 1) {
        uint64_t lines[ISA_MAX_LANES], d[ISA_MAX_LANES];
        for (int i = 0; i < naddr; i++)
            lines[i] = addr[i] >> s->shift;
        k = lines_distinct(lines, naddr, d);
    }
    s->st.accesses++;
    s->st.lines += (uint64_t)k;
    return ((uint64_t)k + (uint64_t)s->p.ports - 1) / (uint64_t)s->p.ports;
}
