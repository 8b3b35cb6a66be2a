/* tests/support/report_run.h -- a run of `sfsim run`'s library entry (render_run) into a fresh
 * temporary folder, its report read back: what the report, statistics, energy and scene tests
 * share. */
#ifndef SFSIM_TESTS_REPORT_RUN_H
#define SFSIM_TESTS_REPORT_RUN_H

#include <cjson/cJSON.h>

#include "../../sim/render.h"

/* render_run(o) into /tmp/sfsim-TAG-XXXXXX (o->out_dir is set to it, then cleared); returns
 * report.json parsed (cJSON_Delete it) and, when txt is not NULL, report.txt in *txt (free() it).
 * The folder and everything the run wrote are removed. The test fails when the run fails or
 * report.json does not parse. */
cJSON *tu_run_report(RenderOptions *o, const char *tag, char **txt);

#endif
