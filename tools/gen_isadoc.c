/* tools/gen_isadoc.c -- prints docs/isa.md, the instruction-set reference, from isa/opcodes.def
 * (through the tables of isa/isa.c). `make docs` runs it; tests/unit/test_isa.c fails when the
 * checked-in docs/isa.md differs from its output.
 *
 * Owns: the wording of the reference and the grouping of opcodes into sections.
 * Must not: hold any fact about an instruction that the table already holds (names, codes,
 * operands, units, categories, flags and meanings all come from isa_ops[] and isa_formats[]);
 * the bit layout below is the one fixed text, copied from isa/isa.h.
 * Output is deterministic: no dates, no paths, table order only.
 */
#include <stdio.h>
#include <string.h>

#include "../isa/isa.h"

/* Sections of the reference by opcode range (the ranges of the comment blocks in opcodes.def).
 * An opcode outside every range lands in a final catch-all section, so a new row is never lost. */
typedef struct Group { unsigned lo, hi; const char *title; const char *note; } Group;

static const Group groups[] = {
    {0x00, 0x0F, "Control", "Branch targets are instruction indices (labels). `jal`/`jr` give calls and returns."},
    {0x10, 0x2F, "Scalar integer", "32-bit two's-complement, wrapping. Shift counts use the low 5 bits."},
    {0x30, 0x3F, "Scalar float", "IEEE-754 binary32 bit patterns in scalar registers, round to nearest even."},
    {0x40, 0x57, "Vector float", "Per lane, binary32, under the exec mask (merge masking)."},
    {0x58, 0x67, "Vector integer and bit operations", "Per lane, 32-bit wrapping, under the exec mask. Shift counts use the low 5 bits."},
    {0x68, 0x6F, "Vector compares into masks", "`ma := E & test`: lanes outside the exec mask E are cleared, lanes >= N are 0."},
    {0x70, 0x77, "Vector moves and select", "Under the exec mask, except `vext` which reads one lane."},
    {0x78, 0x87, "Mask registers", "Masks hold N bits (lane 0 = bit 0); bits at lanes >= N are always 0."},
    {0x88, 0x8F, "ID streams: address-generation units", "A stream is an array of 32-bit ray IDs in IDM between two byte addresses [begin, end)."},
    {0x90, 0x97, "Ray buffers", "Two buffers RB0/RB1; RBc is the current one, RBn the next (swapped by `rswap`). Field arrays are indexed by ray ID."},
    {0x98, 0x9F, "Partition unit", "The partition unit keeps a queue of mask bits fed by `pmask` and reorders a stream by them."},
    {0xA0, 0xA7, "Scratchpad", "Dual-ported scratchpad: traversal stack and intermediates. `.spad` data is loaded at address 0."},
    {0xA8, 0xAF, "Scene memory", "BVH, triangles, materials, textures, lights. `.data` is loaded at address 0."},
    {0xB0, 0xB7, "Framebuffer", "Floats, accumulated by scatter-add."},
};
#define NGROUPS (sizeof groups / sizeof groups[0])

static const char *const flag_names[] = {"vec", "float", "branch", "end", "rb", "idm", "spad", "scene", "fb", "write", "rbn", "side"};

static const char *const flag_descs[] = {
    "operates on N lanes; counts toward SIMD utilization",
    "interprets values as IEEE-754 binary32",
    "may change the pc",
    "ends execution",
    "touches a ray buffer",
    "touches ID-stream memory",
    "touches the scratchpad",
    "touches scene memory",
    "touches the framebuffer",
    "writes the memory it touches (store, scatter, append, scatter-add, in-place partition); without it a memory instruction only reads",
    "with rb: the next ray buffer (RBn), not the current one (RBc)",
    "an effect no operand or memory flag shows (swapping the ray buffers, the statistics' stage or generation): the scheduling pass moves nothing across it",
};

/* Operand placeholder as written in the syntax column: the kind letter and the field letter,
 * matching the DESC column's `ra := rb + rc`. */
