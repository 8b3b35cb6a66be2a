/* bench/core_speed.c -- speed of the functional core: simulated instructions per host second.
 *
 * Four instruction mixes, each an endless loop built with isa_encode, run on a core of the default
 * machine (sim/config.def; set up by sim/run/timedcore.h, untimed) at N = 4, 16 and 64 in slices
 * of CHUNK instructions until at least the target time has passed (default 0.3 s; `core_speed
 * SECONDS` changes it). Each point is measured REPS times on a fresh core and the fastest run is
 * reported (best of 3: a shared host only ever slows a run down):
 *
 *   vfloat   vector float arithmetic: vfma, vfadd, vfmul, vfsub, vfmin, vfmax (8 vector ops + jmp)
 *   filter   the stream filter of Gribble & Ramani 2008, Fig. 5, over a 4096-ID stream: sfetch,
 *            3 x rgat, vfadd, 2 compares, mand, pmask, loop branch; then part, and again
 *   scalar   scalar integer hashing with a data-dependent branch and a counted loop
 *   gather   scene-memory gathers: 4 x ldg per iteration, addresses advanced with vaddi/vandi
 *
 * Columns: simulated instructions, host seconds, millions of simulated instructions per host
 * second, and millions of active lanes per host second (lane-operations of vector instructions).
 * Not a test: numbers depend on the host. docs/core.md quotes a run.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../asm/object.h"
#include "../isa/isa.h"
#include "../sim/config.h"
#include "../sim/core.h"
#include "../sim/run/timedcore.h"
#include "../sim/util.h"

#define X(OP, a, b, c, d, m, imm) {ISA_OP_##OP, (a), (b), (c), (d), (m), (uint32_t)(imm)}

#define CHUNK 100000ull
#define REPS 3

static uint32_t fbits(float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return u;
}

/* ---- the mixes ---------------------------------------------------------------------------------- */

static const IsaInstr vfloat_prog[] = {
    X(VLI, 1, 0, 0, 0, 0, 0x3F800347),     /* ~1.0001 */
    X(VLI, 2, 0, 0, 0, 0, 0x3F7FF972),     /* ~0.9999 */
    X(VLI, 3, 0, 0, 0, 0, 0x3F000000),     /* 0.5 */
    X(VLI, 4, 0, 0, 0, 0, 0x3E800000),     /* 0.25 */
    /* 4: loop -- no feedback, so the values stay normal numbers */
    X(VFMA, 5, 1, 2, 3, 0, 0),
    X(VFADD, 6, 5, 4, 0, 0, 0),
    X(VFMUL, 7, 6, 2, 0, 0, 0),
    X(VFSUB, 8, 7, 3, 0, 0, 0),
    X(VFMIN, 9, 8, 1, 0, 0, 0),
    X(VFMAX, 10, 9, 4, 0, 0, 0),
    X(VFMA, 11, 10, 2, 4, 0, 0),
    X(VFMUL, 12, 11, 1, 0, 0, 0),
    X(JMP, 0, 0, 0, 0, 0, 4),
};

enum { FIELD_X = 0, FIELD_Y = 4096 * 4, FIELD_Z = 2 * 4096 * 4, STREAM_IDS = 4096 };

