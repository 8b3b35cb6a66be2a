/* tests/support/xcheck.c -- golden-model closest hits against Embree 3 (robust mode). */
#include "xcheck.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../../sim/ref_kd.h"
#include "../../sim/ref_trace.h"
#include "../../sim/reference.h"
#include "../../sim/util.h"

static void make_ray(const PackedScene *p, uint32_t i, uint32_t camera_rays, uint32_t seed, RefRay *r)
{
    float bmin[3], bmax[3];
    for (int k = 0; k < 3; k++) {
        bmin[k] = sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MIN + k));
        bmax[k] = sm_f32(p, sm_hdr(p, SM_HDR_BOUNDS_MAX + k));
    }
    uint32_t key = ref_path_key(seed, i, 0);
    if (i < camera_rays) {
        /* Camera rays over a square grid covering the image. */
        uint32_t side = (uint32_t)ceil(sqrt((double)camera_rays));
        float px = ((float)(i % side) + ref_rand(key, 0, 0)) / (float)side - 0.5f;
        float py = 0.5f - ((float)(i / side) + ref_rand(key, 0, 1)) / (float)side;
        for (int k = 0; k < 3; k++) {
            r->org[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_POS + k));
            r->dir[k] = sm_f32(p, sm_hdr(p, SM_HDR_CAM_W + k)) + px * sm_f32(p, sm_hdr(p, SM_HDR_CAM_U + k)) +
                        py * sm_f32(p, sm_hdr(p, SM_HDR_CAM_V + k));
        }
    } else {
        /* Random rays: origin uniform in the bounds, direction uniform on the sphere. */
        float z = 1.0f - 2.0f * ref_rand(key, 1, 2), phi = 6.2831853f * ref_rand(key, 1, 3);
        float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        r->dir[0] = s * cosf(phi);
        r->dir[1] = s * sinf(phi);
        r->dir[2] = z;
        for (int k = 0; k < 3; k++)
            r->org[k] = bmin[k] + ref_rand(key, 1, (uint32_t)k) * (bmax[k] - bmin[k]);
    }
    float il = 1.0f / sqrtf(r->dir[0] * r->dir[0] + r->dir[1] * r->dir[1] + r->dir[2] * r->dir[2]);
    for (int k = 0; k < 3; k++)
        r->dir[k] *= il;
    r->tmax = INFINITY;
}

/* How far two correct binary32 intersectors may disagree on t for this ray and triangle. The
 * rounding error of a ray/plane distance grows with the magnitude of the coordinates involved
 * (origin, vertices, hit point), not with t, and with 1 / |cos| of the angle between ray and
 * plane. The watertight test also divides barycentric-weighted sums by their total (twice the
 * projected area), so on slivers it loses precision in proportion to the ratio of the longest
 * edge to the height on it (sponza has 11.6 x 0.019 slivers where it is off by 1e-4 of t while
 * Embree is exact). 32 ulps of the magnitude, times (1 + that ratio), over the cosine. */
static float t_tolerance(const Scene *s, const RefRay *r, uint32_t tri, float t)
{
    const float *p = &s->pos[9 * (size_t)tri];
    float mag = 0.0f;
    for (int k = 0; k < 9; k++)
        mag = fmaxf(mag, fabsf(p[k]));
    for (int k = 0; k < 3; k++)
        mag = fmaxf(mag, fabsf(r->org[k]));
    mag += t;
    float e1[3], e2[3], n[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = p[3 + k] - p[k];
        e2[k] = p[6 + k] - p[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    float nl = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float c = nl > 0.0f ? fabsf(n[0] * r->dir[0] + n[1] * r->dir[1] + n[2] * r->dir[2]) / nl : 0.0f;
    float e3[3] = {p[6] - p[3], p[7] - p[4], p[8] - p[5]};
    float l2 = fmaxf(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2],
                     fmaxf(e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2], e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2]));
    float sliver = nl > 0.0f ? l2 / nl : 1e6f; /* longest edge / height on it = L^2 / (2 area) */
    return 32.0f * FLT_EPSILON * mag * (1.0f + sliver) / fmaxf(c, 1e-3f);
}

int xcheck_embree_open(const Scene *scene, XcheckEmbree *e, char *err, size_t errlen)
{
    memset(e, 0, sizeof *e);
    e->dev = rtcNewDevice("threads=1");
    if (!e->dev) {
        snprintf(err, errlen, "embree: cannot create a device (error %d)", (int)rtcGetDeviceError(NULL));
        return -1;
    }
    e->scene = rtcNewScene(e->dev);
    rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    if (scene->ntris > 0) {
        RTCGeometry g = rtcNewGeometry(e->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                            3 * sizeof(float), 3 * (size_t)scene->ntris);
        unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                               3 * sizeof(unsigned), scene->ntris);
        if (!vb || !ib) {
            snprintf(err, errlen, "embree: cannot allocate buffers for %u triangles", scene->ntris);
            rtcReleaseGeometry(g);
            xcheck_embree_close(e);
            return -1;
        }
        memcpy(vb, scene->pos, sizeof(float) * 9 * (size_t)scene->ntris);
        for (uint32_t i = 0; i < 3 * scene->ntris; i++)
            ib[i] = i;
        rtcCommitGeometry(g);
        rtcAttachGeometry(e->scene, g);
        rtcReleaseGeometry(g);
    }
    double t0 = util_now();
    rtcCommitScene(e->scene);
    e->build_seconds = util_now() - t0;
    if (rtcGetDeviceError(e->dev) != RTC_ERROR_NONE) {
        snprintf(err, errlen, "embree: the scene's build failed (error %d)", (int)rtcGetDeviceError(e->dev));
        xcheck_embree_close(e);
        return -1;
    }
    return 0;
}

