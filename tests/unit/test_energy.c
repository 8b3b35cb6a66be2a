/* tests/unit/test_energy.c -- the energy, power and area model (sim/energy/, docs/energy.md).
 *
 * What must hold: a run's every energy figure is what its own counters (report.json) give under
 * the table (sim/energy/energy.def's defaults and the CACTI 7 rows, written out here from
 * ../shared/data/cacti7-sram.tsv); the DRAM's energy of small hand-made `sfsim mem` traces is the
 * closed form of the IDD currents, written out in each case's comment; the magnitudes agree with
 * published figures; a bad figure is an error naming its key.
 *
 * Suites: energy_run, energy_dram, energy_magnitude, energy_keys.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../isa/isa.h"
#include "../../sim/cli/mem.h"
#include "../../sim/config.h"
#include "../../sim/energy/dramenergy.h"
#include "../../sim/energy/sram.h"
#include "../../sim/render.h"
#include "../../sim/run/run.h"
#include "../support/files.h"
#include "../support/report_run.h"

/* Equal to rounding: the same sum taken in another order. */
#define EXPECT_SAME(a, b, what) \
    cr_expect(fabs((a) - (b)) <= 1e-9 * fabs(b) + 1e-18, "%s: %.12g != %.12g", what, (double)(a), (double)(b))

static const cJSON *at(const cJSON *o, const char *path)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *save = NULL, *k = strtok_r(buf, ".", &save); k && o; k = strtok_r(NULL, ".", &save))
        o = cJSON_GetObjectItemCaseSensitive(o, k);
    return o;
}

static double num(const cJSON *root, const char *path)
{
    const cJSON *x = at(root, path);
    cr_assert(cJSON_IsNumber(x), "%s is not a number in report.json", path);
    return x->valuedouble;
}

/* render_run into a fresh folder; report.json parsed. */
static cJSON *run_report(RenderOptions *o) { return tu_run_report(o, "energy", NULL); }

/* ==== energy_run =================================================================================== */

/* The chip of the test: 2 cores of the default machine (N = 16, 512 KB ray buffers in 32 banks,
 * 32 KB ID streams, 64 KB scratchpad, 64 KB 4-way scene cache), a 1024 KB 16-way L2 in 8 banks, a
 * network of latency 4, DDR4-2400. At 45 nm every SRAM is a CACTI 7 row itself (cacti7-sram.tsv):
 *   ray-buffer bank 16 KB   ram   16  1  1 45: read 25.8, write 50.0 pJ, 19.0 mW, 0.071 mm^2
 *   ID streams      32 KB   ram   32  1  1 45: read 30.7, write 79.7 pJ, 37.4 mW, 0.115 mm^2
 *   scratchpad      64 KB   ram   64  1  1 45: read 40.4, write 139.1 pJ, 74.2 mW, 0.204 mm^2
 *   scene cache     64 KB   cache 64  4  1 45: read 107.3, write 114.5 pJ, 71.5 mW, 0.292 mm^2
 *   L2            1024 KB   cache 1024 16 8 45: read 1059.5, write 1063.9 pJ, 176.1 mW a bank, 14.760 mm^2
 *   vector registers 2 KB (32 x 16 x 4 B): the 16 KB ram row x 1/8: 19.0/8 mW, 0.071/8 mm^2 */
static void chip_config(CfgMachine *c)
{
    cfg_defaults(c);
    c->stream_rays = 1024;
    c->chip_cores = 2;
    c->chip_memory = CFG_CHIP_MEMORY_SHARED;
    c->l2_size_kb = 1024;
    c->l2_ways = 16;
    c->l2_banks = 8;
    c->noc_latency = 4;
}

/* Register words, arithmetic pJ and the write shares, from report.json's executions per mnemonic
 * and the ISA table (the rules of docs/energy.md, written again). */
typedef struct Ops { double instr, words, simd_pj, rb, rbw, sp, spw, spad_scalar, appends; } Ops;

