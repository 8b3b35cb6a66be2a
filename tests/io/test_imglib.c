/* tests/io/test_imglib.c -- the loader of the image library (sim/imglib.h): where it looks, the
 * errors of a library that is missing, not a shared object or not sfsim's, and the built
 * libsfsim-img.so against the copy this binary links in (the same pixels read); and the image
 * writers' 8-bit conversion (sim/img_write.c) against the lround expression it replaced.
 *
 * The built library's path comes from $SFSIM_TEST_IMGLIB (make sets it); run by hand without
 * it, that test is skipped. bin/sfsim's own loading is tested by tests/cli/standalone.sh.
 */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../sim/img.h"
#include "../../sim/imglib.h"
#include "../support/files.h"

Test(imglib, locate_follows_the_binary_or_the_environment)
{
    char buf[4096], err[256], exe[4096];
    char *old = getenv("SFSIM_IMG_LIB") ? strdup(getenv("SFSIM_IMG_LIB")) : NULL;
    unsetenv("SFSIM_IMG_LIB");
    cr_assert_not_null(imglib_locate(buf, sizeof buf, err, sizeof err), "%s", err);
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    cr_assert_gt(n, 0);
    exe[n] = 0;
    *strrchr(exe, '/') = 0;
    *strrchr(exe, '/') = 0; /* <dir>/tests/io -> <dir> */
    char want[4200];
    snprintf(want, sizeof want, "%s/lib/sfsim/libsfsim-img.so", exe);
    cr_expect_str_eq(buf, want);
    setenv("SFSIM_IMG_LIB", "/somewhere/else.so", 1);
    cr_assert_not_null(imglib_locate(buf, sizeof buf, err, sizeof err), "%s", err);
    cr_expect_str_eq(buf, "/somewhere/else.so");
    setenv("SFSIM_IMG_LIB", "", 1); /* empty: as if unset */
    cr_assert_not_null(imglib_locate(buf, sizeof buf, err, sizeof err), "%s", err);
    cr_expect_str_eq(buf, want);
    if (old)
        setenv("SFSIM_IMG_LIB", old, 1);
    else
        unsetenv("SFSIM_IMG_LIB");
    free(old);
}

Test(imglib, a_missing_file_is_named_with_the_loader_error)
{
    char err[512];
    cr_assert_null(imglib_open("/nonexistent-dir/libsfsim-img.so", err, sizeof err));
    cr_expect(strstr(err, "cannot load the image library /nonexistent-dir/libsfsim-img.so: ") != NULL, "%s", err);
    cr_expect(strstr(err, "No such file") != NULL, "dlerror() is not in: %s", err);
}

Test(imglib, a_file_that_is_not_a_library_is_named_with_the_loader_error)
{
    char dir[64], path[128], err[512];
    tu_make_tmpdir(dir, sizeof dir, "imglib");
    snprintf(path, sizeof path, "%s/libsfsim-img.so", dir);
    tu_write_file(path, "not a shared object\n");
    cr_expect_null(imglib_open(path, err, sizeof err));
    cr_expect(strstr(err, path) != NULL && strstr(err, "cannot load the image library") == err, "%s", err);
    cr_expect(strstr(err, "ELF") != NULL || strstr(err, "too short") != NULL, "dlerror() is not in: %s", err);
    tu_remove_tree(dir);
}

Test(imglib, a_library_without_the_table_is_refused)
{
    char err[512];
    cr_assert_null(imglib_open("libm.so.6", err, sizeof err));
    cr_expect(strstr(err, "libm.so.6") != NULL && strstr(err, "no img_shim table") != NULL, "%s", err);
}

Test(imglib, the_built_library_reads_what_the_linked_copy_reads)
{
    const char *lib = getenv("SFSIM_TEST_IMGLIB");
    if (!lib || !*lib)
        cr_skip_test("SFSIM_TEST_IMGLIB is not set (make sets it to the built libsfsim-img.so)");
    char err[1024], dir[64], path[128];
    const ImgShim *built = imglib_open(lib, err, sizeof err);
    cr_assert_not_null(built, "%s", err);
    const ImgShim *linked = imglib_get(err, sizeof err);
    cr_assert_not_null(linked, "%s", err);
    cr_assert_neq(built, linked, "the test binary should link its own copy");
    float px[4 * 3 * 3];
    for (int i = 0; i < 36; i++)
        px[i] = 0.03f * (float)i;
    tu_make_tmpdir(dir, sizeof dir, "imglib");
    const char *names[] = {"x.exr", "x.png"};
    for (int k = 0; k < 2; k++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        int rc = k ? img_write_display(NULL, path, px, 4, 3, 1.0f, err, sizeof err)
                   : img_write_linear(NULL, path, px, 4, 3, err, sizeof err);
        cr_assert_eq(rc, 0, "%s", err);
        float *a = NULL, *b = NULL;
        int wa = 0, ha = 0, wb = 0, hb = 0;
        cr_assert_eq(built->read(path, &a, &wa, &ha, err, sizeof err), 0, "%s", err);
        cr_assert_eq(linked->read(path, &b, &wb, &hb, err, sizeof err), 0, "%s", err);
        cr_expect(wa == 4 && ha == 3 && wb == 4 && hb == 3, "%s: %d x %d and %d x %d", names[k], wa, ha, wb, hb);
        cr_expect_eq(memcmp(a, b, sizeof px), 0, "%s read differently", names[k]);
        free(a);
        free(b);
    }
    tu_remove_tree(dir);
}

