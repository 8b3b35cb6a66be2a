/* sim/raybatch.c -- ray files in and hit files out for `sfsim trace` (docs/trace.md).
 *
 * Owns: parsing (text and binary) with messages that name the file and the line or byte, and the
 * hit file writers. Must not: trace, or accept a file silently truncated or padded.
 */
#include "raybatch.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../host/infile.h"
#include "../host/outfile.h"

void raybatch_free(RayBatch *b)
{
    free(b->rays);
    b->rays = NULL;
    b->count = 0;
}

int raybatch_ray_invalid(const BatchRay *r)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(r->org[k]) || !isfinite(r->dir[k]))
            return 1;
    return r->dir[0] == 0.0f && r->dir[1] == 0.0f && r->dir[2] == 0.0f;
}

static int push(RayBatch *b, uint32_t *cap, const BatchRay *r)
{
    if (b->count == *cap) {
        uint32_t nc = *cap ? *cap * 2 : 1024;
        BatchRay *n = realloc(b->rays, sizeof(BatchRay) * nc);
        if (!n)
            return -1;
        b->rays = n;
        *cap = nc;
    }
    b->rays[b->count++] = *r;
    return 0;
}

static uint32_t rd32(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }

static float rdf(const unsigned char *p)
{
    uint32_t u = rd32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* Binary: "SFRAYS1\0", u32 count, u32 reserved (0), then count records of 8 little-endian
 * words: org xyz, dir xyz (float), tmax (float), query (u32: 0 closest, 1 any). */
static int parse_binary(const char *name, const unsigned char *d, size_t len, RayBatch *out, char *err, size_t errlen)
{
    if (len < 16) {
        snprintf(err, errlen, "%s: byte %zu: file ends inside the 16-byte header", name, len);
        return -1;
    }
    uint32_t count = rd32(d + 8), reserved = rd32(d + 12);
    if (reserved != 0) {
        snprintf(err, errlen, "%s: byte 12: reserved word is %u, must be 0", name, reserved);
        return -1;
    }
    if (count > RAYBATCH_MAX_RAYS) {
        snprintf(err, errlen, "%s: byte 8: %u rays, more than the limit of %u", name, count, RAYBATCH_MAX_RAYS);
        return -1;
    }
    size_t need = 16 + (size_t)count * 32;
    if (len != need) {
        snprintf(err, errlen, "%s: %zu bytes, but a header claiming %u rays needs exactly %zu", name, len, count,
                 need);
        return -1;
    }
    out->rays = calloc(count ? count : 1, sizeof(BatchRay));
    if (!out->rays) {
        snprintf(err, errlen, "%s: out of memory for %u rays", name, count);
        return -1;
    }
    out->count = count;
    for (uint32_t i = 0; i < count; i++) {
        const unsigned char *p = d + 16 + (size_t)i * 32;
        BatchRay *r = &out->rays[i];
        for (int k = 0; k < 3; k++) {
            r->org[k] = rdf(p + 4 * k);
            r->dir[k] = rdf(p + 12 + 4 * k);
        }
        r->tmax = rdf(p + 24);
        r->query = rd32(p + 28);
        if (r->query > RAY_ANY) {
            snprintf(err, errlen, "%s: byte %zu: ray %u: query %u (0 closest, 1 any)", name, (size_t)(p + 28 - d), i,
                     r->query);
            raybatch_free(out);
            return -1;
        }
        if (isnan(r->tmax) || !(r->tmax > 0.0f)) {
            snprintf(err, errlen, "%s: byte %zu: ray %u: tmax must be > 0 (infinity allowed)", name,
                     (size_t)(p + 24 - d), i);
            raybatch_free(out);
            return -1;
        }
    }
    return 0;
}

/* Text: one ray per line, "ox oy oz dx dy dz [tmax [closest|any]]"; '#' starts a comment;
 * blank lines are skipped. Numbers are C floats (inf allowed for tmax). */
static int parse_text(const char *name, const unsigned char *d, size_t len, RayBatch *out, char *err, size_t errlen)
{
    uint32_t cap = 0;
    size_t pos = 0;
    int line = 0;
    char buf[1024];
    while (pos < len) {
        line++;
        size_t e = pos;
        while (e < len && d[e] != '\n')
            e++;
        size_t n = e - pos;
        if (n >= sizeof buf) {
            snprintf(err, errlen, "%s:%d: line longer than %zu characters", name, line, sizeof buf - 1);
            goto fail;
        }
        memcpy(buf, d + pos, n);
        buf[n] = 0;
        pos = e + 1;
        if (memchr(buf, 0, n)) {
            snprintf(err, errlen, "%s:%d: NUL byte in a text ray file", name, line);
            goto fail;
        }
        char *hash = strchr(buf, '#');
        if (hash)
            *hash = 0;
        char *tok[9];
        int nt = 0;
        char *save = NULL;
        for (char *t = strtok_r(buf, " \t\r,", &save); t; t = strtok_r(NULL, " \t\r,", &save)) {
            if (nt == 8) {
                snprintf(err, errlen, "%s:%d: too many fields (expected ox oy oz dx dy dz [tmax [closest|any]])", name,
                         line);
                goto fail;
            }
            tok[nt++] = t;
        }
        if (nt == 0)
            continue;
        if (nt < 6) {
            snprintf(err, errlen, "%s:%d: %d fields, expected ox oy oz dx dy dz [tmax [closest|any]]", name, line, nt);
            goto fail;
        }
        BatchRay r;
        memset(&r, 0, sizeof r);
        r.tmax = INFINITY;
        float v[7];
        int nv = nt >= 7 ? 7 : 6;
        for (int k = 0; k < nv; k++) {
            char *end;
            errno = 0;
            v[k] = strtof(tok[k], &end);
            if (*end || end == tok[k]) {
                snprintf(err, errlen, "%s:%d: field %d: '%s' is not a number", name, line, k + 1, tok[k]);
                goto fail;
            }
        }
        for (int k = 0; k < 3; k++) {
            r.org[k] = v[k];
            r.dir[k] = v[3 + k];
        }
        if (nv == 7) {
            r.tmax = v[6];
            if (isnan(r.tmax) || !(r.tmax > 0.0f)) {
                snprintf(err, errlen, "%s:%d: tmax must be > 0 (inf allowed)", name, line);
                goto fail;
            }
        }
        if (nt == 8) {
            if (!strcmp(tok[7], "closest"))
                r.query = RAY_CLOSEST;
            else if (!strcmp(tok[7], "any"))
                r.query = RAY_ANY;
            else {
                snprintf(err, errlen, "%s:%d: query '%s': expected closest or any", name, line, tok[7]);
                goto fail;
            }
        }
        if (out->count >= RAYBATCH_MAX_RAYS) {
            snprintf(err, errlen, "%s:%d: more than %u rays", name, line, RAYBATCH_MAX_RAYS);
            goto fail;
        }
        if (push(out, &cap, &r) != 0) {
            snprintf(err, errlen, "%s:%d: out of memory", name, line);
            goto fail;
        }
    }
    return 0;
fail:
    raybatch_free(out);
    return -1;
}

int raybatch_parse(const char *name, const unsigned char *data, size_t len, RayBatch *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    if (len >= 8 && !memcmp(data, RAYBATCH_MAGIC, 8))
        return parse_binary(name, data, len, out, err, errlen);
    /* A UTF-8 byte-order mark (an editor's) is skipped, as the INI reader skips it. */
    size_t bom = infile_bom(data, len);
    return parse_text(name, data + bom, len - bom, out, err, errlen);
}

int raybatch_load(const char *path, RayBatch *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    char *data;
    size_t len;
    /* A text file of the most rays a file may claim, at four times the binary size, is the cap. */
    if (infile_read(path, ((uint64_t)RAYBATCH_MAX_RAYS * 32 + 16) * 4, "a ray file", &data, &len, err, errlen) != 0)
        return -1;
    int rc = raybatch_parse(path, (const unsigned char *)data, len, out, err, errlen);
    free(data);
    return rc;
}

static void wr32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

int raybatch_write_hits(const char *path, const RayBatch *b, const BatchHit *hits, int binary, char *err,
                        size_t errlen)
{
    /* Through host/outfile.c: every write checked, and the file in place only once whole. */
    OutFile f;
    if (outfile_open(&f, path, err, errlen) != 0)
        return -1;
    int ok;
    if (binary) {
        unsigned char h[16] = "SFHITS1";
        wr32(h + 8, b->count);
        wr32(h + 12, 0);
        ok = outfile_write(&f, h, 16, err, errlen) == 0;
        for (uint32_t i = 0; ok && i < b->count; i++) {
            unsigned char r[20];
            uint32_t status = hits[i].invalid ? 2u : b->rays[i].query == RAY_ANY ? hits[i].prim : hits[i].prim != UINT32_MAX;
            uint32_t u;
            wr32(r, status);
            wr32(r + 4, b->rays[i].query == RAY_ANY ? UINT32_MAX : hits[i].prim);
            memcpy(&u, &hits[i].t, 4);
            wr32(r + 8, u);
            memcpy(&u, &hits[i].u, 4);
            wr32(r + 12, u);
            memcpy(&u, &hits[i].v, 4);
            wr32(r + 16, u);
            ok = outfile_write(&f, r, 20, err, errlen) == 0;
        }
    } else {
        ok = outfile_printf(&f, err, errlen,
                            "# sfsim trace: ray  closest: t prim u v | miss ; any: occluded | clear ; invalid\n") == 0;
        for (uint32_t i = 0; ok && i < b->count; i++) {
            if (hits[i].invalid)
                ok = outfile_printf(&f, err, errlen, "%u invalid\n", i) == 0;
            else if (b->rays[i].query == RAY_ANY)
                ok = outfile_printf(&f, err, errlen, "%u %s\n", i, hits[i].prim ? "occluded" : "clear") == 0;
            else if (hits[i].prim == UINT32_MAX)
                ok = outfile_printf(&f, err, errlen, "%u miss\n", i) == 0;
            else
                ok = outfile_printf(&f, err, errlen, "%u %.9g %u %.9g %.9g\n", i, (double)hits[i].t, hits[i].prim,
                                    (double)hits[i].u, (double)hits[i].v) == 0;
        }
    }
    if (!ok) {
        outfile_discard(&f);
        return -1;
    }
    return outfile_close(&f, NULL, err, errlen);
}
