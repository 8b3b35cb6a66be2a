/* tools/validation.c -- the utilization and stream-length experiments of docs/validation.md:
 * the kernel on the functional core, measured the way Gribble & Ramani 2008 (seed 001,
 * Tables 2-4) and Wald et al. 2007 (seed 000, Tables 1-4) measure, printed as markdown tables
 * with the papers' figures beside ours. `make validation` writes docs/validation-data.md. Scenes are
 * opened and frames rendered through the entry point every command uses (sim/run/run.h).
 *
 * usage: validation [--quick] [--timing-only | --kd-only]   (--quick: smaller images, for a smoke
 *        run; --timing-only: only the detailed-mode and kd-tree tables; --kd-only: only the kd-tree table)
 *
 * Utilization = active lanes / (N x vector instructions) of a stage, over the generations the
 * experiment names: primary rays are generation 0 (camera rays only), secondary rays the later
 * generations (shadow and bounce rays), the n-th specular bounce generation n.
 */
#include <math.h>
#include <stdio.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

#include "../sim/config.h"
#include "../sim/ref_kd.h"
#include "../sim/ref_trace.h"
#include "../sim/run/accel.h"
#include "../sim/run/run.h"
#include "../sim/stats.h"
#include "../sim/timing.h"
#include "../sim/util.h"

typedef struct Loaded {
    const char *name, *path;
    RunScene sc;
    int open;
} Loaded;

static Loaded scenes[] = {
    {.name = "cornell", .path = "scenes/cornell/mcguire.ini"},
    {.name = "sponza", .path = "scenes/sponza-dabrovic/scene.ini"},
    {.name = "conference", .path = "scenes/conference/scene.ini"},
};
#define NSCENES 3

static int quick;

static void unload(Loaded *l)
{
    if (l->open)
        run_scene_close(&l->sc);
    l->open = 0;
}

/* (Re)open l at w x h pixels, spp (max_depth < 0: the scene's), with the default BVH and, when cfg
 * (NULL: the defaults) says accel.structure = kd, its kd-tree (sim/run/run.h). Exits on failure. */
static void load_cfg(Loaded *l, int w, int h, int spp, int max_depth, const CfgMachine *cfg)
{
    static char err[65536];
    unload(l);
    RunSize size = {w, h, spp, max_depth};
    l->open = 1;
    if (run_scene_open(&l->sc, l->path, &size, cfg, RUN_DETAILED, NULL, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", l->name, err);
        exit(1);
    }
}

static void load(Loaded *l, int w, int h, int spp, int max_depth)
{
    load_cfg(l, w, h, spp, max_depth, NULL);
}

typedef struct Run {
    RunFrame fr;
    int lanes;
} Run;

/* mode: 0 stream of M rays, 1 packets of N rays */
static int order = CFG_STREAM_ORDER_FIRST;

static int timed; /* detailed mode for the runs of Tables 5-6 */

/* l's frame through the kernel on the machine of cfg, in detailed mode when detailed, else
 * functional; 2 host threads. Exits on failure. */
static void run_cfg(const Loaded *l, const CfgMachine *cfg, int detailed, RunFrame *fr)
{
    static char err[65536];
    RunSpec spec = {.mode = detailed ? RUN_DETAILED : RUN_FUNCTIONAL, .cfg = cfg,
                    .kernel_path = "kernels/pathtrace.s", .seed = 1, .threads = 2};
    if (run_frame(&l->sc, &spec, fr, err, sizeof err) != 0) {
        fprintf(stderr, "%s: %s\n", l->name, err);
        exit(1);
    }
}

static void run(const Loaded *l, int lanes, int rays, int packet, int workload, int bounces, Run *r)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.stream_order = order;
    cfg.core_simd_width = lanes;
    cfg.stream_rays = rays;
    cfg.stream_mode = packet ? CFG_STREAM_MODE_PACKET : CFG_STREAM_MODE_STREAM;
    cfg.workload_kind = workload;
    if (bounces > 0)
        cfg.workload_bounces = bounces;
    run_cfg(l, &cfg, timed, &r->fr);
    r->lanes = lanes;
}

/* Utilization (percent) of a stage over generations [g0, g1) (sim/stats.h). */
static double util(const Run *r, int stage, int g0, int g1)
{
    return 100.0 * stats_utilization_gens(&r->fr.f.core, r->lanes, stage, g0, g1);
}

static double stream_len(const Run *r, int stage3, int g0)
{
    return stats_stream_length(&r->fr.f, stage3, g0, FUNC_MAX_GENERATIONS);
}

