/* scenes/scene_file.c -- scene.ini: a glTF reference (or several, placed with transforms) plus
 * what glTF lacks: camera, render settings, lights, spheres, material overrides.
 *
 * Owns: reading and checking scene.ini. Every problem is reported with file, line and key, all
 * of them in one run. Must not: finish the scene or read glTF itself (gltf_shim.cpp).
 */
#include "scene_file.h"

#include <errno.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gltf.h"

typedef struct Entry {
    char *section, *key, *value;
    int line;
} Entry;

typedef struct Parse {
    FILE *f;
    const char *path;
    int line;
    Entry *e;
    size_t n, cap;
    /* diagnostics */
    char *err;
    size_t errlen, used;
    int nerr, dropped;
} Parse;

static void diag(Parse *p, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    p->nerr++;
    size_t need = strlen(line) + (p->used ? 1 : 0);
    /* Keep room for the closing "... and N more" line so nothing is dropped silently. */
    if (p->used + need + 48 >= p->errlen) {
        p->dropped++;
        return;
    }
    if (p->used)
        p->err[p->used++] = '\n';
    memcpy(p->err + p->used, line, strlen(line) + 1);
    p->used += strlen(line);
}

static char *reader(char *str, int num, void *stream)
{
    Parse *p = stream;
    if (!fgets(str, num, p->f))
        return NULL;
    p->line++;
    size_t len = strlen(str);
    if (len > 0 && str[len - 1] != '\n' && !feof(p->f)) {
        diag(p, "%s:%d: line longer than %d characters", p->path, p->line, num - 1);
        int ch;
        while ((ch = fgetc(p->f)) != EOF && ch != '\n')
            ;
        str[0] = '\n';
        str[1] = 0;
    }
    return str;
}

static int on_entry(void *user, const char *section, const char *key, const char *value)
{
    Parse *p = user;
    if (p->n == p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 32;
        Entry *e = realloc(p->e, cap * sizeof *e);
        if (!e)
            return 0;
        p->e = e;
        p->cap = cap;
    }
    Entry *e = &p->e[p->n++];
    e->section = strdup(section);
    e->key = strdup(key);
    e->value = strdup(value);
    e->line = p->line;
    return e->section && e->key && e->value;
}

/* ---- values ---------------------------------------------------------------------------------- */

static int parse_floats(Parse *p, const Entry *e, float *out, int n)
{
    const char *s = e->value;
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || errno || !isfinite(v) || fabs(v) > 3.4e38) {
            diag(p, "%s:%d: key '%s.%s': expected %d number%s, got '%s'", p->path, e->line, e->section, e->key, n,
                 n == 1 ? "" : "s", e->value);
            return -1;
        }
        out[i] = (float)v;
        s = end;
    }
    while (*s == ' ' || *s == '\t')
        s++;
    if (*s) {
        diag(p, "%s:%d: key '%s.%s': expected %d number%s, got '%s'", p->path, e->line, e->section, e->key, n,
             n == 1 ? "" : "s", e->value);
        return -1;
    }
    return 0;
}

static int parse_int(Parse *p, const Entry *e, int lo, int hi, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(e->value, &end, 10);
    while (*end == ' ' || *end == '\t')
        end++;
    if (end == e->value || *end || errno) {
        diag(p, "%s:%d: key '%s.%s': expected an integer, got '%s'", p->path, e->line, e->section, e->key, e->value);
        return -1;
    }
    if (v < lo || v > hi) {
        diag(p, "%s:%d: key '%s.%s': value %ld out of range %d..%d", p->path, e->line, e->section, e->key, v, lo, hi);
        return -1;
    }
    *out = (int)v;
    return 0;
}

static int positive(Parse *p, const Entry *e, float v, int allow_zero)
{
    if (v > 0.0f || (allow_zero && v == 0.0f))
        return 0;
    diag(p, "%s:%d: key '%s.%s': must be %s, got '%s'", p->path, e->line, e->section, e->key,
         allow_zero ? "zero or positive" : "positive", e->value);
    return -1;
}

static void unknown_key(Parse *p, const Entry *e)
{
    diag(p, "%s:%d: key '%s.%s': unknown key", p->path, e->line, e->section, e->key);
}

