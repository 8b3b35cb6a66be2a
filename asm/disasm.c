/* asm/disasm.c -- sfasm's disassembler: an object back to assembler text.
 *
 * Owns: the text layout of a disassembly (labels L<pc> at branch targets, one instruction per
 * line from isa_disassemble, DATA and SPAD as exact .word/.byte lines). The output assembles back
 * to identical TEXT, DATA and SPAD bytes. Must not: change the object or depend on its symbols.
 */
#include <stdlib.h>

#include "asm.h"
#include "../isa/isa.h"

/* The label operand of an instruction, if its format has one: 1 with *target set. */
static int label_target(const IsaInstr *in, uint32_t *target)
{
    const IsaFormatInfo *f = &isa_formats[isa_ops[in->op].format];
    for (int i = 0; i < f->nops; i++)
        if (f->ops[i].kind == ISA_K_LABEL) {
            *target = in->imm;
            return 1;
        }
    return 0;
}

static void print_text(const AsmObject *obj, FILE *out, int with_source)
{
    /* One flag per pc, plus one for a label just past the last instruction. */
    uint8_t *is_target = calloc((size_t)obj->ntext + 1, 1);
    IsaInstr in;
    char buf[160], err[160], where[512];
    uint32_t t;
    for (uint32_t pc = 0; is_target && pc < obj->ntext; pc++)
        if (isa_decode(obj->text[pc], &in, err, sizeof err) == 0 && label_target(&in, &t) && t <= obj->ntext)
            is_target[t] = 1;
    fprintf(out, "        .text\n");
    for (uint32_t pc = 0; pc < obj->ntext; pc++) {
        if (is_target && is_target[pc])
            fprintf(out, "L%u:\n", pc);
        if (isa_decode(obj->text[pc], &in, err, sizeof err) != 0) {
            fprintf(out, "        ; pc %u: undecodable word 0x%016llx (%s)\n", pc,
                    (unsigned long long)obj->text[pc], err);
            continue;
        }
        /* A target outside the program has no label to name it: print the number. */
        int named = is_target && (!label_target(&in, &t) || t <= obj->ntext);
        isa_disassemble(&in, named, buf, sizeof buf);
        if (with_source) {
            asm_object_where(obj, pc, where, sizeof where);
            fprintf(out, "        %-40s ; %s\n", buf, where);
        } else {
            fprintf(out, "        %s\n", buf);
        }
    }
    if (is_target && is_target[obj->ntext])
        fprintf(out, "L%u:\n", obj->ntext);
    free(is_target);
}

/* Exact bytes: little-endian words, four per line, then any tail as .byte. */
static void print_image(FILE *out, const char *name, const uint8_t *p, uint32_t n)
{
    if (n == 0)
        return;
    fprintf(out, "\n        %s\n", name);
    uint32_t i = 0;
    for (; i + 4 <= n; i += 16) {
        fprintf(out, "        .word ");
        uint32_t k = 0;
        for (; k < 16 && i + k + 4 <= n; k += 4) {
            uint32_t w = (uint32_t)p[i + k] | (uint32_t)p[i + k + 1] << 8 |
                         (uint32_t)p[i + k + 2] << 16 | (uint32_t)p[i + k + 3] << 24;
            fprintf(out, "%s0x%08x", k ? ", " : "", w);
        }
        fprintf(out, "    ; +0x%x\n", i);
        if (k < 16) {
            i += k;
            break;
        }
    }
    if (i < n) {
        fprintf(out, "        .byte ");
        for (uint32_t k = i; k < n; k++)
            fprintf(out, "%s0x%02x", k > i ? ", " : "", p[k]);
        fprintf(out, "    ; +0x%x\n", i);
    }
}

void asm_disassemble(const AsmObject *obj, FILE *out, int with_source)
{
    print_text(obj, out, with_source);
    print_image(out, ".data", obj->data, obj->ndata);
    print_image(out, ".spad", obj->spad, obj->nspad);
}