/* ---- seed 001 Table 2 (primary rays, T / I) and seed 000 Tables 1-2 ------------------------- */
static const char *t2_paper[3][3] = { /* [N 4,16,64][size packet,32,64]: rtrt, conf, kala */
    {"95/84 94/79 92/70", "97/89 95/80 95/90", "97/87 95/89 94/92"},
    {"90/70 91/64 87/55", "94/80 97/87 96/80", "93/79 96/88 96/83"},
    {"80/43 82/41 80/33", "89/50 91/72 89/55", "90/52 90/74 91/57"},
};

static void table2(void)
{
    int W = quick ? 128 : 512, H = quick ? 128 : 512;
    printf("## Primary rays: SIMD utilization T / I (seed 001 Table 2; seed 000 Tables 1, 2)\n\n");
    printf("%d x %d pixels, 1 sample per pixel, generation 0 only (camera rays); the packet row is\n"
           "stream.mode = packet (a stream of N rays, a sqrt(N) x sqrt(N) tile).\n\n", W, H);
    printf("| N | stream | cornell | sponza | conference | seed 001 (rtrt conf kala) |\n|---|---|---|---|---|---|\n");
    for (int i = 0; i < NSCENES; i++)
        load(&scenes[i], W, H, 1, 0);
    static const int ns[3] = {4, 16, 64};
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 3; b++) {
            int side = b == 0 ? (ns[a] == 4 ? 2 : ns[a] == 16 ? 4 : 8) : b == 1 ? 32 : 64;
            printf("| %d | %dx%d%s |", ns[a], side, side, b == 0 ? " (packet)" : "");
            for (int i = 0; i < NSCENES; i++) {
                Run r;
                run(&scenes[i], ns[a], b == 2 ? 4096 : 1024, b == 0, CFG_WORKLOAD_PATH, 0, &r);
                printf(" %.0f / %.0f |", util(&r, ISA_STAGE_TRAVERSAL, 0, 1), util(&r, ISA_STAGE_INTERSECTION, 0, 1));
                run_frame_free(&r.fr);
            }
            printf(" %s |\n", t2_paper[a][b]);
            fflush(stdout);
        }
    }
    printf("\n");
}

/* ---- seed 001 Tables 3 and 4 (secondary rays, T / I / S; stream lengths) ------------------- */
static const char *t3_paper[3][2] = {
    {"70/47/86 57/23/90 56/26/96", "77/55/93 70/31/95 67/31/95"},
    {"60/38/82 45/17/89 45/19/92", "70/46/92 61/24/96 56/25/97"},
    {"52/34/81 38/13/87 38/14/91", "65/42/89 54/18/94 49/20/96"},
};
static const char *t4_paper[3][2] = {
    {"rtrt 17.0 / 8.5 / 56.6", "rtrt 29.1 / 12.2 / 147.7"},
    {"conf 9.3 / 2.7 / 64.9", "conf 17.4 / 3.9 / 242.1"},
    {"kala 9.6 / 3.0 / 133.9", "kala 14.9 / 4.3 / 535.5"},
};

