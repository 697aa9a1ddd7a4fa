/* fovea — scene model and its Embree acceleration structures (see scene_impl.h for the layout).
 *
 * Limits: triangle meshes and signed distance fields (scene_sdf.c) only; rigid animation only
 * (anim.c, for objects and delta lights alike); emissive objects must be static (area lights are
 * sampled from a table built once at commit; a moving delta light only updates its entry).
 */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "fovea/limits.h"
#include "scene/scene_impl.h"
#include "scene/texture.h"

static void embree_error(void *user, enum RTCError code, const char *str)
{
    fv_scene *s = user;
    snprintf(s->embree_msg, sizeof s->embree_msg, "Embree error %d: %s", (int)code, str ? str : "");
}

fv_status fv_scene_create(fv_scene **out, fv_error *err)
{
    fv_scene *s = calloc(1, sizeof *s);
    if (!s) return fv_error_set(err, FV_ERR_NOMEM, "out of memory creating a scene");
    s->dev = rtcNewDevice(NULL);
    if (!s->dev) {
        free(s);
        return fv_error_set(err, FV_ERR_INTERNAL, "cannot create an Embree device (error %d)", (int)rtcGetDeviceError(NULL));
    }
    rtcSetDeviceErrorFunction(s->dev, embree_error, s);
    *out = s;
    return FV_OK;
}

void fv_scene_destroy(fv_scene *s)
{
    if (!s) return;
    for (int i = 0; i < s->nobj; i++) {
        fv_object *o = &s->objs[i];
        free(o->pos);
        free(o->nrm);
        free(o->uv);
        free(o->idx);
        free(o->mat);
        fv_anim_free(&o->anim);
        fv_sdf_destroy(o->sdf);
        if (o->rtc_child) rtcReleaseScene(o->rtc_child);
        if (s->tri_light) free(s->tri_light[i]);
    }
    if (s->rtc_all) rtcReleaseScene(s->rtc_all);
    if (s->rtc_dynamic) rtcReleaseScene(s->rtc_dynamic);
    if (s->rtc_static) rtcReleaseScene(s->rtc_static);
    if (s->dev) rtcReleaseDevice(s->dev);
    free(s->tri_light);
    free(s->objs);
    free(s->mats);
    for (int i = 0; i < s->ntex; i++) free(s->tex[i].rgb);
    free(s->tex);
    for (int i = 0; i < s->ndelta; i++) fv_anim_free(&s->delta[i].anim);
    free(s->delta);
    free(s->lights);
    free(s->light_cdf);
    free(s->ktex);
    free(s);
}

static fv_status check_open(const fv_scene *s, fv_error *err)
{
    return s->committed ? fv_error_set(err, FV_ERR_INTERNAL, "scene already committed: it cannot be changed") : FV_OK;
}

fv_status fv_scene_add_material(fv_scene *s, const fv_material *m, int *id, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK || (st = fv_material_validate(m, err)) != FV_OK) return st;
    if (m->albedo_texture > s->ntex)
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': albedo_texture %d does not exist", m->name, m->albedo_texture);
    if (m->emission_texture > s->ntex)
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': emission_texture %d does not exist", m->name, m->emission_texture);
    if (fv_grow((void **)&s->mats, &s->capmat, s->nmat + 1, sizeof *s->mats))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory adding material '%s'", m->name);
    s->mats[s->nmat] = *m;
    s->mats[s->nmat].name[FV_NAME_MAX - 1] = '\0';
    if (id) *id = s->nmat;
    s->nmat++;
    return FV_OK;
}

int fv_scene_find_material(const fv_scene *s, const char *name)
{
    for (int i = 0; i < s->nmat; i++)
        if (strcmp(s->mats[i].name, name) == 0) return i;
    return -1;
}

/* A triangle is kept when its vertices are finite and within the ray kernels' range
 * (fovea/limits.h) and it has a non-zero area relative to its edge lengths (collinear vertices
 * give zero area and a NaN normal). */
static bool in_range(fv_vec3 p)
{
    return fv_limit_vec3("", p, NULL) == FV_OK; /* false for NaN */
}

static bool triangle_ok(fv_vec3 a, fv_vec3 b, fv_vec3 c)
{
    if (!in_range(a) || !in_range(b) || !in_range(c)) return false;
    fv_vec3 e1 = fv_sub(b, a), e2 = fv_sub(c, a);
    float cr = fv_length(fv_cross(e1, e2));
    return isfinite(cr) && cr > 1e-7f * fv_length(e1) * fv_length(e2);
}

fv_status fv_scene_add_mesh(fv_scene *s, const fv_mesh_desc *m, const fv_log *log, int *object_id, fv_error *err)
{
    int dropped = 0;
    fv_status st = fv_scene_add_mesh_counted(s, m, &dropped, object_id, err);
    if (st == FV_OK && dropped)
        fv_log_warn(log, "mesh '%s': dropped %d of %d triangles (degenerate, non-finite, beyond +-%g or bad index)", m->name ? m->name : "mesh",
                    dropped, m->triangle_count, FV_COORD_MAX);
    return st;
}

