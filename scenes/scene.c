/* scenes/scene.c -- scene_load: dispatch to the glTF or OBJ shim or the scene.ini reader, then the
 * defaults, bounds, emissive-triangle list, default camera and needs of the loaded scene.
 *
 * Owns: what a loaded scene looks like once complete. Must not: parse files itself (the glTF shim
 * scenes/gltf_*.cpp, scene_file.c) or build acceleration structures.
 */
#include "scene.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "gltf.h"
#include "obj.h"
#include "scene_file.h"

void scene_init(Scene *s, const char *source)
{
    memset(s, 0, sizeof *s);
    s->render.width = 512;
    s->render.height = 512;
    s->render.spp = 1;
    s->render.max_depth = 3; /* Gribble & Ramani 2008, Sec. 4.2: three bounces */
    s->camera.source = SCENE_CAMERA_DEFAULT;
    s->source = strdup(source ? source : "");
}

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && strcasecmp(s + a - b, suf) == 0;
}

/* What every loader's triangles must satisfy (scene.h's limits): the loaders check their own
 * values where they can name them; this catches whatever a loader left, naming the triangle. */
static int check_geometry(const Scene *s, char *err, size_t errlen)
{
    char why[320];
    for (uint32_t t = 0; t < s->ntris; t++) {
        const float *p = &s->pos[9 * (size_t)t];
        double v[9];
        for (int i = 0; i < 9; i++)
            v[i] = p[i];
        for (int c = 0; c < 3; c++)
            if (scene_limit_check(SCENE_LIMIT_COORD, v + 3 * c, 3, why, sizeof why) != 0) {
                snprintf(err, errlen, "%s: triangle %u: vertex %d %s", s->source, t, c, why);
                return -1;
            }
        if (scene_limit_check1(SCENE_LIMIT_AREA, scene_cross_norm(p, p + 3, p + 6), why, sizeof why) != 0) {
            snprintf(err, errlen, "%s: triangle %u: |e1 x e2| %s", s->source, t, why);
            return -1;
        }
    }
    return 0;
}

/* The camera, wherever it came from: a scene.ini's [camera] (checked there too, by line), a glTF
 * camera (named by s->camera_from), or the default camera made from the bounds (refused only when
 * its rays would overflow; a warning when it merely stands beyond the coordinate limit). */
static int check_camera(Scene *s, char *err, size_t errlen)
{
    char why[400], who[300];
    if (s->camera.source == SCENE_CAMERA_GLTF && s->camera_from)
        snprintf(who, sizeof who, "%s", s->camera_from);
    else if (s->camera.source == SCENE_CAMERA_DEFAULT)
        snprintf(who, sizeof who, "%s: the default camera (the one that frames the scene's bounds)", s->source);
    else
        snprintf(who, sizeof who, "%s: [camera]", s->source);
    int view = scene_camera_view_check(&s->camera, s->render.width, s->render.height, why, sizeof why);
    if (view == 0 && scene_camera_check(&s->camera, why, sizeof why) == 0)
        return 0;
    if (view == 0 && s->camera.source == SCENE_CAMERA_DEFAULT) {
        /* The default camera of a scene near the coordinate limit stands beyond it, within the
         * headroom of the differences the renderers square (docs/scenes.md): said, not refused,
         * since a glTF file alone cannot name another camera. */
        if (scene_warn(s, "%s: %s; give the scene a camera (scene.ini [camera])", who, why) == 0)
            return 0;
        snprintf(err, errlen, "%s: out of memory", s->source);
        return -1;
    }
    snprintf(err, errlen, "%s: %s%s", who, why,
             s->camera.source == SCENE_CAMERA_DEFAULT ? "; give the scene a camera (scene.ini [camera])" : "");
    return -1;
}

