// scenes/gltf_accessor.cpp -- glTF accessors: their bufferViews and buffers, checked, and the
// sparse substitution.
//
// Owns: a checked View of an accessor (component and element types, byte strides, every element
// inside its bufferView and the bufferView inside its buffer, with every sum checked against
// overflow), the sparse substitution of glTF 2.0 Sec. 3.6.2.3 into a dense copy the Loader keeps,
// and the component-type rule for vertex attributes (FLOAT, KHR_mesh_quantization, normalized).
// Must not: interpret what an accessor holds (positions, indices, colours: gltf_mesh.cpp), or
// read past a buffer whatever the file says.
#include "gltf_internal.hpp"

namespace sfgltf {

namespace {

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

} // namespace

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


} // namespace sfgltf
