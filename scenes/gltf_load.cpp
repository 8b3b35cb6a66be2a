// scenes/gltf_load.cpp -- glTF 2.0 through tinygltf (Debian's libtinygltf 2.7), behind the C API of
// scenes/gltf.h: the entry points and the document as a whole.
//
// Owns: gltf_append and gltf_append_memory; reading the file (regular files only) and the external
// files tinygltf asks for, only inside the glTF file's folder; the checks made before tinygltf
// parses (JSON depth, required extensions); the tinygltf parse, with images kept encoded; the
// node hierarchy's checks and its roots; commit into the Scene (triangles, materials, textures,
// lights, warnings); the names used in messages. The parts of the document are read by the
// other scenes/gltf_*.cpp files (scenes/gltf_internal.hpp lists them). Must not: pick scene
// defaults, compute bounds or needs (scenes/scene.c), build acceleration structures, print
// anything, or let an exception cross the C boundary.
//
// The glTF shim is the only C++ in the project besides the OpenImageIO shim (ARCHITECTURE.md
// Sec. 2). The fuzz build (tests/fuzz/fuzz_scene.c) compiles tinygltf and stb_image into this
// file, so the sanitizers and the fuzzer's coverage reach inside them; every other build links
// Debian's libtinygltf.
#ifdef SFSIM_TINYGLTF_IMPLEMENTATION
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE_WRITE
#endif
#include "gltf_internal.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>

#include <sys/stat.h>
#include <unistd.h>

#include <cjson/cJSON.h>
#include <cstdlib>

#include "../host/infile.h"

namespace sfgltf {

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


namespace {

// ---- images: kept encoded while tinygltf parses, decoded only when a material uses them --------

// tinygltf calls this for images given by data URI or external file (the bytes are ours to copy)
// and for images in a bufferView. The latter are not touched here: tinygltf 2.7 hands over
// &buffer.data[byteOffset] without checking that the view lies inside its buffer, so those bytes
// are read later, after our own check (decode_image). Decoding lazily also skips normal, occlusion
// and metallic-roughness maps, which nothing here uses.
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

bool under(const std::string &path, const std::string &dir) { return path.compare(0, dir.size(), dir) == 0; }

// Whether `path` stays inside the folder: by name, and, when it exists, through symbolic links.
bool inside_folder(const FsContext &c, const std::string &path)
{
    if (!under(scene_shim::lexical_path(path), c.root))
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
    // The one input check (host/infile.h): a folder, a device or a FIFO is refused by name.
    char *buf, why[4352];
    size_t len;
    if (infile_read(path.c_str(), SCENE_FILE_MAX_BYTES, "a scene file", &buf, &len, why, sizeof why) != 0) {
        if (err)
            *err += std::string(why) + "\n";
        return false;
    }
    out->assign(buf, buf + len);
    std::free(buf);
    return true;
}

// ---- extensions ------------------------------------------------------------------------------

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

// ---- the document ----------------------------------------------------------------------------

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
    if (L.camera_set && s->camera.source == SCENE_CAMERA_DEFAULT) {
        s->camera = L.camera;
        std::free(s->camera_from);
        if (!(s->camera_from = strdup((L.file + ": " + L.camera_where).c_str())))
            return L.fail("out of memory");
    }
    return true;
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
    if (binary && len >= 12) {
        // The GLB header (glTF 2.0 Sec. 4.4.2): magic, version, length. tinygltf 2.7 reads a
        // version 1 container (binary glTF 1.0, whose JSON means something else) without a word.
        uint32_t version;
        std::memcpy(&version, data + 4, 4);
        if (version != 2) {
            std::snprintf(err, errlen, "%s: GLB header version %u, not 2: sfsim reads glTF 2.0 only", name,
                          (unsigned)version);
            return -1;
        }
    }
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
} // namespace sfgltf

using namespace sfgltf;

extern "C" int gltf_append(const char *path, const double *xf, Scene *s, char *err, size_t errlen)
{
    try {
        // The file is read here, not by tinygltf: it sizes files by seeking to their end, which
        // on a directory or a device gives nonsense (a directory "holds" 2^63 bytes), and the
        // JSON is checked before tinygltf parses it (json_too_deep).
        std::vector<unsigned char> data;
        std::string rerr;
        if (!read_regular_file(&data, &rerr, path, nullptr)) { // (the file named by the user: no folder check)
            std::snprintf(err, errlen, "%s", one_line(rerr).c_str());
            return -1;
        }
        const char *slash = std::strrchr(path, '/');
        std::string base_dir = slash ? std::string(path, (size_t)(slash - path) + 1) : std::string();
        FsContext ctx;
        ctx.base = base_dir;
        ctx.root = scene_shim::lexical_path(base_dir.empty() ? "." : base_dir);
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