static void table3(void)
{
    int W = quick ? 64 : 256, H = quick ? 64 : 256, spp = quick ? 2 : 8;
    printf("## Secondary rays: SIMD utilization T / I / S (seed 001 Table 3)\n\n");
    printf("%d x %d pixels, %d samples per pixel, the scenes' max depth, generations >= 1 (shadow and\n"
           "bounce rays; camera rays excluded). Seed 001 used 64 samples per pixel. Rows marked *ray*\n"
           "use stream.order = ray (the default: every ray meets its own near child first, which splits\n"
           "streams by direction at every inner node); the others stream.order = first, as in the papers.\n\n",
           W, H, spp);
    printf("| N | stream | order | cornell | sponza | conference | seed 001 (rtrt conf kala) |\n"
           "|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < NSCENES; i++)
        load(&scenes[i], W, H, spp, -1);
    static const int ns[3] = {8, 12, 16};
    double len[2][NSCENES][2][3];
    int saved = order;
    for (int a = 0; a < 3; a++) {
        for (int b = 0; b < 2; b++) {
            for (int o = 0; o < 2; o++) {
                order = o ? CFG_STREAM_ORDER_RAY : CFG_STREAM_ORDER_FIRST;
                printf("| %d | %s | %s |", ns[a], b ? "64x64" : "32x32", o ? "*ray*" : "first");
                for (int i = 0; i < NSCENES; i++) {
                    Run r;
                    run(&scenes[i], ns[a], b ? 4096 : 1024, 0, CFG_WORKLOAD_PATH, 0, &r);
                    printf(" %.0f / %.0f / %.0f |", util(&r, ISA_STAGE_TRAVERSAL, 1, 64),
                           util(&r, ISA_STAGE_INTERSECTION, 1, 64), util(&r, ISA_STAGE_SHADING, 1, 64));
                    for (int k = 0; k < 3; k++)
                        len[o][i][b][k] = stream_len(&r, k, 1);
                    run_frame_free(&r.fr);
                }
                printf(" %s |\n", o ? "" : t3_paper[a][b]);
                fflush(stdout);
            }
        }
    }
    order = saved;
    printf("\n## Secondary rays: average stream length trav / isec / shade (seed 001 Table 4)\n\n");
    printf("The same runs (stream lengths do not depend on N: filtering decides per ray; the N = 16 runs).\n\n");
    printf("| stream | order | cornell | sponza | conference | seed 001 |\n|---|---|---|---|---|---|\n");
    for (int b = 0; b < 2; b++)
        for (int o = 0; o < 2; o++) {
            printf("| %s | %s |", b ? "64x64" : "32x32", o ? "*ray*" : "first");
            for (int i = 0; i < NSCENES; i++)
                printf(" %.1f / %.1f / %.1f |", len[o][i][b][0], len[o][i][b][1], len[o][i][b][2]);
            if (o)
                printf(" |\n");
            else
                printf(" %s; %s; %s |\n", t4_paper[0][b], t4_paper[1][b], t4_paper[2][b]);
        }
    printf("\n");
}

/* ---- seed 000 Table 3: n-bounce specular ----------------------------------------------------- */
static const char *s3_paper[2][5][2] = { /* [N 4,16][bounces 0,1,2,4,6][packet, stream]: erw6 conf fairy blade */
    {{"99/97 97/87 96/83 83/39", "99/99 99/98 99/97 96/61"},
     {"98/92 94/81 90/74 76/37", "99/99 99/97 98/93 92/55"},
     {"97/91 91/76 85/67 70/35", "99/99 99/96 97/89 89/52"},
     {"95/89 82/64 76/59 67/35", "99/99 97/90 94/82 88/50"},
     {"94/87 74/55 71/55 67/34", "99/98 95/83 92/78 87/49"}},
    {{"97/93 93/69 88/61 57/13", "99/99 98/93 97/85 80/18"},
     {"95/84 86/58 75/46 46/12", "99/98 97/88 92/71 66/15"},
     {"92/82 77/49 63/36 39/11", "99/97 95/80 86/59 60/14"},
     {"88/77 60/34 48/27 35/10", "98/96 87/62 74/45 55/13"},
     {"83/72 46/25 40/23 34/10", "97/94 79/46 67/38 54/13"}},
};

static void specular(void)
{
    int W = quick ? 64 : 256, H = quick ? 64 : 256;
    printf("## N-bounce specular rays: T / I, packet vs stream (seed 000 Table 3)\n\n");
    printf("%d x %d pixels, 1 sample per pixel, workload.kind = specular with 6 forced mirror bounces;\n"
           "bounce n is generation n. Packets of N rays (2x2, 4x4) against streams of 32 x 32 rays.\n\n",
           W, H);
    printf("| N | bounces | method | cornell | sponza | conference | seed 000 (erw6 conf fairy blade) |\n"
           "|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < NSCENES; i++)
        load(&scenes[i], W, H, 1, -1);
    static const int ns[2] = {4, 16};
    static const int bn[5] = {0, 1, 2, 4, 6};
    for (int a = 0; a < 2; a++) {
        Run r[2][NSCENES];
        for (int m = 0; m < 2; m++)
            for (int i = 0; i < NSCENES; i++)
                run(&scenes[i], ns[a], 1024, m == 0, CFG_WORKLOAD_SPECULAR, 6, &r[m][i]);
        for (int b = 0; b < 5; b++)
            for (int m = 0; m < 2; m++) {
                printf("| %d | %d | %s |", ns[a], bn[b], m == 0 ? (ns[a] == 4 ? "packet 2x2" : "packet 4x4") : "stream 32x32");
                for (int i = 0; i < NSCENES; i++)
                    printf(" %.0f / %.0f |", util(&r[m][i], ISA_STAGE_TRAVERSAL, bn[b], bn[b] + 1),
                           util(&r[m][i], ISA_STAGE_INTERSECTION, bn[b], bn[b] + 1));
                printf(" %s |\n", s3_paper[a][b][m]);
            }
        for (int m = 0; m < 2; m++)
            for (int i = 0; i < NSCENES; i++)
                run_frame_free(&r[m][i].fr);
        fflush(stdout);
    }
    printf("\n");
}

/* ---- seed 000 Table 4: one-bounce diffuse ----------------------------------------------------- */
static const char *s4_paper[2][3] = { /* erw6 conf fairy */
    {"92/85 89/72 71/53", "99/99 98/92 95/84", "99/99 99/95 97/90"},
    {"86/70 69/42 40/21", "99/96 91/70 79/49", "99/98 95/80 88/63"},
};

static void diffuse(void)
{
    int W = quick ? 32 : 128, H = quick ? 32 : 128, spp = 16;
    printf("## One-bounce diffuse rays: T / I, packet vs stream (seed 000 Table 4)\n\n");
    printf("%d x %d pixels, %d samples per pixel, workload.kind = diffuse; the bounce rays only\n"
           "(generation 1). Each sample pass is its own stream of tile pixels (seed 000 put the 16\n"
           "samples of a pixel into one stream).\n\n", W, H, spp);
    printf("| N | method | cornell | sponza | conference | seed 000 (erw6 conf fairy) |\n|---|---|---|---|---|---|\n");
    for (int i = 0; i < NSCENES; i++)
        load(&scenes[i], W, H, spp, -1);
    static const int ns[2] = {4, 16};
    for (int a = 0; a < 2; a++)
        for (int m = 0; m < 3; m++) {
            printf("| %d | %s |", ns[a],
                   m == 0 ? (ns[a] == 4 ? "packet 2x2" : "packet 4x4") : m == 1 ? "stream 32x32" : "stream 64x64");
            for (int i = 0; i < NSCENES; i++) {
                Run r;
                run(&scenes[i], ns[a], m == 2 ? 4096 : 1024, m == 0, CFG_WORKLOAD_DIFFUSE, 0, &r);
                printf(" %.0f / %.0f |", util(&r, ISA_STAGE_TRAVERSAL, 1, 2), util(&r, ISA_STAGE_INTERSECTION, 1, 2));
                run_frame_free(&r.fr);
            }
            printf(" %s |\n", s4_paper[a][m]);
            fflush(stdout);
        }
    printf("\n");
}


/* ---- seed 001 Tables 5 and 6: detailed mode ---------------------------------------------------- */
/* Table 6, fps at 500 MHz, 1024 x 1024, 64 spp: [N 8, 12, 16][32x32, 64x64] for rtrt, conf, kala */
static const char *t6_paper[3][2] = {
    {"16.60 / 8.15 / 6.73", "18.78 / 12.78 / 8.34"},
    {"21.82 / 12.56 / 11.78", "24.52 / 18.32 / 13.45"},
    {"22.36 / 14.35 / 13.34", "26.35 / 20.32 / 15.65"}};
/* Table 5, N = 16, 64x64: load, store, compute, scatter/gather, partition (%) */
static const char *t5_paper[3] = {"24.1 / 14.9 / 35.4 / 19.6 / 5.0", "23.2 / 19.7 / 34.5 / 18.7 / 3.8",
                                  "23.8 / 20.3 / 31.9 / 21.7 / 2.0"};
static const char *paper_name[3] = {"rtrt", "kala", "conf"}; /* beside cornell, sponza, conference */
static const int paper_col[3] = {0, 2, 1};                   /* column in the paper's tables */

static double pct(uint64_t a, uint64_t b) { return 100.0 * stats_ratio(a, b); }

static void timing_tables(void)
{
    const int widths[] = {4, 8, 12, 16, 32, 64};
    const int w = quick ? 64 : 128, h = quick ? 64 : 128, spp = quick ? 1 : 2;
    /* The paper's Table 1: rays per frame (rtrt, conf, kala) and its no-stall fps (Sec. 4.2). */
    static const double paper_rays[3] = {1.18e8, 1.62e8, 1.57e8}, paper_max_fps[3] = {100, 64, 32};
    printf("## Detailed mode: fps, stalls and operation mix (001 Tables 5 and 6)\n\n"
           "Detailed mode (the timing model, docs/model.md) on the default machine (500 MHz) with the N and\n"
           "stream size of each row; %d x %d pixels, %d spp, max depth 3 (the paper: 1024 x 1024, 64 spp,\n"
           "three bounces). *fps* is for our frame; *rel* is fps relative to N = 16 at the same stream size\n"
           "(ours and the paper's Table 6), the shape to compare. *rays/kc* is rays traced per 1000 cycles\n"
           "(the paper's: Table 1's rays per frame x Table 6's fps / 500 MHz). *stalled* is the share of\n"
           "cycles in which nothing issued (the paper's: 1 - fps / no-stall fps). The cause columns are\n"
           "percent of all cycles. Operation mix: percent of executed instructions in the paper's five\n"
           "categories, with integer and control apart (the paper folds them into load and store).\n\n",
           w, h, spp);
    for (int si = 0; si < NSCENES; si++) {
        Loaded *l = &scenes[si];
        load(l, w, h, spp, 3);
        int pc = paper_col[si];
        printf("### %s (beside %s)\n\n", l->name, paper_name[si]);
        printf("| M | N | cycles | fps | rel | paper rel | rays/kc | paper rays/kc | stalled | paper stalled | addr | bank | "
               "align | icn | fu | dep | part | spad | scene | ctrl | load | store | comp | s/g | part | int | ctrl | paper mix |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for (int mi = 0; mi < 2; mi++) {
            int rays = mi ? 4096 : 1024;
            Run runs[6];
            for (int wi = 0; wi < 6; wi++) {
                timed = 1;
                run(l, widths[wi], rays, 0, CFG_WORKLOAD_PATH, 0, &runs[wi]);
                timed = 0;
            }
            double paper_fps[6] = {0};
            for (int wi = 0; wi < 6; wi++) {
                int prow = widths[wi] == 8 ? 0 : widths[wi] == 12 ? 1 : widths[wi] == 16 ? 2 : -1;
                if (prow < 0)
                    continue;
                char tmp[64];
                snprintf(tmp, sizeof tmp, "%s", t6_paper[prow][mi]);
                char *save = NULL, *tok = strtok_r(tmp, "/", &save);
                for (int k = 0; k < pc && tok; k++)
                    tok = strtok_r(NULL, "/", &save);
                paper_fps[wi] = tok ? atof(tok) : 0.0;
            }
            const uint64_t c16 = runs[3].fr.f.timing.cycles;
            for (int wi = 0; wi < 6; wi++) {
                Run *r = &runs[wi];
                const FuncStats *f = &r->fr.f;
                const TimingStats *t = &f->timing;
                uint64_t nrays = stats_rays_total(f);
                char prel[16] = "", prk[16] = "", pst[16] = "";
                if (paper_fps[wi] > 0) {
                    snprintf(prel, sizeof prel, "%.2f", paper_fps[wi] / paper_fps[3]);
                    snprintf(prk, sizeof prk, "%.0f", 1000.0 * paper_rays[pc] * paper_fps[wi] / 500e6);
                    snprintf(pst, sizeof pst, "%.0f", 100.0 * (1.0 - paper_fps[wi] / paper_max_fps[pc]));
                }
                uint64_t ops[ISA_C_COUNT] = {0}, all = 0;
                for (int c = 0; c < ISA_C_COUNT; c++) {
                    ops[c] = stats_ops(&f->core, c);
                    all += ops[c];
                }
                printf("| %s | %d | %llu | %.1f | %.2f | %s | %.1f | %s | %.0f | %s |", mi ? "64x64" : "32x32",
                       widths[wi], (unsigned long long)t->cycles, stats_frame(t, f->instructions, 500, NULL).fps,
                       t->cycles ? (double)c16 / (double)t->cycles : 0.0, prel,
                       t->cycles ? 1000.0 * (double)nrays / (double)t->cycles : 0.0, prk,
                       pct(t->cycles - t->busy, t->cycles), pst);
                for (int c = 0; c < TM_CAUSE_COUNT; c++)
                    printf(" %.1f |", 100.0 * stats_stall_share(t, c));
                printf(" %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %s |\n", pct(ops[ISA_C_LOAD], all),
                       pct(ops[ISA_C_STORE], all), pct(ops[ISA_C_COMPUTE], all), pct(ops[ISA_C_SCATGATH], all),
                       pct(ops[ISA_C_PARTITION], all), pct(ops[ISA_C_INTEGER], all), pct(ops[ISA_C_CONTROL], all),
                       mi && widths[wi] == 16 ? t5_paper[pc] : "");
            }
            for (int wi = 0; wi < 6; wi++)
                run_frame_free(&runs[wi].fr);
            fflush(stdout);
        }
        printf("\n");
    }
}

/* ---- seed 004: the kd-tree traversal family (golden model) ------------------------------------ */
static void kd_tables(void)
{
    static const char *const names[3] = {"cornell", "toy-car", "conference"};
    static const char *const paths[3] = {"scenes/cornell/mcguire.ini", "scenes/toy-car/scene.ini",
                                         "scenes/conference/scene.ini"};
    const int w = quick ? 64 : 256, h = quick ? 64 : 256;
    printf("## kd-tree traversals: nodes visited relative to the full stack (seed 004)\n\n"
           "Golden model (sim/ref_kd.c), camera rays through pixel centres of a %d x %d image (pinhole),\n"
           "closest hit; kd-tree of scenes/kdtree.c with the paper's costs (intersection = traversal step).\n"
           "Each variant's nodes visited (inner nodes and leaves) divided by the full stack's. The paper:\n"
           "push-down visits 3-22 %% fewer nodes than restart on its complex scenes, short-stack a further\n"
           "48-52 %% fewer, a 3-entry short stack is within 3 %% of the full stack.\n\n"
           "| scene | triangles | kd nodes | depth | stack nodes/ray | restart | push-down | short 1 | short 2 | short 3 | "
           "short 4 | short 8 | push-down vs restart | short 3 vs push-down |\n"
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
           w, h);
    for (int si = 0; si < 3; si++) {
        Loaded l = {.name = names[si], .path = paths[si]};
        load(&l, w, h, 1, -1);
        KdParams kp;
        kd_default_params(&kp);
        KdTree t;
        char err[1024];
        if (accel_kd_build(&l.sc.p, &kp, &t, err, sizeof err) != 0) {
            fprintf(stderr, "%s: %s\n", l.name, err);
            exit(1);
        }
        static const int depths[5] = {1, 2, 3, 4, 8};
        RefKdStats st[8];
        memset(st, 0, sizeof st);
        const PackedScene *p = &l.sc.p;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                RefRay r;
                float px = ((float)x + 0.5f) / (float)w - 0.5f, py = 0.5f - ((float)y + 0.5f) / (float)h;
                float len = 0.0f;
                for (int k = 0; k < 3; k++) {
                    r.org[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_POS + k));
                    r.dir[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_W + k)) + px * sm_f32(p, sm_hdr(p, SM_HDR_CAM_U + k)) +
                               py * sm_f32(p, sm_hdr(p, SM_HDR_CAM_V + k));
                    len += r.dir[k] * r.dir[k];
                }
                len = sqrtf(len);
                for (int k = 0; k < 3; k++)
                    r.dir[k] /= len;
                r.tmax = INFINITY;
                RefHit hh;
                for (int vi = 0; vi < 3; vi++)
                    ref_kd_closest_hit(p, &t, (RefKdVariant)vi, 0, &r, &hh, &st[vi]);
                for (int di = 0; di < 5; di++)
                    ref_kd_closest_hit(p, &t, REF_KD_SHORTSTACK, depths[di], &r, &hh, &st[3 + di]);
            }
        double base = (double)st[0].nodes_visited;
        printf("| %s | %u | %u | %u | %.1f |", l.name, p->nprims, t.nnodes, t.depth, base / ((double)w * h));
        for (int i = 1; i < 8; i++)
            printf(" %.3f |", (double)st[i].nodes_visited / base);
        printf(" %.1f %% fewer | %.1f %% fewer |\n",
               100.0 * (1.0 - (double)st[2].nodes_visited / (double)st[1].nodes_visited),
               100.0 * (1.0 - (double)st[5].nodes_visited / (double)st[2].nodes_visited));
        fflush(stdout);
        kd_free(&t);
        unload(&l);
    }
    printf("\n");
}

