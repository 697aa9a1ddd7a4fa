/* fovea — light sampling on fv_scene (see light.h): the kernel's sampling (kernel/klight.h) on the
 * scene's own table, and the emission of photons and VPLs, which only CPU techniques use. */
#include "scene/light.h"
#include "kernel/kbsdf.h"
#include "scene/scene_impl.h"

static int pick_light(const fv_scene *s, float u, float *pmf) { return fv_klights_pick(&s->klights, u, pmf); }

static float env_radius(const fv_scene *s) { return fv_kenv_radius(&s->klights); }

/* A point uniform on the disc of radius R facing unit w (its normal) at distance R from the
 * bounding sphere's centre along w. */
static fv_vec3 disc_point(const fv_scene *s, fv_vec3 w, float R, float u0, float u1)
{
    fv_vec3 t, b;
    fv_basis(w, &t, &b);
    float r = R * sqrtf(u0), phi = 2.0f * FV_PI * u1;
    return fv_add(fv_madd(s->klights.env_c, w, R), fv_add(fv_scale(t, r * cosf(phi)), fv_scale(b, r * sinf(phi))));
}

fv_vec3 fv_light_env_radiance(const fv_scene *s, fv_vec3 w) { return fv_klights_env_radiance(&s->klights, w); }

float fv_light_env_pdf(const fv_scene *s, fv_vec3 w) { return fv_klights_env_pdf(&s->klights, w); }

fv_vec3 fv_light_emitted(const fv_scene *s, const fv_material *m, fv_vec3 ng, fv_vec3 w)
{
    (void)s;
    return fv_klight_emitted(m, ng, w);
}

bool fv_light_sample_li(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out)
{
    return fv_klights_sample_li(&s->klights, p, u0, u1, u2, out);
}

bool fv_light_sample_li_area(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out)
{
    /* the delta lights come first in the table: map u0 onto the rest of the cdf */
    const int n = s->klights.n, nd = s->klights.ndelta;
    float lo = nd > 0 ? s->light_cdf[nd] : 0.0f;
    if (n == nd || !(lo < 1.0f)) return false;
    float u = fv_minf(lo + u0 * (1.0f - lo), 0.99999994f);
    if (!fv_light_sample_li(s, p, u, u1, u2, out) || out->delta) return false;
    out->pdf /= 1.0f - lo;
    return true;
}

const fv_klights *fv_scene_klights(const fv_scene *s) { return &s->klights; }

int fv_light_of_triangle(const fv_scene *s, int obj, int prim)
{
    return s->tri_light && s->tri_light[obj] ? s->tri_light[obj][prim] : -1;
}

float fv_light_pdf_li(const fv_scene *s, int obj, int prim, fv_vec3 p, fv_vec3 hit_p, fv_vec3 hit_ng, fv_vec3 w)
{
    if (!s->tri_light || !s->tri_light[obj]) return 0.0f;
    return fv_klights_pdf_li(&s->klights, s->tri_light[obj][prim], p, hit_p, hit_ng, w);
}