static const char *operand_text(const IsaOperand *o, char *buf, size_t len)
{
    static const char fl[] = "abcd";
    switch (o->kind) {
    case ISA_K_R: snprintf(buf, len, "r%c", fl[o->field]); break;
    case ISA_K_V: snprintf(buf, len, "v%c", fl[o->field]); break;
    case ISA_K_M: snprintf(buf, len, "m%c", fl[o->field]); break;
    case ISA_K_IMM: snprintf(buf, len, "imm"); break;
    case ISA_K_LABEL: snprintf(buf, len, "label"); break;
    }
    return buf;
}

static void syntax_text(const IsaOpInfo *oi, char *buf, size_t len)
{
    const IsaFormatInfo *f = &isa_formats[oi->format];
    size_t n = (size_t)snprintf(buf, len, "%s", oi->mnemonic);
    char ob[16];
    for (int i = 0; i < f->nops && n < len; i++)
        n += (size_t)snprintf(buf + n, len - n, "%s%s", i == 0 ? " " : ", ", operand_text(&f->ops[i], ob, sizeof ob));
    if (f->masked && n < len)
        snprintf(buf + n, len - n, " [@mK]");
}

static void flags_text(uint32_t flags, char *buf, size_t len)
{
    size_t n = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < sizeof flag_names / sizeof flag_names[0] && n < len; i++)
        if (flags & (1u << i))
            n += (size_t)snprintf(buf + n, len - n, "%s%s", n ? " " : "", flag_names[i]);
}

/* A table cell: `|` must be escaped inside GitHub-flavoured tables. */
static void put_cell(FILE *out, const char *s)
{
    for (; *s; s++) {
        if (*s == '|')
            fputs("\\|", out);
        else
            fputc(*s, out);
    }
}

static int group_of(uint8_t code)
{
    for (size_t g = 0; g < NGROUPS; g++)
        if (code >= groups[g].lo && code <= groups[g].hi)
            return (int)g;
    return -1;
}

static void op_row(FILE *out, const IsaOpInfo *oi)
{
    char syn[96], fl[96];
    syntax_text(oi, syn, sizeof syn);
    flags_text(oi->flags, fl, sizeof fl);
    fprintf(out, "| `%s` | `%s` | 0x%02X | %s | %s | %s | %s | ", oi->mnemonic, syn, oi->code,
            oi->access[0] ? oi->access : "-", isa_unit_names[oi->unit], isa_category_keys[oi->category],
            fl[0] ? fl : "-");
    put_cell(out, oi->desc);
    fputs(" |\n", out);
}

static void ops_in_code_order(int *order)
{
    int n = 0;
    for (int code = 0; code < 256; code++) {
        int op = isa_op_from_code((uint8_t)code);
        if (op >= 0)
            order[n++] = op;
    }
}

