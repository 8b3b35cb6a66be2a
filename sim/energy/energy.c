/* sim/energy/energy.c -- energy, power and area of a run from its counters (sim/energy/energy.h;
 * docs/energy.md gives every rule written here and its reason).
 *
 * Owns: the figures of sim/energy/energy.def at the run's node, which counter feeds which part,
 * the derived counts, the sums by level, the areas and the figures of merit. Must not: count,
 * time, or run inside the timing loop.
 */
#include "energy.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "../chip/chip.h"
#include "sram.h"

#define KEY_ARRAY(name, key, desc) key,
const char *const energy_part_keys[EN_P_COUNT] = {ENERGY_PARTS(KEY_ARRAY)};
const char *const energy_level_keys[EN_L_COUNT] = {ENERGY_LEVELS(KEY_ARRAY)};
const char *const energy_dram_keys[EN_D_COUNT] = {ENERGY_DRAM_PARTS(KEY_ARRAY)};
const char *const energy_area_keys[EN_A_COUNT] = {ENERGY_AREAS(KEY_ARRAY)};
#undef KEY_ARRAY

/* The level each part belongs to. */
static const EnergyLevel part_level[EN_P_COUNT] = {
    [EN_P_FETCH] = EN_L_DATAPATH, [EN_P_REGFILE] = EN_L_REGISTERS, [EN_P_SIMD] = EN_L_DATAPATH,
    [EN_P_RAYBUF] = EN_L_LOCAL, [EN_P_IDM] = EN_L_LOCAL, [EN_P_AGU] = EN_L_DATAPATH,
    [EN_P_INTERCONNECT] = EN_L_DATAPATH, [EN_P_PARTITION] = EN_L_DATAPATH, [EN_P_SPAD] = EN_L_LOCAL,
    [EN_P_L1] = EN_L_L1, [EN_P_L2] = EN_L_L2, [EN_P_NOC] = EN_L_NOC, [EN_P_DRAM] = EN_L_DRAM,
    [EN_P_DRAM_IO] = EN_L_DRAM, [EN_P_VRF] = EN_L_REGISTERS, [EN_P_LOGIC] = EN_L_DATAPATH};

/* The figures at the run's node: pJ, mm^2, mW (SRAMs: per 64-byte access, whole arrays). */
typedef struct Figs {
    double add, mul, iadd, special, fetch, rf, wire, logic_leak_mw_mm2;
    double fadd_mm2, fmul_mm2, iadd_mm2;
    SramFig rb, idm, spad, l1, l2;   /* rb: one bank */
    double vrf_leak_mw, vrf_area_mm2;
} Figs;

/* A user's figure (at 45 nm, scaled) where the key is not 0. */
static void sram_keys(SramFig *s, double rd, double wr, double leak, double area, SramNodeScale ns)
{
    if (rd > 0)
        s->read_pj = rd * ns.dynamic;
    if (wr > 0)
        s->write_pj = wr * ns.dynamic;
    if (leak > 0)
        s->leak_mw = leak * ns.leakage;
    if (area > 0)
        s->area_mm2 = area * ns.area;
}

static int sram(int cache, double kib, int ways, int banks, double nm, SramFig *s, const char *what, char *err,
                size_t errlen)
{
    if (sram_figures(cache, kib, ways, banks, nm, s) == 0)
        return 0;
    snprintf(err, errlen, "energy: no CACTI 7 row for %s (%g KiB)", what, kib);
    return -1;
}

