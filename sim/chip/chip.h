/* sim/chip/chip.h -- the memory the chip's cores share (docs/chip.md): the on-chip network, the
 * L2 and DRAM, each optional, joined as levels (sim/mem/level.h), with the cores' scene caches
 * above them, stepped in one global time order.
 *
 * Owns: building the shared levels from the config (chip.*, noc.*, l2.*, dram.*), the cores'
 * requests on their way in (ordered by cycle, then core, then the order a core sent them),
 * stepping the levels one cycle of theirs at a time, and handing each answer to its core's
 * timing model (timing_answer). Must not: run a core, hand out work, or decide when a cycle may
 * be stepped (its caller, the chip's run in sim/run/chiprun.c, keeps the rule of docs/chip.md).
 *
 * A request a core's L1 makes in cycle c enters the shared memory in cycle c + 1 (the cycle it
 * takes to leave the core); so once the memory has done cycle e, a core that goes on from cycle
 * e can still send anything it has to, and nothing the memory did in cycle e could have changed.
 */
#ifndef SFSIM_CHIP_CHIP_H
#define SFSIM_CHIP_CHIP_H

#include <stddef.h>
#include <stdint.h>

#include "../config.h"
#include "../mem/dram.h"
#include "../mem/l2.h"
#include "../mem/monitor.h"
#include "../mem/noc.h"
#include "../timing.h"

typedef struct Chip Chip;

/* Whether cfg's chip has shared memory below its cores' L1s (chip.memory = shared). */
int chip_shared(const CfgMachine *cfg);
/* The shared memory's keys checked together: 0, or -1 with the keys named in err. */
int chip_check(const CfgMachine *cfg, char *err, size_t errlen);
/* The shared levels, top to bottom, as a watch names them (chip_level_keys: "noc", "l2", "dram"). */
enum { CHIP_LEVEL_NOC, CHIP_LEVEL_L2, CHIP_LEVEL_DRAM, CHIP_LEVELS };
extern const char *const chip_level_keys[CHIP_LEVELS];
/* The shared memory of cfg's chip for `cores` cores; with watch (NULL: none), every request into
 * each level there is and its answer are told to it (sim/mem/monitor.h: a timeline). NULL with err
 * on a bad config or out of memory. */
Chip *chip_new(const CfgMachine *cfg, int cores, const MemWatch *watch, char *err, size_t errlen);
void chip_free(Chip *c);
/* Every level cold and idle, nothing in flight, as chip_new left it (the counters go on): before
 * a sampled chip's unit (sim/run/chipunit.h), whose cores' models are reset too. */
void chip_reset(Chip *c);
/* Functional warming of a reset chip (a sampled chip's unit): the n line addresses, oldest first,
 * read as if each had been read and nothing else had happened: into the L2 (when there is one),
 * and the DRAM row of each that the L2 did not hold (every one without an L2) opened. No time
 * passes and nothing is counted. */
void chip_warm(Chip *c, const uint64_t *addr, size_t n);
/* ... and as if each had been written (a framebuffer's lines): into a write-back L2, dirty; no
 * DRAM row opened (a write-back L2 did not send them below yet; without one, or write-through,
 * the writes left nothing behind). */
void chip_warm_written(Chip *c, const uint64_t *addr, size_t n);
/* Core k's timing model sends its L1's misses and write-backs here from now on. 0, or -1 on out
 * of memory. */
int chip_attach(Chip *c, int k, Timing *t);
/* The requests the cores sent while they ran (each into a list of its own, so that cores may run
 * on any host threads) taken in: those of the n cores listed (every core that ran since the last
 * call), before chip_next, with no core running. */
void chip_collect(Chip *c, const int *cores, int n);
/* The next cycle in which the shared memory has something to do (a request entering, an event of
 * a level); UINT64_MAX: nothing. */
uint64_t chip_next(const Chip *c);
/* Does cycle e (e = chip_next): the requests entering then, then every level's events of it. Each
 * read answered is given to its core's timing model, and woke(ctx, core, cycle) is called after. */
typedef void (*ChipWoke)(void *ctx, int core, uint64_t cycle);
void chip_step(Chip *c, uint64_t e, ChipWoke woke, void *ctx);
/* Internal errors (out of memory in a queue); NULL when none. */
const char *chip_error(const Chip *c);

/* The shared levels' counters: which levels there are, and theirs. */
typedef struct ChipMemStats {
    int has_noc, has_l2;
    NocStats noc;
    L2Stats l2;
    DramChanStats dram;              /* summed over channels */
    int dram_channels;
    uint64_t requests, writes;       /* from the cores */
    uint64_t read_latency;           /* sum over reads of answer - the cycle the L1 sent it */
    uint64_t read_latency_max;
    double dram_clock_mhz;           /* its command clock */
    double dram_peak_gbs;            /* channels x bus width x data rate, GB/s (10^9 bytes) */
} ChipMemStats;
void chip_stats(const Chip *c, ChipMemStats *s);

/* One core's share of the shared memory's work: its reads as they came in and their latency sum
 * as they were answered (ChipMemStats.requests, .read_latency), and with an L2 counting cores
 * (chip_count_cores) its accesses and hits there and DRAM's bytes for the lines the L2 sent below
 * for it (a fill, the dirty line it evicted, a write through), as the L2 took its requests;
 * without an L2, DRAM's bytes of its requests as its L1 sent them. A sampled chip's waves read it
 * per unit (docs/sampling.md): a request sent as a unit ended counts for the next unit on its core,
 * but in the DRAM bytes without an L2 (there a unit's last write-backs are many of its bytes, and
 * the requests and their latencies are not in the same ratio). Zero for k out of range. */
typedef struct ChipCoreStats {
    uint64_t requests, read_latency, l2_accesses, l2_hits, dram_bytes;
} ChipCoreStats;
/* Count the L2's work by core from now on; 0, or -1 when out of memory. */
int chip_count_cores(Chip *c);
void chip_core_stats(const Chip *c, int k, ChipCoreStats *s);

/* The memory figures the report gives of a chip's counters over a frame of `seconds`
 * (docs/report.md): the average read latency below the L1s (cycles), the L2's hit rate and DRAM's
 * bandwidth (GB/s, 10^9 bytes); each -1 where it has no meaning (no request, no L2 or no access
 * to it, no time). */
enum { CHIP_FIG_LATENCY, CHIP_FIG_L2_HIT_RATE, CHIP_FIG_DRAM_GBS, CHIP_FIG_COUNT };
void chip_mem_figures(const ChipMemStats *s, double seconds, double out[CHIP_FIG_COUNT]);

#endif
