/* asm/table.h -- a string-keyed hash table for sfasm's symbols, macros and aliases (internal).
 *
 * Owns: key storage and lookup. Must not: own or interpret the values (callers free them).
 */
#ifndef SFSIM_ASM_TABLE_H
#define SFSIM_ASM_TABLE_H

#include <stddef.h>

typedef struct AsmTableSlot {
    char *key;      /* NUL-terminated copy; NULL marks an empty slot */
    size_t len;
    void *val;
} AsmTableSlot;

typedef struct AsmTable {
    AsmTableSlot *slots;
    size_t cap, count;   /* cap is 0 or a power of two */
} AsmTable;

/* The value stored under key[0, len), or NULL. */
void *asm_table_get(const AsmTable *t, const char *key, size_t len);
/* Stores val under key (replacing any value). 0, or -1 when out of memory. */
int asm_table_put(AsmTable *t, const char *key, size_t len, void *val);
/* Frees the keys and the slots, not the values. */
void asm_table_free(AsmTable *t);

#endif
