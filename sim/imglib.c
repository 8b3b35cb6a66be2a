/* sim/imglib.c -- loads the image library libsfsim-img.so on demand (sim/imglib.h) and
 * implements img.h's file functions and heatmap.h through its table (sim/imgshim.h).
 *
 * Owns: the library's search order, the one load per process (pthread_once, so a background
 * load and a first image call on the main thread cannot both load it), the loader thread's
 * join at exit. Must not: touch pixels, or exit (the callers map a failure to EXIT_IO).
 */
#include "imglib.h"

#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "heatmap.h"
#include "img.h"
#include "outfile.h"

/* Defined when the binary links the library's objects in (tests and tools: sim/imgshim.h). */
extern const ImgShim img_shim __attribute__((weak));

static pthread_once_t load_once = PTHREAD_ONCE_INIT;
static const ImgShim *loaded;
static char load_err[PATH_MAX + 1024];
static pthread_t loader;
static int loader_running, preloaded;
/* Set before the first dlopen of the library or its dependencies (on either thread). */
static atomic_int dlopen_used;

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
    atomic_store(&dlopen_used, 1);
    open_dependencies(path);
    loaded = imglib_open(path, load_err, sizeof load_err);
}

static void *load_in_background(void *arg)
{
    (void)arg;
    pthread_once(&load_once, load_library);
    return NULL;
}

static void join_loader(void)
{
    if (loader_running) {
        pthread_join(loader, NULL);
        loader_running = 0;
    }
}

int imglib_preload(char *err, size_t errlen)
{
    if (preloaded || &img_shim)
        return 0;
    preloaded = 1;
    char path[PATH_MAX + 64];
    if (!imglib_locate(path, sizeof path, err, errlen))
        return -1;
    if (access(path, R_OK) != 0) {
        snprintf(err, errlen, "cannot load the image library %s: %s (make builds it; make install puts it in "
                              "PREFIX/lib/sfsim; SFSIM_IMG_LIB names another)", path, strerror(errno));
        return -1;
    }
    /* Joined at exit, so that exit never runs while the library's constructors do. Without the
     * thread (or the handler) the first image call loads the library itself. The thread blocks
     * every signal, so ^C and the held signals of sim/outfile.c reach the main thread as before. */
    atomic_store(&dlopen_used, 1);
    sigset_t all, old;
    sigfillset(&all);
    pthread_sigmask(SIG_SETMASK, &all, &old);
    if (atexit(join_loader) == 0 && pthread_create(&loader, NULL, load_in_background, NULL) == 0)
        loader_running = 1;
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return 0;
}

int imglib_dlopened(void)
{
    return atomic_load(&dlopen_used);
}

const ImgShim *imglib_get(char *err, size_t errlen)
{
    pthread_once(&load_once, load_library);
    if (!loaded)
        snprintf(err, errlen, "%s", load_err);
    return loaded;
}

/* ---- img.h and heatmap.h through the library ------------------------------------------------ */

static int sink_write(void *ctx, const char *path, const void *bytes, size_t n, char *err, size_t errlen)
{
    return outfile_write_file(ctx, path, bytes, n, err, errlen);
}

/* The library, or NULL with "path: cannot load the image library ..." in err. */
static const ImgShim *shim_for(const char *path, char *err, size_t errlen)
{
    char why[sizeof load_err];
    const ImgShim *t = imglib_get(why, sizeof why);
    if (!t)
        snprintf(err, errlen, "%s: %s", path, why);
    return t;
}

int img_write_linear(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                     size_t errlen)
{
    const ImgShim *t = shim_for(path, err, errlen);
    ImgSink sink = {sink_write, set};
    return t ? t->write_linear(&sink, path, rgb, width, height, err, errlen) : -1;
}

int img_write_display(OutSet *set, const char *path, const float *rgb, int width, int height, float exposure,
                      char *err, size_t errlen)
{
    const ImgShim *t = shim_for(path, err, errlen);
    ImgSink sink = {sink_write, set};
    return t ? t->write_display(&sink, path, rgb, width, height, exposure, err, errlen) : -1;
}

int img_write_rgb8(OutSet *set, const char *path, const float *rgb, int width, int height, char *err,
                   size_t errlen)
{
    const ImgShim *t = shim_for(path, err, errlen);
    ImgSink sink = {sink_write, set};
    return t ? t->write_rgb8(&sink, path, rgb, width, height, err, errlen) : -1;
}

int img_read(const char *path, float **rgb, int *width, int *height, char *err, size_t errlen)
{
    *rgb = NULL;
    const ImgShim *t = shim_for(path, err, errlen);
    return t ? t->read(path, rgb, width, height, err, errlen) : -1;
}

int heatmap_write(OutSet *set, const char *path, const double *values, int width, int height, const char *title,
                  const char *unit, char *err, size_t errlen)
{
    const ImgShim *t = shim_for(path, err, errlen);
    ImgSink sink = {sink_write, set};
    return t ? t->heatmap_write(&sink, path, values, width, height, title, unit, err, errlen) : -1;
}

void heatmap_set_font(const char *font_path)
{
    char err[sizeof load_err];
    const ImgShim *t = imglib_get(err, sizeof err);
    if (t)
        t->heatmap_set_font(font_path);
}