static Ops ops_of(const cJSON *root, int n, double add, double mul, double iadd, double special)
{
    Ops o = {0};
    const cJSON *by = at(root, "by_opcode");
    cr_assert(cJSON_IsObject(by));
    for (int op = 0; op < ISA_OP_COUNT; op++) {
        const IsaOpInfo *in = &isa_ops[op];
        const cJSON *x = cJSON_GetObjectItemCaseSensitive(by, in->mnemonic);
        double k = cJSON_IsNumber(x) ? x->valuedouble : 0;
        o.instr += k;
        const IsaFormatInfo *f = &isa_formats[in->format];
        for (int i = 0, r = 0; i < f->nops; i++) {
            if (f->ops[i].kind == ISA_K_IMM || f->ops[i].kind == ISA_K_LABEL)
                continue;
            o.words += k * (f->ops[i].kind == ISA_K_V ? n : 1) * (in->access[r++] == 'x' ? 2 : 1);
        }
        double pj = 0;
        switch (in->unit) {
        case ISA_U_SALU: case ISA_U_MASK: case ISA_U_BRANCH: pj = iadd; break;
        case ISA_U_VCMP: case ISA_U_VLOGIC: case ISA_U_VSEL: pj = n * iadd; break;
        case ISA_U_SFPU: pj = add + mul; break;
        case ISA_U_VFMA: pj = n * (add + mul); break;
        case ISA_U_VADD: pj = n * add; break;
        case ISA_U_VMUL: pj = n * mul; break;
        case ISA_U_SSPEC: pj = special; break;
        case ISA_U_VSPEC: pj = n * special; break;
        default: break;
        }
        o.simd_pj += k * pj;
        int w = (in->flags & ISA_FL_WRITE) != 0;
        if (in->flags & ISA_FL_RB) {
            o.rb += k;
            o.rbw += w ? k : 0;
        }
        if (in->flags & ISA_FL_SPAD) {
            o.sp += k;
            o.spw += w ? k : 0;
            o.spad_scalar += (in->flags & ISA_FL_VEC) ? 0 : k;
        }
        if ((in->flags & (ISA_FL_VEC | ISA_FL_IDM | ISA_FL_WRITE)) == (ISA_FL_VEC | ISA_FL_IDM | ISA_FL_WRITE))
            o.appends += k;
    }
    return o;
}

static double part(const cJSON *root, const char *p, const char *kind)
{
    char path[128];
    snprintf(path, sizeof path, "energy.parts.%s.%s", p, kind);
    return num(root, path);
}

