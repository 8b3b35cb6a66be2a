/* sim/timeline_write.c -- the timeline's file: the Chrome trace event format's JSON object form
 * (timeline.h; docs/timeline.md), written whole or not at all.
 *
 * Owns: the names, processes, threads and counters of the file. Must not: record anything.
 */
#include "timeline_int.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../host/outfile.h"
#include "../isa/isa.h"
#include "chip/chip.h"

typedef struct TlOut {
    OutFile f;
    char *err;
    size_t errlen;
    int failed;
    int first;                 /* no event written yet (no comma before it) */
    uint64_t seq;              /* async slices' ids */
} TlOut;

static void out(TlOut *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void out(TlOut *o, const char *fmt, ...)
{
    if (o->failed)
        return;
    char buf[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= sizeof buf || outfile_write(&o->f, buf, (size_t)n, o->err, o->errlen))
        o->failed = 1;
}

/* The start of an event: a comma before every one but the first. */
static void ev(TlOut *o)
{
    out(o, o->first ? "\n" : ",\n");
    o->first = 0;
}

static void name_of(const TlEv *e, char *buf, size_t len)
{
    if (e->name == N_BUSY)
        snprintf(buf, len, "busy");
    else if (e->name == N_IDLE)
        snprintf(buf, len, "idle");
    else if (e->name < N_FROM)
        snprintf(buf, len, "stall: %s", tm_cause_keys[e->name - N_STALL]);
    else if (e->name < N_UNIT)
        snprintf(buf, len, "stall: scene_memory (%s)", e->name == N_FROM + TIMING_FROM_L2 ? "l2" : "dram");
    else if (e->name < N_PASS)
        snprintf(buf, len, "%s", timing_unit_keys[e->name - N_UNIT]);
    else if (e->name == N_PASS)
        snprintf(buf, len, "tile %llu pass %llu", (unsigned long long)e->a, (unsigned long long)e->b);
    else if (e->name == N_READ || e->name == N_WRITE)
        snprintf(buf, len, "%s", e->name == N_READ ? "read" : "write");
    else
        snprintf(buf, len, "%s", isa_ops[(e->a >> 32) % ISA_OP_COUNT].mnemonic);
}

static void meta(TlOut *o, int pid, int tid, const char *what, const char *name)
{
    ev(o);
    if (tid < 0)
        out(o, "{\"ph\":\"M\",\"pid\":%d,\"name\":\"%s\",\"args\":{\"name\":\"%s\"}}", pid, what, name);
    else
        out(o, "{\"ph\":\"M\",\"pid\":%d,\"tid\":%d,\"name\":\"%s\",\"args\":{\"name\":\"%s\"}}", pid, tid, what,
            name);
}

static void spans(TlOut *o, int pid, int tid, const char *cat, const TlList *l)
{
    char name[64];
    for (size_t i = 0; i < l->n; i++) {
        const TlEv *e = &l->v[i];
        name_of(e, name, sizeof name);
        ev(o);
        out(o, "{\"ph\":\"X\",\"pid\":%d,\"tid\":%d,\"cat\":\"%s\",\"name\":\"%s\",\"ts\":%llu,\"dur\":%llu}", pid, tid, cat,
            name, (unsigned long long)e->from, (unsigned long long)(e->to - e->from));
    }
}

/* Requests (or instructions) as async slices, each with an id of its own. */
static void slices(TlOut *o, int pid, int tid, const char *cat, const TlList *l)
{
    char name[64];
    for (size_t i = 0; i < l->n; i++) {
        const TlEv *e = &l->v[i];
        const unsigned long long id = (unsigned long long)++o->seq;
        name_of(e, name, sizeof name);
        ev(o);
        if (e->name == N_INSTR) {
            char cause[64] = "";
            if (e->c) {
                const TlEv c = {.name = e->c};
                name_of(&c, cause, sizeof cause);
            }
            out(o, "{\"ph\":\"b\",\"pid\":%d,\"tid\":%d,\"cat\":\"%s\",\"id\":%llu,\"name\":\"%s\",\"ts\":%llu,"
                "\"args\":{\"pc\":%u,\"issue\":%llu,\"complete\":%llu,\"stall_cycles\":%llu,\"stall_cause\":\"%s\"}}",
                pid, tid, cat, id, name, (unsigned long long)e->from, (unsigned)(uint32_t)e->a,
                (unsigned long long)e->from, (unsigned long long)e->to, (unsigned long long)e->b,
                e->c ? cause + strlen("stall: ") : "");
        } else {
            out(o, "{\"ph\":\"b\",\"pid\":%d,\"tid\":%d,\"cat\":\"%s\",\"id\":%llu,\"name\":\"%s\",\"ts\":%llu,"
                "\"args\":{\"addr\":\"0x%llx\",\"request\":\"0x%llx\"}}", pid, tid, cat, id, name,
                (unsigned long long)e->from, (unsigned long long)e->a, (unsigned long long)e->b);
        }
        ev(o);
        out(o, "{\"ph\":\"e\",\"pid\":%d,\"tid\":%d,\"cat\":\"%s\",\"id\":%llu,\"name\":\"%s\",\"ts\":%llu}", pid, tid,
            cat, id, name, (unsigned long long)e->to);
    }
}

typedef struct Step {
    uint64_t at;
    int d;
} Step;

static int step_order(const void *pa, const void *pb)
{
    const Step *a = pa, *b = pb;
    return a->at < b->at ? -1 : a->at > b->at;
}

/* A counter of the slices of l in flight, a point wherever it changes. -1 on out of memory. */
static int in_flight(TlOut *o, int pid, const char *name, const TlList *l)
{
    if (!l->n)
        return 0;
    Step *s = malloc(2 * l->n * sizeof *s);
    if (!s)
        return -1;
    for (size_t i = 0; i < l->n; i++) {
        s[2 * i] = (Step){l->v[i].from, 1};
        s[2 * i + 1] = (Step){l->v[i].to, -1};
    }
    qsort(s, 2 * l->n, sizeof *s, step_order);
    long long n = 0;
    for (size_t i = 0; i < 2 * l->n;) {
        const uint64_t at = s[i].at;
        for (; i < 2 * l->n && s[i].at == at; i++)
            n += s[i].d;
        ev(o);
        out(o, "{\"ph\":\"C\",\"pid\":%d,\"name\":\"%s\",\"ts\":%llu,\"args\":{\"requests\":%lld}}", pid, name,
            (unsigned long long)at, n);
    }
    free(s);
    return 0;
}

static const char *const thread_names[T_COUNT] = {"issue", "work", NULL, NULL, NULL, NULL, NULL, "bus requests",
                                                  "pipeline"};

static int write_core(TlOut *o, const Timeline *tl, int k)
{
    const TlCore *c = &tl->core[k];
    const int pid = k + 1;
    char name[64];
    snprintf(name, sizeof name, "core %d", k);
    meta(o, pid, -1, "process_name", name);
    for (int t = 0; t < T_COUNT; t++) {
        if (t != T_ISSUE && !c->t[t].n)
            continue;
        if (t >= T_UNIT && t < T_BUS)
            snprintf(name, sizeof name, "unit: %s", timing_unit_keys[t - T_UNIT]);
        else
            snprintf(name, sizeof name, "%s", thread_names[t]);
        meta(o, pid, t, "thread_name", name);
    }
    spans(o, pid, T_ISSUE, "core", &c->t[T_ISSUE]);
    spans(o, pid, T_WORK, "work", &c->t[T_WORK]);
    for (int u = 0; u < TIMING_UNIT_COUNT; u++)
        spans(o, pid, T_UNIT + u, "unit", &c->t[T_UNIT + u]);
    slices(o, pid, T_BUS, "bus", &c->t[T_BUS]);
    slices(o, pid, T_PIPE, "pipeline", &c->t[T_PIPE]);
    return in_flight(o, pid, "bus requests in flight", &c->t[T_BUS]);
}

static int write_memory(TlOut *o, const Timeline *tl)
{
    const int pid = tl->cores + 1;
    int any = 0;
    for (int i = 0; i < CHIP_LEVELS; i++)
        any |= tl->level[i].n > 0;
    if (!any)
        return 0;
    meta(o, pid, -1, "process_name", "shared memory");
    char name[64];
    for (int i = 0; i < CHIP_LEVELS; i++) {
        if (!tl->level[i].n)
            continue;
        meta(o, pid, T_LEVEL + i, "thread_name", chip_level_keys[i]);
        slices(o, pid, T_LEVEL + i, chip_level_keys[i], &tl->level[i]);
        snprintf(name, sizeof name, "%s requests in flight", chip_level_keys[i]);
        if (in_flight(o, pid, name, &tl->level[i]))
            return -1;
    }
    return 0;
}

int timeline_write(const Timeline *tl, const char *path, char *err, size_t errlen)
{
    int oom = tl->oom;
    for (int k = 0; k < tl->cores; k++)
        oom |= tl->core[k].oom;
    if (oom) {
        snprintf(err, errlen, "%s: out of memory recording the timeline (a shorter --timeline-window needs less)",
                 path);
        return -1;
    }
    uint64_t mismatch = 0;
    for (int k = 0; k < tl->cores; k++)
        mismatch += tl->core[k].mismatch;
    if (mismatch) {
        snprintf(err, errlen, "%s: timeline: internal error: %llu instructions' stalls did not fill their cycles",
                 path, (unsigned long long)mismatch);
        return -1;
    }
    TlOut o = {.err = err, .errlen = errlen, .first = 1};
    if (outfile_open(&o.f, path, err, errlen))
        return -1;
    out(&o, "{\"otherData\":{\"format\":\"sfsim timeline 1\",\"time_unit\":\"cycle (1 us on the axis = 1 cycle)\","
        "\"clock_mhz\":%g,\"window\":[%llu,%llu],\"cores\":%d},\n\"traceEvents\":[", tl->clock_mhz,
        (unsigned long long)tl->from, (unsigned long long)tl->to, tl->cores);
    for (int k = 0; k < tl->cores && !o.failed; k++)
        if (write_core(&o, tl, k)) {
            snprintf(err, errlen, "%s: out of memory writing the timeline", path);
            o.failed = 1;
        }
    if (!o.failed && write_memory(&o, tl)) {
        snprintf(err, errlen, "%s: out of memory writing the timeline", path);
        o.failed = 1;
    }
    out(&o, "\n]}\n");
    if (o.failed) {
        outfile_discard(&o.f);
        return -1;
    }
    return outfile_close(&o.f, NULL, err, errlen);
}