static const IsaInstr filter_prog[] = {
    X(LI, 6, 0, 0, 0, 0, 0),                    /*  0 stream begin */
    X(LI, 7, 0, 0, 0, 0, 4 * STREAM_IDS),       /*  1 stream end */
    X(LI, 20, 0, 0, 0, 0, 0),                   /*  2 ray-buffer base */
    X(LI, 13, 0, 0, 0, 0, 0x3E800000),          /*  3 0.25 */
    X(VBCAST, 7, 13, 0, 0, 0, 0),               /*  4 */
    X(LI, 14, 0, 0, 0, 0, 0x3F400000),          /*  5 0.75 */
    X(VBCAST, 8, 14, 0, 0, 0, 0),               /*  6 */
    X(MOV, 9, 6, 0, 0, 0, 0),                   /*  7 outer */
    X(SFETCH, 4, 1, 9, 7, 0, 0),                /*  8 inner */
    X(RGAT, 5, 4, 20, 0, 1, FIELD_X),           /*  9 */
    X(RGAT, 6, 4, 20, 0, 1, FIELD_Y),           /* 10 */
    X(RGAT, 10, 4, 20, 0, 1, FIELD_Z),          /* 11 */
    X(VFADD, 11, 5, 10, 0, 1, 0),               /* 12 */
    X(VFLE, 2, 7, 5, 0, 1, 0),                  /* 13 0.25 <= x */
    X(VFLT, 3, 6, 8, 0, 1, 0),                  /* 14 y < 0.75 */
    X(MAND, 2, 2, 3, 0, 0, 0),                  /* 15 */
    X(PMASK, 2, 0, 0, 0, 0, 0),                 /* 16 */
    X(BLT, 9, 7, 0, 0, 0, 8),                   /* 17 */
    X(PART, 16, 6, 7, 0, 0, 0),                 /* 18 */
    X(JMP, 0, 0, 0, 0, 0, 7),                   /* 19 */
};

static const IsaInstr scalar_prog[] = {
    X(LI, 1, 0, 0, 0, 0, 0),                    /*  0 i */
    X(LI, 2, 0, 0, 0, 0, 12345),                /*  1 hash */
    X(LI, 3, 0, 0, 0, 0, 1000),                 /*  2 trip count */
    X(ADDI, 1, 1, 0, 0, 0, 1),                  /*  3 loop */
    X(XOR, 2, 2, 1, 0, 0, 0),                   /*  4 */
    X(SHLI, 4, 2, 0, 0, 0, 3),                  /*  5 */
    X(ADD, 2, 2, 4, 0, 0, 0),                   /*  6 */
    X(SHRI, 5, 2, 0, 0, 0, 7),                  /*  7 */
    X(XOR, 2, 2, 5, 0, 0, 0),                   /*  8 */
    X(ANDI, 6, 2, 0, 0, 0, 1),                  /*  9 */
    X(BEQ, 6, 0, 0, 0, 0, 12),                  /* 10 data-dependent (r0 = 0) */
    X(ADDI, 7, 7, 0, 0, 0, 1),                  /* 11 */
    X(SLTU, 8, 1, 3, 0, 0, 0),                  /* 12 */
    X(BNE, 8, 0, 0, 0, 0, 3),                   /* 13 */
    X(LI, 1, 0, 0, 0, 0, 0),                    /* 14 */
    X(JMP, 0, 0, 0, 0, 0, 3),                   /* 15 */
};

static const IsaInstr gather_prog[] = {
    X(VIOTA, 0, 0, 0, 0, 0, 0),                 /* 0 */
    X(VSHLI, 1, 0, 0, 0, 0, 6),                 /* 1 lane l at byte 64 l */
    X(LDG, 2, 1, 0, 0, 0, 0),                   /* 2 loop */
    X(LDG, 3, 1, 0, 0, 0, 4),                   /* 3 */
    X(LDG, 4, 1, 0, 0, 0, 8),                   /* 4 */
    X(LDG, 5, 1, 0, 0, 0, 12),                  /* 5 */
    X(VADDI, 1, 1, 0, 0, 0, 4096 + 64),         /* 6 next node, another line */
    X(VANDI, 1, 1, 0, 0, 0, 0x00FFFFC0),        /* 7 stay in the first 16 MiB */
    X(JMP, 0, 0, 0, 0, 0, 2),                   /* 8 */
};

static void setup_filter(Core *c)
{
    uint32_t size;
    uint8_t *idm = core_mem(c, CORE_MEM_IDM, &size);
    uint8_t *rb = core_mem(c, CORE_MEM_RB0, &size);
    uint32_t s = 1;
    for (uint32_t i = 0; i < STREAM_IDS; i++) {
        memcpy(idm + 4 * i, &i, 4);
        for (uint32_t f = 0; f < 3; f++) {
            s = s * 1664525u + 1013904223u;
            uint32_t v = fbits((float)(s >> 8) / 16777216.0f);
            memcpy(rb + f * 4 * STREAM_IDS + 4 * i, &v, 4);
        }
    }
}

