/* fovea — signed distance fields as scene objects: fv_scene_add_sdf and the Embree user geometry
 * that sphere-traces a field (issue 11: Polychronakis, Koulieris and Mania, "An Inverted Pyramid
 * Acceleration Structure Guiding Foveated Sphere Tracing for Implicit Surfaces in VR", EG 2023,
 * Sec. 2.1: march along the ray by the distance the field returns, which never overshoots).
 *
 * Each SDF object is one user primitive. Embree asks its box (fv_sdf_bounds) when building the
 * BVH and calls intersect/occluded for rays that reach the box; those clip the ray to the box and
 * sphere-trace inside it, so an SDF sits in the same BVH as the meshes and every query of
 * scene/query.h (single rays, 8-ray packets, occlusion, the static/dynamic sets) sees it. A
 * dynamic SDF is instanced like a dynamic mesh: Embree hands the callbacks the ray in object
 * space, where the field lives.
 *
 * Limits: the hit is where |distance| falls below 1e-4 of the field's bounds diagonal (then
 * refined), so a ray grazing a surface closer than that counts as a hit, as in any sphere tracer;
 * a ray that needs more than FV_KSDF_TRACE_STEPS steps is reported as a miss (kernel/ksdf_trace.h). SDF objects never
 * emit: lights stay emissive triangles and delta lights.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "core/alloc.h"
#include "kernel/ksdf_trace.h"
#include "scene/scene_impl.h"

/* Hit distance relative to the field's bounds diagonal; the scene's ray offset (1e-4 of the
 * whole scene's diagonal) is never smaller, so a ray leaving a surface starts outside the band. */
#define FV_SDF_HIT_REL 1e-4f

static bool is_leaf(fv_sdf_kind k) { return k >= FV_SDF_SPHERE && k <= FV_SDF_HEIGHTFIELD; }

fv_status fv_scene_add_sdf(fv_scene *s, const char *name, const fv_sdf_node *nodes, int count, int root, const fv_log *log,
                           int *object_id, fv_error *err)
{
    (void)log;
    if (s->committed) return fv_error_set(err, FV_ERR_INTERNAL, "scene already committed: it cannot be changed");
    if (!name) name = "sdf";
    if (!nodes || count < 1) return fv_error_set(err, FV_ERR_INVALID, "sdf '%s': no nodes", name);
    fv_sdf *sdf = NULL;
    fv_status st = fv_sdf_create(nodes, count, root, &sdf, err);
    if (st != FV_OK) {
        fv_error_prefix(err, "sdf '%s': ", name);
        return st;
    }
    for (int i = 0; i < count; i++) {
        if (!is_leaf(nodes[i].kind)) continue;
        int m = nodes[i].material;
        const char *kind = fv_sdf_kind_name(nodes[i].kind);
        if (m < 0 || m >= s->nmat) {
            fv_sdf_destroy(sdf);
            return fv_error_set(err, FV_ERR_INVALID, "sdf '%s': node %d (%s): material id %d does not exist", name, i, kind, m);
        }
        if (fv_max3(s->mats[m].emission) > 0.0f) {
            fv_sdf_destroy(sdf);
            return fv_error_set(err, FV_ERR_INVALID,
                                "sdf '%s': node %d (%s): material '%s' is emissive; SDF objects cannot emit (lights are emissive "
                                "triangles or point/spot lights)",
                                name, i, kind, s->mats[m].name);
        }
    }
    fv_object o;
    memset(&o, 0, sizeof o);
    snprintf(o.name, sizeof o.name, "%s", name);
    o.sdf = sdf;
    o.xf = o.inv = fv_xform_identity();
    fv_sdf_bounds(sdf, &o.lo, &o.hi);
    o.sdf_eps = FV_SDF_HIT_REL * fv_length(fv_sub(o.hi, o.lo));
    if (fv_grow((void **)&s->objs, &s->capobj, s->nobj + 1, sizeof *s->objs)) {
        fv_sdf_destroy(sdf);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory adding sdf '%s'", name);
    }
    s->objs[s->nobj] = o;
    if (object_id) *object_id = s->nobj;
    s->nobj++;
    return FV_OK;
}

int fv_scene_sdf_material(const fv_object *o, fv_vec3 p)
{
    int m = 0;
    fv_sdf_distance(o->sdf, p, &m);
    return m;
}

/* The box the tracer clips to and Embree bounds the field by (kernel/ksdf_trace.h). */
static void padded_box(const fv_object *o, fv_vec3 *lo, fv_vec3 *hi) { fv_sdf_padded_box(o->lo, o->hi, o->sdf_eps, lo, hi); }

/* Sphere-traces o + t d for t in [tnear, tfar] (d need not be unit): the one tracer of fields,
 * kernel/ksdf_trace.h, which the portable and CUDA traversals run too. */
