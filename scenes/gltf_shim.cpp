// scenes/gltf_shim.cpp -- glTF 2.0 through tinygltf (Debian's libtinygltf 2.7), behind a C API.
//
// Owns: walking a glTF document (default scene, node transforms, meshes, accessors with their
// sparse substitution, materials, base-colour and emissive textures with their texture
// coordinates and KHR_texture_transform, vertex colours, KHR_lights_punctual, the first camera)
// and validating everything it reads, so a malformed file gives an error naming the file and the
// element instead of a crash; what it leaves out (points, lines, sampler wrap modes) becomes a
// warning line in the Scene; external files are read only inside the glTF file's folder. Must
// not: pick scene defaults, compute bounds or needs (scenes/scene.c), build acceleration
// structures, or print anything.
//
// The only C++ in the project besides the OpenImageIO shim (ARCHITECTURE.md Sec. 2). Exceptions
// never cross the C boundary.
// The fuzz build (tests/fuzz/fuzz_scene.c) compiles tinygltf and stb_image into this file, so
// the sanitizers and the fuzzer's coverage reach inside them; every other build links Debian's
// libtinygltf.
#ifdef SFSIM_TINYGLTF_IMPLEMENTATION
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE_WRITE
#endif
#include <tiny_gltf.h>

#include <cerrno>
#include <deque>
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>

extern "C" {
#include "gltf.h"
}

namespace {

// ---- small matrix helpers (double precision; column-major like glTF) --------------------------

struct Mat4 {
    double m[16];
};

Mat4 identity()
{
    Mat4 r{};
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0;
    return r;
}

Mat4 mul(const Mat4 &a, const Mat4 &b)
{
    Mat4 r{};
    for (int c = 0; c < 4; c++)
        for (int row = 0; row < 4; row++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a.m[k * 4 + row] * b.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

void xform_point(const Mat4 &m, const double *p, double *out)
{
    for (int r = 0; r < 3; r++)
        out[r] = m.m[r] * p[0] + m.m[4 + r] * p[1] + m.m[8 + r] * p[2] + m.m[12 + r];
}

void xform_dir(const Mat4 &m, const double *p, double *out)
{
    for (int r = 0; r < 3; r++)
        out[r] = m.m[r] * p[0] + m.m[4 + r] * p[1] + m.m[8 + r] * p[2];
}

double det3(const Mat4 &m)
{
    return m.m[0] * (m.m[5] * m.m[10] - m.m[9] * m.m[6]) - m.m[4] * (m.m[1] * m.m[10] - m.m[9] * m.m[2]) +
           m.m[8] * (m.m[1] * m.m[6] - m.m[5] * m.m[2]);
}

// The inverse transpose of the upper 3x3 (column-major 3x3), which carries normals; false for a
// singular matrix.
bool normal_matrix(const Mat4 &m, double *out)
{
    double a = m.m[0], b = m.m[4], c = m.m[8], d = m.m[1], e = m.m[5], f = m.m[9], g = m.m[2], h = m.m[6],
           i = m.m[10];
    double det = det3(m);
    if (!(std::fabs(det) > 1e-300) || !std::isfinite(det))
        return false;
    // The cofactor matrix divided by the determinant is the inverse transpose.
    double cof[9] = {e * i - f * h, -(d * i - f * g), d * h - e * g, -(b * i - c * h), a * i - c * g,
                     -(a * h - b * g), b * f - c * e, -(a * f - c * d), a * e - b * d};
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            out[col * 3 + r] = cof[r * 3 + col] / det;
    return true;
}

bool normalize(double *v)
{
    double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0) || !std::isfinite(l))
        return false;
    for (int k = 0; k < 3; k++)
        v[k] /= l;
    return true;
}

// ---- names for messages ----------------------------------------------------------------------

std::string elem(const char *kind, int index, const std::string &name)
{
    std::string r = std::string(kind) + " " + std::to_string(index);
    if (!name.empty())
        r += " '" + name + "'";
    return r;
}

const char *mode_name(int mode)
{
    switch (mode) {
    case TINYGLTF_MODE_POINTS: return "POINTS";
    case TINYGLTF_MODE_LINE: return "LINES";
    case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
    case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
    case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
    case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
    case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
    default: return "unknown";
    }
}

const char *ctype_name(int ctype)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    default: return "unknown";
    }
}

// A number for messages, as printf's %g writes it (1e+30, 0.5, inf).
std::string num(double x)
{
    char b[32];
    std::snprintf(b, sizeof b, "%g", x);
    return b;
}

// One line from tinygltf's multi-line error and warning text.
std::string one_line(std::string s)
{
    for (char &c : s)
        if (c == '\n' || c == '\r')
            c = ' ';
    while (!s.empty() && s.back() == ' ')
        s.pop_back();
    return s;
}

// ---- accessors -------------------------------------------------------------------------------

int component_size(int ctype)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0; // INT is not a legal glTF accessor component type
    }
}

int type_components(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0; // matrices never describe vertices or indices
    }
}

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

// ---- images: kept encoded while tinygltf parses, decoded only when a material uses them --------

// tinygltf calls this for images given by data URI or external file (the bytes are ours to copy)
// and for images in a bufferView. The latter are not touched here: tinygltf 2.7 hands over
// &buffer.data[byteOffset] without checking that the view lies inside its buffer, so those bytes
// are read later, after our own check (decode_image). Decoding lazily also skips normal, occlusion
// and metallic-roughness maps, which nothing here uses.
struct Stash {
    std::vector<std::vector<unsigned char>> encoded; // by image index
};

bool keep_encoded(tinygltf::Image *image, const int idx, std::string *, std::string *, int, int,
                  const unsigned char *bytes, int size, void *user)
{
    Stash *st = static_cast<Stash *>(user);
    if (image->bufferView >= 0 || idx < 0 || size <= 0)
        return true;
    if ((size_t)idx >= st->encoded.size())
        st->encoded.resize((size_t)idx + 1);
    st->encoded[(size_t)idx].assign(bytes, bytes + size);
    return true;
}

// Loading from memory (the fuzzer, tests) never reads files: only data URIs and the GLB chunk.
bool no_file_exists(const std::string &, void *) { return false; }
std::string same_path(const std::string &p, void *) { return p; }
bool no_read(std::vector<unsigned char> *, std::string *err, const std::string &path, void *)
{
    if (err)
        *err += "external file '" + path + "' cannot be read when loading from memory\n";
    return false;
}
bool no_write(std::string *err, const std::string &, const std::vector<unsigned char> &, void *)
{
    if (err)
        *err += "writing is not supported\n";
    return false;
}

// Loading from a file: external buffers and images are read by tinygltf, but through this reader,
// which refuses what is not a regular file (tinygltf sizes a file by seeking to its end, and a
// directory or device answers with nonsense such as 2^63 bytes), and what lies outside the glTF
// file's folder (a uri such as ../../etc/passwd) unless SFSIM_ALLOW_OUTSIDE_URIS=1 says otherwise.
struct FsContext {
    std::string base;     // the glTF file's folder as tinygltf joins uris to it ("" or "dir/")
    std::string root;     // the same, absolute and normalized, ending in '/'
    std::string real;     // the same through realpath (symbolic links resolved), ending in '/'
    bool allow_outside = false;
    std::string refused;  // the first uri refused, as the file wrote it
};

// path made absolute (from the working directory) with "." and ".." resolved by name alone.
std::string lexical_path(const std::string &path)
{
    std::string full = path;
    if (full.empty() || full[0] != '/') {
        char cwd[4096];
        if (!getcwd(cwd, sizeof cwd))
            return std::string();
        full = std::string(cwd) + "/" + full;
    }
    std::vector<std::string> parts;
    size_t i = 0;
    while (i <= full.size()) {
        size_t j = full.find('/', i);
        if (j == std::string::npos)
            j = full.size();
        std::string part = full.substr(i, j - i);
        if (part == "..") {
            if (!parts.empty())
                parts.pop_back();
        } else if (!part.empty() && part != ".") {
            parts.push_back(part);
        }
        i = j + 1;
    }
    std::string out;
    for (const auto &part : parts)
        out += "/" + part;
    return out.empty() ? "/" : out;
}

bool under(const std::string &path, const std::string &dir) { return path.compare(0, dir.size(), dir) == 0; }

// Whether `path` stays inside the folder: by name, and, when it exists, through symbolic links.
bool inside_folder(const FsContext &c, const std::string &path)
{
    if (!under(lexical_path(path), c.root))
        return false;
    char *r = realpath(path.c_str(), nullptr);
    if (!r)
        return true; // does not exist: the read reports it
    bool in = under(std::string(r), c.real);
    std::free(r);
    return in;
}