/* The kd-tree kernels on the default machine (detailed mode) against the BVH stream-filter
 * kernel: the same frame, every variant; cycles, fps, the same image or not, and the kernels'
 * own counters per ray. */
typedef struct KdRow {
    const char *label, *traversal;
    int depth;
} KdRow;

static const KdRow kd_rows[] = {
        {"BVH stream filter", NULL, 0},  {"kd stack", "stack", 3},          {"kd restart", "restart", 3},
        {"kd push-down", "pushdown", 3}, {"kd short 1", "shortstack", 1},   {"kd short 2", "shortstack", 2},
        {"kd short 3", "shortstack", 3}, {"kd short 4", "shortstack", 4},   {"kd short 8", "shortstack", 8},
        {"kd packet 3", "packet", 3},    {"kd packet 8", "packet", 8},      {"kd stream filter", "stream", 3},
};

/* One row of a kd-kernel table: st, the frame of row (its image compared with ref's: NULL for the
 * BVH row itself), cycles relative to the BVH row's. */
static void kd_kernel_row(const KdRow *row, int workload, const RunFrame *fr, const RunFrame *ref, int lanes,
                          uint64_t bvh_cycles, size_t n)
{
    const FuncStats *st = &fr->f;
    const TimingStats *t = &st->timing;
    double tu = 100.0 * stats_utilization_cycles(st, lanes, ISA_STAGE_TRAVERSAL);
    const char *same = !ref ? "-" : memcmp(ref->rgb, fr->rgb, n * sizeof(float)) == 0 ? "same" : "DIFFERS";
    double rel = bvh_cycles ? (double)t->cycles / (double)bvh_cycles : 0.0;
    double fps = stats_frame(t, st->instructions, 500, NULL).fps;
    if (workload == CFG_WORKLOAD_PHONG) {
        printf("| %s | %llu | %.2f | %.2f | %s | %.1f |", row->label, (unsigned long long)t->cycles, fps, rel,
               same, tu);
        char bounce[32] = "-";
        if (st->rays_indirect)
            snprintf(bounce, sizeof bounce, "%.1f", stats_kd_per_ray(st, FUNC_KD_INDIRECT, FUNC_KD_NODES));
        if (st->kd)
            printf(" %.1f | %.1f | %s | %.3f |\n", stats_kd_per_ray(st, FUNC_KD_CAMERA, FUNC_KD_NODES),
                   stats_kd_per_ray(st, FUNC_KD_SHADOW, FUNC_KD_NODES), bounce,
                   stats_kd_per_ray(st, FUNC_KD_KINDS, FUNC_KD_RESTARTS));
        else
            printf(" | | | |\n");
    } else {
        printf("| %s | %llu | %llu | %.2f | %.2f | %s | %.1f |", row->label, (unsigned long long)st->instructions,
               (unsigned long long)t->cycles, fps, rel, same, tu);
        if (st->kd)
            printf(" %.1f | %.1f | %.1f | %.3f | %.3f |\n", stats_kd_per_ray(st, FUNC_KD_CAMERA, FUNC_KD_NODES),
                   stats_kd_per_ray(st, FUNC_KD_KINDS, FUNC_KD_NODES),
                   stats_kd_per_ray(st, FUNC_KD_KINDS, FUNC_KD_PRIMS),
                   stats_kd_per_ray(st, FUNC_KD_KINDS, FUNC_KD_RESTARTS),
                   stats_kd_per_ray(st, FUNC_KD_KINDS, FUNC_KD_OVERFLOWS));
        else
            printf(" | | | | |\n");
    }
    fflush(stdout);
}

