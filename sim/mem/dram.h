/* sim/mem/dram.h -- sfsim's own DRAM model: the controller (FR-FCFS, read and write queues, write
 * draining, refresh) and the bank state machines of one or more channels, in DRAM clock cycles.
 *
 * Owns: the DRAM's parameters (a preset of sim/mem/dram_presets.def overridden by the [dram] keys
 * of sim/config.def), the address mapping, the commands' timing rules and the DRAM's counters
 * (DRAM_STATS). Must not: know what is above it (an L2, a core, a trace file), convert between
 * clock domains (the caller does, with the integer clock_mhz), use floating point in a timing
 * decision, print, or exit. docs/dram.md is the model's description.
 *
 * Time is the DRAM's own clock, CK, counted in uint64_t from 0. A request is one burst
 * (DramParams.burst_bytes): the address's bits below the burst are ignored.
 */
#ifndef SFSIM_MEM_DRAM_H
#define SFSIM_MEM_DRAM_H

#include <stddef.h>
#include <stdint.h>

#include "../config.h"

/* The presets of dram_presets.def, in its order (the values of the key dram.preset). */
typedef enum DramPreset {
#define DRAM_PRESET(name, ...) DRAM_PRESET_##name,
#include "dram_presets.def"
#undef DRAM_PRESET
    DRAM_NPRESETS
} DramPreset;

/* The address fields, as named in a mapping string. */
typedef enum DramField { DRAM_F_CH, DRAM_F_RA, DRAM_F_BG, DRAM_F_BA, DRAM_F_RO, DRAM_F_CO, DRAM_NFIELDS } DramField;

enum { DRAM_PAGE_OPEN = 0, DRAM_PAGE_CLOSED = 1 };

/* The devices' supply and currents (dram_presets.def's power columns, docs/energy.md): V, and mA of
 * one device; 0: not given. The I/O figure: pJ per bit moved on the data bus, at the preset's data
 * rate; 0: not modelled. Read only by the energy model (sim/energy/dramenergy.h). */
typedef struct DramPower {
    double vdd, idd0, idd2n, idd3n, idd4r, idd4w, idd5b;
    const char *source;             /* the data sheet, or why there is none */
    double io_pj_bit;               /* the preset's, or the key energy.dram_io_pj_bit's when not 0 */
    const char *io_source;          /* its derivation, or why there is none */
} DramPower;

typedef struct DramParams {
    const char *name;               /* the preset's name ("ddr4_2400") */
    int clock_mhz;                  /* CK; tCK = 1000 / clock_mhz ns */
    int beats;                      /* data beats per CK per pin */
    int channels, ranks, bankgroups, banks, rows, columns; /* banks: per bank group */
    int device_width, bus_bits, bl;
    int cl, cwl, trcd, trp, tras, trc, tccd_s, tccd_l, trrd_s, trrd_l, tfaw, twr, twtr_s, twtr_l, trtp;
    int trefi, trfc, trtrs, trtw;
    char mapping[64];               /* field order, most significant first: "ro,ra,ba,co,bg,ch" */
    int page_policy;                /* DRAM_PAGE_OPEN or DRAM_PAGE_CLOSED */
    int read_queue, write_queue;    /* entries per channel */
    int write_high, write_low;      /* write-drain watermarks (entries): start at >= high, stop at <= low */
    /* Derived by dram_params_check: */
    int burst_cycles;               /* bl / beats: CK the data bus is busy per burst */
    int burst_bytes;                /* bus_bits / 8 * bl: the bytes of one request */
    int field_shift[DRAM_NFIELDS], field_bits[DRAM_NFIELDS];
    int offset_bits, addr_bits;     /* bits below the fields; bits of the whole capacity */
    DramPower power;                /* the energy model's figures (no timing decision reads them) */
} DramParams;

/* The preset's values with the controller defaults of sim/config.def; checked. 0 or -1. */
int dram_preset(DramPreset which, DramParams *p);
/* The preset named by the key dram.preset, overridden by every other [dram] key that is not 0.
 * 0, or -1 with "key dram.NAME: ..." in err. */
int dram_params(const CfgMachine *c, DramParams *p, char *err, size_t errlen);
/* Checks the values and derives burst_cycles, burst_bytes and the field positions from mapping:
 * the mapping names each of ch, ra, bg, ba, ro, co exactly once, separated by commas, and the fields
 * fit 64 address bits. 0, or -1 with a message naming the key (dram.mapping, dram.trc, ...). */
int dram_params_check(DramParams *p, char *err, size_t errlen);
const char *dram_preset_name(DramPreset which);
const char *dram_preset_source(DramPreset which);

/* An address's fields under p's mapping (bits above the capacity are ignored). */
typedef struct DramAddr { int ch, ra, bg, ba, ro, co; } DramAddr;
DramAddr dram_decode(const DramParams *p, uint64_t addr);

