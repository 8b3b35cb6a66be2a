/* sim/sweep/plot.c -- the sweep's plots: gnuplot scripts, their data and the PNGs they draw in
 * DIR/plots (docs/sweep.md, "Plots").
 *
 * Owns: which plots a sweep gets (lines and stacked bars against each numeric swept key, or bar
 * charts against the point), their .gp and .dat files, titles, axis units and colours, and
 * running gnuplot (a missing or failing gnuplot is a warning), and the figure columns they draw,
 * found by their sweep.csv names once (sweep_plot_cols). Must not: read reports (csv.c gives the
 * rows), index a figure column by a number of its own, or decide the exit status of a sweep (it
 * says how many plots could not be drawn; sweep.c decides).
 *
 * Whole or not at all: gnuplot draws each PNG under a temporary name (".NAME.png.tmp-PID", given to
 * the script as the variable sfsim_png, so that the .gp file still draws NAME.png when a user runs
 * it by hand); the PNG is renamed into place only when gnuplot exited 0 and the file ends with
 * PNG's IEND chunk. pngcairo does not report a failed write (a full disk, a file-size limit).
 */
#include "../../host/outfile.h"
#include "../energy/energy.h"
#include "sweep_int.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

/* Series of a stacked plot: stall causes or operation categories; m0 the column of the first. */
typedef struct Series {
    int m0, n;
    const char *const *names;
    const char *what, *ylabel, *base;
    int unit_range;
} Series;

typedef struct Plotter {
    const SweepPlan *pl;
    const SweepRow *rows;
    SweepPlotCols c;
    Series stall, ops, energy;
    const char *dir; /* DIR/plots */
    char *subtitle;  /* scene, mode and fixed keys, gnuplot-escaped, lines joined by \n */
    int made;
    int gnuplot_missing, gnuplot_failed;
} Plotter;

/* A string in gnuplot double quotes. */
static void gp_str(UtilBuf *b, const char *s)
{
    util_buf_puts(b, "\"");
    for (const char *c = s; *c; c++) {
        if (*c == '"' || *c == '\\')
            util_buf_puts(b, "\\");
        util_buf_add(b, c, 1);
    }
    util_buf_puts(b, "\"");
}

/* Units of a key for its axis label. */
static const char *key_unit(const char *key)
{
    static const struct { const char *suffix, *unit; } units[] = {
        {"core.simd_width", "lanes"}, {"stream.rays", "rays per stream"}, {"render.width", "pixels"},
        {"render.height", "pixels"}, {"render.spp", "samples per pixel"}, {"render.max_depth", "bounces"},
        {"kd.max_depth", "levels"},
        {"_per_cycle", "per cycle"}, {"_kb", "KiB"}, {"_mb", "MiB"}, {"_mhz", "MHz"}, {"_bytes", "bytes"},
        {"_cycles", "cycles"}, {"_penalty", "cycles"}, {"latency", "cycles"}, {"banks", "banks"}, {"ports", "ports"},
        {"_ways", "ways"}, {"_depth", "entries"}, {"bins", "bins"}, {"leaf_size", "primitives"},
        {"bounces", "bounces"}};
    size_t kl = strlen(key);
    for (size_t i = 0; i < sizeof units / sizeof units[0]; i++) {
        size_t sl = strlen(units[i].suffix);
        if (kl >= sl && !strcmp(key + kl - sl, units[i].suffix))
            return units[i].unit;
    }
    if (!strncmp(key, "latency.", 8))
        return "cycles";
    if (!strncmp(key, "issue.", 6))
        return "cycles between issues";
    return NULL;
}

static void axis_label(UtilBuf *b, const char *key)
{
    const char *u = key_unit(key);
    UtilBuf t = {0};
    util_buf_printf(&t, u ? "%s (%s)" : "%s", key, u);
    gp_str(b, sweep_buf_text(&t));
    util_buf_free(&t);
}

/* Distinct values of a key over all points; *numeric when every point sets it to a number. */
static int key_values(const SweepPlan *pl, const char *key, int *numeric)
{
    SweepStrs seen = {0};
    *numeric = 1;
    for (int p = 0; p < pl->npoints; p++) {
        const char *v = sweep_plan_value(pl, p, key);
        double d;
        if (!v || !sweep_is_number(v, &d))
            *numeric = 0;
        int dup = 0;
        for (int i = 0; i < seen.n && !dup; i++)
            dup = sweep_str_eq(seen.v[i], v);
        if (!dup)
            sweep_strs_push(&seen, v ? xstrdup(v) : NULL);
    }
    int n = seen.n;
    sweep_strs_free(&seen);
    return n;
}

static int key_swept(const SweepPlan *pl, const char *key)
{
    int numeric;
    return key_values(pl, key, &numeric) > 1;
}

static int row_usable(const Plotter *p, int r, int m0, int n)
{
    if (p->rows[r].state != SWEEP_DONE)
        return 0;
    for (int m = m0; m < m0 + n; m++)
        if (p->rows[r].has[m])
            return 1;
    return 0;
}

static void dat_num(UtilBuf *b, const SweepRow *row, int m)
{
    char v[64];
    if (row->has[m])
        sweep_fmt_num(row->m[m], v, sizeof v);
    else
        snprintf(v, sizeof v, "NaN");
    util_buf_printf(b, " %s", v);
}

/* The tallest stack of series m0 .. m0 + n - 1 over the rows given (0 when none has a figure). */
static double stack_max(const SweepRow *rows, const int *idx, int count, int m0, int n)
{
    double top = 0.0;
    for (int j = 0; j < count; j++) {
        double sum = 0.0;
        for (int c = 0; c < n; c++)
            if (rows[idx[j]].has[m0 + c] && rows[idx[j]].m[m0 + c] > 0.0)
                sum += rows[idx[j]].m[m0 + c];
        top = sum > top ? sum : top;
    }
    return top;
}