/* The reference img_to_u8 replaced (sim/img_write.c; once in sim/img.cpp). */
static unsigned char to_u8_reference(float x)
{
    float v = isfinite(x) ? fminf(fmaxf(x, 0.0f), 1.0f) : 0.0f;
    return (unsigned char)lroundf(v * 255.0f);
}

static float float_of(uint32_t bits)
{
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

static uint32_t bits_of(float f)
{
    uint32_t b;
    memcpy(&b, &f, sizeof b);
    return b;
}

Test(imglib, to_u8_rounds_as_lround_of_the_clamped_value)
{
    /* around every rounding boundary (k + 0.5) / 255 and every k / 255, 4096 floats either side */
    for (int k = 0; k <= 510; k++) {
        uint32_t mid = bits_of((float)k / 510.0f);
        for (uint32_t d = 0; d < 4096; d++) {
            float a = float_of(mid + d), b = float_of(mid - d);
            cr_assert_eq(img_to_u8(a), to_u8_reference(a), "x = %.9g", (double)a);
            cr_assert_eq(img_to_u8(b), to_u8_reference(b), "x = %.9g", (double)b);
        }
    }
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 2.0f, 0.49999997f / 255.0f, 0.5f / 255.0f, 1e-45f, -1e-45f,
                             1e30f, -1e30f, INFINITY, -INFINITY, NAN, -NAN, 0.99999994f, 1.0000001f};
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        cr_expect_eq(img_to_u8(special[i]), to_u8_reference(special[i]), "x = %.9g", (double)special[i]);
    /* every float bit pattern, in a stride that visits each exponent many times */
    for (uint64_t b = 0; b < 0x100000000ull; b += 65537)
        cr_assert_eq(img_to_u8(float_of((uint32_t)b)), to_u8_reference(float_of((uint32_t)b)), "bits 0x%08x",
                     (unsigned)b);
}

/* img_to_u8_n (eight lanes at a time, then one by one) gives img_to_u8's reference
 * value for every channel: each rounding boundary and special value, and a stride through every
 * float bit pattern, at each start and length modulo 8 so that the vector blocks and the tail
 * both meet every value. (Checked once over all 2^32 floats when written.) */
Test(imglib, to_u8_n_converts_as_to_u8_does)
{
    enum { N = 511 * 2 * 64 + 17 + 65536 };
    float *x = malloc(sizeof(float) * N);
    unsigned char *out = malloc(N + 8);
    cr_assert(x && out);
    size_t n = 0;
    for (int k = 0; k <= 510; k++) {
        uint32_t mid = bits_of((float)k / 510.0f);
        for (uint32_t d = 0; d < 64; d++) {
            x[n++] = float_of(mid + d);
            x[n++] = float_of(mid - d);
        }
    }
    const float special[] = {0.0f, -0.0f, 1.0f, -1.0f, 2.0f, 0.49999997f / 255.0f, 0.5f / 255.0f, 1e-45f, -1e-45f,
                             1e30f, -1e30f, INFINITY, -INFINITY, NAN, -NAN, 0.99999994f, 1.0000001f};
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        x[n++] = special[i];
    for (uint64_t b = 0; b < 0x100000000ull && n < N; b += 65537)
        x[n++] = float_of((uint32_t)b);
    for (size_t start = 0; start < 8; start++) {
        size_t len = n - 8 - start; /* every length modulo 8 too */
        memset(out, 0xaa, N + 8);
        img_to_u8_n(x + start, out + start, len);
        for (size_t i = 0; i < start; i++)
            cr_assert_eq(out[i], 0xaa, "wrote before the start");
        for (size_t i = start; i < start + len; i++)
            cr_assert_eq(out[i], to_u8_reference(x[i]), "x = %.9g (bits 0x%08x), start %zu", (double)x[i],
                         (unsigned)bits_of(x[i]), start);
        cr_assert_eq(out[start + len], 0xaa, "wrote past the end");
    }
    free(x);
    free(out);
}

/* The test binary links the library's objects, so nothing was dlopen'ed and sfsim's _exit at
 * the end (sim/main.c) would not apply to it. */
Test(imglib, a_binary_with_the_linked_copy_has_not_dlopened_it)
{
    char err[1024];
    cr_assert_not_null(imglib_get(err, sizeof err), "%s", err);
    cr_assert_eq(imglib_dlopened(), 0);
}
