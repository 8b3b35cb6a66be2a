/* sim/config.c -- machine-config keys from sim/config.def: defaults, INI reading (through
 * sim/ini.c, the INI reader of every file: docs/ini.md), --set overrides, checks, listings.
 *
 * Owns: turning text into CfgMachine values and saying precisely what is wrong with bad text.
 * Must not: exit, or interpret what a key means for the machine.
 */
#include "config.h"

#include "chip/chip.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "ini.h"

typedef enum CfgType { CFG_INT, CFG_I64, CFG_FLOAT, CFG_ENUM } CfgType;

/* The names of ENUM keys' values, in index order (sim/config.h has the index constants). */
#define CFG_ENUM_NAMES 8
static const struct { const char *section, *key; const char *names[CFG_ENUM_NAMES]; } enum_names[] = {
    {"stream", "mode", {"stream", "packet"}},
    {"stream", "order", {"ray", "first"}},
    {"workload", "kind", {"path", "specular", "diffuse", "phong"}},
    {"accel", "structure", {"bvh", "kd"}},
    {"kd", "traversal", {"stack", "restart", "pushdown", "shortstack", "packet", "stream"}},
    /* sim/mem/dram_presets.def's rows, in order (DramPreset). */
    {"dram", "preset", {"ddr4_2400", "ddr5_4800", "lpddr5_6400", "gddr6_14000", "hbm2_2000"}},
    /* Field orders (sim/mem/dram.h; config keys hold no free strings, `sfsim mem --mapping` takes any). */
    {"dram", "mapping", {"preset", "ro,ra,ba,co,bg,ch", "ro,ra,bg,ba,co,ch", "ro,ra,ba,bg,co,ch", "ch,ro,ba,bg,ra,co",
                         "ro,ra,bg,ba,ch,co", "ro,co,ra,ba,bg,ch"}},
    {"dram", "page_policy", {"open", "closed"}},
    {"kernel", "schedule", {"none", "list"}},
    {"chip", "memory", {"bus", "shared"}},
    {"l2", "write_policy", {"back", "through"}},
};

static const char *const *enum_of(const char *section, const char *key)
{
    for (size_t i = 0; i < sizeof enum_names / sizeof enum_names[0]; i++)
        if (!strcmp(enum_names[i].section, section) && !strcmp(enum_names[i].key, key))
            return enum_names[i].names;
    return NULL;
}

const char *cfg_enum_name(const char *section, const char *key, int value)
{
    const char *const *n = enum_of(section, key);
    if (!n || value < 0 || value >= CFG_ENUM_NAMES)
        return NULL;
    return n[value];
}

typedef struct CfgKeyInfo {
    const char *section, *key;
    CfgType type;
    double def, lo, hi;
    long long ilo, ihi;  /* exact bounds of integer keys */
    const char *help;
    size_t offset;
} CfgKeyInfo;