fv_status fv_scene_add_mesh_counted(fv_scene *s, const fv_mesh_desc *m, int *dropped_out, int *object_id, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    const char *name = m->name ? m->name : "mesh";
    if (m->vertex_count < 0 || m->triangle_count < 0 || (m->triangle_count > 0 && (!m->positions || !m->indices)))
        return fv_error_set(err, FV_ERR_INVALID, "mesh '%s': bad vertex/triangle arrays", name);
    if (!m->materials && (m->material < 0 || m->material >= s->nmat))
        return fv_error_set(err, FV_ERR_INVALID, "mesh '%s': material id %d does not exist", name, m->material);

    fv_object o;
    memset(&o, 0, sizeof o);
    snprintf(o.name, sizeof o.name, "%s", name);
    o.xf = o.inv = fv_xform_identity();
    o.idx = fv_alloc_array((size_t)m->triangle_count, 3 * sizeof(uint32_t));
    o.mat = fv_alloc_array((size_t)m->triangle_count, sizeof(int));
    int *remap = fv_alloc_array((size_t)m->vertex_count, sizeof(int));
    if (!o.idx || !o.mat || !remap) goto nomem;
    for (int i = 0; i < m->vertex_count; i++) remap[i] = -1;

    int dropped = 0;
    for (int t = 0; t < m->triangle_count; t++) {
        const uint32_t *ix = &m->indices[3 * t];
        if (ix[0] >= (uint32_t)m->vertex_count || ix[1] >= (uint32_t)m->vertex_count || ix[2] >= (uint32_t)m->vertex_count ||
            !triangle_ok(m->positions[ix[0]], m->positions[ix[1]], m->positions[ix[2]])) {
            dropped++;
            continue;
        }
        int mat = m->materials ? m->materials[t] : m->material;
        if (mat < 0 || mat >= s->nmat) {
            free(remap);
            free(o.idx);
            free(o.mat);
            return fv_error_set(err, FV_ERR_INVALID, "mesh '%s': triangle %d uses material id %d, which does not exist", name, t, mat);
        }
        for (int k = 0; k < 3; k++) {
            if (remap[ix[k]] < 0) remap[ix[k]] = o.nv++;
            o.idx[3 * o.nt + k] = (uint32_t)remap[ix[k]];
        }
        o.mat[o.nt++] = mat;
    }
    if (o.nt == 0) {
        free(remap);
        free(o.idx);
        free(o.mat);
        return fv_error_set(err, FV_ERR_INVALID, "mesh '%s': no valid triangles (%d dropped as degenerate, non-finite or beyond +-%g)", name, dropped, FV_COORD_MAX);
    }
    *dropped_out = dropped;

    /* +1 element: Embree reads vertex buffers with 16-byte loads. */
    o.pos = fv_alloc_array((size_t)o.nv + 1, sizeof(fv_vec3));
    if (!o.pos) goto nomem;
    if (m->normals && !(o.nrm = fv_alloc_array((size_t)o.nv + 1, sizeof(fv_vec3)))) goto nomem;
    if (m->uvs && !(o.uv = fv_alloc_array((size_t)o.nv, sizeof(fv_vec2)))) goto nomem;
    o.lo = fv_v3s(FLT_MAX);
    o.hi = fv_v3s(-FLT_MAX);
    for (int i = 0; i < m->vertex_count; i++) {
        if (remap[i] < 0) continue;
        o.pos[remap[i]] = m->positions[i];
        o.lo = fv_vmin(o.lo, m->positions[i]);
        o.hi = fv_vmax(o.hi, m->positions[i]);
        if (o.nrm) {
            fv_vec3 n = m->normals[i];
            o.nrm[remap[i]] = fv_is_finite3(n) && fv_length(n) > 0.0f ? fv_normalize(n) : fv_v3(0, 0, 0);
        }
        if (o.uv) o.uv[remap[i]] = m->uvs[i]; /* non-finite ones are read as (0,0) (texture.c) */
    }
    o.pos[o.nv] = fv_v3(0, 0, 0);
    if (o.nrm) o.nrm[o.nv] = fv_v3(0, 0, 0);
    free(remap);
    remap = NULL;
    if (fv_grow((void **)&s->objs, &s->capobj, s->nobj + 1, sizeof *s->objs)) goto nomem;
    s->objs[s->nobj] = o;
    if (object_id) *object_id = s->nobj;
    s->nobj++;
    return FV_OK;
nomem:
    free(remap);
    free(o.idx);
    free(o.mat);
    free(o.pos);
    free(o.nrm);
    free(o.uv);
    return fv_error_set(err, FV_ERR_NOMEM, "out of memory adding mesh '%s' (%d triangles)", name, m->triangle_count);
}

static bool object_emissive(const fv_scene *s, const fv_object *o)
{
    for (int t = 0; t < o->nt; t++)
        if (fv_max3(s->mats[o->mat[t]].emission) > 0.0f) return true;
    return false;
}

fv_status fv_scene_animate_object(fv_scene *s, int id, const fv_anim_key *keys, int count, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    if (id < 0 || id >= s->nobj) return fv_error_set(err, FV_ERR_INVALID, "animation: object %d does not exist", id);
    fv_object *o = &s->objs[id];
    char who[FV_NAME_MAX + 2];
    snprintf(who, sizeof who, "'%s'", o->name);
    if ((st = fv_anim_check(who, keys, count, err)) != FV_OK) return st;
    if (object_emissive(s, o))
        return fv_error_set(err, FV_ERR_INVALID, "animation of '%s': emissive objects cannot be dynamic", o->name);
    if ((st = fv_anim_set(&o->anim, who, keys, count, err)) != FV_OK) return st;
    o->dynamic = true;
    return FV_OK;
}

fv_status fv_scene_animate_light(fv_scene *s, int index, const fv_anim_key *keys, int count, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    if (index < 0 || index >= s->ndelta)
        return fv_error_set(err, FV_ERR_INVALID, "animation: light %d does not exist (the scene has %d point, spot and directional lights)", index, s->ndelta);
    char who[32];
    snprintf(who, sizeof who, "light %d", index);
    return fv_anim_set(&s->delta[index].anim, who, keys, count, err);
}

