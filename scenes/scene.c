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
