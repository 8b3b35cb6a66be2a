/* sim/energy/sram.c -- the CACTI 7 table (sim/energy/cacti7.def), the row an array takes, and the
 * node rule (sim/energy/sram.h; docs/energy.md).
 *
 * Owns: the table's rows and the two rules written in sram.h. Must not: read the config, or know
 * the units of the machine.
 */
#include "sram.h"

#include <math.h>

typedef struct CactiRow {
    int cache, kib, ways, banks, nm;
    double access_ns, cycle_ns, read_pj, write_pj, leak_mw_per_bank, area_mm2;
} CactiRow;

static const CactiRow rows[] = {
#define CACTI_ROW(c, kib, ways, banks, nm, acc, cyc, rd, wr, leak, area) {c, kib, ways, banks, nm, acc, cyc, rd, wr, leak, area},
#include "cacti7.def"
#undef CACTI_ROW
};
#define NROWS ((int)(sizeof rows / sizeof rows[0]))

SramNodeExp sram_node_exponents(void)
{
    double sd = 0, sl = 0, sa = 0;
    int n = 0;
    const double lr = log(22.0 / 45.0);
    for (int i = 0; i < NROWS; i++) {
        if (rows[i].nm != 45)
            continue;
        for (int j = 0; j < NROWS; j++) {
            const CactiRow *a = &rows[i], *b = &rows[j];
            if (b->nm != 22 || b->cache != a->cache || b->kib != a->kib || b->ways != a->ways || b->banks != a->banks)
                continue;
            sd += log((b->read_pj + b->write_pj) / (a->read_pj + a->write_pj)) / lr;
            sl += log(b->leak_mw_per_bank / a->leak_mw_per_bank) / lr;
            sa += log(b->area_mm2 / a->area_mm2) / lr;
            n++;
        }
    }
    SramNodeExp e = {sd / n, sl / n, sa / n};
    return e;
}

SramNodeScale sram_node_scale(double node_nm)
{
    SramNodeExp e = sram_node_exponents();
    double r = node_nm / SRAM_REF_NM;
    SramNodeScale s = {pow(r, e.dynamic), pow(r, e.leakage), pow(r, e.area)};
    return s;
}

static int has_node(int cache, int nm)
{
    for (int i = 0; i < NROWS; i++)
        if (rows[i].cache == cache && rows[i].nm == nm)
            return 1;
    return 0;
}

/* Distance of a row from the array asked: size first, then banks, then ways (log2 ratios). */
static double distance(const CactiRow *r, double kib, int ways, int banks)
{
    double d = fabs(log2(kib / r->kib)) * 1e6 + fabs(log2((double)banks / r->banks)) * 1e3;
    if (r->cache)
        d += fabs(log2((double)ways / r->ways));
    return d;
}

int sram_figures(int cache, double kib, int ways, int banks, double node_nm, SramFig *out)
{
    if (!(kib > 0) || banks < 1 || ways < 1 || !(node_nm > 0))
        return -1;
    int nm = (node_nm == floor(node_nm) && has_node(cache, (int)node_nm)) ? (int)node_nm : 45;
    const CactiRow *best = NULL;
    double bd = 0;
    for (int i = 0; i < NROWS; i++) {
        if (rows[i].cache != !!cache || rows[i].nm != nm)
            continue;
        double d = distance(&rows[i], kib, ways, banks);
        if (!best || d < bd) {
            best = &rows[i];
            bd = d;
        }
    }
    if (!best)
        return -1;
    double s = kib / best->kib, e = sqrt(s);
    SramNodeScale ns = {1, 1, 1};
    if (nm != (int)node_nm || node_nm != floor(node_nm))
        ns = sram_node_scale(node_nm);
    out->read_pj = best->read_pj * e * ns.dynamic;
    out->write_pj = best->write_pj * e * ns.dynamic;
    out->leak_mw = best->leak_mw_per_bank * best->banks * s * ns.leakage;
    out->area_mm2 = best->area_mm2 * s * ns.area;
    out->row_cache = best->cache;
    out->row_kib = best->kib;
    out->row_ways = best->ways;
    out->row_banks = best->banks;
    out->row_nm = best->nm;
    out->size_factor = s;
    return 0;
}