static int figs_resolve(const CfgMachine *c, Figs *g, char *err, size_t errlen)
{
    const double nm = c->energy_node_nm;
    const SramNodeScale ns = sram_node_scale(nm);
    memset(g, 0, sizeof *g);
    g->add = c->energy_fp32_add_pj * ns.dynamic;
    g->mul = c->energy_fp32_mul_pj * ns.dynamic;
    g->iadd = c->energy_int32_add_pj * ns.dynamic;
    g->special = c->energy_special_fmas * (g->add + g->mul);
    g->fetch = c->energy_fetch_pj * ns.dynamic;
    g->rf = c->energy_rf_word_pj * ns.dynamic;
    g->wire = c->energy_wire_pj_bit_mm * ns.dynamic;
    g->logic_leak_mw_mm2 = c->energy_logic_leak_mw_mm2 * ns.leakage / ns.area; /* per mm^2 of the scaled area */
    g->fadd_mm2 = c->energy_fp32_add_um2 * 1e-6 * ns.area;
    g->fmul_mm2 = c->energy_fp32_mul_um2 * 1e-6 * ns.area;
    g->iadd_mm2 = c->energy_int32_add_um2 * 1e-6 * ns.area;
    /* A ray-buffer bank is an array of its own: one line per bank per access (Gribble & Ramani
     * 2008, Sec. 3.3); the ID-stream memory, the scratchpad, the vector registers single arrays. */
    if (sram(0, (double)c->raybuf_size_kb / c->raybuf_banks, 1, 1, nm, &g->rb, "a ray-buffer bank", err, errlen) ||
        sram(0, c->idm_size_kb, 1, 1, nm, &g->idm, "the ID-stream memory", err, errlen) ||
        sram(0, c->spad_size_kb, 1, 1, nm, &g->spad, "the scratchpad", err, errlen))
        return -1;
    if (c->scene_cache_kb > 0 &&
        sram(1, c->scene_cache_kb, c->scene_cache_ways, 1, nm, &g->l1, "the scene cache", err, errlen))
        return -1;
    if (c->l2_size_kb > 0 && sram(1, c->l2_size_kb, c->l2_ways, c->l2_banks, nm, &g->l2, "the L2", err, errlen))
        return -1;
    sram_keys(&g->rb, c->energy_raybuf_read_pj, c->energy_raybuf_write_pj, c->energy_raybuf_leak_mw,
              c->energy_raybuf_area_mm2, ns);
    sram_keys(&g->idm, c->energy_idm_read_pj, c->energy_idm_write_pj, c->energy_idm_leak_mw, c->energy_idm_area_mm2, ns);
    sram_keys(&g->spad, c->energy_spad_read_pj, c->energy_spad_write_pj, c->energy_spad_leak_mw,
              c->energy_spad_area_mm2, ns);
    sram_keys(&g->l1, c->energy_l1_read_pj, c->energy_l1_write_pj, c->energy_l1_leak_mw, c->energy_l1_area_mm2, ns);
    sram_keys(&g->l2, c->energy_l2_read_pj, c->energy_l2_write_pj, c->energy_l2_leak_mw, c->energy_l2_area_mm2, ns);
    SramFig v;
    double vrf_kib = 32.0 * c->core_simd_width * 4 / 1024;   /* 32 registers of N 32-bit lanes */
    if (sram(0, vrf_kib, 1, 1, nm, &v, "the vector register file", err, errlen))
        return -1;
    g->vrf_leak_mw = c->energy_vrf_leak_mw > 0 ? c->energy_vrf_leak_mw * ns.leakage : v.leak_mw;
    g->vrf_area_mm2 = c->energy_vrf_area_mm2 > 0 ? c->energy_vrf_area_mm2 * ns.area : v.area_mm2;
    return 0;
}

/* Counts the run does not keep, derived from the executed instructions (by_op) and the ISA table. */
typedef struct Derived {
    double by_unit[ISA_U_COUNT];       /* executed instructions per unit class */
    double rf_words;                   /* 32-bit register words read and written */
    double rb_write_share, spad_write_share;   /* of a memory's instructions, the stores */
    double appends, spad_scalar;       /* ID-vector appends; scalar scratchpad accesses */
} Derived;

