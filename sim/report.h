/* sim/report.h -- report.json, report.txt and stats.txt of one `sfsim run` (docs/report.md).
 *
 * Owns: their content. Must not: write files (sim/render.c stages and commits them).
 */
#ifndef SFSIM_REPORT_H
#define SFSIM_REPORT_H

#include <stddef.h>

#include "config.h"
#include "energy/energy.h"
#include "render.h"
#include "run/run.h"

struct cJSON;

/* A finished run, as the report files describe it. */
typedef struct Report {
    const RenderOptions *o;    /* as the user asked: mode name, scene and config paths, seed, sample */
    RunMode mode;
    const CfgMachine *cfg;     /* the machine as used */
    const RunScene *sc;
    const RunFrame *fr;
    double mean;               /* of the image's finite values */
    long nonfinite;
    EnergyReport energy;       /* timed modes: report_energy's (sim/energy/energy.h) */
    int has_energy;
} Report;

/* The run's energy, power and area into r->energy, once after the run (timed modes; others: none).
 * 0, or -1 with the reason in err. */
int report_energy(Report *r, char *err, size_t errlen);

/* report.json; NULL when out of memory. */
struct cJSON *report_json(const Report *r);
/* report.txt into txt (truncated to cap). */
void report_txt(const Report *r, char *txt, size_t cap);
/* stats.txt, gem5's form, into *text (malloc'd; free it) of *len bytes. 0, or -1 when out of memory. */
int report_stats_txt(const Report *r, char **text, size_t *len);

#endif