Test(energy_run, every_figure_recomputes_from_the_counters, .timeout = 300)
{
    CfgMachine cfg;
    chip_config(&cfg);
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.kernel_path = "kernels/pathtrace.s";
    o.mode = RUN_DETAILED;
    o.cfg = &cfg;
    o.width = 64;
    o.height = 64;
    o.spp = 1;
    o.threads = 2;
    cJSON *j = run_report(&o);
    const int n = 16, line = 64;
    /* Horowitz ISSCC 2014 at 45 nm (energy.def's defaults): pJ. */
    const double add = 0.9, mul = 3.7, iadd = 0.1, special = 4 * (add + mul), fetch = 25, rf = 2, wire = 0.121;
    Ops p = ops_of(j, n, add, mul, iadd, special);
    const double seconds = num(j, "cycles") / 500e6;
    cr_assert_gt(p.instr, 0);
    EXPECT_SAME(part(j, "fetch", "events_j"), p.instr * fetch * 1e-12, "fetch");
    EXPECT_SAME(part(j, "registers", "events_j"), p.words * rf * 1e-12, "registers");
    EXPECT_SAME(part(j, "simd", "events_j"), p.simd_pj * 1e-12, "simd");
    const double wrb = p.rbw / p.rb, wsp = p.spw / p.sp;
    EXPECT_SAME(part(j, "ray_buffers", "events_j"),
                num(j, "units.ray_buffers.lines") * ((1 - wrb) * 25.8 + wrb * 50.0) * 1e-12, "ray buffers");
    /* An ID vector of 16 IDs is one 64-byte line; the partition unit reads and writes 4 bytes an ID. */
    const double ids = num(j, "units.partition.ids"), fetches = num(j, "units.agu.id_vectors");
    EXPECT_SAME(part(j, "id_streams", "events_j"),
                (fetches * 30.7 + p.appends * 79.7 + ids * 4.0 / line * (30.7 + 79.7)) * 1e-12, "id streams");
    EXPECT_SAME(part(j, "agu", "events_j"), fetches * n * iadd * 1e-12, "agu");
    EXPECT_SAME(part(j, "partition", "events_j"), ids * iadd * 1e-12, "partition");
    EXPECT_SAME(part(j, "scratchpad", "events_j"),
                (num(j, "units.scratchpad.lines") + p.spad_scalar) * ((1 - wsp) * 40.4 + wsp * 139.1) * 1e-12, "spad");
    EXPECT_SAME(part(j, "l1", "events_j"),
                ((num(j, "units.scene_memory.line_accesses") + num(j, "units.scene_memory.writebacks")) * 107.3 +
                 num(j, "units.scene_memory.misses") * 114.5) * 1e-12, "l1");
    EXPECT_SAME(part(j, "l2", "events_j"),
                ((num(j, "l2.reads") + num(j, "l2.writebacks")) * 1059.5 + (num(j, "l2.writes") + num(j, "l2.fills")) * 1063.9) *
                    1e-12, "l2");
    /* Areas (mm^2): a lane is an adder, a multiplier, 2 FMAs (adder + multiplier) and 3 integer
     * adders; the scalar side an integer adder and 2 FMAs (Horowitz: 4184, 7700, 137 um^2). */
    const double fa = 4184e-6, fm = 7700e-6, ia = 137e-6;
    const double a_simd = n * (fa + fm + 2 * (fa + fm) + 3 * ia) + ia + 2 * (fa + fm);
    const double a_rb = 2 * 32 * 0.071, a_core = a_simd + 0.071 / 8 + a_rb + 0.115 + 0.204 + 0.292;
    const double a_chip = 2 * a_core + 14.760;
    EXPECT_SAME(num(j, "area.simd_mm2"), a_simd, "area simd");
    EXPECT_SAME(num(j, "area.core_mm2"), a_core, "area core");
    EXPECT_SAME(num(j, "area.chip_mm2"), a_chip, "area chip");
    /* Interconnect: N x 32 bits over half the side of the two ray buffers; network: over half the chip's. */
    EXPECT_SAME(part(j, "interconnect", "events_j"),
                num(j, "units.interconnect.data_path_transfers") * n * 32 * wire * 0.5 * sqrt(a_rb) * 1e-12, "icn");
    EXPECT_SAME(part(j, "noc", "events_j"), num(j, "noc.bytes") * 8 * wire * 0.5 * sqrt(a_chip) * 1e-12, "noc");
    /* Leakage, W, of 2 cores and the L2, over the frame. */
    /* and the SIMD datapath's logic, 17.80 mW per mm^2 of its area (Nangate 45 nm FA_X1: 75.762 nW
     * over 4.256 um^2; docs/energy.md). */
    const double leak_w = 2 * (2 * 32 * 19.0 + 37.4 + 74.2 + 71.5 + 19.0 / 8) * 1e-3 + 8 * 176.1 * 1e-3 +
                          2 * 17.80 * a_simd * 1e-3;
    EXPECT_SAME(num(j, "power.leakage_w"), leak_w, "leakage W");
    EXPECT_SAME(num(j, "energy.leakage_j"), leak_w * seconds, "leakage J");
    EXPECT_SAME(part(j, "ray_buffers", "leakage_j"), 2 * 2 * 32 * 19.0e-3 * seconds, "ray-buffer leakage");
    EXPECT_SAME(part(j, "logic", "leakage_j"), 2 * 17.80 * a_simd * 1e-3 * seconds, "logic leakage");
    /* DRAM (DDR4-2400: VDD 1.2 V, tCK 1/1.2 ns, 8 devices; docs/energy.md): pJ a command. */
    /* VDD x tCK = 1.2 V x 1/1.2 ns = 1: a rank's pJ are 8 x mA x CK cycles. */
    const double act = 8.0 * (48 * 55 - (43 * 39 + 34 * 16)), rd = 8.0 * (135 - 43) * 4,
                 wr = 8.0 * (123 - 43) * 4, ref = 8.0 * (250 - 43) * 420;
    const double rank_cycles = seconds * 1200e6, active = num(j, "dram.active_cycles") + num(j, "dram.refresh_cycles");
    EXPECT_SAME(num(j, "energy.dram.activate_j"), num(j, "dram.activates") * act * 1e-12, "dram act");
    EXPECT_SAME(num(j, "energy.dram.read_j"), num(j, "dram.reads") * rd * 1e-12, "dram rd");
    EXPECT_SAME(num(j, "energy.dram.write_j"), num(j, "dram.writes") * wr * 1e-12, "dram wr");
    EXPECT_SAME(num(j, "energy.dram.refresh_j"), num(j, "dram.refreshes") * ref * 1e-12, "dram ref");
    EXPECT_SAME(num(j, "energy.dram.background_active_j"), 43 * active * 8 * 1e-12, "dram active standby");
    EXPECT_SAME(num(j, "energy.dram.background_precharged_j"), 34 * (rank_cycles - active) * 8 * 1e-12, "dram pre");
    /* I/O, apart: DDR4-2400's 2.287 pJ per bit moved (docs/energy.md, "DRAM I/O"). */
    EXPECT_SAME(part(j, "dram_io", "events_j"), num(j, "dram.bytes") * 8 * 2.287e-12, "dram I/O");
    cr_expect_gt(num(j, "dram.reads"), 0, "the frame reaches DRAM");
    /* The sums and the figures of merit. */
    double ev = 0, lk = 0;
    const cJSON *parts = at(j, "energy.parts");
    for (const cJSON *x = parts ? parts->child : NULL; x; x = x->next) {
        ev += num(x, "events_j");
        lk += num(x, "leakage_j");
    }
    EXPECT_SAME(num(j, "energy.events_j"), ev, "events");
    EXPECT_SAME(num(j, "energy.total_j"), ev + lk, "total");
    EXPECT_SAME(num(j, "power.average_w"), (ev + lk) / seconds, "average W");
    EXPECT_SAME(num(j, "energy.mrays_per_j"), num(j, "rays.total") / (ev + lk) * 1e-6, "MRays/J");
    EXPECT_SAME(num(j, "energy.fps_per_w"), num(j, "fps") / num(j, "power.average_w"), "fps/W");
    EXPECT_SAME(num(j, "area.fps_per_mm2"), num(j, "fps") / a_chip, "fps/mm^2");
    cJSON_Delete(j);
}

