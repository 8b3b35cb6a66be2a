/* sim/mem/dram.c -- the DRAM's parameters: presets (dram_presets.def), the [dram] config keys over
 * them, the checks, the address mapping, and the latency histogram's buckets.
 *
 * Owns: turning a preset and keys into checked DramParams, with messages that name the key. Must
 * not: simulate (sim/mem/dram_sched.c), print, or exit.
 */
#include "dram.h"

#include <stdio.h>
#include <string.h>

typedef struct PresetRow {
    const char *name, *source;
    DramParams p;
} PresetRow;

static const PresetRow presets[DRAM_NPRESETS] = {
#define DRAM_PRESET(nm, mhz, bt, ch, ra, bg, ba, ro, co, wd, bus, bl, cl, cwl, trcd, trp, tras, trc, ccds, ccdl, \
                    rrds, rrdl, faw, twr, wtrs, wtrl, rtp, trefi, trfc, rtrs, rtw, map, src, vdd, idd0, idd2n,  \
                    idd3n, idd4r, idd4w, idd5b, psrc, io, iosrc)                                               \
    {#nm, src,                                                                                                   \
     {#nm, mhz, bt, ch, ra, bg, ba, ro, co, wd, bus, bl, cl, cwl, trcd, trp, tras, trc, ccds, ccdl, rrds, rrdl,   \
      faw, twr, wtrs, wtrl, rtp, trefi, trfc, rtrs, rtw, map, 0, 0, 0, 0, 0, 0, 0, {0}, {0}, 0, 0,               \
      {vdd, idd0, idd2n, idd3n, idd4r, idd4w, idd5b, psrc, io, iosrc}}},
#include "dram_presets.def"
#undef DRAM_PRESET
};

static const char *const field_names[DRAM_NFIELDS] = {"ch", "ra", "bg", "ba", "ro", "co"};

const char *dram_preset_name(DramPreset which)
{
    return which >= 0 && which < DRAM_NPRESETS ? presets[which].name : "?";
}

const char *dram_preset_source(DramPreset which)
{
    return which >= 0 && which < DRAM_NPRESETS ? presets[which].source : "?";
}

static int log2_exact(long long v)
{
    if (v <= 0 || (v & (v - 1)))
        return -1;
    int b = 0;
    while ((1LL << b) < v)
        b++;
    return b;
}

/* The mapping string into shifts and widths: each field once, comma-separated, most significant
 * first. */
static int parse_mapping(DramParams *p, const int bits[DRAM_NFIELDS], char *err, size_t errlen)
{
    const char *s = p->mapping;
    int order[DRAM_NFIELDS], n = 0, seen[DRAM_NFIELDS] = {0};
    while (*s) {
        const char *e = strchr(s, ',');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        int f = -1;
        for (int k = 0; k < DRAM_NFIELDS; k++)
            if (len == 2 && !strncmp(s, field_names[k], 2))
                f = k;
        if (f < 0) {
            snprintf(err, errlen, "key dram.mapping: '%.*s' in '%s' is not a field (ch, ra, bg, ba, ro, co)", (int)len,
                     s, p->mapping);
            return -1;
        }
        if (seen[f]++) {
            snprintf(err, errlen, "key dram.mapping: '%s' names %s twice", p->mapping, field_names[f]);
            return -1;
        }
        if (n < DRAM_NFIELDS)
            order[n++] = f;
        s = e ? e + 1 : s + len;
        if (e && !*s) {
            snprintf(err, errlen, "key dram.mapping: '%s' ends with a comma", p->mapping);
            return -1;
        }
    }
    for (int k = 0; k < DRAM_NFIELDS; k++)
        if (!seen[k]) {
            snprintf(err, errlen, "key dram.mapping: '%s' does not name %s (each of ch, ra, bg, ba, ro, co once)",
                     p->mapping, field_names[k]);
            return -1;
        }
    int shift = p->offset_bits;
    for (int i = DRAM_NFIELDS - 1; i >= 0; i--) {
        p->field_shift[order[i]] = shift;
        p->field_bits[order[i]] = bits[order[i]];
        shift += bits[order[i]];
    }
    p->addr_bits = shift;
    if (shift > 64) {
        snprintf(err, errlen, "key dram.mapping: the fields need %d address bits, more than 64", shift);
        return -1;
    }
    return 0;
}

/* One check: v in lo..hi, else a message naming the key. */
static int range(const char *key, long long v, long long lo, long long hi, char *err, size_t errlen)
{
    if (v < lo || v > hi) {
        snprintf(err, errlen, "key dram.%s: %lld is out of range %lld..%lld", key, v, lo, hi);
        return -1;
    }
    return 0;
}