bool regular_file_exists(const std::string &path, void *user)
{
    const FsContext *c = static_cast<const FsContext *>(user);
    if (c && !c->allow_outside && !inside_folder(*c, path))
        // tinygltf tries the file's folder, then the working directory. A uri that leaves the
        // folder "exists", so the read below refuses it whether or not it does (its existence is
        // not revealed); the working-directory fallback is simply not searched.
        return c->base.empty() || under(path, c->base);
    struct stat st;
    return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool read_regular_file(std::vector<unsigned char> *out, std::string *err, const std::string &path, void *user)
{
    FsContext *c = static_cast<FsContext *>(user);
    if (c && !c->allow_outside && !inside_folder(*c, path)) {
        std::string uri = under(path, c->base) ? path.substr(c->base.size()) : path;
        if (c->refused.empty())
            c->refused = uri;
        if (err)
            *err += "'" + uri + "' lies outside the glTF file's folder\n";
        return false;
    }
    struct stat st;
    if (stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
        if (err)
            *err += "'" + path + "' is not a regular file\n";
        return false;
    }
    FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) {
        if (err)
            *err += "cannot open '" + path + "': " + std::strerror(errno) + "\n";
        return false;
    }
    out->resize((size_t)st.st_size);
    size_t n = out->empty() ? 0 : std::fread(out->data(), 1, out->size(), f);
    std::fclose(f);
    if (n != out->size()) {
        if (err)
            *err += "cannot read '" + path + "'\n";
        return false;
    }
    return true;
}

float srgb8_table[256];
bool srgb8_ready = false;

float srgb_to_linear(double c)
{
    return (float)(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

// ---- the loader ------------------------------------------------------------------------------

// Emissive texture analysis: which texels emit, as an OR pyramid for conservative rectangle
// queries (the emitting part of a material with an emissive texture, see split_emissive).
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

// Checks that `count` elements of elem_size bytes, stride bytes apart, lie inside bufferView bvi
// from byte offset `offset`; sets `data` to the first. `an` names the accessor in messages,
// `what` the part of it ("", " sparse indices", " sparse values").
bool view_range(Loader &L, const std::string &an, const char *what, int bvi, size_t offset, size_t count,
                size_t elem_size, size_t stride, const unsigned char *&data)
{
    const auto &m = L.m;
    if (bvi < 0 || (size_t)bvi >= m.bufferViews.size())
        return L.fail(an + ":" + what + " has no data (bufferView " + std::to_string(bvi) + ")");
    const auto &bv = m.bufferViews[(size_t)bvi];
    if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
        return L.fail(an + ":" + what + " bufferView " + std::to_string(bvi) + " names missing buffer " +
                      std::to_string(bv.buffer));
    const auto &buf = m.buffers[(size_t)bv.buffer];
    size_t size = buf.data.size();
    // Every sum below is checked against overflow before it is formed.
    std::string where_buf = " (bufferView " + std::to_string(bvi) + ": offset " + std::to_string(bv.byteOffset) +
                            ", length " + std::to_string(bv.byteLength) + "; buffer " + std::to_string(bv.buffer) +
                            ": " + std::to_string(size) + " bytes)";
    if (bv.byteOffset > size || bv.byteLength > size - bv.byteOffset)
        return L.fail(an + ":" + what + " bufferView lies outside its buffer" + where_buf);
    if (count) {
        if (offset > bv.byteLength || elem_size > bv.byteLength - offset ||
            count - 1 > (bv.byteLength - offset - elem_size) / stride)
            return L.fail(an + ":" + what + " " + std::to_string(count) + " elements at offset " +
                          std::to_string(offset) + " run past the end of the bufferView" + where_buf);
    }
    data = buf.data.data() + bv.byteOffset + (count ? offset : 0);
    return true;
}

// The sparse substitution of glTF 2.0 Sec. 3.6.2.3: a dense copy of the accessor (its bufferView's
// elements, or zeros without one) with sparse.count elements replaced; v then reads the copy.
bool apply_sparse(Loader &L, const tinygltf::Accessor &a, const std::string &an, size_t elem_size, View &v)
{
    const auto &sp = a.sparse;
    std::string sn = an + ": sparse";
    if (sp.count < 1 || (size_t)sp.count > a.count)
        return L.fail(sn + " count " + std::to_string(sp.count) + " is not between 1 and the accessor's count (" +
                      std::to_string(a.count) + ")");
    int ics = sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE    ? 1
              : sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ? 2
              : sp.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT   ? 4
                                                                                   : 0;
    if (!ics)
        return L.fail(sn + " indices: component type " + ctype_name(sp.indices.componentType) +
                      " is not UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT");
    if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0)
        return L.fail(sn + ": negative byteOffset");
    size_t n = (size_t)sp.count;
    const unsigned char *ip, *vp;
    if (!view_range(L, an, " sparse indices", sp.indices.bufferView, (size_t)sp.indices.byteOffset, n, (size_t)ics,
                    (size_t)ics, ip) ||
        !view_range(L, an, " sparse values", sp.values.bufferView, (size_t)sp.values.byteOffset, n, elem_size,
                    elem_size, vp))
        return false;
    if (a.count > ((size_t)1 << 31) / elem_size)
        return L.fail(an + ": " + std::to_string(a.count) + " elements are too many for a sparse accessor");
    L.dense.emplace_back(a.count * elem_size, (unsigned char)0);
    std::vector<unsigned char> &d = L.dense.back();
    if (v.base)
        for (size_t i = 0; i < a.count; i++)
            std::memcpy(&d[i * elem_size], v.base + i * v.stride, elem_size);
    View iv;
    iv.base = ip;
    iv.stride = (size_t)ics;
    iv.count = n;
    iv.ctype = sp.indices.componentType;
    iv.ncomp = 1;
    for (size_t i = 0; i < n; i++) {
        uint32_t at = iv.index(i);
        // glTF 2.0 Sec. 5.3: indices strictly increasing, each below the accessor's count.
        if (at >= a.count)
            return L.fail(sn + " index " + std::to_string(i) + " is " + std::to_string(at) +
                          ", out of range (accessor count " + std::to_string(a.count) + ")");
        if (i > 0 && at <= iv.index(i - 1))
            return L.fail(sn + " index " + std::to_string(i) + " is " + std::to_string(at) +
                          ", not greater than the one before (" + std::to_string(iv.index(i - 1)) +
                          "): sparse indices must increase strictly");
        std::memcpy(&d[(size_t)at * elem_size], vp + i * elem_size, elem_size);
    }
    v.base = d.data();
    v.stride = elem_size;
    return true;
}

bool accessor_view(Loader &L, int index, const std::string &where, View &v)
{
    const auto &m = L.m;
    if (index < 0 || (size_t)index >= m.accessors.size())
        return L.fail(where + ": accessor " + std::to_string(index) + " does not exist");
    const auto &a = m.accessors[(size_t)index];
    std::string an = where + ": " + elem("accessor", index, a.name);
    int cs = component_size(a.componentType), nc = type_components(a.type);
    if (!cs)
        return L.fail(an + ": component type " + std::to_string(a.componentType) + " is not a glTF accessor type");
    if (!nc)
        return L.fail(an + ": type " + std::to_string(a.type) + " is not SCALAR or VEC2..VEC4");
    size_t elem_size = (size_t)cs * (size_t)nc, stride = elem_size;
    v = View();
    // A sparse accessor without a bufferView starts from zeros (glTF 2.0 Sec. 3.6.2.3).
    if (a.bufferView >= 0 || !a.sparse.isSparse) {
        if (a.bufferView >= 0 && (size_t)a.bufferView < m.bufferViews.size()) {
            const auto &bv = m.bufferViews[(size_t)a.bufferView];
            stride = bv.byteStride ? bv.byteStride : elem_size;
            if (stride < elem_size)
                return L.fail(an + ": byteStride " + std::to_string(bv.byteStride) +
                              " is smaller than an element (" + std::to_string(elem_size) + " bytes)");
        }
        if (!view_range(L, an, "", a.bufferView, a.byteOffset, a.count, elem_size, stride, v.base))
            return false;
        v.stride = stride;
    }
    v.count = a.count;
    v.ctype = a.componentType;
    v.ncomp = nc;
    v.normalized = a.normalized;
    if (a.sparse.isSparse && !apply_sparse(L, a, an, elem_size, v))
        return false;
    return true;
}

double ext_number(const tinygltf::ExtensionMap &ext, const char *name, const char *key, double def)
{
    auto it = ext.find(name);
    if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key))
        return def;
    const auto &v = it->second.Get(key);
    return v.IsNumber() ? v.GetNumberAsDouble() : def;
}