bool fv_light_sample_emission(const fv_scene *s, const float u[5], fv_vec3 *origin, fv_vec3 *dir, fv_vec3 *power,
                              fv_vec3 *normal)
{
    if (s->klights.n == 0) return false;
    float pmf;
    const fv_light *l = &s->lights[pick_light(s, u[0], &pmf)];
    if (!(pmf > 0.0f)) return false;
    if (l->kind == FV_KLIGHT_DELTA && l->desc.type == FV_LIGHT_DIRECTIONAL) {
        /* Parallel light through a disc of the bounding sphere's radius facing it, just outside
         * the sphere (the environment's disc for one direction): flux E pi R^2. */
        float R = env_radius(s);
        fv_vec3 w = l->desc.dir;
        *origin = disc_point(s, fv_neg(w), R, u[3], u[4]);
        *dir = w;
        *normal = fv_v3s(0.0f);
        *power = fv_scale(l->desc.intensity, FV_PI * R * R / pmf);
        return true;
    }
    if (l->kind == FV_KLIGHT_DELTA) {
        *origin = l->desc.pos;
        *normal = fv_v3s(0.0f);
        /* Uniform sphere direction: pdf 1/(4 pi), so power = I * 4 pi * falloff / pmf. */
        float z = 1.0f - 2.0f * u[1], r = sqrtf(fv_maxf(0.0f, 1.0f - z * z)), phi = 2.0f * FV_PI * u[2];
        *dir = fv_v3(r * cosf(phi), r * sinf(phi), z);
        float fall = l->desc.type == FV_LIGHT_SPOT ? fv_klight_spot_falloff(&l->desc, *dir) : 1.0f;
        *power = fv_scale(l->desc.intensity, 4.0f * FV_PI * fall / pmf);
        return fall > 0.0f;
    }
    if (l->kind == FV_KLIGHT_ENV) {
        /* A direction w from the environment, then a point uniform on a disc of the bounding
         * sphere's radius facing it, just outside the sphere: every photon crosses the scene's
         * bounds, and the flux through the disc is L(w) pi R^2 per unit solid angle. */
        float pdf_w, R = env_radius(s);
        fv_vec3 w = fv_kenv_sample_dir(&s->klights, u[1], u[2], &pdf_w), t, b;
        fv_basis(w, &t, &b);
        float r = R * sqrtf(u[3]), phi = 2.0f * FV_PI * u[4];
        *origin = fv_add(fv_madd(s->klights.env_c, w, R), fv_add(fv_scale(t, r * cosf(phi)), fv_scale(b, r * sinf(phi))));
        *dir = fv_neg(w);
        *normal = fv_v3s(0.0f);
        fv_vec3 L = fv_kenv_radiance(&s->env, w);
        *power = fv_scale(L, FV_PI * R * R / (pdf_w * pmf));
        return fv_max3(L) > 0.0f;
    }
    float bw[3];
    fv_klight_triangle_bary(u[1], u[2], bw);
    *origin = fv_klight_triangle_at(l, bw);
    fv_vec3 n = l->n, t, b;
    float side = 1.0f;
    float uu = u[3];
    if (l->two_sided) { /* pick a side, reuse the number */
        side = uu < 0.5f ? 1.0f : -1.0f;
        uu = uu < 0.5f ? 2.0f * uu : 2.0f * uu - 1.0f;
    }
    n = fv_scale(n, side);
    fv_basis(n, &t, &b);
    fv_vec3 w = fv_sample_cosine_hemisphere(uu, u[4]);
    *dir = fv_from_local(w, t, b, n);
    *normal = n;
    /* L cos / (pmf * (1/A) * cos/pi * side prob) = L pi A / (pmf * side prob) */
    *power = fv_scale(fv_klight_triangle_emission(&s->klights, l, bw), FV_PI * l->area * (l->two_sided ? 2.0f : 1.0f) / pmf);
    return true;
}

int fv_light_emission_dir_dims(const fv_scene *s, float u0)
{
    if (s->klights.n == 0) return 1;
    float pmf;
    return s->lights[pick_light(s, u0, &pmf)].kind == FV_KLIGHT_TRIANGLE ? 3 : 1;
}

bool fv_light_pick_point(const fv_scene *s, fv_rng *rng, fv_light_point *out)
{
    if (s->klights.n == 0) return false;
    out->light = pick_light(s, fv_rng_next(rng), &out->pmf);
    if (!(out->pmf > 0.0f)) return false;
    const fv_light *l = &s->lights[out->light];
    out->delta = l->kind == FV_KLIGHT_DELTA;
    out->directional = out->delta && l->desc.type == FV_LIGHT_DIRECTIONAL;
    if (out->directional) {
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng);
        out->p = disc_point(s, fv_neg(l->desc.dir), env_radius(s), u0, u1);
        out->n = l->desc.dir;
    } else if (out->delta) {
        out->p = l->desc.pos;
        out->n = fv_v3s(0.0f);
    } else if (l->kind == FV_KLIGHT_ENV) {
        float z = 1.0f - 2.0f * fv_rng_next(rng), r = sqrtf(fv_maxf(0.0f, 1.0f - z * z)), phi = 2.0f * FV_PI * fv_rng_next(rng);
        fv_vec3 d = fv_v3(r * cosf(phi), r * sinf(phi), z);
        out->p = fv_madd(s->klights.env_c, d, env_radius(s));
        out->n = fv_neg(d);
    } else {
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), bw[3];
        fv_klight_triangle_bary(u0, u1, bw);
        out->p = fv_klight_triangle_at(l, bw);
        out->n = l->n;
        out->le = fv_klight_triangle_emission(&s->klights, l, bw);
    }
    return true;
}

