/* sim/trace.c -- `sfsim trace`: a batch of rays through the kernel's traversal and intersection
 * (sim/run/engine.c, TRACE_ONLY) or the golden model (sim/ref_trace.c), through the run entry point
 * (sim/run/run.h); hits to a file.
 *
 * Owns: the hit file and the summary. Must not: trace rays itself.
 */
#include "trace.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

#include "../host/outfile.h"
#include "run/run.h"

int trace_run(const TraceOptions *o, TraceSummary *sum, char *err, size_t errlen)
{
    memset(sum, 0, sizeof *sum);
    RunSpec spec = {.cfg = o->cfg, .kernel_path = o->kernel_path, .seed = 1, .threads = o->threads};
    spec.mode = o->mode;
    assert(spec.mode != RUN_SAMPLED); /* the command line refuses it (sim/cli/runopts.c) */
    /* Before any work: a hit file that cannot be written would fail the run only at its end. */
    if (outfile_check_file(o->out_path, err, errlen) != 0)
        return -3;
    RunScene sc;
    RayBatch b;
    BatchHit *hits = NULL;
    memset(&b, 0, sizeof b);
    int rc = -1;
    if (run_scene_open(&sc, o->scene_path, NULL, o->cfg, spec.mode, "sfsim trace", err, errlen) != 0)
        goto out;
    if (raybatch_load(o->rays_path, &b, err, errlen) != 0)
        goto out;
    hits = calloc(b.count ? b.count : 1, sizeof *hits);
    if (!hits) {
        snprintf(err, errlen, "out of memory for %u hits", b.count);
        goto out;
    }
    RunTrace rt;
    rc = run_trace(&sc.p, sc.image, sc.s.needs, &spec, &b, hits, &rt, err, errlen);
    sum->timed = rt.timed;
    sum->timing = rt.timing;
    sum->cores = rt.cores;
    sum->cores_used = rt.cores_used;
    sum->makespan = rt.makespan;
    sum->sim_instructions = rt.instructions;
    sum->seconds = rt.seconds;
    if (rc != 0)
        goto out;
    rc = -3; /* an output that could not be written */
    if (raybatch_write_hits(o->out_path, &b, hits, o->binary, err, errlen) != 0)
        goto out;
    sum->rays = b.count;
    for (uint32_t i = 0; i < b.count; i++) {
        if (hits[i].invalid)
            sum->invalid++;
        else if (b.rays[i].query == RAY_ANY)
            hits[i].prim ? sum->occluded++ : sum->clear++;
        else
            hits[i].prim == UINT32_MAX ? sum->misses++ : sum->hits++;
    }
    rc = 0;
out:
    free(hits);
    raybatch_free(&b);
    run_scene_close(&sc);
    return rc;
}