/* The y range of stacked bars: [0:1] for shares; otherwise one range for every panel, from 0 to
 * the tallest stack of all of them and a margin, so that side-by-side panels compare by eye (each
 * panel scaled on its own made equal heights mean different cycles). */
static void stack_yrange(UtilBuf *gp, int unit_range, double top)
{
    if (unit_range || !(top > 0.0))
        util_buf_printf(gp, "set yrange [0:%s]\n", unit_range ? "1" : "*");
    else
        util_buf_printf(gp, "set yrange [0:%.17g]\n", top * 1.05);
}

/* A group of rows: the points that share the values of the swept keys other than x. */
typedef struct Group {
    char *label;
    int *rows;
    int n;
} Group;

static void groups_free(Group *g, int n)
{
    for (int i = 0; i < n; i++) {
        free(g[i].label);
        free(g[i].rows);
    }
    free(g);
}

/* Usable rows (metrics m0..m0+n-1) grouped by the other swept keys, each sorted by x. */
static int groups_make(const Plotter *p, const char *xkey, int m0, int nm, Group **out)
{
    const SweepPlan *pl = p->pl;
    Group *g = NULL;
    int ng = 0;
    for (int r = 0; r < pl->npoints; r++) {
        if (!row_usable(p, r, m0, nm))
            continue;
        UtilBuf label = {0};
        for (int k = 0; k < pl->nkeys; k++) {
            if (!strcmp(pl->keys[k], xkey) || !key_swept(pl, pl->keys[k]))
                continue;
            const char *v = sweep_plan_value(pl, r, pl->keys[k]);
            util_buf_printf(&label, "%s%s=%s", label.len ? ", " : "", pl->keys[k], v ? v : "(unset)");
        }
        int i = 0;
        while (i < ng && strcmp(g[i].label, sweep_buf_text(&label)))
            i++;
        if (i == ng) {
            g = xrealloc(g, (size_t)(ng + 1) * sizeof *g);
            g[ng].label = xstrdup(sweep_buf_text(&label));
            g[ng].rows = NULL;
            g[ng].n = 0;
            ng++;
        }
        util_buf_free(&label);
        g[i].rows = xrealloc(g[i].rows, (size_t)(g[i].n + 1) * sizeof *g[i].rows);
        double x, y;
        sweep_is_number(sweep_plan_value(pl, r, xkey), &x);
        int j = g[i].n++;
        while (j > 0 && sweep_is_number(sweep_plan_value(pl, g[i].rows[j - 1], xkey), &y) && y > x) {
            g[i].rows[j] = g[i].rows[j - 1];
            j--;
        }
        g[i].rows[j] = r;
    }
    *out = g;
    return ng;
}

/* 1 when the file at path is a whole PNG as far as its ends tell: the signature first and the
 * IEND chunk (length 0, type, CRC AE 42 60 82) last. */
static int png_whole(const char *path)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    unsigned char head[8], tail[12];
    int fd = open(path, O_RDONLY | O_CLOEXEC), ok = 0;
    struct stat st;
    if (fd < 0)
        return 0;
    if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size >= 20 && pread(fd, head, 8, 0) == 8 &&
        pread(fd, tail, 12, st.st_size - 12) == 12)
        ok = !memcmp(head, sig, 8) && !memcmp(tail, iend, 12) && fsync(fd) == 0;
    return close(fd) == 0 && ok;
}

/* Run gnuplot on base.gp in the plots folder, drawing into a temporary PNG renamed into place once
 * whole; its messages go to gnuplot.log. */
static void gp_run(Plotter *p, const char *base)
{
    if (p->gnuplot_missing)
        return;
    char *script = xasprintf("%s.gp", base);
    char *logpath = xasprintf("%s/gnuplot.log", p->dir);
    char *tmpname = xasprintf(".%s.png.tmp-%ld", base, (long)getpid());
    char *tmp = xasprintf("%s/%s", p->dir, tmpname), *png = xasprintf("%s/%s.png", p->dir, base);
    char *var = xasprintf("sfsim_png='%s'", tmpname); /* base has no quote (plot names are ours) */
    int logfd = open(logpath, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (logfd < 0) {
        fprintf(stderr, "sfsim sweep: warning: %s: cannot create: %s; no plots\n", logpath, strerror(errno));
        p->gnuplot_missing = 1;
        goto out;
    }
    dprintf(logfd, "== gnuplot %s\n", script);
    int made_before = p->made;
    pid_t pid = fork();
    if (pid == 0) {
        if (chdir(p->dir) != 0 || dup2(logfd, 1) < 0 || dup2(logfd, 2) < 0)
            _exit(126);
        execlp("gnuplot", "gnuplot", "-e", var, script, (char *)NULL);
        _exit(127);
    }
    close(logfd);
    int st = 0;
    if (pid < 0) {
        fprintf(stderr, "sfsim sweep: warning: cannot start gnuplot: %s; no plots\n", strerror(errno));
        p->gnuplot_missing = 1;
        goto out;
    }
    while (waitpid(pid, &st, 0) < 0 && errno == EINTR)
        ;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 127) {
        fprintf(stderr, "sfsim sweep: warning: gnuplot is not installed (Debian: gnuplot-nox); no plots, the CSV is "
                        "written\n");
        p->gnuplot_missing = 1;
    } else if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "sfsim sweep: %s: gnuplot failed on %s (see %s); the plot was not drawn\n", png, script, logpath);
        p->gnuplot_failed++;
    } else if (!png_whole(tmp)) {
        fprintf(stderr, "sfsim sweep: %s: gnuplot wrote an incomplete PNG (a full disk or a file-size limit?); the plot "
                        "was not drawn\n", png);
        p->gnuplot_failed++;
    } else if (rename(tmp, png) != 0) {
        fprintf(stderr, "sfsim sweep: %s: cannot rename into place: %s; the plot was not drawn\n", png, strerror(errno));
        p->gnuplot_failed++;
    } else {
        p->made++;
    }
    /* A plot of an earlier merge must not stand beside this CSV as if drawn from it. */
    if (p->made == made_before)
        unlink(png);