/* One scene: the kernels of rows[] (rows[0] the BVH), on the workload given; prints a table. */
static void kd_kernel_scene(const char *name, const char *path, int w, int h, int workload, int bounces,
                            const int *rows, int nrows)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.workload_kind = workload;
    cfg.workload_bounces = bounces;
    CfgErrors ce = {0};
    if (cfg_set(&cfg, "accel.structure=kd", &ce) != 0) {
        fprintf(stderr, "%s: %s\n", name, ce.text ? ce.text : "");
        exit(1);
    }
    /* One scene memory for every row: the BVH and the kd-tree of the kd.* keys (the BVH row
     * ignores the tree). */
    Loaded l = {.name = name, .path = path};
    load_cfg(&l, w, h, 1, 3, &cfg);
    const AccelKdInfo *info = &l.sc.accel.kd;
    if (workload == CFG_WORKLOAD_PHONG)
        printf("### %s, Phong, %d bounce%s (%u triangles; kd-tree %u nodes, depth %u)\n\n"
               "| kernel | cycles | fps | rel | image | trav util | nodes/camera ray | nodes/shadow ray | "
               "nodes/bounce ray | restarts/ray |\n|---|---|---|---|---|---|---|---|---|---|\n",
               l.name, bounces, bounces == 1 ? "" : "s", l.sc.s.ntris, info->nodes, info->depth);
    else
        printf("### %s (%u triangles; kd-tree %u nodes, depth %u)\n\n"
               "| kernel | instructions | cycles | fps | rel | image | trav util | camera nodes/ray | nodes/ray | "
               "prims/ray | restarts/ray | overflows/ray |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
               l.name, l.sc.s.ntris, info->nodes, info->depth);
    size_t n = 3 * (size_t)w * h;
    RunFrame ref;
    uint64_t bvh_cycles = 0;
    for (int i = 0; i < nrows; i++) {
        const KdRow *row = &kd_rows[rows[i]];
        CfgMachine c = cfg;
        char a[96];
        if (!row->traversal) {
            cfg_set(&c, "accel.structure=bvh", &ce);
        } else {
            snprintf(a, sizeof a, "kd.traversal=%s", row->traversal);
            cfg_set(&c, a, &ce);
            snprintf(a, sizeof a, "kd.stack_depth=%d", row->depth);
            cfg_set(&c, a, &ce);
        }
        RunFrame fr;
        run_cfg(&l, &c, 1, &fr);
        if (i == 0)
            bvh_cycles = fr.f.timing.cycles;
        kd_kernel_row(row, workload, &fr, i ? &ref : NULL, c.core_simd_width, bvh_cycles, n);
        if (i == 0)
            ref = fr; /* the BVH kernel's image, kept for the kd rows */
        else
            run_frame_free(&fr);
    }
    if (nrows > 0)
        run_frame_free(&ref);
    cfg_errors_free(&ce);
    printf("\n");
    unload(&l);
}