/* Sampled mode: the events follow the estimated instructions, so the bounds hold the estimate. */
Test(energy_run, sampled_mode_has_an_interval, .timeout = 300)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    RenderOptions o;
    render_default_options(&o);
    o.scene_path = "scenes/cornell/scene.ini";
    o.kernel_path = "kernels/pathtrace.s";
    o.mode = RUN_SAMPLED;
    o.sample = 0.25;   /* 6 of 16 units: an interval of some width */
    o.target_error = 0;
    o.cfg = &cfg;
    o.width = 128;
    o.height = 128;
    o.spp = 1;
    o.threads = 2;
    cJSON *j = run_report(&o);
    const cJSON *b = at(j, "energy.total_j_ci95");
    cr_assert(cJSON_IsArray(b) && cJSON_GetArraySize(b) == 2);
    double lo = cJSON_GetArrayItem(b, 0)->valuedouble, hi = cJSON_GetArrayItem(b, 1)->valuedouble;
    double e = num(j, "energy.total_j");
    cr_expect(lo <= e && e <= hi && lo < hi, "%g <= %g <= %g", lo, e, hi);
    /* The fetch energy is the estimated instructions' (sample.instructions), not the sampled ones'. */
    EXPECT_SAME(num(j, "energy.parts.fetch.events_j"), num(j, "sample.instructions") * 25e-12, "fetch");
    cJSON_Delete(j);
}

/* ==== energy_dram: `sfsim mem` on hand-made traces ================================================== */

/* `sfsim mem` on the trace text (DRAMsim3's format) with extra arguments; report.json's "energy". */
static cJSON *mem_energy2(const char *trace, const char *set, const char *set2, cJSON **root)
{
    char dir[] = "/tmp/sfsim-energy-mem-XXXXXX", path[320], out[64];
    cr_assert_not_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/t.trc", dir);
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs(trace, f);
    fclose(f);
    snprintf(out, sizeof out, "%s/out", dir);
    char *argv[] = {"mem", "--trace", path, "-o", out, "--set", (char *)set, "--set", (char *)set2, NULL};
    int argc = set ? (set2 ? 9 : 7) : 5;
    FILE *saved = stdout;
    stdout = fopen("/dev/null", "w");
    int rc = cmd_mem(argc, argv);
    fclose(stdout);
    stdout = saved;
    cr_assert_eq(rc, 0);
    snprintf(path, sizeof path, "%s/report.json", out);
    char *json = tu_slurp(path);
    *root = cJSON_Parse(json);
    free(json);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    cr_assert_eq(system(cmd), 0);
    cr_assert_not_null(*root);
    return cJSON_GetObjectItemCaseSensitive(*root, "energy");
}
static cJSON *mem_energy(const char *trace, const char *set, cJSON **root)
{
    return mem_energy2(trace, set, NULL, root);
}

