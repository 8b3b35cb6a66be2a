/* sim/sweep/plan.c -- the plan of a sweep, sweep.json (the manifest): built from the arguments,
 * taken apart, compared with the one a folder holds, and which of its points still run.
 *
 * Owns: the manifest's format (SWEEP_MANIFEST_FORMAT: config, sweep file and their contents,
 * scene, mode, sample, --sets, the points), the point and key order the CSV and folders use,
 * what makes two sweeps differ, and the resume decision (done and failed points are kept, failed
 * ones run again with --retry-failed). Must not: parse sweep files (sweepfile.c), write into the
 * sweep folder (folder.c), or run anything.
 */
#include "sweep_int.h"

#include <errno.h>

#include "../config.h"
#include "../ini.h"
#include "../../scenes/scene_file.h"

void sweep_plan_free(SweepPlan *pl)
{
    for (int i = 0; i < pl->npoints; i++) {
        free(pl->points[i].key);
        free(pl->points[i].val);
    }
    free(pl->points);
    free(pl->keys);
    free(pl->sets);
    cJSON_Delete(pl->json);
    memset(pl, 0, sizeof *pl);
}

static const char *json_str(const cJSON *o, const char *name, int nullable, int *bad)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, name);
    if (cJSON_IsString(it))
        return it->valuestring;
    if (!(nullable && (!it || cJSON_IsNull(it))))
        *bad = 1;
    return NULL;
}

/* Take the manifest (owned from here on) apart; -1 with err when it is not one. */
int sweep_plan_load(cJSON *json, SweepPlan *pl, char *err, size_t errlen)
{
    memset(pl, 0, sizeof *pl);
    pl->json = json;
    int bad = 0;
    const char *format = json_str(json, "format", 0, &bad);
    if (bad || strcmp(format, SWEEP_MANIFEST_FORMAT) != 0) {
        snprintf(err, errlen, "not a sweep manifest of this sfsim (its \"format\" is not \"%s\")",
                 SWEEP_MANIFEST_FORMAT);
        return -1;
    }
    pl->config = json_str(json, "config", 1, &bad);
    pl->config_text = json_str(json, "config_contents", 1, &bad);
    pl->sweep = json_str(json, "sweep_file", 0, &bad);
    pl->sweep_text = json_str(json, "sweep_contents", 0, &bad);
    pl->scene = json_str(json, "scene", 0, &bad);
    pl->mode = json_str(json, "mode", 0, &bad);
    pl->sample = json_str(json, "sample", 1, &bad);
    const char *kind = json_str(json, "kind", 0, &bad);
    const cJSON *sets = cJSON_GetObjectItemCaseSensitive(json, "sets");
    const cJSON *points = cJSON_GetObjectItemCaseSensitive(json, "points");
    if (bad || !cJSON_IsArray(sets) || !cJSON_IsArray(points) || cJSON_GetArraySize(points) < 1 ||
        cJSON_GetArraySize(points) > SWEEP_MAX_POINTS || (strcmp(kind, "cross") && strcmp(kind, "points"))) {
        snprintf(err, errlen, "a field is missing or has the wrong type");
        return -1;
    }
    pl->explicit_points = !strcmp(kind, "points");
    pl->sets = xrealloc(NULL, (size_t)cJSON_GetArraySize(sets) * sizeof *pl->sets);
    const cJSON *it;
    cJSON_ArrayForEach(it, sets)
    {
        if (!cJSON_IsString(it)) {
            snprintf(err, errlen, "\"sets\" holds a non-string");
            return -1;
        }
        pl->sets[pl->nsets++] = it->valuestring;
    }
    int np = cJSON_GetArraySize(points);
    pl->points = xrealloc(NULL, (size_t)np * sizeof *pl->points);
    memset(pl->points, 0, (size_t)np * sizeof *pl->points);
    int kcap = 0;
    cJSON_ArrayForEach(it, points)
    {
        SweepPoint *p = &pl->points[pl->npoints++];
        const cJSON *set = cJSON_GetObjectItemCaseSensitive(it, "settings");
        p->name = json_str(it, "name", 1, &bad);
        if (bad || !cJSON_IsObject(set) || (pl->explicit_points && !p->name)) {
            snprintf(err, errlen, "point %d is malformed", pl->npoints - 1);
            return -1;
        }
        int n = cJSON_GetArraySize(set);
        p->key = xrealloc(NULL, (size_t)n * sizeof *p->key);
        p->val = xrealloc(NULL, (size_t)n * sizeof *p->val);
        const cJSON *kv;
        cJSON_ArrayForEach(kv, set)
        {
            if (!cJSON_IsString(kv) || !kv->string) {
                snprintf(err, errlen, "point %d: a setting is not a string", pl->npoints - 1);
                return -1;
            }
            p->key[p->n] = kv->string;
            p->val[p->n++] = kv->valuestring;
            int known = 0;
            for (int k = 0; k < pl->nkeys && !known; k++)
                known = !strcmp(pl->keys[k], kv->string);
            if (!known) {
                if (pl->nkeys == kcap) {
                    kcap = kcap ? 2 * kcap : 8;
                    pl->keys = xrealloc(pl->keys, (size_t)kcap * sizeof *pl->keys);
                }
                pl->keys[pl->nkeys++] = kv->string;
            }
        }
    }
    pl->digits = 3;
    for (int m = 1000; m <= pl->npoints - 1; m *= 10)
        pl->digits++;
    return 0;
}

