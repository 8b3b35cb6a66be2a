/* tests/unit/test_timeline.c -- `--timeline`: a run's timeline in the Chrome trace event format
 * (sim/timeline.h, docs/timeline.md).
 *
 * What must hold: the file is the format's JSON object form (traceEvents; every event a known
 * phase with its fields; every async slice begun is ended, no earlier than it began); on each
 * core's issue thread the spans tile the window without gap or overlap; over a window covering
 * the run, each core's busy, stall (by cause, scene_memory by where the data came from) and idle
 * spans add up to exactly the report's counts; a window clips them; watching changes no result;
 * and the exec pipeline trace has one slice per instruction, issued in order.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../scenes/pack.h"
#include "../../scenes/scene.h"
#include "../../sim/chip/chip.h"
#include "../../sim/config.h"
#include "../../sim/run/engine.h"
#include "../../sim/timeline.h"
#include "../../sim/timing.h"

#include "../support/files.h"
#include "../support/packed.h"

static Scene scene;
static PackedScene packed;

static void load(void) { packed_load("scenes/cornell/scene.ini", 64, 64, 1, &scene, &packed); }
static void unload(void) { packed_free(&scene, &packed); }

/* 64 x 64 pixels in 32 x 32 tiles: 4 tiles. */
static void small_frame(CfgMachine *cfg, int cores, int shared)
{
    cfg_defaults(cfg);
    cfg->stream_rays = 1024;
    cfg->chip_cores = cores;
    if (shared) {
        cfg->chip_memory = CFG_CHIP_MEMORY_SHARED;
        cfg->chip_cold_units = 0;
        cfg->l2_size_kb = 64;
        cfg->l2_banks = 4;
        cfg->noc_latency = 4;
    }
}

static void render(const CfgMachine *cfg, Timeline *tl, FuncStats *st)
{
    size_t n = 3 * (size_t)scene.render.width * scene.render.height;
    float *rgb = calloc(n, sizeof *rgb);
    static char err[65536];
    FuncParams fp = {.cfg = cfg, .kernel_path = "kernels/pathtrace.s", .needs = scene.needs, .seed = 1,
                     .threads = 2, .timed = 1, .timeline = tl};
    cr_assert_eq(func_render(&packed, &fp, rgb, st, err, sizeof err), 0, "%s", err);
    free(rgb);
}

static cJSON *write_and_parse(const Timeline *tl, const char *name)
{
    char path[256], err[512];
    snprintf(path, sizeof path, "/tmp/sfsim-test-timeline-%d-%s.json", (int)getpid(), name);
    cr_assert_eq(timeline_write(tl, path, err, sizeof err), 0, "%s", err);
    char *text = tu_slurp(path);
    cr_assert_not_null(text, "%s: not readable", path);
    cJSON *doc = cJSON_Parse(text);
    cr_assert_not_null(doc, "%s: not JSON", path);
    free(text);
    remove(path);
    return doc;
}

/* The format's rules for each event; async slices matched by (cat, id). */
static void check_format(const cJSON *doc)
{
    cr_assert(cJSON_IsObject(doc));
    const cJSON *evs = cJSON_GetObjectItemCaseSensitive(doc, "traceEvents");
    cr_assert(cJSON_IsArray(evs), "traceEvents is an array");
    cr_assert_gt(cJSON_GetArraySize(evs), 0);
    int open = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, evs) {
        const cJSON *ph = cJSON_GetObjectItemCaseSensitive(e, "ph");
        cr_assert(cJSON_IsString(ph), "every event has a phase");
        cr_assert(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(e, "pid")), "every event has a pid");
        cr_assert(cJSON_IsString(cJSON_GetObjectItemCaseSensitive(e, "name")), "every event has a name");
        const char p = ph->valuestring[0];
        cr_assert(strchr("MXbeC", p) && ph->valuestring[1] == 0, "phase %s", ph->valuestring);
        if (p == 'M')
            continue;
        const cJSON *ts = cJSON_GetObjectItemCaseSensitive(e, "ts");
        cr_assert(cJSON_IsNumber(ts) && ts->valuedouble >= 0, "a timed event has ts >= 0");
        if (p == 'X') {
            const cJSON *dur = cJSON_GetObjectItemCaseSensitive(e, "dur");
            cr_assert(cJSON_IsNumber(dur) && dur->valuedouble > 0, "a span lasts");
            cr_assert(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(e, "tid")));
        }
        if (p == 'b' || p == 'e') {
            cr_assert(cJSON_IsString(cJSON_GetObjectItemCaseSensitive(e, "cat")));
            cr_assert(cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(e, "id")));
            open += p == 'b' ? 1 : -1;
        }
        if (p == 'C')
            cr_assert(cJSON_IsObject(cJSON_GetObjectItemCaseSensitive(e, "args")), "a counter has its values");
    }
    cr_assert_eq(open, 0, "every async slice begun is ended");
    /* each end after its begin: the writer puts them next to each other */
    const cJSON *prev = NULL;
    cJSON_ArrayForEach(e, evs) {
        const char p = cJSON_GetObjectItemCaseSensitive(e, "ph")->valuestring[0];
        if (p == 'e') {
            cr_assert_not_null(prev);
            cr_assert_eq(cJSON_GetObjectItemCaseSensitive(prev, "ph")->valuestring[0], 'b');
            cr_assert_eq(cJSON_GetObjectItemCaseSensitive(prev, "id")->valuedouble,
                         cJSON_GetObjectItemCaseSensitive(e, "id")->valuedouble);
            cr_assert_geq(cJSON_GetObjectItemCaseSensitive(e, "ts")->valuedouble,
                          cJSON_GetObjectItemCaseSensitive(prev, "ts")->valuedouble);
        }
        prev = e;
    }
}