/* DDR4-2400 (Micron MT40A1G8 -083E: VDD 1.2 V, IDD0 48, IDD2N 34, IDD3N 43, IDD4R 135, IDD4W 123,
 * IDD5B 250 mA a device, 8 x8 devices a rank), tCK = 1/1.2 ns, so VDD x tCK = 1 V ns and a rank's
 * energy is 8 x (mA x CK cycles) pJ:
 *   ACT+PRE = 8 (IDD0 tRC - (IDD3N tRAS + IDD2N (tRC - tRAS))) = 8 (48 x 55 - (43 x 39 + 34 x 16)) = 3352 pJ
 *   RD      = 8 (IDD4R - IDD3N) x 4 (BL8 over 4 CK)            = 8 x 92 x 4  = 2944 pJ
 *   REF     = 8 (IDD5B - IDD3N) x tRFC 420                    = 8 x 207 x 420 = 695520 pJ
 *   a rank-cycle in active standby 8 x 43 = 344 pJ, precharged 8 x 34 = 272 pJ. */

/* One read to a closed bank, closed page: ACT at 0, RD at tRCD 16, data done at 16 + CL 16 + 4 =
 * 36, the replay spans cycles 0..36 (37 cycles); auto-precharge at tRAS = 39, after the span, so
 * the rank is active all 37 cycles: 3352 + 2944 + 37 x 344 = 19024 pJ over 512 bits. */
Test(energy_dram, a_read_to_a_closed_bank)
{
    cJSON *root;
    const cJSON *e = mem_energy("0x0 READ 0\n", "dram.page_policy=closed", &root);
    cr_expect_eq(num(root, "total.activates"), 1);
    cr_expect_eq(num(root, "total.precharges"), 1);
    cr_expect_eq(num(root, "total.cycles"), 37);
    EXPECT_SAME(num(e, "act_pre_pj"), 3352.0, "ACT+PRE");
    EXPECT_SAME(num(e, "read_burst_pj"), 2944.0, "RD");
    EXPECT_SAME(num(e, "total_j"), 19024e-12, "ACT + RD + PRE + standby");
    EXPECT_SAME(num(e, "pj_per_bit"), 19024.0 / 512, "pJ/bit");
    /* I/O apart, not in the total: the 512 bits of the burst x DDR4-2400's 2.287 pJ/bit. */
    EXPECT_SAME(num(e, "io_pj_per_bit"), 2.287, "I/O pJ/bit");
    EXPECT_SAME(num(e, "io_j"), 512 * 2.287e-12, "I/O");
    cJSON_Delete(root);
}

/* DDR4-2400's I/O figure is its termination (docs/energy.md, "DRAM I/O"): POD12, so a DQ pin draws
 * current only while low, through R_TT + R_s + R_ON = 120 + 10 + 34 = 164 ohm from VDDQ 1.2 V, on a
 * read (the controller's R_TT, the device's R_ON) as on a write (the device's R_TT(WR), the
 * controller's R_ON). Per low bit: 1.44 / 164 W x 1 / 2.4 ns = 3.6585 pJ; half the DQ bits are low,
 * and of each x8 device's strobe pair one pin is low all burst (1/8 of a low pin per DQ bit):
 *   3.6585 x (1/2 + 1/8) = 2.2866 pJ/bit, the preset's 2.287 to its 4 digits. */
Test(energy_dram, ddr4_io_is_its_termination)
{
    CfgMachine c;
    cfg_defaults(&c);
    DramParams p;
    char err[256];
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    const double per_low_bit_pj = 1.2 * 1.2 / (120 + 10 + 34) / 2.4 * 1e3;
    const double io = per_low_bit_pj * (0.5 + 1.0 / 8);
    cr_expect(fabs(p.power.io_pj_bit - io) < 5e-4, "preset %g, derived %g", p.power.io_pj_bit, io);
    cr_expect(p.power.io_source && strstr(p.power.io_source, "energydram"), "%s", p.power.io_source);
    /* The key stands for the preset's figure when given; a preset without a figure has 0 and says why. */
    c.energy_dram_io_pj_bit = 5;
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(p.power.io_pj_bit, 5);
    cr_expect(strstr(p.power.io_source, "energy.dram_io_pj_bit"), "%s", p.power.io_source);
    c.energy_dram_io_pj_bit = 0;
    c.dram_preset = DRAM_PRESET_gddr6_14000;
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    cr_expect_eq(p.power.io_pj_bit, 0);
    cr_expect(strstr(p.power.io_source, "none"), "%s", p.power.io_source);
    DramChanStats s = {.activates = 1, .reads = 1, .bytes = 128};
    DramEnergy e;
    dram_energy(&p, &s, 0, &e);
    cr_expect_eq(e.io, 0);
}