/* The value point p gives key k, or NULL. */
const char *sweep_plan_value(const SweepPlan *pl, int p, const char *key)
{
    for (int i = 0; i < pl->points[p].n; i++)
        if (!strcmp(pl->points[p].key[i], key))
            return pl->points[p].val[i];
    return NULL;
}

/* ---- building the manifest from the arguments ---------------------------------------------- */

/* Read and check everything the arguments name, and build the manifest; NULL after printing
 * every problem. */
cJSON *sweep_manifest_build(const SweepArgs *a)
{
    SweepErrs errs = {0};
    char err[PATH_MAX + 256];
    char *config = NULL, *config_text = NULL, *sweep = NULL, *sweep_text = NULL, *scene = NULL;
    size_t config_len = 0, sweep_len = 0;
    cJSON *points = NULL, *m = NULL;
    int explicit_points = 0;

    /* The config and the sweep file are INI files: read as sim/ini.c reads every one (a regular
     * file of at most 16 MiB), and their text kept in the manifest. */
    if (a->config) {
        if (inifile_read(a->config, &config_text, &config_len, err, sizeof err))
            sweep_err_add(&errs, "%s", err);
        else if (!(config = realpath(a->config, NULL)))
            sweep_err_add(&errs, "%s: cannot open: %s", a->config, strerror(errno));
        else {
            CfgMachine cfg;
            CfgErrors ce = {0};
            cfg_defaults(&cfg);
            cfg_load_text(&cfg, config_text, config_len, a->config, &ce);
            if (ce.count)
                util_buf_puts(&errs.text, ce.text);
            errs.count += ce.count;
            cfg_errors_free(&ce);
        }
    }
    for (int i = 0; i < a->nsets; i++) {
        const char *eq = strchr(a->sets[i], '=');
        int unknown;
        char msg[512];
        if (!eq || eq == a->sets[i]) {
            sweep_err_add(&errs, "--set %s: expected section.key=value", a->sets[i]);
            continue;
        }
        char *key = xstrndup(a->sets[i], (size_t)(eq - a->sets[i]));
        if (sweep_value_check(key, eq + 1, &unknown, msg, sizeof msg))
            sweep_err_add(&errs, "--set %s: %s", a->sets[i], msg);
        free(key);
    }
    scene = realpath(a->scene, NULL);
    if (!scene)
        sweep_err_add(&errs, "scene %s: cannot open: %s", a->scene, strerror(errno));
    else if (scene_file_check(a->scene, err, sizeof err)) /* its mesh files too, before any point */
        sweep_err_add(&errs, "%s", err);
    if (inifile_read(a->sweep, &sweep_text, &sweep_len, err, sizeof err))
        sweep_err_add(&errs, "%s", err);
    else if (!(sweep = realpath(a->sweep, NULL)))
        sweep_err_add(&errs, "%s: cannot open: %s", a->sweep, strerror(errno));
    else
        points = sweep_file_points(a->sweep, sweep_text, sweep_len, &errs, &explicit_points);
    if (errs.count) {
        fputs(sweep_buf_text(&errs.text), stderr);
        fprintf(stderr, "sfsim sweep: %d error%s; nothing was run\n", errs.count, errs.count == 1 ? "" : "s");
        cJSON_Delete(points);
        goto out;
    }
    /* A --set of a key the sweep also sets is overridden by each point: say so. */
    for (int i = 0; i < a->nsets; i++) {
        size_t kl = strcspn(a->sets[i], "=");
        const cJSON *p;
        int hit = 0;
        cJSON_ArrayForEach(p, points)
        {
            const cJSON *kv;
            cJSON_ArrayForEach(kv, cJSON_GetObjectItemCaseSensitive(p, "settings"))
                hit |= strlen(kv->string) == kl && !strncmp(kv->string, a->sets[i], kl);
        }
        if (hit)
            fprintf(stderr, "sfsim sweep: note: --set %s: the sweep file sets %.*s too; its value wins\n", a->sets[i],
                    (int)kl, a->sets[i]);
    }
    m = cJSON_CreateObject();
    cJSON_AddStringToObject(m, "format", SWEEP_MANIFEST_FORMAT);
    if (config) {
        cJSON_AddStringToObject(m, "config", config);
        cJSON_AddStringToObject(m, "config_contents", config_text);
    } else {
        cJSON_AddNullToObject(m, "config");
        cJSON_AddNullToObject(m, "config_contents");
    }
    cJSON_AddStringToObject(m, "sweep_file", sweep);
    cJSON_AddStringToObject(m, "sweep_contents", sweep_text);
    cJSON_AddStringToObject(m, "scene", scene);
    cJSON_AddStringToObject(m, "mode", a->mode);
    if (a->sample)
        cJSON_AddStringToObject(m, "sample", a->sample);
    else
        cJSON_AddNullToObject(m, "sample");
    cJSON *sets = cJSON_AddArrayToObject(m, "sets");
    for (int i = 0; i < a->nsets; i++)
        cJSON_AddItemToArray(sets, cJSON_CreateString(a->sets[i]));
    cJSON_AddStringToObject(m, "kind", explicit_points ? "points" : "cross");
    cJSON_AddItemToObject(m, "points", points);
out:
    util_buf_free(&errs.text);
    free(config);
    free(config_text);
    free(sweep);
    free(sweep_text);
    free(scene);
    return m;
}