void xcheck_embree_close(XcheckEmbree *e)
{
    if (e->scene)
        rtcReleaseScene(e->scene);
    if (e->dev)
        rtcReleaseDevice(e->dev);
    memset(e, 0, sizeof *e);
}

XcheckVerdict xcheck_compare(const Scene *scene, const PackedScene *p, const RefRay *r, const RefHit *ours,
                             int ehit, uint32_t eprim, float et)
{
    int ohit = ours->prim != REF_NO_HIT;
    if (!ehit || !ohit)
        return ehit == ohit ? XCHECK_AGREE : XCHECK_DISAGREE;
    uint32_t prims = sm_u32(p, sm_hdr(p, SM_HDR_PRIMS));
    uint32_t osrc = sm_u32(p, sm_rec(prims, SM_PRIM_WORDS, ours->prim, SM_PRIM_SRC));
    int close = fabsf(ours->t - et) <= t_tolerance(scene, r, osrc, ours->t);
    if (osrc == eprim)
        return close ? XCHECK_AGREE : XCHECK_DISAGREE;
    return close ? XCHECK_TIE : XCHECK_DISAGREE;
}

int xcheck_run(const Scene *scene, const PackedScene *p, const XcheckTracer *tr, uint32_t camera_rays,
               uint32_t random_rays, uint32_t seed, XcheckResult *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    out->first_bad = UINT64_MAX;
    XcheckEmbree e;
    if (xcheck_embree_open(scene, &e, err, errlen) != 0)
        return -1;
    uint32_t n = camera_rays + random_rays;
    RefHit *ours = malloc(sizeof(RefHit) * n);
    RefRay *rays = malloc(sizeof(RefRay) * n);
    if (!ours || !rays) {
        free(ours);
        free(rays);
        xcheck_embree_close(&e);
        snprintf(err, errlen, "xcheck: out of memory for %u rays", n);
        return -1;
    }
    for (uint32_t i = 0; i < n; i++)
        make_ray(p, i, camera_rays, seed, &rays[i]);
    double t0 = util_now();
    for (uint32_t i = 0; i < n; i++)
        if (tr && tr->kd)
            ref_kd_closest_hit(p, tr->kd, (RefKdVariant)tr->variant, tr->depth, &rays[i], &ours[i], NULL);
        else
            ref_closest_hit(p, &rays[i], &ours[i], NULL);
    double t1 = util_now();
    for (uint32_t i = 0; tr && tr->kd && i < n; i++) {
        RefHit b;
        ref_closest_hit(p, &rays[i], &b, NULL);
        out->unlike_bvh += b.prim != ours[i].prim || (b.prim != REF_NO_HIT && memcmp(&b, &ours[i], sizeof b) != 0);
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    double te = 0.0;
    for (uint32_t i = 0; i < n; i++) {
        struct RTCRayHit rh;
        memset(&rh, 0, sizeof rh);
        xcheck_embree_ray(&rays[i], &rh.ray);
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        double a = util_now();
        rtcIntersect1(e.scene, &ctx, &rh);
        te += util_now() - a;
        out->hits += (uint64_t)(ours[i].prim != REF_NO_HIT);
        XcheckVerdict v = xcheck_compare(scene, p, &rays[i], &ours[i], rh.hit.geomID != RTC_INVALID_GEOMETRY_ID,
                                         rh.hit.primID, rh.ray.tfar);
        if (v == XCHECK_AGREE) {
            out->agree++;
        } else if (v == XCHECK_TIE) {
            out->ties++;
        } else {
            out->disagree++;
            if (out->first_bad == UINT64_MAX)
                out->first_bad = i;
        }
    }
    out->rays = n;
    out->ours_seconds = t1 - t0;
    out->embree_seconds = te;
    free(ours);
    free(rays);
    xcheck_embree_close(&e);
    return 0;
}

void xcheck_embree_ray(const RefRay *r, struct RTCRay *er)
{
    memset(er, 0, sizeof *er);
    er->org_x = r->org[0];
    er->org_y = r->org[1];
    er->org_z = r->org[2];
    er->dir_x = r->dir[0];
    er->dir_y = r->dir[1];
    er->dir_z = r->dir[2];
    er->tnear = 0.0f;
    er->tfar = r->tmax;
    er->mask = 0xFFFFFFFFu;
}
