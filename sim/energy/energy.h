/* sim/energy/energy.h -- energy, power and area of a run, computed once after it from the counters
 * it kept (docs/energy.md): dynamic energy per event and leakage x the frame's time for every
 * part of the machine, by part and by level, the DRAM's by command and state, area per structure
 * and the chip's.
 *
 * Owns: which counter feeds which figure of sim/energy/energy.def (the [energy] keys), the rules
 * that derive a count the run does not keep (register-file words from the operands of the
 * executed instructions, the write share of a memory's lines from its store instructions), and
 * the figures of merit (average power, MRays/J, fps/W, fps/mm^2). SRAM figures: sim/energy/sram.h;
 * the DRAM's: sim/energy/dramenergy.h.
 * Must not: be called from the timing loop (one call after the run: sim/report.c), count, or
 * change a counter.
 */
#ifndef SFSIM_ENERGY_ENERGY_H
#define SFSIM_ENERGY_ENERGY_H

#include <stddef.h>

#include "../config.h"
#include "../run/engine.h"
#include "dramenergy.h"

/* The parts energy is reported by: key, and what its energy is. */
#define ENERGY_PARTS(X) \
    X(FETCH,        "fetch",        "instruction fetch: fetch_pj per executed instruction") \
    X(REGFILE,      "registers",    "register-file words read and written, from the executed instructions' operands (a vector register: N words)") \
    X(SIMD,         "simd",         "the arithmetic of the executed instructions by unit class (vector classes: all N lanes)") \
    X(RAYBUF,       "ray_buffers",  "ray-buffer bank lines; leakage of both buffers' banks") \
    X(IDM,          "id_streams",   "ID-stream memory lines: ID vectors fetched and appended, IDs the partition unit read and wrote") \
    X(AGU,          "agu",          "an address (an integer add) per ID of each ID vector the AGUs fetched") \
    X(INTERCONNECT, "interconnect", "data-path transfers: N x 32 bits over interconnect_mm of wire") \
    X(PARTITION,    "partition",    "a comparison (an integer add) per ID the partition unit moved") \
    X(SPAD,         "scratchpad",   "scratchpad lines (vector accesses' lines, a line per scalar access)") \
    X(L1,           "l1",           "scene-cache accesses (a read each), fills (a write) and write-backs (a read)") \
    X(L2,           "l2",           "L2 reads, writes, fills (a write) and write-backs (a read); tags and data in one CACTI cache figure") \
    X(NOC,          "noc",          "network bytes over noc_mm of wire") \
    X(DRAM,         "dram",         "the DRAM's commands and background standby (IDD currents); its I/O apart") \
    X(DRAM_IO,      "dram_io",      "the DRAM's I/O: dram_io_pj_bit per bit transferred") \
    X(VRF,          "vector_registers", "leakage of the vector register file (its accesses: registers)") \
    X(LOGIC,        "logic",        "leakage of the SIMD datapath (logic_leak_mw_mm2 x its area)")

typedef enum EnergyPart {
#define ENERGY_PART_ENUM(name, key, desc) EN_P_##name,
    ENERGY_PARTS(ENERGY_PART_ENUM)
#undef ENERGY_PART_ENUM
    EN_P_COUNT
} EnergyPart;

#define ENERGY_LEVELS(X) \
    X(DATAPATH,  "datapath",       "fetch, SIMD arithmetic, AGUs, interconnect, partition unit, logic leakage") \
    X(REGISTERS, "registers",      "register files") \
    X(LOCAL,     "local_memories", "ray buffers, ID-stream memory, scratchpad") \
    X(L1,        "l1",             "the scene caches") \
    X(L2,        "l2",             "the shared L2") \
    X(NOC,       "noc",            "the on-chip network") \
    X(DRAM,      "dram",           "DRAM, its I/O included")

typedef enum EnergyLevel {
#define ENERGY_LEVEL_ENUM(name, key, desc) EN_L_##name,
    ENERGY_LEVELS(ENERGY_LEVEL_ENUM)
#undef ENERGY_LEVEL_ENUM
    EN_L_COUNT
} EnergyLevel;