static const char *or_none(const char *s, const char *none)
{
    return s ? s : none;
}

/* What differs between the sweep in a folder (old) and the one the arguments define, a line each. */
void sweep_plan_diff(const SweepPlan *old, const SweepPlan *cur, UtilBuf *out)
{
    if (!sweep_str_eq(old->config, cur->config))
        util_buf_printf(out, "  -c: %s there, %s here\n", or_none(old->config, "none (the built-in machine)"),
                        or_none(cur->config, "none (the built-in machine)"));
    else if (!sweep_str_eq(old->config_text, cur->config_text))
        util_buf_printf(out, "  the config file %s: its contents changed since the sweep began\n", cur->config);
    if (!sweep_str_eq(old->sweep, cur->sweep))
        util_buf_printf(out, "  --sweep: %s there, %s here\n", old->sweep, cur->sweep);
    else if (!sweep_str_eq(old->sweep_text, cur->sweep_text))
        util_buf_printf(out, "  the sweep file %s: its contents changed since the sweep began\n", cur->sweep);
    if (!sweep_str_eq(old->scene, cur->scene))
        util_buf_printf(out, "  -s: %s there, %s here\n", old->scene, cur->scene);
    if (!sweep_str_eq(old->mode, cur->mode))
        util_buf_printf(out, "  --mode: %s there, %s here\n", old->mode, cur->mode);
    if (!sweep_str_eq(old->sample, cur->sample))
        util_buf_printf(out, "  --sample: %s there, %s here\n", or_none(old->sample, "none"),
                        or_none(cur->sample, "none"));
    int same_sets = old->nsets == cur->nsets;
    for (int i = 0; same_sets && i < old->nsets; i++)
        same_sets = !strcmp(old->sets[i], cur->sets[i]);
    if (!same_sets) {
        util_buf_puts(out, "  --set:");
        for (int i = 0; i < old->nsets; i++)
            util_buf_printf(out, " %s", old->sets[i]);
        util_buf_printf(out, "%s there;", old->nsets ? "" : " none");
        for (int i = 0; i < cur->nsets; i++)
            util_buf_printf(out, " %s", cur->sets[i]);
        util_buf_printf(out, "%s here\n", cur->nsets ? "" : " none");
    }
    if (!out->len && !cJSON_Compare(cJSON_GetObjectItemCaseSensitive(old->json, "points"),
                                    cJSON_GetObjectItemCaseSensitive(cur->json, "points"), 1))
        util_buf_puts(out, "  the points (the sweep was begun by another version of sfsim)\n");
}

int sweep_plan_todo(const SweepPlan *pl, const char *dir, int retry, int *todo, SweepTally *t)
{
    int ntodo = 0;
    for (int k = 0; k < pl->npoints; k++) {
        double secs;
        int s = sweep_point_state(pl, dir, k, &secs, NULL);
        if (s == SWEEP_DONE || (s == SWEEP_FAILED && !retry)) {
            t->done += s == SWEEP_DONE;
            t->failed += s == SWEEP_FAILED;
            if (secs > 0) {
                t->secs_sum += secs;
                t->secs_n++;
            }
        } else {
            todo[ntodo++] = k;
        }
    }
    return ntodo;
}
