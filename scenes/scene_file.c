/* scenes/scene_file.c -- scene.ini: glTF files (placed with transforms) plus what glTF lacks:
 * camera, render settings, lights, spheres, material overrides (docs/scenes.md).
 *
 * Owns: reading and checking scene.ini. Every problem is reported as "FILE:LINE: key
 * 'section.key': message" (or "section [name]: message"), all of them in one run. Must not:
 * finish the scene (scene_finish) or read glTF itself (scenes/gltf_*.cpp).
 *
 * The syntax (comments, sections, keys, a section or key given twice, a UTF-8 BOM, size and line
 * limits) is sim/ini.c's, the INI reader of every sfsim file (docs/ini.md); this file knows the
 * sections and keys of a scene.
 */
#include "scene_file.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <strings.h>
#include <sys/stat.h>

#include "../sim/ini.h"
#include "gltf.h"
#include "obj.h"

typedef IniEntry Entry;

typedef struct Diag {
    int line;   /* the messages come out in line order, */
    size_t seq; /* and in the order found within a line */
    char *text;
} Diag;

typedef struct Parse {
    const char *path;
    IniFile ini; /* the sections and keys, each once */
    Diag *d;
    size_t nd, capd;
    int nerr;
} Parse;

static void diag_keep(Parse *p, int line, char *text);
static void diag(Parse *p, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void diag(Parse *p, int line, const char *fmt, ...)
{
    char *msg = NULL, *text = NULL;
    va_list ap;
    va_start(ap, fmt);
    int n = vasprintf(&msg, fmt, ap);
    va_end(ap);
    p->nerr++;
    if (n >= 0)
        n = line > 0 ? asprintf(&text, "%s:%d: %s", p->path, line, msg) : asprintf(&text, "%s: %s", p->path, msg);
    free(msg);
    if (n < 0)
        return; /* out of memory: counted, not shown */
    diag_keep(p, line, text);
}

/* Keep a message made elsewhere (the INI reader's), already "FILE:LINE: ...". */
static void diag_keep(Parse *p, int line, char *text)
{
    if (p->nd == p->capd) {
        size_t cap = p->capd ? 2 * p->capd : 16;
        Diag *d = realloc(p->d, cap * sizeof *d);
        if (!d) {
            free(text);
            return;
        }
        p->d = d;
        p->capd = cap;
    }
    p->d[p->nd].line = line;
    p->d[p->nd].seq = p->nd;
    p->d[p->nd].text = text;
    p->nd++;
}

static int by_line(const void *a, const void *b)
{
    const Diag *x = a, *y = b;
    if (x->line != y->line)
        return x->line < y->line ? -1 : 1;
    return x->seq < y->seq ? -1 : x->seq > y->seq;
}

/* All messages, in line order, one per line; what does not fit is counted in a last line. */
static void write_diags(Parse *p, char *err, size_t errlen)
{
    size_t used = 0;
    int shown = 0;
    if (errlen)
        err[0] = 0;
    if (p->nd > 1)
        qsort(p->d, p->nd, sizeof *p->d, by_line);
    for (size_t i = 0; i < p->nd; i++) {
        size_t len = strlen(p->d[i].text);
        if (used + len + 1 + 40 < errlen) {
            if (used)
                err[used++] = '\n';
            memcpy(err + used, p->d[i].text, len + 1);
            used += len;
            shown++;
        }
        free(p->d[i].text);
    }
    free(p->d);
    if (shown < p->nerr && used < errlen)
        snprintf(err + used, errlen - used, "%s... and %d more error%s", used ? "\n" : "", p->nerr - shown,
                 p->nerr - shown == 1 ? "" : "s");
}

/* ---- values ---------------------------------------------------------------------------------- */

static void bad_value(Parse *p, const Entry *e, const char *what)
{
    diag(p, e->line, "key '%s.%s': %s, got '%s'", e->section, e->key, what, e->value);
}

/* n finite numbers separated by blanks. */
static int parse_floats(Parse *p, const Entry *e, float *out, int n)
{
    const char *s = e->value;
    float v[4];
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        double d = strtod(s, &end);
        if (end == s || errno || !isfinite(d) || fabs(d) > 3.4e38 || (*end && !isspace((unsigned char)*end))) {
            bad_value(p, e, n == 1 ? "expected a number" : n == 2 ? "expected 2 numbers" : "expected 3 numbers");
            return -1;
        }
        v[i] = (float)d;
        s = end;
    }
    while (isspace((unsigned char)*s))
        s++;
    if (*s) {
        bad_value(p, e, n == 1 ? "expected a number" : n == 2 ? "expected 2 numbers" : "expected 3 numbers");
        return -1;
    }
    memcpy(out, v, sizeof(float) * (size_t)n);
    return 0;
}