// Decode glTF image `img` into a SceneTexture (linear RGBA floats).
bool decode_image(Loader &L, int img, SceneTexture &tx)
{
    const auto &m = L.m;
    const auto &im = m.images[(size_t)img];
    std::string what = elem("image", img, im.name);
    const unsigned char *bytes = nullptr;
    size_t len = 0;
    if (im.bufferView >= 0) {
        if ((size_t)im.bufferView >= m.bufferViews.size())
            return L.fail(what + ": bufferView " + std::to_string(im.bufferView) + " does not exist");
        const auto &bv = m.bufferViews[(size_t)im.bufferView];
        if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size())
            return L.fail(what + ": bufferView " + std::to_string(im.bufferView) + " names missing buffer " +
                          std::to_string(bv.buffer));
        const auto &buf = m.buffers[(size_t)bv.buffer];
        if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset)
            return L.fail(what + ": bufferView " + std::to_string(im.bufferView) + " lies outside buffer " +
                          std::to_string(bv.buffer) + " (" + std::to_string(buf.data.size()) + " bytes)");
        bytes = buf.data.data() + bv.byteOffset;
        len = bv.byteLength;
    } else if ((size_t)img < L.stash->encoded.size() && !L.stash->encoded[(size_t)img].empty()) {
        bytes = L.stash->encoded[(size_t)img].data();
        len = L.stash->encoded[(size_t)img].size();
    } else {
        return L.fail(what + ": no image data (uri '" + im.uri + "' could not be read)");
    }
    if (len == 0 || len > (size_t)INT_MAX)
        return L.fail(what + ": " + std::to_string(len) + " bytes of image data");
    tinygltf::Image dec;
    std::string ierr, iwarn;
    // nullptr options: tinygltf's default, every image expanded to RGBA (8 or 16 bits per channel).
    if (!tinygltf::LoadImageData(&dec, img, &ierr, &iwarn, 0, 0, bytes, (int)len, nullptr))
        return L.fail(what + ": cannot decode: " + one_line(ierr));
    if (dec.width <= 0 || dec.height <= 0 || dec.component != 4 || (dec.bits != 8 && dec.bits != 16))
        return L.fail(what + ": decoded to an unusable format");
    size_t px = (size_t)dec.width * (size_t)dec.height, bpc = (size_t)dec.bits / 8;
    if (dec.image.size() < px * 4 * bpc)
        return L.fail(what + ": pixel data shorter than its size");
    if (!srgb8_ready) {
        for (int i = 0; i < 256; i++)
            srgb8_table[i] = srgb_to_linear(i / 255.0);
        srgb8_ready = true;
    }
    tx.name = strdup(im.name.c_str());
    tx.width = dec.width;
    tx.height = dec.height;
    tx.rgba = (float *)std::malloc(sizeof(float) * 4 * px);
    if (!tx.rgba || !tx.name) {
        std::free(tx.rgba);
        std::free(tx.name);
        tx.rgba = nullptr;
        tx.name = nullptr;
        return L.fail(what + ": out of memory");
    }
    const unsigned char *d = dec.image.data();
    for (size_t i = 0; i < 4 * px; i++) {
        bool alpha = (i & 3) == 3; // alpha is linear in glTF; colour channels are sRGB-encoded
        if (bpc == 1) {
            tx.rgba[i] = alpha ? d[i] / 255.0f : srgb8_table[d[i]];
        } else {
            uint16_t u;
            std::memcpy(&u, d + 2 * i, 2);
            tx.rgba[i] = alpha ? u / 65535.0f : srgb_to_linear(u / 65535.0);
        }
    }
    return true;
}

// The absolute SceneTexture index of glTF texture `t` (decoding its image once), or -1.
bool texture_index(Loader &L, int t, const std::string &where, int &out)
{
    out = -1;
    if (t < 0)
        return true;
    const auto &m = L.m;
    if ((size_t)t >= m.textures.size())
        return L.fail(where + ": texture " + std::to_string(t) + " does not exist");
    int img = m.textures[(size_t)t].source;
    if (img < 0)
        return true; // no source image (e.g. only an extension's): no texture
    // Textures always repeat (docs/scenes.md): a sampler that asks for clamping or mirroring is
    // counted for a warning.
    if (L.wrap_seen.size() != m.textures.size())
        L.wrap_seen.assign(m.textures.size(), 0);
    int smp = m.textures[(size_t)t].sampler;
    if (!L.wrap_seen[(size_t)t] && smp >= 0 && (size_t)smp < m.samplers.size() &&
        (m.samplers[(size_t)smp].wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT ||
         m.samplers[(size_t)smp].wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT))
        L.not_repeat++;
    L.wrap_seen[(size_t)t] = 1;
    if ((size_t)img >= m.images.size())
        return L.fail(where + ": texture " + std::to_string(t) + " names missing image " + std::to_string(img));
    if (L.image_to_tex[(size_t)img] >= 0) {
        out = L.image_to_tex[(size_t)img];
        return true;
    }
    SceneTexture tx{};
    if (!decode_image(L, img, tx))
        return false;
    out = (int)(L.tex_base + L.texs.size());
    L.texs.push_back(tx);
    L.maps.emplace_back();
    L.image_to_tex[(size_t)img] = out;
    return true;
}

// Texels darker than this (linear, every channel) do not emit: it keeps JPEG noise in the black
// parts of an emissive texture from turning whole models into lights.
const float EMIT_BLACK = 1.0f / 256.0f;

// Builds (once) the emitting-texel pyramid of texture `tex` (absolute); returns whether any texel
// emits and whether all do.
const EmitMap &emit_map(Loader &L, int tex, bool &any, bool &all)
{
    EmitMap &em = L.maps[(size_t)(tex - (int)L.tex_base)];
    const SceneTexture &t = L.texs[(size_t)(tex - (int)L.tex_base)];
    if (em.lv.empty()) {
        em.w = t.width;
        em.h = t.height;
        std::vector<unsigned char> l0((size_t)t.width * (size_t)t.height);
        for (size_t i = 0; i < l0.size(); i++) {
            const float *p = &t.rgba[4 * i];
            l0[i] = p[0] > EMIT_BLACK || p[1] > EMIT_BLACK || p[2] > EMIT_BLACK;
        }
        em.lv.push_back(std::move(l0));
        em.lw.push_back(t.width);
        em.lh.push_back(t.height);
        while (em.lw.back() > 1 || em.lh.back() > 1) {
            int pw = em.lw.back(), ph = em.lh.back(), w = (pw + 1) / 2, h = (ph + 1) / 2;
            const auto &prev = em.lv.back();
            std::vector<unsigned char> cur((size_t)w * (size_t)h, 0);
            for (int y = 0; y < ph; y++)
                for (int x = 0; x < pw; x++)
                    cur[(size_t)(y / 2) * (size_t)w + (size_t)(x / 2)] |= prev[(size_t)y * (size_t)pw + (size_t)x];
            em.lv.push_back(std::move(cur));
            em.lw.push_back(w);
            em.lh.push_back(h);
        }
    }
    any = em.lv.back()[0] != 0;
    all = true;
    for (unsigned char f : em.lv[0])
        if (!f) {
            all = false;
            break;
        }
    return em;
}

// A texel range [a, b] of a repeating texture of n texels, as up to two ranges inside it.
int wrap_ranges(double lo, double hi, int n, int r[4])
{
    double fl = std::floor(lo);
    lo -= fl;
    hi -= fl;
    // Bilinear filtering at u reads texels floor(u n - 1/2) and the next one; nearest reads
    // floor(u n), which lies between.
    long a = (long)std::floor(lo * n - 0.5), b = (long)std::floor(hi * n - 0.5) + 1;
    if (b - a + 1 >= n) {
        r[0] = 0;
        r[1] = n - 1;
        return 1;
    }
    long a2 = ((a % n) + n) % n, b2 = a2 + (b - a);
    if (b2 < n) {
        r[0] = (int)a2;
        r[1] = (int)b2;
        return 1;
    }
    r[0] = (int)a2;
    r[1] = n - 1;
    r[2] = 0;
    r[3] = (int)(b2 - n);
    return 2;
}

// Does the triangle with texture coordinates uv (3 x 2) touch an emitting texel?
bool uv_emits(const EmitMap &em, const double *uv)
{
    double u0 = std::fmin(uv[0], std::fmin(uv[2], uv[4])), u1 = std::fmax(uv[0], std::fmax(uv[2], uv[4]));
    double v0 = std::fmin(uv[1], std::fmin(uv[3], uv[5])), v1 = std::fmax(uv[1], std::fmax(uv[3], uv[5]));
    if (u1 - u0 >= 1.0 || v1 - v0 >= 1.0 || std::fabs(u0) > 1e6 || std::fabs(v0) > 1e6)
        return em.lv.back()[0] != 0;
    int xr[4], yr[4];
    int nx = wrap_ranges(u0, u1, em.w, xr), ny = wrap_ranges(v0, v1, em.h, yr);
    for (int i = 0; i < nx; i++)
        for (int j = 0; j < ny; j++)
            if (em.any(xr[2 * i], xr[2 * i + 1], yr[2 * j], yr[2 * j + 1]))
                return true;
    return false;
}

// The coordinates texture info `ti` samples with: texCoord, and KHR_texture_transform's offset,
// rotation and scale (and its texCoord, which overrides the other), composed as the extension
// says: translation x rotation x scale.
bool uv_map(Loader &L, const tinygltf::TextureInfo &ti, const std::string &where, UvMap &out)
{
    out = UvMap();
    out.set = ti.texCoord;
    auto it = ti.extensions.find("KHR_texture_transform");
    if (it != ti.extensions.end() && it->second.IsObject()) {
        const tinygltf::Value &x = it->second;
        std::string w = where + ": KHR_texture_transform";
        double off[2] = {0, 0}, sc[2] = {1, 1}, rot = 0;
        const char *pairs[2] = {"offset", "scale"};
        double *dst[2] = {off, sc};
        for (int k = 0; k < 2; k++) {
            if (!x.Has(pairs[k]))
                continue;
            const tinygltf::Value &a = x.Get(pairs[k]);
            if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber())
                return L.fail(w + ": " + pairs[k] + " is not 2 numbers");
            dst[k][0] = a.Get(0).GetNumberAsDouble();
            dst[k][1] = a.Get(1).GetNumberAsDouble();
        }
        if (x.Has("rotation")) {
            if (!x.Get("rotation").IsNumber())
                return L.fail(w + ": rotation is not a number");
            rot = x.Get("rotation").GetNumberAsDouble();
        }
        if (x.Has("texCoord")) {
            if (!x.Get("texCoord").IsInt())
                return L.fail(w + ": texCoord is not an integer");
            out.set = x.Get("texCoord").GetNumberAsInt();
        }
        if (!std::isfinite(off[0]) || !std::isfinite(off[1]) || !std::isfinite(sc[0]) || !std::isfinite(sc[1]) ||
            !std::isfinite(rot))
            return L.fail(w + ": a value is not finite");
        double c = std::cos(rot), sn = std::sin(rot);
        double m[6] = {c * sc[0], sn * sc[1], off[0], -sn * sc[0], c * sc[1], off[1]};
        std::memcpy(out.m, m, sizeof m);
    }
    if (out.set < 0)
        return L.fail(where + ": texCoord " + std::to_string(out.set) + " is negative");
    return true;
}

