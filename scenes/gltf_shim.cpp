// scenes/gltf_shim.cpp -- glTF 2.0 through tinygltf (Debian's libtinygltf), behind a C API.
//
// Owns: walking a glTF document (nodes, transforms, meshes, accessors, materials, textures,
// KHR_lights_punctual, cameras) and validating everything it reads, so a malformed file gives an
// error naming the file and the element instead of a crash. Must not: pick defaults, compute
// bounds or needs (scenes/scene.c), or build acceleration structures.
#include <tiny_gltf.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

extern "C" {
#include "gltf.h"
}

namespace {

struct Mat4 {
    double m[16]; // column-major
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
        for (int rr = 0; rr < 4; rr++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += a.m[k * 4 + rr] * b.m[c * 4 + k];
            r.m[c * 4 + rr] = s;
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

// Inverse transpose of the upper 3x3, for normals (3x3 column-major into out).
bool normal_matrix(const Mat4 &m, double *out)
{
    double a = m.m[0], b = m.m[4], c = m.m[8], d = m.m[1], e = m.m[5], f = m.m[9], g = m.m[2], h = m.m[6],
           i = m.m[10];
    double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    if (!(std::fabs(det) > 1e-300))
        return false;
    double id = 1.0 / det;
    // cofactor matrix / det = inverse transpose
    double cof[9] = {(e * i - f * h), -(d * i - f * g), (d * h - e * g), -(b * i - c * h), (a * i - c * g),
                     -(a * h - b * g), (b * f - c * e), -(a * f - c * d), (a * e - b * d)};
    // cof is row-major [row][col] of the cofactor matrix; out is column-major of (inverse)^T = cof/det
    for (int r = 0; r < 3; r++)
        for (int col = 0; col < 3; col++)
            out[col * 3 + r] = cof[r * 3 + col] * id;
    return true;
}

struct Loader {
    const tinygltf::Model &m;
    std::string file;
    Scene *s;
    Mat4 pre;
    std::string err;
    uint32_t mat_base = 0, tex_base = 0;
    std::vector<int> image_to_tex; // image index -> SceneTexture index (or -1 not loaded yet)
    // accumulated geometry
    std::vector<float> pos, nrm, uv;
    std::vector<uint32_t> tmat;
    bool any_normals = false, any_uvs = false;
    std::vector<SceneMaterial> mats;
    std::vector<SceneTexture> texs;
    std::vector<SceneLight> lights;
    bool camera_set = false;
    SceneCamera camera{};

    Loader(const tinygltf::Model &model, const char *name, Scene *scene) : m(model), file(name), s(scene) {}

    bool fail(const std::string &what)
    {
        if (err.empty())
            err = file + ": " + what;
        return false;
    }
};

std::string elem(const char *kind, int index, const std::string &name)
{
    std::string r = std::string(kind) + " " + std::to_string(index);
    if (!name.empty())
        r += " '" + name + "'";
    return r;
}

// A validated view of an accessor: element i, component k.
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
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            double v = p[k];
            return normalized ? v / 255.0 : v;
        }
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
        default:
            return 0.0;
        }
    }
};

int component_size(int ctype)
{
    switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

int type_components(int type)
{
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    default: return 0;
    }
}