static void kd_kernel_tables(void)
{
    static const char *const names[3] = {"cornell", "toy-car", "conference"};
    static const char *const paths[3] = {"scenes/cornell/mcguire.ini", "scenes/toy-car/scene.ini",
                                         "scenes/conference/scene.ini"};
    const int all[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}, few[] = {0, 1, 2, 3, 6, 9, 11};
    const int w = quick ? 32 : 128, h = quick ? 32 : 128;
    printf("## kd-tree kernels against the BVH kernel: cycles and fps (seed 004 on our machine)\n\n"
           "Detailed mode on the default machine (N = 16, streams of 64 x 64 rays, 500 MHz); the path\n"
           "tracer, %d x %d pixels, 1 spp, max depth 3; the same kd-tree (paper costs) for every kd row.\n"
           "*image*: bit-identical to the BVH kernel's. *rel*: cycles relative to the BVH kernel's. *trav\n"
           "util*: SIMD utilization of the traversal stage (timed). *nodes/ray*: the kernels' counters, inner\n"
           "nodes and leaves entered per ray (camera rays; all rays); *prims/ray*, *restarts/ray* all rays.\n\n",
           w, h);
    for (int si = 0; si < 3; si++)
        kd_kernel_scene(names[si], paths[si], w, h, CFG_WORKLOAD_PATH, 0, all, 12);
    printf("The paper's workloads (seed 004 Sec. 5): Sponza (66,450 triangles, one light) rendered with\n"
           "workload.kind = phong -- camera rays, one shadow ray per light per hit carrying local Phong\n"
           "shading, and 0, 1 or 3 mirror bounces (docs/golden-model.md); %d x %d pixels, 1 spp. Nodes per\n"
           "ray by ray kind.\n\n", w, h);
    for (int b = 0; b <= 3; b += b ? 2 : 1)
        kd_kernel_scene("sponza", "scenes/sponza-dabrovic/scene.ini", w, h, CFG_WORKLOAD_PHONG, b, few, 7);
}