// glTF materials -> SceneMaterial (ARCHITECTURE.md Sec. 1 mapping).
bool load_materials(Loader &L)
{
    const auto &m = L.m;
    L.minfo.assign(m.materials.size(), MatInfo{});
    for (size_t i = 0; i < m.materials.size(); i++) {
        const auto &gm = m.materials[i];
        std::string where = elem("material", (int)i, gm.name);
        const auto &pbr = gm.pbrMetallicRoughness;
        SceneMaterial sm{};
        std::string name = gm.name.empty() ? "material_" + std::to_string(i) : gm.name;
        bool has_color = pbr.baseColorFactor.size() == 4;
        for (int k = 0; k < 3; k++)
            sm.base_color[k] = has_color ? (float)pbr.baseColorFactor[(size_t)k] : 1.0f;
        sm.alpha = has_color ? (float)pbr.baseColorFactor[3] : 1.0f;
        sm.metallic = (float)pbr.metallicFactor;   // tinygltf's default is glTF's: 1
        sm.roughness = (float)pbr.roughnessFactor; // likewise 1
        sm.transmission = (float)ext_number(gm.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0);
        sm.ior = (float)ext_number(gm.extensions, "KHR_materials_ior", "ior", 1.5);
        double strength = ext_number(gm.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0);
        for (int k = 0; k < 3; k++)
            sm.emission[k] = gm.emissiveFactor.size() == 3 ? (float)(gm.emissiveFactor[(size_t)k] * strength) : 0.0f;
        for (int k = 0; k < 3; k++)
            if (!std::isfinite(sm.base_color[k]) || !std::isfinite(sm.emission[k]) || sm.base_color[k] < 0.0f ||
                sm.emission[k] < 0.0f)
                return L.fail(where + ": colour component is negative or not finite");
        if (!std::isfinite(sm.alpha) || !std::isfinite(sm.metallic) || !std::isfinite(sm.roughness) ||
            !std::isfinite(sm.transmission) || !std::isfinite((float)gm.alphaCutoff))
            return L.fail(where + ": a factor is not finite");
        if (!(sm.ior >= 1.0f) || !std::isfinite(sm.ior)) {
            // KHR_materials_ior: 0 means 1 / infinity (a perfect mirror); anything else below 1 is invalid.
            if (sm.ior == 0.0f)
                sm.ior = 1.0f;
            else
                return L.fail(where + ": KHR_materials_ior ior " + std::to_string(sm.ior) + " is below 1");
        }
        // ARCHITECTURE.md Sec. 1: transmission > 0 -> dielectric; metallic > 0 or roughness < 1 ->
        // coupled glossy; otherwise Lambertian.
        if (sm.transmission > 0.0f)
            sm.kind = SCENE_MAT_DIELECTRIC;
        else if (sm.metallic > 0.0f || sm.roughness < 1.0f)
            sm.kind = SCENE_MAT_GLOSSY;
        else
            sm.kind = SCENE_MAT_LAMBERT;
        sm.alpha_mode = gm.alphaMode == "MASK"    ? SCENE_ALPHA_MASK
                        : gm.alphaMode == "BLEND" ? SCENE_ALPHA_BLEND
                                                  : SCENE_ALPHA_OPAQUE;
        sm.alpha_cutoff = (float)gm.alphaCutoff;
        sm.double_sided = gm.doubleSided ? 1 : 0;
        int tex;
        MatInfo &info = L.minfo[i];
        if (!texture_index(L, pbr.baseColorTexture.index, where + " baseColorTexture", tex))
            return false;
        if (tex >= 0 && !uv_map(L, pbr.baseColorTexture, where + " baseColorTexture", info.base_uv))
            return false;
        sm.base_texture = tex;
        sm.emissive_texture = -1;
        bool emits = sm.emission[0] > 0.0f || sm.emission[1] > 0.0f || sm.emission[2] > 0.0f;
        if (emits && !texture_index(L, gm.emissiveTexture.index, where + " emissiveTexture", tex))
            return false;
        if (emits && tex >= 0 && !uv_map(L, gm.emissiveTexture, where + " emissiveTexture", info.emit_uv))
            return false;
        if (emits)
            sm.emissive_texture = tex;
        sm.name = strdup(name.c_str());
        if (!sm.name)
            return L.fail("out of memory");
        L.mats.push_back(sm);
        MatInfo &mi = info;
        mi.index = (int)(L.mat_base + L.mats.size() - 1);
        mi.emit_tex = emits && tex >= 0;
        if (emits && tex >= 0) {
            // An emissive texture that is black in places: the triangles that only see black texels
            // do not emit. The material splits into a non-emitting part (this one) and an emitting
            // twin of the same name, so later stages, which sample no emissive texture, light only
            // what glows (docs/scenes.md, "Emissive textures").
            bool any, all;
            const EmitMap &em = emit_map(L, tex, any, all);
            SceneMaterial &me = L.mat(mi.index);
            if (!any) {
                for (int k = 0; k < 3; k++)
                    me.emission[k] = 0.0f;
                me.emissive_texture = -1;
                mi.emit_tex = false;
            } else if (!all) {
                SceneMaterial twin = me;
                twin.name = strdup(me.name);
                for (int k = 0; k < 3; k++)
                    me.emission[k] = 0.0f;
                me.emissive_texture = -1;
                if (!twin.name)
                    return L.fail("out of memory");
                L.mats.push_back(twin);
                L.minfo[i].emit_twin = (int)(L.mat_base + L.mats.size() - 1);
                L.minfo[i].map = &em;
            }
        }
    }
    return true;
}

// glTF's default material (white, metallic 1, roughness 1: coupled glossy) for primitives that
// name none; added once per file, on first use.
int default_material(Loader &L)
{
    if (L.default_mat >= 0)
        return L.default_mat;
    SceneMaterial sm{};
    sm.name = strdup("(glTF default material)");
    sm.kind = SCENE_MAT_GLOSSY;
    sm.base_color[0] = sm.base_color[1] = sm.base_color[2] = 1.0f;
    sm.alpha = 1.0f;
    sm.metallic = 1.0f;
    sm.roughness = 1.0f;
    sm.ior = 1.5f;
    sm.base_texture = sm.emissive_texture = -1;
    sm.alpha_cutoff = 0.5f;
    if (!sm.name)
        return -1;
    L.mats.push_back(sm);
    L.default_mat = (int)(L.mat_base + L.mats.size() - 1);
    return L.default_mat;
}

// ---- the Scene's triangle arrays ---------------------------------------------------------------

void geometric_normals(const float *pos, float *nrm, size_t from, size_t to)
{
    for (size_t t = from; t < to; t++) {
        const float *p = &pos[9 * t];
        double e1[3], e2[3], g[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)p[3 + k] - p[k];
            e2[k] = (double)p[6 + k] - p[k];
        }
        g[0] = e1[1] * e2[2] - e1[2] * e2[1];
        g[1] = e1[2] * e2[0] - e1[0] * e2[2];
        g[2] = e1[0] * e2[1] - e1[1] * e2[0];
        if (!normalize(g)) // a degenerate triangle: any unit vector keeps later stages NaN-free
            g[0] = g[2] = 0.0, g[1] = 1.0;
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++)
                nrm[9 * t + 3 * (size_t)c + (size_t)k] = (float)g[k];
    }
}

// The Scene's optional per-triangle arrays (NULL until a file has the attribute): the address of
// the pointer, floats per triangle, and the value earlier triangles get (normals: their
// geometric normal instead).
struct TriArray {
    float **p;
    size_t per;
    float fill;
};

std::vector<TriArray> tri_arrays(Scene *s)
{
    return {{&s->nrm, 9, 0.0f}, {&s->uv, 6, 0.0f}, {&s->uv_emit, 6, 0.0f}, {&s->col, 9, 1.0f}};
}

// Room for `more` triangles after the ones written so far (the counting pass in load() usually
// reserved everything at once).
bool reserve(Loader &L, size_t more)
{
    Scene *s = L.s;
    size_t need = L.old + L.cur + more;
    if (need > 0x3FFFFFFFu)
        return L.fail("too many triangles (" + std::to_string(need) + "; scene memory addresses at most 2^30)");
    if (need <= L.cap && s->pos)
        return true;
    size_t cap = std::max(need, L.cap + L.cap / 2) + 1; // + 1: never a zero-size allocation
    float *pos = (float *)std::realloc(s->pos, sizeof(float) * 9 * cap);
    if (pos)
        s->pos = pos;
    uint32_t *tm = pos ? (uint32_t *)std::realloc(s->tri_material, sizeof(uint32_t) * cap) : nullptr;
    if (tm)
        s->tri_material = tm;
    bool ok = pos && tm;
    for (const TriArray &a : tri_arrays(s))
        if (ok && *a.p) {
            float *r = (float *)std::realloc(*a.p, sizeof(float) * a.per * cap);
            if (r)
                *a.p = r;
            ok = r != nullptr;
        }
    if (!ok)
        return L.fail("out of memory for " + std::to_string(need) + " triangles");
    L.cap = cap;
    return true;
}