static void derive(const FuncStats *f, int lanes, Derived *d)
{
    double rb = 0, rbw = 0, sp = 0, spw = 0;
    memset(d, 0, sizeof *d);
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaOpInfo *in = &isa_ops[op];
        const double n = (double)f->core.by_op[op];
        if (n == 0)
            continue;
        d->by_unit[in->unit] += n;
        const IsaFormatInfo *fm = &isa_formats[in->format];
        int reg = 0;   /* the ACC column has a character per register operand, in order */
        for (int k = 0; k < fm->nops; k++) {
            IsaOperandKind kind = fm->ops[k].kind;
            if (kind == ISA_K_IMM || kind == ISA_K_LABEL)
                continue;
            char a = in->access[reg++];
            double words = (kind == ISA_K_V ? lanes : 1) * (a == ISA_ACC_RW ? 2 : 1);
            d->rf_words += n * words;
        }
        if (in->flags & ISA_FL_RB) {
            rb += n;
            rbw += (in->flags & ISA_FL_WRITE) ? n : 0;
        }
        if (in->flags & ISA_FL_SPAD) {
            sp += n;
            spw += (in->flags & ISA_FL_WRITE) ? n : 0;
            d->spad_scalar += (in->flags & ISA_FL_VEC) ? 0 : n;
        }
        if (isa_id_append(in->flags))
            d->appends += n;
    }
    d->rb_write_share = rb > 0 ? rbw / rb : 0;
    d->spad_write_share = sp > 0 ? spw / sp : 0;
}

/* pJ of one instruction's arithmetic per lane, by unit class (docs/energy.md, "Arithmetic"). */
static double unit_pj(const Figs *g, int unit)
{
    switch (unit) {
    case ISA_U_SALU: case ISA_U_VCMP: case ISA_U_VLOGIC: case ISA_U_VSEL: case ISA_U_MASK: case ISA_U_BRANCH:
        return g->iadd;
    case ISA_U_SFPU: case ISA_U_VFMA: return g->add + g->mul;
    case ISA_U_VADD: return g->add;
    case ISA_U_VMUL: return g->mul;
    case ISA_U_SSPEC: case ISA_U_VSPEC: return g->special;
    default: return 0;   /* memories and the AGU, partition units: their parts */
    }
}

static int unit_vector(int unit)
{
    return unit >= ISA_U_VADD && unit <= ISA_U_VSEL;
}

/* pJ of a line of `bytes` bytes, reads and writes mixed by share w, from a 64-byte access. */
static double line_pj(const SramFig *s, double w, int bytes)
{
    return ((1 - w) * s->read_pj + w * s->write_pj) * bytes / 64.0;
}

/* The half side of a square of area a (mm). */
static double half_side(double a) { return 0.5 * sqrt(a); }

static void core_events(const CfgMachine *c, const FuncStats *f, const Figs *g, const double *area, double *ev)
{
    const TimingStats *t = &f->timing;
    const int n = c->core_simd_width, line = c->raybuf_line_bytes;
    Derived d;
    derive(f, n, &d);
    double simd = 0;
    for (int u = 0; u < ISA_U_COUNT; u++)
        simd += d.by_unit[u] * unit_pj(g, u) * (unit_vector(u) ? n : 1);
    const double idv_lines = ceil(4.0 * n / line);   /* lines of one ID vector */
    const double icn_mm = c->energy_interconnect_mm > 0 ? c->energy_interconnect_mm : half_side(area[EN_A_RAYBUF]);
    ev[EN_P_FETCH] = (double)f->instructions * g->fetch;
    ev[EN_P_REGFILE] = d.rf_words * g->rf;
    ev[EN_P_SIMD] = simd;
    ev[EN_P_RAYBUF] = (double)t->rb.lines * line_pj(&g->rb, d.rb_write_share, line);
    ev[EN_P_IDM] = (double)t->agu.fetches * idv_lines * line_pj(&g->idm, 0, line) +
                   d.appends * idv_lines * line_pj(&g->idm, 1, line) +
                   (double)t->part.ids * 4.0 / line * (line_pj(&g->idm, 0, line) + line_pj(&g->idm, 1, line));
    ev[EN_P_AGU] = (double)t->agu.fetches * n * g->iadd;
    ev[EN_P_INTERCONNECT] = (double)t->xbar.transfers * n * 32.0 * g->wire * icn_mm;
    ev[EN_P_PARTITION] = (double)t->part.ids * g->iadd;
    ev[EN_P_SPAD] = ((double)t->spad.lines + d.spad_scalar) * line_pj(&g->spad, d.spad_write_share, c->spad_line_bytes);
    if (c->scene_cache_kb > 0) {
        const int sl = c->scene_line_bytes;
        ev[EN_P_L1] = (double)t->l1.accesses * line_pj(&g->l1, 0, sl) + (double)t->l1.misses * line_pj(&g->l1, 1, sl) +
                      (double)t->l1.writebacks * line_pj(&g->l1, 0, sl);
    }
}