fv_status fv_scene_add_light(fv_scene *s, const fv_light_desc *l, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    if (l->type != FV_LIGHT_POINT && l->type != FV_LIGHT_SPOT && l->type != FV_LIGHT_DIRECTIONAL)
        return fv_error_set(err, FV_ERR_INVALID, "light: unknown type %d", (int)l->type);
    if ((st = fv_limit_vec3("light: position", l->pos, err)) != FV_OK || (st = fv_limit_intensity3("light: intensity", l->intensity, err)) != FV_OK)
        return st;
    fv_light_desc c = *l;
    if (l->type == FV_LIGHT_SPOT) {
        if ((st = fv_limit_vec3("spot light: direction", l->dir, err)) != FV_OK) return st;
        if (!(fv_length(l->dir) > 0.0f)) return fv_error_set(err, FV_ERR_INVALID, "spot light: direction must be non-zero");
        if (!(l->outer_deg > 0.0f && l->outer_deg < 90.0f && l->inner_deg >= 0.0f && l->inner_deg <= l->outer_deg))
            return fv_error_set(err, FV_ERR_INVALID, "spot light: need 0 <= inner (%g) <= outer (%g) < 90 degrees", l->inner_deg, l->outer_deg);
        c.dir = fv_normalize(l->dir);
    } else if (l->type == FV_LIGHT_DIRECTIONAL) {
        if ((st = fv_limit_vec3("directional light: direction", l->dir, err)) != FV_OK) return st;
        if (!(fv_length(l->dir) > 0.0f)) return fv_error_set(err, FV_ERR_INVALID, "directional light: direction must be non-zero");
        c.dir = fv_normalize(l->dir);
    }
    if (fv_grow((void **)&s->delta, &s->capdelta, s->ndelta + 1, sizeof *s->delta))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    s->delta[s->ndelta].desc = c;
    s->delta[s->ndelta].anim = (fv_anim){NULL, 0};
    s->ndelta++;
    return FV_OK;
}

/* ---- animation ---- */

static fv_xform anim_eval(const fv_object *o, double t)
{
    fv_anim_key k = fv_anim_at(&o->anim, t);
    return fv_anim_key_xform(&k);
}

/* Delta light entry l at time t: the key's transform moves the light's position, its rotation
 * turns a spot's axis or a directional light's direction (a scale would otherwise tilt it). */
static void light_move(const fv_delta *d, fv_light *l, double t)
{
    fv_anim_key k = fv_anim_at(&d->anim, t);
    fv_xform x = fv_anim_key_xform(&k);
    l->desc.pos = fv_xform_point(&x, d->desc.pos);
    if (d->desc.type == FV_LIGHT_SPOT || d->desc.type == FV_LIGHT_DIRECTIONAL) {
        fv_xform r = fv_xform_trs(fv_v3s(0.0f), k.rotate, fv_v3s(1.0f));
        l->desc.dir = fv_normalize(fv_xform_vector(&r, d->desc.dir));
    }
}

static void bounds_add_box(fv_vec3 *lo, fv_vec3 *hi, const fv_xform *x, fv_vec3 a, fv_vec3 b)
{
    for (int c = 0; c < 8; c++) {
        fv_vec3 p = fv_v3(c & 1 ? b.x : a.x, c & 2 ? b.y : a.y, c & 4 ? b.z : a.z);
        p = fv_xform_point(x, p);
        *lo = fv_vmin(*lo, p);
        *hi = fv_vmax(*hi, p);
    }
}

fv_env_desc fv_env_uniform(fv_vec3 radiance)
{
    fv_env_desc e = {radiance, radiance, radiance, fv_v3(0, 1, 0)};
    return e;
}

fv_status fv_scene_set_env(fv_scene *s, const fv_env_desc *e, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    const fv_vec3 c[3] = {e->zenith, e->horizon, e->ground};
    for (int i = 0; i < 3; i++)
        if (!fv_is_finite3(c[i]) || fv_min3(c[i]) < 0.0f || fv_max3(c[i]) > (float)FV_RADIANCE_MAX)
            return fv_error_set(err, FV_ERR_INVALID, "environment: radiance (%g, %g, %g) must be within [0, %g]", c[i].x, c[i].y, c[i].z,
                                FV_RADIANCE_MAX);
    if (!fv_is_finite3(e->up) || !(fv_length(e->up) > 0.0f) || !isfinite(fv_length(e->up)))
        return fv_error_set(err, FV_ERR_INVALID, "environment: up must be finite and non-zero");
    s->env = *e;
    s->env.up = fv_normalize(e->up);
    s->has_env = fv_max3(fv_vmax(fv_vmax(e->zenith, e->horizon), e->ground)) > 0.0f;
    return FV_OK;
}

bool fv_scene_env(const fv_scene *s, fv_env_desc *out)
{
    if (s->has_env) *out = s->env;
    return s->has_env;
}

/* One object's world box: as it stands when static, over all its keys when dynamic. */
static void object_world_bounds(const fv_object *o, fv_vec3 *lo, fv_vec3 *hi)
{
    *lo = fv_v3s(FLT_MAX);
    *hi = fv_v3s(-FLT_MAX);
    if (!o->dynamic) {
        bounds_add_box(lo, hi, &o->xf, o->lo, o->hi);
        return;
    }
    for (int k = 0; k < o->anim.nkeys; k++) {
        fv_xform x = anim_eval(o, o->anim.keys[k].time);
        bounds_add_box(lo, hi, &x, o->lo, o->hi);
    }
}