out:
    unlink(tmp); /* nothing there once renamed */
    free(script);
    free(logpath);
    free(tmpname);
    free(tmp);
    free(png);
    free(var);
}

/* Write base.gp and base.dat, then draw base.png. */
static void plot_write(Plotter *p, const char *base, const UtilBuf *gp, const UtilBuf *dat)
{
    char err[PATH_MAX + 256];
    char *gpath = xasprintf("%s/%s.gp", p->dir, base), *dpath = xasprintf("%s/%s.dat", p->dir, base);
    if (outfile_write_file(NULL, dpath, sweep_buf_text(dat), dat->len, err, sizeof err) ||
        outfile_write_file(NULL, gpath, sweep_buf_text(gp), gp->len, err, sizeof err))
        fprintf(stderr, "sfsim sweep: warning: %s\n", err);
    else
        gp_run(p, base);
    free(gpath);
    free(dpath);
}

/* End the script (closing a multiplot), write both files, draw, and free the buffers. */
static void plot_finish(Plotter *p, const char *base, UtilBuf *gp, UtilBuf *dat, int multiplot)
{
    if (multiplot)
        util_buf_puts(gp, "unset multiplot\n");
    plot_write(p, base, gp, dat);
    util_buf_free(gp);
    util_buf_free(dat);
}

static void gp_head(const Plotter *p, UtilBuf *g, const char *base, int w, int h, const char *what, const char *against)
{
    util_buf_printf(g, "# Written by sfsim sweep / sfsim merge from the points of this sweep; the data is in %s.dat.\n"
                       "# Restyle and redraw: cd into this folder, then gnuplot %s.gp\n", base, base);
    util_buf_printf(g, "set terminal pngcairo size %d,%d noenhanced font \"sans,11\"\n"
                       "set output (exists(\"sfsim_png\") ? sfsim_png : \"%s.png\")\n", w, h, base);
    util_buf_puts(g, "set datafile missing \"NaN\"\nset grid\n");
    UtilBuf t = {0};
    util_buf_printf(&t, "%s against %s", what, against);
    util_buf_puts(g, "set title ");
    gp_str(g, sweep_buf_text(&t));
    util_buf_printf(g, " . \"\\n\" . %s\n", p->subtitle);
    util_buf_free(&t);
}

/* Colours of stacked bars (matplotlib's tab10). */
static const char *const palette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
                                      "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};
#define N_PALETTE (int)(sizeof palette / sizeof palette[0])

static void gp_palette(UtilBuf *g, int n)
{
    for (int i = 0; i < n; i++)
        util_buf_printf(g, "set linetype %d lc rgb \"%s\"\n", i + 1, palette[i % N_PALETTE]);
}

/* The column m0 is filled in by sweep_plots_make. */
static const Series stall_series = {-1, TM_CAUSE_COUNT, tm_cause_keys, "stall cycles by cause",
                                    "share of all cycles", "stalls", 0};
static const Series ops_series = {-1, ISA_C_COUNT, isa_category_keys, "operation mix",
                                  "share of executed instructions", "ops", 1};
static const Series energy_series = {-1, EN_L_COUNT, energy_level_keys, "energy per frame by level (docs/energy.md)",
                                     "J per frame", "energy", 0};

/* The stages the utilization plots draw, in the order of their columns and panels. */
static const int plot_stages[3] = {ISA_STAGE_TRAVERSAL, ISA_STAGE_INTERSECTION, ISA_STAGE_SHADING};

/* The columns named prefix + keys[i] + suffix, found by name; they must follow each other. */
static int group_cols_sfx(const char *prefix, const char *const *keys, const char *suffix, int n, int *first, char *err,
                          size_t errlen)
{
    for (int i = 0; i < n; i++) {
        char name[128];
        snprintf(name, sizeof name, "%s%s%s", prefix, keys[i], suffix);
        int m = sweep_col(name, err, errlen);
        if (m < 0)
            return -1;
        if (i == 0) {
            *first = m;
        } else if (m != *first + i) {
            snprintf(err, errlen, "sweep.csv's column '%s' is not %d after '%s%s' (the plots draw a group in order)",
                     name, i, prefix, keys[0]);
            return -1;
        }
    }
    return 0;
}

static int group_cols(const char *prefix, const char *const *keys, int n, int *first, char *err, size_t errlen)
{
    return group_cols_sfx(prefix, keys, "", n, first, err, errlen);
}

int sweep_plot_cols(SweepPlotCols *cols, char *err, size_t errlen)
{
    /* A chip's figures (docs/chip.md): a point has some of them when it ran a chip. */
    static const char *const chip_keys[] = {"load_imbalance", "memory_latency", "l2_hit_rate", "dram_gbs",
                                            "dram_bandwidth_share"};
    cols->chip_n = (int)(sizeof chip_keys / sizeof chip_keys[0]);
    const char *stages[3];
    for (int s = 0; s < 3; s++)
        stages[s] = isa_stage_keys[plot_stages[s]];
    if ((cols->fps = sweep_col("fps", err, errlen)) < 0 ||
        (cols->fps_lo = sweep_col("fps_lo", err, errlen)) < 0 ||
        (cols->fps_hi = sweep_col("fps_hi", err, errlen)) < 0 ||
        (cols->kd = sweep_col("kd_nodes_per_ray", err, errlen)) < 0 ||
        (cols->kd_camera = sweep_col("kd_camera_nodes_per_ray", err, errlen)) < 0 ||
        (cols->power = sweep_col("power_w", err, errlen)) < 0 ||
        (cols->area = sweep_col("area_chip_mm2", err, errlen)) < 0)
        return -1;
    if (group_cols_sfx("energy_", energy_level_keys, "_j", EN_L_COUNT, &cols->energy, err, errlen))
        return -1;
    if (group_cols("utilization_", stages, 3, &cols->util, err, errlen) ||
        group_cols("stall_share_", tm_cause_keys, TM_CAUSE_COUNT, &cols->stall, err, errlen) ||
        group_cols("ops_share_", isa_category_keys, ISA_C_COUNT, &cols->ops, err, errlen) ||
        group_cols("", chip_keys, cols->chip_n, &cols->chip, err, errlen))
        return -1;
    return 0;
}