/* Bounds, emissive triangles, default camera, needs. */
int scene_finish(Scene *s, char *err, size_t errlen)
{
    if (s->ntris == 0 && s->nspheres == 0) {
        if (s->skipped_primitives)
            snprintf(err, errlen, "%s: the scene has no geometry (its %u glTF primitives that are not triangles were "
                     "skipped)", s->source, s->skipped_primitives);
        else
            snprintf(err, errlen, "%s: the scene has no geometry", s->source);
        return -1;
    }
    if (check_geometry(s, err, errlen) != 0)
        return -1;
    for (int k = 0; k < 3; k++) {
        s->bounds_min[k] = INFINITY;
        s->bounds_max[k] = -INFINITY;
    }
    for (size_t i = 0; i < 9 * (size_t)s->ntris; i++) {
        int k = (int)(i % 3);
        s->bounds_min[k] = fminf(s->bounds_min[k], s->pos[i]);
        s->bounds_max[k] = fmaxf(s->bounds_max[k], s->pos[i]);
    }
    for (uint32_t j = 0; j < s->nspheres; j++)
        for (int k = 0; k < 3; k++) {
            s->bounds_min[k] = fminf(s->bounds_min[k], s->spheres[j].center[k] - s->spheres[j].radius);
            s->bounds_max[k] = fmaxf(s->bounds_max[k], s->spheres[j].center[k] + s->spheres[j].radius);
        }

    free(s->emissive_tris);
    s->emissive_tris = NULL;
    s->nemissive = 0;
    uint32_t *used = calloc(s->nmaterials ? s->nmaterials : 1, sizeof(uint32_t));
    if (!used) {
        snprintf(err, errlen, "%s: out of memory", s->source);
        return -1;
    }
    uint32_t nem = 0;
    for (uint32_t t = 0; t < s->ntris; t++) {
        const SceneMaterial *m = &s->materials[s->tri_material[t]];
        used[s->tri_material[t]] = 1;
        nem += m->emission[0] + m->emission[1] + m->emission[2] > 0.0f;
    }
    for (uint32_t j = 0; j < s->nspheres; j++)
        used[s->spheres[j].material] = 1;
    if (nem) {
        s->emissive_tris = malloc(sizeof(uint32_t) * nem);
        if (!s->emissive_tris) {
            free(used);
            snprintf(err, errlen, "%s: out of memory", s->source);
            return -1;
        }
        for (uint32_t t = 0; t < s->ntris; t++) {
            const SceneMaterial *m = &s->materials[s->tri_material[t]];
            if (m->emission[0] + m->emission[1] + m->emission[2] > 0.0f)
                s->emissive_tris[s->nemissive++] = t;
        }
    }

    if (s->camera.source == SCENE_CAMERA_DEFAULT) {
        /* Look at the centre of the bounds from +z, 45 degrees vertically, from the distance at
         * which the bounding sphere fits the narrower of the two fields of view, plus 5%. */
        double c[3], r = 0.0;
        for (int k = 0; k < 3; k++) {
            c[k] = 0.5 * ((double)s->bounds_min[k] + s->bounds_max[k]);
            double h = 0.5 * ((double)s->bounds_max[k] - s->bounds_min[k]);
            r += h * h;
        }
        r = sqrt(r);
        if (!(r > 0.0))
            r = 1.0;
        double half_y = 0.5 * 45.0 * M_PI / 180.0, aspect = (double)s->render.width / (double)s->render.height;
        double half = aspect < 1.0 ? atan(tan(half_y) * aspect) : half_y;
        float d = (float)(1.05 * r / sin(half));
        for (int k = 0; k < 3; k++) {
            s->camera.look_at[k] = (float)c[k];
            s->camera.position[k] = (float)c[k];
            s->camera.up[k] = 0.0f;
        }
        s->camera.position[2] += d;
        s->camera.up[1] = 1.0f;
        s->camera.fov_y = 45.0f;
        s->camera.aperture = 0.0f;
        s->camera.focus_distance = 0.0f;
    }

    uint32_t needs = 0;
    for (uint32_t i = 0; i < s->nmaterials; i++) {
        if (!used[i])
            continue;
        const SceneMaterial *m = &s->materials[i];
        if (m->emission[0] + m->emission[1] + m->emission[2] > 0.0f) {
            /* a light: shaded by the hit-light filter, not a material shader -- unless its
             * emissive texture makes it partly dark, when it is also shaded (docs/scenes.md) */
            if (m->emissive_texture < 0 || !s->uv_emit)
                continue;
            needs |= SCENE_NEED_EMISSIVE_TEXTURES;
        }
        needs |= m->kind == SCENE_MAT_LAMBERT ? SCENE_NEED_LAMBERT
               : m->kind == SCENE_MAT_GLOSSY ? SCENE_NEED_GLOSSY : SCENE_NEED_DIELECTRIC;
        if (m->base_texture >= 0 && s->uv)
            needs |= SCENE_NEED_TEXTURES;
        if (m->alpha_mode != SCENE_ALPHA_OPAQUE)
            needs |= SCENE_NEED_ALPHA;
    }
    free(used);
    if (check_camera(s, err, errlen) != 0)
        return -1;
    if (s->col && s->ntris)
        needs |= SCENE_NEED_VERTEX_COLORS;
    if (s->nspheres)
        needs |= SCENE_NEED_SPHERES;
    if (s->nemissive)
        needs |= SCENE_NEED_AREA_LIGHTS;
    for (uint32_t i = 0; i < s->nlights; i++)
        needs |= s->lights[i].kind == SCENE_LIGHT_QUAD ? SCENE_NEED_AREA_LIGHTS : SCENE_NEED_PUNCTUAL;
    if (s->render.background[0] + s->render.background[1] + s->render.background[2] > 0.0f)
        needs |= SCENE_NEED_BACKGROUND;
    if (s->render.ambient[0] + s->render.ambient[1] + s->render.ambient[2] > 0.0f)
        needs |= SCENE_NEED_AMBIENT;
    s->needs = needs;
    return 0;
}