// The first per-triangle array `a` of the scene: every earlier triangle gets a.fill (normals:
// the geometric normal).
bool add_array(Loader &L, const TriArray &a)
{
    size_t n = a.per * (L.cap ? L.cap : 1);
    float *t = (float *)std::malloc(sizeof(float) * n);
    if (!t)
        return L.fail("out of memory for per-vertex data");
    for (size_t i = 0; i < n; i++)
        t[i] = a.fill;
    if (a.p == &L.s->nrm)
        geometric_normals(L.s->pos, t, 0, L.old + L.cur);
    *a.p = t;
    return true;
}

bool check_float_or_quantized(Loader &L, const View &v, const std::string &what, bool allow_normalized)
{
    if (v.ctype == TINYGLTF_COMPONENT_TYPE_FLOAT)
        return true;
    if (L.quantized && v.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
        return true;
    if (allow_normalized && v.normalized &&
        (v.ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE || v.ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT))
        return true;
    return L.fail(what + ": component type " + ctype_name(v.ctype) + (v.normalized ? " (normalized)" : "") +
                  " is not allowed here" +
                  (allow_normalized ? " (FLOAT or normalized UNSIGNED_BYTE/SHORT)" : " (FLOAT)"));
}

// The TEXCOORD_<map.set> of primitive p through map's transform, 2 floats per vertex into out;
// has = false (out empty) when the primitive has no such attribute.
bool read_uvs(Loader &L, const tinygltf::Primitive &p, const std::string &where, const UvMap &map, size_t nverts,
              std::vector<float> &out, bool &has)
{
    std::string attr = "TEXCOORD_" + std::to_string(map.set);
    auto ta = p.attributes.find(attr);
    has = ta != p.attributes.end();
    out.clear();
    if (!has)
        return true;
    View vt;
    std::string an = where + " " + attr + ": accessor " + std::to_string(ta->second);
    if (!accessor_view(L, ta->second, where + " " + attr, vt))
        return false;
    if (vt.ncomp != 2 || vt.count != nverts)
        return L.fail(an + " must be VEC2 with " + std::to_string(nverts) + " elements (has " +
                      std::to_string(vt.ncomp) + " components, " + std::to_string(vt.count) + " elements)");
    if (!check_float_or_quantized(L, vt, an, true))
        return false;
    out.resize(2 * nverts);
    const double *m = map.m;
    for (size_t v = 0; v < nverts; v++) {
        double u = vt.get(v, 0), w = vt.get(v, 1);
        double t[2] = {m[0] * u + m[1] * w + m[2], m[3] * u + m[4] * w + m[5]};
        for (int k = 0; k < 2; k++) {
            if (!std::isfinite((float)t[k]))
                return L.fail(where + " " + attr + ": vertex " + std::to_string(v) + " is not finite" +
                              (map.m[0] == 1 && map.m[1] == 0 && map.m[2] == 0 && map.m[3] == 0 && map.m[4] == 1 &&
                                       map.m[5] == 0
                                   ? ""
                                   : " after KHR_texture_transform"));
            out[2 * v + (size_t)k] = (float)t[k];
        }
    }
    return true;
}

bool load_primitive(Loader &L, const Mat4 &full, int mesh, int pi)
{
    const auto &m = L.m;
    const auto &gm = m.meshes[(size_t)mesh];
    const auto &p = gm.primitives[(size_t)pi];
    std::string where = elem("mesh", mesh, gm.name) + " primitive " + std::to_string(pi);
    int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    L.primitives++;
    // Points and lines have no area for a ray to hit: skipped, counted, and reported (commit).
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
        L.skipped[mode]++;
        return true;
    }
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        return L.fail(where + ": mode " + std::to_string(mode) + " is not a glTF primitive mode (0 to 6)");
    auto pa = p.attributes.find("POSITION");
    if (pa == p.attributes.end())
        return L.fail(where + ": no POSITION attribute");
    View vp, vn, vc, vi;
    if (!accessor_view(L, pa->second, where + " POSITION", vp))
        return false;
    if (vp.ncomp != 3)
        return L.fail(where + " POSITION: accessor " + std::to_string(pa->second) + " is not VEC3");
    if (!check_float_or_quantized(L, vp, where + " POSITION: accessor " + std::to_string(pa->second), false))
        return false;
    auto na = p.attributes.find("NORMAL");
    bool has_n = na != p.attributes.end();
    if (has_n) {
        if (!accessor_view(L, na->second, where + " NORMAL", vn))
            return false;
        if (vn.ncomp != 3 || vn.count != vp.count)
            return L.fail(where + " NORMAL: accessor " + std::to_string(na->second) + " must be VEC3 with " +
                          std::to_string(vp.count) + " elements (has " + std::to_string(vn.ncomp) + " components, " +
                          std::to_string(vn.count) + " elements)");
        if (!check_float_or_quantized(L, vn, where + " NORMAL: accessor " + std::to_string(na->second), false))
            return false;
    }
    // Vertex colours: COLOR_0 multiplies the base colour (glTF 2.0 Sec. 3.7.2.1; alpha ignored).
    auto ca = p.attributes.find("COLOR_0");
    bool has_c = ca != p.attributes.end();
    if (has_c) {
        std::string an = where + " COLOR_0: accessor " + std::to_string(ca->second);
        if (!accessor_view(L, ca->second, where + " COLOR_0", vc))
            return false;
        if ((vc.ncomp != 3 && vc.ncomp != 4) || vc.count != vp.count)
            return L.fail(an + " must be VEC3 or VEC4 with " + std::to_string(vp.count) + " elements (has " +
                          std::to_string(vc.ncomp) + " components, " + std::to_string(vc.count) + " elements)");
        if (vc.ctype != TINYGLTF_COMPONENT_TYPE_FLOAT &&
            !(vc.normalized && (vc.ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                vc.ctype == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)))
            return L.fail(an + ": component type " + ctype_name(vc.ctype) + (vc.normalized ? " (normalized)" : "") +
                          " is not allowed here (FLOAT or normalized UNSIGNED_BYTE/SHORT)");
    }
    // Indices: any unsigned integer type, each below the vertex count.
    std::vector<uint32_t> idx;
    if (p.indices >= 0) {
        if (!accessor_view(L, p.indices, where + " indices", vi))
            return false;
        std::string an = where + " indices: accessor " + std::to_string(p.indices);
        if (vi.ncomp != 1)
            return L.fail(an + ": is not SCALAR");
        if (vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return L.fail(an + ": component type " + ctype_name(vi.ctype) + " is not an unsigned integer type");
        if (vi.normalized)
            return L.fail(an + ": indices must not be normalized");
        idx.resize(vi.count);
        for (size_t i = 0; i < vi.count; i++) {
            uint32_t v = vi.index(i);
            if (v >= vp.count)
                return L.fail(where + ": index " + std::to_string(v) + " out of range (vertex count " +
                              std::to_string(vp.count) + ")");
            idx[i] = v;
        }
    } else {
        if (vp.count > 0xFFFFFFFFu)
            return L.fail(where + ": more than 2^32 vertices");
        idx.resize(vp.count);
        for (size_t i = 0; i < vp.count; i++)
            idx[i] = (uint32_t)i;
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && idx.size() % 3 != 0)
        return L.fail(where + ": " + std::to_string(idx.size()) + (p.indices >= 0 ? " indices" : " vertices") +
                      " do not make whole triangles (not a multiple of 3)");
    // The triangle list.
    std::vector<uint32_t> tri;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tri.swap(idx);
    } else {
        for (size_t i = 2; i < idx.size(); i++) {
            if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
                tri.insert(tri.end(), {idx[0], idx[i - 1], idx[i]});
            } else if (i % 2 == 0) {
                tri.insert(tri.end(), {idx[i - 2], idx[i - 1], idx[i]});
            } else {
                tri.insert(tri.end(), {idx[i - 1], idx[i - 2], idx[i]}); // keeps the winding
            }
        }
    }
    int mat, twin = -1;
    const MatInfo *mi = nullptr;
    static const MatInfo no_material;
    if (p.material >= 0) {
        if ((size_t)p.material >= m.materials.size())
            return L.fail(where + ": material " + std::to_string(p.material) + " does not exist");
        mi = &L.minfo[(size_t)p.material];
        mat = mi->index;
        twin = mi->emit_twin;
    } else if ((mat = default_material(L)) < 0) {
        return L.fail("out of memory");
    } else {
        mi = &no_material;
    }
    // Texture coordinates, per texture: the base-colour texture's set through its transform (a
    // material without one: TEXCOORD_0 as it is), the emissive texture's likewise.
    std::vector<float> wt, we;
    bool has_t, has_e = false;
    if (!read_uvs(L, p, where, mi->base_uv, vp.count, wt, has_t) ||
        (mi->emit_tex && !read_uvs(L, p, where, mi->emit_uv, vp.count, we, has_e)))
        return false;
    double nm[9];
    bool nm_ok = normal_matrix(full, nm);
    bool flip = det3(full) < 0.0; // a mirroring transform reverses the winding (glTF 2.0 Sec. 3.7.4)
    // Every vertex once.
    std::vector<float> wp(3 * vp.count), wn(has_n ? 3 * vp.count : 0), wc(has_c ? 3 * vp.count : 0);
    std::string pw = where + " POSITION: accessor " + std::to_string(pa->second) + ": vertex ";
    for (size_t v = 0; v < vp.count; v++) {
        double in[3] = {vp.get(v, 0), vp.get(v, 1), vp.get(v, 2)}, out[3];
        // What the file holds first, then where the node transforms put it: each error says which.
        for (int k = 0; k < 3; k++) {
            if (!std::isfinite(in[k]))
                return L.fail(pw + std::to_string(v) + " coordinate " + std::to_string(k) + " is not finite (" +
                              std::to_string(in[k]) + ")");
            if (std::fabs(in[k]) > SCENE_COORD_LIMIT)
                return L.fail(pw + std::to_string(v) + " coordinate " + std::to_string(k) + " is " + num(in[k]) +
                              ", beyond the limit of " + num(SCENE_COORD_LIMIT) +
                              " on scene coordinates (docs/scenes.md, Limits)");
        }
        xform_point(full, in, out);
        for (int k = 0; k < 3; k++) {
            if (!std::isfinite(out[k]) || std::fabs(out[k]) > SCENE_COORD_LIMIT)
                return L.fail(pw + std::to_string(v) + " is (" + num(out[0]) + ", " + num(out[1]) + ", " + num(out[2]) +
                              ") after the node transforms, beyond the limit of " + num(SCENE_COORD_LIMIT) +
                              " on scene coordinates (docs/scenes.md, Limits)");
            wp[3 * v + (size_t)k] = (float)out[k];
        }
        if (has_n) {
            double n[3] = {vn.get(v, 0), vn.get(v, 1), vn.get(v, 2)}, o[3] = {n[0], n[1], n[2]};
            if (nm_ok)
                for (int r = 0; r < 3; r++)
                    o[r] = nm[r] * n[0] + nm[3 + r] * n[1] + nm[6 + r] * n[2];
            if (!normalize(o)) // zero or non-finite normals fall back to the geometric normal
                o[0] = o[1] = o[2] = 0.0;
            for (int k = 0; k < 3; k++)
                wn[3 * v + (size_t)k] = (float)o[k];
        }
        if (has_c)
            for (int k = 0; k < 3; k++) {
                double c = vc.get(v, k);
                if (!std::isfinite(c) || c < 0.0)
                    return L.fail(where + " COLOR_0: vertex " + std::to_string(v) + " component " + std::to_string(k) +
                                  " is negative or not finite (" + std::to_string(c) + ")");
                wc[3 * v + (size_t)k] = (float)c;
            }
    }
    size_t nt = tri.size() / 3;
    Scene *S = L.s;
    if (!reserve(L, nt) || (has_n && !S->nrm && !add_array(L, tri_arrays(S)[0])) ||
        (has_t && !S->uv && !add_array(L, tri_arrays(S)[1])) ||
        (mi->emit_tex && !S->uv_emit && !add_array(L, tri_arrays(S)[2])) ||
        (has_c && !S->col && !add_array(L, tri_arrays(S)[3])))
        return false;
    size_t at = L.old + L.cur;
    float *P = S->pos + 9 * at, *N = S->nrm ? S->nrm + 9 * at : nullptr;
    float *T = S->uv ? S->uv + 6 * at : nullptr, *E = S->uv_emit ? S->uv_emit + 6 * at : nullptr;
    float *C = S->col ? S->col + 9 * at : nullptr;
    uint32_t *M = S->tri_material + at;
    bool twin_uv = twin >= 0 && has_e;
    for (size_t t = 0; t < nt; t++) {
        uint32_t c3[3] = {tri[3 * t], tri[3 * t + 1], tri[3 * t + 2]};
        if (flip)
            std::swap(c3[1], c3[2]);
        float g[9];
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                g[3 * c + k] = wp[3 * (size_t)c3[c] + (size_t)k];
                *P++ = g[3 * c + k];
            }
        double e1[3], e2[3], gn[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = (double)g[3 + k] - g[k];
            e2[k] = (double)g[6 + k] - g[k];
        }
        gn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        gn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        gn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        if (!normalize(gn)) { // a degenerate triangle: any unit vector keeps later stages NaN-free
            gn[0] = gn[2] = 0.0;
            gn[1] = 1.0;
        }
        double tuv[6];
        for (int c = 0; c < 3; c++) {
            const float *vn3 = has_n ? &wn[3 * (size_t)c3[c]] : nullptr;
            bool usable = vn3 && (vn3[0] != 0.0f || vn3[1] != 0.0f || vn3[2] != 0.0f);
            if (N)
                for (int k = 0; k < 3; k++)
                    *N++ = usable ? vn3[k] : (float)gn[k];
            for (int k = 0; k < 2; k++) {
                float u = has_t ? wt[2 * (size_t)c3[c] + (size_t)k] : 0.0f;
                float e = has_e ? we[2 * (size_t)c3[c] + (size_t)k] : 0.0f;
                if (T)
                    *T++ = u;
                if (E)
                    *E++ = e;
                tuv[2 * c + k] = e;
            }
            for (int k = 0; C && k < 3; k++)
                *C++ = has_c ? wc[3 * (size_t)c3[c] + (size_t)k] : 1.0f;
        }
        uint32_t tm = (uint32_t)mat;
        if (twin >= 0 && (!twin_uv || uv_emits(*mi->map, tuv)))
            tm = (uint32_t)twin;
        *M++ = tm;
    }
    L.cur += nt;
    return true;
}

