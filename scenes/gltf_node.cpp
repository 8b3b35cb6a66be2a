// scenes/gltf_node.cpp -- the glTF node hierarchy: transforms, the walk over the nodes, cameras
// and KHR_lights_punctual.
//
// Owns: the double-precision matrix helpers (column-major like glTF), a node's local transform
// (matrix or translation x rotation x scale, checked), the depth-first walk that hands each mesh's
// primitives to gltf_mesh.cpp under the full transform (placement x world), the first perspective
// camera and the punctual lights with their node transforms. Must not: check the hierarchy's
// shape (gltf_load.cpp does, before the walk), read accessors or materials itself, or touch the
// Scene (lights and the camera wait in the Loader until commit).
#include "gltf_internal.hpp"

#include <cmath>

namespace sfgltf {

// ---- small matrix helpers (double precision; column-major like glTF) --------------------------

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

namespace {

// How far a node matrix's bottom row may be from 0 0 0 1 (absolute, per entry): a few binary32
// ulps of 1 (2^-23 = 1.2e-7) and more, far below any projection.
const double AFFINE_TOLERANCE = 1e-6;

// ---- nodes -----------------------------------------------------------------------------------

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
    // glTF 2.0 Sec. 5.25: a node's matrix is affine (TRS is by construction). A bottom row other
    // than 0 0 0 1 would be a projection, which xform_point (and the renderers) cannot apply:
    // refused, within AFFINE_TOLERANCE of each entry (exporters round-trip through binary32).
    const double bottom[4] = {r.m[3], r.m[7], r.m[11], r.m[15]};
    if (std::fabs(bottom[0]) > AFFINE_TOLERANCE || std::fabs(bottom[1]) > AFFINE_TOLERANCE ||
        std::fabs(bottom[2]) > AFFINE_TOLERANCE || std::fabs(bottom[3] - 1.0) > AFFINE_TOLERANCE)
        return L.fail(elem("node", node, n.name) + ": matrix is not affine: its bottom row is (" + num(bottom[0]) +
                      ", " + num(bottom[1]) + ", " + num(bottom[2]) + ", " + num(bottom[3]) +
                      "), not (0, 0, 0, 1) within " + num(AFFINE_TOLERANCE));
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
    // Checked against the limits once the scene is whole (scene_finish): a scene.ini [camera] may
    // still replace what is out of range.
    L.camera_where = elem("node", node, n.name) + ": " + elem("camera", n.camera, cam.name);
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
    // What the renderers use: the position (a shadow ray's end) and colour x intensity, the
    // radiance scenes/pack.c stores (in binary32, as here).
    char why[320];
    double rad[3], pos[3] = {po[0], po[1], po[2]};
    for (int k = 0; k < 3; k++)
        rad[k] = (double)(sl.color[k] * sl.intensity);
    if (sl.kind != SCENE_LIGHT_DIRECTIONAL && scene_limit_check(SCENE_LIMIT_COORD, pos, 3, why, sizeof why) != 0)
        return L.fail(where + " " + lw + ": position " + why);
    if (scene_limit_check(sl.kind == SCENE_LIGHT_DIRECTIONAL ? SCENE_LIMIT_RADIANCE : SCENE_LIMIT_INTENSITY, rad, 3,
                          why, sizeof why) != 0)
        return L.fail(lw + ": color x intensity " + why);
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

} // namespace

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
    for (double v : full.m)
        if (!std::isfinite(v))
            return L.fail(elem("node", node, n.name) + ": transform composed with its parents' is not finite");
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
} // namespace sfgltf