/* ---- limits of scene values (scene.h's SCENE_LIMITS; docs/scenes.md) ------------------------ */

static const struct {
    double value;
    const char *what;
} limits[SCENE_LIMIT_COUNT] = {
#define SCENE_LIMIT_ROW(name, value, what) {value, what},
    SCENE_LIMITS(SCENE_LIMIT_ROW)
#undef SCENE_LIMIT_ROW
};

double scene_limit(SceneLimit k)
{
    return limits[k].value;
}

int scene_limit_check(SceneLimit k, const double *v, int n, char *why, size_t len)
{
    int bad = -1, nonfinite = 0;
    for (int i = 0; i < n; i++) {
        if (!isfinite(v[i])) {
            bad = i;
            nonfinite = 1;
            break;
        }
        if (bad < 0 && fabs(v[i]) > limits[k].value)
            bad = i;
    }
    if (bad < 0)
        return 0;
    char shown[160];
    size_t u = 0;
    if (n > 1)
        shown[u++] = '(';
    for (int i = 0; i < n && u < sizeof shown - 24; i++)
        u += (size_t)snprintf(shown + u, sizeof shown - u, "%s%g", i ? ", " : "", v[i]);
    if (n > 1)
        snprintf(shown + u, sizeof shown - u, ")");
    else
        shown[u] = 0;
    if (nonfinite)
        snprintf(why, len, "is not finite %s%s%s", n > 1 ? "" : "(", shown, n > 1 ? "" : ")");
    else
        snprintf(why, len, "is %s, beyond the limit of %g on %s (docs/scenes.md, Limits of scene values)", shown,
                 limits[k].value, limits[k].what);
    return -1;
}

int scene_limit_check1(SceneLimit k, double v, char *why, size_t len)
{
    return scene_limit_check(k, &v, 1, why, len);
}

double scene_cross_norm(const float *a, const float *b, const float *c)
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = (double)b[k] - a[k];
        e2[k] = (double)c[k] - a[k];
    }
    double x = e1[1] * e2[2] - e1[2] * e2[1], y = e1[2] * e2[0] - e1[0] * e2[2], z = e1[0] * e2[1] - e1[1] * e2[0];
    return sqrt(x * x + y * y + z * z);
}

/* The camera ray's origin is the position plus a point of the lens (radius aperture / 2). */
int scene_camera_check(const SceneCamera *c, char *why, size_t len)
{
    char w[320];
    double pos[3], at[3], lens[3], r = 0.5 * (double)c->aperture;
    for (int k = 0; k < 3; k++) {
        pos[k] = c->position[k];
        at[k] = c->look_at[k];
        lens[k] = fabs(pos[k]) + r;
    }
    if (scene_limit_check(SCENE_LIMIT_COORD, pos, 3, w, sizeof w) != 0) {
        snprintf(why, len, "position %s", w);
        return -1;
    }
    if (scene_limit_check(SCENE_LIMIT_COORD, at, 3, w, sizeof w) != 0) {
        snprintf(why, len, "look_at %s", w);
        return -1;
    }
    if (scene_limit_check(SCENE_LIMIT_COORD, lens, 3, w, sizeof w) != 0) {
        snprintf(why, len, "the lens (position +- aperture / 2, aperture %g) %s", (double)c->aperture, w);
        return -1;
    }
    return 0;
}