typedef struct Mix {
    const char *name;
    const IsaInstr *prog;
    size_t n;
    void (*setup)(Core *c);
} Mix;

static const Mix mixes[] = {
    {"vfloat", vfloat_prog, sizeof vfloat_prog / sizeof vfloat_prog[0], NULL},
    {"filter", filter_prog, sizeof filter_prog / sizeof filter_prog[0], setup_filter},
    {"scalar", scalar_prog, sizeof scalar_prog / sizeof scalar_prog[0], NULL},
    {"gather", gather_prog, sizeof gather_prog / sizeof gather_prog[0], NULL},
};

/* ---- running ------------------------------------------------------------------------------------ */

/* One timed run of mix m at N = lanes on a fresh core. 0, or -1 after printing why. */
static int time_once(const Mix *m, int lanes, double target, uint64_t *instr, uint64_t *active, double *secs)
{
    AsmObject obj;
    memset(&obj, 0, sizeof obj);
    obj.ntext = (uint32_t)m->n;
    obj.text = malloc(sizeof(uint64_t) * m->n);
    if (!obj.text)
        return -1;
    for (size_t i = 0; i < m->n; i++)
        obj.text[i] = isa_encode(&m->prog[i]);
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.core_simd_width = lanes;
    char err[512];
    TimedCore tc; /* untimed: the functional core alone is measured */
    if (timedcore_open(&tc, &cfg, &obj, 0, err, sizeof err) != 0) {
        fprintf(stderr, "core_speed: %s: %s\n", m->name, err);
        free(obj.text);
        return -1;
    }
    Core *c = tc.core;
    if (m->setup)
        m->setup(c);
    double t0 = util_now(), t = 0;
    int rc = 0;
    do {
        CoreExit e = core_run(c, CHUNK);
        if (e != CORE_EXIT_LIMIT) {
            fprintf(stderr, "core_speed: %s at N = %d: %s\n", m->name, lanes, core_trap_message(c));
            rc = -1;
            break;
        }
        t = util_now() - t0;
    } while (t < target);
    const CoreStats *st = core_stats(c);
    *instr = core_instructions(c);
    *active = 0;
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        *active += st->active_lanes[s];
    *secs = t;
    timedcore_close(&tc);
    free(obj.text);
    return rc;
}

static int run_point(const Mix *m, int lanes, double target)
{
    double best = 0, best_secs = 0;
    uint64_t best_instr = 0, best_active = 0;
    for (int r = 0; r < REPS; r++) {
        uint64_t ni, na;
        double t;
        if (time_once(m, lanes, target, &ni, &na, &t) != 0)
            return -1;
        if ((double)ni / t > best) {
            best = (double)ni / t;
            best_instr = ni;
            best_active = na;
            best_secs = t;
        }
    }
    printf("| %-6s | %2d | %11llu | %6.3f | %9.1f | %12.1f |\n", m->name, lanes, (unsigned long long)best_instr,
           best_secs, 1e-6 * best, 1e-6 * (double)best_active / best_secs);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    double target = 0.3;
    if (argc > 1) {
        char *end;
        target = strtod(argv[1], &end);
        if (*end || !(target > 0) || target > 600) {
            fprintf(stderr, "usage: core_speed [SECONDS per point, default 0.3]\n");
            return 2;
        }
    }
    static const int widths[] = {4, 16, 64};
    printf("sfsim functional core: simulated instructions per host second (best of %d runs of %.2f s per point)\n\n",
           REPS, target);
    printf("| mix    |  N | sim. instr. | host s | M instr/s | M lane-ops/s |\n");
    printf("|--------|---:|------------:|-------:|----------:|-------------:|\n");
    int rc = 0;
    for (size_t m = 0; m < sizeof mixes / sizeof mixes[0]; m++)
        for (size_t w = 0; w < sizeof widths / sizeof widths[0]; w++)
            if (run_point(&mixes[m], widths[w], target) != 0)
                rc = 1;
    return rc;
}