/* HBM2-2000's I/O figure is its DQ lines' switching (docs/energy.md, "DRAM I/O"): an unterminated
 * bus, so a line draws C V^2 from VDDQ on each rising edge and nothing while it holds. With random
 * data a bit is a rising edge one time in four (0 then 1), so per bit 1/4 x C_IO x VDDQ^2 =
 * 0.25 x 2.4 pF x 1.2^2 V^2 = 0.864 pJ, whatever the data rate; C_IO 2.4 pF is the HBM I/O
 * capacitance "up to 2.4 pF" quoted in the abstract of IEEE Xplore 9980680 (2022). The other presets
 * without a figure (DDR5, LPDDR5, GDDR6) keep 0 and say why. */
Test(energy_dram, hbm2_io_is_its_switched_capacitance)
{
    CfgMachine c;
    cfg_defaults(&c);
    c.dram_preset = DRAM_PRESET_hbm2_2000;
    DramParams p;
    char err[256];
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    const double c_io_pf = 2.4, vddq = 1.2, rising = 0.25;
    const double io = rising * c_io_pf * vddq * vddq;
    cr_expect(fabs(p.power.io_pj_bit - io) < 5e-4, "preset %g, derived %g", p.power.io_pj_bit, io);
    cr_expect(strstr(p.power.io_source, "9980680"), "%s", p.power.io_source);
    /* A burst's I/O is its bits times the figure, apart from the core's energy. */
    DramChanStats s = {.activates = 1, .reads = 1, .bytes = (uint64_t)p.burst_bytes};
    DramEnergy e;
    dram_energy(&p, &s, 0, &e);
    EXPECT_SAME(e.io, p.burst_bytes * 8 * io * 1e-12, "HBM2 burst I/O");
    const int none[] = {DRAM_PRESET_ddr5_4800, DRAM_PRESET_lpddr5_6400, DRAM_PRESET_gddr6_14000};
    for (int i = 0; i < 3; i++) {
        c.dram_preset = none[i];
        cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
        cr_expect_eq(p.power.io_pj_bit, 0, "preset %d", none[i]);
        cr_expect(strstr(p.power.io_source, "none"), "%s", p.power.io_source);
    }
}

/* A row hit: A (row 0, column 0) misses, B (row 0, column 1: address bit 8) hits: ACT 0, RD 16,
 * RD 22 (tCCD_L), B done 22 + 20 = 42; 43 cycles open: 3352 + 2 x 2944 + 43 x 344 = 24032 pJ. The
 * hit costs its burst and the 6 cycles it extends the span, nothing else. */
Test(energy_dram, a_row_hit)
{
    cJSON *root;
    const cJSON *e = mem_energy("0x0 READ 0\n0x100 READ 0\n", NULL, &root);
    cr_expect_eq(num(root, "total.activates"), 1);
    cr_expect_eq(num(root, "total.row_hits"), 1);
    cr_expect_eq(num(root, "total.cycles"), 43);
    EXPECT_SAME(num(e, "total_j"), 24032e-12, "ACT + 2 RD + standby");
    cJSON_Delete(root);
}

/* A refresh: a read at 0 and one at 9400, past tREFI 9360: one REF of 695520 pJ, and the rest
 * from the report's own counters: E = ACTs x 3352 + RDs x 2944 + REFs x 695520 + 344 (active +
 * refreshing cycles) + 272 (the other cycles). */
Test(energy_dram, a_refresh)
{
    cJSON *root;
    const cJSON *e = mem_energy("0x0 READ 0\n0x0 READ 9400\n", NULL, &root);
    cr_expect_eq(num(root, "total.refreshes"), 1);
    EXPECT_SAME(num(e, "refresh_pj"), 695520.0, "REF");
    double cyc = num(root, "total.cycles"), act = num(root, "total.active_cycles") + num(root, "total.refresh_cycles");
    cr_expect_eq(num(root, "total.refresh_cycles"), 420);
    double pj = num(root, "total.activates") * 3352 + num(root, "total.reads") * 2944 + 695520 + 344 * act + 272 * (cyc - act);
    EXPECT_SAME(num(e, "total_j"), pj * 1e-12, "with a refresh");
    EXPECT_SAME(num(e, "refresh_j"), 695520e-12, "refresh");
    cJSON_Delete(root);
}