bool accessor_view(Loader &L, int index, const std::string &where, int want_comp, View &v)
{
    const auto &m = L.m;
    if (index < 0 || index >= (int)m.accessors.size())
        return L.fail(where + ": accessor " + std::to_string(index) + " does not exist");
    const auto &a = m.accessors[index];
    std::string an = where + ": accessor " + std::to_string(index);
    if (a.sparse.isSparse)
        return L.fail(an + ": sparse accessors are not supported");
    int cs = component_size(a.componentType), nc = type_components(a.type);
    if (!cs || !nc)
        return L.fail(an + ": unsupported component type " + std::to_string(a.componentType) + " or type " +
                      std::to_string(a.type));
    if (want_comp && nc != want_comp)
        return L.fail(an + ": has " + std::to_string(nc) + " components, expected " + std::to_string(want_comp));
    if (a.bufferView < 0 || a.bufferView >= (int)m.bufferViews.size())
        return L.fail(an + ": missing or bad bufferView " + std::to_string(a.bufferView));
    const auto &bv = m.bufferViews[a.bufferView];
    if (bv.buffer < 0 || bv.buffer >= (int)m.buffers.size())
        return L.fail(an + ": bufferView " + std::to_string(a.bufferView) + " names missing buffer " +
                      std::to_string(bv.buffer));
    const auto &buf = m.buffers[bv.buffer];
    size_t elem_size = (size_t)cs * (size_t)nc;
    size_t stride = bv.byteStride ? bv.byteStride : elem_size;
    if (stride < elem_size)
        return L.fail(an + ": byteStride " + std::to_string(bv.byteStride) + " smaller than an element");
    size_t start = bv.byteOffset + a.byteOffset;
    size_t need = a.count ? start + stride * (a.count - 1) + elem_size : start;
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset ||
        a.byteOffset > bv.byteLength || need > bv.byteOffset + bv.byteLength || need > buf.data.size())
        return L.fail(an + ": data outside buffer " + std::to_string(bv.buffer) + " (" +
                      std::to_string(buf.data.size()) + " bytes)");
    v.base = buf.data.data() + start;
    v.stride = stride;
    v.count = a.count;
    v.ctype = a.componentType;
    v.ncomp = nc;
    v.normalized = a.normalized;
    return true;
}

double ext_number(const tinygltf::ExtensionMap &ext, const char *name, const char *key, double def, bool *present)
{
    auto it = ext.find(name);
    if (present)
        *present = it != ext.end();
    if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key))
        return def;
    const auto &v = it->second.Get(key);
    return v.IsNumber() ? v.GetNumberAsDouble() : def;
}

