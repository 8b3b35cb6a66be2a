/* scenes/scene.h -- a loaded scene: flattened world-space triangles, materials, textures, lights,
 * spheres, camera and render settings, and what the scene needs.
 *
 * Owns: the in-memory scene every later stage (BVH builder, scene-memory packing, golden model,
 * kernel selection) reads. Loaders fill it: scenes/gltf_*.cpp (glTF 2.0 through tinygltf) and
 * scenes/scene_file.c (scene.ini: a glTF reference plus camera, render, lights, spheres,
 * material overrides). Must not: build acceleration structures or know the simulated machine.
 *
 * Conventions: right-handed, y up (glTF); floats are binary32; colours are linear RGB.
 */
#ifndef SFSIM_SCENE_H
#define SFSIM_SCENE_H

#include <stddef.h>
#include <stdint.h>

typedef enum SceneMatKind {
    SCENE_MAT_LAMBERT = 0,    /* glTF: metallic == 0 and roughness == 1, no transmission */
    SCENE_MAT_GLOSSY = 1,     /* coupled glossy: metallic > 0 or roughness < 1 */
    SCENE_MAT_DIELECTRIC = 2  /* KHR_materials_transmission > 0 (ior from KHR_materials_ior) */
} SceneMatKind;

typedef enum SceneAlphaMode { SCENE_ALPHA_OPAQUE = 0, SCENE_ALPHA_MASK = 1, SCENE_ALPHA_BLEND = 2 } SceneAlphaMode;

typedef struct SceneMaterial {
    char *name;
    SceneMatKind kind;
    float base_color[3];      /* baseColorFactor rgb */
    float alpha;              /* baseColorFactor a */
    int base_texture;         /* index into textures, or -1 */
    float metallic, roughness;
    float ior;                /* 1.5 when not given */
    float transmission;
    float emission[3];        /* emissiveFactor x KHR_materials_emissive_strength */
    int emissive_texture;     /* index into textures, or -1 */
    SceneAlphaMode alpha_mode;
    float alpha_cutoff;
    int double_sided;
} SceneMaterial;

typedef struct SceneTexture {
    char *name;
    int width, height;
    float *rgba;              /* width*height*4, linear (sRGB-decoded for colour textures) */
} SceneTexture;

typedef enum SceneLightKind {
    SCENE_LIGHT_POINT = 0,
    SCENE_LIGHT_SPOT = 1,
    SCENE_LIGHT_DIRECTIONAL = 2,
    SCENE_LIGHT_QUAD = 3      /* a rectangle area light from scene.ini: corner + two edges */
} SceneLightKind;

typedef struct SceneLight {
    char *name;
    SceneLightKind kind;
    float position[3];        /* point, spot; quad: corner */
    float direction[3];       /* spot, directional: direction the light travels */
    float edge_u[3], edge_v[3]; /* quad */
    float color[3];
    float intensity;          /* point/spot: candela; directional: lux; quad: radiance scale */
    float inner_cone, outer_cone; /* spot, radians */
} SceneLight;

typedef struct SceneSphere {
    char *name;
    float center[3];
    float radius;
    int material;             /* index into materials */
} SceneSphere;

typedef struct SceneCamera {
    float position[3], look_at[3], up[3];
    float fov_y;              /* degrees, vertical */
    float aperture;           /* lens diameter in scene units; 0 = pinhole */
    float focus_distance;     /* 0 = distance from position to look_at */
    int source;               /* SceneCameraSource */
} SceneCamera;

typedef enum SceneCameraSource { SCENE_CAMERA_DEFAULT = 0, SCENE_CAMERA_GLTF = 1, SCENE_CAMERA_FILE = 2 } SceneCameraSource;

typedef struct SceneRender {
    int width, height;        /* default 512 x 512 */
    int spp;                  /* samples per pixel, default 1 */
    int max_depth;            /* default 3 (001 Sec. 4.2: three bounces) */
    float background[3];      /* radiance of rays that leave the scene; default 0 */
    float ambient[3];         /* constant ambient term (001's rtrt setting); default 0 = off */
} SceneRender;