bool fv_light_point_power(const fv_scene *s, const fv_light_point *lp, fv_vec3 dir, float pdf, fv_vec3 *power)
{
    const fv_light *l = &s->lights[lp->light];
    if (lp->directional) { /* the disc of fv_light_pick_point, area pi R^2, along lp->n only */
        float R = env_radius(s);
        if (!(fv_dot(dir, lp->n) > 0.9999f)) return false;
        *power = fv_scale(l->desc.intensity, FV_PI * R * R / pdf);
        return true;
    }
    if (lp->delta) {
        *power = fv_scale(fv_light_delta_intensity(l, dir), 1.0f / pdf);
        return true;
    }
    if (l->kind == FV_KLIGHT_ENV) { /* the inward-emitting sphere of fv_light_pick_point, area 4 pi R^2 */
        float c = fv_dot(lp->n, dir), R = env_radius(s);
        if (!(c > 0.0f)) return false;
        *power = fv_scale(fv_kenv_radiance(&s->env, fv_neg(dir)), c * 4.0f * FV_PI * R * R / pdf);
        return true;
    }
    float c = fv_dot(l->n, dir);
    if (!(c > 0.0f || (l->two_sided && c < 0.0f))) return false;
    *power = fv_scale(lp->le, fabsf(c) * l->area / pdf);
    return true;
}

int fv_light_delta_count(const fv_scene *s) { return s->klights.ndelta; }

/* Delta lights come first in the table (build_lights in scene.c). */
const fv_light *fv_light_delta_at(const fv_scene *s, int i) { return i >= 0 && i < s->klights.ndelta ? &s->lights[i] : NULL; }

fv_vec3 fv_light_delta_pos(const fv_light *l) { return l->desc.pos; }

bool fv_scene_lights_move(const fv_scene *s) { return s->lights_move; }

bool fv_light_delta_directional(const fv_light *l, fv_vec3 *dir)
{
    if (l->desc.type != FV_LIGHT_DIRECTIONAL) return false;
    if (dir) *dir = l->desc.dir;
    return true;
}

fv_vec3 fv_light_delta_intensity(const fv_light *l, fv_vec3 w) { return fv_klight_delta_intensity(l, w); }

fv_vec3 fv_light_total_power(const fv_scene *s)
{
    fv_vec3 p = fv_v3s(0.0f);
    for (int i = 0; i < s->klights.n; i++) {
        const fv_light *l = &s->lights[i];
        if (l->kind == FV_KLIGHT_ENV) {
            fv_vec3 sum = fv_add(fv_add(fv_scale(s->env.horizon, 2.0f), s->env.zenith), s->env.ground); /* 2 x the two means */
            p = fv_add(p, fv_scale(sum, FV_PI * env_radius(s) * env_radius(s) * FV_PI));
        } else if (l->kind == FV_KLIGHT_TRIANGLE) {
            p = fv_add(p, fv_scale(l->emission_mean, FV_PI * l->area * (l->two_sided ? 2.0f : 1.0f)));
        } else if (l->desc.type == FV_LIGHT_POINT) {
            p = fv_add(p, fv_scale(l->desc.intensity, 4.0f * FV_PI));
        } else if (l->desc.type == FV_LIGHT_DIRECTIONAL) {
            p = fv_add(p, fv_scale(l->desc.intensity, FV_PI * env_radius(s) * env_radius(s)));
        } else {
            float ci = cosf(fv_radians(l->desc.inner_deg)), co = cosf(fv_radians(l->desc.outer_deg));
            p = fv_add(p, fv_scale(l->desc.intensity, 2.0f * FV_PI * (1.0f - 0.5f * (ci + co))));
        }
    }
    return p;
}
