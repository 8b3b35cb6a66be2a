/* sim/cli/opts.c -- getopt_long's loop with sfsim's messages, and the config options (opts.h). */
#include "opts.h"

#include <stdlib.h>
#include <string.h>

#include "../../host/version.h"
#include "../util.h"

int cli_first_operand(void)
{
    return optind;
}

/* The option as the user wrote it, for a message: the argument getopt just looked at. */
static const char *written(const CliParse *p)
{
    int i = optind - 1;
    return i >= 1 && i < p->argc ? p->argv[i] : "?";
}

int cli_next(CliParse *p, const char **arg)
{
    char shorts[128];
    /* ':' first: a missing value is told apart from an unknown option; errors are ours. */
    snprintf(shorts, sizeof shorts, ":%s", p->shorts);
    if (!p->started) {
        optind = 0; /* glibc: start over, with its permutation state reset */
        p->started = 1;
    }
    opterr = 0;
    *arg = NULL;
    int code = getopt_long(p->argc, p->argv, shorts, p->longs, NULL);
    if (code == -1)
        return 0;
    if (code == ':') {
        fprintf(stderr, "%s: option '%s' needs a value (sfsim help %s)\n", p->cmd, written(p), p->topic);
        return -1;
    }
    if (code == '?') {
        const char *w = written(p);
        if (strncmp(w, "--", 2) != 0)
            fprintf(stderr, "%s: unknown option '-%c' (sfsim help %s)\n", p->cmd, optopt ? optopt : '?', p->topic);
        else if (optopt && strchr(w, '='))
            fprintf(stderr, "%s: option '%.*s' takes no value (sfsim help %s)\n", p->cmd, (int)(strchr(w, '=') - w), w,
                    p->topic);
        else
            fprintf(stderr, "%s: unknown or ambiguous option '%s' (sfsim help %s)\n", p->cmd, w, p->topic);
        return -1;
    }
    *arg = optarg;
    return code;
}

int cli_common(const CliParse *p, int code, void (*usage)(FILE *))
{
    if (code == CLI_HELP) {
        usage(stdout);
        return 1;
    }
    if (code == CLI_VERSION) {
        printf("sfsim %s (commit %s)\n", version_string(), version_commit());
        (void)p;
        return 1;
    }
    return 0;
}

int cli_int(const CliParse *p, const char *opt, const char *s, long long lo, long long hi, long long *out)
{
    if (util_parse_int(s, lo, hi, out)) {
        fprintf(stderr, "%s: %s %s: expected an integer in %lld..%lld\n", p->cmd, opt, s, lo, hi);
        return -1;
    }
    return 0;
}

int cli_config_set(CliConfig *c, const char *set)
{
    if (c->nsets == c->cap) {
        int cap = c->cap ? 2 * c->cap : 16;
        const char **n = realloc(c->sets, (size_t)cap * sizeof *n);
        if (!n) {
            fprintf(stderr, "sfsim: out of memory\n");
            return -1;
        }
        c->sets = n;
        c->cap = cap;
    }
    c->sets[c->nsets++] = set;
    return 0;
}

int cli_config_build(const CliConfig *c, CfgMachine *cfg)
{
    CfgErrors errs = {0};
    cfg_defaults(cfg);
    if (c->path)
        cfg_load(cfg, c->path, &errs);
    for (int i = 0; i < c->nsets; i++)
        cfg_set(cfg, c->sets[i], &errs);
    if (!errs.count)
        cfg_check(cfg, &errs);
    if (errs.count) {
        fprintf(stderr, "%s", errs.text);
        fprintf(stderr, "sfsim: %d configuration error%s\n", errs.count, errs.count == 1 ? "" : "s");
    }
    int n = errs.count;
    cfg_errors_free(&errs);
    return n ? -1 : 0;
}

void cli_config_free(CliConfig *c)
{
    free(c->sets);
    c->sets = NULL;
    c->nsets = c->cap = 0;
}