static int pow2(const char *key, long long v, char *err, size_t errlen)
{
    if (log2_exact(v) < 0) {
        snprintf(err, errlen, "key dram.%s: %lld is not a power of two", key, v);
        return -1;
    }
    return 0;
}

static int check_org(const DramParams *p, char *err, size_t errlen)
{
    if (range("clock_mhz", p->clock_mhz, 1, 100000, err, errlen) || pow2("channels", p->channels, err, errlen) ||
        pow2("ranks", p->ranks, err, errlen) || pow2("bankgroups", p->bankgroups, err, errlen) ||
        pow2("banks", p->banks, err, errlen) || pow2("rows", p->rows, err, errlen) ||
        pow2("columns", p->columns, err, errlen) || pow2("bl", p->bl, err, errlen) ||
        pow2("beats", p->beats, err, errlen) || pow2("device_width", p->device_width, err, errlen) ||
        pow2("bus_bits", p->bus_bits, err, errlen))
        return -1;
    if (p->channels > 64 || p->ranks > 16 || p->bankgroups > 16 || p->banks > 64)
        return snprintf(err, errlen, "key dram.channels/ranks/bankgroups/banks: at most 64/16/16/64"), -1;
    if (p->bus_bits < 8 || p->bus_bits % p->device_width)
        return snprintf(err, errlen, "key dram.bus_bits: %d is not a multiple of the device width %d (and >= 8)",
                        p->bus_bits, p->device_width), -1;
    if (p->bl % p->beats)
        return snprintf(err, errlen, "key dram.bl: burst length %d is not a multiple of %d beats per clock", p->bl,
                        p->beats), -1;
    if (p->columns < p->bl)
        return snprintf(err, errlen, "key dram.columns: %d columns hold no burst of %d", p->columns, p->bl), -1;
    return 0;
}

static int check_timing(const DramParams *p, char *err, size_t errlen)
{
    static const char *const names[] = {"cl",     "cwl",    "trcd",   "trp",  "tras",  "trc",   "tccd_s",
                                        "tccd_l", "trrd_s", "trrd_l", "tfaw", "twr",   "twtr_s", "twtr_l",
                                        "trtp",   "trefi",  "trfc",   "trtrs", "trtw"};
    const int v[] = {p->cl,     p->cwl,   p->trcd, p->trp,    p->tras,   p->trc,  p->tccd_s,
                     p->tccd_l, p->trrd_s, p->trrd_l, p->tfaw, p->twr,   p->twtr_s, p->twtr_l,
                     p->trtp,   p->trefi, p->trfc, p->trtrs,  p->trtw};
    for (size_t i = 0; i < sizeof v / sizeof v[0]; i++)
        if (range(names[i], v[i], i >= 17 ? 0 : 1, 1000000, err, errlen))
            return -1;
    if (p->trc < p->tras + p->trp)
        return snprintf(err, errlen, "key dram.trc: %d is less than tRAS + tRP = %d", p->trc, p->tras + p->trp), -1;
    if (p->trefi <= p->trfc)
        return snprintf(err, errlen, "key dram.trefi: %d is not longer than tRFC %d", p->trefi, p->trfc), -1;
    return 0;
}

static int check_queues(const DramParams *p, char *err, size_t errlen)
{
    if (range("read_queue", p->read_queue, 1, 1024, err, errlen) ||
        range("write_queue", p->write_queue, 1, 1024, err, errlen) ||
        range("write_high", p->write_high, 1, p->write_queue, err, errlen) ||
        range("write_low", p->write_low, 0, p->write_high - 1, err, errlen) ||
        range("page_policy", p->page_policy, 0, 1, err, errlen))
        return -1;
    return 0;
}

int dram_params_check(DramParams *p, char *err, size_t errlen)
{
    if (check_org(p, err, errlen) || check_timing(p, err, errlen) || check_queues(p, err, errlen))
        return -1;
    p->burst_cycles = p->bl / p->beats;
    p->burst_bytes = p->bus_bits / 8 * p->bl;
    p->offset_bits = log2_exact(p->burst_bytes);
    const int bits[DRAM_NFIELDS] = {log2_exact(p->channels), log2_exact(p->ranks), log2_exact(p->bankgroups),
                                    log2_exact(p->banks),    log2_exact(p->rows),  log2_exact(p->columns / p->bl)};
    return parse_mapping(p, bits, err, errlen);
}

int dram_preset(DramPreset which, DramParams *p)
{
    char err[256];
    if (which < 0 || which >= DRAM_NPRESETS)
        return -1;
    *p = presets[which].p;
    p->page_policy = DRAM_PAGE_OPEN;
    p->read_queue = p->write_queue = 32; /* sim/config.def's defaults */
    p->write_high = 24;
    p->write_low = 8;
    return dram_params_check(p, err, sizeof err);
}