/* " name" for each of the n columns from m0 on: a .dat file's column heads. */
static void dat_heads(UtilBuf *b, int m0, int n)
{
    char name[128];
    for (int m = m0; m < m0 + n; m++)
        util_buf_printf(b, " %s", stats_csv_name(m, name, sizeof name));
}

/* The x axis of lines against a numeric key: its label, its values as ticks (up to 16), a log
 * scale when they span a factor of 100 or more, and a margin either side. */
static void gp_xaxis(const Plotter *p, UtilBuf *gp, const char *xkey)
{
    util_buf_puts(gp, "set xlabel ");
    axis_label(gp, xkey);
    util_buf_puts(gp, "\n");
    int numeric, nv = key_values(p->pl, xkey, &numeric);
    double lo = INFINITY, hi = -INFINITY;
    for (int r = 0; r < p->pl->npoints; r++) {
        double x;
        if (sweep_is_number(sweep_plan_value(p->pl, r, xkey), &x))
            lo = fmin(lo, x), hi = fmax(hi, x);
    }
    if (lo > 0 && hi / lo >= 100)
        util_buf_puts(gp, "set logscale x\n");
    if (nv <= 16) {
        util_buf_puts(gp, "set xtics (");
        SweepStrs seen = {0};
        for (int r = 0; r < p->pl->npoints; r++) {
            const char *v = sweep_plan_value(p->pl, r, xkey);
            int dup = 0;
            for (int i = 0; i < seen.n && !dup; i++)
                dup = !strcmp(seen.v[i], v);
            if (!dup) {
                util_buf_printf(gp, "%s%s", seen.n ? ", " : "", v);
                sweep_strs_push(&seen, xstrdup(v));
            }
        }
        sweep_strs_free(&seen);
        util_buf_puts(gp, ")\n");
    }
    util_buf_puts(gp, "set autoscale xfix\nset offsets graph 0.03, graph 0.03, 0, 0\n");
}

/* fps (lines, with the confidence interval as error bars when every point has one), SIMD
 * utilization (three panels) or, for kd-tree runs, nodes visited per ray against a numeric key.
 * what: 0 fps, 1 utilization, 2 kd-tree nodes. */
static void plot_lines(Plotter *p, const char *xkey, int what)
{
    const int util = what == 1, kd = what == 2;
    const SweepPlotCols *cols = &p->c;
    int m0 = util ? cols->util : kd ? cols->kd : cols->fps, nm = util ? 3 : 1;
    Group *g;
    int ng = groups_make(p, xkey, m0, nm, &g);
    if (!ng) {
        groups_free(g, ng);
        return;
    }
    int ci = !util && !kd;
    for (int i = 0; i < ng && ci; i++)
        for (int j = 0; j < g[i].n && ci; j++)
            ci = p->rows[g[i].rows[j]].has[cols->fps_lo] && p->rows[g[i].rows[j]].has[cols->fps_hi];
    char *base = xasprintf("%s_%s", util ? "utilization" : kd ? "kd_nodes" : "fps", xkey);
    UtilBuf gp = {0}, dat = {0};
    for (int i = 0; i < ng; i++) {
        util_buf_printf(&dat, "%s# %s\n# %s", i ? "\n\n" : "", g[i].label[0] ? g[i].label : "all points", xkey);
        if (util) {
            dat_heads(&dat, cols->util, 3);
        } else if (kd) {
            dat_heads(&dat, cols->kd_camera, 1);
            dat_heads(&dat, cols->kd, 1);
        } else {
            dat_heads(&dat, cols->fps, 1);
            dat_heads(&dat, cols->fps_lo, 1);
            dat_heads(&dat, cols->fps_hi, 1);
        }
        util_buf_puts(&dat, "\n");
        for (int j = 0; j < g[i].n; j++) {
            const SweepRow *row = &p->rows[g[i].rows[j]];
            util_buf_printf(&dat, "%s", sweep_plan_value(p->pl, g[i].rows[j], xkey));
            if (util) {
                for (int s = 0; s < 3; s++)
                    dat_num(&dat, row, cols->util + s);
            } else if (kd) {
                dat_num(&dat, row, cols->kd_camera);
                dat_num(&dat, row, cols->kd);
            } else {
                dat_num(&dat, row, cols->fps);
                dat_num(&dat, row, cols->fps_lo);
                dat_num(&dat, row, cols->fps_hi);
            }
            util_buf_puts(&dat, "\n");
        }
    }
    gp_head(p, &gp, base, util ? 1500 : 960, util ? 560 : 620,
            util ? "SIMD utilization per stage" : kd ? "kd-tree nodes visited per ray" : "frames per second", xkey);
    gp_xaxis(p, &gp, xkey);
    util_buf_puts(&gp, ng > 1 || kd ? "set key outside below center horizontal\n" : "unset key\n");
    if (util) {
        util_buf_puts(&gp, "set yrange [0:1]\nset ylabel \"SIMD utilization (active lanes / N)\"\n");
        util_buf_puts(&gp, "set multiplot layout 1,3 title ");
        UtilBuf t = {0};
        util_buf_printf(&t, "SIMD utilization per stage against %s", xkey);
        gp_str(&gp, sweep_buf_text(&t));
        util_buf_free(&t);
        util_buf_printf(&gp, " . \"\\n\" . %s\nunset title\n", p->subtitle);
    } else if (kd) {
        util_buf_puts(&gp, "set yrange [0:*]\nset ylabel \"nodes visited per ray (inner nodes and leaves)\"\n");
    } else {
        util_buf_printf(&gp, "set yrange [0:*]\nset ylabel \"frames per second (at core.clock_mhz)%s\"\n",
                        ci ? "; bars: 95% confidence interval" : "");
    }
    for (int s = 0; s < (util ? 3 : 1); s++) {
        if (util)
            util_buf_printf(&gp, "set title \"%s\"\n", isa_stage_keys[plot_stages[s]]);
        util_buf_puts(&gp, "plot ");
        for (int i = 0; i < ng && kd; i++)
            for (int c = 0; c < 2; c++) {
                UtilBuf t = {0};
                util_buf_printf(&t, "%s%s%s", c ? "all rays" : "camera rays", g[i].label[0] ? ", " : "", g[i].label);
                util_buf_printf(&gp, "%s\"%s.dat\" index %d using 1:%d with linespoints lw 2 pt 7 ps 1.2 title ",
                                i || c ? ", \\\n     " : "", base, i, 2 + c);
                gp_str(&gp, sweep_buf_text(&t));
                util_buf_free(&t);
            }
        for (int i = 0; i < ng && !kd; i++) {
            util_buf_printf(&gp, "%s\"%s.dat\" index %d using 1:%d%s with %s lw 2 pt 7 ps 1.2 title ",
                            i ? ", \\\n     " : "", base, i, 2 + s, ci ? ":3:4" : "",
                            ci ? "yerrorlines" : "linespoints");
            gp_str(&gp, g[i].label[0] ? g[i].label : (ci ? "fps, 95% confidence interval" : "all points"));
        }
        util_buf_puts(&gp, "\n");
    }
    plot_finish(p, base, &gp, &dat, util);
    free(base);
    groups_free(g, ng);
}