/* Counters per channel: X(name, unit, description). Plain uint64_t fields. */
#define DRAM_STATS(X)                                                                                            \
    X(reads,          "requests", "read requests served (counted when their RD issues)")                                                     \
    X(writes,         "requests", "write requests served (counted when their WR issues)")                                                    \
    X(activates,      "commands", "ACT commands")                                                                \
    X(precharges,     "commands", "PRE commands and auto-precharges (closed page)")                             \
    X(row_hits,       "requests", "requests whose row was open when they were served")                          \
    X(row_misses,     "requests", "requests that found their bank closed (an ACT)")                              \
    X(row_conflicts,  "requests", "requests that found another row open (a PRE and an ACT)")                     \
    X(refreshes,      "commands", "all-bank REF commands")                                                       \
    X(refresh_cycles, "cycles",   "tRFC x refreshes: cycles a rank was refreshing")                             \
    X(bytes,          "bytes",    "bytes transferred (reads and writes)")                                        \
    X(busy_cycles,    "cycles",   "data-bus cycles carrying data")                                               \
    X(read_latency,   "cycles",   "sum over reads of done cycle - arrival cycle")                                      \
    X(write_latency,  "cycles",   "sum over writes of done cycle - arrival cycle")                                     \
    X(max_latency,    "cycles",   "largest completion - arrival")                                                \
    X(occupancy_sum,  "entry-cycles", "sum over cycles of the read + write queue entries (average = / cycles)") \
    X(occupancy_max,  "entries",  "most read + write queue entries at once")                                     \
    X(backpressure,   "cycles",   "sum over requests of cycles waited for a queue slot")                         \
    X(backpressured,  "requests", "requests that found their queue full")                                       \
    X(cycles,         "cycles",   "cycles simulated (the time of the last dram_run)")                          \
    X(active_cycles,  "cycles",   "rank-cycles with a bank open (active standby, IDD3N: the energy model's background)")

/* Latency histogram: exact below DRAM_HIST_EXACT cycles, then 32 buckets per power of two
 * (a bucket's values differ by less than 1/32). */
enum { DRAM_HIST_EXACT = 1024, DRAM_HIST_SUB = 32, DRAM_HIST_OCT = 40,
       DRAM_HIST_BUCKETS = DRAM_HIST_EXACT + DRAM_HIST_SUB * DRAM_HIST_OCT };

typedef struct DramChanStats {
#define DRAM_X(name, unit, desc) uint64_t name;
    DRAM_STATS(DRAM_X)
#undef DRAM_X
    uint64_t hist[DRAM_HIST_BUCKETS];
} DramChanStats;

typedef struct DramStats {
    int channels;
    DramChanStats total;       /* sums over channels (maxima for the max fields) */
    DramChanStats *chan;       /* [channels] */
} DramStats;

/* A latency's histogram bucket and the smallest latency in a bucket. */
int dram_hist_bucket(uint64_t latency);
uint64_t dram_hist_low(int bucket);
/* The q-quantile (0 < q <= 1) of the latencies in h: the smallest bucket low whose cumulative count
 * reaches ceil(q x n) (exact below DRAM_HIST_EXACT). */
uint64_t dram_hist_quantile(const uint64_t *h, double q);

typedef struct Dram Dram;
Dram *dram_new(const DramParams *p, char *err, size_t errlen);
void dram_free(Dram *d);
/* Cold: banks precharged, queues empty, time 0; counters kept. */
void dram_reset(Dram *d);
/* Functional warming (a sampled chip's unit: docs/sampling.md): the row addr maps to left open in
 * its bank, as an access would leave it with an open page (nothing with a closed page); no time
 * passes and nothing is counted. Only on an idle DRAM (after dram_reset, before the first push). */
void dram_warm(Dram *d, uint64_t addr);
/* Requests arrive in non-decreasing cycle order, at or after the until of the last dram_run (an
 * earlier cycle is taken as that one). Always accepted: one that finds its queue full waits in an
 * arrival FIFO (counted as back-pressure) and enters when a slot frees. id is the caller's. */
void dram_push(Dram *d, uint64_t addr, int write, uint64_t cycle, uint64_t id);
#define DRAM_NEVER UINT64_MAX
/* The cycle of the next thing the controller will do on its own (a command, a refresh, a
 * completion), or DRAM_NEVER. Refreshes recur for ever: use dram_outstanding to know when a
 * replay is done. */
uint64_t dram_next(const Dram *d);
/* Requests pushed and not yet reported done. */
uint64_t dram_outstanding(const Dram *d);
/* Simulate every cycle < until; each finished request is reported once, in (cycle, id) order: a
 * read at the cycle its last data beat has arrived, a write at the cycle its last data beat has
 * been transferred to the DRAM (the write recovery tWR after it delays only that bank). */
typedef void (*DramDone)(void *ctx, uint64_t id, int write, uint64_t cycle);
void dram_run(Dram *d, uint64_t until, DramDone done, void *ctx);
const DramStats *dram_stats(const Dram *d);
const DramParams *dram_get_params(const Dram *d);

/* Test hook: 1 evaluates the scheduler at every cycle instead of jumping to the next event. */
void dram_set_tick_every_cycle(Dram *d, int on);

#endif