int dram_params(const CfgMachine *c, DramParams *p, char *err, size_t errlen)
{
    if (c->dram_preset < 0 || c->dram_preset >= DRAM_NPRESETS) {
        snprintf(err, errlen, "key dram.preset: %d is not a preset", (int)c->dram_preset);
        return -1;
    }
    *p = presets[c->dram_preset].p;
#define OVR(field) \
    if (c->dram_##field)  \
        p->field = c->dram_##field;
    OVR(channels) OVR(ranks) OVR(bankgroups) OVR(banks) OVR(rows) OVR(columns) OVR(clock_mhz)
    OVR(cl) OVR(cwl) OVR(trcd) OVR(trp) OVR(tras) OVR(trc) OVR(tccd_s) OVR(tccd_l) OVR(trrd_s) OVR(trrd_l)
    OVR(tfaw) OVR(twr) OVR(twtr_s) OVR(twtr_l) OVR(trtp) OVR(trefi) OVR(trfc) OVR(trtrs) OVR(trtw)
#undef OVR
#define OVRF(field) \
    if (c->dram_##field > 0) \
        p->power.field = c->dram_##field;
    OVRF(vdd) OVRF(idd0) OVRF(idd2n) OVRF(idd3n) OVRF(idd4r) OVRF(idd4w) OVRF(idd5b)
#undef OVRF
    if (c->energy_dram_io_pj_bit > 0) {
        p->power.io_pj_bit = c->energy_dram_io_pj_bit;
        p->power.io_source = "the key energy.dram_io_pj_bit";
    }
    if (c->dram_mapping > 0) {
        const char *m = cfg_enum_name("dram", "mapping", c->dram_mapping);
        if (!m) {
            snprintf(err, errlen, "key dram.mapping: %d is not a mapping", (int)c->dram_mapping);
            return -1;
        }
        snprintf(p->mapping, sizeof p->mapping, "%s", m);
    }
    p->page_policy = c->dram_page_policy;
    p->read_queue = c->dram_read_queue;
    p->write_queue = c->dram_write_queue;
    p->write_high = c->dram_write_high;
    p->write_low = c->dram_write_low;
    return dram_params_check(p, err, errlen);
}

DramAddr dram_decode(const DramParams *p, uint64_t addr)
{
    int v[DRAM_NFIELDS];
    for (int k = 0; k < DRAM_NFIELDS; k++) {
        int b = p->field_bits[k];
        v[k] = b ? (int)((addr >> p->field_shift[k]) & ((1ULL << b) - 1)) : 0;
    }
    return (DramAddr){v[DRAM_F_CH], v[DRAM_F_RA], v[DRAM_F_BG], v[DRAM_F_BA], v[DRAM_F_RO], v[DRAM_F_CO]};
}

int dram_hist_bucket(uint64_t lat)
{
    if (lat < DRAM_HIST_EXACT)
        return (int)lat;
    int oct = 63 - __builtin_clzll(lat); /* >= 10 */
    int sub = (int)((lat >> (oct - 5)) & (DRAM_HIST_SUB - 1));
    int b = DRAM_HIST_EXACT + (oct - 10) * DRAM_HIST_SUB + sub;
    return b < DRAM_HIST_BUCKETS ? b : DRAM_HIST_BUCKETS - 1;
}

uint64_t dram_hist_low(int b)
{
    if (b < DRAM_HIST_EXACT)
        return (uint64_t)b;
    int oct = (b - DRAM_HIST_EXACT) / DRAM_HIST_SUB + 10, sub = (b - DRAM_HIST_EXACT) % DRAM_HIST_SUB;
    return (1ULL << oct) + ((uint64_t)sub << (oct - 5));
}

uint64_t dram_hist_quantile(const uint64_t *h, double q)
{
    uint64_t n = 0;
    for (int b = 0; b < DRAM_HIST_BUCKETS; b++)
        n += h[b];
    if (!n)
        return 0;
    /* ceil(q n) in integers from q in per-million, so that no rounding of q x n decides a rank. */
    uint64_t qm = (uint64_t)(q * 1000000.0 + 0.5);
    uint64_t rank = (qm * n + 999999) / 1000000, cum = 0;
    if (rank < 1)
        rank = 1;
    for (int b = 0; b < DRAM_HIST_BUCKETS; b++) {
        cum += h[b];
        if (cum >= rank)
            return dram_hist_low(b);
    }
    return dram_hist_low(DRAM_HIST_BUCKETS - 1);
}