/* A chip's memory figures against a numeric key (memory_K.png), a panel each, a line per
 * combination of the other keys: only for sweeps some of whose points ran a chip (docs/chip.md). A
 * figure a point does not have (the L2's hit rate with no L2) is a gap in its line. */
static const struct {
    const char *col, *title, *ylabel;
    int unit_range;
} chip_panels[] = {
    {"dram_gbs", "DRAM bandwidth used", "GB/s (10^9 bytes) over the frame", 0},
    {"dram_bandwidth_share", "DRAM bandwidth, share of peak", "bandwidth used / peak", 0},
    {"memory_latency", "average memory latency", "cycles from a miss leaving its core to its line", 0},
    {"l2_hit_rate", "L2 hit rate", "L2 hits / requests", 1},
    {"stall_share_scene_memory", "scene-memory stalls", "share of the cores' busy + stall cycles", 0},
    {"load_imbalance", "load imbalance", "most busy + stall cycles of a core / mean", 0},
};
#define N_CHIP_PANELS (int)(sizeof chip_panels / sizeof chip_panels[0])

static void plot_chip(Plotter *p, const char *xkey)
{
    int m[N_CHIP_PANELS];
    char err[256];
    for (int c = 0; c < N_CHIP_PANELS; c++)
        if ((m[c] = sweep_col(chip_panels[c].col, err, sizeof err)) < 0)
            return; /* sweep_plot_cols found every one of them */
    Group *g;
    int ng = groups_make(p, xkey, p->c.chip, p->c.chip_n, &g);
    if (!ng) {
        groups_free(g, ng);
        return;
    }
    char *base = xasprintf("memory_%s", xkey);
    UtilBuf gp = {0}, dat = {0};
    for (int i = 0; i < ng; i++) {
        util_buf_printf(&dat, "%s# %s\n# %s", i ? "\n\n" : "", g[i].label[0] ? g[i].label : "all points", xkey);
        for (int c = 0; c < N_CHIP_PANELS; c++)
            util_buf_printf(&dat, " %s", chip_panels[c].col);
        util_buf_puts(&dat, "\n");
        for (int j = 0; j < g[i].n; j++) {
            util_buf_printf(&dat, "%s", sweep_plan_value(p->pl, g[i].rows[j], xkey));
            for (int c = 0; c < N_CHIP_PANELS; c++)
                dat_num(&dat, &p->rows[g[i].rows[j]], m[c]);
            util_buf_puts(&dat, "\n");
        }
    }
    gp_head(p, &gp, base, 1500, 1020, "the chip's memory", xkey);
    gp_xaxis(p, &gp, xkey);
    util_buf_puts(&gp, ng > 1 ? "set key outside below center horizontal\n" : "unset key\n");
    util_buf_puts(&gp, "set multiplot layout 2,3 title ");
    UtilBuf t = {0};
    util_buf_printf(&t, "the chip's memory against %s", xkey);
    gp_str(&gp, sweep_buf_text(&t));
    util_buf_free(&t);
    util_buf_printf(&gp, " . \"\\n\" . %s\n", p->subtitle);
    for (int c = 0; c < N_CHIP_PANELS; c++) {
        util_buf_printf(&gp, "set title \"%s\"\nset ylabel \"%s\"\nset yrange [0:%s]\nplot ", chip_panels[c].title,
                        chip_panels[c].ylabel, chip_panels[c].unit_range ? "1" : "*");
        for (int i = 0; i < ng; i++) {
            util_buf_printf(&gp, "%s\"%s.dat\" index %d using 1:%d with linespoints lw 2 pt 7 ps 1.2 title ",
                            i ? ", \\\n     " : "", base, i, 2 + c);
            gp_str(&gp, g[i].label[0] ? g[i].label : "all points");
        }
        util_buf_puts(&gp, "\n");
    }
    plot_finish(p, base, &gp, &dat, 1);
    free(base);
    groups_free(g, ng);
}