/* LPDDR5-6400 (Micron MT62F LPDDR5 data sheet, Table 7, VDD2H column at 6400 Mb/s: VDD 1.05 V,
 * IDD0 45, IDD2N 30, IDD3N 39, IDD4R 372, IDD5B 170 mA; one x16 device a channel), tCK 1.25 ns, so
 * VDD x tCK = 1.3125 V ns:
 *   ACT+PRE = 1.3125 (45 x 49 - (39 x 34 + 30 x 15)) = 1.3125 x 429      = 563.0625 pJ
 *   RD      = 1.3125 (372 - 39) x 2 (BL16 over 2 CK, WCK 4:1 DDR)        = 874.125 pJ
 * One read to a closed bank, closed page: ACT 0, RD at tRCD 15, data done 15 + CL 20 + 2 = 37, a span
 * of 38 cycles on each of 4 channels = 152 rank-cycles; the auto-precharge closes the bank at tRAS 34,
 * so 34 are active (1.3125 x 39 each) and 118 precharged (1.3125 x 30 each):
 *   563.0625 + 874.125 + 34 x 51.1875 + 118 x 39.375 = 7823.8125 pJ over one 32-byte burst. */
Test(energy_dram, lpddr5_a_read_to_a_closed_bank)
{
    cJSON *root;
    const cJSON *e = mem_energy2("0x0 READ 0\n", "dram.preset=lpddr5_6400", "dram.page_policy=closed", &root);
    cr_expect(cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(e, "known")));
    cr_expect_eq(num(root, "total.cycles"), 38);
    cr_expect_eq(num(root, "total.active_cycles"), 34);
    cr_expect_eq(num(root, "total.bytes"), 32);
    EXPECT_SAME(num(e, "act_pre_pj"), 563.0625, "ACT+PRE");
    EXPECT_SAME(num(e, "read_burst_pj"), 874.125, "RD");
    EXPECT_SAME(num(e, "rank_cycles"), 152.0, "rank-cycles");
    EXPECT_SAME(num(e, "total_j"), 7823.8125e-12, "ACT + RD + PRE + standby");
    EXPECT_SAME(num(e, "pj_per_bit"), 7823.8125 / 256, "pJ/bit");
    cJSON_Delete(root);
}

/* GDDR6-14000 (DRAMsim3 configs/GDDR6_8Gb_x16.ini: VDD 1.35 V, IDD0 71, IDD2N 60, IDD3N 61, IDD4R
 * 248 mA a x16 channel), tCK 1/1.75 ns, so VDD x tCK = 1.35 / 1.75 V ns:
 *   ACT+PRE = (71 x 79 - (61 x 53 + 60 x 26)) = 816 mA CK, RD = (248 - 61) x 2 = 374 mA CK.
 * A read to a closed bank: RD at tRCD 26, done 26 + CL 24 + 2 = 52, 53 cycles on each of 2 channels;
 * tRAS 53 keeps channel 0's bank open all 53, channel 1 precharged all 53:
 *   (816 + 374 + 53 x 61 + 53 x 60) x 1.35 / 1.75 = 7603 x 1.35 / 1.75 pJ. */
Test(energy_dram, gddr6_a_read_to_a_closed_bank)
{
    cJSON *root;
    const cJSON *e = mem_energy2("0x0 READ 0\n", "dram.preset=gddr6_14000", "dram.page_policy=closed", &root);
    const double v_tck = 1.35 / 1.75;
    cr_expect_eq(num(root, "total.cycles"), 53);
    cr_expect_eq(num(root, "total.active_cycles"), 53);
    EXPECT_SAME(num(e, "act_pre_pj"), 816 * v_tck, "ACT+PRE");
    EXPECT_SAME(num(e, "read_burst_pj"), 374 * v_tck, "RD");
    EXPECT_SAME(num(e, "total_j"), 7603 * v_tck * 1e-12, "ACT + RD + PRE + standby");
    cJSON_Delete(root);
}

/* Currents of 0 (a preset or user without figures) give no energy rather than zero joules. */
Test(energy_dram, no_currents_no_energy)
{
    CfgMachine c;
    cfg_defaults(&c);
    DramParams p;
    char err[256];
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    p.power = (DramPower){0};
    DramChanStats s = {.activates = 1, .reads = 1, .bytes = 64};
    DramEnergy e;
    dram_energy(&p, &s, 100, &e);
    cr_expect(!e.known);
    cr_expect_eq(e.core, 0);
}