/* The part after "kind." of a section name, or NULL. */
static const char *named(const char *section, const char *kind)
{
    size_t n = strlen(kind);
    if (strncmp(section, kind, n) == 0 && section[n] == '.' && section[n + 1])
        return section + n + 1;
    return NULL;
}

/* Directory of path, for relative glTF references. */
static void resolve(const char *ini, const char *rel, char *out, size_t len)
{
    if (rel[0] == '/') {
        snprintf(out, len, "%s", rel);
        return;
    }
    const char *slash = strrchr(ini, '/');
    if (!slash)
        snprintf(out, len, "%s", rel);
    else
        snprintf(out, len, "%.*s/%s", (int)(slash - ini), ini, rel);
}

/* ---- sections ------------------------------------------------------------------------------ */

static void placement(Parse *p, const char *section, double *xf, const char **file, int *line)
{
    float t[3] = {0, 0, 0}, sc[3] = {1, 1, 1}, ry = 0.0f;
    *file = NULL;
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, section) != 0)
            continue;
        if (!strcmp(e->key, "file")) {
            *file = e->value;
            *line = e->line;
        } else if (!strcmp(e->key, "translate")) {
            parse_floats(p, e, t, 3);
        } else if (!strcmp(e->key, "scale")) {
            /* one number, or three */
            float one;
            if (strchr(e->value, ' ') || strchr(e->value, '\t'))
                parse_floats(p, e, sc, 3);
            else if (parse_floats(p, e, &one, 1) == 0)
                sc[0] = sc[1] = sc[2] = one;
        } else if (!strcmp(e->key, "rotate_y")) {
            parse_floats(p, e, &ry, 1);
        } else {
            unknown_key(p, e);
        }
    }
    /* xf = T * Ry * S, column-major */
    double c = cos(ry * M_PI / 180.0), s = sin(ry * M_PI / 180.0);
    double m[16] = {c * sc[0], 0, -s * sc[0], 0, 0, sc[1], 0, 0, s * sc[2], 0, c * sc[2], 0, t[0], t[1], t[2], 1};
    memcpy(xf, m, sizeof m);
}

static int find_material(const Scene *s, const char *name)
{
    for (uint32_t i = 0; i < s->nmaterials; i++)
        if (s->materials[i].name && strcmp(s->materials[i].name, name) == 0)
            return (int)i;
    return -1;
}

static int add_material(Scene *s, const char *name)
{
    SceneMaterial *m = realloc(s->materials, sizeof *m * (s->nmaterials + 1));
    if (!m)
        return -1;
    s->materials = m;
    SceneMaterial *x = &m[s->nmaterials];
    memset(x, 0, sizeof *x);
    x->name = strdup(name);
    x->kind = SCENE_MAT_LAMBERT;
    x->base_color[0] = x->base_color[1] = x->base_color[2] = 0.8f;
    x->alpha = 1.0f;
    x->roughness = 1.0f;
    x->ior = 1.5f;
    x->base_texture = x->emissive_texture = -1;
    x->alpha_cutoff = 0.5f;
    return (int)s->nmaterials++;
}

static void material_section(Parse *p, Scene *s, const char *section, const char *name)
{
    int mi = find_material(s, name);
    if (mi < 0 && (mi = add_material(s, name)) < 0) {
        diag(p, "%s: out of memory", p->path);
        return;
    }
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, section) != 0)
            continue;
        SceneMaterial *m = &s->materials[mi];
        float v;
        if (!strcmp(e->key, "kind")) {
            if (!strcmp(e->value, "lambert"))
                m->kind = SCENE_MAT_LAMBERT;
            else if (!strcmp(e->value, "glossy"))
                m->kind = SCENE_MAT_GLOSSY;
            else if (!strcmp(e->value, "dielectric"))
                m->kind = SCENE_MAT_DIELECTRIC;
            else
                diag(p, "%s:%d: key '%s.%s': expected lambert, glossy or dielectric, got '%s'", p->path, e->line,
                     e->section, e->key, e->value);
        } else if (!strcmp(e->key, "base_color")) {
            parse_floats(p, e, m->base_color, 3);
        } else if (!strcmp(e->key, "emission")) {
            parse_floats(p, e, m->emission, 3);
        } else if (!strcmp(e->key, "roughness")) {
            if (parse_floats(p, e, &v, 1) == 0)
                m->roughness = v;
        } else if (!strcmp(e->key, "metallic")) {
            if (parse_floats(p, e, &v, 1) == 0)
                m->metallic = v;
        } else if (!strcmp(e->key, "ior")) {
            if (parse_floats(p, e, &v, 1) == 0 && positive(p, e, v, 0) == 0)
                m->ior = v;
        } else if (!strcmp(e->key, "double_sided")) {
            int d;
            if (parse_int(p, e, 0, 1, &d) == 0)
                m->double_sided = d;
        } else {
            unknown_key(p, e);
        }
    }
}

