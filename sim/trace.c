/* sim/trace.c -- `sfsim trace`: a batch of rays through the kernel's traversal and intersection
 * (sim/functional.c, TRACE_ONLY) or the golden model (sim/ref_trace.c); hits to a file.
 *
 * Owns: choosing the engine and summarising. Must not: trace rays itself.
 */
#include "trace.h"

#include <stdlib.h>
#include <string.h>

#include "../scenes/scene.h"
#include "functional.h"
#include "outfile.h"
#include "ref_trace.h"
#include "run/accel.h"
#include "run/kernel.h"
#include "util.h"


int trace_batch_run(const PackedScene *p, uint32_t needs, const RayBatch *b, BatchHit *hits, const char *mode,
                    const CfgMachine *cfg, const char *kernel_path, int threads, uint64_t *sim_instructions,
                    TimingStats *timing, char *err, size_t errlen)
{
    if (sim_instructions)
        *sim_instructions = 0;
    if (!strcmp(mode, "reference")) {
        for (uint32_t i = 0; i < b->count; i++) {
            const BatchRay *r = &b->rays[i];
            BatchHit *h = &hits[i];
            memset(h, 0, sizeof *h);
            h->invalid = (uint32_t)raybatch_ray_invalid(r);
            if (h->invalid) {
                h->prim = r->query == RAY_ANY ? 0 : UINT32_MAX;
                continue;
            }
            RefRay q = {{r->org[0], r->org[1], r->org[2]}, {r->dir[0], r->dir[1], r->dir[2]}, r->tmax};
            if (r->query == RAY_ANY) {
                h->prim = (uint32_t)ref_any_hit(p, &q, NULL);
            } else {
                RefHit rh;
                ref_closest_hit(p, &q, &rh, NULL);
                h->prim = rh.prim;
                if (rh.prim != REF_NO_HIT) {
                    h->t = rh.t;
                    h->u = rh.u;
                    h->v = rh.v;
                }
            }
        }
        return 0;
    }
    int detailed = !strcmp(mode, "detailed");
    if (!detailed && strcmp(mode, "functional") != 0) {
        snprintf(err, errlen, "--mode %s: expected functional, detailed or reference", mode);
        return -1;
    }
    char kpath[4200];
    FuncParams fp = {.cfg = cfg,
                     .kernel_path = kernel_path ? kernel_path : kernel_default_path(kpath, sizeof kpath),
                     .needs = needs,
                     .seed = 1,
                     .threads = threads,
                     .batch = b,
                     .hits = hits,
                     .timed = detailed};
    FuncStats st;
    int rc = func_trace(p, &fp, &st, err, errlen);
    if (rc == 0 && sim_instructions)
        *sim_instructions = st.instructions;
    if (rc == 0 && timing)
        *timing = st.timing;
    func_stats_free(&st);
    return rc;
}

int trace_run(const TraceOptions *o, TraceSummary *sum, char *err, size_t errlen)
{
    memset(sum, 0, sizeof *sum);
    Scene s;
    PackedScene p;
    RayBatch b;
    BatchHit *hits = NULL;
    memset(&p, 0, sizeof p);
    memset(&b, 0, sizeof b);
    /* Before any work: a hit file that cannot be written would fail the run only at its end. */
    if (outfile_check_file(o->out_path, err, errlen) != 0)
        return -3;
    if (scene_load(o->scene_path, &s, err, errlen) != 0)
        return -1;
    for (uint32_t i = 0; i < s.nwarnings; i++) /* what the scene left out (docs/scenes.md) */
        fprintf(stderr, "sfsim trace: warning: %s\n", s.warnings[i]);
    int rc = -1;
    AccelInfo accel;
    if (accel_pack(&s, o->cfg, strcmp(o->mode, "reference") != 0, &p, &accel, err, errlen) != 0)
        goto out;
    if (raybatch_load(o->rays_path, &b, err, errlen) != 0)
        goto out;
    hits = calloc(b.count ? b.count : 1, sizeof *hits);
    if (!hits) {
        snprintf(err, errlen, "out of memory for %u hits", b.count);
        goto out;
    }
    double t0 = util_now();
    rc = trace_batch_run(&p, s.needs, &b, hits, o->mode, o->cfg, o->kernel_path, o->threads, &sum->sim_instructions,
                         &sum->timing, err, errlen);
    sum->timed = !strcmp(o->mode, "detailed");
    sum->seconds = util_now() - t0;
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
    pack_free(&p);
    scene_free(&s);
    return rc;
}
