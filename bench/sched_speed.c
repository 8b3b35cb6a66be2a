/* bench/sched_speed.c -- what the scheduling pass (asm/sched.c) adds to a run's start: the path
 * tracer assembled as `sfsim run` assembles it for the Cornell box, without and with the pass, many
 * times; the median and the minimum of each, and their difference (issue 43 asks for at most 10 ms).
 *
 * Owns: that measurement. Must not: be a test (it asserts nothing; a slow host only prints more).
 *
 *   build/bench/sched_speed [REPEATS]     (default 40; run from the repository's top folder)
 */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "../asm/asm.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec / 1e6;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

int main(int argc, char **argv)
{
    int reps = argc > 1 ? atoi(argv[1]) : 40;
    if (reps < 1 || reps > 100000) {
        fprintf(stderr, "usage: sched_speed [REPEATS 1..100000]\n");
        return 2;
    }
    /* the Cornell box's symbols on the default machine (report.json's kernel.defines) */
    static const AsmDefine defs[] = {{"RAYS", 4096}, {"SPAD_BYTES", 65536}, {"HAS_LAMBERT", 1}};
    const char *incs[] = {"kernels/lib"};
    AsmSchedModel m;
    sched_model_default(&m);
    double *t[2];
    uint32_t ntext = 0;
    t[0] = malloc(sizeof(double) * (size_t)reps);
    t[1] = malloc(sizeof(double) * (size_t)reps);
    if (!t[0] || !t[1])
        return 1;
    /* one warm-up, then the two ways alternated, so that neither gets the warmer caches */
    for (int r = -1; r < reps; r++)
        for (int s = 0; s < 2; s++) {
            AsmOptions opt = {defs, 3, incs, 1, NULL, s ? &m : NULL, NULL};
            AsmObject obj;
            double t0 = now_ms();
            int errs = asm_assemble_file("kernels/pathtrace.s", &opt, &obj);
            double dt = now_ms() - t0;
            if (errs) {
                fprintf(stderr, "sched_speed: kernels/pathtrace.s does not assemble (run from the top folder)\n");
                return 1;
            }
            if (r >= 0)
                t[s][r] = dt;
            ntext = obj.ntext;
            asm_object_free(&obj);
        }
    qsort(t[0], (size_t)reps, sizeof(double), cmp_d);
    qsort(t[1], (size_t)reps, sizeof(double), cmp_d);
    printf("kernels/pathtrace.s (%u instructions), %d assemblies each:\n", ntext, reps);
    printf("  source order:  median %.2f ms, min %.2f ms\n", t[0][reps / 2], t[0][0]);
    printf("  list-scheduled: median %.2f ms, min %.2f ms\n", t[1][reps / 2], t[1][0]);
    printf("  the pass adds: median %.2f ms, min %.2f ms\n", t[1][reps / 2] - t[0][reps / 2], t[1][0] - t[0][0]);
    free(t[0]);
    free(t[1]);
    return 0;
}