#define ENERGY_DRAM_PARTS(X) \
    X(ACTIVATE,   "activate",              "ACT commands with their PRE") \
    X(READ,       "read",                  "read bursts") \
    X(WRITE,      "write",                 "write bursts") \
    X(REFRESH,    "refresh",               "all-bank refreshes") \
    X(BG_ACTIVE,  "background_active",     "active standby (a bank open, or refreshing): IDD3N") \
    X(BG_PRE,     "background_precharged", "precharged standby: IDD2N") \
    X(IO,         "io",                    "I/O, per bit")

typedef enum EnergyDramPart {
#define ENERGY_DRAM_ENUM(name, key, desc) EN_D_##name,
    ENERGY_DRAM_PARTS(ENERGY_DRAM_ENUM)
#undef ENERGY_DRAM_ENUM
    EN_D_COUNT
} EnergyDramPart;

#define ENERGY_AREAS(X) \
    X(SIMD,      "simd",        "the SIMD datapath (N lanes) and the scalar units, from the adders' and multipliers' areas") \
    X(REGFILE,   "registers",   "the vector register file") \
    X(RAYBUF,    "ray_buffers", "the two ray buffers") \
    X(IDM,       "id_streams",  "the ID-stream memory") \
    X(SPAD,      "scratchpad",  "the scratchpad") \
    X(L1,        "l1",          "the scene cache") \
    X(CORE,      "core",        "one core: the above") \
    X(CORES,     "cores",       "K cores") \
    X(L2,        "l2",          "the shared L2") \
    X(CHIP,      "chip",        "K cores and the L2 (the network, AGUs, interconnect, partition unit and I-cache are not modelled)")

typedef enum EnergyArea {
#define ENERGY_AREA_ENUM(name, key, desc) EN_A_##name,
    ENERGY_AREAS(ENERGY_AREA_ENUM)
#undef ENERGY_AREA_ENUM
    EN_A_COUNT
} EnergyArea;

extern const char *const energy_part_keys[EN_P_COUNT];
extern const char *const energy_level_keys[EN_L_COUNT];
extern const char *const energy_dram_keys[EN_D_COUNT];
extern const char *const energy_area_keys[EN_A_COUNT];

/* What the run gives: its counters (f: the kernel's, its timing model's, its chip's), the frame's
 * seconds and rays, and in sampled mode the scale of the counted events to the frame's estimate. */
typedef struct EnergyInput {
    const CfgMachine *cfg;
    const FuncStats *f;
    double seconds;                   /* the frame's (the estimate in sampled mode) */
    double scale;                     /* events counted x scale = the frame's (1: all were counted) */
    double seconds_lo, seconds_hi, scale_lo, scale_hi;   /* sampled mode: the 95 % bounds */
    double rays;                      /* the frame's rays, all kinds */
} EnergyInput;

typedef struct EnergyReport {
    double events[EN_P_COUNT];        /* J of the frame's events (the DRAM: its standby too) */
    double leakage[EN_P_COUNT];       /* J: leakage power x seconds */
    double level[EN_L_COUNT];         /* J: events + leakage by level */
    double dram[EN_D_COUNT];          /* J */
    int dram_known;                   /* the DRAM's currents are known (else its energy is 0) */
    int has_dram;                     /* the run had a DRAM (chip.memory = shared) */
    double dram_pj_per_bit;           /* the DRAM's energy but I/O over the bits it moved */
    double area[EN_A_COUNT];          /* mm^2 */
    double seconds, leakage_w;
    double events_j, leakage_j, total_j, average_w, mrays_per_j, fps_per_w, fps_per_mm2;
    double total_lo, total_hi;        /* sampled mode: the 95 % bounds of total_j (else = total_j) */
    double node_nm;
} EnergyReport;

/* The energy of the run in. 0, or -1 with the reason in err (an SRAM the table has no row for). */
int energy_compute(const EnergyInput *in, EnergyReport *r, char *err, size_t errlen);

#endif