static int count_words(const char *s)
{
    int n = 0;
    while (*s) {
        while (isspace((unsigned char)*s))
            s++;
        if (!*s)
            break;
        n++;
        while (*s && !isspace((unsigned char)*s))
            s++;
    }
    return n;
}

static int parse_range(Parse *p, const Entry *e, float lo, float hi, float *out)
{
    float v;
    if (parse_floats(p, e, &v, 1) != 0)
        return -1;
    if (!(v >= lo && v <= hi)) {
        char what[96];
        snprintf(what, sizeof what, "expected a number from %g to %g", lo, hi);
        bad_value(p, e, what);
        return -1;
    }
    *out = v;
    return 0;
}

/* A number > 0 (positive) or >= 0. */
static int parse_sign(Parse *p, const Entry *e, int positive, float *out)
{
    float v;
    if (parse_floats(p, e, &v, 1) != 0)
        return -1;
    if (positive ? !(v > 0.0f) : !(v >= 0.0f)) {
        bad_value(p, e, positive ? "expected a positive number" : "expected a number >= 0");
        return -1;
    }
    *out = v;
    return 0;
}

static int parse_nonneg3(Parse *p, const Entry *e, float *out)
{
    float v[3];
    if (parse_floats(p, e, v, 3) != 0)
        return -1;
    if (v[0] < 0.0f || v[1] < 0.0f || v[2] < 0.0f) {
        bad_value(p, e, "expected 3 numbers, none negative");
        return -1;
    }
    memcpy(out, v, sizeof v);
    return 0;
}

static int parse_int(Parse *p, const Entry *e, long lo, long hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(e->value, &end, 10);
    while (isspace((unsigned char)*end))
        end++;
    if (end == e->value || *end || errno) {
        bad_value(p, e, "expected an integer");
        return -1;
    }
    if (v < lo || v > hi) {
        char what[96];
        snprintf(what, sizeof what, "expected an integer from %ld to %ld", lo, hi);
        bad_value(p, e, what);
        return -1;
    }
    *out = (int)v;
    return 0;
}

/* n values of kind k (scene.h's limits of scene values), reported at entry e, or at the section's
 * line when e is NULL: "FILE:LINE: key 'light.a.intensity': color x intensity is 1e+30, beyond
 * ...". 0, or -1. */
static int limit_check(Parse *p, const Entry *e, const char *section, const char *what, SceneLimit k,
                       const double *v, int n)
{
    char why[320];
    if (scene_limit_check(k, v, n, why, sizeof why) == 0)
        return 0;
    if (e)
        diag(p, e->line, "key '%s.%s': %s %s", e->section, e->key, what, why);
    else
        diag(p, inifile_section(&p->ini, section) ? inifile_section(&p->ini, section)->line : 0,
             "section [%s]: %s %s", section, what, why);
    return -1;
}

/* A radiance (r g b) against the limit of scene values. */
static int radiance_check(Parse *p, const Entry *e, const float *rgb)
{
    double v[3] = {rgb[0], rgb[1], rgb[2]};
    return limit_check(p, e, e->section, "radiance", SCENE_LIMIT_RADIANCE, v, 3);
}

/* A base colour above the reflectance limit: a warning (scene.h), not an error. 0, or -1 out of
 * memory. */
static int reflectance_warn(Parse *p, Scene *s, const Entry *e, const float *rgb)
{
    char why[320];
    double v[3] = {rgb[0], rgb[1], rgb[2]};
    if (scene_limit_check(SCENE_LIMIT_REFLECTANCE, v, 3, why, sizeof why) == 0)
        return 0;
    return scene_warn(s, "%s:%d: key '%s.%s': %s: such a surface reflects more light than it receives", p->path,
                      e->line, e->section, e->key, why);
}

/* ---- sections -------------------------------------------------------------------------------- */

/* The NAME of a "kind.NAME" section, or NULL. */
static const char *named(const char *section, const char *kind)
{
    size_t n = strlen(kind);
    if (strncmp(section, kind, n) == 0 && section[n] == '.' && section[n + 1])
        return section + n + 1;
    return NULL;
}

static int section_line(const Parse *p, const char *name)
{
    const IniSection *s = inifile_section(&p->ini, name);
    return s ? s->line : 0;
}

/* The entry of `key` in `section` (each is there once, but for [scene] gltf), or NULL. */
static const Entry *get(const Parse *p, const char *section, const char *key)
{
    return inifile_get(&p->ini, section, key);
}

static void missing(Parse *p, const char *section, const char *key, const char *why)
{
    diag(p, section_line(p, section), "section [%s]: key '%s' is required%s", section, key, why);
}

/* Directory of the ini, for relative glTF paths. */
static char *resolve(const char *ini, const char *rel)
{
    const char *slash = strrchr(ini, '/');
    char *out = NULL;
    if (rel[0] == '/' || !slash) {
        out = strdup(rel);
    } else if (asprintf(&out, "%.*s/%s", (int)(slash - ini), ini, rel) < 0) {
        out = NULL;
    }
    return out;
}