/* The chip's shared levels: L2, network, DRAM (ev in pJ but the DRAM's, dram[] in J). */
static void chip_events(const CfgMachine *c, const FuncStats *f, const Figs *g, double seconds, double noc_mm,
                        double *ev, EnergyReport *r)
{
    const ChipMemStats *m = f->chip_mem;
    if (!m)
        return;
    const int sl = c->scene_line_bytes;
    if (m->has_l2)
        ev[EN_P_L2] = ((double)m->l2.reads + (double)m->l2.writebacks) * line_pj(&g->l2, 0, sl) +
                      ((double)m->l2.writes + (double)m->l2.fills) * line_pj(&g->l2, 1, sl);
    if (m->has_noc)
        ev[EN_P_NOC] = (double)m->noc.bytes * 8.0 * g->wire * noc_mm;
    DramParams p;
    char err[256];
    if (dram_params(c, &p, err, sizeof err) != 0)
        return;
    DramEnergy e;
    const double rank_cycles = (double)p.channels * p.ranks * seconds * p.clock_mhz * 1e6;
    dram_energy(&p, &m->dram, rank_cycles, &e);
    r->has_dram = 1;
    r->dram_known = e.known;
    r->dram[EN_D_ACTIVATE] = e.activate;
    r->dram[EN_D_READ] = e.read;
    r->dram[EN_D_WRITE] = e.write;
    r->dram[EN_D_REFRESH] = e.refresh;
    r->dram[EN_D_BG_ACTIVE] = e.background_active;
    r->dram[EN_D_BG_PRE] = e.background_precharged;
    r->dram[EN_D_IO] = e.io;
    r->dram_pj_per_bit = e.pj_per_bit;
}

static void areas(const CfgMachine *c, const Figs *g, double *a)
{
    const int n = c->core_simd_width;
    /* A lane: an adder (VADD), a multiplier (VMUL), an FMA and a special-function unit (each an
     * adder and a multiplier), compare, logic and select (an integer adder each); the scalar side:
     * an integer ALU, a float unit and a divide/sqrt unit (an FMA each). */
    const double fma = g->fadd_mm2 + g->fmul_mm2;
    a[EN_A_SIMD] = n * (g->fadd_mm2 + g->fmul_mm2 + 2 * fma + 3 * g->iadd_mm2) + g->iadd_mm2 + 2 * fma;
    a[EN_A_REGFILE] = g->vrf_area_mm2;
    a[EN_A_RAYBUF] = 2.0 * c->raybuf_banks * g->rb.area_mm2;
    a[EN_A_IDM] = g->idm.area_mm2;
    a[EN_A_SPAD] = g->spad.area_mm2;
    a[EN_A_L1] = c->scene_cache_kb > 0 ? g->l1.area_mm2 : 0;
    a[EN_A_CORE] = a[EN_A_SIMD] + a[EN_A_REGFILE] + a[EN_A_RAYBUF] + a[EN_A_IDM] + a[EN_A_SPAD] + a[EN_A_L1];
    a[EN_A_CORES] = c->chip_cores * a[EN_A_CORE];
    a[EN_A_L2] = c->chip_memory == CFG_CHIP_MEMORY_SHARED && c->l2_size_kb > 0 ? g->l2.area_mm2 : 0;
    a[EN_A_CHIP] = a[EN_A_CORES] + a[EN_A_L2];
}

