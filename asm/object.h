/* asm/object.h -- the sfsim object file (.sfo): what sfasm writes and sfsim loads.
 *
 * Owns: the in-memory object and its on-disk encoding (docs/object-format.md).
 * Must not: assemble or execute.
 *
 * On disk (all integers little-endian):
 *   header   : magic "SFO\0" (4 bytes), u32 version (ASM_OBJ_VERSION), u32 section count, u32 0
 *   sections : count x { u32 kind (AsmSectionKind), u32 offset from file start, u32 size, u32 0 }
 *   payloads : TEXT  = ntext x u64 instruction words
 *              DATA  = scene-memory image, loaded at scene address 0
 *              SPAD  = scratchpad image, loaded at scratchpad address 0
 *              FILES = NUL-terminated source file names, in index order
 *              LINES = ntext x { u32 file index, u32 line, u32 column } (debug line table)
 *              SYMS  = nsyms x { u32 section, u32 value, u32 name length, name bytes,
 *                        zero padding to a multiple of 4 }
 * Only TEXT is required; a reader rejects unknown kinds, overlapping or out-of-file sections,
 * and a LINES table whose length differs from TEXT's.
 */
#ifndef SFSIM_ASM_OBJECT_H
#define SFSIM_ASM_OBJECT_H

#include <stddef.h>
#include <stdint.h>

#define ASM_OBJ_MAGIC   "SFO"   /* 4 bytes with the NUL */
#define ASM_OBJ_VERSION 1u
/* The largest object file a reader takes (host/infile.h): 4 GiB, above any program the machine
 * can hold. */
#define ASM_OBJ_MAX_BYTES (1ull << 32)

typedef enum AsmSectionKind {
    ASM_SEC_TEXT = 1,
    ASM_SEC_DATA = 2,
    ASM_SEC_SPAD = 3,
    ASM_SEC_FILES = 4,
    ASM_SEC_LINES = 5,
    ASM_SEC_SYMS = 6
} AsmSectionKind;

typedef struct AsmLine {
    uint32_t file;   /* index into files */
    uint32_t line;   /* 1-based */
    uint32_t col;    /* 1-based */
} AsmLine;

typedef struct AsmSymbol {
    char *name;
    uint32_t section; /* AsmSectionKind of the label's section, or 0 for a constant */
    uint32_t value;   /* instruction index (TEXT), byte offset (DATA/SPAD) or constant value */
} AsmSymbol;

typedef struct AsmObject {
    uint64_t *text;   uint32_t ntext;
    uint8_t *data;    uint32_t ndata;   /* scene-memory image */
    uint8_t *spad;    uint32_t nspad;   /* scratchpad image */
    AsmLine *lines;                     /* ntext entries, or NULL */
    char **files;     uint32_t nfiles;
    AsmSymbol *syms;  uint32_t nsyms;
} AsmObject;

/* Write obj to path. 0 on success, -1 with a message in err. */
int asm_object_write(const AsmObject *obj, const char *path, char *err, size_t errlen);
/* Encode into a malloc'ed buffer (for tests and fuzzers). */
int asm_object_encode(const AsmObject *obj, uint8_t **buf, size_t *len, char *err, size_t errlen);
/* Read and validate; every instruction word must decode (isa_decode). 0, or -1 with
 * "path: message" in err; *obj is zeroed on failure. */
int asm_object_read(const char *path, AsmObject *obj, char *err, size_t errlen);
int asm_object_decode(const uint8_t *buf, size_t len, const char *name, AsmObject *obj,
                      char *err, size_t errlen);
void asm_object_free(AsmObject *obj);
/* Source location of instruction pc as "file:line" into buf, or "?" without debug info. */
void asm_object_where(const AsmObject *obj, uint32_t pc, char *buf, size_t len);

#endif