static void light_section(Parse *p, Scene *s, const char *section, const char *name)
{
    SceneLight l;
    memset(&l, 0, sizeof l);
    l.kind = SCENE_LIGHT_POINT;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 1.0f;
    l.direction[1] = -1.0f;
    float inner = 0.0f, outer = 45.0f;
    int ok = 1;
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, section) != 0)
            continue;
        int r = 0;
        if (!strcmp(e->key, "type")) {
            if (!strcmp(e->value, "point"))
                l.kind = SCENE_LIGHT_POINT;
            else if (!strcmp(e->value, "spot"))
                l.kind = SCENE_LIGHT_SPOT;
            else if (!strcmp(e->value, "directional"))
                l.kind = SCENE_LIGHT_DIRECTIONAL;
            else if (!strcmp(e->value, "quad"))
                l.kind = SCENE_LIGHT_QUAD;
            else {
                diag(p, "%s:%d: key '%s.%s': expected point, spot, directional or quad, got '%s'", p->path, e->line,
                     e->section, e->key, e->value);
                r = -1;
            }
        } else if (!strcmp(e->key, "position")) {
            r = parse_floats(p, e, l.position, 3);
        } else if (!strcmp(e->key, "direction")) {
            r = parse_floats(p, e, l.direction, 3);
        } else if (!strcmp(e->key, "edge_u")) {
            r = parse_floats(p, e, l.edge_u, 3);
        } else if (!strcmp(e->key, "edge_v")) {
            r = parse_floats(p, e, l.edge_v, 3);
        } else if (!strcmp(e->key, "color")) {
            r = parse_floats(p, e, l.color, 3);
        } else if (!strcmp(e->key, "intensity")) {
            r = parse_floats(p, e, &l.intensity, 1);
            if (!r)
                r = positive(p, e, l.intensity, 1);
        } else if (!strcmp(e->key, "inner_cone")) {
            r = parse_floats(p, e, &inner, 1);
        } else if (!strcmp(e->key, "outer_cone")) {
            r = parse_floats(p, e, &outer, 1);
        } else {
            unknown_key(p, e);
            r = -1;
        }
        ok &= r == 0;
    }
    if (l.kind == SCENE_LIGHT_QUAD) {
        float cx = l.edge_u[1] * l.edge_v[2] - l.edge_u[2] * l.edge_v[1];
        float cy = l.edge_u[2] * l.edge_v[0] - l.edge_u[0] * l.edge_v[2];
        float cz = l.edge_u[0] * l.edge_v[1] - l.edge_u[1] * l.edge_v[0];
        if (!(cx * cx + cy * cy + cz * cz > 0.0f)) {
            diag(p, "%s: [%s]: a quad light needs edge_u and edge_v spanning a non-zero area", p->path, section);
            ok = 0;
        }
    }
    if (l.kind == SCENE_LIGHT_SPOT || l.kind == SCENE_LIGHT_DIRECTIONAL) {
        float d2 = l.direction[0] * l.direction[0] + l.direction[1] * l.direction[1] + l.direction[2] * l.direction[2];
        if (!(d2 > 0.0f)) {
            diag(p, "%s: [%s]: direction must not be zero", p->path, section);
            ok = 0;
        }
    }
    l.inner_cone = inner * (float)M_PI / 180.0f;
    l.outer_cone = outer * (float)M_PI / 180.0f;
    if (!ok)
        return;
    SceneLight *arr = realloc(s->lights, sizeof *arr * (s->nlights + 1));
    if (!arr) {
        diag(p, "%s: out of memory", p->path);
        return;
    }
    l.name = strdup(name);
    s->lights = arr;
    s->lights[s->nlights++] = l;
}