int main(int argc, char **argv)
{
    int timing_only = 0, kd_only = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick"))
            quick = 1;
        else if (!strcmp(argv[i], "--timing-only"))
            timing_only = 1;
        else if (!strcmp(argv[i], "--kd-only"))
            kd_only = 1;
    }
    struct stat sh;
    if (stat("../shared/scenes/README.md", &sh) != 0) {
        fprintf(stderr, "validation: needs ../shared (the project's test scenes beside the repository), which is "
                        "absent: every table uses its scenes\n");
        return 1;
    }
    double t0 = util_now();
    printf("# Validation data\n\n<!-- GENERATED by tools/validation.c (make validation); do not edit. "
           "docs/validation.md discusses these numbers. -->\n\n");
    printf("Machine: the default config (sim/config.def) with the N and stream size of each row, and\n"
           "stream.order = first (the stream follows its first ray's near child, as the papers' traversal\n"
           "does) unless a row says *ray*. Percent, rounded. Our scenes: cornell (scenes/cornell/mcguire.ini: 36 triangles, 2 lights), sponza (66K triangles, textures,\n"
           "punctual lights), conference (331K triangles, 72 quad lights).\n\n");
    if (!timing_only && !kd_only) {
        table2();
        table3();
        specular();
        diffuse();
    }
    if (!kd_only)
        timing_tables();
    kd_tables();
    kd_kernel_tables();
    fprintf(stderr, "validation: %.0f s\n", util_now() - t0);
    for (int i = 0; i < NSCENES; i++)
        unload(&scenes[i]);
    return 0;
}
