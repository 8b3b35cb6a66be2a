/* tools/outputs_digest.c -- one line that says what a run produced, for the same-outputs table
 * (tests/outputs/check.sh, tests/outputs/outputs.tsv).
 *
 *   outputs_digest RUN_DIR     prints: cycles instructions image report
 *   outputs_digest --text FILE prints: a hash of the file's bytes
 *
 * cycles and instructions are report.json's (instructions summed over stages; a dash where the
 * mode has none); image is a 64-bit
 * FNV-1a hash of frame.exr's float pixel bits (the EXR file itself carries a capture date); report
 * hashes every value of report.json except the "host" block (host time, threads), host times
 * elsewhere (keys "seconds" and "*_seconds"), "config_file" (a path) and the "run" block (what made
 * the run: version, commit, command line, folder, date, host name, threads; it changes with every
 * run and every commit, by design, and says nothing of the results), in a canonical form -- keys sorted, numbers printed with 17 digits --
 * so that moving the code that writes the report cannot hide a changed value, and reordering
 * keys does not count as one. cost.png's pixels are part of the report hash.
 *
 * Owns: the digest's definition. Must not: decide what a good result is (the table does).
 */
#include <cjson/cJSON.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../sim/img.h"

typedef struct Fnv { uint64_t h; } Fnv;

static void fnv_bytes(Fnv *f, const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++) {
        f->h ^= b[i];
        f->h *= 1099511628211ull;
    }
}

static void fnv_str(Fnv *f, const char *s) { fnv_bytes(f, s, strlen(s) + 1); }

static int cmp_names(const void *a, const void *b)
{
    return strcmp((*(cJSON *const *)a)->string, (*(cJSON *const *)b)->string);
}

/* Host time, wherever the report puts it ("seconds", "build_seconds", ...): never the same twice. */
static int is_host_time(const char *key)
{
    size_t n = strlen(key);
    return strcmp(key, "seconds") == 0 || (n > 8 && strcmp(key + n - 8, "_seconds") == 0);
}

/* The canonical form of a JSON value, hashed as it is walked. */
static void hash_json(Fnv *f, const cJSON *v)
{
    char buf[64];
    if (cJSON_IsObject(v)) {
        int n = cJSON_GetArraySize(v);
        cJSON **kids = malloc(sizeof *kids * (size_t)(n ? n : 1));
        if (!kids) {
            fprintf(stderr, "outputs_digest: out of memory\n");
            exit(1);
        }
        int k = 0;
        for (cJSON *c = v->child; c; c = c->next)
            if (!is_host_time(c->string)) kids[k++] = c;
        n = k;
        qsort(kids, (size_t)n, sizeof *kids, cmp_names);
        fnv_str(f, "{");
        for (int i = 0; i < n; i++) {
            fnv_str(f, kids[i]->string);
            hash_json(f, kids[i]);
        }
        fnv_str(f, "}");
        free(kids);
    } else if (cJSON_IsArray(v)) {
        fnv_str(f, "[");
        for (const cJSON *c = v->child; c; c = c->next) hash_json(f, c);
        fnv_str(f, "]");
    } else if (cJSON_IsNumber(v)) {
        snprintf(buf, sizeof buf, "%.17g", v->valuedouble);
        fnv_str(f, buf);
    } else if (cJSON_IsString(v)) {
        fnv_str(f, "s");
        fnv_str(f, v->valuestring);
    } else if (cJSON_IsBool(v)) {
        fnv_str(f, cJSON_IsTrue(v) ? "true" : "false");
    } else {
        fnv_str(f, "null");
    }
}

static char *slurp(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    if (!fp) return NULL;
    size_t cap = 1 << 16, n = 0;
    char *s = malloc(cap + 1);
    size_t got;
    while (s && (got = fread(s + n, 1, cap - n, fp)) > 0) {
        n += got;
        if (n == cap) {
            char *t = realloc(s, 2 * cap + 1);
            if (!t) { free(s); s = NULL; break; }
            s = t;
            cap *= 2;
        }
    }
    int bad = ferror(fp);
    fclose(fp);
    if (!s || bad) { free(s); return NULL; }
    s[n] = 0;
    if (len) *len = n;
    return s;
}

static int hash_pixels(Fnv *f, const char *path)
{
    float *rgb = NULL;
    int w = 0, h = 0;
    char err[512];
    if (img_read(path, &rgb, &w, &h, err, sizeof err) != 0) {
        fprintf(stderr, "outputs_digest: %s\n", err);
        return -1;
    }
    fnv_bytes(f, &w, sizeof w);
    fnv_bytes(f, &h, sizeof h);
    fnv_bytes(f, rgb, sizeof *rgb * 3 * (size_t)w * (size_t)h);
    free(rgb);
    return 0;
}

static void print_count(const cJSON *root, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(root, key);
    if (cJSON_IsNumber(v)) {
        printf("%.0f", v->valuedouble);
    } else if (cJSON_IsObject(v)) { /* per stage: the total */
        double sum = 0;
        for (const cJSON *c = v->child; c; c = c->next) sum += cJSON_IsNumber(c) ? c->valuedouble : 0;
        printf("%.0f", sum);
    } else {
        printf("-");
    }
}

static int exists(const char *path)
{
    FILE *fp = fopen(path, "rb");
    if (fp) fclose(fp);
    return fp != NULL;
}

int main(int argc, char **argv)
{
    char path[4096];
    if (argc == 3 && strcmp(argv[1], "--text") == 0) {
        size_t n = 0;
        char *s = slurp(argv[2], &n);
        if (!s) {
            fprintf(stderr, "outputs_digest: cannot read %s\n", argv[2]);
            return 1;
        }
        Fnv f = {14695981039346656037ull};
        fnv_bytes(&f, s, n);
        free(s);
        printf("%016llx\n", (unsigned long long)f.h);
        return 0;
    }
    if (argc != 2 || argv[1][0] == '-') {
        fprintf(stderr, "usage: outputs_digest RUN_DIR | outputs_digest --text FILE\n");
        return 2;
    }
    snprintf(path, sizeof path, "%s/report.json", argv[1]);
    char *text = slurp(path, NULL);
    if (!text) {
        fprintf(stderr, "outputs_digest: cannot read %s\n", path);
        return 1;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    if (!cJSON_IsObject(root)) {
        fprintf(stderr, "outputs_digest: %s is not a JSON object\n", path);
        cJSON_Delete(root);
        return 1;
    }
    cJSON_DeleteItemFromObjectCaseSensitive(root, "host");
    cJSON_DeleteItemFromObjectCaseSensitive(root, "config_file");
    cJSON_DeleteItemFromObjectCaseSensitive(root, "run");   /* provenance: see the top */

    Fnv image = {14695981039346656037ull}, report = {14695981039346656037ull};
    snprintf(path, sizeof path, "%s/frame.exr", argv[1]);
    if (hash_pixels(&image, path) != 0) {
        cJSON_Delete(root);
        return 1;
    }
    hash_json(&report, root);
    snprintf(path, sizeof path, "%s/cost.png", argv[1]);
    if (exists(path) && hash_pixels(&report, path) != 0) {
        cJSON_Delete(root);
        return 1;
    }
    print_count(root, "cycles");
    printf(" ");
    print_count(root, "instructions");
    printf(" %016llx %016llx\n", (unsigned long long)image.h, (unsigned long long)report.h);
    cJSON_Delete(root);
    return 0;
}
