/* sim/imglib.c -- loads the image library libsfsim-img.so on demand (sim/imglib.h) and
 * implements img.h's img_read through its table (sim/imgshim.h). The writers do not need it
 * (sim/img_write.c, sim/heatmap.c).
 *
 * Owns: the library's search order, the one load per process (pthread_once). Must not: touch
 * pixels, or exit (the callers map a failure to EXIT_IO).
 */
#include "imglib.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../host/infile.h"
#include "img.h"

/* Defined when the binary links the library's objects in (tests and tools: sim/imgshim.h). */
extern const ImgShim img_shim __attribute__((weak));

static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static const ImgShim *loaded;
static char load_err[PATH_MAX + 1024];
/* Set before the first dlopen of the library or its dependencies. */
static int dlopen_used;

const char *imglib_locate(char *buf, size_t len, char *err, size_t errlen)
{
    const char *env = getenv("SFSIM_IMG_LIB");
    if (env && *env) {
        snprintf(buf, len, "%s", env);
        return buf;
    }
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        snprintf(err, errlen, "cannot find the image library: this program's folder is unknown (/proc/self/exe: %s); "
                              "set SFSIM_IMG_LIB", strerror(errno));
        return NULL;
    }
    exe[n] = 0;
    /* <prefix>/bin/sfsim -> <prefix>/lib/sfsim/libsfsim-img.so, said without "..": it is in messages */
    for (int up = 0; up < 2; up++) {
        char *slash = strrchr(exe, '/');
        if (slash)
            *slash = 0;
    }
    if ((size_t)snprintf(buf, len, "%s/lib/sfsim/%s", exe, IMGLIB_FILE) >= len) {
        snprintf(err, errlen, "%s/lib/sfsim/%s: path too long", exe, IMGLIB_FILE);
        return NULL;
    }
    return buf;
}

const ImgShim *imglib_open(const char *path, char *err, size_t errlen)
{
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *why = dlerror();
        snprintf(err, errlen, "cannot load the image library %s: %s", path, why ? why : "dlopen failed");
        return NULL;
    }
    const ImgShim *t = dlsym(h, IMG_SHIM_SYMBOL);
    if (!t || t->abi != IMG_SHIM_ABI || t->size != sizeof(ImgShim)) {
        snprintf(err, errlen, "cannot load the image library %s: %s", path,
                 !t ? "it has no " IMG_SHIM_SYMBOL " table (not sfsim's image library)"
                    : "it is from another build of sfsim (its interface differs; rebuild or reinstall)");
        dlclose(h);
        return NULL;
    }
    return t; /* kept loaded for the rest of the run */
}

/* Open the libraries that PATH.deps lists (scripts/imglib_deps.sh: each after those it needs),
 * one dlopen each, before the image library itself. Why: in one dlopen of the library every
 * relocation of every one of its ~260 libraries searches that whole list in order, and a C++
 * library late in it finds its own symbols last; opened alone, each library is first in its own
 * search list. Half of the load's CPU time goes (docs/performance.md, "Start-up"). Libraries
 * and symbols are the same either way; a name that does not load (gone after an upgrade, or a
 * library that does not list all it needs) is left to the library's own dlopen. */
static void open_dependencies(const char *path)
{
    char list[PATH_MAX + 80], name[512];
    snprintf(list, sizeof list, "%s.deps", path);
    FILE *f = fopen(list, "r");
    if (!f)
        return;
    while (fgets(name, sizeof name, f)) {
        name[strcspn(name, "\n")] = 0;
        if (*name && !dlopen(name, RTLD_LAZY | RTLD_LOCAL))
            dlerror(); /* clear it: the library's own dlopen reports what matters */
    }
    fclose(f);
}

static void load_library(void)
{
    if (&img_shim) {
        loaded = &img_shim;
        return;
    }
    char path[PATH_MAX + 64];
    if (!imglib_locate(path, sizeof path, load_err, sizeof load_err))
        return;
    dlopen_used = 1;
    open_dependencies(path);
    loaded = imglib_open(path, load_err, sizeof load_err);
}

int imglib_dlopened(void)
{
    return dlopen_used;
}

const ImgShim *imglib_get(char *err, size_t errlen)
{
    pthread_once(&load_once, load_library);
    if (!loaded)
        snprintf(err, errlen, "%s", load_err);
    return loaded;
}

/* ---- img.h through the library ------------------------------------------------------------ */

/* The library, or NULL with "path: cannot load the image library ..." in err. */
static const ImgShim *shim_for(const char *path, char *err, size_t errlen)
{
    char why[sizeof load_err];
    const ImgShim *t = imglib_get(why, sizeof why);
    if (!t)
        snprintf(err, errlen, "%s: %s", path, why);
    return t;
}

int img_read(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen)
{
    *rgb = NULL;
    /* Checked before OpenImageIO opens it: a folder, a device or a FIFO is refused by name. */
    if (infile_check(path, IMG_MAX_FILE_BYTES, "an image file", err, errlen) != 0)
        return -1;
    const ImgShim *t = shim_for(path, err, errlen);
    return t ? t->read(path, rgb, width, height, err, errlen) : -1;
}
