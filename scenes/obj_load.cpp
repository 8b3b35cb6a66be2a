// scenes/obj_load.cpp -- Wavefront OBJ + MTL through tinyobjloader (Debian's libtinyobjloader
// 2.0.0~rc10), behind the C API of scenes/obj.h.
//
// Owns: reading the OBJ file (regular files only) and the MTL files and map_Kd textures it names
// (inside the OBJ file's folder, as for glTF uris); a check of the OBJ text before tinyobjloader
// parses it, which names the line of each problem tinyobjloader would skip or report without one
// (faces with fewer than 3 or more than 255 vertices, indices 0 or out of range, coordinates that
// are not finite or beyond the coordinate limit (scene_limit), usemtl names no MTL defines); the MTL material
// rules of docs/scenes.md ("OBJ and MTL"); triangulation of polygons (a fan for convex ones, ear
// clipping otherwise); and the move of the result into the Scene. Must not: pick scene defaults,
// compute bounds or needs (scenes/scene.c), print anything, or let an exception or a
// tinyobjloader type cross the C boundary.
//
// tinyobjloader parses with triangulate off: its own triangulation drops the triangles of
// polygons its ear clipping cannot finish without a word, and it keeps a face's vertex count in
// an unsigned char, so faces of more than 255 vertices are refused before it parses. Images are
// decoded by tinygltf's decoder (stb_image), as glTF textures are, so a texture gives the same
// texels through either format. The fuzz build compiles tinyobjloader into this file
// (SFSIM_TINYOBJ_IMPLEMENTATION) so the sanitizers see inside it.
#ifdef SFSIM_TINYOBJ_IMPLEMENTATION
#define TINYOBJLOADER_IMPLEMENTATION
#endif
#include <tiny_obj_loader.h>
#include <tiny_gltf.h>

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <unistd.h>

#include "shim_util.hpp"

extern "C" {
#include "obj.h"
#include "../host/infile.h"
}

namespace {

// tinyobjloader keeps a face's vertex count in an unsigned char (mesh_t::num_face_vertices).
const size_t MAX_FACE_VERTICES = 255;
// An MTL illumination model is 0..10 (Wavefront's MTL specification).
const int MAX_ILLUM = 10;

using scene_shim::num; // scenes/shim_util.hpp
using scene_shim::one_line;

// ---- files -----------------------------------------------------------------------------------


// A whole regular file into out; "" or why not ("cannot open: ...", "not a regular file").
std::string read_file(const std::string &path, std::string &out)
{
    // The one input check (host/infile.h): a folder, a device or a FIFO is refused by name.
    char *buf, why[4352];
    size_t len;
    if (infile_read(path.c_str(), SCENE_FILE_MAX_BYTES, "a scene file", &buf, &len, why, sizeof why) != 0)
    {
        size_t n = path.size(); // the reason past "PATH: " (this file's callers name the path their way)
        return std::strncmp(why, path.c_str(), n) == 0 && why[n] == ':' ? std::string(why + n + 2) : std::string(why);
    }
    out.assign(buf, len);
    std::free(buf);
    return std::string();
}

struct Ctx {
    std::string file;           // the OBJ as named in messages
    std::string dir;            // its folder, "" or ending in '/'
    std::string root, real;     // the folder, absolute (by name; through realpath), ending in '/'
    bool memory = false, allow_outside = false;
    const char *mtl = nullptr;  // memory: the text every mtllib reads
    size_t mtl_len = 0;
    std::map<std::string, int> mtllib_line; // mtllib name -> its line
    std::vector<std::string> mat_file;      // by material: the MTL file that defined it
    std::string err;

    bool fail(const std::string &what)
    {
        if (err.empty())
            err = what;
        return false;
    }

