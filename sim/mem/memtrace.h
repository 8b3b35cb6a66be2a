/* sim/mem/memtrace.h -- memory-access traces: the reader of DRAMsim3's text trace and of sfsim's own
 * format, and the writer of sfsim's format (for `sfsim run --mem-trace FILE`, later).
 *
 * Owns: the two formats' syntax and their error messages ("FILE:LINE: ..."). Must not: know the
 * DRAM (cycles are returned in the trace's own clock; the caller converts), print, or exit.
 *
 * DRAMsim3 (its `--trace` input): one request a line, `0xADDR READ|WRITE CYCLE`, the cycle in the
 * memory's clock (DRAMsim3 also accepts the op spelled `R`/`W`, and so do we).
 *
 * sfsim (docs/dram.md): a first line `sfsim-memtrace 1 clock_mhz=F` (the format, its version, and
 * the clock of the cycle column, a positive number of MHz with at most 3 decimals), then one
 * request a line: `CYCLE R|W 0xADDR [SOURCE]`, CYCLE a decimal integer, SOURCE an optional word
 * of at most 31 characters saying where it came from (`core3`, `l1`, `wb`). Lines starting with '#'
 * and blank lines are ignored in both formats; cycles never decrease.
 */
#ifndef SFSIM_MEM_MEMTRACE_H
#define SFSIM_MEM_MEMTRACE_H

#include <stddef.h>
#include <stdint.h>

typedef enum MtrFormat { MTR_AUTO = 0, MTR_DRAMSIM3, MTR_SFSIM } MtrFormat;

typedef struct MtrRecord {
    uint64_t cycle, addr;
    int write;
    char source[32];
    long line;
} MtrRecord;

typedef struct MtrReader MtrReader;

/* Opens path (a regular file: host/infile.h) and, for MTR_AUTO, tells the format from the first
 * line: the sfsim header, or else DRAMsim3's. NULL with the reason in err. */
MtrReader *mtr_open(const char *path, MtrFormat fmt, char *err, size_t errlen);
/* The next request: 1, 0 at the end, -1 with "FILE:LINE: what is wrong" in err. */
int mtr_next(MtrReader *r, MtrRecord *rec, char *err, size_t errlen);
MtrFormat mtr_format(const MtrReader *r);
/* The clock of the cycle column in kHz (sfsim format), or 0 for DRAMsim3 (the DRAM's own clock). */
uint64_t mtr_clock_khz(const MtrReader *r);
void mtr_close(MtrReader *r);

typedef struct MtrWriter MtrWriter;
/* Starts path (written whole or not at all: host/outfile.h) with the header for clock_mhz. */
MtrWriter *mtr_create(const char *path, double clock_mhz, char *err, size_t errlen);
/* One request; cycles must not decrease (-1 otherwise, and on a write error). source may be NULL. */
int mtr_write(MtrWriter *w, uint64_t cycle, int write, uint64_t addr, const char *source, char *err, size_t errlen);
/* Closes the file into place: 0, or -1 (the file is then not there). w is freed either way. */
int mtr_finish(MtrWriter *w, char *err, size_t errlen);
/* Abandons the file (no file left behind); w is freed. NULL is harmless. */
void mtr_discard(MtrWriter *w);

#endif
