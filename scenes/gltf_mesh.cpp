// scenes/gltf_mesh.cpp -- glTF primitives into the Scene's triangle arrays.
//
// Owns: one primitive at a time (its mode, POSITION, NORMAL, COLOR_0 and TEXCOORD_n attributes,
// its indices, strips and fans unrolled, its material), every vertex through the node
// transforms with the coordinate limit checked, normals through the inverse transpose, the
// winding kept under mirroring transforms, and the Scene's per-triangle arrays (grown once from
// a counting pass; optional arrays added when a file first has the attribute). Must not: make the
// new triangles count (commit in gltf_load.cpp sets Scene.ntris, so a failed file leaves the
// Scene as it was), walk the node hierarchy (gltf_node.cpp), or decide materials
// (gltf_material.cpp).
#include "gltf_internal.hpp"

#include <algorithm>
#include <cmath>

namespace sfgltf {

namespace {

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

} // namespace

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

namespace {

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
    bool identity = m[0] == 1 && m[1] == 0 && m[2] == 0 && m[3] == 0 && m[4] == 1 && m[5] == 0;
    for (size_t v = 0; v < nverts; v++) {
        double u = vt.get(v, 0), w = vt.get(v, 1);
        double t[2] = {m[0] * u + m[1] * w + m[2], m[3] * u + m[4] * w + m[5]};
        for (int k = 0; k < 2; k++) {
            if (!std::isfinite((float)t[k]))
                return L.fail(where + " " + attr + ": vertex " + std::to_string(v) + " is not finite" +
                              (identity ? "" : " after KHR_texture_transform"));
            char why[320];
            if (scene_limit_check1(SCENE_LIMIT_UV, t[k], why, sizeof why) != 0)
                return L.fail(where + " " + attr + ": vertex " + std::to_string(v) + " coordinate " +
                              std::to_string(k) + (identity ? " " : " after KHR_texture_transform ") + why);
            out[2 * v + (size_t)k] = (float)t[k];
        }
    }
    return true;
}

// ---- one primitive -----------------------------------------------------------------------------

// A primitive's vertex attributes, checked: POSITION (accessor pos_acc), NORMAL and COLOR_0 when
// it has them.
struct Attributes {
    View vp, vn, vc;
    int pos_acc = -1;
    bool has_n = false, has_c = false;
};

bool read_attributes(Loader &L, const tinygltf::Primitive &p, const std::string &where, Attributes &a)
{
    auto pa = p.attributes.find("POSITION");
    if (pa == p.attributes.end())
        return L.fail(where + ": no POSITION attribute");
    a.pos_acc = pa->second;
    View &vp = a.vp, &vn = a.vn, &vc = a.vc;
    if (!accessor_view(L, pa->second, where + " POSITION", vp))
        return false;
    if (vp.ncomp != 3)
        return L.fail(where + " POSITION: accessor " + std::to_string(pa->second) + " is not VEC3");
    if (!check_float_or_quantized(L, vp, where + " POSITION: accessor " + std::to_string(pa->second), false))
        return false;
    auto na = p.attributes.find("NORMAL");
    a.has_n = na != p.attributes.end();
    if (a.has_n) {
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
    a.has_c = ca != p.attributes.end();
    if (a.has_c) {
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
    return true;
}

// The primitive's triangles as vertex index triples (strips and fans unrolled, keeping the
// winding), from its indices or, without them, its nverts vertices in order.
bool triangle_list(Loader &L, const tinygltf::Primitive &p, const std::string &where, int mode, size_t nverts,
                   std::vector<uint32_t> &tri)
{
    // Indices: any unsigned integer type, each below the vertex count.
    std::vector<uint32_t> idx;
    if (p.indices >= 0) {
        View vi;
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
            if (v >= nverts)
                return L.fail(where + ": index " + std::to_string(v) + " out of range (vertex count " +
                              std::to_string(nverts) + ")");
            idx[i] = v;
        }
    } else {
        if (nverts > 0xFFFFFFFFu)
            return L.fail(where + ": more than 2^32 vertices");
        idx.resize(nverts);
        for (size_t i = 0; i < nverts; i++)
            idx[i] = (uint32_t)i;
    }
    if (mode == TINYGLTF_MODE_TRIANGLES && idx.size() % 3 != 0)
        return L.fail(where + ": " + std::to_string(idx.size()) + (p.indices >= 0 ? " indices" : " vertices") +
                      " do not make whole triangles (not a multiple of 3)");
    // The triangle list.
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
    return true;
}

// The material of a primitive: its SceneMaterial (absolute index), the emitting twin (-1 for
// none), and what the material samples.
struct PrimMaterial {
    int mat = -1, twin = -1;
    const MatInfo *mi = nullptr;
};

bool primitive_material(Loader &L, const tinygltf::Primitive &p, const std::string &where, PrimMaterial &pm)
{
    static const MatInfo no_material;
    if (p.material >= 0) {
        if ((size_t)p.material >= L.m.materials.size())
            return L.fail(where + ": material " + std::to_string(p.material) + " does not exist");
        pm.mi = &L.minfo[(size_t)p.material];
        pm.mat = pm.mi->index;
        pm.twin = pm.mi->emit_twin;
    } else if ((pm.mat = default_material(L)) < 0) {
        return L.fail("out of memory");
    } else {
        pm.mi = &no_material;
    }
    return true;
}

// Every vertex of a primitive once: positions and normals through the node transforms, colours,
// and texture coordinates per texture (wt: the base colour's, we: the emissive texture's).
struct Vertices {
    std::vector<float> wp, wn, wc, wt, we; // wn, wc, wt, we empty without the attribute
    bool has_n = false, has_c = false, has_t = false, has_e = false;
};

bool transform_vertices(Loader &L, const Attributes &a, const std::string &where, const Mat4 &full, Vertices &w)
{
    const View &vp = a.vp, &vn = a.vn, &vc = a.vc;
    bool has_n = a.has_n, has_c = a.has_c;
    double nm[9];
    bool nm_ok = normal_matrix(full, nm);
    w.has_n = has_n;
    w.has_c = has_c;
    w.wp.assign(3 * vp.count, 0.0f);
    w.wn.assign(has_n ? 3 * vp.count : 0, 0.0f);
    w.wc.assign(has_c ? 3 * vp.count : 0, 0.0f);
    std::string pw = where + " POSITION: accessor " + std::to_string(a.pos_acc) + ": vertex ";
    for (size_t v = 0; v < vp.count; v++) {
        double in[3] = {vp.get(v, 0), vp.get(v, 1), vp.get(v, 2)}, out[3];
        // What the file holds first, then where the node transforms put it: each error says which.
        for (int k = 0; k < 3; k++) {
            if (!std::isfinite(in[k]))
                return L.fail(pw + std::to_string(v) + " coordinate " + std::to_string(k) + " is not finite (" +
                              std::to_string(in[k]) + ")");
            char why[320];
            if (scene_limit_check1(SCENE_LIMIT_COORD, in[k], why, sizeof why) != 0)
                return L.fail(pw + std::to_string(v) + " coordinate " + std::to_string(k) + " " + why);
        }
        xform_point(full, in, out);
        char why[320];
        if (scene_limit_check(SCENE_LIMIT_COORD, out, 3, why, sizeof why) != 0)
            return L.fail(pw + std::to_string(v) + " after the node transforms " + why);
        for (int k = 0; k < 3; k++)
            w.wp[3 * v + (size_t)k] = (float)out[k];
        if (has_n) {
            double n[3] = {vn.get(v, 0), vn.get(v, 1), vn.get(v, 2)}, o[3] = {n[0], n[1], n[2]};
            if (nm_ok)
                for (int r = 0; r < 3; r++)
                    o[r] = nm[r] * n[0] + nm[3 + r] * n[1] + nm[6 + r] * n[2];
            if (!normalize(o)) // zero or non-finite normals fall back to the geometric normal
                o[0] = o[1] = o[2] = 0.0;
            for (int k = 0; k < 3; k++)
                w.wn[3 * v + (size_t)k] = (float)o[k];
        }
        if (has_c)
            for (int k = 0; k < 3; k++) {
                double c = vc.get(v, k);
                if (!std::isfinite(c) || c < 0.0)
                    return L.fail(where + " COLOR_0: vertex " + std::to_string(v) + " component " + std::to_string(k) +
                                  " is negative or not finite (" + std::to_string(c) + ")");
                w.wc[3 * v + (size_t)k] = (float)c;
            }
    }
    return true;
}

// The triangles `tri` (vertex index triples into w) after the ones written so far: positions,
// normals (a vertex without a usable normal gets the geometric one), texture coordinates, colours
// and materials (the emitting twin where the triangle touches an emitting texel). A mirroring
// transform reverses the winding (glTF 2.0 Sec. 3.7.4).
bool write_triangles(Loader &L, const std::string &where, const Mat4 &full, const std::vector<uint32_t> &tri,
                     const PrimMaterial &pm, const Vertices &w)
{
    const MatInfo *mi = pm.mi;
    int mat = pm.mat, twin = pm.twin;
    bool has_n = w.has_n, has_t = w.has_t, has_e = w.has_e, has_c = w.has_c;
    const std::vector<float> &wp = w.wp, &wn = w.wn, &wt = w.wt, &we = w.we, &wc = w.wc;
    bool flip = det3(full) < 0.0;
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
        // The renderers square |e1 x e2| in binary32 for the triangle's normal (and an emitting
        // triangle's area): beyond the AREA limit it is inf and the triangle turns black.
        char why[320];
        if (scene_limit_check1(SCENE_LIMIT_AREA, std::sqrt(gn[0] * gn[0] + gn[1] * gn[1] + gn[2] * gn[2]), why,
                               sizeof why) != 0)
            return L.fail(where + ": triangle " + std::to_string(t) + " (vertices " + std::to_string(tri[3 * t]) +
                          ", " + std::to_string(tri[3 * t + 1]) + ", " + std::to_string(tri[3 * t + 2]) +
                          "): |e1 x e2| " + why);
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

} // namespace

bool load_primitive(Loader &L, const Mat4 &full, int mesh, int pi)
{
    const auto &gm = L.m.meshes[(size_t)mesh];
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
    Attributes a;
    std::vector<uint32_t> tri;
    PrimMaterial pm;
    if (!read_attributes(L, p, where, a) || !triangle_list(L, p, where, mode, a.vp.count, tri) ||
        !primitive_material(L, p, where, pm))
        return false;
    // Texture coordinates, per texture: the base-colour texture's set through its transform (a
    // material without one: TEXCOORD_0 as it is), the emissive texture's likewise.
    Vertices w;
    if (!read_uvs(L, p, where, pm.mi->base_uv, a.vp.count, w.wt, w.has_t) ||
        (pm.mi->emit_tex && !read_uvs(L, p, where, pm.mi->emit_uv, a.vp.count, w.we, w.has_e)))
        return false;
    return transform_vertices(L, a, where, full, w) && write_triangles(L, where, full, tri, pm, w);
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

} // namespace sfgltf
