/* tests/fuzz/fuzz_asm.c -- libFuzzer target for sfasm and the object reader.
 *
 * Feeds the input to the assembler as source text (diagnostics to /dev/null) and to
 * asm_object_decode as an object file; when the source assembles, its object is also encoded,
 * decoded, disassembled and reassembled (same bytes required), which checks the writer, reader
 * and disassembler on valid objects.
 * Must not: leak, write files, or depend on the working directory beyond what .include reads.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../asm/asm.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static FILE *devnull(void)
{
    static FILE *f;
    if (!f)
        f = fopen("/dev/null", "w");
    return f;
}

/* The disassembly of a valid object must assemble back to the same bytes. */
static void check_reassembly(const AsmObject *obj)
{
    char *text = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&text, &len);
    if (!m)
        return;
    asm_disassemble(obj, m, 0);
    fclose(m);
    AsmOptions opt = {0};
    opt.diag = devnull();
    AsmObject back;
    if (asm_assemble_string("dis.s", text, len, &opt, &back) != 0 || back.ntext != obj->ntext ||
        back.ndata != obj->ndata || back.nspad != obj->nspad ||
        (obj->ntext && memcmp(back.text, obj->text, obj->ntext * sizeof *obj->text)) ||
        (obj->ndata && memcmp(back.data, obj->data, obj->ndata)) ||
        (obj->nspad && memcmp(back.spad, obj->spad, obj->nspad)))
        abort();
    asm_object_free(&back);
    free(text);
}

/* Objects this large take seconds to print and reassemble under ASan for no new coverage:
 * the unit tests and small objects cover the same code. */
static int is_large(const AsmObject *obj)
{
    return obj->ntext > 65536 || obj->ndata + (uint64_t)obj->nspad > (1u << 20);
}

static void check_object(const AsmObject *obj)
{
    uint8_t *buf;
    size_t len;
    char err[256];
    if (asm_object_encode(obj, &buf, &len, err, sizeof err) != 0)
        abort(); /* an object the assembler made must always encode */
    AsmObject back;
    if (asm_object_decode(buf, len, "fuzz.sfo", &back, err, sizeof err) != 0)
        abort(); /* ...and be accepted by the reader */
    if (!is_large(&back))
        asm_disassemble(&back, devnull(), 1);
    asm_object_free(&back);
    free(buf);
    if (!is_large(obj))
        check_reassembly(obj);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    AsmOptions opt = {0};
    opt.diag = devnull();
    AsmObject obj;
    if (asm_assemble_string("fuzz.s", (const char *)data, size, &opt, &obj) == 0)
        check_object(&obj);
    asm_object_free(&obj);

    char err[256];
    if (asm_object_decode(data, size, "fuzz.sfo", &obj, err, sizeof err) == 0) {
        asm_disassemble(&obj, devnull(), 1);
        asm_object_free(&obj);
    }
    return 0;
}