/* A camera ray's direction, before the renderers normalize it (scenes/pack.c's vectors), reaches
 * the image plane at the focus distance d: at most d sqrt(1 + t^2 (1 + aspect^2)) + aperture / 2
 * long, with t = tan(fov_y / 2). */
int scene_camera_view_check(const SceneCamera *c, int width, int height, char *why, size_t len)
{
    char w[320];
    double d = 0.0, r = 0.5 * (double)c->aperture;
    for (int k = 0; k < 3; k++)
        d += ((double)c->look_at[k] - c->position[k]) * ((double)c->look_at[k] - c->position[k]);
    d = c->focus_distance > 0.0f ? (double)c->focus_distance : sqrt(d);
    double t = tan(0.5 * (double)c->fov_y * M_PI / 180.0);
    double aspect = (double)width / (double)(height > 0 ? height : 1);
    double ray = d * sqrt(1.0 + t * t * (1.0 + aspect * aspect)) + r;
    if (scene_limit_check1(SCENE_LIMIT_VIEW, ray, w, sizeof w) != 0) {
        snprintf(why, len, "ray length (focus distance %g, fov_y %g, for a %d x %d image) %s", d, (double)c->fov_y,
                 width, height, w);
        return -1;
    }
    return 0;
}

int scene_load(const char *path, Scene *s, char *err, size_t errlen)
{
    scene_init(s, path);
    int rc;
    if (ends_with(path, ".ini"))
        rc = scene_file_load(path, s, err, errlen);
    else if (ends_with(path, ".gltf") || ends_with(path, ".glb"))
        rc = gltf_append(path, NULL, s, err, errlen);
    else if (ends_with(path, ".obj"))
        rc = obj_append(path, NULL, s, err, errlen);
    else {
        snprintf(err, errlen, "%s: unknown scene type (expected .gltf, .glb, .obj or .ini)", path);
        rc = -1;
    }
    if (rc == 0)
        rc = scene_finish(s, err, errlen);
    if (rc != 0)
        scene_free(s);
    return rc;
}

void scene_free(Scene *s)
{
    for (uint32_t i = 0; i < s->nmaterials; i++)
        free(s->materials[i].name);
    for (uint32_t i = 0; i < s->ntextures; i++) {
        free(s->textures[i].name);
        free(s->textures[i].rgba);
    }
    for (uint32_t i = 0; i < s->nlights; i++)
        free(s->lights[i].name);
    for (uint32_t i = 0; i < s->nspheres; i++)
        free(s->spheres[i].name);
    free(s->pos);
    free(s->nrm);
    free(s->uv);
    free(s->uv_emit);
    free(s->col);
    free(s->tri_material);
    free(s->materials);
    free(s->textures);
    free(s->lights);
    free(s->emissive_tris);
    free(s->spheres);
    free(s->source);
    free(s->camera_from);
    for (uint32_t i = 0; i < s->nwarnings; i++)
        free(s->warnings[i]);
    free(s->warnings);
    memset(s, 0, sizeof *s);
}

int scene_warn(Scene *s, const char *fmt, ...)
{
    char **w = realloc(s->warnings, sizeof *w * ((size_t)s->nwarnings + 1));
    if (!w)
        return -1;
    s->warnings = w;
    va_list ap;
    va_start(ap, fmt);
    int n = vasprintf(&w[s->nwarnings], fmt, ap);
    va_end(ap);
    if (n < 0)
        return -1;
    s->nwarnings++;
    return 0;
}

void scene_needs_string(uint32_t needs, char *buf, size_t len)
{
    size_t n = 0;
    if (len)
        buf[0] = 0;
#define NEED_NAME(bit, name)                                                                     \
    if ((needs & (bit)) && n < len)                                                              \
        n += (size_t)snprintf(buf + n, len - n, "%s%s", n ? "," : "", name);
    SCENE_NEED_LIST(NEED_NAME)
#undef NEED_NAME
}