typedef struct Sums {
    uint64_t busy, idle, stalls[TM_CAUSE_COUNT], from[2];
    uint64_t first, end;       /* the issue thread's extent */
    int spans;
} Sums;

/* Core k's (pid k + 1) issue thread: spans back to back, summed by name. */
static Sums issue_sums(const cJSON *doc, int k)
{
    Sums s;
    memset(&s, 0, sizeof s);
    const cJSON *e;
    uint64_t at = 0;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(doc, "traceEvents")) {
        if (strcmp(cJSON_GetObjectItemCaseSensitive(e, "ph")->valuestring, "X") ||
            cJSON_GetObjectItemCaseSensitive(e, "pid")->valueint != k + 1 ||
            cJSON_GetObjectItemCaseSensitive(e, "tid")->valueint != 0)
            continue;
        const uint64_t ts = (uint64_t)cJSON_GetObjectItemCaseSensitive(e, "ts")->valuedouble;
        const uint64_t dur = (uint64_t)cJSON_GetObjectItemCaseSensitive(e, "dur")->valuedouble;
        if (s.spans++ == 0)
            s.first = ts;
        else
            cr_assert_eq(ts, at, "core %d: the issue thread's spans are back to back (%llu after %llu)", k,
                         (unsigned long long)ts, (unsigned long long)at);
        at = ts + dur;
        const char *name = cJSON_GetObjectItemCaseSensitive(e, "name")->valuestring;
        if (!strcmp(name, "busy")) {
            s.busy += dur;
        } else if (!strcmp(name, "idle")) {
            s.idle += dur;
        } else if (!strcmp(name, "stall: scene_memory (l2)")) {
            s.from[TIMING_FROM_L2] += dur;
            s.stalls[TM_SCENE_MEMORY] += dur;
        } else if (!strcmp(name, "stall: scene_memory (dram)")) {
            s.from[TIMING_FROM_DRAM] += dur;
            s.stalls[TM_SCENE_MEMORY] += dur;
        } else {
            int found = 0;
            for (int c = 0; c < TM_CAUSE_COUNT; c++) {
                char want[64];
                snprintf(want, sizeof want, "stall: %s", tm_cause_keys[c]);
                if (!strcmp(name, want)) {
                    s.stalls[c] += dur;
                    found = 1;
                }
            }
            cr_assert(found, "an issue span named %s", name);
        }
    }
    s.end = at;
    return s;
}

static void check_core(const Sums *s, int k, uint64_t busy, const uint64_t *stalls, uint64_t idle, uint64_t makespan)
{
    cr_assert_eq(s->first, 0, "core %d: from cycle 0", k);
    cr_assert_eq(s->end, makespan, "core %d: to the makespan %llu (%llu)", k, (unsigned long long)makespan,
                 (unsigned long long)s->end);
    cr_expect_eq(s->busy, busy, "core %d: busy %llu on the timeline, %llu in the report", k,
                 (unsigned long long)s->busy, (unsigned long long)busy);
    cr_expect_eq(s->idle, idle, "core %d: idle %llu, %llu", k, (unsigned long long)s->idle, (unsigned long long)idle);
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        cr_expect_eq(s->stalls[c], stalls[c], "core %d: %s %llu on the timeline, %llu in the report", k,
                     tm_cause_keys[c], (unsigned long long)s->stalls[c], (unsigned long long)stalls[c]);
}

TestSuite(timeline, .init = load, .fini = unload, .timeout = 300);

