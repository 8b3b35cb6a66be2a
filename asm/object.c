/* asm/object.c -- the .sfo object file: encoding, writing, reading and validation.
 *
 * Owns: the byte layout described in object.h and docs/object-format.md, and the checks a
 * reader applies before anything else trusts an object. Must not: assemble, execute, or trust
 * any size or index read from a file before checking it against the buffer.
 */
#include "object.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../isa/isa.h"
#include "../host/infile.h"
#include "../host/outfile.h"

#define OBJ_HDR_BYTES  16u
#define OBJ_SEC_BYTES  16u
#define OBJ_LINE_BYTES 12u
#define OBJ_ALIGN      8u   /* payloads start 8-byte aligned so TEXT words are naturally aligned */
#define OBJ_NKINDS     6u

/* ---- little-endian helpers ---------------------------------------------------------------- */

static uint32_t get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static uint64_t get_u64(const uint8_t *p)
{
    return (uint64_t)get_u32(p) | (uint64_t)get_u32(p + 4) << 32;
}

static void put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

static void put_u64(uint8_t *p, uint64_t v)
{
    put_u32(p, (uint32_t)v);
    put_u32(p + 4, (uint32_t)(v >> 32));
}

static void set_err(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

static uint64_t align_up(uint64_t v) { return (v + OBJ_ALIGN - 1) & ~(uint64_t)(OBJ_ALIGN - 1); }

/* ---- encoding ------------------------------------------------------------------------------ */

/* One section about to be written: kind and payload size; the payload is produced by fill. */
typedef struct OutSection {
    uint32_t kind;
    uint64_t size;
    uint64_t offset;
} OutSection;

static uint64_t syms_bytes(const AsmObject *obj)
{
    uint64_t n = 0;
    for (uint32_t i = 0; i < obj->nsyms; i++)
        n += 12 + ((strlen(obj->syms[i].name) + 3) & ~(size_t)3);
    return n;
}

static uint64_t files_bytes(const AsmObject *obj)
{
    uint64_t n = 0;
    for (uint32_t i = 0; i < obj->nfiles; i++)
        n += strlen(obj->files[i]) + 1;
    return n;
}

/* Checks the in-memory object is writable: pointers present for the counts given, and the
 * line table refers to existing files, so that the reader will accept what we write. */
static int check_for_encode(const AsmObject *obj, char *err, size_t errlen)
{
    if ((obj->ntext && !obj->text) || (obj->ndata && !obj->data) || (obj->nspad && !obj->spad) ||
        (obj->nfiles && !obj->files) || (obj->nsyms && !obj->syms)) {
        set_err(err, errlen, "object has a count without its array");
        return -1;
    }
    for (uint32_t i = 0; i < obj->nfiles; i++)
        if (!obj->files[i]) {
            set_err(err, errlen, "file name %u is missing", i);
            return -1;
        }
    for (uint32_t i = 0; i < obj->nsyms; i++)
        if (!obj->syms[i].name || !obj->syms[i].name[0]) {
            set_err(err, errlen, "symbol %u has no name", i);
            return -1;
        }
    for (uint32_t i = 0; obj->lines && i < obj->ntext; i++)
        if (obj->lines[i].file >= obj->nfiles) {
            set_err(err, errlen, "line table entry %u names file %u of %u", i, obj->lines[i].file,
                    obj->nfiles);
            return -1;
        }
    return 0;
}

static void fill_section(const AsmObject *obj, const OutSection *s, uint8_t *buf)
{
    uint8_t *p = buf + s->offset;
    switch ((AsmSectionKind)s->kind) {
    case ASM_SEC_TEXT:
        for (uint32_t i = 0; i < obj->ntext; i++)
            put_u64(p + 8 * (size_t)i, obj->text[i]);
        break;
    case ASM_SEC_DATA: memcpy(p, obj->data, obj->ndata); break;
    case ASM_SEC_SPAD: memcpy(p, obj->spad, obj->nspad); break;
    case ASM_SEC_FILES:
        for (uint32_t i = 0; i < obj->nfiles; i++) {
            size_t n = strlen(obj->files[i]) + 1;
            memcpy(p, obj->files[i], n);
            p += n;
        }
        break;
    case ASM_SEC_LINES:
        for (uint32_t i = 0; i < obj->ntext; i++, p += OBJ_LINE_BYTES) {
            put_u32(p, obj->lines[i].file);
            put_u32(p + 4, obj->lines[i].line);
            put_u32(p + 8, obj->lines[i].col);
        }
        break;
    case ASM_SEC_SYMS:
        for (uint32_t i = 0; i < obj->nsyms; i++) {
            size_t n = strlen(obj->syms[i].name);
            put_u32(p, obj->syms[i].section);
            put_u32(p + 4, obj->syms[i].value);
            put_u32(p + 8, (uint32_t)n);
            memcpy(p + 12, obj->syms[i].name, n); /* padding is already zero (calloc) */
            p += 12 + ((n + 3) & ~(size_t)3);
        }
        break;
    }
}

int asm_object_encode(const AsmObject *obj, uint8_t **buf, size_t *len, char *err, size_t errlen)
{
    *buf = NULL;
    *len = 0;
    if (check_for_encode(obj, err, errlen) < 0)
        return -1;
    OutSection secs[OBJ_NKINDS];
    uint32_t n = 0;
    secs[n++] = (OutSection){ASM_SEC_TEXT, (uint64_t)obj->ntext * 8, 0};
    if (obj->ndata)
        secs[n++] = (OutSection){ASM_SEC_DATA, obj->ndata, 0};
    if (obj->nspad)
        secs[n++] = (OutSection){ASM_SEC_SPAD, obj->nspad, 0};
    if (obj->nfiles)
        secs[n++] = (OutSection){ASM_SEC_FILES, files_bytes(obj), 0};
    if (obj->lines)
        secs[n++] = (OutSection){ASM_SEC_LINES, (uint64_t)obj->ntext * OBJ_LINE_BYTES, 0};
    if (obj->nsyms)
        secs[n++] = (OutSection){ASM_SEC_SYMS, syms_bytes(obj), 0};
    uint64_t off = align_up(OBJ_HDR_BYTES + (uint64_t)n * OBJ_SEC_BYTES);
    for (uint32_t i = 0; i < n; i++) {
        secs[i].offset = off;
        off = i + 1 < n ? align_up(off + secs[i].size) : off + secs[i].size; /* no tail padding */
    }
    /* Offsets and sizes are u32 on disk. */
    if (off > UINT32_MAX) {
        set_err(err, errlen, "object too large (%llu bytes)", (unsigned long long)off);
        return -1;
    }
    uint8_t *b = calloc(1, (size_t)off);
    if (!b) {
        set_err(err, errlen, "out of memory");
        return -1;
    }
    memcpy(b, ASM_OBJ_MAGIC, 4);
    put_u32(b + 4, ASM_OBJ_VERSION);
    put_u32(b + 8, n);
    for (uint32_t i = 0; i < n; i++) {
        uint8_t *e = b + OBJ_HDR_BYTES + OBJ_SEC_BYTES * i;
        put_u32(e, secs[i].kind);
        put_u32(e + 4, (uint32_t)secs[i].offset);
        put_u32(e + 8, (uint32_t)secs[i].size);
        fill_section(obj, &secs[i], b);
    }
    *buf = b;
    *len = (size_t)off;
    return 0;
}

int asm_object_write(const AsmObject *obj, const char *path, char *err, size_t errlen)
{
    uint8_t *buf;
    size_t len;
    if (asm_object_encode(obj, &buf, &len, err, errlen) < 0)
        return -1;
    /* Written under a temporary name and renamed into place once whole (host/outfile.h): a full
     * disk or a file-size limit leaves the object that was there, not a truncated one. */
    int rc = outfile_write_file(NULL, path, buf, len, err, errlen);
    free(buf);
    return rc;
}

/* ---- decoding ------------------------------------------------------------------------------ */

typedef struct InSection {
    int present;
    uint32_t offset, size;
} InSection;

/* Reads the header and the section table into secs[kind]; rejects anything malformed. */
static int read_table(const uint8_t *buf, size_t len, InSection secs[OBJ_NKINDS + 1], char *msg,
                      size_t msglen)
{
    if (len < OBJ_HDR_BYTES) {
        snprintf(msg, msglen, "truncated header (%zu bytes, need %u)", len, OBJ_HDR_BYTES);
        return -1;
    }
    if (memcmp(buf, ASM_OBJ_MAGIC, 4) != 0) {
        snprintf(msg, msglen, "bad magic (not an sfsim object)");
        return -1;
    }
    uint32_t version = get_u32(buf + 4), count = get_u32(buf + 8);
    if (version != ASM_OBJ_VERSION) {
        snprintf(msg, msglen, "unsupported version %u (expected %u)", version, ASM_OBJ_VERSION);
        return -1;
    }
    if (get_u32(buf + 12) != 0) {
        snprintf(msg, msglen, "reserved header word is not zero");
        return -1;
    }
    uint64_t table_end = OBJ_HDR_BYTES + (uint64_t)count * OBJ_SEC_BYTES;
    if (table_end > len) {
        snprintf(msg, msglen, "truncated section table (%u sections)", count);
        return -1;
    }
    for (uint32_t i = 0; i < count; i++) {
        const uint8_t *e = buf + OBJ_HDR_BYTES + OBJ_SEC_BYTES * (size_t)i;
        uint32_t kind = get_u32(e), off = get_u32(e + 4), size = get_u32(e + 8);
        if (kind < ASM_SEC_TEXT || kind > ASM_SEC_SYMS) {
            snprintf(msg, msglen, "section %u: unknown kind %u", i, kind);
            return -1;
        }
        if (secs[kind].present) {
            snprintf(msg, msglen, "section %u: duplicate section of kind %u", i, kind);
            return -1;
        }
        if (get_u32(e + 12) != 0) {
            snprintf(msg, msglen, "section %u: reserved word is not zero", i);
            return -1;
        }
        if (off < table_end || (uint64_t)off + size > len) {
            snprintf(msg, msglen, "section %u: bytes [%u, %llu) outside the file (%zu bytes, payload from %llu)",
                     i, off, (unsigned long long)off + size, len, (unsigned long long)table_end);
            return -1;
        }
        for (uint32_t k = 1; k <= OBJ_NKINDS; k++) {
            if (secs[k].present && size && secs[k].size &&
                off < (uint64_t)secs[k].offset + secs[k].size && secs[k].offset < (uint64_t)off + size) {
                snprintf(msg, msglen, "section %u (kind %u) overlaps section of kind %u", i, kind, k);
                return -1;
            }
        }
        secs[kind] = (InSection){1, off, size};
    }
    if (!secs[ASM_SEC_TEXT].present) {
        snprintf(msg, msglen, "no TEXT section");
        return -1;
    }
    return 0;
}

static int read_text(const uint8_t *buf, const InSection *s, AsmObject *obj, char *msg, size_t msglen)
{
    if (s->size % 8 != 0) {
        snprintf(msg, msglen, "section TEXT: size %u is not a multiple of 8", s->size);
        return -1;
    }
    obj->ntext = s->size / 8;
    obj->text = calloc(obj->ntext ? obj->ntext : 1, sizeof *obj->text);
    if (!obj->text) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    for (uint32_t i = 0; i < obj->ntext; i++) {
        uint64_t w = get_u64(buf + s->offset + 8 * (size_t)i);
        IsaInstr in;
        char derr[160];
        if (isa_decode(w, &in, derr, sizeof derr) < 0) {
            snprintf(msg, msglen, "section TEXT word %u: %s", i, derr);
            return -1;
        }
        obj->text[i] = w;
    }
    return 0;
}

static int read_image(const uint8_t *buf, const InSection *s, uint8_t **img, uint32_t *n,
                      char *msg, size_t msglen)
{
    if (!s->present || s->size == 0)
        return 0;
    *img = malloc(s->size);
    if (!*img) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    memcpy(*img, buf + s->offset, s->size);
    *n = s->size;
    return 0;
}

static int read_files(const uint8_t *buf, const InSection *s, AsmObject *obj, char *msg,
                      size_t msglen)
{
    if (!s->present || s->size == 0)
        return 0;
    const char *p = (const char *)buf + s->offset;
    if (p[s->size - 1] != '\0') {
        snprintf(msg, msglen, "section FILES: last name is not NUL-terminated");
        return -1;
    }
    uint32_t count = 0;
    for (uint32_t i = 0; i < s->size; i++)
        count += p[i] == '\0';
    obj->files = calloc(count, sizeof *obj->files);
    if (!obj->files) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    for (uint32_t i = 0; i < count; i++) {
        obj->files[i] = strdup(p);
        if (!obj->files[i]) {
            snprintf(msg, msglen, "out of memory");
            return -1;
        }
        obj->nfiles = i + 1;
        p += strlen(p) + 1;
    }
    return 0;
}

static int read_lines(const uint8_t *buf, const InSection *s, AsmObject *obj, char *msg,
                      size_t msglen)
{
    if (!s->present)
        return 0;
    if (s->size % OBJ_LINE_BYTES != 0 || s->size / OBJ_LINE_BYTES != obj->ntext) {
        snprintf(msg, msglen, "section LINES: %u bytes do not hold %u entries of %u bytes", s->size,
                 obj->ntext, OBJ_LINE_BYTES);
        return -1;
    }
    obj->lines = calloc(obj->ntext ? obj->ntext : 1, sizeof *obj->lines);
    if (!obj->lines) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    for (uint32_t i = 0; i < obj->ntext; i++) {
        const uint8_t *e = buf + s->offset + OBJ_LINE_BYTES * (size_t)i;
        AsmLine l = {get_u32(e), get_u32(e + 4), get_u32(e + 8)};
        if (l.file >= obj->nfiles) {
            snprintf(msg, msglen, "section LINES entry %u: file index %u out of range (%u files)", i,
                     l.file, obj->nfiles);
            return -1;
        }
        if (l.line == 0 || l.col == 0) {
            snprintf(msg, msglen, "section LINES entry %u: line and column must be 1-based", i);
            return -1;
        }
        obj->lines[i] = l;
    }
    return 0;
}

/* Upper bound of a label's value in its section: one past the end is allowed (end labels). */
static int sym_value_ok(const AsmObject *obj, uint32_t section, uint32_t value)
{
    switch (section) {
    case 0: return 1;
    case ASM_SEC_TEXT: return value <= obj->ntext;
    case ASM_SEC_DATA: return value <= obj->ndata;
    case ASM_SEC_SPAD: return value <= obj->nspad;
    default: return 0;
    }
}

static int read_one_sym(const uint8_t *p, uint32_t left, uint32_t idx, const AsmObject *obj,
                        AsmSymbol *sym, uint32_t *used, char *msg, size_t msglen)
{
    if (left < 12) {
        snprintf(msg, msglen, "section SYMS: symbol %u truncated", idx);
        return -1;
    }
    uint32_t section = get_u32(p), value = get_u32(p + 4), nlen = get_u32(p + 8);
    uint64_t padded = ((uint64_t)nlen + 3) & ~(uint64_t)3;
    if (nlen == 0 || padded > left - 12) {
        snprintf(msg, msglen, "section SYMS: symbol %u: bad name length %u", idx, nlen);
        return -1;
    }
    if (memchr(p + 12, '\0', nlen)) {
        snprintf(msg, msglen, "section SYMS: symbol %u: NUL inside the name", idx);
        return -1;
    }
    for (uint64_t k = nlen; k < padded; k++)
        if (p[12 + k] != 0) {
            snprintf(msg, msglen, "section SYMS: symbol %u: non-zero padding", idx);
            return -1;
        }
    if (section > ASM_SEC_SPAD || !sym_value_ok(obj, section, value)) {
        snprintf(msg, msglen, "section SYMS: symbol %u: value %u outside section %u", idx, value,
                 section);
        return -1;
    }
    sym->name = strndup((const char *)p + 12, nlen);
    if (!sym->name) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    sym->section = section;
    sym->value = value;
    *used = (uint32_t)(12 + padded);
    return 0;
}

static int read_syms(const uint8_t *buf, const InSection *s, AsmObject *obj, char *msg,
                     size_t msglen)
{
    if (!s->present || s->size == 0)
        return 0;
    /* Every record takes at least 16 bytes: a safe bound for the array. */
    obj->syms = calloc(s->size / 16 + 1, sizeof *obj->syms);
    if (!obj->syms) {
        snprintf(msg, msglen, "out of memory");
        return -1;
    }
    uint32_t pos = 0;
    while (pos < s->size) {
        uint32_t used;
        if (read_one_sym(buf + s->offset + pos, s->size - pos, obj->nsyms, obj,
                         &obj->syms[obj->nsyms], &used, msg, msglen) < 0)
            return -1;
        obj->nsyms++;
        pos += used;
    }
    return 0;
}

int asm_object_decode(const uint8_t *buf, size_t len, const char *name, AsmObject *obj, char *err,
                      size_t errlen)
{
    memset(obj, 0, sizeof *obj);
    InSection secs[OBJ_NKINDS + 1];
    memset(secs, 0, sizeof secs);
    char msg[256];
    if (!name)
        name = "<object>";
    if (!buf && len)
        len = 0;
    if (read_table(buf, len, secs, msg, sizeof msg) < 0 ||
        read_text(buf, &secs[ASM_SEC_TEXT], obj, msg, sizeof msg) < 0 ||
        read_image(buf, &secs[ASM_SEC_DATA], &obj->data, &obj->ndata, msg, sizeof msg) < 0 ||
        read_image(buf, &secs[ASM_SEC_SPAD], &obj->spad, &obj->nspad, msg, sizeof msg) < 0 ||
        read_files(buf, &secs[ASM_SEC_FILES], obj, msg, sizeof msg) < 0 ||
        read_lines(buf, &secs[ASM_SEC_LINES], obj, msg, sizeof msg) < 0 ||
        read_syms(buf, &secs[ASM_SEC_SYMS], obj, msg, sizeof msg) < 0) {
        set_err(err, errlen, "%s: %s", name, msg);
        asm_object_free(obj);
        return -1;
    }
    return 0;
}

int asm_object_read(const char *path, AsmObject *obj, char *err, size_t errlen)
{
    memset(obj, 0, sizeof *obj);
    char *buf;
    size_t len;
    if (infile_read(path, ASM_OBJ_MAX_BYTES, "an object file", &buf, &len, err, errlen) != 0)
        return -1;
    int rc = asm_object_decode((const uint8_t *)buf, len, path, obj, err, errlen);
    free(buf);
    return rc;
}

void asm_object_free(AsmObject *obj)
{
    if (!obj)
        return;
    free(obj->text);
    free(obj->data);
    free(obj->spad);
    free(obj->lines);
    for (uint32_t i = 0; obj->files && i < obj->nfiles; i++)
        free(obj->files[i]);
    free(obj->files);
    for (uint32_t i = 0; obj->syms && i < obj->nsyms; i++)
        free(obj->syms[i].name);
    free(obj->syms);
    memset(obj, 0, sizeof *obj);
}

void asm_object_where(const AsmObject *obj, uint32_t pc, char *buf, size_t len)
{
    if (!buf || len == 0)
        return;
    if (!obj || !obj->lines || pc >= obj->ntext || obj->lines[pc].file >= obj->nfiles ||
        !obj->files || !obj->files[obj->lines[pc].file]) {
        snprintf(buf, len, "?");
        return;
    }
    snprintf(buf, len, "%s:%u", obj->files[obj->lines[pc].file], obj->lines[pc].line);
}