bool local_matrix(Loader &L, int node, const tinygltf::Node &n, Mat4 &r)
{
    r = identity();
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16)
            return L.fail(elem("node", node, n.name) + ": matrix has " + std::to_string(n.matrix.size()) +
                          " numbers, not 16");
        for (size_t i = 0; i < 16; i++)
            r.m[i] = n.matrix[i];
    } else {
        Mat4 t = identity(), q = identity(), s = identity();
        if (!n.translation.empty() && n.translation.size() != 3)
            return L.fail(elem("node", node, n.name) + ": translation does not have 3 numbers");
        if (!n.rotation.empty() && n.rotation.size() != 4)
            return L.fail(elem("node", node, n.name) + ": rotation does not have 4 numbers");
        if (!n.scale.empty() && n.scale.size() != 3)
            return L.fail(elem("node", node, n.name) + ": scale does not have 3 numbers");
        if (n.translation.size() == 3)
            for (size_t k = 0; k < 3; k++)
                t.m[12 + k] = n.translation[k];
        if (n.rotation.size() == 4) { // unit quaternion (x, y, z, w); normalized here to be forgiving
            double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
            double l = std::sqrt(x * x + y * y + z * z + w * w);
            if (!(l > 0.0) || !std::isfinite(l))
                return L.fail(elem("node", node, n.name) + ": rotation is not a unit quaternion");
            x /= l, y /= l, z /= l, w /= l;
            q.m[0] = 1 - 2 * (y * y + z * z);
            q.m[1] = 2 * (x * y + z * w);
            q.m[2] = 2 * (x * z - y * w);
            q.m[4] = 2 * (x * y - z * w);
            q.m[5] = 1 - 2 * (x * x + z * z);
            q.m[6] = 2 * (y * z + x * w);
            q.m[8] = 2 * (x * z + y * w);
            q.m[9] = 2 * (y * z - x * w);
            q.m[10] = 1 - 2 * (x * x + y * y);
        }
        if (n.scale.size() == 3)
            for (size_t k = 0; k < 3; k++)
                s.m[5 * k] = n.scale[k];
        r = mul(t, mul(q, s));
    }
    for (double v : r.m)
        if (!std::isfinite(v))
            return L.fail(elem("node", node, n.name) + ": transform is not finite");
    return true;
}

bool load_camera(Loader &L, int node, const tinygltf::Node &n, const Mat4 &full)
{
    const auto &m = L.m;
    if ((size_t)n.camera >= m.cameras.size())
        return L.fail(elem("node", node, n.name) + ": camera " + std::to_string(n.camera) + " does not exist");
    const auto &cam = m.cameras[(size_t)n.camera];
    if (cam.type != "perspective")
        return true; // orthographic cameras are skipped: the path tracer's camera is a (thin) lens
    double yfov = cam.perspective.yfov * 180.0 / M_PI;
    if (!(yfov > 0.0 && yfov < 180.0))
        return L.fail(elem("camera", n.camera, cam.name) + ": yfov " + std::to_string(cam.perspective.yfov) +
                      " is not between 0 and pi");
    // A glTF camera looks down its local -z with +y up.
    double o[3] = {0, 0, 0}, f[3] = {0, 0, -1}, u[3] = {0, 1, 0}, po[3], fd[3], ud[3];
    xform_point(full, o, po);
    xform_dir(full, f, fd);
    xform_dir(full, u, ud);
    if (!normalize(fd) || !normalize(ud))
        return L.fail(elem("node", node, n.name) + ": camera transform is singular");
    for (int k = 0; k < 3; k++) {
        L.camera.position[k] = (float)po[k];
        L.camera.look_at[k] = (float)(po[k] + fd[k]);
        L.camera.up[k] = (float)ud[k];
    }
    L.camera.fov_y = (float)yfov;
    L.camera.aperture = 0.0f;
    L.camera.focus_distance = 0.0f;
    L.camera.source = SCENE_CAMERA_GLTF;
    L.camera_set = true;
    return true;
}