/* Stall shares or the operation mix as stacked bars against a numeric key, one panel per
 * combination of the other swept keys. */
static void plot_stacked(Plotter *p, const char *xkey, const Series *se)
{
    Group *g;
    int ng = groups_make(p, xkey, se->m0, se->n, &g);
    if (!ng) {
        groups_free(g, ng);
        return;
    }
    int cols = ng == 1 ? 1 : ng <= 4 ? 2 : 3, rws = (ng + cols - 1) / cols;
    char *base = xasprintf("%s_%s", se->base, xkey);
    UtilBuf gp = {0}, dat = {0};
    for (int i = 0; i < ng; i++) {
        util_buf_printf(&dat, "%s# %s\n# %s", i ? "\n\n" : "", g[i].label[0] ? g[i].label : "all points", xkey);
        for (int c = 0; c < se->n; c++)
            util_buf_printf(&dat, " %s", se->names[c]);
        util_buf_puts(&dat, "\n");
        for (int j = 0; j < g[i].n; j++) {
            util_buf_printf(&dat, "\"%s\"", sweep_plan_value(p->pl, g[i].rows[j], xkey));
            for (int c = 0; c < se->n; c++)
                dat_num(&dat, &p->rows[g[i].rows[j]], se->m0 + c);
            util_buf_puts(&dat, "\n");
        }
    }
    gp_head(p, &gp, base, 820 * cols, 480 * rws + 60, se->what, xkey);
    /* rowstacked puts the first series at the bottom; "invert" lists the key in the same order,
     * the top of the stack first, so that legend and bars read alike. */
    util_buf_puts(&gp, "set style data histograms\nset style histogram rowstacked\n"
                       "set style fill solid 0.85 border -1\nset boxwidth 0.7 relative\n"
                       "set key outside right top invert\n");
    double top = 0.0;
    for (int i = 0; i < ng; i++) {
        double t = stack_max(p->rows, g[i].rows, g[i].n, se->m0, se->n);
        top = t > top ? t : top;
    }
    stack_yrange(&gp, se->unit_range, top);
    util_buf_printf(&gp, "set ylabel \"%s\"\nset xlabel ", se->ylabel);
    axis_label(&gp, xkey);
    util_buf_puts(&gp, "\n");
    gp_palette(&gp, se->n);
    if (ng > 1) {
        util_buf_printf(&gp, "set multiplot layout %d,%d title ", rws, cols);
        UtilBuf t = {0};
        util_buf_printf(&t, "%s against %s (a panel per combination of the other keys)", se->what, xkey);
        gp_str(&gp, sweep_buf_text(&t));
        util_buf_free(&t);
        util_buf_printf(&gp, " . \"\\n\" . %s\n", p->subtitle);
    }
    for (int i = 0; i < ng; i++) {
        if (ng > 1) {
            util_buf_puts(&gp, "set title ");
            gp_str(&gp, g[i].label);
            util_buf_puts(&gp, "\n");
        }
        util_buf_puts(&gp, "plot ");
        for (int c = 0; c < se->n; c++)
            util_buf_printf(&gp, "%s\"%s.dat\" index %d using %d%s title \"%s\"", c ? ", \\\n     " : "", base, i,
                            c + 2, c ? "" : ":xtic(1)", se->names[c]);
        util_buf_puts(&gp, "\n");
    }
    plot_finish(p, base, &gp, &dat, ng > 1);
    free(base);
    groups_free(g, ng);
}

/* fps against x (power_w or area_chip_mm2) over every point with both, each point labelled with
 * its swept values, and the Pareto front: the points no other point beats on both (more fps for
 * no more x), joined in order of x. Drawn once a sweep, when two points or more have both. */
static void plot_pareto(Plotter *p, int xcol, const char *xname, const char *base)
{
    const SweepPlan *pl = p->pl;
    const int fps = p->c.fps;
    int *idx = malloc((size_t)pl->npoints * sizeof *idx), n = 0;
    for (int r = 0; idx && r < pl->npoints; r++)
        if (row_usable(p, r, xcol, 1) && row_usable(p, r, fps, 1) && p->rows[r].has[xcol] && p->rows[r].has[fps])
            idx[n++] = r;
    if (n < 2) {
        free(idx);
        return;
    }
    UtilBuf gp = {0}, dat = {0};
    util_buf_printf(&dat, "# every point: %s fps label\n", xname);
    for (int i = 0; i < n; i++) {
        const SweepRow *row = &p->rows[idx[i]];
        util_buf_printf(&dat, "%.10g %.10g \"", row->m[xcol], row->m[fps]);
        for (int k = 0; k < pl->nkeys; k++)
            util_buf_printf(&dat, "%s%s", k ? " " : "", sweep_plan_value(pl, idx[i], pl->keys[k]));
        util_buf_puts(&dat, "\"\n");
    }
    util_buf_printf(&dat, "\n\n# the Pareto front: %s fps, by %s\n", xname, xname);
    for (double last = -1.0;;) { /* the next front point: the smallest x above last, most fps at it */
        int best = -1;
        for (int i = 0; i < n; i++) {
            const SweepRow *a = &p->rows[idx[i]];
            int beaten = 0;
            for (int j = 0; j < n && !beaten; j++) {
                const SweepRow *b = &p->rows[idx[j]];
                beaten = b->m[xcol] <= a->m[xcol] && b->m[fps] >= a->m[fps] &&
                         (b->m[xcol] < a->m[xcol] || b->m[fps] > a->m[fps]);
            }
            if (!beaten && a->m[xcol] > last && (best < 0 || a->m[xcol] < p->rows[idx[best]].m[xcol]))
                best = i;
        }
        if (best < 0)
            break;
        last = p->rows[idx[best]].m[xcol];
        util_buf_printf(&dat, "%.10g %.10g\n", last, p->rows[idx[best]].m[fps]);
    }
    gp_head(p, &gp, base, 900, 600, "fps", xname);
    util_buf_printf(&gp, "set xlabel \"%s\"\nset ylabel \"frames/s\"\nset key top left\n", xname);
    util_buf_printf(&gp, "plot \"%s.dat\" index 0 using 1:2 with points pt 7 ps 1.3 title \"points\", \\\n"
                         "     \"%s.dat\" index 0 using 1:2:3 with labels offset 0.8,0.8 left notitle, \\\n"
                         "     \"%s.dat\" index 1 using 1:2 with linespoints lw 2 title \"Pareto front\"\n",
                    base, base, base);
    plot_finish(p, base, &gp, &dat, 0);
    free(idx);
}