static int has_ext(const char *path, const char *ext)
{
    size_t a = strlen(path), b = strlen(ext);
    return a >= b && strcasecmp(path + a - b, ext) == 0;
}

/* "; where to get the scene: SOURCE (...)" when [scene] source says, else "". */
static const char *source_note(const IniFile *ini, char *buf, size_t len)
{
    const Entry *e = inifile_get(ini, "scene", "source");
    if (!e || !e->value[0])
        return "";
    snprintf(buf, len, "; where to get the scene: %s (docs/scenes.md, Getting the scenes)", e->value);
    return buf;
}

/* A mesh file: glTF (.gltf, .glb) or, by its extension, Wavefront OBJ (.obj). */
static int load_gltf(Parse *p, Scene *s, const Entry *file, const double *xf)
{
    if (!file->value[0]) {
        bad_value(p, file, "expected the path of a .gltf, .glb or .obj file");
        return -1;
    }
    char *full = resolve(p->path, file->value);
    char gerr[2048], note[512];
    int rc;
    struct stat st;
    if (!full) {
        diag(p, 0, "out of memory");
        return -1;
    }
    rc = has_ext(full, ".obj") ? obj_append(full, xf, s, gerr, sizeof gerr) : gltf_append(full, xf, s, gerr, sizeof gerr);
    if (rc != 0)
        diag(p, file->line, "key '%s.%s': %s%s", file->section, file->key, gerr,
             stat(full, &st) != 0 ? source_note(&p->ini, note, sizeof note) : "");
    free(full);
    return rc;
}

/* [gltf.NAME]: file, translate, scale (one number or three), rotate_y (degrees). The
 * placement is x' = T Ry S x. */
static int gltf_section(Parse *p, Scene *s, const char *section)
{
    float t[3] = {0, 0, 0}, sc[3] = {1, 1, 1}, ry = 0.0f;
    int bad = 0;
    const Entry *e, *file = get(p, section, "file");
    if ((e = get(p, section, "translate")))
        bad |= parse_floats(p, e, t, 3);
    if ((e = get(p, section, "scale"))) {
        if (count_words(e->value) == 3) {
            bad |= parse_floats(p, e, sc, 3);
        } else if (parse_floats(p, e, sc, 1) == 0) {
            sc[1] = sc[2] = sc[0];
        } else {
            bad = -1;
        }
        if (!bad && (sc[0] == 0.0f || sc[1] == 0.0f || sc[2] == 0.0f)) {
            bad_value(p, e, "expected non-zero scale factors");
            bad = -1;
        }
    }
    if ((e = get(p, section, "rotate_y")))
        bad |= parse_floats(p, e, &ry, 1);
    if (!file) {
        missing(p, section, "file", "");
        return -1;
    }
    if (bad)
        return -1;
    double c = cos(ry * M_PI / 180.0), sn = sin(ry * M_PI / 180.0);
    double xf[16] = {c * sc[0], 0, -sn * sc[0], 0, 0, sc[1], 0, 0, sn * sc[2], 0, c * sc[2], 0, t[0], t[1], t[2], 1};
    return load_gltf(p, s, file, xf);
}

static int add_material(Scene *s, const char *name)
{
    SceneMaterial *m = realloc(s->materials, sizeof *m * ((size_t)s->nmaterials + 1));
    if (!m)
        return -1;
    s->materials = m;
    SceneMaterial *x = &m[s->nmaterials];
    memset(x, 0, sizeof *x);
    if (!(x->name = strdup(name)))
        return -1;
    x->kind = SCENE_MAT_LAMBERT;
    x->base_color[0] = x->base_color[1] = x->base_color[2] = 0.8f;
    x->alpha = 1.0f;
    x->roughness = 1.0f;
    x->ior = 1.5f;
    x->base_texture = x->emissive_texture = -1;
    x->alpha_cutoff = 0.5f;
    return (int)s->nmaterials++;
}

/* [material.NAME]: a new material, or an override of every glTF material called NAME. Only
 * the keys given change; without 'kind', the kind follows the glTF mapping again (metallic > 0
 * or roughness < 1: glossy) unless the material is a dielectric. */