bool load_light(Loader &L, int node, const tinygltf::Node &n, const Mat4 &full)
{
    const auto &m = L.m;
    auto le = n.extensions.find("KHR_lights_punctual");
    if (le == n.extensions.end())
        return true;
    std::string where = elem("node", node, n.name) + ": KHR_lights_punctual";
    if (!le->second.IsObject() || !le->second.Has("light") || !le->second.Get("light").IsInt())
        return L.fail(where + ": no light index");
    int li = le->second.Get("light").GetNumberAsInt();
    if (li < 0 || (size_t)li >= m.lights.size())
        return L.fail(where + ": light " + std::to_string(li) + " does not exist");
    const auto &gl = m.lights[(size_t)li];
    std::string lw = elem("light", li, gl.name);
    SceneLight sl{};
    if (gl.type == "point")
        sl.kind = SCENE_LIGHT_POINT;
    else if (gl.type == "spot")
        sl.kind = SCENE_LIGHT_SPOT;
    else if (gl.type == "directional")
        sl.kind = SCENE_LIGHT_DIRECTIONAL;
    else
        return L.fail(lw + ": unknown type '" + gl.type + "'");
    // A punctual light sits at its node's origin and shines down its local -z.
    double o[3] = {0, 0, 0}, f[3] = {0, 0, -1}, po[3], fd[3];
    xform_point(full, o, po);
    xform_dir(full, f, fd);
    if (sl.kind != SCENE_LIGHT_POINT && !normalize(fd))
        return L.fail(where + ": the node's transform gives the light no direction");
    if (sl.kind == SCENE_LIGHT_POINT && !normalize(fd))
        fd[0] = fd[2] = 0.0, fd[1] = -1.0;
    if (!gl.color.empty() && gl.color.size() != 3)
        return L.fail(lw + ": color does not have 3 numbers");
    for (int k = 0; k < 3; k++) {
        sl.position[k] = (float)po[k];
        sl.direction[k] = (float)fd[k];
        sl.color[k] = gl.color.size() == 3 ? (float)gl.color[(size_t)k] : 1.0f;
        if (!std::isfinite(sl.color[k]) || sl.color[k] < 0.0f)
            return L.fail(lw + ": color is negative or not finite");
    }
    sl.intensity = (float)gl.intensity;
    if (!std::isfinite(sl.intensity) || sl.intensity < 0.0f)
        return L.fail(lw + ": intensity is negative or not finite");
    if (sl.kind == SCENE_LIGHT_SPOT) {
        sl.inner_cone = (float)gl.spot.innerConeAngle;
        sl.outer_cone = (float)gl.spot.outerConeAngle;
        if (!(sl.inner_cone >= 0.0f && sl.inner_cone < sl.outer_cone && sl.outer_cone <= (float)(M_PI / 2) + 1e-6f))
            return L.fail(lw + ": spot cone angles must satisfy 0 <= inner < outer <= pi/2");
    }
    sl.name = strdup(gl.name.empty() ? ("light_" + std::to_string(li)).c_str() : gl.name.c_str());
    if (!sl.name)
        return L.fail("out of memory");
    L.lights.push_back(sl);
    return true;
}

bool visit(Loader &L, int node, const Mat4 &parent, int depth)
{
    const auto &m = L.m;
    const auto &n = m.nodes[(size_t)node];
    // The parent checks in load() make the hierarchy a forest, so this runs once per node; the
    // depth bound only protects the stack.
    if (depth > 1000)
        return L.fail(elem("node", node, n.name) + ": hierarchy deeper than 1000 levels");
    Mat4 local;
    if (!local_matrix(L, node, n, local))
        return false;
    Mat4 world = mul(parent, local), full = mul(L.pre, world);
    if (n.mesh >= 0) {
        if ((size_t)n.mesh >= m.meshes.size())
            return L.fail(elem("node", node, n.name) + ": mesh " + std::to_string(n.mesh) + " does not exist");
        for (size_t pi = 0; pi < m.meshes[(size_t)n.mesh].primitives.size(); pi++)
            if (!load_primitive(L, full, n.mesh, (int)pi))
                return false;
    }
    if (n.camera >= 0 && !L.camera_set && !load_camera(L, node, n, full))
        return false;
    if (!load_light(L, node, n, full))
        return false;
    for (int c : n.children)
        if (!visit(L, c, world, depth + 1))
            return false;
    return true;
}

// Required extensions this loader honours, the one list: everything else that a file requires is
// refused by name; extensions that are only used are ignored (docs/scenes.md lists them).
const char *const supported_required[] = {"KHR_materials_emissive_strength", "KHR_materials_transmission",
                                          "KHR_materials_ior", "KHR_lights_punctual", "KHR_mesh_quantization"};

bool supported_extension(const std::string &ext)
{
    for (const char *k : supported_required)
        if (ext == k)
            return true;
    return false;
}

void refuse_extension(const char *name, const std::string &ext, char *err, size_t errlen)
{
    std::snprintf(err, errlen, "%s: requires extension %s, which sfsim does not support", name, ext.c_str());
}

// extensionsRequired, read from the JSON before tinygltf parses the rest: tinygltf fails on what
// such an extension changes (a Draco-compressed accessor has no bufferView) before the model it
// would hand back says which extension that was. Broken JSON is left to tinygltf to report.
bool check_required_first(const unsigned char *json, size_t len, const char *name, char *err, size_t errlen)
{
    cJSON *doc = cJSON_ParseWithLength((const char *)json, len);
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(doc, "extensionsRequired");
    if (!cJSON_IsArray(req))
        req = nullptr;
    const cJSON *e = nullptr;
    bool ok = true;
    cJSON_ArrayForEach(e, req)
        if (ok && cJSON_IsString(e) && !supported_extension(e->valuestring)) {
            refuse_extension(name, e->valuestring, err, errlen);
            ok = false;
        }
    cJSON_Delete(doc);
    return ok;
}

template <class T> bool append(T *&arr, uint32_t n, const std::vector<T> &more)
{
    if (more.empty())
        return true;
    T *r = (T *)std::realloc(arr, sizeof(T) * ((size_t)n + more.size()));
    if (!r)
        return false;
    arr = r;
    std::memcpy(r + n, more.data(), sizeof(T) * more.size());
    return true;
}

// Makes the file's triangles count and moves its materials, textures and lights into the Scene.
bool commit(Loader &L)
{
    Scene *s = L.s;
    if (!append(s->materials, s->nmaterials, L.mats) || !append(s->textures, s->ntextures, L.texs) ||
        !append(s->lights, s->nlights, L.lights))
        return L.fail("out of memory");
    uint32_t skipped = L.skipped[0] + L.skipped[1] + L.skipped[2] + L.skipped[3];
    if (skipped) {
        std::string by;
        for (int k = 0; k < 4; k++)
            if (L.skipped[k])
                by += std::string(by.empty() ? "" : ", ") + std::to_string(L.skipped[k]) + " " + mode_name(k);
        if (scene_warn(s, "%s: skipped %u of %u primitives: not triangles (%s); only triangles are ray traced",
                       L.file.c_str(), skipped, L.primitives, by.c_str()) != 0)
            return L.fail("out of memory");
        s->skipped_primitives += skipped;
    }
    if (L.not_repeat && scene_warn(s, "%s: %u textures ask for CLAMP_TO_EDGE or MIRRORED_REPEAT wrapping, which is not "
                                      "applied: every texture repeats", L.file.c_str(), L.not_repeat) != 0)
        return L.fail("out of memory");
    s->ntris = (uint32_t)(L.old + L.cur);
    s->nmaterials += (uint32_t)L.mats.size();
    s->ntextures += (uint32_t)L.texs.size();
    s->nlights += (uint32_t)L.lights.size();
    L.mats.clear(); // owned by the Scene now
    L.texs.clear();
    L.lights.clear();
    if (L.camera_set && s->camera.source == SCENE_CAMERA_DEFAULT)
        s->camera = L.camera;
    return true;
}

// Triangles the primitives under `roots` will produce, so the arrays grow once. Malformed
// accessors count nothing here; the real pass reports them.
size_t count_triangles(const Loader &L, const std::vector<int> &roots)
{
    const auto &m = L.m;
    size_t total = 0;
    std::vector<int> stack(roots.rbegin(), roots.rend());
    while (!stack.empty()) {
        const auto &n = m.nodes[(size_t)stack.back()];
        stack.pop_back();
        for (int c : n.children)
            stack.push_back(c);
        if (n.mesh < 0 || (size_t)n.mesh >= m.meshes.size())
            continue;
        for (const auto &p : m.meshes[(size_t)n.mesh].primitives) {
            int acc = p.indices;
            if (acc < 0) {
                auto pa = p.attributes.find("POSITION");
                acc = pa == p.attributes.end() ? -1 : pa->second;
            }
            if (acc < 0 || (size_t)acc >= m.accessors.size())
                continue;
            const auto &a = m.accessors[(size_t)acc];
            size_t cnt = a.count, tris;
            if (p.mode == TINYGLTF_MODE_TRIANGLES || p.mode < 0)
                tris = cnt / 3;
            else if (p.mode == TINYGLTF_MODE_TRIANGLE_STRIP || p.mode == TINYGLTF_MODE_TRIANGLE_FAN)
                tris = cnt >= 2 ? cnt - 2 : 0;
            else // points and lines are skipped; other modes fail later
                continue;
            // An accessor cannot hold more elements than its buffer has bytes.
            if (a.bufferView < 0 || (size_t)a.bufferView >= m.bufferViews.size())
                continue;
            const auto &bv = m.bufferViews[(size_t)a.bufferView];
            if (bv.buffer < 0 || (size_t)bv.buffer >= m.buffers.size() ||
                cnt > m.buffers[(size_t)bv.buffer].data.size())
                continue;
            total += tris;
            if (total > 0x3FFFFFFFu)
                return total;
        }
    }
    return total;
}