/* ==== energy_magnitude: against published figures ==================================================== */

/* A 512 KB SRAM read at 45 nm is the CACTI 7 row (206.2 pJ for 64 bytes); per 64 bits (25.8 pJ) it
 * lies between Horowitz's 64-bit reads of an 8 KB (10 pJ) and a 1 MB (100 pJ) cache (ISSCC 2014). */
Test(energy_magnitude, sram_512kb_read)
{
    SramFig f;
    cr_assert_eq(sram_figures(0, 512, 1, 1, 45, &f), 0);
    cr_expect_eq(f.read_pj, 206.2);
    cr_expect_eq(f.row_kib, 512);
    cr_expect(f.read_pj / 8 > 10 && f.read_pj / 8 < 100, "%g pJ per 64 bits", f.read_pj / 8);
    /* At 22 nm the 22 nm row itself; at 30 nm (no row) the 45 nm row scaled, between the two. */
    cr_assert_eq(sram_figures(0, 512, 1, 1, 22, &f), 0);
    cr_expect_eq(f.read_pj, 62.6);
    cr_assert_eq(sram_figures(0, 512, 1, 1, 30, &f), 0);
    cr_expect(f.read_pj < 206.2 && f.read_pj > 62.6, "%g", f.read_pj);
    /* Sizes not in the table scale: 1024 KB from the 512 KB row, energy x sqrt 2, area x 2. */
    cr_assert_eq(sram_figures(0, 1024, 1, 1, 45, &f), 0);
    cr_expect_eq(f.row_kib, 512);
    EXPECT_SAME(f.read_pj, 206.2 * sqrt(2.0), "1 MB read");
    EXPECT_SAME(f.area_mm2, 2 * 1.828, "1 MB area");
    /* The fitted node exponents: dynamic energy falls faster than linearly with the node, area about
     * as its square (a 22 nm cell is about a quarter of a 45 nm one). */
    SramNodeExp x = sram_node_exponents();
    cr_expect(x.dynamic > 1 && x.dynamic < 2.5, "%g", x.dynamic);
    cr_expect(x.area > 1.5 && x.area < 2.5, "%g", x.area);
}

/* A DDR4 read to a closed bank (ACT + RD) per bit is below Horowitz's 1.3-2.6 nJ per 64-bit DRAM
 * access (20-40 pJ/bit, ISSCC 2014, which includes I/O) and above the HBM2 preset's, a DRAM built
 * to spend less per bit. */
Test(energy_magnitude, ddr4_read_per_bit)
{
    CfgMachine c;
    cfg_defaults(&c);
    DramParams p, h;
    char err[256];
    cr_assert_eq(dram_params(&c, &p, err, sizeof err), 0, "%s", err);
    c.dram_preset = 4;   /* hbm2_2000 */
    cr_assert_eq(dram_params(&c, &h, err, sizeof err), 0, "%s", err);
    DramChanStats s = {.activates = 1, .reads = 1, .bytes = 64};
    DramEnergy e, eh;
    dram_energy(&p, &s, 0, &e);
    s.bytes = (uint64_t)h.burst_bytes;
    dram_energy(&h, &s, 0, &eh);
    cr_expect(e.pj_per_bit > 5 && e.pj_per_bit < 40, "DDR4 %g pJ/bit", e.pj_per_bit);
    cr_expect(e.pj_per_bit > eh.pj_per_bit, "DDR4 %g, HBM2 %g pJ/bit", e.pj_per_bit, eh.pj_per_bit);
}

/* ==== energy_keys ===================================================================================== */

Test(energy_keys, a_negative_figure_is_an_error_naming_its_key)
{
    CfgMachine c;
    cfg_defaults(&c);
    CfgErrors errs = {0};
    cr_expect_eq(cfg_set(&c, "energy.fp32_add_pj=-1", &errs), 1);
    cr_expect(errs.text && strstr(errs.text, "energy.fp32_add_pj"), "%s", errs.text ? errs.text : "");
    cfg_errors_free(&errs);
    cr_expect_eq(cfg_set(&c, "energy.node_nm=0", &errs), 1);
    cr_expect(errs.text && strstr(errs.text, "energy.node_nm"), "%s", errs.text ? errs.text : "");
    cfg_errors_free(&errs);
    cr_expect_eq(cfg_set(&c, "dram.idd0=-3", &errs), 1);
    cfg_errors_free(&errs);
}
