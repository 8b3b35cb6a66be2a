/* sim/datadir.c -- finds sfsim's own files relative to its binary (sim/datadir.h).
 *
 * Owns: the search order for the data folder. Must not: look at the working directory, so that
 * the same command gives the same result from any folder.
 */
#include "datadir.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int holds_kernel(const char *dir)
{
    char p[PATH_MAX + 64];
    struct stat st;
    if ((size_t)snprintf(p, sizeof p, "%.*s/%s", PATH_MAX, dir, DATADIR_KERNEL) >= sizeof p)
        return 0;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

const char *datadir_get(char *buf, size_t len, char *err, size_t errlen)
{
    const char *env = getenv("SFSIM_DATA_DIR");
    if (env && *env) {
        if (!holds_kernel(env)) {
            snprintf(err, errlen, "SFSIM_DATA_DIR=%s: no %s there", env, DATADIR_KERNEL);
            return NULL;
        }
        snprintf(buf, len, "%s", env);
        return buf;
    }
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        snprintf(err, errlen, "cannot find this program's folder (/proc/self/exe: %s); set SFSIM_DATA_DIR",
                 strerror(errno));
        return NULL;
    }
    exe[n] = 0;
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = 0;
    /* exe is now the binary's folder: bin/ of a build tree or of an installation */
    char cand[2][PATH_MAX + 32];
    snprintf(cand[0], sizeof cand[0], "%.*s/..", PATH_MAX - 16, exe);
    snprintf(cand[1], sizeof cand[1], "%.*s/../share/sfsim", PATH_MAX - 16, exe);
    for (int i = 0; i < 2; i++) {
        if (!holds_kernel(cand[i]))
            continue;
        char real[PATH_MAX];
        snprintf(buf, len, "%s", realpath(cand[i], real) ? real : cand[i]);
        return buf;
    }
    snprintf(err, errlen, "sfsim's data files are missing: no %s in %s/.. or %s/../share/sfsim (reinstall, or set SFSIM_DATA_DIR)",
             DATADIR_KERNEL, exe, exe);
    return NULL;
}

const char *datadir_path(const char *rel, char *buf, size_t len, char *err, size_t errlen)
{
    char dir[PATH_MAX];
    if (!datadir_get(dir, sizeof dir, err, errlen))
        return NULL;
    if ((size_t)snprintf(buf, len, "%s/%s", dir, rel) >= len) {
        snprintf(err, errlen, "%s/%s: path too long", dir, rel);
        return NULL;
    }
    return buf;
}
