/* tests/support/report_run.c -- render_run into a fresh folder, the report read back (see
 * report_run.h). */
#include "report_run.h"

#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>

#include "files.h"

cJSON *tu_run_report(RenderOptions *o, const char *tag, char **txt)
{
    char dir[96], path[160];
    static char err[65536];
    tu_make_tmpdir(dir, sizeof dir, tag);
    o->out_dir = dir;
    cr_assert_eq(render_run(o, err, sizeof err), 0, "%s", err);
    o->out_dir = NULL;
    snprintf(path, sizeof path, "%s/report.json", dir);
    char *json = tu_slurp(path);
    if (txt) {
        snprintf(path, sizeof path, "%s/report.txt", dir);
        *txt = tu_slurp(path);
    }
    tu_remove_tree(dir);
    cJSON *j = cJSON_Parse(json);
    free(json);
    cr_assert(cJSON_IsObject(j), "report.json does not parse");
    return j;
}
