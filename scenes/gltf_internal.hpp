// scenes/gltf_internal.hpp -- what the files of the glTF shim share (scenes/gltf_*.cpp only).
//
// Owns: the loader's state (Loader), the checked accessor view (View), the matrix type, the
// material bookkeeping (MatInfo, UvMap, EmitMap), the stash of encoded images, and the
// declarations of the functions one shim file calls in another:
//   gltf_load.cpp      the C entry points, file and extension checks, the tinygltf parse, the
//                      node hierarchy's checks, commit into the Scene, message helpers
//   gltf_accessor.cpp  accessors and their bufferViews, sparse substitution
//   gltf_material.cpp  materials, image decoding, textures, KHR_texture_transform, emissive maps
//   gltf_mesh.cpp      primitives into the Scene's triangle arrays
//   gltf_node.cpp      node transforms and the walk over them, cameras, KHR_lights_punctual
// Must not: be included outside scenes/gltf_*.cpp (the C face is scenes/gltf.h), or let a C++
// exception or a tinygltf type reach C code.
#ifndef SFSIM_GLTF_INTERNAL_HPP
#define SFSIM_GLTF_INTERNAL_HPP

#include <tiny_gltf.h>

#include <cstddef>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

extern "C" {
#include "gltf.h"
#include "shim_util.hpp"
}

namespace sfgltf {

// ---- small matrix helpers (double precision; column-major like glTF): gltf_node.cpp ----------

struct Mat4 {
    double m[16];
};

Mat4 identity();
Mat4 mul(const Mat4 &a, const Mat4 &b);
void xform_point(const Mat4 &m, const double *p, double *out);
void xform_dir(const Mat4 &m, const double *p, double *out);
double det3(const Mat4 &m);
// The inverse transpose of the upper 3x3 (column-major 3x3), which carries normals; false for a
// singular matrix.
bool normal_matrix(const Mat4 &m, double *out);
bool normalize(double *v);

// ---- names for messages: gltf_load.cpp --------------------------------------------------------

// "kind index 'name'" (without the name when it is empty).
std::string elem(const char *kind, int index, const std::string &name);
const char *mode_name(int mode);
const char *ctype_name(int ctype);
using scene_shim::num;      // scenes/shim_util.hpp
using scene_shim::one_line;

// ---- the loader's shared types ----------------------------------------------------------------

// A checked view of an accessor's data: element i, component k, as a double (normalized
// integers mapped to [0,1] or [-1,1] as glTF 2.0 Sec. 3.11 says).
struct View {
    const unsigned char *base = nullptr;
    size_t stride = 0, count = 0;
    int ctype = 0, ncomp = 0;
    bool normalized = false;

    double get(size_t i, int k) const
    {
        const unsigned char *p = base + i * stride;
        switch (ctype) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float f;
            std::memcpy(&f, p + 4 * k, 4);
            return f;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[k] / 255.0 : p[k];
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            double v = (signed char)p[k];
            return normalized ? std::fmax(v / 127.0, -1.0) : v;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t u;
            std::memcpy(&u, p + 2 * k, 2);
            return normalized ? u / 65535.0 : u;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t u;
            std::memcpy(&u, p + 2 * k, 2);
            return normalized ? std::fmax(u / 32767.0, -1.0) : u;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t u;
            std::memcpy(&u, p + 4 * k, 4);
            return u;
        }
        default: return 0.0;
        }
    }

    uint32_t index(size_t i) const
    {
        const unsigned char *p = base + i * stride;
        switch (ctype) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return p[0];
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t u;
            std::memcpy(&u, p, 2);
            return u;
        }
        default: {
            uint32_t u;
            std::memcpy(&u, p, 4);
            return u;
        }
        }
    }
};

// Images kept encoded while tinygltf parses, decoded only when a material uses them
// (gltf_load.cpp's image callback fills it; gltf_material.cpp's decode_image reads it).
struct Stash {
    std::vector<std::vector<unsigned char>> encoded; // by image index
};

// Emissive texture analysis: which texels emit, as an OR pyramid for conservative rectangle
// queries (the emitting part of a material with an emissive texture, see load_materials).
struct EmitMap {
    int w = 0, h = 0;
    std::vector<std::vector<unsigned char>> lv; // level k: ceil(w / 2^k) x ceil(h / 2^k) flags
    std::vector<int> lw, lh;

    bool any(int x0, int x1, int y0, int y1) const // inclusive texel ranges inside the image
    {
        size_t k = 0;
        while (k + 1 < lv.size() && ((x1 >> k) - (x0 >> k) > 3 || (y1 >> k) - (y0 >> k) > 3))
            k++;
        for (int y = y0 >> k; y <= (y1 >> k); y++)
            for (int x = x0 >> k; x <= (x1 >> k); x++)
                if (lv[k][(size_t)y * (size_t)lw[k] + (size_t)x])
                    return true;
        return false;
    }
};