static void material_section(Parse *p, Scene *s, const char *section, const char *name)
{
    int kind = -1, have_double = 0, dsided = 0, bad = 0;
    float base[3], em[3], rough = 0, metal = 0, ior = 0;
    const Entry *ek = get(p, section, "kind"), *eb = get(p, section, "base_color"), *ee = get(p, section, "emission"),
                *er = get(p, section, "roughness"), *em_ = get(p, section, "metallic"), *ei = get(p, section, "ior"),
                *ed = get(p, section, "double_sided");
    if (ek) {
        if (!strcmp(ek->value, "lambert"))
            kind = SCENE_MAT_LAMBERT;
        else if (!strcmp(ek->value, "glossy"))
            kind = SCENE_MAT_GLOSSY;
        else if (!strcmp(ek->value, "dielectric"))
            kind = SCENE_MAT_DIELECTRIC;
        else {
            bad_value(p, ek, "expected lambert, glossy or dielectric");
            bad = 1;
        }
    }
    if (eb && parse_nonneg3(p, eb, base) != 0)
        bad = 1;
    else if (eb && !bad && reflectance_warn(p, s, eb, base) != 0)
        diag(p, 0, "out of memory");
    bad |= ee && (parse_nonneg3(p, ee, em) != 0 || radiance_check(p, ee, em) != 0);
    bad |= er && parse_range(p, er, 0.0f, 1.0f, &rough) != 0;
    bad |= em_ && parse_range(p, em_, 0.0f, 1.0f, &metal) != 0;
    bad |= ei && parse_range(p, ei, 1.0f, 10.0f, &ior) != 0;
    if (ed) {
        bad |= parse_int(p, ed, 0, 1, &dsided) != 0;
        have_double = 1;
    }
    if (bad)
        return;
    int any = 0;
    for (uint32_t i = 0; i < s->nmaterials; i++)
        any |= s->materials[i].name && !strcmp(s->materials[i].name, name);
    if (!any && add_material(s, name) < 0) {
        diag(p, 0, "out of memory");
        return;
    }
    for (uint32_t i = 0; i < s->nmaterials; i++) {
        SceneMaterial *m = &s->materials[i];
        if (!m->name || strcmp(m->name, name) != 0)
            continue;
        if (eb)
            memcpy(m->base_color, base, sizeof base);
        if (ee)
            memcpy(m->emission, em, sizeof em);
        if (er)
            m->roughness = rough;
        if (em_)
            m->metallic = metal;
        if (ei)
            m->ior = ior;
        if (have_double)
            m->double_sided = dsided;
        if (kind >= 0)
            m->kind = (SceneMatKind)kind;
        else if (m->kind != SCENE_MAT_DIELECTRIC)
            m->kind = m->metallic > 0.0f || m->roughness < 1.0f ? SCENE_MAT_GLOSSY : SCENE_MAT_LAMBERT;
        if (m->kind == SCENE_MAT_DIELECTRIC && m->transmission <= 0.0f)
            m->transmission = 1.0f;
        if (m->kind != SCENE_MAT_DIELECTRIC)
            m->transmission = 0.0f;
    }
}

typedef struct LightKey {
    const char *key;
    unsigned types; /* bit per SceneLightKind that takes the key */
    unsigned required;
} LightKey;

#define LT(k) (1u << (k))
static const LightKey light_keys[] = {
    {"position", LT(SCENE_LIGHT_POINT) | LT(SCENE_LIGHT_SPOT) | LT(SCENE_LIGHT_QUAD),
     LT(SCENE_LIGHT_POINT) | LT(SCENE_LIGHT_SPOT) | LT(SCENE_LIGHT_QUAD)},
    {"direction", LT(SCENE_LIGHT_SPOT) | LT(SCENE_LIGHT_DIRECTIONAL),
     LT(SCENE_LIGHT_SPOT) | LT(SCENE_LIGHT_DIRECTIONAL)},
    {"edge_u", LT(SCENE_LIGHT_QUAD), LT(SCENE_LIGHT_QUAD)},
    {"edge_v", LT(SCENE_LIGHT_QUAD), LT(SCENE_LIGHT_QUAD)},
    {"inner_cone", LT(SCENE_LIGHT_SPOT), 0},
    {"outer_cone", LT(SCENE_LIGHT_SPOT), 0},
    {"color", 0xF, 0},
    {"intensity", 0xF, 0},
};
static const char *const light_type_names[] = {"point", "spot", "directional", "quad"};

/* What the renderers take from a light (scene.h's limits): its position, or a quad's four corners
 * and area, within reach of a shadow ray; colour x intensity as the radiance scenes/pack.c stores
 * (in binary32, as here). 0, or -1 with the key named. */
