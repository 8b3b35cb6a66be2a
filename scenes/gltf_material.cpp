// scenes/gltf_material.cpp -- glTF materials and their textures.
//
// Owns: the mapping of glTF materials to SceneMaterial (ARCHITECTURE.md Sec. 1: dielectric,
// coupled glossy or Lambertian; KHR_materials_emissive_strength, _transmission, _ior; alpha
// modes), glTF's default material, decoding the images a material uses (sRGB to linear RGBA
// floats; bufferView images checked against their buffer first), the texture coordinates each
// texture samples (texCoord and KHR_texture_transform), the sampler wrap-mode warning count, and
// the emissive-texture analysis that splits a partly emitting material into a dark part and an
// emitting twin. Must not: read vertex data (gltf_mesh.cpp applies the UvMaps and asks
// uv_emits per triangle), or move anything into the Scene (commit in gltf_load.cpp does).
#include "gltf_internal.hpp"

#include <climits>
#include <cmath>

namespace sfgltf {

namespace {

float srgb8_table[256];
bool srgb8_ready = false;

float srgb_to_linear(double c)
{
    return (float)(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
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

} // namespace

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
namespace {

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

} // namespace

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
        // What the renderers multiply: the emitted radiance (limits of scene values, scene.h).
        char why[320];
        double em[3];
        for (int k = 0; k < 3; k++)
            em[k] = gm.emissiveFactor.size() == 3 ? gm.emissiveFactor[(size_t)k] * strength : 0.0;
        if (scene_limit_check(SCENE_LIMIT_RADIANCE, em, 3, why, sizeof why) != 0)
            return L.fail(where + ": emission (emissiveFactor x KHR_materials_emissive_strength) " + why);
        for (int k = 0; k < 3; k++)
            sm.emission[k] = (float)em[k];
        for (int k = 0; k < 3; k++)
            if (!std::isfinite(sm.base_color[k]) || !std::isfinite(sm.emission[k]) || sm.base_color[k] < 0.0f ||
                sm.emission[k] < 0.0f)
                return L.fail(where + ": colour component is negative or not finite");
        double base[3] = {sm.base_color[0], sm.base_color[1], sm.base_color[2]};
        if (scene_limit_check(SCENE_LIMIT_REFLECTANCE, base, 3, why, sizeof why) != 0 &&
            scene_warn(L.s, "%s: %s: baseColorFactor %s: such a surface reflects more light than it receives",
                       L.file.c_str(), where.c_str(), why) != 0)
            return L.fail("out of memory");
        if (!std::isfinite(sm.alpha) || !std::isfinite(sm.metallic) || !std::isfinite(sm.roughness) ||
            !std::isfinite(sm.transmission) || !std::isfinite((float)gm.alphaCutoff))
            return L.fail(where + ": a factor is not finite");
        if (!(sm.ior >= 1.0f) || !std::isfinite(sm.ior)) {
            // KHR_materials_ior: 0 means 1 / infinity (a perfect mirror); anything else below 1 is invalid.
            if (sm.ior == 0.0f)
                sm.ior = 1.0f;
            else if (std::isfinite(sm.ior))
                return L.fail(where + ": KHR_materials_ior ior " + std::to_string(sm.ior) + " is below 1");
        }
        if (scene_limit_check1(SCENE_LIMIT_IOR, sm.ior, why, sizeof why) != 0)
            return L.fail(where + ": KHR_materials_ior ior " + why);
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

} // namespace sfgltf
