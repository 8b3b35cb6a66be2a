/* sim/cli/mem.c -- `sfsim mem`: replays a memory-access trace (DRAMsim3's or sfsim's format,
 * sim/mem/memtrace.h) through the DRAM of the config (sim/mem/dram.h) and reports, per channel and
 * in total, bandwidth against peak, average and percentile latency, row-buffer outcomes, queue
 * occupancy, refreshes and back-pressure; with -o, report.txt and report.json written whole.
 *
 * Owns: the command's options, the trace-to-DRAM clock conversion, the exact latency percentiles
 * and the report's layout. Must not: model the DRAM. Exit codes: sim/exitcodes.def.
 */
#include "mem.h"

#include <cjson/cJSON.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../host/outfile.h"
#include "../exitcodes.h"
#include "../energy/dramenergy.h"
#include "../mem/dram.h"
#include "../mem/memtrace.h"
#include "help.h"
#include "opts.h"

enum { M_SET = CLI_LONG, M_TRACE, M_FORMAT, M_JSON, M_MAPPING };
static const struct option mem_longs[] = {
    {"config", required_argument, NULL, 'c'},  {"set", required_argument, NULL, M_SET},
    {"trace", required_argument, NULL, M_TRACE}, {"format", required_argument, NULL, M_FORMAT},
    {"out", required_argument, NULL, 'o'},     {"json", no_argument, NULL, M_JSON},
    {"mapping", required_argument, NULL, M_MAPPING}, {"help", no_argument, NULL, CLI_HELP},
    {"version", no_argument, NULL, CLI_VERSION}, {NULL, 0, NULL, 0}};

/* Latencies of one channel (or all), for exact percentiles. */
typedef struct Lats {
    uint32_t *v;
    size_t n, cap;
} Lats;

typedef struct Replay {
    const DramParams *p;
    uint64_t *arrival;  /* per request id */
    uint8_t *chan;      /* per request id */
    size_t nreq, capreq;
    Lats *lat;          /* [channels + 1]: the last is every channel's */
    uint64_t first, last; /* first arrival, last completion */
    int oom;
} Replay;

static void lats_add(Replay *r, Lats *l, uint64_t v)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 4096;
        uint32_t *n = realloc(l->v, cap * sizeof *n);
        if (!n) {
            r->oom = 1;
            return;
        }
        l->v = n;
        l->cap = cap;
    }
    l->v[l->n++] = v > UINT32_MAX ? UINT32_MAX : (uint32_t)v;
}