static int light_limits(Parse *p, const char *section, const SceneLight *l)
{
    const Entry *ep = get(p, section, "position"), *ei = get(p, section, "intensity");
    double rad[3];
    for (int k = 0; k < 3; k++)
        rad[k] = (double)(l->color[k] * l->intensity);
    SceneLimit lim = l->kind == SCENE_LIGHT_POINT || l->kind == SCENE_LIGHT_SPOT ? SCENE_LIMIT_INTENSITY
                                                                                   : SCENE_LIMIT_RADIANCE;
    if (limit_check(p, ei ? ei : get(p, section, "color"), section, "color x intensity", lim, rad, 3) != 0)
        return -1;
    if (l->kind == SCENE_LIGHT_DIRECTIONAL)
        return 0;
    for (int c = 0; c < (l->kind == SCENE_LIGHT_QUAD ? 4 : 1); c++) {
        double v[3];
        for (int k = 0; k < 3; k++)
            v[k] = (double)l->position[k] + (c & 1 ? l->edge_u[k] : 0.0f) + (c & 2 ? l->edge_v[k] : 0.0f);
        static const char *const corner[] = {"the position", "the corner position + edge_u",
                                             "the corner position + edge_v", "the corner position + edge_u + edge_v"};
        if (limit_check(p, c == 0 ? ep : get(p, section, c == 2 ? "edge_v" : "edge_u"), section, corner[c],
                        SCENE_LIMIT_COORD, v, 3) != 0)
            return -1;
    }
    if (l->kind == SCENE_LIGHT_QUAD) {
        float z[3] = {0, 0, 0};
        double area = scene_cross_norm(z, l->edge_u, l->edge_v);
        if (limit_check(p, NULL, section, "the area |edge_u x edge_v|", SCENE_LIMIT_AREA, &area, 1) != 0)
            return -1;
    }
    return 0;
}

/* [light.NAME]: type = point | spot | directional | quad and the keys of that type. */
static void light_section(Parse *p, Scene *s, const char *section, const char *name)
{
    SceneLight l;
    memset(&l, 0, sizeof l);
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 1.0f;
    float inner = 0.0f, outer = 45.0f;
    int bad = 0, kind = -1;
    const Entry *et = get(p, section, "type");
    if (!et) {
        missing(p, section, "type", " (point, spot, directional or quad)");
        bad = 1;
    } else {
        for (int k = 0; k < 4; k++)
            if (!strcmp(et->value, light_type_names[k]))
                kind = k;
        if (kind < 0) {
            bad_value(p, et, "expected point, spot, directional or quad");
            bad = 1;
        }
    }
    for (size_t i = 0; i < sizeof light_keys / sizeof light_keys[0]; i++) {
        const LightKey *lk = &light_keys[i];
        const Entry *e = get(p, section, lk->key);
        if (kind < 0)
            continue;
        if (!e) {
            if (lk->required & LT(kind)) {
                char why[64];
                snprintf(why, sizeof why, " for a %s light", light_type_names[kind]);
                missing(p, section, lk->key, why);
                bad = 1;
            }
            continue;
        }
        if (!(lk->types & LT(kind))) {
            diag(p, e->line, "key '%s.%s': does not apply to a %s light", e->section, e->key,
                 light_type_names[kind]);
            bad = 1;
            continue;
        }
        int r = 0;
        if (!strcmp(lk->key, "position"))
            r = parse_floats(p, e, l.position, 3);
        else if (!strcmp(lk->key, "direction"))
            r = parse_floats(p, e, l.direction, 3);
        else if (!strcmp(lk->key, "edge_u"))
            r = parse_floats(p, e, l.edge_u, 3);
        else if (!strcmp(lk->key, "edge_v"))
            r = parse_floats(p, e, l.edge_v, 3);
        else if (!strcmp(lk->key, "inner_cone"))
            r = parse_range(p, e, 0.0f, 90.0f, &inner);
        else if (!strcmp(lk->key, "outer_cone"))
            r = parse_range(p, e, 0.0f, 90.0f, &outer);
        else if (!strcmp(lk->key, "color"))
            r = parse_nonneg3(p, e, l.color);
        else if (!strcmp(lk->key, "intensity"))
            r = parse_sign(p, e, 0, &l.intensity);
        bad |= r != 0;
    }
    if (bad)
        return;
    int line = section_line(p, section);
    l.kind = (SceneLightKind)kind;
    if (kind == SCENE_LIGHT_SPOT || kind == SCENE_LIGHT_DIRECTIONAL) {
        double d[3] = {l.direction[0], l.direction[1], l.direction[2]};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0.0)) {
            diag(p, get(p, section, "direction")->line, "key '%s.direction': must not be zero", section);
            return;
        }
        for (int k = 0; k < 3; k++)
            l.direction[k] = (float)(d[k] / len);
    }
    if (kind == SCENE_LIGHT_SPOT && !(inner < outer && outer > 0.0f)) {
        diag(p, line, "section [%s]: inner_cone (%g) must be smaller than outer_cone (%g)", section,
             inner, outer);
        return;
    }
    if (kind == SCENE_LIGHT_QUAD) {
        double u[3] = {l.edge_u[0], l.edge_u[1], l.edge_u[2]}, v[3] = {l.edge_v[0], l.edge_v[1], l.edge_v[2]};
        double cx = u[1] * v[2] - u[2] * v[1], cy = u[2] * v[0] - u[0] * v[2], cz = u[0] * v[1] - u[1] * v[0];
        if (!(cx * cx + cy * cy + cz * cz > 0.0)) {
            diag(p, line, "section [%s]: edge_u and edge_v must span a non-zero area", section);
            return;
        }
    }
    if (light_limits(p, section, &l) != 0)
        return;
    l.inner_cone = inner * (float)M_PI / 180.0f;
    l.outer_cone = outer * (float)M_PI / 180.0f;
    SceneLight *arr = realloc(s->lights, sizeof *arr * ((size_t)s->nlights + 1));
    if (!arr || !(l.name = strdup(name))) {
        if (arr)
            s->lights = arr;
        diag(p, 0, "out of memory");
        return;
    }
    s->lights = arr;
    s->lights[s->nlights++] = l;
}