static void write_intro(FILE *out)
{
    fputs("# sfsim instruction set\n\n"
          "<!-- GENERATED from isa/opcodes.def by tools/gen_isadoc.c (make docs); do not edit. -->\n\n"
          "The instruction set of the simulated stream-filtering ray tracing processor, one row per\n"
          "instruction of `isa/opcodes.def`. Why it looks this way: [isa-design.md](isa-design.md).\n"
          "Assembler syntax: [assembler.md](assembler.md). Core behaviour in detail: [core.md](core.md).\n\n"
          "## Machine state\n\n"
          "- **Scalar registers** `r0`..`r31`: 32 bits each, holding integers or binary32 float bit\n"
          "  patterns. `r0` is an ordinary register (it is not hard-wired to zero).\n"
          "- **Vector registers** `v0`..`v31`: N lanes of 32 bits each. N, the SIMD width, is a\n"
          "  machine parameter chosen at run time (1..64), not part of the program; `rdn` reads it.\n"
          "- **Mask registers** `m0`..`m7`: N bits each, bit l for lane l; bits for lanes >= N are 0.\n"
          "- At reset every register is 0, `m0` has all N lanes set and `m1`..`m7` are empty, the pc is\n"
          "  0 and the statistics stage is `other`.\n"
          "- **Exec mask.** Instructions of a masked format (marked `[@mK]` below) take an optional\n"
          "  trailing `@mK`; without it the exec mask E is `m0`. Only lanes whose E bit is set change\n"
          "  (merge masking): the other lanes of the destination keep their old values, and scatters,\n"
          "  appends and framebuffer adds write nothing for them. Compares write `E & test`, clearing\n"
          "  the lanes outside E.\n"
          "- **Memories**, byte-addressed; every access is a 32-bit little-endian word at a 4-byte\n"
          "  aligned address (sizes come from the machine config):\n"
          "  - **RB0, RB1** — the two ray buffers. One is current (**RBc**, read by `rgat`, written by\n"
          "    `rsct`), the other next (**RBn**, `rgatn`/`rsctn`); `rswap` exchanges them.\n"
          "  - **IDM** — ID-stream memory: the streams of ray IDs (`sfetch`, `sapp`, `part`, `sld`/`sst`).\n"
          "  - **SP** — scratchpad (`spld`/`spst`, `vspld`/`vspst`); the `.spad` section is loaded at 0.\n"
          "  - **SM** — scene memory (`ld`/`st`, `ldb`, `ldg`); the `.data` section is loaded at 0.\n"
          "  - **FB** — framebuffer of floats (`fbadd`).\n"
          "- **Partition unit**: a queue of mask bits (`pmask` appends N bits, lane 0 first; `part`\n"
          "  consumes the queue; `pclr` empties it).\n"
          "- **Traps.** Among others: an access outside a memory or misaligned, a bad stream (such as\n"
          "  `sfetch` with begin > end), a partition whose queued bit count q is not in L <= q < L + N\n"
          "  for a stream of L IDs, an integer division by zero, `vext` with a lane >= N, a pc outside\n"
          "  the program, or the instruction limit stops the machine with a message naming the pc, the\n"
          "  instruction and its source file:line (the full list: [core.md](core.md)).\n\n",
          out);
    fputs("## Instruction word\n\n"
          "Every instruction is one 64-bit word (little-endian in object files):\n\n"
          "```\n"
          " 63                              32 31 30  28 27   23 22   18 17   13 12    8 7      0\n"
          "+----------------------------------+--+------+-------+-------+-------+-------+--------+\n"
          "|             imm (32)             |0 | mask |   d   |   c   |   b   |   a   | opcode |\n"
          "+----------------------------------+--+------+-------+-------+-------+-------+--------+\n"
          "```\n\n"
          "| bits | field | contents |\n|---|---|---|\n"
          "| 7:0 | opcode | the instruction (the table's code column) |\n"
          "| 12:8 | a | register number (0..31 for r and v, 0..7 for m) |\n"
          "| 17:13 | b | register number |\n"
          "| 22:18 | c | register number |\n"
          "| 27:23 | d | register number |\n"
          "| 30:28 | mask | exec mask register K of `@mK` (masked formats only; 0 = m0) |\n"
          "| 31 | - | reserved, zero |\n"
          "| 63:32 | imm | 32-bit immediate: integer, float bits, byte offset or branch target |\n\n"
          "A field the format does not use must be zero, and so must the mask field of an unmasked\n"
          "format: the decoder rejects other words, so each valid word has exactly one meaning.\n\n",
          out);
}

static void write_formats(FILE *out)
{
    fputs("## Operand formats\n\n"
          "In the syntax, `ra`/`va`/`ma` stand for a scalar, vector or mask register held in field a\n"
          "(likewise b, c, d), `imm` for an immediate expression (integer or float) and `label` for a code\n"
          "address. The access column of the instruction tables gives, per register operand in order\n"
          "(immediates and labels have no entry), `r` (read), `w` (written) or `x` (read and written).\n\n"
          "| format | operands | exec mask |\n|---|---|---|\n",
          out);
    for (int f = 0; f < ISA_F_COUNT; f++) {
        const IsaFormatInfo *fi = &isa_formats[f];
        char ops[96], ob[16];
        size_t n = 0;
        ops[0] = '\0';
        for (int i = 0; i < fi->nops; i++)
            n += (size_t)snprintf(ops + n, sizeof ops - n, "%s%s", i ? ", " : "", operand_text(&fi->ops[i], ob, sizeof ob));
        fprintf(out, "| %s | %s | %s |\n", fi->name, fi->nops ? ops : "(none)", fi->masked ? "`@mK`" : "-");
    }
    fputs("\n", out);
}