/* What a scene needs: later stages model only these (ARCHITECTURE.md Sec. 3). */
enum {
    SCENE_NEED_LAMBERT     = 1u << 0,
    SCENE_NEED_GLOSSY      = 1u << 1,
    SCENE_NEED_DIELECTRIC  = 1u << 2,
    SCENE_NEED_TEXTURES    = 1u << 3,
    SCENE_NEED_SPHERES     = 1u << 4,
    SCENE_NEED_AREA_LIGHTS = 1u << 5,  /* emissive triangles or quad lights */
    SCENE_NEED_PUNCTUAL    = 1u << 6,  /* point, spot or directional lights */
    SCENE_NEED_ALPHA       = 1u << 7,  /* alpha mask or blend materials in use */
    SCENE_NEED_BACKGROUND  = 1u << 8,  /* non-zero background radiance */
    SCENE_NEED_AMBIENT     = 1u << 9,  /* constant ambient term */
    SCENE_NEED_EMISSIVE_TEXTURES = 1u << 10, /* an emitting material with an emissive texture */
    SCENE_NEED_VERTEX_COLORS = 1u << 11     /* COLOR_0 on some triangles */
};
#define SCENE_NEED_LIST(X) \
    X(SCENE_NEED_LAMBERT, "lambert") X(SCENE_NEED_GLOSSY, "glossy") \
    X(SCENE_NEED_DIELECTRIC, "dielectric") X(SCENE_NEED_TEXTURES, "textures") \
    X(SCENE_NEED_SPHERES, "spheres") X(SCENE_NEED_AREA_LIGHTS, "area_lights") \
    X(SCENE_NEED_PUNCTUAL, "punctual_lights") X(SCENE_NEED_ALPHA, "alpha") \
    X(SCENE_NEED_BACKGROUND, "background") X(SCENE_NEED_AMBIENT, "ambient") \
    X(SCENE_NEED_EMISSIVE_TEXTURES, "emissive_textures") X(SCENE_NEED_VERTEX_COLORS, "vertex_colors")

typedef struct Scene {
    /* Triangles, flattened to world space. */
    uint32_t ntris;
    float *pos;               /* ntris * 9: v0 v1 v2 */
    float *nrm;               /* ntris * 9 shading normals, or NULL when the file has none */
    float *uv;                /* ntris * 6 texture coordinates of the base-colour texture (its
                                 TEXCOORD set through its KHR_texture_transform), or NULL */
    float *uv_emit;           /* ntris * 6 texture coordinates of the emissive texture, the same
                                 way; NULL when no material samples one */
    float *col;               /* ntris * 9 vertex colours (COLOR_0 rgb, linear; 1 where a file has
                                 none), or NULL */
    uint32_t *tri_material;   /* ntris material indices */

    SceneMaterial *materials; uint32_t nmaterials;
    SceneTexture *textures;   uint32_t ntextures;
    SceneLight *lights;       uint32_t nlights;   /* punctual and quad lights */
    uint32_t *emissive_tris;  uint32_t nemissive; /* triangles whose material emits */
    SceneSphere *spheres;     uint32_t nspheres;

    SceneCamera camera;
    char *camera_from;        /* a glTF camera's file, node and camera ("x.gltf: node 2 'cam':
                                 camera 0 'main'"), for messages; NULL for other cameras */
    SceneRender render;
    float bounds_min[3], bounds_max[3];  /* of triangles and spheres */
    uint32_t needs;           /* SCENE_NEED_* */
    char *source;             /* the file the scene was loaded from */
    /* What the loaders left out: glTF primitives that are not triangles (POINTS, LINES,
     * LINE_LOOP, LINE_STRIP), skipped; and one line per thing left out or approximated, each
     * naming the file and the feature, for the caller to print (library code prints nothing). */
    uint32_t skipped_primitives;
    char **warnings;          uint32_t nwarnings;
} Scene;

/* The largest file a scene loader reads (a glTF, GLB, its buffers and images, an OBJ, its MTL files
 * and textures), through the one input check (host/infile.h): 16 GiB, far above the largest scenes
 * of the validation (the 5 M-triangle cases hold a few hundred MB). */
#define SCENE_FILE_MAX_BYTES (16ull << 30)