static void sphere_section(Parse *p, Scene *s, const char *section, const char *name)
{
    SceneSphere sp;
    memset(&sp, 0, sizeof sp);
    sp.radius = 1.0f;
    sp.material = -1;
    int ok = 1, have_mat = 0;
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, section) != 0)
            continue;
        if (!strcmp(e->key, "center")) {
            ok &= parse_floats(p, e, sp.center, 3) == 0;
        } else if (!strcmp(e->key, "radius")) {
            ok &= parse_floats(p, e, &sp.radius, 1) == 0 && positive(p, e, sp.radius, 0) == 0;
        } else if (!strcmp(e->key, "material")) {
            have_mat = 1;
            sp.material = find_material(s, e->value);
            if (sp.material < 0) {
                diag(p, "%s:%d: key '%s.%s': no material named '%s'", p->path, e->line, e->section, e->key, e->value);
                ok = 0;
            }
        } else {
            unknown_key(p, e);
            ok = 0;
        }
    }
    if (!have_mat) {
        diag(p, "%s: [%s]: key 'material' is required", p->path, section);
        ok = 0;
    }
    if (!ok)
        return;
    SceneSphere *arr = realloc(s->spheres, sizeof *arr * (s->nspheres + 1));
    if (!arr) {
        diag(p, "%s: out of memory", p->path);
        return;
    }
    sp.name = strdup(name);
    s->spheres = arr;
    s->spheres[s->nspheres++] = sp;
}

static void camera_section(Parse *p, Scene *s)
{
    SceneCamera c = s->camera;
    int have_pos = 0, have_at = 0, any = 0;
    if (c.source == SCENE_CAMERA_DEFAULT) {
        memset(&c, 0, sizeof c);
        c.up[1] = 1.0f;
        c.fov_y = 45.0f;
    }
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, "camera") != 0)
            continue;
        any = 1;
        if (!strcmp(e->key, "position")) {
            have_pos = parse_floats(p, e, c.position, 3) == 0;
        } else if (!strcmp(e->key, "look_at")) {
            have_at = parse_floats(p, e, c.look_at, 3) == 0;
        } else if (!strcmp(e->key, "up")) {
            parse_floats(p, e, c.up, 3);
        } else if (!strcmp(e->key, "fov_y")) {
            if (parse_floats(p, e, &c.fov_y, 1) == 0 && !(c.fov_y > 0.0f && c.fov_y < 180.0f))
                diag(p, "%s:%d: key 'camera.fov_y': must be between 0 and 180 degrees, got '%s'", p->path, e->line, e->value);
        } else if (!strcmp(e->key, "aperture")) {
            if (parse_floats(p, e, &c.aperture, 1) == 0)
                positive(p, e, c.aperture, 1);
        } else if (!strcmp(e->key, "focus_distance")) {
            if (parse_floats(p, e, &c.focus_distance, 1) == 0)
                positive(p, e, c.focus_distance, 1);
        } else {
            unknown_key(p, e);
        }
    }
    if (!any)
        return;
    if (s->camera.source == SCENE_CAMERA_DEFAULT && (!have_pos || !have_at)) {
        diag(p, "%s: [camera]: position and look_at are required when the glTF file has no camera", p->path);
        return;
    }
    float d[3] = {c.look_at[0] - c.position[0], c.look_at[1] - c.position[1], c.look_at[2] - c.position[2]};
    float cr[3] = {d[1] * c.up[2] - d[2] * c.up[1], d[2] * c.up[0] - d[0] * c.up[2], d[0] * c.up[1] - d[1] * c.up[0]};
    if (!(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] > 0.0f) || !(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2] > 0.0f)) {
        diag(p, "%s: [camera]: look_at must differ from position and not lie along up", p->path);
        return;
    }
    c.source = SCENE_CAMERA_FILE;
    s->camera = c;
}