void fv_scene_world_bounds(const fv_scene *s, fv_vec3 *lo, fv_vec3 *hi)
{
    /* Static objects as they are, dynamic ones at every key. */
    *lo = fv_v3s(FLT_MAX);
    *hi = fv_v3s(-FLT_MAX);
    for (int i = 0; i < s->nobj; i++) {
        fv_vec3 a, b;
        object_world_bounds(&s->objs[i], &a, &b);
        *lo = fv_vmin(*lo, a);
        *hi = fv_vmax(*hi, b);
    }
}

/* ---- commit ---- */

static fv_status embree_status(fv_scene *s, const char *what, fv_error *err)
{
    enum RTCError e = rtcGetDeviceError(s->dev);
    if (e == RTC_ERROR_NONE) return FV_OK;
    if (e == RTC_ERROR_OUT_OF_MEMORY) return fv_error_set(err, FV_ERR_NOMEM, "out of memory while %s (%s)", what, s->embree_msg);
    return fv_error_set(err, FV_ERR_INTERNAL, "%s failed: %s", what, s->embree_msg[0] ? s->embree_msg : "Embree error");
}

static RTCGeometry make_triangles(fv_scene *s, fv_object *o)
{
    RTCGeometry g = rtcNewGeometry(s->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, o->pos, 0, sizeof(fv_vec3), (size_t)o->nv);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, o->idx, 0, 3 * sizeof(uint32_t), (size_t)o->nt);
    rtcCommitGeometry(g);
    return g;
}

static void attach_instance(fv_scene *s, RTCScene parent, RTCScene child, unsigned id, const fv_xform *x)
{
    RTCGeometry g = rtcNewGeometry(s->dev, RTC_GEOMETRY_TYPE_INSTANCE);
    rtcSetGeometryInstancedScene(g, child);
    rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &x->m[0][0]);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(parent, g, id);
    rtcReleaseGeometry(g);
}

static float tri_area(const fv_object *o, int t)
{
    fv_vec3 a = o->pos[o->idx[3 * t]], b = o->pos[o->idx[3 * t + 1]], c = o->pos[o->idx[3 * t + 2]];
    return 0.5f * fv_length(fv_cross(fv_sub(b, a), fv_sub(c, a)));
}

static fv_status build_lights(fv_scene *s, fv_error *err)
{
    int n = s->ndelta + (s->has_env ? 1 : 0);
    for (int i = 0; i < s->nobj; i++)
        for (int t = 0; t < s->objs[i].nt; t++)
            if (fv_max3(s->mats[s->objs[i].mat[t]].emission) > 0.0f) n++;
    s->lights = fv_calloc_array((size_t)n, sizeof *s->lights);
    s->light_cdf = fv_calloc_array((size_t)n + 1, sizeof(float));
    s->tri_light = fv_calloc_array((size_t)s->nobj, sizeof(int *));
    if (!s->lights || !s->light_cdf || !s->tri_light) return fv_error_set(err, FV_ERR_NOMEM, "out of memory building lights");
    int k = 0;
    s->lights_move = false;
    /* The bounding sphere: where the environment's and directional lights' photons start. */
    s->klights.env_c = fv_scale(fv_add(s->lo, s->hi), 0.5f);
    s->klights.env_r = 0.5f * fv_length(fv_sub(s->hi, s->lo));
    for (int i = 0; i < s->ndelta; i++) {
        fv_light *l = &s->lights[k];
        l->kind = FV_KLIGHT_DELTA;
        l->desc = s->delta[i].desc;
        l->delta = i;
        float lum = fv_luminance(l->desc.intensity);
        if (l->desc.type == FV_LIGHT_POINT) {
            l->power = 4.0f * FV_PI * lum;
        } else if (l->desc.type == FV_LIGHT_DIRECTIONAL) {
            /* its photons leave a disc of the bounding sphere's radius, like the environment's */
            l->power = FV_PI * s->klights.env_r * s->klights.env_r * lum;
        } else {
            float ci = cosf(fv_radians(l->desc.inner_deg)), co = cosf(fv_radians(l->desc.outer_deg));
            l->power = 2.0f * FV_PI * (1.0f - 0.5f * (ci + co)) * lum;
        }
        /* An emitted power beyond the float range would turn the whole pick table into NaN and
         * silently switch every light off. */
        if (!isfinite(l->power)) return fv_error_set(err, FV_ERR_INVALID, "light %d: intensity %g emits more power than a float holds", i, lum);
        if (l->power > 0.0f) {
            k++;
            s->lights_move |= s->delta[i].anim.nkeys > 0;
        }
    }
    s->klights.ndelta = k;
    for (int i = 0; i < s->nobj; i++) {
        fv_object *o = &s->objs[i];
        if (!object_emissive(s, o)) continue;
        if (!(s->tri_light[i] = fv_alloc_array((size_t)o->nt, sizeof(int)))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int t = 0; t < o->nt; t++) {
            const fv_material *m = &s->mats[o->mat[t]];
            s->tri_light[i][t] = -1;
            float area = tri_area(o, t);
            if (!(fv_max3(m->emission) > 0.0f) || !(area > 0.0f)) continue;
            fv_light *l = &s->lights[k];
            l->kind = FV_KLIGHT_TRIANGLE;
            l->obj = i;
            l->prim = t;
            fv_scene_triangle(s, i, t, &l->a, &l->b, &l->c);
            l->area = area;
            fv_vec3 a = o->pos[o->idx[3 * t]], b = o->pos[o->idx[3 * t + 1]], c = o->pos[o->idx[3 * t + 2]];
            l->n = fv_normalize(fv_cross(fv_sub(b, a), fv_sub(c, a)));
            l->emission = m->emission;
            l->two_sided = m->two_sided_emission;
            /* A textured emitter is picked by its mean emission over the triangle; the radiance
             * itself is read at each sampled point (kernel/klight.h), so the pick weight only has
             * to be positive where it emits: a floor keeps dark-but-not-black triangles. */
            fv_vec3 mean = fv_v3s(1.0f);
            l->emission_texture = o->uv && m->emission_texture >= 1 && m->emission_texture <= s->ntex ? m->emission_texture : 0;
            if (l->emission_texture) {
                const uint32_t *ix = &o->idx[3 * t];
                l->ta = o->uv[ix[0]], l->tb = o->uv[ix[1]], l->tc = o->uv[ix[2]];
                mean = fv_texture_triangle_mean(s, l->emission_texture, i, t);
            }
            l->emission_mean = fv_mul(m->emission, mean);
            fv_vec3 floored = fv_v3(fv_maxf(mean.x, 1e-3f), fv_maxf(mean.y, 1e-3f), fv_maxf(mean.z, 1e-3f));
            l->power = FV_PI * fv_luminance(fv_mul(m->emission, floored)) * area * (l->two_sided ? 2.0f : 1.0f);
            if (!isfinite(l->power))
                return fv_error_set(err, FV_ERR_INVALID, "object '%s', triangle %d: material '%s' emits more power than a float holds (emission too large)",
                                    o->name, t, m->name);
            if (l->power > 0.0f) s->tri_light[i][t] = k++;
        }
    }
    s->klights.env_light = -1;
    if (s->has_env) {
        /* Its photons leave a disc of the bounding sphere's radius (light.c), so its power is
         * pi R^2 times the integral of the radiance over the sphere of directions: 2 pi times the
         * two hemispheres' mean radiances, (horizon + zenith) / 2 and (horizon + ground) / 2. */
        float up = 0.5f * fv_luminance(fv_add(s->env.horizon, s->env.zenith));
        float down = 0.5f * fv_luminance(fv_add(s->env.horizon, s->env.ground));
        s->klights.env_p_up = up + down > 0.0f ? up / (up + down) : 0.5f;
        fv_light *l = &s->lights[k];
        l->kind = FV_KLIGHT_ENV;
        l->power = FV_PI * s->klights.env_r * s->klights.env_r * 2.0f * FV_PI * (up + down);
        if (!isfinite(l->power)) return fv_error_set(err, FV_ERR_INVALID, "environment: radiance too large (its power overflows a float)");
        if (l->power > 0.0f) s->klights.env_light = k++;
    }
    s->klights.n = k;
    double total = 0.0;
    for (int i = 0; i < k; i++) total += s->lights[i].power;
    double acc = 0.0;
    for (int i = 0; i < k; i++) {
        s->light_cdf[i] = (float)(acc / total);
        acc += s->lights[i].power;
    }
    s->light_cdf[k] = 1.0f;
    s->klights.light = s->lights;
    s->klights.cdf = s->light_cdf;
    s->klights.env = s->env;
    if (s->ntex > 0 && !s->ktex) {
        if (!(s->ktex = fv_calloc_array((size_t)s->ntex, sizeof *s->ktex))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int i = 0; i < s->ntex; i++) s->ktex[i] = (fv_ktexture){s->tex[i].w, s->tex[i].h, s->tex[i].rgb};
    }
    s->klights.tex = s->ktex;
    s->klights.ntex = s->ntex;
    return FV_OK;
}