int load(bool ok, const std::string &gerr, const std::string &warn, const tinygltf::Model &model, const Stash &stash,
         const char *name, const double *xf, Scene *s, char *err, size_t errlen)
{
    if (!ok) {
        std::string e = one_line(gerr.empty() ? "not a readable glTF file" : gerr);
        if (!warn.empty())
            e += " (tinygltf warnings: " + one_line(warn) + ")";
        std::snprintf(err, errlen, "%s: %s", name, e.c_str());
        return -1;
    }
    for (const auto &ext : model.extensionsRequired)
        if (!supported_extension(ext)) {
            refuse_extension(name, ext, err, errlen);
            return -1;
        }
    Loader L(model, name, s);
    if (xf)
        std::memcpy(L.pre.m, xf, sizeof L.pre.m);
    L.stash = &stash;
    for (const auto &ext : model.extensionsUsed)
        L.quantized |= ext == "KHR_mesh_quantization";
    L.mat_base = s->nmaterials;
    L.tex_base = s->ntextures;
    L.image_to_tex.assign(model.images.size(), -1);
    L.maps.reserve(model.images.size()); // EmitMap pointers in MatInfo stay valid

    // The hierarchy must be a forest (glTF 2.0 Sec. 3.5.3): one parent per node, roots have none.
    // Checking it first bounds the walk to one visit per node whatever the file says.
    std::vector<int> parent(model.nodes.size(), -1);
    bool good = true;
    for (size_t i = 0; good && i < model.nodes.size(); i++)
        for (int c : model.nodes[i].children) {
            if (c < 0 || (size_t)c >= model.nodes.size()) {
                good = L.fail(elem("node", (int)i, model.nodes[i].name) + ": child " + std::to_string(c) +
                              " does not exist");
                break;
            }
            if (parent[(size_t)c] >= 0 || (size_t)c == i) {
                good = L.fail(elem("node", c, model.nodes[(size_t)c].name) +
                              ": has more than one parent or is its own child (the node hierarchy must be a tree)");
                break;
            }
            parent[(size_t)c] = (int)i;
        }
    // A node inside a cycle has its parent inside the cycle, so no walk from a root (a node
    // without a parent) reaches it: cycles are unreachable, not infinite.
    std::vector<int> roots;
    if (good && !model.scenes.empty()) {
        int sc = model.defaultScene >= 0 ? model.defaultScene : 0;
        if ((size_t)sc >= model.scenes.size())
            good = L.fail("default scene " + std::to_string(sc) + " does not exist");
        else {
            std::vector<bool> seen(model.nodes.size(), false);
            for (int n : model.scenes[(size_t)sc].nodes) {
                if (n < 0 || (size_t)n >= model.nodes.size()) {
                    good = L.fail(elem("scene", sc, model.scenes[(size_t)sc].name) + ": node " + std::to_string(n) +
                                  " does not exist");
                    break;
                }
                if (parent[(size_t)n] >= 0 || seen[(size_t)n]) {
                    good = L.fail(elem("scene", sc, model.scenes[(size_t)sc].name) + ": " +
                                  elem("node", n, model.nodes[(size_t)n].name) +
                                  " is not a root node or is listed twice");
                    break;
                }
                seen[(size_t)n] = true;
                roots.push_back(n);
            }
        }
    } else if (good) {
        // No scenes: every node without a parent is a root.
        for (size_t n = 0; n < model.nodes.size(); n++)
            if (parent[n] < 0)
                roots.push_back((int)n);
    }
    L.old = s->ntris;
    if (good && load_materials(L) && reserve(L, count_triangles(L, roots)))
        for (int n : roots)
            if (!visit(L, n, identity(), 0))
                break;
    if (L.err.empty())
        commit(L);
    if (!L.err.empty()) {
        std::snprintf(err, errlen, "%s", L.err.c_str());
        return -1;
    }
    return 0;
}

// tinygltf 2.7 turns "extras" and "extensions" into its Value type recursively, one C++ frame per
// level of JSON nesting: a few tens of thousands of '[' overflow the stack. glTF itself nests a
// dozen levels deep, so deeper documents are refused before tinygltf sees them.
const int MAX_JSON_DEPTH = 512;

bool json_too_deep(const unsigned char *p, size_t n)
{
    int depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = p[i];
        if (in_string) {
            if (c == '\\')
                i++;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > MAX_JSON_DEPTH)
                return true;
        } else if (c == ']' || c == '}') {
            depth--;
        }
    }
    return false;
}

// Loads a glTF held in memory: binary when it starts with the GLB magic. base_dir is where
// external files are looked for; fs says whether they may be read at all.
int load_memory(const unsigned char *data, size_t len, const char *name, const std::string &base_dir,
                const tinygltf::FsCallbacks &fs, const double *xf, Scene *s, char *err, size_t errlen)
{
    if (len > 0xFFFFFFFFu) {
        std::snprintf(err, errlen, "%s: larger than 4 GiB", name);
        return -1;
    }
    bool binary = len >= 4 && std::memcmp(data, "glTF", 4) == 0;
    const unsigned char *json = data;
    size_t json_len = len;
    if (binary && len >= 20) { // the JSON chunk; tinygltf checks the header itself
        uint32_t chunk;
        std::memcpy(&chunk, data + 12, 4);
        json = data + 20;
        json_len = std::min((size_t)chunk, len - 20);
    }
    if (json_too_deep(json, json_len)) {
        std::snprintf(err, errlen, "%s: JSON nested deeper than %d levels", name, MAX_JSON_DEPTH);
        return -1;
    }
    if (!check_required_first(json, json_len, name, err, errlen))
        return -1;
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    Stash stash;
    loader.SetImageLoader(keep_encoded, &stash);
    loader.SetFsCallbacks(fs);
    std::string gerr, warn;
    unsigned int n = (unsigned int)len;
    bool ok = binary ? loader.LoadBinaryFromMemory(&model, &gerr, &warn, data, n, base_dir)
                     : loader.LoadASCIIFromString(&model, &gerr, &warn, (const char *)data, n, base_dir);
    return load(ok, gerr, warn, model, stash, name, xf, s, err, errlen);
}

} // namespace

extern "C" int gltf_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        // The file is read here, not by tinygltf: it sizes files by seeking to their end, which
        // on a directory or a device gives nonsense (a directory "holds" 2^63 bytes), and the
        // JSON is checked before tinygltf parses it (json_too_deep).
        struct stat st;
        if (stat(path, &st) != 0) {
            std::snprintf(err, errlen, "%s: cannot open: %s", path, std::strerror(errno));
            return -1;
        }
        if (!S_ISREG(st.st_mode)) {
            std::snprintf(err, errlen, "%s: not a regular file", path);
            return -1;
        }
        std::vector<unsigned char> data;
        std::string rerr;
        if (!read_regular_file(&data, &rerr, path, nullptr)) { // (the file named by the user: no folder check)
            std::snprintf(err, errlen, "%s: %s", path, one_line(rerr).c_str());
            return -1;
        }
        const char *slash = std::strrchr(path, '/');
        std::string base_dir = slash ? std::string(path, (size_t)(slash - path) + 1) : std::string();
        FsContext ctx;
        ctx.base = base_dir;
        ctx.root = lexical_path(base_dir.empty() ? "." : base_dir);
        char *real = realpath(base_dir.empty() ? "." : base_dir.c_str(), nullptr);
        ctx.real = real ? real : ctx.root;
        std::free(real);
        if (ctx.root.empty() || ctx.root.back() != '/')
            ctx.root += "/";
        if (ctx.real.back() != '/')
            ctx.real += "/";
        const char *allow = std::getenv("SFSIM_ALLOW_OUTSIDE_URIS");
        ctx.allow_outside = allow && std::strcmp(allow, "1") == 0;
        tinygltf::FsCallbacks fs = {regular_file_exists, same_path, read_regular_file, no_write, &ctx};
        int rc = load_memory(data.data(), data.size(), path, base_dir, fs, xf, s, err, errlen);
        if (rc != 0 && !ctx.refused.empty())
            std::snprintf(err, errlen,
                          "%s: uri '%s' leads outside the folder of the glTF file, which sfsim does not read (set "
                          "SFSIM_ALLOW_OUTSIDE_URIS=1 to allow it)",
                          path, ctx.refused.c_str());
        return rc;
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", path, e.what());
        return -1;
    }
}

extern "C" int gltf_append_memory(const unsigned char *data, size_t len, const char *name, const double *xf,
                                  Scene *s, char *err, size_t errlen)
{
    try {
        tinygltf::FsCallbacks fs = {no_file_exists, same_path, no_read, no_write, nullptr};
        return load_memory(data, len, name, std::string(), fs, xf, s, err, errlen);
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", name, e.what());
        return -1;
    }
}
