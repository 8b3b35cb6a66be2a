/* sim/core_loop.h -- the functional core's run loop, a template: sim/core.c includes it once per
 * copy it needs, naming it CORE_LOOP_NAME, with CORE_LOOP_HOOKED 0 (functional mode: no record is
 * built, no hook test is left in the code) or 1 (the timed modes). Not a header
 * of its own: it uses core.c's types, its semantics families (the CORE_EXEC_<UNIT> macros) and
 * its helpers, and nothing else includes it.
 *
 * Dispatch is threaded: a table of label addresses by opcode (a GNU C extension), and every
 * opcode's code ends with its own copy of the step to the next instruction and its own indirect
 * jump. A single jump shared by all opcodes (a switch in a loop) is predicted from that one
 * site; one jump per opcode is predicted from the opcode before, which in a kernel's loops is
 * nearly always followed by the same one (callgrind's branch simulation of the conference frame:
 * docs/core.md). A function with a computed goto cannot be inlined or cloned, hence the template.
 *
 * One instruction: the exec mask, its family's semantics (0, or -1 on a trap), its counts in the
 * row of the stage and generation before it, the hook, then the pc (a halted core stays on its
 * halt). max_instr = 0: no limit.
 *
 * CORE_LOOP_LANES is N when the copy is made for one lane count (the default machine's 16: the
 * lane loops of a vector instruction become one block, with no loop), or 0 for any N (c->n).
 */
static __attribute__((noinline)) CoreExit CORE_LOOP_NAME(Core *c, uint64_t max_instr, uint64_t limit)
{
    const int hooked = CORE_LOOP_HOOKED;
    static const void *const disp[ISA_OP_COUNT + 1] = {
#define ISA_OP(name, code, mnem, fmt, acc, unit, cat, flags, desc) [ISA_OP_##name] = &&op_##name,
#include "../isa/opcodes.def"
#undef ISA_OP
        [ISA_OP_COUNT] = &&op_end, /* not an opcode: only the sentinel after the program carries it */
    };
    const int n = CORE_LOOP_LANES ? CORE_LOOP_LANES : c->n;
    if (n < 1 || n > ISA_MAX_LANES) /* core_new guarantees it; tells the compiler the lane bound */
        __builtin_unreachable();
    /* Instructions left before the limit; no limit (0): more than any run can execute. */
    uint64_t left = max_instr ? max_instr : UINT64_MAX;
    const Dec *dc;
    const IsaInstr *in;
    uint64_t E, *row, where = 0; /* where: the record's core_record_word, hooked */
    Exec x;
    int r;

#define CORE_NEXT()                                                                             \
    do {                                                                                        \
        if (left-- == 0)                                                                        \
            goto limit;                                                                         \
        dc = &c->code[c->pc]; /* pc <= ncode always: code[ncode] is the end sentinel */         \
        in = &dc->in;                                                                           \
        E = c->m[dc->emask] & c->all;                                                           \
        x = (Exec){.in = in, .E = E, .n = n, .next = c->pc + 1, .lanes = E, .hooked = hooked};  \
        if (hooked) {                                                                           \
            where = c->pc | c->rec_hi;                                                          \
            record_reset(&c->rec, where, in, E);                                                \
        }                                                                                       \
        row = c->row; /* counted in the stage and generation before the instruction */          \
        goto *disp[in->op];                                                                     \
    } while (0)

    if (hooked) { /* record_reset leaves these to the memory families (a trap may have left them set) */
        c->rec.naddr = 0;
        c->rec.count = 0;
        c->rec.base = 0;
    }
    CORE_NEXT();
#define ISA_OP(name, code, mnem, fmt, acc, unit, cat, flags, desc)                              \
    op_##name:                                                                                  \
        r = CORE_EXEC_##unit(c, &x, ISA_OP_##name);                                             \
        if (r) {                                                                                \
            c->slice_left = left;                                                               \
            return CORE_EXIT_TRAP;                                                              \
        }                                                                                       \
        row[ISA_OP_##name]++;                                                                   \
        if ((flags) & ISA_FL_VEC)                                                               \
            row[ISA_OP_COUNT] += (uint64_t)popcount64(x.lanes);                                 \
        if (hooked) {                                                                           \
            CoreFollow *f_ = c->follow;                                                         \
            const uint64_t w_ = ((flags) & ISA_FL_BRANCH) ? where | (uint64_t)c->rec.taken << 48 : where; \
            if (w_ == f_->where && (uint32_t)where != f_->last) {                               \
                f_->where++;                                                                    \
            } else {                                                                            \
                c->rec.next_pc = x.halt ? c->pc : x.next;                                       \
                c->hook_op[ISA_OP_##name](c->hook_ctx, &c->rec);                                \
                if (__builtin_expect(f_->yield, 0)) { /* the record stays for the hook's owner */ \
                    if (!x.halt)                                                                \
                        c->pc = x.next;                                                         \
                    c->slice_left = left;                                                       \
                    return CORE_EXIT_YIELD;                                                     \
                }                                                                               \
            }                                                                                   \
            /* what record_reset leaves to the memory families: the addresses, and the count and \
             * base that only the AGU's and the partition unit's set */                          \
            if (ISA_U_##unit == ISA_U_AGU || ISA_U_##unit == ISA_U_RBUF ||                      \
                ISA_U_##unit == ISA_U_PART || ISA_U_##unit == ISA_U_SPAD ||                     \
                ISA_U_##unit == ISA_U_SCENE || ISA_U_##unit == ISA_U_FB)                        \
                c->rec.naddr = 0;                                                               \
            if (ISA_U_##unit == ISA_U_AGU || ISA_U_##unit == ISA_U_PART) {                      \
                c->rec.count = 0;                                                               \
                c->rec.base = 0;                                                                \
            }                                                                                   \
        }                                                                                       \
        if (x.halt) {                                                                           \
            c->slice_left = left;                                                               \
            return CORE_EXIT_HALT;                                                              \
        }                                                                                       \
        c->pc = x.next;                                                                         \
        CORE_NEXT();
#include "../isa/opcodes.def"
#undef ISA_OP
#undef CORE_NEXT

op_end:
    c->slice_left = left;
    trap(c, "pc past the end of the program (%u instructions)", c->ncode);
    return CORE_EXIT_TRAP;
limit:
    c->slice_left = 0;
    trap(c, "instruction limit of %llu reached", (unsigned long long)limit);
    return CORE_EXIT_LIMIT;
}

#undef CORE_LOOP_NAME
#undef CORE_LOOP_HOOKED
#undef CORE_LOOP_LANES