static bool sdf_trace(const fv_object *ob, fv_vec3 o, fv_vec3 d, float tnear, float tfar, float *thit)
{
    return fv_sdf_trace_field(ob->sdf, ob->sdf_eps, o, d, tnear, tfar, thit);
}

/* Embree's SOA packets of runtime size N (rtcore_ray.h gives accessors only to C++): ray fields
 * org_x, org_y, org_z, tnear, dir_x, dir_y, dir_z, time, tfar, mask, id, flags, then the hit
 * Ng_x, Ng_y, Ng_z, u, v, primID, geomID, instID[levels], each N wide. */
#define RAYF(base, N, field, i) (((float *)(base))[(field) * (N) + (i)])
#define RAYU(base, N, field, i) (((unsigned *)(base))[(field) * (N) + (i)])
enum { R_OX, R_OY, R_OZ, R_TNEAR, R_DX, R_DY, R_DZ, R_TIME, R_TFAR };
enum { H_NGX, H_NGY, H_NGZ, H_U, H_V, H_PRIM, H_GEOM, H_INST };

static void sdf_bounds_cb(const struct RTCBoundsFunctionArguments *args)
{
    const fv_object *o = args->geometryUserPtr;
    fv_vec3 lo, hi;
    padded_box(o, &lo, &hi);
    struct RTCBounds *b = args->bounds_o;
    b->lower_x = lo.x;
    b->lower_y = lo.y;
    b->lower_z = lo.z;
    b->upper_x = hi.x;
    b->upper_y = hi.y;
    b->upper_z = hi.z;
}

static void ray_of(const void *ray, unsigned N, unsigned i, fv_vec3 *o, fv_vec3 *d)
{
    *o = fv_v3(RAYF(ray, N, R_OX, i), RAYF(ray, N, R_OY, i), RAYF(ray, N, R_OZ, i));
    *d = fv_v3(RAYF(ray, N, R_DX, i), RAYF(ray, N, R_DY, i), RAYF(ray, N, R_DZ, i));
}

static void sdf_intersect_cb(const struct RTCIntersectFunctionNArguments *args)
{
    const fv_object *ob = args->geometryUserPtr;
    const unsigned N = args->N;
    void *ray = args->rayhit;
    void *hit = (float *)args->rayhit + 12 * N;
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] != -1) continue;
        fv_vec3 o, d;
        ray_of(ray, N, i, &o, &d);
        float t;
        if (!sdf_trace(ob, o, d, RAYF(ray, N, R_TNEAR, i), RAYF(ray, N, R_TFAR, i), &t)) continue;
        fv_vec3 n = fv_sdf_normal(ob->sdf, fv_madd(o, d, t), 0.0f);
        /* Where the differences cancel (a crease's exact middle), face the ray. */
        if (!(fv_dot(n, n) > 0.0f)) n = fv_neg(d);
        RAYF(ray, N, R_TFAR, i) = t;
        RAYF(hit, N, H_NGX, i) = n.x;
        RAYF(hit, N, H_NGY, i) = n.y;
        RAYF(hit, N, H_NGZ, i) = n.z;
        RAYF(hit, N, H_U, i) = 0.0f;
        RAYF(hit, N, H_V, i) = 0.0f;
        RAYU(hit, N, H_PRIM, i) = args->primID;
        RAYU(hit, N, H_GEOM, i) = args->geomID;
        for (unsigned l = 0; l < RTC_MAX_INSTANCE_LEVEL_COUNT; l++) RAYU(hit, N, H_INST + l, i) = args->context->instID[l];
    }
}

static void sdf_occluded_cb(const struct RTCOccludedFunctionNArguments *args)
{
    const fv_object *ob = args->geometryUserPtr;
    const unsigned N = args->N;
    void *ray = args->ray;
    for (unsigned i = 0; i < N; i++) {
        if (args->valid[i] != -1) continue;
        fv_vec3 o, d;
        ray_of(ray, N, i, &o, &d);
        float t;
        if (sdf_trace(ob, o, d, RAYF(ray, N, R_TNEAR, i), RAYF(ray, N, R_TFAR, i), &t)) RAYF(ray, N, R_TFAR, i) = -INFINITY;
    }
}

RTCGeometry fv_scene_sdf_geometry(fv_scene *s, fv_object *o)
{
    RTCGeometry g = rtcNewGeometry(s->dev, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, o);
    rtcSetGeometryBoundsFunction(g, sdf_bounds_cb, NULL);
    rtcSetGeometryIntersectFunction(g, sdf_intersect_cb);
    rtcSetGeometryOccludedFunction(g, sdf_occluded_cb);
    rtcCommitGeometry(g);
    return g;
}