/* The paper's machine (its tiles back to back): the timeline's spans are the frame's counts. */
Test(timeline, one_core_adds_up)
{
    CfgMachine cfg;
    small_frame(&cfg, 1, 0);
    FuncStats plain, st;
    render(&cfg, NULL, &plain);
    Timeline *tl = timeline_new(0, UINT64_MAX, 1, cfg.core_clock_mhz, 0);
    cr_assert_not_null(tl);
    render(&cfg, tl, &st);
    cr_assert_eq(st.timing.cycles, plain.timing.cycles, "watching changes no cycle");
    cr_assert_eq(memcmp(st.timing.stalls, plain.timing.stalls, sizeof st.timing.stalls), 0);
    cJSON *doc = write_and_parse(tl, "one");
    check_format(doc);
    const Sums s = issue_sums(doc, 0);
    check_core(&s, 0, st.timing.busy, st.timing.stalls, 0, st.timing.cycles);
    cr_assert_gt(s.stalls[TM_SCENE_MEMORY], 0, "the frame has scene-memory stalls to show");
    cJSON_Delete(doc);
    timeline_free(tl);
    func_stats_free(&plain);
    func_stats_free(&st);
}

/* Four cores sharing an L2 and DRAM: every core's busy, stalls by cause and by level, and idle. */
Test(timeline, chip_adds_up)
{
    CfgMachine cfg;
    small_frame(&cfg, 4, 1);
    FuncStats plain, st;
    render(&cfg, NULL, &plain);
    Timeline *tl = timeline_new(0, UINT64_MAX, 4, cfg.core_clock_mhz, 0);
    cr_assert_not_null(tl);
    render(&cfg, tl, &st);
    cr_assert_eq(st.makespan, plain.makespan, "watching changes no cycle");
    cJSON *doc = write_and_parse(tl, "chip");
    check_format(doc);
    uint64_t from[2] = {0, 0};
    for (int k = 0; k < 4; k++) {
        const FuncCore *fc = &st.cores[k];
        const Sums s = issue_sums(doc, k);
        check_core(&s, k, fc->busy, fc->stalls, fc->idle, st.makespan);
        from[0] += s.from[0];
        from[1] += s.from[1];
    }
    cr_expect_eq(from[0], st.timing.scene_from[0], "scene_memory (l2): %llu, %llu", (unsigned long long)from[0],
                 (unsigned long long)st.timing.scene_from[0]);
    cr_expect_eq(from[1], st.timing.scene_from[1], "scene_memory (dram): %llu, %llu", (unsigned long long)from[1],
                 (unsigned long long)st.timing.scene_from[1]);
    /* the shared levels' requests are on it: as many into DRAM as DRAM counted */
    uint64_t dram = 0;
    const cJSON *e;
    cJSON_ArrayForEach(e, cJSON_GetObjectItemCaseSensitive(doc, "traceEvents")) {
        const cJSON *cat = cJSON_GetObjectItemCaseSensitive(e, "cat");
        dram += cJSON_IsString(cat) && !strcmp(cat->valuestring, "dram") &&
                !strcmp(cJSON_GetObjectItemCaseSensitive(e, "ph")->valuestring, "b");
    }
    cr_assert_gt(dram, 0);
    cr_expect_eq(dram, st.chip_mem->dram.reads + st.chip_mem->dram.writes, "DRAM requests: %llu on the timeline",
                 (unsigned long long)dram);
    cJSON_Delete(doc);
    timeline_free(tl);
    func_stats_free(&plain);
    func_stats_free(&st);
}

/* A window: the issue thread covers exactly its cycles. */
Test(timeline, window_clips)
{
    CfgMachine cfg;
    small_frame(&cfg, 1, 0);
    Timeline *tl = timeline_new(1000, 21000, 1, cfg.core_clock_mhz, 0);
    cr_assert_not_null(tl);
    FuncStats st;
    render(&cfg, tl, &st);
    cr_assert_gt(st.timing.cycles, 21000);
    cJSON *doc = write_and_parse(tl, "window");
    check_format(doc);
    const Sums s = issue_sums(doc, 0);
    cr_assert_eq(s.first, 1000);
    cr_assert_eq(s.end, 21000);
    uint64_t stall = 0;
    for (int c = 0; c < TM_CAUSE_COUNT; c++)
        stall += s.stalls[c];
    cr_assert_eq(s.busy + stall + s.idle, 20000);
    cr_assert_eq(s.idle, 0);
    cJSON_Delete(doc);
    timeline_free(tl);
    func_stats_free(&st);
}

Test(timeline, window_parse)
{
    uint64_t f, t;
    char err[300];
    cr_assert_eq(timeline_parse_window("5:10", &f, &t, err, sizeof err), 0);
    cr_assert(f == 5 && t == 10);
    cr_assert_eq(timeline_parse_window("5000:", &f, &t, err, sizeof err), 0);
    cr_assert(f == 5000 && t == 5000 + TIMELINE_DEFAULT_CYCLES);
    cr_assert_eq(timeline_parse_window(":7", &f, &t, err, sizeof err), 0);
    cr_assert(f == 0 && t == 7);
    const char *bad[] = {"10:5", "5:5", "x:1", "1:2:3", "12", "-1:5", "99999999999999999999999:1", ""};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++)
        cr_assert_eq(timeline_parse_window(bad[i], &f, &t, err, sizeof err), -1, "'%s' refused", bad[i]);
}