// Where a texture reads its coordinates: the TEXCOORD_<set> attribute through the affine map of
// KHR_texture_transform, u' = m0 u + m1 v + m2, v' = m3 u + m4 v + m5 (identity without one).
struct UvMap {
    int set = 0;
    double m[6] = {1, 0, 0, 0, 1, 0};
};

struct MatInfo {
    int index = -1;      // SceneMaterial index (absolute) of the material as loaded
    int emit_twin = -1;  // the emitting part when an emissive texture only partly emits, else -1
    bool emit_tex = false; // an emissive texture is sampled (by the material or its twin)
    UvMap base_uv, emit_uv;
    const EmitMap *map = nullptr;
};

struct Loader {
    const tinygltf::Model &m;
    std::string file;
    Scene *s;
    Mat4 pre = identity();
    std::string err;
    const Stash *stash = nullptr;
    bool quantized = false; // KHR_mesh_quantization: integer positions, normals, texcoords are legal
    uint32_t mat_base = 0, tex_base = 0;
    std::vector<int> image_to_tex; // image index -> absolute SceneTexture index, -1 not decoded
    std::vector<MatInfo> minfo;    // by glTF material index
    std::vector<EmitMap> maps;     // by local texture index (empty map: not analysed)
    std::deque<std::vector<unsigned char>> dense; // sparse accessors, substituted (Views point here)
    int default_mat = -1;
    // Triangles go straight into the Scene's arrays, after its `old` triangles; only commit()
    // makes them count (Scene.ntris), so a failed file leaves the Scene as it was, with larger
    // arrays. Materials, textures and lights wait here until commit().
    size_t old = 0, cur = 0, cap = 0; // triangles: the Scene's, this file's so far, room for
    uint32_t primitives = 0, skipped[4] = {0, 0, 0, 0}; // primitives met; skipped by mode (POINTS..LINE_STRIP)
    std::vector<char> wrap_seen;  // by glTF texture: its sampler's wrap modes were looked at
    uint32_t not_repeat = 0;      // used textures whose sampler does not repeat (not applied)
    std::vector<SceneMaterial> mats;
    std::vector<SceneTexture> texs;
    std::vector<SceneLight> lights;
    bool camera_set = false;
    SceneCamera camera{};
    std::string camera_where; // "node 2 'cam': camera 0 'main'", for the camera's limit checks

    Loader(const tinygltf::Model &model, const char *name, Scene *scene) : m(model), file(name), s(scene) {}
    ~Loader()
    {
        for (auto &mm : mats)
            std::free(mm.name);
        for (auto &t : texs) {
            std::free(t.name);
            std::free(t.rgba);
        }
        for (auto &l : lights)
            std::free(l.name);
    }
    Loader(const Loader &) = delete;
    Loader &operator=(const Loader &) = delete;

    bool fail(const std::string &what)
    {
        if (err.empty())
            err = file + ": " + what;
        return false;
    }
    SceneMaterial &mat(int absolute) { return mats[(size_t)(absolute - (int)mat_base)]; }
};

// ---- gltf_accessor.cpp --------------------------------------------------------------------------

// The checked view of accessor `index` (sparse accessors substituted); `where` names its user.
bool accessor_view(Loader &L, int index, const std::string &where, View &v);
// FLOAT, or what KHR_mesh_quantization allows, or (allow_normalized) normalized UNSIGNED_BYTE/SHORT.
bool check_float_or_quantized(Loader &L, const View &v, const std::string &what, bool allow_normalized);

// ---- gltf_material.cpp --------------------------------------------------------------------------

// glTF materials -> SceneMaterial (ARCHITECTURE.md Sec. 1 mapping), with their textures.
bool load_materials(Loader &L);
// glTF's default material, added once per file on first use; its absolute index, -1 out of memory.
int default_material(Loader &L);
// Does the triangle with texture coordinates uv (3 x 2) touch an emitting texel?
bool uv_emits(const EmitMap &em, const double *uv);

// ---- gltf_mesh.cpp ------------------------------------------------------------------------------

// Room for `more` triangles after the ones written so far.
bool reserve(Loader &L, size_t more);
// Primitive pi of mesh `mesh`, every vertex through `full`, into the Scene's triangle arrays.
bool load_primitive(Loader &L, const Mat4 &full, int mesh, int pi);
// Triangles the primitives under `roots` will produce, so the arrays grow once.
size_t count_triangles(const Loader &L, const std::vector<int> &roots);

// ---- gltf_node.cpp ------------------------------------------------------------------------------

// Node `node` under the transform `parent`, then its children: meshes, the first camera, lights.
bool visit(Loader &L, int node, const Mat4 &parent, int depth);

} // namespace sfgltf

#endif