/* Bar charts against the point (explicit points, or no numeric key swept). kind: 0 fps,
 * 1 utilization, 2 stalls, 3 ops. */
static void plot_bars(Plotter *p, int kind)
{
    const SweepPlan *pl = p->pl;
    const SweepPlotCols *cols = &p->c;
    const Series *se = kind == 2 ? &p->stall : kind == 3 ? &p->ops : NULL;
    int m0 = se ? se->m0 : kind == 1 ? cols->util : kind == 4 ? cols->kd : cols->fps;
    int nm = se ? se->n : kind == 1 ? 3 : 1;
    static const char *const bases[] = {"fps_point", "utilization_point", "stalls_point", "ops_point",
                                        "kd_nodes_point"};
    static const char *const whats[] = {"frames per second", "SIMD utilization per stage", "stall cycles by cause",
                                        "operation mix", "kd-tree nodes visited per ray"};
    UtilBuf gp = {0}, dat = {0};
    int n = 0, ci = kind == 0, longest = 0;
    for (int r = 0; r < pl->npoints; r++) {
        if (!row_usable(p, r, m0, nm))
            continue;
        UtilBuf label = {0};
        if (pl->points[r].name)
            util_buf_puts(&label, pl->points[r].name);
        for (int k = 0; k < pl->nkeys && !pl->points[r].name; k++)
            if (key_swept(pl, pl->keys[k])) {
                const char *v = sweep_plan_value(pl, r, pl->keys[k]);
                util_buf_printf(&label, "%s%s=%s", label.len ? ", " : "", pl->keys[k], v ? v : "(unset)");
            }
        if (!label.len)
            util_buf_printf(&label, "%d", r);
        longest = (int)label.len > longest ? (int)label.len : longest;
        gp_str(&dat, sweep_buf_text(&label));
        util_buf_free(&label);
        if (kind == 0) {
            dat_num(&dat, &p->rows[r], cols->fps);
            dat_num(&dat, &p->rows[r], cols->fps_lo);
            dat_num(&dat, &p->rows[r], cols->fps_hi);
            ci = ci && p->rows[r].has[cols->fps_lo] && p->rows[r].has[cols->fps_hi];
        } else if (kind == 4) {
            dat_num(&dat, &p->rows[r], cols->kd_camera);
            dat_num(&dat, &p->rows[r], cols->kd);
        } else {
            for (int m = m0; m < m0 + nm; m++)
                dat_num(&dat, &p->rows[r], m);
        }
        util_buf_puts(&dat, "\n");
        n++;
    }
    if (!n) {
        util_buf_free(&dat);
        return;
    }
    int w = 300 + 70 * n * (kind == 1 || kind == 4 ? 2 : 1);
    int wmin = kind == 0 ? 900 : 1100;
    gp_head(p, &gp, bases[kind], w < wmin ? wmin : w, 600 + 6 * (longest > 12 ? longest : 0), whats[kind], "the point");
    util_buf_puts(&gp, "set style fill solid 0.85 border -1\nset xlabel \"point\"\n");
    if (n > 6 || longest > 10)
        util_buf_puts(&gp, "set xtics rotate by 30 right\n");
    if (kind == 0) {
        util_buf_printf(&gp, "set boxwidth 0.6\nset xrange [-0.6:%g]\nset yrange [0:*]\n"
                             "set ylabel \"frames per second (at core.clock_mhz)\"\n", n - 0.4);
        util_buf_printf(&gp, "plot \"%s.dat\" using 0:2:xtic(1) with boxes lc rgb \"%s\" %s", bases[kind], palette[0],
                        ci ? "title \"fps\"" : "notitle");
        if (ci)
            util_buf_printf(&gp, ", \\\n     \"%s.dat\" using 0:2:3:4 with yerrorbars lc rgb \"black\" pt -1 "
                                 "title \"95%% confidence interval\"", bases[kind]);
        util_buf_puts(&gp, "\n");
    } else if (kind == 4) {
        util_buf_puts(&gp, "set style data histograms\nset style histogram clustered gap 1\nset yrange [0:*]\n"
                           "set ylabel \"nodes visited per ray (inner nodes and leaves)\"\n"
                           "set key outside right top\n");
        gp_palette(&gp, 2);
        util_buf_printf(&gp, "plot \"%s.dat\" using 2:xtic(1) title \"camera rays\", \\\n     \"%s.dat\" using 3 "
                             "title \"all rays\"\n", bases[kind], bases[kind]);
    } else if (kind == 1) {
        util_buf_puts(&gp, "set style data histograms\nset style histogram clustered gap 1\nset yrange [0:1]\n"
                           "set ylabel \"SIMD utilization (active lanes / N)\"\nset key outside right top\n");
        gp_palette(&gp, 3);
        for (int s = 0; s < 3; s++)
            util_buf_printf(&gp, "%s\"%s.dat\" using %d%s title \"%s\"", s ? ", \\\n     " : "plot ", bases[kind],
                            s + 2, s ? "" : ":xtic(1)", isa_stage_keys[plot_stages[s]]);
        util_buf_puts(&gp, "\n");
    } else {
        util_buf_printf(&gp, "set style data histograms\nset style histogram rowstacked\nset boxwidth 0.7 relative\n"
                             "set yrange [0:%s]\nset ylabel \"%s\"\nset key outside right top invert\n",
                   se->unit_range ? "1" : "*", se->ylabel);
        gp_palette(&gp, se->n);
        for (int c = 0; c < se->n; c++)
            util_buf_printf(&gp, "%s\"%s.dat\" using %d%s title \"%s\"", c ? ", \\\n     " : "plot ", bases[kind],
                            c + 2, c ? "" : ":xtic(1)", se->names[c]);
        util_buf_puts(&gp, "\n");
    }
    plot_finish(p, bases[kind], &gp, &dat, 0);
}