fv_status fv_scene_commit(fv_scene *s, const fv_log *log, fv_error *err)
{
    fv_status st = check_open(s, err);
    if (st != FV_OK) return st;
    if (s->nobj == 0) return fv_error_set(err, FV_ERR_INVALID, "scene is empty: it has no objects (no triangles, no SDF)");
    for (int i = 0; i < s->nobj; i++)
        if (s->objs[i].dynamic) s->ndynamic++;

    fv_scene_world_bounds(s, &s->lo, &s->hi);
    for (int i = 0; i < s->nobj; i++) {
        fv_vec3 lo, hi;
        object_world_bounds(&s->objs[i], &lo, &hi);
        /* Every ray starts at a camera, a light or a point on an object: each object must stay
         * within the ray kernels' range wherever its animation takes it (fovea/limits.h). */
        char what[FV_NAME_MAX + 48];
        snprintf(what, sizeof what, "object '%s'%s: bounds", s->objs[i].name, s->objs[i].dynamic ? " (as animated)" : "");
        if ((st = fv_limit_vec3(what, lo, err)) != FV_OK || (st = fv_limit_vec3(what, hi, err)) != FV_OK) return st;
    }
    for (int i = 0; i < s->ndelta; i++)
        for (int k = 0; k < s->delta[i].anim.nkeys; k++) {
            fv_xform x = fv_anim_key_xform(&s->delta[i].anim.keys[k]);
            char what[64];
            snprintf(what, sizeof what, "light %d (as animated): position", i);
            if ((st = fv_limit_vec3(what, fv_xform_point(&x, s->delta[i].desc.pos), err)) != FV_OK) return st;
        }
    fv_vec3 ext = fv_sub(s->hi, s->lo);
    float diag = fv_length(ext);
    if (!(diag > 0.0f))
        return fv_error_set(err, FV_ERR_INVALID, "scene has zero extent: all its geometry is at the single point (%g, %g, %g)", s->lo.x,
                            s->lo.y, s->lo.z);
    s->eps = 1e-4f * diag;

    if ((st = build_lights(s, err)) != FV_OK) return st;
    if (s->klights.n == 0) {
        fv_vec3 c = fv_scale(fv_add(s->lo, s->hi), 0.5f);
        /* Within the intensity limit, so a huge scene gets a dim light rather than a refusal that
         * names a light the user never wrote. */
        fv_light_desc l = {FV_LIGHT_POINT, fv_v3(c.x, s->lo.y + 0.9f * ext.y, c.z), fv_v3(0, -1, 0),
                           fv_v3s(fminf(0.25f * diag * diag, (float)FV_INTENSITY_MAX)), 0, 0};
        fv_log_warn(log, "scene has no lights: added a point light at (%g, %g, %g) with intensity %g", l.pos.x, l.pos.y, l.pos.z,
                    l.intensity.x);
        if ((st = fv_scene_add_light(s, &l, err)) != FV_OK) return st;
        free(s->lights);
        free(s->light_cdf);
        for (int i = 0; i < s->nobj; i++) free(s->tri_light[i]);
        free(s->tri_light);
        s->lights = NULL;
        s->light_cdf = NULL;
        s->tri_light = NULL;
        if ((st = build_lights(s, err)) != FV_OK) return st;
    }

    s->rtc_static = rtcNewScene(s->dev);
    rtcSetSceneBuildQuality(s->rtc_static, RTC_BUILD_QUALITY_HIGH);
    for (int i = 0; i < s->nobj; i++) {
        fv_object *o = &s->objs[i];
        RTCGeometry g = o->sdf ? fv_scene_sdf_geometry(s, o) : make_triangles(s, o);
        if (o->dynamic) {
            o->rtc_child = rtcNewScene(s->dev);
            rtcAttachGeometryByID(o->rtc_child, g, 0);
            rtcCommitScene(o->rtc_child);
        } else {
            rtcAttachGeometryByID(s->rtc_static, g, (unsigned)i);
        }
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(s->rtc_static);
    if ((st = embree_status(s, "building the static BVH", err)) != FV_OK) return st;

    s->static_inst_id = RTC_INVALID_GEOMETRY_ID;
    if (s->ndynamic == 0) {
        s->rtc_all = s->rtc_static;
        rtcRetainScene(s->rtc_all);
    } else {
        s->rtc_all = rtcNewScene(s->dev);
        s->rtc_dynamic = rtcNewScene(s->dev);
        rtcSetSceneFlags(s->rtc_all, RTC_SCENE_FLAG_DYNAMIC);
        rtcSetSceneFlags(s->rtc_dynamic, RTC_SCENE_FLAG_DYNAMIC);
        rtcSetSceneBuildQuality(s->rtc_all, RTC_BUILD_QUALITY_LOW);
        rtcSetSceneBuildQuality(s->rtc_dynamic, RTC_BUILD_QUALITY_LOW);
        s->static_inst_id = (unsigned)s->nobj;
        fv_xform id = fv_xform_identity();
        attach_instance(s, s->rtc_all, s->rtc_static, s->static_inst_id, &id);
        for (int i = 0; i < s->nobj; i++) {
            if (!s->objs[i].dynamic) continue;
            attach_instance(s, s->rtc_all, s->objs[i].rtc_child, (unsigned)i, &id);
            attach_instance(s, s->rtc_dynamic, s->objs[i].rtc_child, (unsigned)i, &id);
        }
    }
    s->committed = true;
    s->time = -1.0;
    return fv_scene_set_time(s, 0.0, err);
}

fv_status fv_scene_set_time(fv_scene *s, double t, fv_error *err)
{
    if (!s->committed) return fv_error_set(err, FV_ERR_INTERNAL, "scene not committed");
    if (!isfinite(t)) return fv_error_set(err, FV_ERR_INVALID, "scene time must be finite");
    if (t == s->time) return FV_OK;
    s->time = t;
    /* Lights first: a scene whose only motion is its lights has no dynamic object to update. */
    for (int i = 0; i < s->klights.ndelta && s->lights_move; i++) {
        fv_light *l = &s->lights[i];
        if (s->delta[l->delta].anim.nkeys > 0) light_move(&s->delta[l->delta], l, t);
    }
    if (s->ndynamic == 0) return FV_OK;
    for (int i = 0; i < s->nobj; i++) {
        fv_object *o = &s->objs[i];
        if (!o->dynamic) continue;
        o->xf = anim_eval(o, t);
        if (!fv_xform_inverse(&o->xf, &o->inv)) o->inv = fv_xform_identity();
        RTCScene parents[2] = {s->rtc_all, s->rtc_dynamic};
        for (int p = 0; p < 2; p++) {
            RTCGeometry g = rtcGetGeometry(parents[p], (unsigned)i);
            rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &o->xf.m[0][0]);
            rtcCommitGeometry(g);
        }
    }
    rtcCommitScene(s->rtc_all);
    rtcCommitScene(s->rtc_dynamic);
    return embree_status(s, "updating dynamic objects", err);
}