/* [sphere.NAME]: center, radius, material. */
static void sphere_section(Parse *p, Scene *s, const char *section, const char *name, int gltf_failed)
{
    SceneSphere sp;
    memset(&sp, 0, sizeof sp);
    sp.material = -1;
    int bad = 0;
    const Entry *ec = get(p, section, "center"), *er = get(p, section, "radius"), *em = get(p, section, "material");
    if (!ec)
        missing(p, section, "center", "");
    if (!er)
        missing(p, section, "radius", "");
    if (!em)
        missing(p, section, "material", "");
    bad = !ec || !er || !em;
    bad |= ec && parse_floats(p, ec, sp.center, 3) != 0;
    bad |= er && parse_sign(p, er, 1, &sp.radius) != 0;
    if (em) {
        for (uint32_t i = 0; i < s->nmaterials && sp.material < 0; i++)
            if (s->materials[i].name && !strcmp(s->materials[i].name, em->value))
                sp.material = (int)i;
        if (sp.material < 0) {
            if (!gltf_failed) /* the name may be in the glTF file that failed to load */
                diag(p, em->line, "key '%s.material': no [material.%s] section and no glTF material called '%s'",
                     section, em->value, em->value);
            bad = 1;
        }
    }
    if (bad)
        return;
    /* The ray/sphere test squares the radius and the distance to the centre: the sphere's box
     * lies within the coordinate limit, as a triangle's vertices do. */
    double c[3] = {sp.center[0], sp.center[1], sp.center[2]}, box[3];
    for (int k = 0; k < 3; k++)
        box[k] = fabs(c[k]) + sp.radius;
    if (limit_check(p, ec, section, "center", SCENE_LIMIT_COORD, c, 3) != 0 ||
        limit_check(p, er, section, "|center| + radius", SCENE_LIMIT_COORD, box, 3) != 0)
        return;
    SceneSphere *arr = realloc(s->spheres, sizeof *arr * ((size_t)s->nspheres + 1));
    if (!arr || !(sp.name = strdup(name))) {
        if (arr)
            s->spheres = arr;
        diag(p, 0, "out of memory");
        return;
    }
    s->spheres = arr;
    s->spheres[s->nspheres++] = sp;
}

/* [camera]: position, look_at, up, fov_y, aperture, focus_distance. Overrides the glTF file's
 * camera key by key; without one, position and look_at are required. */
static void camera_section(Parse *p, Scene *s)
{
    SceneCamera c = s->camera;
    int from_gltf = c.source == SCENE_CAMERA_GLTF, bad = 0;
    if (!from_gltf) {
        memset(&c, 0, sizeof c);
        c.up[1] = 1.0f;
        c.fov_y = 45.0f;
    }
    const Entry *ep = get(p, "camera", "position"), *ea = get(p, "camera", "look_at"), *eu = get(p, "camera", "up"),
                *ef = get(p, "camera", "fov_y"), *eap = get(p, "camera", "aperture"),
                *ed = get(p, "camera", "focus_distance");
    bad |= ep && parse_floats(p, ep, c.position, 3) != 0;
    bad |= ea && parse_floats(p, ea, c.look_at, 3) != 0;
    bad |= eu && parse_floats(p, eu, c.up, 3) != 0;
    if (ef) {
        float f;
        if (parse_floats(p, ef, &f, 1) != 0) {
            bad = 1;
        } else if (!(f > 0.0f && f < 180.0f)) {
            bad_value(p, ef, "expected an angle between 0 and 180 degrees (exclusive)");
            bad = 1;
        } else {
            c.fov_y = f;
        }
    }
    bad |= eap && parse_sign(p, eap, 0, &c.aperture) != 0;
    bad |= ed && parse_sign(p, ed, 0, &c.focus_distance) != 0;
    if (!from_gltf && (!ep || !ea)) {
        if (!ep)
            missing(p, "camera", "position", " (the glTF files have no camera)");
        if (!ea)
            missing(p, "camera", "look_at", " (the glTF files have no camera)");
        return;
    }
    if (bad)
        return;
    /* The limits first: beyond them, look_at and position are often one binary32 number. */
    int line = section_line(p, "camera");
    char why[400];
    if (scene_camera_check(&c, why, sizeof why) != 0) {
        diag(p, line, "section [camera]: %s", why);
        return;
    }
    double d[3], u[3] = {c.up[0], c.up[1], c.up[2]};
    for (int k = 0; k < 3; k++)
        d[k] = (double)c.look_at[k] - c.position[k];
    double cr[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
    if (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0.0)) {
        diag(p, line, "section [camera]: look_at must differ from position");
        return;
    }
    if (!(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2] > 0.0)) {
        diag(p, line, "section [camera]: up must not be zero or parallel to the view direction");
        return;
    }
    c.source = SCENE_CAMERA_FILE;
    s->camera = c;
}