    // rel (as the file wrote it) under the OBJ's folder; false (and an error) when it leaves it.
    bool resolve(const std::string &rel, const std::string &who, std::string &full)
    {
        std::string r = rel;
        for (char &c : r)
            if (c == '\\') // Windows exporters write back slashes
                c = '/';
        full = r[0] == '/' ? r : dir + r;
        if (allow_outside)
            return true;
        bool in = scene_shim::lexical_path(full).compare(0, root.size(), root) == 0;
        char *rp = in ? realpath(full.c_str(), nullptr) : nullptr;
        if (rp) {
            in = (std::string(rp) + "/").compare(0, real.size(), real) == 0;
            std::free(rp);
        }
        if (!in)
            return fail(who + " '" + rel + "' leads outside the folder of the OBJ file, which sfsim does not read "
                        "(set SFSIM_ALLOW_OUTSIDE_URIS=1 to allow it)");
        return true;
    }
};

// The MTL files a mtllib line names: read here (regular files inside the OBJ's folder), parsed
// by tinyobjloader. A missing or unreadable MTL file is an error (docs/scenes.md).
struct MtlReader : tinyobj::MaterialReader {
    Ctx &c;
    explicit MtlReader(Ctx &ctx) : c(ctx) {}
    bool operator()(const std::string &id, std::vector<tinyobj::material_t> *mats,
                    std::map<std::string, int> *names, std::string *warn, std::string *err) override
    {
        auto ln = c.mtllib_line.find(id);
        std::string at = c.file + (ln != c.mtllib_line.end() ? ":" + std::to_string(ln->second) : std::string());
        std::string text, full = id;
        if (c.memory) {
            if (!c.mtl)
                return c.fail(at + ": mtllib '" + id + "': no MTL text given");
            text.assign(c.mtl, c.mtl_len);
        } else {
            if (!c.resolve(id, at + ": mtllib", full))
                return false;
            std::string why = read_file(full, text);
            if (!why.empty())
                return c.fail(at + ": mtllib '" + id + "': " + full + ": " + why +
                              " (an OBJ file's materials are required: docs/scenes.md, OBJ and MTL)");
        }
        std::istringstream in(text);
        tinyobj::LoadMtl(names, mats, &in, warn, err);
        c.mat_file.resize(mats->size(), full);
        return true;
    }
};

// ---- the check before tinyobjloader parses ---------------------------------------------------

struct Check {
    size_t nv = 0, nvt = 0, nvn = 0, faces = 0, lines = 0, points = 0;
    std::vector<std::pair<int, std::string>> usemtl; // line, name (first use of each name)
};

// The next blank-separated word of s from i (i moves past it).
std::string word(const std::string &s, size_t &i)
{
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t'))
        i++;
    size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t')
        i++;
    return s.substr(b, i - b);
}

// One "v", "vt" or "vn" line: n numbers (vt: 1 to 3); coordinates finite and within the limit.
bool check_numbers(Ctx &c, const std::string &at, const std::string &kind, const std::string &line, size_t i)
{
    int need = kind == "vt" ? 1 : 3;
    for (int k = 0; k < 3; k++) {
        std::string w = word(line, i);
        if (w.empty()) {
            if (k < need)
                return c.fail(at + ": '" + kind + "' line with " + std::to_string(k) + " numbers (expected " +
                              (kind == "vt" ? std::string("1 to 3") : std::string("3")) + ")");
            break;
        }
        char *end;
        double d = std::strtod(w.c_str(), &end);
        if (*end || end == w.c_str())
            return c.fail(at + ": '" + kind + "' coordinate " + std::to_string(k) + " is not a number ('" + w + "')");
        if (kind == "vn")
            continue; // a normal that is not finite falls back to the geometric normal
        if (!std::isfinite(d) || (kind == "vt" && std::fabs(d) > 3.4e38))
            return c.fail(at + ": vertex coordinate " + std::to_string(k) + " is not finite (" + w + ")");
        if (kind == "v" && std::fabs(d) > scene_limit(SCENE_LIMIT_COORD))
            return c.fail(at + ": vertex coordinate " + std::to_string(k) + " is " + num(d) + ", beyond the limit of " +
                          num(scene_limit(SCENE_LIMIT_COORD)) + " on scene coordinates (docs/scenes.md, Limits of scene values)");
    }
    return true;
}

// One face vertex "v", "v/t", "v//n" or "v/t/n": each index not 0, a relative (negative) one
// within what came before, a positive one within the counts of the whole file (fwd: checked at
// the end).
struct Fwd {
    int line;
    long idx;
    int kind; // 0 v, 1 vt, 2 vn
};

bool check_face_vertex(Ctx &c, const std::string &at, int line, const std::string &w, const Check &k,
                       std::vector<Fwd> &fwd)
{
    static const char *const names[3] = {"vertex", "texture coordinate", "normal"};
    size_t counts[3] = {k.nv, k.nvt, k.nvn};
    const char *p = w.c_str();
    for (int part = 0; part < 3 && *p; part++) {
        if (*p == '/') { // "v//n": no texture coordinate
            p++;
            continue;
        }
        char *end;
        errno = 0;
        long idx = std::strtol(p, &end, 10);
        if (end == p || (*end && *end != '/') || errno || idx < INT_MIN || idx > INT_MAX)
            return c.fail(at + ": face vertex '" + w + "' is not v, v/t, v//n or v/t/n with integer indices");
        if (idx == 0)
            return c.fail(at + ": face vertex '" + w + "': " + names[part] + " index 0 (OBJ indices start at 1)");
        if (idx < 0 && (size_t)(-idx) > counts[part])
            return c.fail(at + ": face vertex '" + w + "': relative " + names[part] + " index " + std::to_string(idx) +
                          " reaches before the first one (" + std::to_string(counts[part]) + " so far)");
        if (idx > 0 && (size_t)idx > counts[part])
            fwd.push_back({line, idx, part});
        p = *end == '/' ? end + 1 : end;
    }
    return true;
}

bool check_text(Ctx &c, const std::string &text, Check &k)
{
    std::vector<Fwd> fwd;
    std::map<std::string, int> seen;
    size_t pos = 0;
    int ln = 0;
    while (pos < text.size()) {
        size_t nl = text.find('\n', pos);
        if (nl == std::string::npos)
            nl = text.size();
        std::string line = text.substr(pos, nl - pos);
        pos = nl + 1;
        ln++;
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        size_t i = 0;
        std::string kind = word(line, i), at = c.file + ":" + std::to_string(ln);
        if (kind == "v" || kind == "vt" || kind == "vn") {
            if (!check_numbers(c, at, kind, line, i))
                return false;
            (kind == "v" ? k.nv : kind == "vt" ? k.nvt : k.nvn)++;
        } else if (kind == "f") {
            size_t n = 0;
            for (std::string w = word(line, i); !w.empty(); w = word(line, i), n++)
                if (!check_face_vertex(c, at, ln, w, k, fwd))
                    return false;
            if (n < 3)
                return c.fail(at + ": face with " + std::to_string(n) + " vertices (a face needs at least 3)");
            if (n > MAX_FACE_VERTICES)
                return c.fail(at + ": face with " + std::to_string(n) + " vertices, more than the " +
                              std::to_string(MAX_FACE_VERTICES) + " tinyobjloader keeps; split it into smaller faces");
            k.faces++;
        } else if (kind == "l") {
            k.lines++;
        } else if (kind == "p") {
            k.points++;
        } else if (kind == "usemtl") {
            std::string name = word(line, i);
            if (!seen.count(name)) {
                seen[name] = ln;
                k.usemtl.push_back({ln, name});
            }
        } else if (kind == "mtllib") {
            for (std::string w = word(line, i); !w.empty(); w = word(line, i))
                if (!c.mtllib_line.count(w))
                    c.mtllib_line[w] = ln;
        }
    }
    static const char *const names[3] = {"vertex", "texture coordinate", "normal"};
    size_t counts[3] = {k.nv, k.nvt, k.nvn};
    for (const Fwd &f : fwd)
        if ((size_t)f.idx > counts[f.kind])
            return c.fail(c.file + ":" + std::to_string(f.line) + ": " + names[f.kind] + " index " +
                          std::to_string(f.idx) + " out of range (the file has " + std::to_string(counts[f.kind]) + ")");
    if (k.faces == 0)
        return c.fail(c.file + ": no faces (nothing to ray trace" +
                      std::string(k.lines + k.points ? ": lines and points are not surfaces)" : ")"));
    return true;
}

// ---- materials -------------------------------------------------------------------------------

float srgb_to_linear(double v)
{
    return (float)(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

// An image file into a SceneTexture: decoded by tinygltf's decoder, sRGB colour and linear alpha
// (as scenes/gltf_material.cpp's decode_image does for glTF base-colour textures).
bool decode_texture(Ctx &c, const std::string &who, const std::string &path, SceneTexture &tx)
{
    std::string data, why = read_file(path, data);
    if (!why.empty())
        return c.fail(who + ": " + path + ": " + why);
    if (data.empty() || data.size() > (size_t)INT_MAX)
        return c.fail(who + ": " + path + ": " + std::to_string(data.size()) + " bytes of image data");
    tinygltf::Image dec;
    std::string ierr, iwarn;
    if (!tinygltf::LoadImageData(&dec, 0, &ierr, &iwarn, 0, 0, (const unsigned char *)data.data(), (int)data.size(),
                                 nullptr))
        return c.fail(who + ": " + path + ": cannot decode: " + one_line(ierr));
    if (dec.width <= 0 || dec.height <= 0 || dec.component != 4 || (dec.bits != 8 && dec.bits != 16))
        return c.fail(who + ": " + path + ": decoded to an unusable format");
    size_t px = (size_t)dec.width * (size_t)dec.height, bpc = (size_t)dec.bits / 8;
    if (dec.image.size() < px * 4 * bpc)
        return c.fail(who + ": " + path + ": pixel data shorter than its size");
    tx.name = strdup(path.c_str());
    tx.width = dec.width;
    tx.height = dec.height;
    tx.rgba = (float *)std::malloc(sizeof(float) * 4 * px);
    if (!tx.rgba || !tx.name)
        return c.fail(who + ": out of memory");
    const unsigned char *d = dec.image.data();
    for (size_t i = 0; i < 4 * px; i++) {
        double v;
        if (bpc == 1) {
            v = d[i] / 255.0;
        } else {
            uint16_t u;
            std::memcpy(&u, d + 2 * i, 2);
            v = u / 65535.0;
        }
        tx.rgba[i] = (i & 3) == 3 ? (float)v : srgb_to_linear(v);
    }
    return true;
}

bool colour_ok(const float *c)
{
    for (int k = 0; k < 3; k++)
        if (!std::isfinite(c[k]) || c[k] < 0.0f)
            return false;
    return true;
}

bool any_positive(const float *c) { return c[0] > 0.0f || c[1] > 0.0f || c[2] > 0.0f; }

struct Out {
    std::vector<SceneMaterial> mats;
    std::vector<SceneTexture> texs;
    std::map<std::string, int> tex_of_path; // resolved path -> absolute texture index
    uint32_t mat_base = 0, tex_base = 0;
    int default_mat = -1; // absolute index, once a face uses no material
    std::vector<float> pos, nrm, uv;
    std::vector<uint32_t> mat;
    bool has_n = false, has_t = false;
    uint32_t map_ke = 0, map_d = 0;

    ~Out()
    {
        for (auto &m : mats)
            std::free(m.name);
        for (auto &t : texs) {
            std::free(t.name);
            std::free(t.rgba);
        }
    }
};

// One MTL material -> SceneMaterial by the rules of docs/scenes.md ("OBJ and MTL").
bool convert_material(Ctx &c, Out &o, size_t i, const tinyobj::material_t &m)
{
    const std::string &mtl = i < c.mat_file.size() ? c.mat_file[i] : c.file;
    std::string who = mtl + ": material '" + m.name + "'";
    SceneMaterial sm{};
    float kd[3], ks[3], ke[3], tf[3];
    for (int k = 0; k < 3; k++) {
        kd[k] = (float)m.diffuse[k];
        ks[k] = (float)m.specular[k];
        ke[k] = (float)m.emission[k];
        tf[k] = (float)m.transmittance[k];
    }
    if (!colour_ok(kd) || !colour_ok(ks) || !colour_ok(ke) || !colour_ok(tf))
        return c.fail(who + ": a colour (Kd, Ks, Ke or Tf) component is negative or not finite");
    if (!std::isfinite(m.shininess) || m.shininess < 0.0f)
        return c.fail(who + ": Ns " + num(m.shininess) + " is negative or not finite");
    if (!std::isfinite(m.ior) || m.ior < 0.0f)
        return c.fail(who + ": Ni " + num(m.ior) + " is negative or not finite");
    // The limits of the arithmetic they enter (scenes/scene.h, SCENE_LIMITS): emission is radiance,
    // and the refraction squares the index.
    double ked[3] = {ke[0], ke[1], ke[2]}, ni = m.ior;
    char why[256];
    if (scene_limit_check(SCENE_LIMIT_RADIANCE, ked, 3, why, sizeof why) != 0)
        return c.fail(who + ": Ke " + why);
    if (scene_limit_check(SCENE_LIMIT_IOR, &ni, 1, why, sizeof why) != 0)
        return c.fail(who + ": Ni " + why);
    if (!(m.dissolve >= 0.0f && m.dissolve <= 1.0f))
        return c.fail(who + ": d " + num(m.dissolve) + " (or 1 - Tr) is not between 0 and 1");
    if (m.illum < 0 || m.illum > MAX_ILLUM)
        return c.fail(who + ": illum " + std::to_string(m.illum) + " is not an MTL illumination model (0 to 10)");
    bool glass = m.illum == 4 || m.illum == 6 || m.illum == 7 || m.illum == 9;
    bool mirror = m.illum == 3 || m.illum == 5 || m.illum == 8;
    sm.alpha = 1.0f;
    sm.ior = 1.5f;
    sm.alpha_cutoff = 0.5f;
    sm.base_texture = sm.emissive_texture = -1;
    std::memcpy(sm.emission, ke, sizeof ke);
    if (glass) {
        sm.kind = SCENE_MAT_DIELECTRIC;
        sm.transmission = 1.0f;
        sm.ior = m.ior > 1.0f ? (float)m.ior : 1.5f;
        for (int k = 0; k < 3; k++)
            sm.base_color[k] = any_positive(tf) ? tf[k] : 1.0f;
        sm.roughness = 0.0f;
    } else if (mirror) {
        sm.kind = SCENE_MAT_GLOSSY;
        sm.metallic = 1.0f;
        sm.roughness = 0.0f;
        std::memcpy(sm.base_color, any_positive(ks) ? ks : kd, sizeof kd);
    } else {
        std::memcpy(sm.base_color, kd, sizeof kd);
        // obj2gltf's reading of Ns (the shared scenes' conversions): 1 - Ns / 1000, clamped.
        double r = m.illum == 2 && any_positive(ks) ? 1.0 - std::fmin(m.shininess / 1000.0, 1.0) : 1.0;
        sm.roughness = (float)r;
        sm.kind = sm.roughness < 1.0f ? SCENE_MAT_GLOSSY : SCENE_MAT_LAMBERT;
        if (m.dissolve < 1.0f) {
            sm.alpha = (float)m.dissolve;
            sm.alpha_mode = SCENE_ALPHA_BLEND;
        }
    }
    if (!m.diffuse_texname.empty() && !glass) {
        std::string full, tw = who + " map_Kd '" + m.diffuse_texname + "'";
        if (c.memory)
            return c.fail(tw + ": textures are not read when loading from memory");
        // Texture names are relative to the MTL file's folder.
        std::string mdir = mtl.find('/') == std::string::npos ? std::string() : mtl.substr(0, mtl.rfind('/') + 1);
        std::string save = c.dir;
        c.dir = mdir;
        bool ok = c.resolve(m.diffuse_texname, tw, full);
        c.dir = save;
        if (!ok)
            return false;
        auto it = o.tex_of_path.find(full);
        if (it != o.tex_of_path.end()) {
            sm.base_texture = it->second;
        } else {
            SceneTexture tx{};
            if (!decode_texture(c, tw, full, tx)) {
                std::free(tx.name);
                std::free(tx.rgba);
                return false;
            }
            o.texs.push_back(tx);
            sm.base_texture = o.tex_of_path[full] = (int)(o.tex_base + o.texs.size() - 1);
        }
    }
    o.map_ke += !m.emissive_texname.empty();
    o.map_d += !m.alpha_texname.empty();
    sm.name = strdup(m.name.c_str());
    if (!sm.name)
        return c.fail(c.file + ": out of memory");
    o.mats.push_back(sm);
    return true;
}

// The material of faces that name none (no usemtl yet): Lambertian grey, as a scene.ini material.
int default_material(Ctx &c, Out &o)
{
    if (o.default_mat >= 0)
        return o.default_mat;
    SceneMaterial sm{};
    sm.name = strdup("(OBJ default material)");
    if (!sm.name) {
        c.fail(c.file + ": out of memory");
        return -1;
    }
    sm.kind = SCENE_MAT_LAMBERT;
    sm.base_color[0] = sm.base_color[1] = sm.base_color[2] = 0.8f;
    sm.alpha = 1.0f;
    sm.roughness = 1.0f;
    sm.ior = 1.5f;
    sm.base_texture = sm.emissive_texture = -1;
    sm.alpha_cutoff = 0.5f;
    o.mats.push_back(sm);
    return o.default_mat = (int)(o.mat_base + o.mats.size() - 1);
}

// ---- geometry --------------------------------------------------------------------------------

bool unit(double *v)
{
    double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0.0) || !std::isfinite(l))
        return false;
    for (int k = 0; k < 3; k++)
        v[k] /= l;
    return true;
}

// A polygon's triangles as corner triples: a fan from the first corner when the polygon is convex
// (in the plane of its Newell normal), ear clipping otherwise; a polygon with no ear left (self-
// intersecting, or of zero area) is finished as a fan. Always n - 2 triangles.
void triangulate(const std::vector<double> &p, std::vector<int> &tri)
{
    int n = (int)(p.size() / 3);
    double nw[3] = {0, 0, 0};
    for (int i = 0; i < n; i++) {
        const double *a = &p[3 * (size_t)i], *b = &p[3 * (size_t)((i + 1) % n)];
        nw[0] += (a[1] - b[1]) * (a[2] + b[2]);
        nw[1] += (a[2] - b[2]) * (a[0] + b[0]);
        nw[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    int ax = std::fabs(nw[0]) > std::fabs(nw[1]) ? (std::fabs(nw[0]) > std::fabs(nw[2]) ? 0 : 2)
                                                  : (std::fabs(nw[1]) > std::fabs(nw[2]) ? 1 : 2);
    int u = (ax + 1) % 3, v = (ax + 2) % 3;
    double sign = nw[ax] < 0.0 ? -1.0 : 1.0;
    auto cross = [&](int a, int b, int d) {
        const double *A = &p[3 * (size_t)a], *B = &p[3 * (size_t)b], *D = &p[3 * (size_t)d];
        return sign * ((B[u] - A[u]) * (D[v] - A[v]) - (B[v] - A[v]) * (D[u] - A[u]));
    };
    bool convex = true;
    for (int i = 0; i < n && convex; i++)
        convex = cross((i + n - 1) % n, i, (i + 1) % n) >= 0.0;
    std::vector<int> ring(n);
    for (int i = 0; i < n; i++)
        ring[(size_t)i] = i;
    while (!convex && ring.size() > 3) {
        bool cut = false;
        size_t m = ring.size();
        for (size_t i = 0; i < m && !cut; i++) {
            int a = ring[(i + m - 1) % m], b = ring[i], d = ring[(i + 1) % m];
            if (!(cross(a, b, d) > 0.0))
                continue;
            bool inside = false;
            for (size_t j = 0; j < m && !inside; j++) {
                int q = ring[j];
                inside = q != a && q != b && q != d && cross(a, b, q) >= 0.0 && cross(b, d, q) >= 0.0 &&
                         cross(d, a, q) >= 0.0;
            }
            if (inside)
                continue;
            tri.insert(tri.end(), {a, b, d});
            ring.erase(ring.begin() + (long)i);
            cut = true;
        }
        if (!cut)
            break;
    }
    for (size_t i = 1; i + 1 < ring.size(); i++)
        tri.insert(tri.end(), {ring[0], ring[i], ring[i + 1]});
}

// The inverse transpose of xf's upper 3x3 (column-major), which carries normals.
void normal_matrix(const double *xf, double *nm)
{
    double a[9] = {xf[0], xf[1], xf[2], xf[4], xf[5], xf[6], xf[8], xf[9], xf[10]}; // columns
    // cofactor(A) / det(A) = inverse transpose; a[c*3+r] is A[r][c]
    auto A = [&](int r, int cc) { return a[cc * 3 + r]; };
    double det = A(0, 0) * (A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1)) - A(0, 1) * (A(1, 0) * A(2, 2) - A(1, 2) * A(2, 0)) +
                 A(0, 2) * (A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0));
    for (int r = 0; r < 3; r++)
        for (int cc = 0; cc < 3; cc++) {
            int r1 = (r + 1) % 3, r2 = (r + 2) % 3, c1 = (cc + 1) % 3, c2 = (cc + 2) % 3;
            double cof = A(r1, c1) * A(r2, c2) - A(r1, c2) * A(r2, c1);
            nm[cc * 3 + r] = det != 0.0 ? cof / det : (r == cc ? 1.0 : 0.0);
        }
}

double det3(const double *xf)
{
    return xf[0] * (xf[5] * xf[10] - xf[9] * xf[6]) - xf[4] * (xf[1] * xf[10] - xf[9] * xf[2]) +
           xf[8] * (xf[1] * xf[6] - xf[5] * xf[2]);
}

// Every face of every shape, triangulated, through xf, into o's arrays.
bool build_triangles(Ctx &c, Out &o, const tinyobj::attrib_t &at, const std::vector<tinyobj::shape_t> &shapes,
                     const double *xf)
{
    static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    const double *X = xf ? xf : identity;
    double nm[9];
    normal_matrix(X, nm);
    bool flip = det3(X) < 0.0;
    size_t nv = at.vertices.size() / 3, nn = at.normals.size() / 3, nt = at.texcoords.size() / 2;
    std::vector<double> poly;
    std::vector<int> tri;
    for (const auto &sh : shapes) {
        size_t off = 0;
        for (size_t f = 0; f < sh.mesh.num_face_vertices.size(); f++) {
            size_t n = sh.mesh.num_face_vertices[f];
            if (off + n > sh.mesh.indices.size())
                return c.fail(c.file + ": shape '" + sh.name + "': face indices run past the end");
            const tinyobj::index_t *ix = &sh.mesh.indices[off];
            off += n;
            int mid = f < sh.mesh.material_ids.size() ? sh.mesh.material_ids[f] : -1;
            int mat = mid >= 0 && (size_t)mid < o.mats.size() ? (int)o.mat_base + mid : default_material(c, o);
            if (mat < 0)
                return false;
            poly.assign(3 * n, 0.0);
            for (size_t k = 0; k < n; k++) {
                if (ix[k].vertex_index < 0 || (size_t)ix[k].vertex_index >= nv)
                    return c.fail(c.file + ": shape '" + sh.name + "': vertex index " +
                                  std::to_string(ix[k].vertex_index + 1) + " out of range (the file has " +
                                  std::to_string(nv) + ")");
                const float *v = &at.vertices[3 * (size_t)ix[k].vertex_index];
                double w[3];
                bool fine = true;
                for (int r = 0; r < 3; r++) {
                    w[r] = X[r] * v[0] + X[4 + r] * v[1] + X[8 + r] * v[2] + X[12 + r];
                    fine &= std::isfinite(w[r]) && std::fabs(w[r]) <= scene_limit(SCENE_LIMIT_COORD);
                    poly[3 * k + (size_t)r] = w[r];
                }
                if (!fine)
                    return c.fail(c.file + ": vertex " + std::to_string(ix[k].vertex_index + 1) + " is (" + num(w[0]) +
                                  ", " + num(w[1]) + ", " + num(w[2]) + ")" + (xf ? " after the placement" : "") +
                                  ", beyond the limit of " + num(scene_limit(SCENE_LIMIT_COORD)) +
                                  " on scene coordinates (docs/scenes.md, Limits of scene values)");
            }
            tri.clear();
            triangulate(poly, tri);
            for (size_t t = 0; t + 2 < tri.size(); t += 3) {
                int cs[3] = {tri[t], tri[t + 1], tri[t + 2]};
                if (flip)
                    std::swap(cs[1], cs[2]);
                double e1[3], e2[3], g[3];
                for (int r = 0; r < 3; r++) {
                    e1[r] = (double)(float)poly[3 * (size_t)cs[1] + (size_t)r] - (float)poly[3 * (size_t)cs[0] + (size_t)r];
                    e2[r] = (double)(float)poly[3 * (size_t)cs[2] + (size_t)r] - (float)poly[3 * (size_t)cs[0] + (size_t)r];
                }
                g[0] = e1[1] * e2[2] - e1[2] * e2[1];
                g[1] = e1[2] * e2[0] - e1[0] * e2[2];
                g[2] = e1[0] * e2[1] - e1[1] * e2[0];
                if (!unit(g)) // a degenerate triangle: any unit vector keeps later stages NaN-free
                    g[0] = g[2] = 0.0, g[1] = 1.0;
                for (int q = 0; q < 3; q++) {
                    const tinyobj::index_t &id = ix[cs[q]];
                    for (int r = 0; r < 3; r++)
                        o.pos.push_back((float)poly[3 * (size_t)cs[q] + (size_t)r]);
                    double nv3[3] = {g[0], g[1], g[2]};
                    if (id.normal_index >= 0 && (size_t)id.normal_index < nn) {
                        const float *vn = &at.normals[3 * (size_t)id.normal_index];
                        double w[3];
                        for (int r = 0; r < 3; r++)
                            w[r] = nm[r] * vn[0] + nm[3 + r] * vn[1] + nm[6 + r] * vn[2];
                        if (unit(w))
                            std::memcpy(nv3, w, sizeof w);
                        o.has_n = true;
                    }
                    for (int r = 0; r < 3; r++)
                        o.nrm.push_back((float)nv3[r]);
                    float tu = 0.0f, tv = 0.0f;
                    if (id.texcoord_index >= 0 && (size_t)id.texcoord_index < nt) {
                        // OBJ's v grows upward from the image's bottom row; glTF's (and the
                        // renderers') from the top row.
                        tu = at.texcoords[2 * (size_t)id.texcoord_index];
                        tv = (float)(1.0 - (double)at.texcoords[2 * (size_t)id.texcoord_index + 1]);
                        o.has_t = true;
                    }
                    o.uv.push_back(tu);
                    o.uv.push_back(tv);
                }
                o.mat.push_back((uint32_t)mat);
            }
        }
    }
    if (o.mat.size() > 0x3FFFFFFFu)
        return c.fail(c.file + ": too many triangles (" + std::to_string(o.mat.size()) +
                      "; scene memory addresses at most 2^30)");
    return true;
}

// ---- into the Scene --------------------------------------------------------------------------

// arr (the Scene's, `old` triangles of `per` floats, or NULL) grown to old + more triangles; a
// new array gets `fill` (normals: the earlier triangles' geometric normals) for the old ones.
bool grow(float **arr, const Scene *s, size_t old, size_t more, size_t per, bool make, float fill, bool geometric)
{
    if (!*arr && !make)
        return true;
    float *r = (float *)std::realloc(*arr, sizeof(float) * per * (old + more + 1));
    if (!r)
        return false;
    if (!*arr)
        for (size_t t = 0; t < old; t++) {
            double g[3] = {0, 1, 0};
            if (geometric) {
                const float *p = &s->pos[9 * t];
                double e1[3], e2[3];
                for (int k = 0; k < 3; k++) {
                    e1[k] = (double)p[3 + k] - p[k];
                    e2[k] = (double)p[6 + k] - p[k];
                }
                g[0] = e1[1] * e2[2] - e1[2] * e2[1];
                g[1] = e1[2] * e2[0] - e1[0] * e2[2];
                g[2] = e1[0] * e2[1] - e1[1] * e2[0];
                if (!unit(g))
                    g[0] = g[2] = 0.0, g[1] = 1.0;
            }
            for (size_t k = 0; k < per; k++)
                r[per * t + k] = geometric ? (float)g[k % 3] : fill;
        }
    *arr = r;
    return true;
}

template <class T> bool append(T *&arr, uint32_t n, std::vector<T> &more)
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

bool commit(Ctx &c, Out &o, Scene *s)
{
    size_t old = s->ntris, nt = o.mat.size();
    if (old + nt > 0x3FFFFFFFu)
        return c.fail(c.file + ": too many triangles (" + std::to_string(old + nt) +
                      "; scene memory addresses at most 2^30)");
    float *pos = (float *)std::realloc(s->pos, sizeof(float) * 9 * (old + nt + 1));
    if (pos)
        s->pos = pos;
    uint32_t *tm = pos ? (uint32_t *)std::realloc(s->tri_material, sizeof(uint32_t) * (old + nt + 1)) : nullptr;
    if (tm)
        s->tri_material = tm;
    // The optional arrays exist when any triangle of the scene has the attribute (as glTF's).
    if (!pos || !tm || !grow(&s->nrm, s, old, nt, 9, o.has_n, 0.0f, true) ||
        !grow(&s->uv, s, old, nt, 6, o.has_t, 0.0f, false) || !grow(&s->uv_emit, s, old, nt, 6, false, 0.0f, false) ||
        !grow(&s->col, s, old, nt, 9, false, 1.0f, false) || !append(s->materials, s->nmaterials, o.mats) ||
        !append(s->textures, s->ntextures, o.texs))
        return c.fail(c.file + ": out of memory for " + std::to_string(old + nt) + " triangles");
    std::memcpy(s->pos + 9 * old, o.pos.data(), sizeof(float) * 9 * nt);
    std::memcpy(s->tri_material + old, o.mat.data(), sizeof(uint32_t) * nt);
    if (s->nrm)
        std::memcpy(s->nrm + 9 * old, o.nrm.data(), sizeof(float) * 9 * nt);
    if (s->uv)
        std::memcpy(s->uv + 6 * old, o.uv.data(), sizeof(float) * 6 * nt);
    for (size_t i = 0; s->uv_emit && i < 6 * nt; i++)
        s->uv_emit[6 * old + i] = 0.0f;
    for (size_t i = 0; s->col && i < 9 * nt; i++)
        s->col[9 * old + i] = 1.0f;
    s->ntris = (uint32_t)(old + nt);
    s->nmaterials += (uint32_t)o.mats.size();
    s->ntextures += (uint32_t)o.texs.size();
    o.mats.clear(); // owned by the Scene now
    o.texs.clear();
    return true;
}

int load(Ctx &c, const std::string &text, const double *xf, Scene *s, char *err, size_t errlen)
{
    Check k;
    tinyobj::attrib_t at;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> mats;
    std::string warn, terr;
    Out o;
    o.mat_base = s->nmaterials;
    o.tex_base = s->ntextures;
    if (check_text(c, text, k)) {
        std::istringstream in(text);
        MtlReader reader(c);
        bool ok = tinyobj::LoadObj(&at, &shapes, &mats, &warn, &terr, &in, &reader, false, false);
        if (!ok && c.err.empty())
            c.fail(c.file + ": " + one_line(terr.empty() ? "not a readable OBJ file" : terr));
    }
    for (size_t i = 0; c.err.empty() && i < k.usemtl.size(); i++) {
        bool found = false;
        for (const auto &m : mats)
            found |= m.name == k.usemtl[i].second;
        if (!found)
            c.fail(c.file + ":" + std::to_string(k.usemtl[i].first) + ": usemtl '" + k.usemtl[i].second +
                   "': no material of that name in " + (c.mtllib_line.empty() ? "any MTL file (the OBJ names none)"
                                                                               : "its MTL files"));
    }
    for (size_t i = 0; c.err.empty() && i < mats.size(); i++)
        convert_material(c, o, i, mats[i]);
    if (c.err.empty())
        build_triangles(c, o, at, shapes, xf);
    if (c.err.empty() && commit(c, o, s)) {
        bool bad = false;
        if (k.lines + k.points)
            bad |= scene_warn(s, "%s: skipped %zu lines and %zu points: only faces are ray traced", c.file.c_str(),
                              k.lines, k.points) != 0;
        if (o.map_ke)
            bad |= scene_warn(s, "%s: %u materials have an emissive texture (map_Ke), which is not applied: Ke "
                                 "alone sets the emission", c.file.c_str(), o.map_ke) != 0;
        if (o.map_d)
            bad |= scene_warn(s, "%s: %u materials have an alpha texture (map_d), which is not applied: d alone "
                                 "sets the opacity", c.file.c_str(), o.map_d) != 0;
        if (bad)
            c.fail(c.file + ": out of memory");
    }
    if (!c.err.empty()) {
        std::snprintf(err, errlen, "%s", c.err.c_str());
        return -1;
    }
    return 0;
}

void set_folder(Ctx &c, const char *path)
{
    const char *slash = std::strrchr(path, '/');
    c.dir = slash ? std::string(path, (size_t)(slash - path) + 1) : std::string();
    c.root = scene_shim::lexical_path(c.dir.empty() ? "." : c.dir);
    char *real = realpath(c.dir.empty() ? "." : c.dir.c_str(), nullptr);
    c.real = real ? std::string(real) + "/" : c.root;
    std::free(real);
    const char *allow = std::getenv("SFSIM_ALLOW_OUTSIDE_URIS");
    c.allow_outside = allow && std::strcmp(allow, "1") == 0;
}

} // namespace

extern "C" int obj_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        Ctx c;
        c.file = path;
        set_folder(c, path);
        std::string text, why = read_file(path, text);
        if (!why.empty()) {
            std::snprintf(err, errlen, "%s: %s", path, why.c_str());
            return -1;
        }
        return load(c, text, xf, s, err, errlen);
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", path, e.what());
        return -1;
    }
}

extern "C" int obj_append_memory(const char *obj, size_t obj_len, const char *mtl, size_t mtl_len, const char *name,
                                 const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        Ctx c;
        c.file = name;
        c.memory = true;
        c.mtl = mtl;
        c.mtl_len = mtl_len;
        return load(c, std::string(obj, obj_len), xf, s, err, errlen);
    } catch (const std::exception &e) {
        std::snprintf(err, errlen, "%s: %s", name, e.what());
        return -1;
    }
}