float srgb_to_linear(double c)
{
    return (float)(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

// The SceneTexture index of glTF texture `t` (decoding its image once), or -1.
bool texture_index(Loader &L, int t, const std::string &where, int &out)
{
    out = -1;
    if (t < 0)
        return true;
    const auto &m = L.m;
    if (t >= (int)m.textures.size())
        return L.fail(where + ": texture " + std::to_string(t) + " does not exist");
    int img = m.textures[t].source;
    if (img < 0)
        return true; // a texture without a source image: no texture
    if (img >= (int)m.images.size())
        return L.fail(where + ": texture " + std::to_string(t) + " names missing image " + std::to_string(img));
    if (L.image_to_tex[img] >= 0) {
        out = L.image_to_tex[img];
        return true;
    }
    const auto &im = m.images[img];
    if (im.width <= 0 || im.height <= 0 || im.component < 1 || im.component > 4 ||
        (im.bits != 8 && im.bits != 16))
        return L.fail(elem("image", img, im.name) + ": could not be decoded (" + std::to_string(im.width) + "x" +
                      std::to_string(im.height) + ", " + std::to_string(im.component) + " channels, " +
                      std::to_string(im.bits) + " bits)");
    size_t px = (size_t)im.width * (size_t)im.height, bpc = im.bits / 8;
    if (im.image.size() < px * (size_t)im.component * bpc)
        return L.fail(elem("image", img, im.name) + ": pixel data shorter than its size");
    SceneTexture tx{};
    tx.name = strdup(im.name.c_str());
    tx.width = im.width;
    tx.height = im.height;
    tx.rgba = (float *)std::malloc(sizeof(float) * 4 * px);
    if (!tx.rgba || !tx.name) {
        std::free(tx.rgba);
        std::free(tx.name);
        return L.fail("out of memory for image " + std::to_string(img));
    }
    for (size_t i = 0; i < px; i++) {
        double ch[4] = {0, 0, 0, 1};
        for (int k = 0; k < im.component; k++) {
            size_t o = (i * (size_t)im.component + (size_t)k) * bpc;
            ch[k] = bpc == 1 ? im.image[o] / 255.0 : (im.image[o] | im.image[o + 1] << 8) / 65535.0;
        }
        if (im.component <= 2) { // grey (+ alpha)
            ch[3] = im.component == 2 ? ch[1] : 1.0;
            ch[1] = ch[2] = ch[0];
        }
        for (int k = 0; k < 3; k++)
            tx.rgba[4 * i + k] = srgb_to_linear(ch[k]);
        tx.rgba[4 * i + 3] = (float)ch[3];
    }
    out = (int)(L.tex_base + L.texs.size());
    L.texs.push_back(tx);
    L.image_to_tex[img] = out;
    return true;
}

bool load_materials(Loader &L)
{
    const auto &m = L.m;
    for (size_t i = 0; i < m.materials.size(); i++) {
        const auto &gm = m.materials[i];
        std::string where = elem("material", (int)i, gm.name);
        SceneMaterial sm{};
        sm.name = strdup(gm.name.c_str());
        const auto &pbr = gm.pbrMetallicRoughness;
        for (int k = 0; k < 3; k++)
            sm.base_color[k] = pbr.baseColorFactor.size() == 4 ? (float)pbr.baseColorFactor[k] : 1.0f;
        sm.alpha = pbr.baseColorFactor.size() == 4 ? (float)pbr.baseColorFactor[3] : 1.0f;
        sm.metallic = (float)pbr.metallicFactor;
        sm.roughness = (float)pbr.roughnessFactor;
        bool has_tr = false;
        sm.transmission = (float)ext_number(gm.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0, &has_tr);
        sm.ior = (float)ext_number(gm.extensions, "KHR_materials_ior", "ior", 1.5, nullptr);
        double strength = ext_number(gm.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0, nullptr);
        for (int k = 0; k < 3; k++)
            sm.emission[k] = gm.emissiveFactor.size() == 3 ? (float)(gm.emissiveFactor[k] * strength) : 0.0f;
        // ARCHITECTURE.md Sec. 1: transmission > 0 -> dielectric; metallic > 0 or roughness < 1 ->
        // coupled glossy; otherwise Lambertian.
        if (sm.transmission > 0.0f)
            sm.kind = SCENE_MAT_DIELECTRIC;
        else if (sm.metallic > 0.0f || sm.roughness < 1.0f)
            sm.kind = SCENE_MAT_GLOSSY;
        else
            sm.kind = SCENE_MAT_LAMBERT;
        for (int k = 0; k < 3; k++)
            if (!std::isfinite(sm.base_color[k]) || !std::isfinite(sm.emission[k]))
                return L.fail(where + ": non-finite colour");
        if (!std::isfinite(sm.metallic) || !std::isfinite(sm.roughness) || !std::isfinite(sm.ior) || sm.ior <= 0.0f)
            return L.fail(where + ": non-finite or non-positive factor");
        int tex;
        if (!texture_index(L, pbr.baseColorTexture.index, where, tex))
            return false;
        sm.base_texture = tex;
        if (!texture_index(L, gm.emissiveTexture.index, where, tex))
            return false;
        sm.emissive_texture = tex;
        sm.alpha_mode = gm.alphaMode == "MASK" ? SCENE_ALPHA_MASK : gm.alphaMode == "BLEND" ? SCENE_ALPHA_BLEND : SCENE_ALPHA_OPAQUE;
        sm.alpha_cutoff = (float)gm.alphaCutoff;
        sm.double_sided = gm.doubleSided ? 1 : 0;
        L.mats.push_back(sm);
    }
    return true;
}

// The material used when a primitive names none: glTF's default (white, metallic 1,
// roughness 1), which the mapping makes coupled glossy; added once, on first use.
int default_material(Loader &L)
{
    static const char *name = "(glTF default material)";
    for (size_t i = 0; i < L.mats.size(); i++)
        if (L.mats[i].name && std::strcmp(L.mats[i].name, name) == 0)
            return (int)(L.mat_base + i);
    SceneMaterial sm{};
    sm.name = strdup(name);
    sm.kind = SCENE_MAT_GLOSSY;
    sm.base_color[0] = sm.base_color[1] = sm.base_color[2] = 1.0f;
    sm.alpha = 1.0f;
    sm.metallic = 1.0f;
    sm.roughness = 1.0f;
    sm.ior = 1.5f;
    sm.base_texture = sm.emissive_texture = -1;
    sm.alpha_cutoff = 0.5f;
    L.mats.push_back(sm);
    return (int)(L.mat_base + L.mats.size() - 1);
}

bool load_primitive(Loader &L, const Mat4 &world, int mesh, int pi)
{
    const auto &m = L.m;
    const auto &gm = m.meshes[mesh];
    const auto &p = gm.primitives[pi];
    std::string where = elem("mesh", mesh, gm.name) + " primitive " + std::to_string(pi);
    int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        return L.fail(where + ": mode " + std::to_string(mode) + " is not a triangle primitive (points and lines cannot be ray traced)");
    auto pa = p.attributes.find("POSITION");
    if (pa == p.attributes.end())
        return L.fail(where + ": no POSITION attribute");
    View vp, vn, vt, vi;
    if (!accessor_view(L, pa->second, where + " POSITION", 3, vp))
        return false;
    if (vp.ctype != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return L.fail(where + " POSITION: accessor " + std::to_string(pa->second) + " is not float");
    bool has_n = false, has_t = false;
    auto na = p.attributes.find("NORMAL");
    if (na != p.attributes.end()) {
        if (!accessor_view(L, na->second, where + " NORMAL", 3, vn))
            return false;
        if (vn.count != vp.count)
            return L.fail(where + " NORMAL: " + std::to_string(vn.count) + " normals for " + std::to_string(vp.count) + " vertices");
        has_n = true;
    }
    auto ta = p.attributes.find("TEXCOORD_0");
    if (ta != p.attributes.end()) {
        if (!accessor_view(L, ta->second, where + " TEXCOORD_0", 2, vt))
            return false;
        if (vt.count != vp.count)
            return L.fail(where + " TEXCOORD_0: " + std::to_string(vt.count) + " coordinates for " + std::to_string(vp.count) + " vertices");
        has_t = true;
    }
    std::vector<uint32_t> idx;
    if (p.indices >= 0) {
        if (!accessor_view(L, p.indices, where + " indices", 1, vi))
            return false;
        if (vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            vi.ctype != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return L.fail(where + " indices: accessor " + std::to_string(p.indices) + " is not an unsigned integer type");
        idx.resize(vi.count);
        for (size_t i = 0; i < vi.count; i++) {
            double v = vi.get(i, 0);
            if (v >= (double)vp.count)
                return L.fail(where + ": index " + std::to_string((unsigned long long)v) + " out of range (vertex count " +
                              std::to_string(vp.count) + ")");
            idx[i] = (uint32_t)v;
        }
    } else {
        idx.resize(vp.count);
        for (size_t i = 0; i < vp.count; i++)
            idx[i] = (uint32_t)i;
    }
    // Triangle list from the mode.
    std::vector<uint32_t> tri;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tri.assign(idx.begin(), idx.begin() + (idx.size() / 3) * 3);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (size_t i = 2; i < idx.size(); i++) {
            bool odd = (i % 2) == 1;
            tri.push_back(idx[odd ? i - 1 : i - 2]);
            tri.push_back(idx[odd ? i - 2 : i - 1]);
            tri.push_back(idx[i]);
        }
    } else {
        for (size_t i = 2; i < idx.size(); i++) {
            tri.push_back(idx[0]);
            tri.push_back(idx[i - 1]);
            tri.push_back(idx[i]);
        }
    }
    int mat;
    if (p.material >= 0) {
        if (p.material >= (int)m.materials.size())
            return L.fail(where + ": material " + std::to_string(p.material) + " does not exist");
        mat = (int)L.mat_base + p.material;
    } else {
        mat = default_material(L);
    }
    Mat4 full = mul(L.pre, world);
    double nm[9];
    bool nm_ok = normal_matrix(full, nm);
    // Transform every vertex once.
    std::vector<float> wp(3 * vp.count), wn(has_n ? 3 * vp.count : 0);
    for (size_t v = 0; v < vp.count; v++) {
        double in[3] = {vp.get(v, 0), vp.get(v, 1), vp.get(v, 2)}, out[3];
        xform_point(full, in, out);
        for (int k = 0; k < 3; k++) {
            if (!std::isfinite(in[k]) || !std::isfinite(out[k]) || std::fabs(out[k]) > 1e30)
                return L.fail(where + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
            wp[3 * v + k] = (float)out[k];
        }
        if (has_n) {
            double n[3] = {vn.get(v, 0), vn.get(v, 1), vn.get(v, 2)}, o[3] = {n[0], n[1], n[2]};
            if (nm_ok)
                for (int r = 0; r < 3; r++)
                    o[r] = nm[r] * n[0] + nm[3 + r] * n[1] + nm[6 + r] * n[2];
            double len = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
            for (int k = 0; k < 3; k++)
                wn[3 * v + k] = len > 0.0 && std::isfinite(len) ? (float)(o[k] / len) : 0.0f;
        }
    }
    for (size_t t = 0; t + 2 < tri.size(); t += 3) {
        float g[9];
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                g[3 * c + k] = wp[3 * tri[t + c] + k];
                L.pos.push_back(g[3 * c + k]);
            }
        // Vertex normals; the geometric normal where the primitive has none (or a zero one).
        double e1[3], e2[3], gn[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = g[3 + k] - g[k];
            e2[k] = g[6 + k] - g[k];
        }
        gn[0] = e1[1] * e2[2] - e1[2] * e2[1];
        gn[1] = e1[2] * e2[0] - e1[0] * e2[2];
        gn[2] = e1[0] * e2[1] - e1[1] * e2[0];
        double gl = std::sqrt(gn[0] * gn[0] + gn[1] * gn[1] + gn[2] * gn[2]);
        for (int c = 0; c < 3; c++) {
            const float *vnrm = has_n ? &wn[3 * tri[t + c]] : nullptr;
            bool usable = vnrm && (vnrm[0] != 0.0f || vnrm[1] != 0.0f || vnrm[2] != 0.0f);
            for (int k = 0; k < 3; k++)
                L.nrm.push_back(usable ? vnrm[k] : (gl > 0.0 ? (float)(gn[k] / gl) : 0.0f));
            for (int k = 0; k < 2; k++)
                L.uv.push_back(has_t ? (float)vt.get(tri[t + c], k) : 0.0f);
        }
        L.tmat.push_back((uint32_t)mat);
    }
    L.any_normals |= has_n;
    L.any_uvs |= has_t;
    return true;
}

Mat4 local_matrix(const tinygltf::Node &n)
{
    Mat4 r = identity();
    if (n.matrix.size() == 16) {
        for (int i = 0; i < 16; i++)
            r.m[i] = n.matrix[i];
        return r;
    }
    Mat4 t = identity(), q = identity(), s = identity();
    if (n.translation.size() == 3)
        for (int k = 0; k < 3; k++)
            t.m[12 + k] = n.translation[k];
    if (n.rotation.size() == 4) {
        double x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
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
        for (int k = 0; k < 3; k++)
            s.m[5 * k] = n.scale[k];
    return mul(t, mul(q, s));
}

bool visit(Loader &L, int node, const Mat4 &parent, std::vector<int> &path)
{
    const auto &m = L.m;
    if (node < 0 || node >= (int)m.nodes.size())
        return L.fail("node " + std::to_string(node) + " does not exist");
    for (int p : path)
        if (p == node)
            return L.fail(elem("node", node, m.nodes[node].name) + ": is its own ancestor (a cycle)");
    if (path.size() > 256)
        return L.fail(elem("node", node, m.nodes[node].name) + ": hierarchy deeper than 256 levels");
    const auto &n = m.nodes[node];
    Mat4 world = mul(parent, local_matrix(n));
    Mat4 full = mul(L.pre, world);
    if (n.mesh >= 0) {
        if (n.mesh >= (int)m.meshes.size())
            return L.fail(elem("node", node, n.name) + ": mesh " + std::to_string(n.mesh) + " does not exist");
        for (size_t pi = 0; pi < m.meshes[n.mesh].primitives.size(); pi++)
            if (!load_primitive(L, world, n.mesh, (int)pi))
                return false;
    }
    if (n.camera >= 0 && !L.camera_set) {
        if (n.camera >= (int)m.cameras.size())
            return L.fail(elem("node", node, n.name) + ": camera " + std::to_string(n.camera) + " does not exist");
        const auto &cam = m.cameras[n.camera];
        if (cam.type == "perspective") {
            double o[3] = {0, 0, 0}, f[3] = {0, 0, -1}, u[3] = {0, 1, 0}, po[3], fd[3], ud[3];
            xform_point(full, o, po);
            xform_dir(full, f, fd);
            xform_dir(full, u, ud);
            for (int k = 0; k < 3; k++) {
                L.camera.position[k] = (float)po[k];
                L.camera.look_at[k] = (float)(po[k] + fd[k]);
                L.camera.up[k] = (float)ud[k];
            }
            L.camera.fov_y = (float)(cam.perspective.yfov * 180.0 / M_PI);
            L.camera.source = SCENE_CAMERA_GLTF;
            L.camera_set = true;
        }
    }
    auto le = n.extensions.find("KHR_lights_punctual");
    if (le != n.extensions.end() && le->second.IsObject() && le->second.Has("light")) {
        const auto &lv = le->second.Get("light");
        int li = lv.IsInt() ? lv.Get<int>() : -1;
        if (li < 0 || li >= (int)m.lights.size())
            return L.fail(elem("node", node, n.name) + ": KHR_lights_punctual light " + std::to_string(li) + " does not exist");
        const auto &gl = m.lights[li];
        SceneLight sl{};
        sl.name = strdup(gl.name.c_str());
        double o[3] = {0, 0, 0}, f[3] = {0, 0, -1}, po[3], fd[3];
        xform_point(full, o, po);
        xform_dir(full, f, fd);
        double fl = std::sqrt(fd[0] * fd[0] + fd[1] * fd[1] + fd[2] * fd[2]);
        for (int k = 0; k < 3; k++) {
            sl.position[k] = (float)po[k];
            sl.direction[k] = fl > 0 ? (float)(fd[k] / fl) : 0.0f;
            sl.color[k] = gl.color.size() == 3 ? (float)gl.color[k] : 1.0f;
        }
        sl.intensity = (float)gl.intensity;
        if (gl.type == "point") {
            sl.kind = SCENE_LIGHT_POINT;
        } else if (gl.type == "spot") {
            sl.kind = SCENE_LIGHT_SPOT;
            sl.inner_cone = (float)gl.spot.innerConeAngle;
            sl.outer_cone = (float)gl.spot.outerConeAngle;
        } else if (gl.type == "directional") {
            sl.kind = SCENE_LIGHT_DIRECTIONAL;
        } else {
            std::free(sl.name);
            return L.fail("light " + std::to_string(li) + ": unknown type '" + gl.type + "'");
        }
        L.lights.push_back(sl);
    }
    path.push_back(node);
    for (int c : n.children)
        if (!visit(L, c, world, path))
            return false;
    path.pop_back();
    return true;
}

const std::set<std::string> supported_required = {"KHR_materials_emissive_strength", "KHR_materials_transmission",
                                                  "KHR_materials_ior", "KHR_lights_punctual",
                                                  "KHR_texture_transform", "KHR_materials_volume"};

template <class T> T *append(T *arr, uint32_t n, const std::vector<T> &more)
{
    if (more.empty())
        return arr;
    T *r = (T *)std::realloc(arr, sizeof(T) * (n + more.size()));
    if (!r)
        return nullptr;
    std::memcpy(r + n, more.data(), sizeof(T) * more.size());
    return r;
}

int finish(Loader &L, char *err, size_t errlen)
{
    auto cleanup = [&]() {
        for (auto &mm : L.mats)
            std::free(mm.name);
        for (auto &t : L.texs) {
            std::free(t.name);
            std::free(t.rgba);
        }
        for (auto &l : L.lights)
            std::free(l.name);
    };
    if (!L.err.empty()) {
        std::snprintf(err, errlen, "%s", L.err.c_str());
        cleanup();
        return -1;
    }
    Scene *s = L.s;
    uint32_t nt = (uint32_t)L.tmat.size();
    if ((uint64_t)s->ntris + nt > 0x3FFFFFFFu) {
        std::snprintf(err, errlen, "%s: too many triangles (%u + %u)", L.file.c_str(), s->ntris, nt);
        cleanup();
        return -1;
    }
    // Normals/UVs: arrays exist for the whole scene once any source has them.
    bool want_n = s->nrm || L.any_normals, want_t = s->uv || L.any_uvs;
    float *pos = (float *)std::realloc(s->pos, sizeof(float) * 9 * ((size_t)s->ntris + nt + 1));
    float *nrm = want_n ? (float *)std::realloc(s->nrm, sizeof(float) * 9 * ((size_t)s->ntris + nt + 1)) : nullptr;
    float *uv = want_t ? (float *)std::realloc(s->uv, sizeof(float) * 6 * ((size_t)s->ntris + nt + 1)) : nullptr;
    uint32_t *tm = (uint32_t *)std::realloc(s->tri_material, sizeof(uint32_t) * ((size_t)s->ntris + nt + 1));
    if (pos) s->pos = pos;
    if (nrm) {
        if (!s->nrm) // earlier triangles had no normals: give them zero (= use the geometric normal)
            std::memset(nrm, 0, sizeof(float) * 9 * (size_t)s->ntris);
        s->nrm = nrm;
    }
    if (uv) {
        if (!s->uv)
            std::memset(uv, 0, sizeof(float) * 6 * (size_t)s->ntris);
        s->uv = uv;
    }
    if (tm) s->tri_material = tm;
    SceneMaterial *mats = append(s->materials, s->nmaterials, L.mats);
    SceneTexture *texs = append(s->textures, s->ntextures, L.texs);
    SceneLight *lights = append(s->lights, s->nlights, L.lights);
    if (!pos || (want_n && !nrm) || (want_t && !uv) || !tm || (!L.mats.empty() && !mats) ||
        (!L.texs.empty() && !texs) || (!L.lights.empty() && !lights)) {
        std::snprintf(err, errlen, "%s: out of memory", L.file.c_str());
        if (mats) s->materials = mats;
        if (texs) s->textures = texs;
        if (lights) s->lights = lights;
        cleanup();
        return -1;
    }
    std::memcpy(s->pos + 9 * (size_t)s->ntris, L.pos.data(), sizeof(float) * L.pos.size());
    if (want_n)
        std::memcpy(s->nrm + 9 * (size_t)s->ntris, L.nrm.data(), sizeof(float) * L.nrm.size());
    if (want_t)
        std::memcpy(s->uv + 6 * (size_t)s->ntris, L.uv.data(), sizeof(float) * L.uv.size());
    std::memcpy(s->tri_material + s->ntris, L.tmat.data(), sizeof(uint32_t) * L.tmat.size());
    s->ntris += nt;
    s->materials = mats ? mats : s->materials;
    s->nmaterials += (uint32_t)L.mats.size();
    s->textures = texs ? texs : s->textures;
    s->ntextures += (uint32_t)L.texs.size();
    s->lights = lights ? lights : s->lights;
    s->nlights += (uint32_t)L.lights.size();
    if (L.camera_set && s->camera.source == SCENE_CAMERA_DEFAULT)
        s->camera = L.camera;
    return 0;
}

int load(tinygltf::TinyGLTF &loader, bool ok, const std::string &gerr, const std::string &warn,
         const tinygltf::Model &model, const char *name, const double *xf, Scene *s, char *err, size_t errlen)
{
    (void)loader;
    (void)warn;
    if (!ok) {
        std::string e = gerr.empty() ? "not a readable glTF file" : gerr;
        while (!e.empty() && (e.back() == '\n' || e.back() == '\r'))
            e.pop_back();
        std::snprintf(err, errlen, "%s: %s", name, e.c_str());
        return -1;
    }
    for (const auto &ext : model.extensionsRequired)
        if (!supported_required.count(ext)) {
            std::snprintf(err, errlen, "%s: required extension %s is not supported", name, ext.c_str());
            return -1;
        }
    Loader L(model, name, s);
    if (xf)
        std::memcpy(L.pre.m, xf, sizeof L.pre.m);
    else
        L.pre = identity();
    L.mat_base = s->nmaterials;
    L.tex_base = s->ntextures;
    L.image_to_tex.assign(model.images.size(), -1);
    if (load_materials(L)) {
        std::vector<int> path;
        if (!model.scenes.empty()) {
            int sc = model.defaultScene >= 0 && model.defaultScene < (int)model.scenes.size() ? model.defaultScene : 0;
            for (int n : model.scenes[sc].nodes)
                if (!visit(L, n, identity(), path))
                    break;
        } else {
            // No scenes: every node that is nobody's child is a root.
            std::vector<bool> child(model.nodes.size(), false);
            for (const auto &n : model.nodes)
                for (int c : n.children)
                    if (c >= 0 && c < (int)child.size())
                        child[c] = true;
            for (size_t n = 0; n < model.nodes.size(); n++)
                if (!child[n] && !visit(L, (int)n, identity(), path))
                    break;
        }
    }
    return finish(L, err, errlen);
}

bool has_suffix(const std::string &s, const char *suf)
{
    size_t n = std::strlen(suf);
    if (s.size() < n)
        return false;
    for (size_t i = 0; i < n; i++)
        if (std::tolower((unsigned char)s[s.size() - n + i]) != suf[i])
            return false;
    return true;
}

} // namespace

extern "C" int gltf_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        tinygltf::Model model;
        tinygltf::TinyGLTF loader;
        std::string gerr, warn;
        FILE *f = std::fopen(path, "rb");
        if (!f) {
            std::snprintf(err, errlen, "%s: cannot open: %s", path, std::strerror(errno));
            return -1;
        }
        std::fclose(f);
        bool ok = has_suffix(path, ".glb") ? loader.LoadBinaryFromFile(&model, &gerr, &warn, path)
                                           : loader.LoadASCIIFromFile(&model, &gerr, &warn, path);
        return load(loader, ok, gerr, warn, model, path, xf, s, err, errlen);
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", path, e.what());
        return -1;
    }
}

extern "C" int gltf_append_memory(const unsigned char *data, size_t len, int binary, const char *name,
                                  const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        tinygltf::Model model;
        tinygltf::TinyGLTF loader;
        std::string gerr, warn;
        bool ok = binary ? loader.LoadBinaryFromMemory(&model, &gerr, &warn, data, (unsigned int)len, "")
                         : loader.LoadASCIIFromString(&model, &gerr, &warn, (const char *)data, (unsigned int)len, "");
        return load(loader, ok, gerr, warn, model, name, xf, s, err, errlen);
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", name, e.what());
        return -1;
    }
}