static void render_section(Parse *p, Scene *s)
{
    for (size_t i = 0; i < p->n; i++) {
        const Entry *e = &p->e[i];
        if (strcmp(e->section, "render") != 0)
            continue;
        if (!strcmp(e->key, "width"))
            parse_int(p, e, 1, 16384, &s->render.width);
        else if (!strcmp(e->key, "height"))
            parse_int(p, e, 1, 16384, &s->render.height);
        else if (!strcmp(e->key, "spp"))
            parse_int(p, e, 1, 1 << 20, &s->render.spp);
        else if (!strcmp(e->key, "max_depth"))
            parse_int(p, e, 0, 63, &s->render.max_depth);
        else if (!strcmp(e->key, "background"))
            parse_floats(p, e, s->render.background, 3);
        else if (!strcmp(e->key, "ambient"))
            parse_floats(p, e, s->render.ambient, 3);
        else
            unknown_key(p, e);
    }
}

int scene_file_load(const char *path, Scene *s, char *err, size_t errlen)
{
    Parse p;
    memset(&p, 0, sizeof p);
    p.path = path;
    p.err = err;
    p.errlen = errlen;
    if (errlen)
        err[0] = 0;
    p.f = fopen(path, "r");
    if (!p.f) {
        snprintf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return -1;
    }
    int rc = ini_parse_stream(reader, &p, on_entry, &p);
    fclose(p.f);
    if (rc > 0)
        diag(&p, "%s:%d: syntax error (expected [section] or key = value)", path, rc);
    else if (rc < 0)
        diag(&p, "%s: cannot read (out of memory)", path);

    /* Sections: check names first, so a typo is reported whatever else happens. */
    for (size_t i = 0; i < p.n; i++) {
        const Entry *e = &p.e[i];
        const char *sec = e->section;
        if (!strcmp(sec, "scene")) {
            if (strcmp(e->key, "gltf") != 0)
                unknown_key(&p, e);
        } else if (strcmp(sec, "camera") && strcmp(sec, "render") && !named(sec, "gltf") && !named(sec, "light") &&
                   !named(sec, "sphere") && !named(sec, "material")) {
            diag(&p, "%s:%d: key '%s.%s': unknown section [%s]", path, e->line, sec, e->key, sec);
        }
    }
    /* glTF files, in the order they appear. */
    for (size_t i = 0; p.nerr == 0 && i < p.n; i++) {
        const Entry *e = &p.e[i];
        char full[4096], gerr[1024];
        if (!strcmp(e->section, "scene") && !strcmp(e->key, "gltf")) {
            resolve(path, e->value, full, sizeof full);
            if (gltf_append(full, NULL, s, gerr, sizeof gerr) != 0)
                diag(&p, "%s:%d: key 'scene.gltf': %s", path, e->line, gerr);
        } else if (named(e->section, "gltf") && (i == 0 || strcmp(p.e[i - 1].section, e->section) != 0)) {
            int seen = 0;
            for (size_t j = 0; j < i; j++)
                seen |= !strcmp(p.e[j].section, e->section);
            if (seen)
                continue;
            double xf[16];
            const char *file;
            int line = e->line;
            placement(&p, e->section, xf, &file, &line);
            if (!file) {
                diag(&p, "%s: [%s]: key 'file' is required", path, e->section);
                continue;
            }
            resolve(path, file, full, sizeof full);
            if (p.nerr == 0 && gltf_append(full, xf, s, gerr, sizeof gerr) != 0)
                diag(&p, "%s:%d: key '%s.file': %s", path, line, e->section, gerr);
        }
    }
    /* Then everything that refers to what the glTF files brought (materials by name). */
    for (int pass = 0; pass < 3; pass++) {
        for (size_t i = 0; i < p.n; i++) {
            const Entry *e = &p.e[i];
            int first = 1;
            for (size_t j = 0; j < i && first; j++)
                first = strcmp(p.e[j].section, e->section) != 0;
            if (!first)
                continue;
            const char *name;
            if (pass == 0 && (name = named(e->section, "material")))
                material_section(&p, s, e->section, name);
            else if (pass == 1 && (name = named(e->section, "sphere")))
                sphere_section(&p, s, e->section, name);
            else if (pass == 2 && (name = named(e->section, "light")))
                light_section(&p, s, e->section, name);
        }
    }
    camera_section(&p, s);
    render_section(&p, s);

    for (size_t i = 0; i < p.n; i++) {
        free(p.e[i].section);
        free(p.e[i].key);
        free(p.e[i].value);
    }
    free(p.e);
    if (p.dropped && p.used < errlen)
        snprintf(err + p.used, errlen - p.used, "\n... and %d more errors", p.dropped);
    return p.nerr ? -1 : 0;
}
