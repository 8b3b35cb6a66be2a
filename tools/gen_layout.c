/* tools/gen_layout.c -- generates, from scenes/layout.def, the assembler include the kernels
 * use (kernels/lib/layout.inc, `gen_layout inc`) and the layout reference
 * (docs/scene-memory.md, `gen_layout md`). One definition; a test fails when either is stale. */
#include <stdio.h>
#include <string.h>

typedef struct Rec { const char *name; int words; const char *desc; } Rec;
typedef struct Field { const char *rec, *name; int word, count; const char *type, *desc; } Field;

static const Rec recs[] = {
#define SM_RECORD(rec, words, desc) {#rec, words, desc},
#define SM_FIELD(rec, name, word, count, type, desc)
#include "../scenes/layout.def"
#undef SM_RECORD
#undef SM_FIELD
};
static const Field fields[] = {
#define SM_RECORD(rec, words, desc)
#define SM_FIELD(rec, name, word, count, type, desc) {#rec, #name, word, count, #type, desc},
#include "../scenes/layout.def"
#undef SM_RECORD
#undef SM_FIELD
};

static void gen_inc(void)
{
    printf("; kernels/lib/layout.inc -- GENERATED from scenes/layout.def by tools/gen_layout.c\n");
    printf("; (make docs). Byte offsets of every field of the packed scene, and record sizes.\n");
    for (size_t r = 0; r < sizeof recs / sizeof recs[0]; r++) {
        printf("\n; %s: %s\nSM_%s_BYTES = %d\n", recs[r].name, recs[r].desc, recs[r].name, 4 * recs[r].words);
        for (size_t f = 0; f < sizeof fields / sizeof fields[0]; f++)
            if (strcmp(fields[f].rec, recs[r].name) == 0)
                printf("SM_%s_%s = %d\n", fields[f].rec, fields[f].name, 4 * fields[f].word);
    }
}

static void gen_md(void)
{
    printf("# Scene-memory layout\n\n");
    printf("<!-- GENERATED from scenes/layout.def by tools/gen_layout.c (make docs); do not edit. -->\n\n");
    printf("`scenes/pack.c` packs a loaded scene and its BVH into simulated scene memory in this layout;\n"
           "the golden model reads it, and the assembly kernels read it through `kernels/lib/layout.inc`\n"
           "(the same offsets, as `SM_<RECORD>_<FIELD>` byte offsets and `SM_<RECORD>_BYTES` sizes).\n"
           "Every field is a 32-bit little-endian word; `addr` fields hold scene-memory byte addresses;\n"
           "arrays start on 64-byte boundaries. The header sits at the packed scene's base address.\n"
           "Primitives are stored in BVH leaf order, so a leaf's primitives are one contiguous run.\n"
           "With `accel.structure = kd` (docs/kdtree.md) `pack_add_kd` appends a kd-tree over the same\n"
           "packed primitives: a `KDNODE` array and its leaf lists, located by the header's `KD_*` fields.\n"
           "Textures are stored as one word per texel (sRGB-encoded 8-bit colour, linear 8-bit alpha);\n"
           "the header's `SRGB_LUT` decodes a colour byte to linear.\n");
    for (size_t r = 0; r < sizeof recs / sizeof recs[0]; r++) {
        printf("\n## %s — %s (%d words)\n\n| word | field | type | meaning |\n|---:|---|---|---|\n",
               recs[r].name, recs[r].desc, recs[r].words);
        for (size_t f = 0; f < sizeof fields / sizeof fields[0]; f++) {
            const Field *x = &fields[f];
            if (strcmp(x->rec, recs[r].name) != 0)
                continue;
            if (x->count > 1)
                printf("| %d-%d | `%s` | %s[%d] | %s |\n", x->word, x->word + x->count - 1, x->name, x->type,
                       x->count, x->desc);
            else
                printf("| %d | `%s` | %s | %s |\n", x->word, x->name, x->type, x->desc);
        }
    }
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "inc") == 0)
        gen_inc();
    else if (argc == 2 && strcmp(argv[1], "md") == 0)
        gen_md();
    else {
        fprintf(stderr, "usage: gen_layout inc|md\n");
        return 2;
    }
    return 0;
}