/* [render]: width, height, spp, max_depth, background, ambient. */
static void render_section(Parse *p, Scene *s)
{
    const Entry *e;
    SceneRender r = s->render;
    int bad = 0;
    /* The ranges sfsim's --set render.* accepts (sim/main.c). */
    if ((e = get(p, "render", "width")))
        bad |= parse_int(p, e, 1, 16384, &r.width);
    if ((e = get(p, "render", "height")))
        bad |= parse_int(p, e, 1, 16384, &r.height);
    if ((e = get(p, "render", "spp")))
        bad |= parse_int(p, e, 1, 1L << 20, &r.spp);
    if ((e = get(p, "render", "max_depth")))
        bad |= parse_int(p, e, 0, 63, &r.max_depth);
    if ((e = get(p, "render", "background")))
        bad |= parse_nonneg3(p, e, r.background) || radiance_check(p, e, r.background);
    if ((e = get(p, "render", "ambient")))
        bad |= parse_nonneg3(p, e, r.ambient) || radiance_check(p, e, r.ambient);
    if (!bad)
        s->render = r;
}

static const char *const known_keys[][2] = {
    {"scene", "gltf source"},
    {"camera", "position look_at up fov_y aperture focus_distance"},
    {"render", "width height spp max_depth background ambient"},
    {"gltf", "file translate scale rotate_y"},
    {"light", "type position direction edge_u edge_v color intensity inner_cone outer_cone"},
    {"sphere", "center radius material"},
    {"material", "kind base_color roughness metallic ior emission double_sided"},
};

/* The kind of a section name ("light" for "light.lamp"), or NULL for an unknown section. */
static const char *section_kind(const char *name)
{
    for (size_t i = 0; i < sizeof known_keys / sizeof known_keys[0]; i++) {
        const char *k = known_keys[i][0];
        int is_named = i >= 3;
        if (is_named ? named(name, k) != NULL : !strcmp(name, k))
            return k;
    }
    return NULL;
}

static const char *keys_of(const char *kind)
{
    for (size_t i = 0; i < sizeof known_keys / sizeof known_keys[0]; i++)
        if (!strcmp(known_keys[i][0], kind))
            return known_keys[i][1];
    return "";
}

