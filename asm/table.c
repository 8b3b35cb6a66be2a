/* asm/table.c -- open-addressing string hash table (FNV-1a, linear probing).
 *
 * Owns: the slot array and key copies. Must not: free or interpret values. Entries are never
 * removed: a removed alias or macro keeps its slot with a NULL-able value chosen by the caller.
 */
#include "table.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static uint64_t hash(const char *key, size_t len)
{
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < len; i++)
        h = (h ^ (unsigned char)key[i]) * 1099511628211ull;
    return h;
}

static AsmTableSlot *find(const AsmTable *t, const char *key, size_t len)
{
    size_t i = (size_t)hash(key, len) & (t->cap - 1);
    for (;;) {
        AsmTableSlot *s = &t->slots[i];
        if (!s->key || (s->len == len && memcmp(s->key, key, len) == 0))
            return s;
        i = (i + 1) & (t->cap - 1);
    }
}

void *asm_table_get(const AsmTable *t, const char *key, size_t len)
{
    if (t->cap == 0)
        return NULL;
    AsmTableSlot *s = find(t, key, len);
    return s->key ? s->val : NULL;
}

static int grow(AsmTable *t)
{
    size_t ncap = t->cap ? t->cap * 2 : 64;
    AsmTableSlot *old = t->slots;
    size_t ocap = t->cap;
    t->slots = calloc(ncap, sizeof *t->slots);
    if (!t->slots) {
        t->slots = old;
        return -1;
    }
    t->cap = ncap;
    for (size_t i = 0; i < ocap; i++)
        if (old[i].key)
            *find(t, old[i].key, old[i].len) = old[i];
    free(old);
    return 0;
}

int asm_table_put(AsmTable *t, const char *key, size_t len, void *val)
{
    /* Keep the load below 1/2 so probes stay short. */
    if ((t->count + 1) * 2 > t->cap && grow(t) < 0)
        return -1;
    AsmTableSlot *s = find(t, key, len);
    if (!s->key) {
        char *k = malloc(len + 1);
        if (!k)
            return -1;
        memcpy(k, key, len);
        k[len] = '\0';
        s->key = k;
        s->len = len;
        t->count++;
    }
    s->val = val;
    return 0;
}

void asm_table_free(AsmTable *t)
{
    for (size_t i = 0; i < t->cap; i++)
        free(t->slots[i].key);
    free(t->slots);
    t->slots = NULL;
    t->cap = t->count = 0;
}