/* The limits of scene values, one row each: the largest magnitude a value of that kind may have
 * where it enters the renderers' binary32 arithmetic, and what messages call it. Every loader
 * checks against this table through scene_limit_check; docs/scenes.md ("Limits of scene values")
 * derives each limit from the arithmetic the value enters.
 *   COORD     positions: triangle vertices (after all transforms), the camera's position, look_at
 *             and lens, point and spot light positions, quad light corners, sphere boxes. The
 *             triangle test multiplies differences of coordinates pairwise, a light's shadow ray
 *             squares its length: (2e18)^2 x 3 = 1.2e37 < FLT_MAX = 3.4e38.
 *   AREA      |e1 x e2| of a triangle (twice its area) or a quad light (its area): normals and
 *             light areas square it (|e1 x e2|^2 <= FLT_MAX: 1.8e19).
 *   VIEW      a camera ray's direction before it is normalized: the focus distance x
 *             sqrt(1 + tan^2(fov_y / 2) (1 + aspect^2)) + aperture / 2, squared when it is
 *             normalized: 1e19^2 = 1e38 < FLT_MAX.
 *   RADIANCE  radiance: emission, a quad light's and a directional light's colour x intensity,
 *             background, ambient. Multiplied by the path's throughput and geometry; 1e18 leaves
 *             them a factor of 3.4e20.
 *   INTENSITY a point or spot light's colour x intensity (W/sr): divided by the squared distance
 *             it lights, so it scales with the scene's size squared. RADIANCE x AREA (1e36), what
 *             the largest quad light gives; colour x intensity / d^2 overflows only closer than
 *             sqrt(1e36 / FLT_MAX) = 0.054 to the light.
 *   REFLECTANCE a base colour: a warning above it, not a refusal (glTF allows 0..1, scene.ini
 *             any value >= 0). A Lambertian bounce multiplies the throughput by base x 2 / 0.95
 *             at most (the direct/indirect split, Russian roulette); with base <= 1 the deepest
 *             path (64 generations) gains at most 2.1^63 = 2.4e20 < FLT_MAX / RADIANCE.
 *   IOR       index of refraction: the refraction squares it.
 *   UV        texture coordinates (after KHR_texture_transform): interpolated at a hit.
 * SCENE_LIMIT(NAME, largest magnitude, what messages call it) */
#define SCENE_LIMITS(X)                                                                          \
    X(COORD, 1e18, "scene coordinates")                                                          \
    X(AREA, 1e18, "areas (|e1 x e2| of a triangle, the area of a quad light)")                   \
    X(VIEW, 1e19, "camera ray lengths (focus distance x the image plane's half-diagonal)")       \
    X(RADIANCE, 1e18, "radiance (emission, background, ambient, quad and directional lights)")   \
    X(INTENSITY, 1e36, "point and spot light intensities (colour x intensity)")                   \
    X(REFLECTANCE, 1, "reflectances (base colour)")                                               \
    X(IOR, 1e18, "indices of refraction")                                                         \
    X(UV, 1e18, "texture coordinates")

typedef enum SceneLimit {
#define SCENE_LIMIT_ENUM(name, value, what) SCENE_LIMIT_##name,
    SCENE_LIMITS(SCENE_LIMIT_ENUM)
#undef SCENE_LIMIT_ENUM
    SCENE_LIMIT_COUNT
} SceneLimit;

/* The largest magnitude of a value of kind k. */
double scene_limit(SceneLimit k);
/* Checks n values of kind k: 0 when each is finite and within the limit; else -1 with why the
 * caller's "LOCATION: VALUE " is refused: "is not finite (nan)", or "is 1e+30, beyond the limit
 * of 1e+18 on scene coordinates (docs/scenes.md, Limits of scene values)" (n > 1: "is (0, 0,
 * 1e+30), ..."). */
int scene_limit_check(SceneLimit k, const double *v, int n, char *why, size_t len);
/* The same for one value that must be at most limit(k) and is not itself written in the file
 * (a derived quantity): "is 2e+20, beyond ...". */
int scene_limit_check1(SceneLimit k, double v, char *why, size_t len);
/* |e1 x e2| for the edges b - a and c - a, in double (what AREA limits). */
double scene_cross_norm(const float *a, const float *b, const float *c);
/* The camera's positions (position, look_at and the lens within COORD): 0, or -1 with
 * "position is (...), beyond ..." naming the value. */
int scene_camera_check(const SceneCamera *c, char *why, size_t len);
/* Its ray lengths (VIEW) for a width x height image: 0, or -1 with "ray length (...) is ...".
 * scene_finish checks the scene's own [render] size; a caller that imposes another size checks
 * again. */
int scene_camera_view_check(const SceneCamera *c, int width, int height, char *why, size_t len);

/* Load a scene: a .gltf/.glb file, or a scene.ini that names one. Fills every field (defaults,
 * camera framing the bounds when none is given, needs). 0, or -1 with a message naming the file
 * and the element ("scene.glb: accessor 3: index 812 out of range (count 500)"). */
int scene_load(const char *path, Scene *s, char *err, size_t errlen);
void scene_free(Scene *s);

/* For loaders and tests: an empty scene with the defaults (512 x 512, 1 spp, max depth 3), and
 * the completion step scene_load runs after the sources are read (bounds, emissive triangles,
 * default camera, needs; an error for a scene without geometry). */
void scene_init(Scene *s, const char *source);
int scene_finish(Scene *s, char *err, size_t errlen);

/* For loaders: adds a warning line (printf format). 0, or -1 when out of memory. */
int scene_warn(Scene *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Writes the needs as a comma-separated list ("lambert,area_lights"). */
void scene_needs_string(uint32_t needs, char *buf, size_t len);

#endif