static const CfgKeyInfo keys[] = {
#define CFG_KEY(sec, key, type, def, lo, hi, help) \
    {#sec, #key, CFG_##type, (double)(def), (double)(lo), (double)(hi), (long long)(lo), (long long)(hi), help, \
     offsetof(CfgMachine, sec##_##key)},
#include "config.def"
#undef CFG_KEY
};
#define NKEYS (sizeof keys / sizeof keys[0])

static void add_error(CfgErrors *e, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    if ((size_t)n >= sizeof line)
        n = (int)sizeof line - 1;
    char *t = realloc(e->text, e->len + (size_t)n + 2);
    if (!t)
        return;
    e->text = t;
    memcpy(e->text + e->len, line, (size_t)n);
    e->len += (size_t)n;
    e->text[e->len++] = '\n';
    e->text[e->len] = 0;
    e->count++;
}

void cfg_errors_free(CfgErrors *errs)
{
    free(errs->text);
    memset(errs, 0, sizeof *errs);
}

/* A parsed value: integers keep all 64 bits (a double would round above 2^53). */
typedef struct CfgValue { double f; long long i; } CfgValue;

static void store(CfgMachine *cfg, const CfgKeyInfo *k, CfgValue v)
{
    char *p = (char *)cfg + k->offset;
    if (k->type == CFG_INT || k->type == CFG_ENUM) {
        int32_t x = (int32_t)v.i;
        memcpy(p, &x, sizeof x);
    } else if (k->type == CFG_I64) {
        int64_t x = (int64_t)v.i;
        memcpy(p, &x, sizeof x);
    } else {
        memcpy(p, &v.f, sizeof v.f);
    }
}

static double load(const CfgMachine *cfg, const CfgKeyInfo *k)
{
    const char *p = (const char *)cfg + k->offset;
    if (k->type == CFG_INT || k->type == CFG_ENUM) {
        int32_t x;
        memcpy(&x, p, sizeof x);
        return x;
    }
    if (k->type == CFG_I64) {
        int64_t x;
        memcpy(&x, p, sizeof x);
        return (double)x;
    }
    double x;
    memcpy(&x, p, sizeof x);
    return x;
}

void cfg_defaults(CfgMachine *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    for (size_t i = 0; i < NKEYS; i++)
        store(cfg, &keys[i], (CfgValue){keys[i].def, (long long)keys[i].def});
}

static const CfgKeyInfo *find(const char *section, const char *key)
{
    for (size_t i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0 && strcmp(keys[i].key, key) == 0)
            return &keys[i];
    return NULL;
}

static int section_known(const char *section)
{
    for (size_t i = 0; i < NKEYS; i++)
        if (strcmp(keys[i].section, section) == 0)
            return 1;
    return 0;
}

/* Keys whose range excludes its lower end 0: kd_build takes costs > 0 and an empty bonus in (0, 1]
 * (a bonus of 0 would make every split with an empty side free). Checked in binary32, the
 * builder's precision, so that a tiny value does not reach it as 0. */
static int must_be_positive(const CfgKeyInfo *k)
{
    static const char *const kd_keys[] = {"cost_traversal", "cost_intersect", "empty_bonus"};
    for (size_t i = 0; i < sizeof kd_keys / sizeof kd_keys[0]; i++)
        if (strcmp(k->section, "kd") == 0 && strcmp(k->key, kd_keys[i]) == 0)
            return 1;
    return 0;
}

/* Parse and range-check; returns NULL on success or a message in buf. */
static const char *parse_value(const CfgKeyInfo *k, const char *text, CfgValue *out, char *buf, size_t buflen)
{
    while (*text == ' ' || *text == '\t')
        text++;
    if (!*text)
        return "missing value";
    if (k->type == CFG_ENUM) {
        const char *const *names = enum_of(k->section, k->key);
        size_t len = strlen(text);
        while (len && (text[len - 1] == ' ' || text[len - 1] == '\t'))
            len--;
        size_t used = (size_t)snprintf(buf, buflen, "expected one of");
        for (long long i = k->ilo; names && i <= k->ihi; i++) {
            if (strlen(names[i]) == len && !strncmp(names[i], text, len)) {
                out->i = i;
                out->f = (double)i;
                return NULL;
            }
            if (used < buflen)
                used += (size_t)snprintf(buf + used, buflen - used, "%s %s", i > k->ilo ? "," : "", names[i]);
        }
        if (used < buflen)
            snprintf(buf + used, buflen - used, ", got '%.*s'", (int)len, text);
        return buf;
    }
    char *end;
    errno = 0;
    int bad_range;
    if (k->type == CFG_FLOAT) {
        out->f = strtod(text, &end);
        out->i = 0;
        bad_range = errno == ERANGE || !isfinite(out->f) || out->f < k->lo || out->f > k->hi;
    } else {
        out->i = strtoll(text, &end, 10); /* decimal: "010" is ten, not octal eight */
        out->f = (double)out->i;
        /* Bounds compared as integers: the table's limits are exact in long long. */
        bad_range = errno == ERANGE || out->i < k->ilo || out->i > k->ihi;
    }
    while (*end == ' ' || *end == '\t')
        end++;
    if (end == text || *end) {
        snprintf(buf, buflen, "expected %s, got '%s'", k->type == CFG_FLOAT ? "a number" : "an integer", text);
        return buf;
    }
    if (bad_range) {
        if (k->type == CFG_FLOAT)
            snprintf(buf, buflen, "value %s out of range %g..%g", text, k->lo, k->hi);
        else
            snprintf(buf, buflen, "value %s out of range %lld..%lld", text, k->ilo, k->ihi);
        return buf;
    }
    if (strcmp(k->section, "stream") == 0 && strcmp(k->key, "rays") == 0 && out->i != 1024 && out->i != 4096) {
        snprintf(buf, buflen, "value %s: must be 1024 or 4096", text);
        return buf;
    }
    if (k->type == CFG_FLOAT && must_be_positive(k) && !((float)out->f > 0.0f)) {
        snprintf(buf, buflen, "value %s: must be greater than 0", text);
        return buf;
    }
    return NULL;
}

/* Check every key of a parsed file against the table and store the good ones; the messages
 * (the reader's and these, in line order) go to errs. */
static int load_file(CfgMachine *cfg, IniFile *f, CfgErrors *errs)
{
    for (int i = 0; i < f->nentries; i++) {
        const IniEntry *e = &f->entries[i];
        const CfgKeyInfo *k = find(e->section, e->key);
        if (!k) {
            if (!section_known(e->section))
                inifile_error(f, e->line, "key '%s.%s': unknown section [%s]", e->section, e->key, e->section);
            else
                inifile_error(f, e->line, "key '%s.%s': unknown key", e->section, e->key);
            continue;
        }
        CfgValue v;
        char buf[256];
        /* An indented line below a key continues its value (docs/ini.md); no machine key takes
         * more than one line. */
        const char *msg = strchr(e->value, '\n') ? "continued on an indented line: the value must be on one line"
                                                  : parse_value(k, e->value, &v, buf, sizeof buf);
        if (msg) {
            inifile_error(f, e->line, "key '%s.%s': %s", e->section, e->key, msg);
            continue;
        }
        store(cfg, k, v);
    }
    int n, before = errs->count, count = f->nerrors;
    const IniMessage *m = inifile_messages(f, &n);
    for (int i = 0; i < n; i++)
        add_error(errs, "%s", m[i].text);
    errs->count = before + count; /* a last "... and N more errors" line stands for N */
    inifile_free(f);
    return count;
}

/* A section may appear again in a machine config (sfsim config --dump writes [raybuf] twice:
 * config.def keeps a unit's timing keys together); a key still appears once. */
static const IniOptions cfg_ini = {1, 0, NULL};

int cfg_load_stream(CfgMachine *cfg, FILE *f, const char *name, CfgErrors *errs)
{
    IniFile ini;
    inifile_load_stream(&ini, f, name, &cfg_ini);
    return load_file(cfg, &ini, errs);
}

int cfg_load_text(CfgMachine *cfg, const char *text, size_t len, const char *name, CfgErrors *errs)
{
    IniFile ini;
    inifile_parse(&ini, name, text, len, &cfg_ini);
    return load_file(cfg, &ini, errs);
}

int cfg_load(CfgMachine *cfg, const char *path, CfgErrors *errs)
{
    IniFile ini;
    inifile_load(&ini, path, &cfg_ini);
    return load_file(cfg, &ini, errs);
}

int cfg_set(CfgMachine *cfg, const char *assignment, CfgErrors *errs)
{
    const char *eq = strchr(assignment, '=');
    const char *dot = strchr(assignment, '.');
    if (!eq || !dot || dot > eq) {
        add_error(errs, "--set %s: expected section.key=value", assignment);
        return 1;
    }
    char section[128], key[128];
    size_t sl = (size_t)(dot - assignment), kl = (size_t)(eq - dot - 1);
    if (sl == 0 || kl == 0 || sl >= sizeof section || kl >= sizeof key) {
        add_error(errs, "--set %s: expected section.key=value", assignment);
        return 1;
    }
    memcpy(section, assignment, sl);
    section[sl] = 0;
    memcpy(key, dot + 1, kl);
    key[kl] = 0;
    const CfgKeyInfo *k = find(section, key);
    if (!k) {
        add_error(errs, "--set %s: unknown key '%s.%s' (sfsim config --dump lists them)", assignment, section, key);
        return 1;
    }
    CfgValue v;
    char buf[256];
    const char *msg = parse_value(k, eq + 1, &v, buf, sizeof buf);
    if (msg) {
        add_error(errs, "--set %s: %s", assignment, msg);
        return 1;
    }
    store(cfg, k, v);
    return 0;
}

int cfg_check(const CfgMachine *cfg, CfgErrors *errs)
{
    int before = errs->count;
    if (cfg->raybuf_size_kb % cfg->raybuf_banks != 0)
        add_error(errs, "config: raybuf.size_kb = %d is not divisible by raybuf.banks = %d", cfg->raybuf_size_kb,
                  cfg->raybuf_banks);
    /* Gribble & Ramani 2008, Sec. 4: a stream's records must fit one buffer; a record is at most
     * 128 bytes (ARCHITECTURE.md Sec. 3), so M rays need M x 128 bytes. */
    if ((int64_t)cfg->stream_rays * 128 > (int64_t)cfg->raybuf_size_kb * 1024)
        add_error(errs, "config: stream.rays = %d needs %d KiB of ray buffer at 128 bytes per ray, raybuf.size_kb = %d",
                  cfg->stream_rays, cfg->stream_rays * 128 / 1024, cfg->raybuf_size_kb);
    /* Two ID streams (current and next generation) of M IDs each. */
    if ((int64_t)cfg->stream_rays * 8 > (int64_t)cfg->idm_size_kb * 1024)
        add_error(errs, "config: stream.rays = %d needs %d KiB of ID-stream memory (two streams), idm.size_kb = %d",
                  cfg->stream_rays, cfg->stream_rays * 8 / 1024, cfg->idm_size_kb);
    /* The forced specular workload bounces at least once (phong may stop at its shadow rays). */
    if (cfg->workload_kind == CFG_WORKLOAD_SPECULAR && cfg->workload_bounces < 1)
        add_error(errs, "config: workload.bounces = %d: workload.kind = specular needs at least 1 bounce",
                  cfg->workload_bounces);
    /* Timing model: line sizes are powers of two; the scene cache divides into whole sets. */
    const struct { const char *key; int v; } pow2[] = {
        {"raybuf.line_bytes", cfg->raybuf_line_bytes}, {"spad.line_bytes", cfg->spad_line_bytes},
        {"scene.line_bytes", cfg->scene_line_bytes}};
    for (size_t i = 0; i < sizeof pow2 / sizeof pow2[0]; i++)
        if (pow2[i].v & (pow2[i].v - 1))
            add_error(errs, "config: %s = %d is not a power of two", pow2[i].key, pow2[i].v);
    char why[600];
    if (chip_check(cfg, why, sizeof why))
        add_error(errs, "config: %s", why);
    if (cfg->scene_cache_kb > 0) {
        int64_t set_bytes = (int64_t)cfg->scene_line_bytes * cfg->scene_cache_ways;
        if (((int64_t)cfg->scene_cache_kb * 1024) % set_bytes != 0)
            add_error(errs, "config: scene.cache_kb = %d is not a whole number of sets of scene.cache_ways = %d x "
                      "scene.line_bytes = %d", cfg->scene_cache_kb, cfg->scene_cache_ways, cfg->scene_line_bytes);
    }
    return errs->count - before;
}

void cfg_core_params(const CfgMachine *cfg, CoreParams *p)
{
    memset(p, 0, sizeof *p);
    p->lanes = cfg->core_simd_width;
    p->mem_bytes[CORE_MEM_RB0] = p->mem_bytes[CORE_MEM_RB1] = (uint32_t)cfg->raybuf_size_kb * 1024u;
    p->mem_bytes[CORE_MEM_IDM] = (uint32_t)cfg->idm_size_kb * 1024u;
    p->mem_bytes[CORE_MEM_SPAD] = (uint32_t)cfg->spad_size_kb * 1024u;
    p->mem_bytes[CORE_MEM_SCENE] = (uint32_t)cfg->scene_size_mb * 1024u * 1024u;
    p->mem_bytes[CORE_MEM_FB] = (uint32_t)cfg->fb_size_kb * 1024u;
}

static const char *type_name(CfgType t)
{
    return t == CFG_INT ? "int" : t == CFG_I64 ? "int64" : t == CFG_ENUM ? "enum" : "float";
}

static void fmt_value(const CfgKeyInfo *k, double v, char *buf, size_t len)
{
    if (k->type == CFG_ENUM) {
        const char *n = cfg_enum_name(k->section, k->key, (int)v);
        snprintf(buf, len, "%s", n ? n : "?");
    } else if (k->type == CFG_FLOAT)
        snprintf(buf, len, "%g", v);
    else
        snprintf(buf, len, "%.0f", v);
}

/* "a, b, c": the names of an ENUM key. */
static const char *enum_list(const CfgKeyInfo *k, char *buf, size_t len)
{
    const char *const *names = enum_of(k->section, k->key);
    size_t used = 0;
    buf[0] = 0;
    for (long long i = k->ilo; names && i <= k->ihi && used < len; i++)
        used += (size_t)snprintf(buf + used, len - used, "%s%s", i > k->ilo ? ", " : "", names[i]);
    return buf;
}

/* A comment of the dump, wrapped at spaces into lines of at most 100 characters: every line of a
 * dump is read back by the INI reader, whose lines hold at most 198 (docs/ini.md). */
static void dump_comment(FILE *out, const char *text)
{
    enum { WIDTH = 100 - 6 }; /* "    ; " */
    while (*text) {
        size_t n = strlen(text);
        if (n > WIDTH) {
            n = WIDTH;
            while (n > 0 && text[n] != ' ')
                n--;
            if (n == 0) /* one word longer than a line: cut it */
                n = WIDTH;
        }
        fprintf(out, "    ; %.*s\n", (int)n, text);
        text += n;
        while (*text == ' ')
            text++;
    }
}

void cfg_dump(const CfgMachine *cfg, FILE *out)
{
    const char *sec = "";
    for (size_t i = 0; i < NKEYS; i++) {
        const CfgKeyInfo *k = &keys[i];
        if (strcmp(sec, k->section) != 0) {
            fprintf(out, "%s[%s]\n", i ? "\n" : "", k->section);
            sec = k->section;
        }
        char val[64], def[64], lo[64], hi[64], text[1024];
        fmt_value(k, load(cfg, k), val, sizeof val);
        fmt_value(k, k->def, def, sizeof def);
        fmt_value(k, k->lo, lo, sizeof lo);
        fmt_value(k, k->hi, hi, sizeof hi);
        if (k->type == CFG_ENUM)
            snprintf(text, sizeof text, "%s, default %s, one of %s: %s", type_name(k->type), def,
                     enum_list(k, lo, sizeof lo), k->help);
        else
            snprintf(text, sizeof text, "%s, default %s, range %s..%s: %s", type_name(k->type), def, lo, hi, k->help);
        fprintf(out, "%s = %s\n", k->key, val);
        dump_comment(out, text);
    }
}

void cfg_markdown(FILE *out)
{
    fprintf(out, "# Machine configuration\n\n"
                 "<!-- GENERATED by `bin/sfsim config --markdown` from sim/config.def; do not edit. -->\n\n"
                 "A machine config is an INI file (`configs/streamray.ini` is the machine of Gribble & Ramani\n"
                 "2008, Sec. 3.3), read by the reader of every sfsim INI file with its rules ([ini.md](ini.md):\n"
                 "comments, a key once per section, a UTF-8 BOM, a regular file of at most 16 MiB, lines of at\n"
                 "most 198 characters). A section may appear more than once (`config --dump` repeats some); a value is on\n"
                 "one line. Every key has a type, a default and a range; a key left out takes its\n"
                 "default. `--set section.key=value` overrides any key on the command line, and\n"
                 "`bin/sfsim config --dump [-c FILE] [--set ...]` prints the values in force. Unknown sections\n"
                 "and keys, values that are not numbers, and values out of range are errors naming the file,\n"
                 "line and key; every error of a file is reported. Cross-key checks: a ray buffer holds M rays\n"
                 "of 128 bytes; ID-stream memory holds two streams of M IDs; ray-buffer size divides into banks;\n"
                 "`workload.kind = specular` needs `workload.bounces` >= 1.\n\n"
                 "| key | type | default | range | meaning |\n|---|---|---|---|---|\n");
    for (size_t i = 0; i < NKEYS; i++) {
        const CfgKeyInfo *k = &keys[i];
        char def[64], lo[64], hi[64];
        fmt_value(k, k->def, def, sizeof def);
        fmt_value(k, k->lo, lo, sizeof lo);
        fmt_value(k, k->hi, hi, sizeof hi);
        if (k->type == CFG_ENUM)
            fprintf(out, "| `%s.%s` | %s | %s | %s | %s |\n", k->section, k->key, type_name(k->type), def,
                    enum_list(k, lo, sizeof lo), k->help);
        else
            fprintf(out, "| `%s.%s` | %s | %s | %s..%s | %s |\n", k->section, k->key, type_name(k->type), def, lo,
                    hi, k->help);
    }
}

void cfg_json(const CfgMachine *cfg, struct cJSON *obj)
{
    for (size_t i = 0; i < NKEYS; i++) {
        const CfgKeyInfo *k = &keys[i];
        char name[128];
        snprintf(name, sizeof name, "%s.%s", k->section, k->key);
        double v = load(cfg, k);
        if (k->type == CFG_ENUM) {
            const char *n = cfg_enum_name(k->section, k->key, (int)v);
            cJSON_AddStringToObject(obj, name, n ? n : "?");
        } else {
            cJSON_AddNumberToObject(obj, name, v);
        }
    }
}