static void on_done(void *ctx, uint64_t id, int write, uint64_t cycle)
{
    Replay *r = ctx;
    (void)write;
    uint64_t lat = cycle - r->arrival[id];
    lats_add(r, &r->lat[r->chan[id]], lat);
    lats_add(r, &r->lat[r->p->channels], lat);
    if (cycle > r->last)
        r->last = cycle;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* Nearest rank: the smallest latency with at least ceil(pct x n / 100) latencies at or below it. */
static uint64_t percentile(const Lats *l, unsigned pct)
{
    if (!l->n)
        return 0;
    size_t rank = (size_t)(((uint64_t)pct * l->n + 99) / 100);
    return l->v[rank ? rank - 1 : 0];
}

/* A trace cycle in DRAM cycles: exact, floor(cycle x DRAM MHz / trace MHz). */
static uint64_t to_dram(uint64_t cycle, uint64_t trace_khz, int dram_mhz)
{
    if (!trace_khz)
        return cycle;
    unsigned __int128 x = (unsigned __int128)cycle * (unsigned __int128)dram_mhz * 1000u / trace_khz;
    return x > (unsigned __int128)(UINT64_MAX / 2) ? UINT64_MAX / 2 : (uint64_t)x;
}

static int grow_req(Replay *r)
{
    if (r->nreq < r->capreq)
        return 0;
    size_t cap = r->capreq ? 2 * r->capreq : 65536;
    uint64_t *a = realloc(r->arrival, cap * sizeof *a);
    if (a)
        r->arrival = a;
    uint8_t *c = realloc(r->chan, cap);
    if (c)
        r->chan = c;
    if (!a || !c)
        return -1;
    r->capreq = cap;
    return 0;
}

/* Reads the whole trace through the DRAM. 0, or -1 with the message in err. */
static int replay(Dram *d, MtrReader *t, Replay *r, char *err, size_t errlen)
{
    MtrRecord rec;
    int rc;
    uint64_t khz = mtr_clock_khz(t);
    r->first = UINT64_MAX;
    while ((rc = mtr_next(t, &rec, err, errlen)) == 1) {
        uint64_t c = to_dram(rec.cycle, khz, r->p->clock_mhz);
        if (grow_req(r)) {
            snprintf(err, errlen, "out of memory after %zu requests", r->nreq);
            return -1;
        }
        dram_run(d, c, on_done, r);
        r->arrival[r->nreq] = c;
        r->chan[r->nreq] = (uint8_t)dram_decode(r->p, rec.addr).ch;
        if (c < r->first)
            r->first = c;
        dram_push(d, rec.addr, rec.write, c, r->nreq++);
    }
    if (rc < 0)
        return -1;
    while (dram_outstanding(d))
        dram_run(d, dram_next(d) + 1, on_done, r);
    if (r->oom) {
        snprintf(err, errlen, "out of memory keeping %zu latencies", r->nreq);
        return -1;
    }
    for (int k = 0; k <= r->p->channels; k++)
        if (r->lat[k].n) /* a channel no request went to has no array */
            qsort(r->lat[k].v, r->lat[k].n, sizeof *r->lat[k].v, cmp_u32);
    if (!r->nreq)
        r->first = r->last = 0;
    return 0;
}

/* ---- the report --------------------------------------------------------------------------------- */

typedef struct Figures {
    uint64_t requests, reads, writes, p50, p95, p99, max;
    double gbs, share, avg, avg_ns, p50_ns, p95_ns, p99_ns, hit_rate, occ_avg;
} Figures;

static Figures figures(const DramParams *p, const Replay *r, const DramChanStats *s, const Lats *l, int nch)
{
    Figures f = {0};
    f.reads = s->reads;
    f.writes = s->writes;
    f.requests = s->reads + s->writes;
    uint64_t span = r->last > r->first ? r->last - r->first : 0;
    double ns_per = 1000.0 / p->clock_mhz;
    double peak = (double)p->bus_bits / 8 * p->beats * p->clock_mhz / 1000.0 * nch; /* GB/s */
    f.gbs = span ? (double)s->bytes / (span * ns_per) : 0;
    f.share = peak > 0 ? f.gbs / peak : 0;
    f.avg = f.requests ? (double)(s->read_latency + s->write_latency) / f.requests : 0;
    f.p50 = percentile(l, 50);
    f.p95 = percentile(l, 95);
    f.p99 = percentile(l, 99);
    f.max = s->max_latency;
    f.avg_ns = f.avg * ns_per;
    f.p50_ns = f.p50 * ns_per;
    f.p95_ns = f.p95 * ns_per;
    f.p99_ns = f.p99 * ns_per;
    f.hit_rate = f.requests ? (double)s->row_hits / f.requests : 0;
    f.occ_avg = s->cycles ? (double)s->occupancy_sum / s->cycles : 0;
    return f;
}

static void text_block(FILE *o, const char *name, const DramChanStats *s, const Figures *f)
{
    fprintf(o, "%s\n", name);
    fprintf(o, "  requests            %llu (%llu reads, %llu writes)\n", (unsigned long long)f->requests,
            (unsigned long long)f->reads, (unsigned long long)f->writes);
    fprintf(o, "  bandwidth           %.3f GB/s, %.1f%% of peak\n", f->gbs, 100 * f->share);
    fprintf(o, "  latency average     %.2f cycles (%.2f ns)\n", f->avg, f->avg_ns);
    fprintf(o, "  latency p50/p95/p99 %llu / %llu / %llu cycles (%.2f / %.2f / %.2f ns), max %llu\n",
            (unsigned long long)f->p50, (unsigned long long)f->p95, (unsigned long long)f->p99, f->p50_ns, f->p95_ns,
            f->p99_ns, (unsigned long long)f->max);
    fprintf(o, "  row buffer          %llu hits, %llu misses, %llu conflicts (hit rate %.1f%%)\n",
            (unsigned long long)s->row_hits, (unsigned long long)s->row_misses, (unsigned long long)s->row_conflicts,
            100 * f->hit_rate);
    fprintf(o, "  commands            %llu ACT, %llu PRE\n", (unsigned long long)s->activates,
            (unsigned long long)s->precharges);
    fprintf(o, "  queue occupancy     %.2f average, %llu max\n", f->occ_avg, (unsigned long long)s->occupancy_max);
    fprintf(o, "  refresh             %llu refreshes, %llu cycles\n", (unsigned long long)s->refreshes,
            (unsigned long long)s->refresh_cycles);
    fprintf(o, "  back-pressure       %llu requests waited %llu cycles for a queue slot\n",
            (unsigned long long)s->backpressured, (unsigned long long)s->backpressure);
}

static cJSON *json_block(const DramChanStats *s, const Figures *f)
{
    cJSON *o = cJSON_CreateObject();
#define DRAM_X(field, unit, desc) cJSON_AddNumberToObject(o, #field, (double)s->field);
    DRAM_STATS(DRAM_X)
#undef DRAM_X
    cJSON_AddNumberToObject(o, "requests", (double)f->requests);
    cJSON_AddNumberToObject(o, "bandwidth_gbs", f->gbs);
    cJSON_AddNumberToObject(o, "peak_share", f->share);
    cJSON_AddNumberToObject(o, "latency_avg", f->avg);
    cJSON_AddNumberToObject(o, "latency_p50", (double)f->p50);
    cJSON_AddNumberToObject(o, "latency_p95", (double)f->p95);
    cJSON_AddNumberToObject(o, "latency_p99", (double)f->p99);
    cJSON_AddNumberToObject(o, "latency_avg_ns", f->avg_ns);
    cJSON_AddNumberToObject(o, "latency_p50_ns", f->p50_ns);
    cJSON_AddNumberToObject(o, "latency_p95_ns", f->p95_ns);
    cJSON_AddNumberToObject(o, "latency_p99_ns", f->p99_ns);
    cJSON_AddNumberToObject(o, "row_hit_rate", f->hit_rate);
    cJSON_AddNumberToObject(o, "occupancy_avg", f->occ_avg);
    return o;
}

/* The DRAM's energy over the replay, cycles 0 to the last (sim/energy/dramenergy.h, docs/energy.md):
 * report.txt's lines and report.json's "energy". */
static cJSON *energy_block(FILE *o, const DramParams *p, const DramChanStats *s)
{
    DramEnergy e;
    const double rank_cycles = (double)p->channels * p->ranks * (double)s->cycles;
    dram_energy(p, s, rank_cycles, &e);
    const DramPower *w = &p->power;
    cJSON *j = cJSON_CreateObject();
    cJSON_AddBoolToObject(j, "known", e.known);
    cJSON_AddStringToObject(j, "source", w->source ? w->source : "");
    cJSON_AddNumberToObject(j, "io_pj_per_bit", e.io_pj_per_bit);
    cJSON_AddStringToObject(j, "io_source", w->io_source ? w->io_source : "");
    cJSON_AddNumberToObject(j, "io_j", e.io);
    if (!e.known) {
        fprintf(o, "energy\n  not computed: the preset gives no IDD currents (%s)\n", w->source ? w->source : "-");
        fprintf(o, "  I/O                 %.4g nJ (%g pJ/bit)\n", e.io * 1e9, e.io_pj_per_bit);
        fprintf(o, "  I/O figure          %g pJ/bit: %s\n", w->io_pj_bit, w->io_source ? w->io_source : "-");
        return j;
    }
    const double dev = (double)p->bus_bits / p->device_width;
    fprintf(o, "energy (IDD method, docs/energy.md): VDD %g V; IDD0 %g, IDD2N %g, IDD3N %g, IDD4R %g, IDD4W %g, IDD5B %g mA "
               "a device, %g devices a rank\n", w->vdd, w->idd0, w->idd2n, w->idd3n, w->idd4r, w->idd4w, w->idd5b, dev);
    fprintf(o, "  per command         ACT+PRE %.2f pJ, RD burst %.2f pJ, WR burst %.2f pJ, REF %.2f pJ\n", e.act_pj,
            e.rd_pj, e.wr_pj, e.ref_pj);
    fprintf(o, "  commands            activate %.4g nJ, read %.4g nJ, write %.4g nJ, refresh %.4g nJ\n", e.activate * 1e9,
            e.read * 1e9, e.write * 1e9, e.refresh * 1e9);
    fprintf(o, "  background          active standby %.4g nJ (%llu rank-cycles with a bank open, %llu refreshing), "
               "precharged standby %.4g nJ, of %.0f rank-cycles\n", e.background_active * 1e9,
            (unsigned long long)s->active_cycles, (unsigned long long)s->refresh_cycles, e.background_precharged * 1e9,
            rank_cycles);
    fprintf(o, "  total               %.4g nJ, %.3f pJ/bit; I/O apart: %.4g nJ (%g pJ/bit)\n", e.core * 1e9, e.pj_per_bit,
            e.io * 1e9, e.io_pj_per_bit);
    fprintf(o, "  I/O figure          %g pJ/bit: %s\n", w->io_pj_bit, w->io_source ? w->io_source : "-");
    const struct { const char *k; double v; } f[] = {
        {"vdd", w->vdd}, {"idd0", w->idd0}, {"idd2n", w->idd2n}, {"idd3n", w->idd3n}, {"idd4r", w->idd4r},
        {"idd4w", w->idd4w}, {"idd5b", w->idd5b}, {"devices_per_rank", dev}, {"act_pre_pj", e.act_pj},
        {"read_burst_pj", e.rd_pj}, {"write_burst_pj", e.wr_pj}, {"refresh_pj", e.ref_pj}, {"activate_j", e.activate},
        {"read_j", e.read}, {"write_j", e.write}, {"refresh_j", e.refresh}, {"background_active_j", e.background_active},
        {"background_precharged_j", e.background_precharged}, {"rank_cycles", rank_cycles}, {"total_j", e.core},
        {"pj_per_bit", e.pj_per_bit}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
        cJSON_AddNumberToObject(j, f[i].k, f[i].v);
    return j;
}

/* report.txt and report.json as text (malloc'ed), or -1. */
static int build_reports(const Dram *d, const Replay *r, const char *trace, MtrFormat fmt, char **txt, char **json)
{
    const DramParams *p = dram_get_params(d);
    const DramStats *s = dram_stats(d);
    size_t len;
    FILE *o = open_memstream(txt, &len);
    cJSON *root = cJSON_CreateObject(), *chans = cJSON_CreateArray();
    if (!o || !root || !chans) {
        if (o)
            fclose(o);
        cJSON_Delete(root);
        cJSON_Delete(chans);
        return -1;
    }
    const char *fname = fmt == MTR_SFSIM ? "sfsim" : "dramsim3";
    fprintf(o, "sfsim mem: %s (%s format), %zu requests, cycles %llu..%llu of the DRAM clock\n", trace, fname,
            r->nreq, (unsigned long long)r->first, (unsigned long long)r->last);
    fprintf(o, "DRAM: %s, %d MHz (tCK %.4f ns), %d channel%s of %d bits, %d B a burst, peak %.3f GB/s a channel\n",
            p->name, p->clock_mhz, 1000.0 / p->clock_mhz, p->channels, p->channels == 1 ? "" : "s", p->bus_bits,
            p->burst_bytes, (double)p->bus_bits / 8 * p->beats * p->clock_mhz / 1000.0);
    fprintf(o, "      mapping %s, %s page, queues %d read / %d write, write drain %d..%d\n", p->mapping,
            p->page_policy == DRAM_PAGE_CLOSED ? "closed" : "open", p->read_queue, p->write_queue, p->write_low,
            p->write_high);
    cJSON_AddStringToObject(root, "trace", trace);
    cJSON_AddStringToObject(root, "format", fname);
    cJSON_AddStringToObject(root, "preset", p->name);
    cJSON_AddNumberToObject(root, "clock_mhz", p->clock_mhz);
    cJSON_AddStringToObject(root, "mapping", p->mapping);
    cJSON_AddStringToObject(root, "page_policy", p->page_policy == DRAM_PAGE_CLOSED ? "closed" : "open");
    cJSON_AddNumberToObject(root, "first_cycle", (double)r->first);
    cJSON_AddNumberToObject(root, "last_cycle", (double)r->last);
    for (int k = 0; k < p->channels; k++) {
        Figures f = figures(p, r, &s->chan[k], &r->lat[k], 1);
        char name[32];
        snprintf(name, sizeof name, "channel %d", k);
        if (p->channels > 1)
            text_block(o, name, &s->chan[k], &f);
        cJSON_AddItemToArray(chans, json_block(&s->chan[k], &f));
    }
    Figures f = figures(p, r, &s->total, &r->lat[p->channels], p->channels);
    text_block(o, "total", &s->total, &f);
    cJSON_AddItemToObject(root, "channels", chans);
    cJSON_AddItemToObject(root, "total", json_block(&s->total, &f));
    cJSON_AddItemToObject(root, "energy", energy_block(o, p, &s->total));
    int bad = fclose(o) != 0;
    char *j = cJSON_Print(root);
    cJSON_Delete(root);
    *json = j ? malloc(strlen(j) + 2) : NULL;
    if (*json)
        sprintf(*json, "%s\n", j);
    free(j);
    if (bad || !*json) {
        free(*txt);
        free(*json);
        return -1;
    }
    return 0;
}

static int write_outputs(const char *dir, const char *txt, const char *json, char *err, size_t errlen)
{
    OutDirs dirs = {0};
    OutSet *set = outset_new();
    char a[4096], b[4096];
    snprintf(a, sizeof a, "%s/report.txt", dir);
    snprintf(b, sizeof b, "%s/report.json", dir);
    int rc = -1;
    if (!set)
        snprintf(err, errlen, "%s: out of memory", dir);
    else if (outfile_make_dirs(dir, &dirs, err, errlen) == 0 &&
             outfile_write_file(set, a, txt, strlen(txt), err, errlen) == 0 &&
             outfile_write_file(set, b, json, strlen(json), err, errlen) == 0 && outset_commit(set, err, errlen) == 0) {
        outfile_keep_dirs(&dirs);
        rc = 0;
    }
    outset_free(set);
    outfile_remove_dirs(&dirs);
    return rc;
}

/* ---- the command -------------------------------------------------------------------------------- */

typedef struct MemOpts {
    CliConfig cfg;
    const char *trace, *out, *mapping;
    MtrFormat fmt;
    int json;
} MemOpts;

/* EXIT_OK to go on, or the code to return (-1: --help or --version printed). */
static int parse(int argc, char **argv, MemOpts *m)
{
    CliParse p = {"sfsim mem", "mem", mem_longs, "c:o:h", argc, argv, 0};
    int code;
    const char *v;
    while ((code = cli_next(&p, &v)) > 0) {
        if (cli_common(&p, code, help_mem))
            return -1;
        if (code == 'c')
            m->cfg.path = v;
        else if (code == M_SET && cli_config_set(&m->cfg, v))
            return EXIT_USAGE;
        else if (code == M_TRACE)
            m->trace = v;
        else if (code == 'o')
            m->out = v;
        else if (code == M_JSON)
            m->json = 1;
        else if (code == M_MAPPING)
            m->mapping = v;
        else if (code == M_FORMAT) {
            if (!strcmp(v, "dramsim3"))
                m->fmt = MTR_DRAMSIM3;
            else if (!strcmp(v, "sfsim"))
                m->fmt = MTR_SFSIM;
            else if (!strcmp(v, "auto"))
                m->fmt = MTR_AUTO;
            else {
                fprintf(stderr, "sfsim mem: --format %s: expected dramsim3, sfsim or auto\n", v);
                return EXIT_INPUT;
            }
        }
    }
    if (code < 0)
        return EXIT_USAGE;
    if (cli_first_operand() < argc) {
        fprintf(stderr, "sfsim mem: unexpected argument '%s' (sfsim help mem)\n", argv[cli_first_operand()]);
        return EXIT_USAGE;
    }
    if (!m->trace) {
        fprintf(stderr, "sfsim mem: give the trace: --trace FILE (sfsim help mem)\n");
        return EXIT_USAGE;
    }
    return EXIT_OK;
}

static Dram *open_dram(const MemOpts *m, DramParams *dp)
{
    CfgMachine cfg;
    char err[512];
    if (cli_config_build(&m->cfg, &cfg))
        return NULL;
    if (dram_params(&cfg, dp, err, sizeof err)) {
        fprintf(stderr, "sfsim mem: %s\n", err);
        return NULL;
    }
    if (m->mapping) {
        if (strlen(m->mapping) >= sizeof dp->mapping) {
            fprintf(stderr, "sfsim mem: --mapping %.80s: longer than %zu characters\n", m->mapping,
                    sizeof dp->mapping - 1);
            return NULL;
        }
        snprintf(dp->mapping, sizeof dp->mapping, "%s", m->mapping);
        if (dram_params_check(dp, err, sizeof err)) {
            fprintf(stderr, "sfsim mem: --mapping: %s\n", err);
            return NULL;
        }
    }
    Dram *d = dram_new(dp, err, sizeof err);
    if (!d)
        fprintf(stderr, "sfsim mem: %s\n", err);
    return d;
}

int cmd_mem(int argc, char **argv)
{
    MemOpts m = {0};
    int rc = parse(argc, argv, &m);
    if (rc) {
        cli_config_free(&m.cfg);
        return rc < 0 ? EXIT_OK : rc;
    }
    char err[4096];
    rc = EXIT_INPUT;
    if (m.out && outfile_check_dir(m.out, err, sizeof err)) {
        fprintf(stderr, "sfsim mem: %s\n", err);
        cli_config_free(&m.cfg);
        return EXIT_IO;
    }
    DramParams dp;
    Dram *d = open_dram(&m, &dp);
    MtrReader *t = d ? mtr_open(m.trace, m.fmt, err, sizeof err) : NULL;
    Replay r = {.p = d ? dram_get_params(d) : NULL};
    char *txt = NULL, *json = NULL;
    if (d && !t)
        fprintf(stderr, "sfsim mem: %s\n", err);
    if (!d || !t)
        goto out;
    r.lat = calloc((size_t)r.p->channels + 1, sizeof *r.lat);
    if (!r.lat || replay(d, t, &r, err, sizeof err)) {
        fprintf(stderr, "sfsim mem: %s\n", r.lat ? err : "out of memory");
        goto out;
    }
    if (build_reports(d, &r, m.trace, mtr_format(t), &txt, &json)) {
        fprintf(stderr, "sfsim mem: out of memory writing the report\n");
        goto out;
    }
    fputs(m.json ? json : txt, stdout);
    rc = EXIT_OK;
    if (m.out && write_outputs(m.out, txt, json, err, sizeof err)) {
        fprintf(stderr, "sfsim mem: %s\n", err);
        rc = EXIT_IO;
    }
out:
    free(txt);
    free(json);
    for (int k = 0; r.lat && k <= r.p->channels; k++)
        free(r.lat[k].v);
    free(r.lat);
    free(r.arrival);
    free(r.chan);
    mtr_close(t);
    dram_free(d);
    cli_config_free(&m.cfg);
    return rc;
}
