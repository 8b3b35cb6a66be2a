/* tests/unit/test_stats_txt.c -- stats.txt (sim/stats_text.c stats_gem5, sim/report.c,
 * docs/report.md): written for every run, in every mode, and the same as report.json value for
 * value. Each report.json number whose path is a row of sim/stats.def (matched here against the
 * row's path pattern, independently of the walk) is in stats.txt under its gem5 name with the same
 * value, and every stats.txt line is such a number or a "::total" that is the sum of its vector.
 */
#include <cjson/cJSON.h>
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../host/version.h"
#include "../../sim/config.h"
#include "../../sim/render.h"
#include "../../sim/stats.h"
#include "../support/files.h"

#define BEGIN "---------- Begin Simulation Statistics ----------"
#define END "---------- End Simulation Statistics   ----------"

typedef struct Line {
    char name[256];
    double value;
    int used;
} Line;

typedef struct Txt {
    Line *l;
    int n;
} Txt;

/* stats.txt's statistics: every line between gem5's markers is "name value # description (unit)". */
static Txt parse_stats_txt(char *text)
{
    Txt t = {calloc(20000, sizeof(Line)), 0};
    cr_assert_not_null(t.l);
    char want_head[128];
    snprintf(want_head, sizeof want_head, "# sfsim %s (commit %s), mode ", version_string(), version_commit());
    cr_expect(!strncmp(text, want_head, strlen(want_head)), "stats.txt does not open with the version: %.80s", text);
    char *b = strstr(text, "\n" BEGIN "\n"), *e = strstr(text, "\n" END "\n");
    cr_assert(b && e && b < e, "stats.txt lacks gem5's Begin and End lines");
    *e = '\0';
    for (char *save = NULL, *line = strtok_r(b + strlen(BEGIN) + 2, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char name[256], rest[2048];
        double v;
        int k = sscanf(line, "%255s %lf %2047[^\n]", name, &v, rest);
        cr_assert_eq(k, 3, "not a statistic's line: %s", line);
        cr_expect(!strncmp(rest, "# ", 2) && rest[strlen(rest) - 1] == ')', "no '# description (unit)': %s", line);
        for (int i = 0; i < t.n; i++)
            cr_assert(strcmp(t.l[i].name, name), "%s twice in stats.txt", name);
        cr_assert_lt(t.n, 20000);
        snprintf(t.l[t.n].name, sizeof t.l[t.n].name, "%s", name);
        t.l[t.n++].value = v;
    }
    return t;
}

static Line *find(Txt *t, const char *name)
{
    for (int i = 0; i < t->n; i++)
        if (!strcmp(t->l[i].name, name))
            return &t->l[i];
    return NULL;
}

/* ---- the registry's path patterns, read here from the rows' text ---------------------------- */

/* A JSON leaf's path: keys, or array indices (key NULL). */
typedef struct Comp {
    const char *key;
    int index;
} Comp;

/* The dimension named name[0..n). */
static int dim_named(const char *name, size_t n)
{
    for (int d = 0; d < STATS_D_COUNT; d++)
        if (strlen(stats_dim_names[d]) == n && !strncmp(stats_dim_names[d], name, n))
            return d;
    cr_assert_fail("no dimension %.*s", (int)n, name);
    return -1;
}

/* key is pre + an element of d + post ("{counter}_per_ray" against "nodes_per_ray"). */
static int key_matches(const char *key, const char *pre, size_t prelen, int d, const char *post, size_t postlen)
{
    size_t n = strlen(key);
    if (n < prelen + postlen || strncmp(key, pre, prelen) || strncmp(key + n - postlen, post, postlen))
        return 0;
    for (int i = 0; i < stats_dim_size((StatsDim)d); i++) {
        const char *k = stats_dim_key((StatsDim)d, i);
        if (k[0] && strlen(k) == n - prelen - postlen && !strncmp(key + prelen, k, strlen(k)))
            return 1;
    }
    return 0;
}

/* Whether the leaf path c[0..n) is an element of the row path pat; if so, its stats.txt name per
 * docs/report.md: the keys with dots, an array index as its number (or its dimension's key: lo, hi),
 * a last component that is an element alone written "::element". */
static int match_row(const char *pat, const Comp *c, int n, char *name, size_t len)
{
    size_t o = 0;
    name[0] = '\0';
    int i = 0;
    for (const char *p = pat; *p; i++) {
        if (i == n)
            return 0;
        int element = 0;
        char key[128];
        if (*p == '[') {
            const char *e = strchr(p, ']');
            int d = dim_named(p + 1, (size_t)(e - p - 1));
            if (c[i].key)
                return 0;
            const char *k = stats_dim_key((StatsDim)d, c[i].index);
            snprintf(key, sizeof key, "%s", k[0] ? k : "");
            if (!k[0])
                snprintf(key, sizeof key, "%d", c[i].index);
            element = 1;
            p = e + 1;
        } else {
            const char *e = p + strcspn(p, ".["), *ob = memchr(p, '{', (size_t)(e - p));
            if (!c[i].key)
                return 0;
            if (ob) {
                const char *cb = memchr(ob, '}', (size_t)(e - ob));
                if (!key_matches(c[i].key, p, (size_t)(ob - p), dim_named(ob + 1, (size_t)(cb - ob - 1)), cb + 1,
                                 (size_t)(e - cb - 1)))
                    return 0;
                element = ob == p && cb + 1 == e;
            } else if (strlen(c[i].key) != (size_t)(e - p) || strncmp(c[i].key, p, (size_t)(e - p))) {
                return 0;
            }
            snprintf(key, sizeof key, "%s", c[i].key);
            p = e;
        }
        if (*p == '.')
            p++;
        int last = !*p;
        o += (size_t)snprintf(name + o, len - o, "%s%s", last && element ? "::" : i ? "." : "", key);
    }
    return i == n;
}

/* The statistics' rows a report.json number can be (the walk writes them: not the external host
 * time, not the report.txt-only lines, not the lists of names). */
static int stat_row(const StatsRow *r)
{
    return r->path && r->src != STATS_SRC_EXTERNAL && !(r->flags & (STATS_F_LIST_NZ | STATS_F_LIST_Z));
}

typedef struct Walk {
    Txt *t;
    int numbers;    /* report.json numbers of the statistics */
    const char *mode;
} Walk;

/* Every number (and flag) under v: when its path is a statistic's, it is in stats.txt, the same. */
static void walk_json(Walk *w, const cJSON *v, Comp *c, int n)
{
    if (cJSON_IsObject(v) || cJSON_IsArray(v)) {
        int i = 0;
        for (const cJSON *x = v->child; x; x = x->next, i++) {
            c[n].key = cJSON_IsObject(v) ? x->string : NULL;
            c[n].index = i;
            walk_json(w, x, c, n + 1);
        }
        return;
    }
    if (!cJSON_IsNumber(v) && !cJSON_IsBool(v))
        return;   /* strings are not statistics; a null has no value */
    char name[512];
    int hits = 0;
    for (int r = 0; r < stats_nrows; r++)
        if (stat_row(&stats_rows[r]) && match_row(stats_rows[r].path, c, n, name, sizeof name)) {
            hits++;
            double want = cJSON_IsBool(v) ? (double)cJSON_IsTrue(v) : v->valuedouble;
            Line *l = find(w->t, name);
            cr_expect_not_null(l, "%s mode: %s (report.json %s) is not in stats.txt", w->mode, name, stats_rows[r].path);
            if (l) {
                cr_expect(l->value == want, "%s mode: %s is %.17g in stats.txt, %.17g in report.json", w->mode, name,
                          l->value, want);
                l->used = 1;
            }
        }
    cr_expect_leq(hits, 1, "%s: %d rows match", name, hits);
    w->numbers += hits;
}

/* A run into a fresh folder; checks its stats.txt against its report.json, returns stats.txt's lines. */
static Txt check_run(RenderOptions *o, int *numbers)
{
    char dir[64], path[128];
    tu_make_tmpdir(dir, sizeof dir, "statstxt");
    o->out_dir = dir;
    char err[65536];
    cr_assert_eq(render_run(o, err, sizeof err), 0, "%s", err);
    snprintf(path, sizeof path, "%s/report.json", dir);
    char *json = tu_slurp(path);
    snprintf(path, sizeof path, "%s/stats.txt", dir);
    char *text = tu_slurp(path);
    tu_remove_tree(dir);
    cJSON *j = cJSON_Parse(json);
    cr_assert(cJSON_IsObject(j), "report.json does not parse");
    Txt t = parse_stats_txt(text);
    Walk w = {&t, 0, run_mode_names[o->mode]};
    Comp c[16];
    walk_json(&w, j, c, 0);
    /* the other way: every line is a report.json number, or a vector's total */
    for (int i = 0; i < t.n; i++) {
        Line *l = &t.l[i];
        size_t len = strlen(l->name);
        if (len > 7 && !strcmp(l->name + len - 7, "::total")) {
            double sum = 0;
            int parts = 0;
            for (int k = 0; k < t.n; k++)
                if (k != i && !strncmp(t.l[k].name, l->name, len - 5) && !strchr(t.l[k].name + len - 5, '.') &&
                    !strstr(t.l[k].name + len - 5, "::")) {
                    sum += t.l[k].value;
                    parts++;
                }
            cr_expect(parts > 0 && sum == l->value, "%s mode: %s is %.17g, its %d elements sum to %.17g", run_mode_names[o->mode], l->name,
                      l->value, parts, sum);
        } else {
            cr_expect(l->used, "%s mode: stats.txt's %s is no statistic of report.json", run_mode_names[o->mode], l->name);
        }
    }
    cJSON_Delete(j);
    free(json);
    free(text);
    *numbers = w.numbers;
    return t;
}

static void small_run(RenderOptions *o, const char *mode)
{
    render_default_options(o);
    o->scene_path = "scenes/cornell/scene.ini";
    cr_assert_eq(run_mode_parse(mode, &o->mode), 0, "%s", mode);
    o->kernel_path = "kernels/pathtrace.s";
    o->width = o->height = 16;
    o->spp = 1;
    o->threads = 2;
}

static void expect_lines(Txt *t, const char *mode, const char *const *names, int present)
{
    for (const char *const *n = names; *n; n++)
        cr_expect(!find(t, *n) == !present, "%s mode: %s %s in stats.txt", mode, *n, present ? "missing" : "present");
}

Test(stats_txt, reference_mode_matches_report_json, .timeout = 120)
{
    RenderOptions o;
    small_run(&o, "reference");
    int numbers;
    Txt t = check_run(&o, &numbers);
    cr_expect_geq(numbers, 8, "only %d statistics", numbers);
    expect_lines(&t, "reference", (const char *const[]){"rays.total", "rays_per_generation::0", "rays_per_generation::total",
                                                        "traversal.nodes_visited", NULL}, 1);
    expect_lines(&t, "reference", (const char *const[]){"cycles", "host.seconds", "instructions::total", NULL}, 0);
    free(t.l);
}

Test(stats_txt, functional_mode_matches_report_json, .timeout = 120)
{
    RenderOptions o;
    small_run(&o, "functional");
    int numbers;
    Txt t = check_run(&o, &numbers);
    cr_expect_geq(numbers, 100, "only %d statistics", numbers);
    expect_lines(&t, "functional", (const char *const[]){"instructions::traversal", "instructions::total",
                                                         "ops_by_stage.traversal::load", "ops_by_stage.traversal::total",
                                                         "tiles.0.instructions", "utilization::shading", NULL}, 1);
    /* null in functional mode (report.json: "cycles": null); a ratio has no total */
    expect_lines(&t, "functional", (const char *const[]){"cycles", "fps", "utilization::total", "stalls::control", NULL}, 0);
    free(t.l);
}

Test(stats_txt, detailed_mode_matches_report_json, .timeout = 120)
{
    RenderOptions o;
    small_run(&o, "detailed");
    int numbers;
    Txt t = check_run(&o, &numbers);
    cr_expect_geq(numbers, 300, "only %d statistics", numbers);
    expect_lines(&t, "detailed", (const char *const[]){"cycles", "fps", "stalls::data_dependency", "stalls::total",
                                                       "stalls_by_stage.traversal::control", "tiles.0.stalls::total",
                                                       "units.scene_memory.hits", "units.scene_memory.cache", NULL}, 1);
    expect_lines(&t, "detailed", (const char *const[]){"stall_shares::total", "cycles_ci95::lo", NULL}, 0);
    Line *all = find(&t, "stalls::total"), *cyc = find(&t, "cycles"), *busy = find(&t, "busy_cycles");
    cr_assert(all && cyc && busy);
    cr_expect_eq(all->value, cyc->value - busy->value, "every stall cycle is charged to one cause");
    free(t.l);
}

Test(stats_txt, sampled_mode_matches_report_json, .timeout = 240)
{
    CfgMachine cfg;   /* tests/cli/run.sh's sampled run: 6 of 12 (tile, pass) units timed */
    cfg_defaults(&cfg);
    cfg.stream_rays = 1024;
    RenderOptions o;
    small_run(&o, "sampled");
    o.cfg = &cfg;
    o.width = 96;
    o.height = 64;
    o.spp = 2;
    o.target_error = 0;
    o.sample = 0.5;
    int numbers;
    Txt t = check_run(&o, &numbers);
    cr_expect_geq(numbers, 300, "only %d statistics", numbers);
    expect_lines(&t, "sampled", (const char *const[]){"cycles", "cycles_ci95::lo", "cycles_ci95::hi", "fps_ci95::hi",
                                                      "sample.units", "sample.r2", NULL}, 1);
    expect_lines(&t, "sampled", (const char *const[]){"cycles_ci95::total", NULL}, 0);
    free(t.l);
}

/* accel.structure = kd (tests/unit/kd_stub.s stands in for the kd kernel): the kd counters, whose
 * elements are different counters, get no total. */
Test(stats_txt, kd_counters_match_report_json, .timeout = 120)
{
    CfgMachine cfg;
    cfg_defaults(&cfg);
    cfg.accel_structure = CFG_ACCEL_KD;
    cfg.kd_traversal = CFG_KD_SHORTSTACK;
    cfg.stream_rays = 1024;
    RenderOptions o;
    small_run(&o, "detailed");
    o.cfg = &cfg;
    o.kernel_path = "tests/unit/kd_stub.s";
    int numbers;
    Txt t = check_run(&o, &numbers);
    expect_lines(&t, "kd", (const char *const[]){"kd.camera.rays", "kd.camera::nodes", "kd.camera.nodes_per_ray",
                                                 "kd.total::leaves", "kd.total.rays", NULL}, 1);
    expect_lines(&t, "kd", (const char *const[]){"kd.camera::total", "kd.total::total", "kd.tree.nodes", NULL}, 0);
    free(t.l);
}