/* Leakage power by part, W. */
static void leakage_w(const CfgMachine *c, const Figs *g, const double *a, double *w)
{
    const double k = c->chip_cores;
    w[EN_P_RAYBUF] = k * 2.0 * c->raybuf_banks * g->rb.leak_mw * 1e-3;
    w[EN_P_IDM] = k * g->idm.leak_mw * 1e-3;
    w[EN_P_SPAD] = k * g->spad.leak_mw * 1e-3;
    w[EN_P_L1] = c->scene_cache_kb > 0 ? k * g->l1.leak_mw * 1e-3 : 0;
    w[EN_P_L2] = a[EN_A_L2] > 0 ? g->l2.leak_mw * 1e-3 : 0;
    w[EN_P_VRF] = k * g->vrf_leak_mw * 1e-3;
    w[EN_P_LOGIC] = k * g->logic_leak_mw_mm2 * a[EN_A_SIMD] * 1e-3;
}

int energy_compute(const EnergyInput *in, EnergyReport *r, char *err, size_t errlen)
{
    const CfgMachine *c = in->cfg;
    Figs g;
    memset(r, 0, sizeof *r);
    if (figs_resolve(c, &g, err, errlen) != 0)
        return -1;
    areas(c, &g, r->area);
    double ev[EN_P_COUNT] = {0}, lw[EN_P_COUNT] = {0};
    core_events(c, in->f, &g, r->area, ev);
    const double noc_mm = c->energy_noc_mm > 0 ? c->energy_noc_mm : half_side(r->area[EN_A_CHIP]);
    chip_events(c, in->f, &g, in->seconds, noc_mm, ev, r);
    leakage_w(c, &g, r->area, lw);
    r->seconds = in->seconds;
    r->node_nm = c->energy_node_nm;
    for (int p = 0; p < EN_P_COUNT; p++) {
        r->events[p] = ev[p] * 1e-12 * in->scale;   /* pJ of the counted events, to the frame's J */
        r->leakage[p] = lw[p] * in->seconds;
        r->leakage_w += lw[p];
    }
    r->events[EN_P_DRAM] = r->dram[EN_D_ACTIVATE] + r->dram[EN_D_READ] + r->dram[EN_D_WRITE] +
                           r->dram[EN_D_REFRESH] + r->dram[EN_D_BG_ACTIVE] + r->dram[EN_D_BG_PRE];
    r->events[EN_P_DRAM_IO] = r->dram[EN_D_IO];
    for (int p = 0; p < EN_P_COUNT; p++) {
        r->events_j += r->events[p];
        r->leakage_j += r->leakage[p];
        r->level[part_level[p]] += r->events[p] + r->leakage[p];
    }
    r->total_j = r->events_j + r->leakage_j;
    r->average_w = in->seconds > 0 ? r->total_j / in->seconds : 0;
    r->mrays_per_j = r->total_j > 0 ? in->rays / r->total_j * 1e-6 : 0;
    r->fps_per_w = r->total_j > 0 ? 1.0 / r->total_j : 0;   /* fps / (J x fps) */
    r->fps_per_mm2 = in->seconds > 0 && r->area[EN_A_CHIP] > 0 ? 1.0 / in->seconds / r->area[EN_A_CHIP] : 0;
    /* Sampled mode: the events follow the instructions' bounds, the leakage the cycles'. */
    const double ev_scaled = r->events_j, per = in->scale > 0 ? ev_scaled / in->scale : 0;
    r->total_lo = in->scale_lo > 0 ? per * in->scale_lo + r->leakage_w * in->seconds_lo : r->total_j;
    r->total_hi = in->scale_hi > 0 ? per * in->scale_hi + r->leakage_w * in->seconds_hi : r->total_j;
    return 0;
}