int scene_file_load(const char *path, Scene *s, char *err, size_t errlen)
{
    static const char *const repeatable[] = {"scene.gltf", NULL};
    const IniOptions opt = {0, 0, repeatable};
    Parse p;
    memset(&p, 0, sizeof p);
    p.path = path;
    inifile_load(&p.ini, path, &opt);
    /* The reader's messages join this file's, all sorted by line in the end. */
    p.nerr += p.ini.nerrors;
    for (int i = 0; i < p.ini.nmessages; i++) {
        diag_keep(&p, p.ini.messages[i].line, p.ini.messages[i].text);
        p.ini.messages[i].text = NULL;
    }
    if (p.ini.nerrors && !p.ini.nsections)
        goto done; /* not read at all, or nothing to check */

    /* Section names: known kinds (each is there once: the reader says so). */
    for (int i = 0; i < p.ini.nsections; i++) {
        const char *name = p.ini.sections[i].name;
        if (!section_kind(name))
            diag(&p, p.ini.sections[i].line,
                 "unknown section [%s] (expected scene, camera, render, gltf.NAME, light.NAME, sphere.NAME or "
                 "material.NAME)",
                 name);
    }
    /* Keys: known for their section, on one line. */
    for (int i = 0; i < p.ini.nentries; i++) {
        Entry *e = &p.ini.entries[i];
        const char *kind = section_kind(e->section);
        if (!kind)
            continue; /* its section is reported */
        const char *keys = keys_of(kind);
        size_t kl = strlen(e->key);
        const char *hit = keys;
        int known = 0;
        while ((hit = strstr(hit, e->key)) != NULL) {
            if ((hit == keys || hit[-1] == ' ') && (hit[kl] == ' ' || hit[kl] == 0)) {
                known = 1;
                break;
            }
            hit += kl;
        }
        if (!known) {
            diag(&p, e->line, "key '%s.%s': unknown key (%s takes: %s)", e->section, e->key,
                 !strcmp(kind, e->section) ? e->section : kind, keys);
            continue;
        }
        char *nl = strchr(e->value, '\n');
        if (nl) {
            diag(&p, e->line, "key '%s.%s': continued on an indented line: the value must be on one line",
                 e->section, e->key);
            /* Reported once: what follows sees blanks, so that no message spans lines. */
            for (char *c = nl; *c; c++)
                if (*c == '\n')
                    *c = ' ';
        }
    }

    /* glTF files in the order they appear: [scene] gltf lines, then [gltf.NAME] sections. */
    int gltf_failed = 0;
    for (int i = 0; i < p.ini.nentries; i++) {
        const Entry *e = &p.ini.entries[i];
        if (!strcmp(e->section, "scene") && !strcmp(e->key, "gltf"))
            gltf_failed |= load_gltf(&p, s, e, NULL) != 0;
    }
    for (int i = 0; i < p.ini.nsections; i++)
        if (named(p.ini.sections[i].name, "gltf"))
            gltf_failed |= gltf_section(&p, s, p.ini.sections[i].name) != 0;

    /* Then what refers to the glTF files' materials by name: materials, spheres; then lights. */
    for (int pass = 0; pass < 3; pass++)
        for (int i = 0; i < p.ini.nsections; i++) {
            const char *sec = p.ini.sections[i].name, *name;
            if (pass == 0 && (name = named(sec, "material")))
                material_section(&p, s, sec, name);
            else if (pass == 1 && (name = named(sec, "sphere")))
                sphere_section(&p, s, sec, name, gltf_failed);
            else if (pass == 2 && (name = named(sec, "light")))
                light_section(&p, s, sec, name);
        }
    if (section_line(&p, "camera"))
        camera_section(&p, s);
    render_section(&p, s);

done:
    inifile_free(&p.ini);
    int nerr = p.nerr;
    write_diags(&p, err, errlen);
    return nerr ? -1 : 0;
}

/* ---- the files a scene names ----------------------------------------------------------------- */

static void check_append(char *err, size_t errlen, size_t *used, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void check_append(char *err, size_t errlen, size_t *used, const char *fmt, ...)
{
    if (*used + 1 >= errlen)
        return;
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(err + *used, errlen - *used, fmt, ap);
    va_end(ap);
    if (n > 0)
        *used = *used + (size_t)n < errlen ? *used + (size_t)n : errlen - 1;
}

/* "cannot open: ..." or "not a regular file" for path, or NULL when it is a regular file. */
static const char *file_problem(const char *path, char *buf, size_t len)
{
    struct stat st;
    if (stat(path, &st) != 0) {
        snprintf(buf, len, "cannot open: %s", strerror(errno));
        return buf;
    }
    return S_ISREG(st.st_mode) ? NULL : "not a regular file";
}

int scene_file_check(const char *path, char *err, size_t errlen)
{
    char why[256], note[512];
    const char *pr = file_problem(path, why, sizeof why);
    size_t used = 0;
    if (errlen)
        err[0] = 0;
    if (pr) {
        check_append(err, errlen, &used, "%s: %s", path, pr);
        return -1;
    }
    if (!has_ext(path, ".ini"))
        return 0;
    static const char *const repeatable[] = {"scene.gltf", NULL};
    const IniOptions opt = {0, 0, repeatable};
    IniFile ini;
    memset(&ini, 0, sizeof ini);
    inifile_load(&ini, path, &opt);
    int bad = 0;
    if (ini.nerrors && !ini.nsections) { /* not read at all: its first message */
        check_append(err, errlen, &used, "%s", ini.nmessages ? ini.messages[0].text : path);
        bad = 1;
    }
    for (int i = 0; i < ini.nentries; i++) {
        const Entry *e = &ini.entries[i];
        int mesh = (!strcmp(e->section, "scene") && !strcmp(e->key, "gltf")) ||
                   (named(e->section, "gltf") && !strcmp(e->key, "file"));
        if (!mesh || !e->value[0])
            continue; /* an empty path is the loader's error */
        char *full = resolve(path, e->value);
        if (full && (pr = file_problem(full, why, sizeof why)) != NULL) {
            check_append(err, errlen, &used, "%s%s:%d: key '%s.%s': %s: %s", bad ? "\n" : "", path, e->line,
                         e->section, e->key, full, pr);
            bad = 1;
        }
        free(full);
    }
    if (bad)
        check_append(err, errlen, &used, "%s", source_note(&ini, note, sizeof note));
    inifile_free(&ini);
    return bad ? -1 : 0;
}