double fv_scene_time(const fv_scene *s) { return s->time; }

/* ---- ray queries ---- */

static RTCScene pick(const fv_scene *s, fv_trace_set set)
{
    switch (set) {
    case FV_TRACE_STATIC: return s->rtc_static;
    case FV_TRACE_DYNAMIC: return s->rtc_dynamic;
    default: return s->rtc_all;
    }
}

/* An fv_hit from what Embree reported. */
static void fill_hit(const fv_scene *s, unsigned geom, unsigned prim_id, unsigned inst, float u, float v, fv_vec3 ng, float t, fv_vec3 o,
                     fv_vec3 d, fv_hit *hit)
{
    /* Static triangles are found directly or through the static instance; dynamic ones through
     * their own instance, whose id is the object index. */
    int obj = (inst == RTC_INVALID_GEOMETRY_ID || inst == s->static_inst_id) ? (int)geom : (int)inst;
    const fv_object *ob = &s->objs[obj];
    /* Embree's geometric normal (object space; for triangles as wound, (v1 - v0) x (v2 - v0); for
     * a field its gradient, which the callback put there) saves reading the geometry back. */
    if (ob->dynamic) ng = fv_xform_normal(&ob->inv, ng);
    hit->ng = fv_normalize(ng);
    hit->ns = hit->ng; /* flat shading unless the mesh has vertex normals */
    hit->t = t;
    hit->p = fv_madd(o, d, t);
    hit->obj = obj;
    hit->u = u;
    hit->v = v;
    if (ob->sdf) {
        /* The material is the leaf's nearest the hit, found again here because Embree's hit has
         * no field for it. */
        hit->prim = 0;
        hit->u = hit->v = 0.0f;
        hit->mat = fv_scene_sdf_material(ob, ob->dynamic ? fv_xform_point(&ob->inv, hit->p) : hit->p);
        return;
    }
    int prim = (int)prim_id;
    hit->prim = prim;
    hit->mat = ob->mat[prim];
    if (ob->nrm) {
        const uint32_t *ix = &ob->idx[3 * prim];
        fv_vec3 n = fv_add(fv_add(fv_scale(ob->nrm[ix[0]], 1.0f - u - v), fv_scale(ob->nrm[ix[1]], u)), fv_scale(ob->nrm[ix[2]], v));
        if (ob->dynamic) n = fv_xform_normal(&ob->inv, n);
        float len = fv_length(n);
        if (len > 1e-6f) hit->ns = fv_scale(n, 1.0f / len);
        if (fv_dot(hit->ns, hit->ng) < 0.0f) hit->ns = fv_neg(hit->ns);
    }
}

