/* sim/provenance.c -- what made a run (sim/provenance.h): recorded once at the start of main(),
 * read by the reports.
 *
 * Owns: the record and the shell quoting of the command line. Must not: write any file, or read
 * anything but the process's own facts (argv, working folder, clock, host name).
 */
#include "provenance.h"

#include <cjson/cJSON.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "../host/version.h"

/* One record per process: main() fills it before any thread starts; the reports only read it. */
static struct {
    int argc;
    char **argv;        /* copies */
    char *command;      /* the quoted line */
    char cwd[PATH_MAX];
    char date[40];
    char host[256];
    int have_date, have_host;
} prov;

size_t prov_quote(const char *arg, char *buf, size_t len)
{
    static const char safe[] = "_@%+=:,./-";
    int plain = arg[0] != '\0';
    for (const char *p = arg; *p && plain; p++)
        plain = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') || strchr(safe, *p);
    size_t n = 0;
#define PUT(ch) do { if (n + 1 < len) buf[n] = (ch); n++; } while (0)
    if (plain) {
        for (const char *p = arg; *p; p++)
            PUT(*p);
    } else {
        PUT('\'');
        for (const char *p = arg; *p; p++) {
            if (*p == '\'') {   /* close the quotes, an escaped quote, open them again */
                PUT('\'');
                PUT('\\');
                PUT('\'');
            }
            PUT(*p);
        }
        PUT('\'');
    }
#undef PUT
    if (len)
        buf[n < len ? n : len - 1] = '\0';
    return n;
}

/* The quoted command line of argv, allocated; NULL when out of memory. */
static char *quote_all(int argc, char **argv)
{
    size_t total = 1;
    for (int i = 0; i < argc; i++)
        total += prov_quote(argv[i], NULL, 0) + 1;
    char *s = malloc(total), *p = s;
    if (!s)
        return NULL;
    *p = '\0';
    for (int i = 0; i < argc; i++) {
        if (i)
            *p++ = ' ';
        p += prov_quote(argv[i], p, total - (size_t)(p - s));
    }
    return s;
}

static void free_record(void)
{
    for (int i = 0; i < prov.argc; i++)
        free(prov.argv[i]);
    free(prov.argv);
    free(prov.command);
    prov.argv = NULL;
    prov.command = NULL;
    prov.argc = 0;
}

/* t as ISO 8601 in local time with the offset written "+01:00" (strftime's %z has no colon). */
static void iso_date(time_t t, char *buf, size_t len)
{
    struct tm tm;
    char z[16];
    tzset();   /* (localtime_r need not read TZ again) */
    if (!localtime_r(&t, &tm) || strftime(buf, len, "%Y-%m-%dT%H:%M:%S", &tm) == 0 ||
        strftime(z, sizeof z, "%z", &tm) != 5) {
        snprintf(buf, len, "unknown");
        return;
    }
    size_t n = strlen(buf);
    snprintf(buf + n, len - n, "%.3s:%.2s", z, z + 3);
}

void prov_set_command(int argc, char **argv)
{
    free_record();
    prov.argv = calloc((size_t)(argc > 0 ? argc : 1), sizeof *prov.argv);
    for (int i = 0; prov.argv && i < argc; i++) {
        prov.argv[i] = strdup(argv[i]);
        if (!prov.argv[i]) {   /* out of memory: keep what was copied */
            prov.argc = i;
            break;
        }
        prov.argc = i + 1;
    }
    prov.command = quote_all(prov.argc, prov.argv);
    if (!getcwd(prov.cwd, sizeof prov.cwd))
        prov.cwd[0] = '\0';
    iso_date(time(NULL), prov.date, sizeof prov.date);
    prov.have_date = 1;
}

int prov_argc(void) { return prov.argc; }

const char *prov_argv(int i) { return i >= 0 && i < prov.argc ? prov.argv[i] : ""; }

const char *prov_command(void) { return prov.command ? prov.command : ""; }

const char *prov_cwd(void)
{
    if (!prov.cwd[0] && !getcwd(prov.cwd, sizeof prov.cwd))
        prov.cwd[0] = '\0';
    return prov.cwd;
}

const char *prov_date(void)
{
    if (!prov.have_date) {
        iso_date(time(NULL), prov.date, sizeof prov.date);
        prov.have_date = 1;
    }
    return prov.date;
}

const char *prov_host(void)
{
    if (!prov.have_host) {
        if (gethostname(prov.host, sizeof prov.host) != 0)
            prov.host[0] = '\0';
        prov.host[sizeof prov.host - 1] = '\0';
        prov.have_host = 1;
    }
    return prov.host;
}

int prov_json(cJSON *o)
{
    int ok = cJSON_AddStringToObject(o, "version", version_string()) && cJSON_AddStringToObject(o, "commit", version_commit()) &&
             cJSON_AddStringToObject(o, "command", prov_command());
    cJSON *a = ok ? cJSON_AddArrayToObject(o, "argv") : NULL;
    for (int i = 0; a && i < prov.argc; i++)
        if (!cJSON_AddItemToArray(a, cJSON_CreateString(prov.argv[i])))
            a = NULL;
    ok = a && cJSON_AddStringToObject(o, "cwd", prov_cwd()) && cJSON_AddStringToObject(o, "date", prov_date()) &&
         cJSON_AddStringToObject(o, "host", prov_host());
    return ok ? 0 : -1;
}