/* "cornell/scene.ini": the scene's file and its folder. */
static const char *short_path(const char *path)
{
    const char *last = strrchr(path, '/');
    if (!last)
        return path;
    const char *prev = last;
    while (prev > path && prev[-1] != '/')
        prev--;
    return prev > path ? prev : last + 1;
}

/* The second title line(s): scene, mode, config and the keys every point shares. */
static char *plot_subtitle(const SweepPlan *pl)
{
    UtilBuf s = {0}, line = {0};
    SweepStrs parts = {0};
    sweep_strs_push(&parts, xasprintf("scene %s", short_path(pl->scene)));
    sweep_strs_push(&parts, pl->sample ? xasprintf("%s mode (sample %s)", pl->mode, pl->sample)
                                       : xasprintf("%s mode", pl->mode));
    sweep_strs_push(&parts, xasprintf("config %s", pl->config ? short_path(pl->config) : "built-in"));
    for (int i = 0; i < pl->nsets; i++)
        sweep_strs_push(&parts, xstrdup(pl->sets[i]));
    for (int k = 0; k < pl->nkeys && !pl->explicit_points; k++)
        if (!key_swept(pl, pl->keys[k]))
            sweep_strs_push(&parts, xasprintf("%s=%s", pl->keys[k], sweep_plan_value(pl, 0, pl->keys[k])));
    /* Lines of at most ~110 characters. */
    for (int i = 0; i < parts.n; i++) {
        if (line.len && line.len + strlen(parts.v[i]) > 110) {
            if (s.len)
                util_buf_puts(&s, " . \"\\n\" . ");
            gp_str(&s, sweep_buf_text(&line));
            line.len = 0;
            line.s[0] = 0;
        }
        util_buf_printf(&line, "%s%s", line.len ? ", " : "", parts.v[i]);
    }
    if (s.len)
        util_buf_puts(&s, " . \"\\n\" . ");
    gp_str(&s, sweep_buf_text(&line));
    util_buf_free(&line);
    sweep_strs_free(&parts);
    if (s.failed)
        sweep_oom();
    return s.s;
}

int sweep_plots_make(const SweepPlan *pl, const SweepRow *rows, const char *dir, int *failed)
{
    char err[PATH_MAX + 256];
    Plotter p = {0};
    p.pl = pl;
    p.rows = rows;
    *failed = 0;
    if (sweep_plot_cols(&p.c, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: warning: %s; no plots\n", err);
        *failed = 1;
        return 0;
    }
    p.stall = stall_series;
    p.stall.m0 = p.c.stall;
    p.ops = ops_series;
    p.ops.m0 = p.c.ops;
    p.energy = energy_series;
    p.energy.m0 = p.c.energy;
    char *pdir = xasprintf("%s/plots", dir);
    p.dir = pdir;
    if (util_mkdir_p(pdir, err, sizeof err)) {
        fprintf(stderr, "sfsim sweep: warning: %s; no plots\n", err);
        free(pdir);
        return 0;
    }
    char *logpath = xasprintf("%s/gnuplot.log", pdir);
    unlink(logpath);
    free(logpath);
    p.subtitle = plot_subtitle(pl);
    int lines = 0;
    for (int k = 0; k < pl->nkeys && !pl->explicit_points; k++) {
        int numeric, nv = key_values(pl, pl->keys[k], &numeric);
        if (nv < 2 || !numeric)
            continue;
        lines++;
        plot_lines(&p, pl->keys[k], 0);
        plot_lines(&p, pl->keys[k], 1);
        plot_lines(&p, pl->keys[k], 2); /* only when some point ran on a kd-tree */
        plot_stacked(&p, pl->keys[k], &p.stall);
        plot_stacked(&p, pl->keys[k], &p.ops);
        plot_chip(&p, pl->keys[k]); /* only when some point ran a chip */
        plot_stacked(&p, pl->keys[k], &p.energy); /* only when some point was timed */
    }
    plot_pareto(&p, p.c.area, "area_chip_mm2", "pareto_fps_area");   /* timed points only */
    plot_pareto(&p, p.c.power, "power_w", "pareto_fps_power");
    if (!lines)
        for (int kind = 0; kind < 5; kind++)
            plot_bars(&p, kind); /* (kd_nodes_point: only when some point ran on a kd-tree) */
    free(p.subtitle);
    free(pdir);
    *failed = p.gnuplot_failed;
    return p.made;
}