bool fv_scene_intersect(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, float tmax, fv_hit *hit)
{
    RTCScene scn = pick(s, set);
    if (!scn) return false;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;
    rh.ray.org_x = o.x;
    rh.ray.org_y = o.y;
    rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x;
    rh.ray.dir_y = d.y;
    rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tmax;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scn, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;

    fill_hit(s, rh.hit.geomID, rh.hit.primID, rh.hit.instID[0], rh.hit.u, rh.hit.v, fv_v3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z),
             rh.ray.tfar, o, d, hit);
    return true;
}

int fv_scene_intersect8(const fv_scene *s, fv_vec3 o, const fv_vec3 *d, int n, fv_hit *hits, bool *ok)
{
    bool active[8];
    for (int i = 0; i < 8; i++) active[i] = i < n;
    return fv_scene_intersect8_active(s, o, d, active, hits, ok);
}

int fv_scene_intersect8_active(const fv_scene *s, fv_vec3 o, const fv_vec3 *d, const bool *active, fv_hit *hits, bool *ok)
{
    /* A packet of camera rays sharing one origin: coherent, so Embree traverses them together.
     * Inactive lanes stay in the packet and idle, as on SIMD hardware. */
    struct RTCRayHit8 rh __attribute__((aligned(32)));
    int valid[8] __attribute__((aligned(32)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    int first = 0;
    while (first < 8 && !active[first]) first++;
    if (first == 8) {
        for (int i = 0; i < 8; i++) ok[i] = false;
        return 0;
    }
    for (int i = 0; i < 8; i++) {
        valid[i] = active[i] ? -1 : 0;
        fv_vec3 di = d[active[i] ? i : first];
        rh.ray.org_x[i] = o.x;
        rh.ray.org_y[i] = o.y;
        rh.ray.org_z[i] = o.z;
        rh.ray.dir_x[i] = di.x;
        rh.ray.dir_y[i] = di.y;
        rh.ray.dir_z[i] = di.z;
        rh.ray.tnear[i] = 0.0f;
        rh.ray.tfar[i] = INFINITY;
        rh.ray.time[i] = 0.0f;
        rh.ray.mask[i] = 0xffffffffu;
        rh.ray.id[i] = (unsigned)i;
        rh.ray.flags[i] = 0;
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, s->rtc_all, &ctx, &rh);
    int count = 0;
    for (int i = 0; i < 8; i++) {
        ok[i] = active[i] && rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
        if (!ok[i]) continue;
        fill_hit(s, rh.hit.geomID[i], rh.hit.primID[i], rh.hit.instID[0][i], rh.hit.u[i], rh.hit.v[i],
                 fv_v3(rh.hit.Ng_x[i], rh.hit.Ng_y[i], rh.hit.Ng_z[i]), rh.ray.tfar[i], o, d[i], &hits[i]);
        count++;
    }
    return count;
}

bool fv_scene_occluded(const fv_scene *s, fv_trace_set set, fv_vec3 o, fv_vec3 d, float tmax)
{
    RTCScene scn = pick(s, set);
    if (!scn) return false;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    r.org_x = o.x;
    r.org_y = o.y;
    r.org_z = o.z;
    r.dir_x = d.x;
    r.dir_y = d.y;
    r.dir_z = d.z;
    r.tnear = 0.0f;
    r.tfar = tmax;
    r.time = 0.0f;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    rtcOccluded1(scn, &ctx, &r);
    return r.tfar < 0.0f;
}

bool fv_scene_visible(const fv_scene *s, fv_trace_set set, fv_vec3 p, fv_vec3 ng, fv_vec3 q)
{
    fv_vec3 o = fv_offset_point(s, p, ng, fv_sub(q, p));
    fv_vec3 d = fv_sub(q, o);
    float len = fv_length(d);
    if (!(len > 2.0f * s->eps)) return true;
    return !fv_scene_occluded(s, set, o, fv_scale(d, 1.0f / len), len - s->eps);
}

int fv_scene_visible8(const fv_scene *s, fv_vec3 p, fv_vec3 ng, const fv_vec3 *q, const bool *active, bool *visible)
{
    /* Eight shadow rays leaving one surface point (a pixel towards eight VPLs): they share the
     * origin up to the side of the surface they leave from, so one packet traverses the BVH
     * together. Lanes too short to need a ray are visible without one. */
    struct RTCRay8 r __attribute__((aligned(32)));
    int valid[8] __attribute__((aligned(32)));
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    int traced = 0;
    for (int i = 0; i < 8; i++) {
        valid[i] = 0;
        r.org_x[i] = p.x;
        r.org_y[i] = p.y;
        r.org_z[i] = p.z;
        r.dir_x[i] = 0.0f;
        r.dir_y[i] = 0.0f;
        r.dir_z[i] = 1.0f;
        r.tnear[i] = 0.0f;
        r.tfar[i] = 0.0f;
        r.time[i] = 0.0f;
        r.mask[i] = 0xffffffffu;
        r.id[i] = (unsigned)i;
        r.flags[i] = 0;
        visible[i] = active[i];
        if (!active[i]) continue;
        fv_vec3 o = fv_offset_point(s, p, ng, fv_sub(q[i], p));
        fv_vec3 d = fv_sub(q[i], o);
        float len = fv_length(d);
        if (!(len > 2.0f * s->eps)) continue;
        d = fv_scale(d, 1.0f / len);
        r.org_x[i] = o.x;
        r.org_y[i] = o.y;
        r.org_z[i] = o.z;
        r.dir_x[i] = d.x;
        r.dir_y[i] = d.y;
        r.dir_z[i] = d.z;
        r.tfar[i] = len - s->eps;
        valid[i] = -1;
        traced++;
    }
    if (!traced) return 0;
    rtcOccluded8(valid, s->rtc_all, &ctx, &r);
    for (int i = 0; i < 8; i++)
        if (valid[i] && r.tfar[i] < 0.0f) visible[i] = false;
    return traced;
}

void fv_scene_triangle(const fv_scene *s, int obj, int prim, fv_vec3 *a, fv_vec3 *b, fv_vec3 *c)
{
    const fv_object *o = &s->objs[obj];
    const uint32_t *ix = &o->idx[3 * prim];
    *a = fv_xform_point(&o->xf, o->pos[ix[0]]);
    *b = fv_xform_point(&o->xf, o->pos[ix[1]]);
    *c = fv_xform_point(&o->xf, o->pos[ix[2]]);
}

int fv_scene_object_triangle_count(const fv_scene *s, int obj) { return obj >= 0 && obj < s->nobj ? s->objs[obj].nt : 0; }

int fv_scene_triangle_material(const fv_scene *s, int obj, int prim) { return s->objs[obj].mat[prim]; }

/* ---- queries ---- */

void fv_scene_bounds(const fv_scene *s, fv_vec3 *lo, fv_vec3 *hi)
{
    *lo = s->lo;
    *hi = s->hi;
}

float fv_scene_ray_eps(const fv_scene *s) { return s->eps; }

fv_object_kind fv_scene_object_kind(const fv_scene *s, int obj)
{
    return obj >= 0 && obj < s->nobj && s->objs[obj].sdf ? FV_OBJECT_SDF : FV_OBJECT_MESH;
}

const fv_sdf *fv_scene_object_sdf(const fv_scene *s, int obj) { return obj >= 0 && obj < s->nobj ? s->objs[obj].sdf : NULL; }

int fv_scene_sdf_object_count(const fv_scene *s)
{
    int n = 0;
    for (int i = 0; i < s->nobj; i++) n += s->objs[i].sdf != NULL;
    return n;
}

bool fv_scene_object_dynamic(const fv_scene *s, int obj) { return obj >= 0 && obj < s->nobj && s->objs[obj].dynamic; }

void fv_scene_object_world_to_local(const fv_scene *s, int obj, fv_xform *out) { *out = s->objs[obj].inv; }

void fv_scene_object_bounds(const fv_scene *s, int obj, fv_vec3 *lo, fv_vec3 *hi)
{
    const fv_object *o = &s->objs[obj];
    *lo = fv_v3s(INFINITY);
    *hi = fv_v3s(-INFINITY);
    /* The object-space box's corners moved to the current time. */
    for (int k = 0; k < 8; k++) {
        fv_vec3 p = fv_v3(k & 1 ? o->hi.x : o->lo.x, k & 2 ? o->hi.y : o->lo.y, k & 4 ? o->hi.z : o->lo.z);
        p = fv_xform_point(&o->xf, p);
        *lo = fv_vmin(*lo, p);
        *hi = fv_vmax(*hi, p);
    }
}

int fv_scene_triangle_count(const fv_scene *s)
{
    int n = 0;
    for (int i = 0; i < s->nobj; i++) n += s->objs[i].nt;
    return n;
}
int fv_scene_object_count(const fv_scene *s) { return s->nobj; }
int fv_scene_dynamic_object_count(const fv_scene *s)
{
    int n = 0;
    for (int i = 0; i < s->nobj; i++) n += s->objs[i].dynamic;
    return n;
}
int fv_scene_light_count(const fv_scene *s) { return s->committed ? s->klights.n : s->ndelta; }
int fv_scene_material_count(const fv_scene *s) { return s->nmat; }
const fv_material *fv_scene_material(const fv_scene *s, int id) { return id >= 0 && id < s->nmat ? &s->mats[id] : NULL; }
