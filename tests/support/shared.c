/* tests/support/shared.c -- is the test data beside the repository? (shared.h) */
#include "shared.h"

#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

int shared_file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

int shared_present(void)
{
    return shared_file_exists("../shared/scenes/README.md");
}

const char *shared_scene_need(const char *scene_path, char *buf, size_t len)
{
    const char *dot = strrchr(scene_path, '.');
    if (!dot || strcmp(dot, ".ini") != 0) /* a glTF file named directly */
        return strstr(scene_path, "shared/") ? snprintf(buf, len, "%s", scene_path), buf : NULL;
    FILE *f = fopen(scene_path, "r");
    if (!f)
        return NULL; /* the test's own loader reports it */
    char line[4096];
    const char *need = NULL;
    while (!need && fgets(line, sizeof line, f)) {
        char *p = line + strspn(line, " \t");
        if (strncmp(p, "gltf", 4) != 0)
            continue;
        p += 4 + strspn(p + 4, " \t");
        if (*p != '=')
            continue;
        p += 1 + strspn(p + 1, " \t");
        p[strcspn(p, "\r\n")] = 0;
        if (!strstr(p, "shared/"))
            break;
        const char *slash = strrchr(scene_path, '/');
        int dirlen = slash ? (int)(slash - scene_path) : 1;
        snprintf(buf, len, "%.*s/%s", dirlen, slash ? scene_path : ".", p);
        need = buf;
    }
    fclose(f);
    return need;
}