static void write_classes(FILE *out)
{
    fputs("## Unit classes\n\n"
          "Each instruction names the functional-unit class it issues to. The timing model maps a\n"
          "class to a latency and an issue rate taken from the machine config; the ISA holds no timing.\n\n"
          "| unit | description |\n|---|---|\n",
          out);
    for (int u = 0; u < ISA_U_COUNT; u++) {
        fprintf(out, "| %s | ", isa_unit_names[u]);
        put_cell(out, isa_unit_descs[u]);
        fputs(" |\n", out);
    }
    fputs("\n## Categories\n\n"
          "Statistics count operations by category: the categories of Gribble & Ramani 2008, Table 5\n"
          "(load, store, compute, scatter/gather, partition), plus integer (scalar address and loop\n"
          "arithmetic) and control.\n\n"
          "| category | instructions |\n|---|---|\n",
          out);
    int order[ISA_OP_COUNT];
    ops_in_code_order(order);
    for (int c = 0; c < ISA_C_COUNT; c++) {
        fprintf(out, "| %s | ", isa_category_keys[c]);
        int first = 1;
        for (int i = 0; i < ISA_OP_COUNT; i++)
            if ((int)isa_ops[order[i]].category == c) {
                fprintf(out, "%s`%s`", first ? "" : " ", isa_ops[order[i]].mnemonic);
                first = 0;
            }
        fputs(" |\n", out);
    }
    fputs("\n## Stages\n\n"
          "`stage imm` attributes the instructions that follow to a statistics stage:\n\n"
          "| imm | stage |\n|---|---|\n",
          out);
    for (int s = 0; s < ISA_STAGE_COUNT; s++)
        fprintf(out, "| %d | %s |\n", s, isa_stage_keys[s]);
    fputs("\n## Flags\n\n| flag | meaning |\n|---|---|\n", out);
    for (size_t i = 0; i < sizeof flag_names / sizeof flag_names[0]; i++)
        fprintf(out, "| %s | %s |\n", flag_names[i], flag_descs[i]);
    fputs("\n", out);
}

static void write_tables(FILE *out)
{
    int order[ISA_OP_COUNT];
    ops_in_code_order(order);
    fprintf(out, "## Instructions\n\n%d instructions. In the meaning column E is the exec mask, l a lane,\n"
                 "memory names as above (`RBc[x]` is the word at byte address x of the current ray buffer).\n\n",
            (int)ISA_OP_COUNT);
    for (size_t g = 0; g <= NGROUPS; g++) {
        int any = 0;
        for (int i = 0; i < ISA_OP_COUNT; i++) {
            const IsaOpInfo *oi = &isa_ops[order[i]];
            int og = group_of(oi->code);
            if (g < NGROUPS ? og != (int)g : og >= 0)
                continue;
            if (!any) {
                if (g < NGROUPS)
                    fprintf(out, "### %s (0x%02X-0x%02X)\n\n%s\n\n", groups[g].title, groups[g].lo, groups[g].hi,
                            groups[g].note);
                else
                    fputs("### Other\n\n", out);
                fputs("| mnemonic | syntax | opcode | access | unit | category | flags | meaning |\n"
                      "|---|---|---|---|---|---|---|---|\n",
                      out);
                any = 1;
            }
            op_row(out, oi);
        }
        if (any)
            fputs("\n", out);
    }
}

/* The whole reference. Returns 0, or -1 if the output could not be written. */
static int gen_isadoc_write(FILE *out)
{
    write_intro(out);
    write_formats(out);
    write_classes(out);
    write_tables(out);
    fflush(out);
    return ferror(out) ? -1 : 0;
}

#ifndef GEN_ISADOC_NO_MAIN
int main(void)
{
    if (gen_isadoc_write(stdout) != 0) {
        fprintf(stderr, "gen_isadoc: write error\n");
        return 1;
    }
    return 0;
}
#endif
