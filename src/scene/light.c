/* fovea — light sampling (see light.h). Spot lights fall off smoothly (smoothstep in cos) between
 * the inner and outer cone; point lights are isotropic. */
#include "scene/light.h"
#include "scene/bsdf.h"
#include "scene/scene_impl.h"

static int pick_light(const fv_scene *s, float u, float *pmf)
{
    int lo = 0, hi = s->nlights - 1;
    while (lo < hi) { /* first i with cdf[i+1] > u */
        int mid = (lo + hi) / 2;
        if (s->light_cdf[mid + 1] <= u) lo = mid + 1;
        else hi = mid;
    }
    *pmf = s->light_cdf[lo + 1] - s->light_cdf[lo];
    return lo;
}

static float spot_falloff(const fv_light_desc *d, fv_vec3 w_out)
{
    float c = fv_dot(w_out, d->dir);
    float ci = cosf(fv_radians(d->inner_deg)), co = cosf(fv_radians(d->outer_deg));
    if (c >= ci) return 1.0f;
    if (c <= co) return 0.0f;
    float t = (c - co) / (ci - co);
    return t * t * (3.0f - 2.0f * t);
}

static fv_vec3 sample_triangle(const fv_scene *s, const fv_light *l, float u0, float u1)
{
    fv_vec3 a, b, c;
    fv_scene_triangle(s, l->obj, l->prim, &a, &b, &c);
    float su = sqrtf(u0);
    float ba = 1.0f - su, bb = u1 * su;
    return fv_add(fv_add(fv_scale(a, ba), fv_scale(b, bb)), fv_scale(c, 1.0f - ba - bb));
}

/* ---- the environment ---- */

static fv_vec3 env_radiance(const fv_env_desc *e, fv_vec3 w)
{
    float t = fv_dot(w, e->up);
    if (t >= 0.0f) return fv_add(e->horizon, fv_scale(fv_sub(e->zenith, e->horizon), fv_minf(t, 1.0f)));
    return fv_add(e->horizon, fv_scale(fv_sub(e->ground, e->horizon), fv_minf(-t, 1.0f)));
}

/* Density of env_sample_dir over the sphere of directions. */
static float env_dir_pdf(const fv_scene *s, fv_vec3 w)
{
    float p = fv_dot(w, s->env.up) >= 0.0f ? s->env_p_up : 1.0f - s->env_p_up;
    return p / (2.0f * FV_PI);
}

/* A hemisphere by u0 (in proportion to its mean luminance), then a uniform direction in it:
 * the height t along up is uniform in [0, 1] (Archimedes), the azimuth 2 pi u1. */
static fv_vec3 env_sample_dir(const fv_scene *s, float u0, float u1, float *pdf)
{
    float p = s->env_p_up, t;
    if (u0 < p) {
        t = u0 / p;
        *pdf = p / (2.0f * FV_PI);
    } else {
        t = -(u0 - p) / (1.0f - p);
        *pdf = (1.0f - p) / (2.0f * FV_PI);
    }
    t = fv_clampf(t, -1.0f, 1.0f);
    float r = sqrtf(fv_maxf(0.0f, 1.0f - t * t)), phi = 2.0f * FV_PI * u1;
    fv_vec3 a, b;
    fv_basis(s->env.up, &a, &b);
    return fv_normalize(fv_from_local(fv_v3(r * cosf(phi), r * sinf(phi), t), a, b, s->env.up));
}

/* The radius of the sphere that stands for the environment where a light must be a place
 * (fv_light_pick_point), and of the disc its photons leave: just outside the bounding sphere. */
static float env_radius(const fv_scene *s) { return 1.001f * s->env_r; }

fv_vec3 fv_light_env_radiance(const fv_scene *s, fv_vec3 w) { return s->env_light >= 0 ? env_radiance(&s->env, w) : fv_v3s(0.0f); }

float fv_light_env_pdf(const fv_scene *s, fv_vec3 w)
{
    if (s->env_light < 0) return 0.0f;
    return (s->light_cdf[s->env_light + 1] - s->light_cdf[s->env_light]) * env_dir_pdf(s, w);
}

fv_vec3 fv_light_emitted(const fv_scene *s, const fv_material *m, fv_vec3 ng, fv_vec3 w)
{
    (void)s;
    float c = fv_dot(ng, w);
    if (c > 0.0f || (m->two_sided_emission && c < 0.0f)) return m->emission;
    return fv_v3s(0.0f);
}

bool fv_light_sample_li(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out)
{
    if (s->nlights == 0) return false;
    float pmf;
    const fv_light *l = &s->lights[pick_light(s, u0, &pmf)];
    if (!(pmf > 0.0f)) return false;
    if (l->kind == 0) {
        fv_vec3 d = fv_sub(l->desc.pos, p);
        float d2 = fv_dot(d, d);
        if (!(d2 > 0.0f)) return false;
        out->dist = sqrtf(d2);
        out->wi = fv_scale(d, 1.0f / out->dist);
        float fall = l->desc.type == FV_LIGHT_SPOT ? spot_falloff(&l->desc, fv_neg(out->wi)) : 1.0f;
        if (fall <= 0.0f) return false;
        out->li = fv_scale(l->desc.intensity, fall / d2);
        out->pdf = pmf;
        out->delta = true;
        return true;
    }
    if (l->kind == 2) {
        float pdf_w;
        out->wi = env_sample_dir(s, u1, u2, &pdf_w);
        out->li = env_radiance(&s->env, out->wi);
        /* a point beyond everything: the shadow ray then tests the whole way out */
        out->dist = 2.0f * (env_radius(s) + fv_length(fv_sub(p, s->env_c)));
        out->pdf = pmf * pdf_w;
        out->delta = false;
        return fv_max3(out->li) > 0.0f;
    }
    fv_vec3 q = sample_triangle(s, l, u1, u2);
    fv_vec3 d = fv_sub(q, p);
    float d2 = fv_dot(d, d);
    if (!(d2 > 0.0f)) return false;
    out->dist = sqrtf(d2);
    out->wi = fv_scale(d, 1.0f / out->dist);
    float cos_l = fv_dot(l->n, out->wi); /* emitter faces p when negative */
    if (!(cos_l < 0.0f || (l->two_sided && cos_l > 0.0f))) return false;
    out->li = l->emission;
    out->pdf = pmf * d2 / (fabsf(cos_l) * l->area);
    out->delta = false;
    return true;
}

bool fv_light_sample_li_area(const fv_scene *s, fv_vec3 p, float u0, float u1, float u2, fv_light_sample *out)
{
    /* the delta lights come first in the table: map u0 onto the rest of the cdf */
    float lo = s->nlights_delta > 0 ? s->light_cdf[s->nlights_delta] : 0.0f;
    if (s->nlights == s->nlights_delta || !(lo < 1.0f)) return false;
    float u = fv_minf(lo + u0 * (1.0f - lo), 0.99999994f);
    if (!fv_light_sample_li(s, p, u, u1, u2, out) || out->delta) return false;
    out->pdf /= 1.0f - lo;
    return true;
}

float fv_light_pdf_li(const fv_scene *s, int obj, int prim, fv_vec3 p, fv_vec3 hit_p, fv_vec3 hit_ng, fv_vec3 w)
{
    if (!s->tri_light || !s->tri_light[obj]) return 0.0f;
    int li = s->tri_light[obj][prim];
    if (li < 0) return 0.0f;
    const fv_light *l = &s->lights[li];
    float pmf = s->light_cdf[li + 1] - s->light_cdf[li];
    fv_vec3 d = fv_sub(hit_p, p);
    float cos_l = fabsf(fv_dot(hit_ng, w));
    if (!(cos_l > 0.0f)) return 0.0f;
    return pmf * fv_dot(d, d) / (cos_l * l->area);
}

bool fv_light_sample_emission(const fv_scene *s, const float u[5], fv_vec3 *origin, fv_vec3 *dir, fv_vec3 *power,
                              fv_vec3 *normal)
{
    if (s->nlights == 0) return false;
    float pmf;
    const fv_light *l = &s->lights[pick_light(s, u[0], &pmf)];
    if (!(pmf > 0.0f)) return false;
    if (l->kind == 0) {
        *origin = l->desc.pos;
        *normal = fv_v3s(0.0f);
        /* Uniform sphere direction: pdf 1/(4 pi), so power = I * 4 pi * falloff / pmf. */
        float z = 1.0f - 2.0f * u[1], r = sqrtf(fv_maxf(0.0f, 1.0f - z * z)), phi = 2.0f * FV_PI * u[2];
        *dir = fv_v3(r * cosf(phi), r * sinf(phi), z);
        float fall = l->desc.type == FV_LIGHT_SPOT ? spot_falloff(&l->desc, *dir) : 1.0f;
        *power = fv_scale(l->desc.intensity, 4.0f * FV_PI * fall / pmf);
        return fall > 0.0f;
    }
    if (l->kind == 2) {
        /* A direction w from the environment, then a point uniform on a disc of the bounding
         * sphere's radius facing it, just outside the sphere: every photon crosses the scene's
         * bounds, and the flux through the disc is L(w) pi R^2 per unit solid angle. */
        float pdf_w, R = env_radius(s);
        fv_vec3 w = env_sample_dir(s, u[1], u[2], &pdf_w), t, b;
        fv_basis(w, &t, &b);
        float r = R * sqrtf(u[3]), phi = 2.0f * FV_PI * u[4];
        *origin = fv_add(fv_madd(s->env_c, w, R), fv_add(fv_scale(t, r * cosf(phi)), fv_scale(b, r * sinf(phi))));
        *dir = fv_neg(w);
        *normal = fv_v3s(0.0f);
        fv_vec3 L = env_radiance(&s->env, w);
        *power = fv_scale(L, FV_PI * R * R / (pdf_w * pmf));
        return fv_max3(L) > 0.0f;
    }
    *origin = sample_triangle(s, l, u[1], u[2]);
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
    *power = fv_scale(l->emission, FV_PI * l->area * (l->two_sided ? 2.0f : 1.0f) / pmf);
    return true;
}

int fv_light_emission_dir_dims(const fv_scene *s, float u0)
{
    if (s->nlights == 0) return 1;
    float pmf;
    return s->lights[pick_light(s, u0, &pmf)].kind == 1 ? 3 : 1;
}

bool fv_light_pick_point(const fv_scene *s, fv_rng *rng, fv_light_point *out)
{
    if (s->nlights == 0) return false;
    out->light = pick_light(s, fv_rng_next(rng), &out->pmf);
    if (!(out->pmf > 0.0f)) return false;
    const fv_light *l = &s->lights[out->light];
    out->delta = l->kind == 0;
    if (out->delta) {
        out->p = l->desc.pos;
        out->n = fv_v3s(0.0f);
    } else if (l->kind == 2) {
        float z = 1.0f - 2.0f * fv_rng_next(rng), r = sqrtf(fv_maxf(0.0f, 1.0f - z * z)), phi = 2.0f * FV_PI * fv_rng_next(rng);
        fv_vec3 d = fv_v3(r * cosf(phi), r * sinf(phi), z);
        out->p = fv_madd(s->env_c, d, env_radius(s));
        out->n = fv_neg(d);
    } else {
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng);
        out->p = sample_triangle(s, l, u0, u1);
        out->n = l->n;
    }
    return true;
}

bool fv_light_point_power(const fv_scene *s, const fv_light_point *lp, fv_vec3 dir, float pdf, fv_vec3 *power)
{
    const fv_light *l = &s->lights[lp->light];
    if (lp->delta) {
        *power = fv_scale(fv_light_delta_intensity(l, dir), 1.0f / pdf);
        return true;
    }
    if (l->kind == 2) { /* the inward-emitting sphere of fv_light_pick_point, area 4 pi R^2 */
        float c = fv_dot(lp->n, dir), R = env_radius(s);
        if (!(c > 0.0f)) return false;
        *power = fv_scale(env_radiance(&s->env, fv_neg(dir)), c * 4.0f * FV_PI * R * R / pdf);
        return true;
    }
    float c = fv_dot(l->n, dir);
    if (!(c > 0.0f || (l->two_sided && c < 0.0f))) return false;
    *power = fv_scale(l->emission, fabsf(c) * l->area / pdf);
    return true;
}

int fv_light_delta_count(const fv_scene *s) { return s->nlights_delta; }

/* Delta lights come first in the table (build_lights in scene.c). */
const fv_light *fv_light_delta_at(const fv_scene *s, int i) { return i >= 0 && i < s->nlights_delta ? &s->lights[i] : NULL; }

fv_vec3 fv_light_delta_pos(const fv_light *l) { return l->desc.pos; }

bool fv_scene_lights_move(const fv_scene *s) { return s->lights_move; }

fv_vec3 fv_light_delta_intensity(const fv_light *l, fv_vec3 w)
{
    float fall = l->desc.type == FV_LIGHT_SPOT ? spot_falloff(&l->desc, w) : 1.0f;
    return fv_scale(l->desc.intensity, fall);
}

fv_vec3 fv_light_total_power(const fv_scene *s)
{
    fv_vec3 p = fv_v3s(0.0f);
    for (int i = 0; i < s->nlights; i++) {
        const fv_light *l = &s->lights[i];
        if (l->kind == 2) {
            fv_vec3 sum = fv_add(fv_add(fv_scale(s->env.horizon, 2.0f), s->env.zenith), s->env.ground); /* 2 x the two means */
            p = fv_add(p, fv_scale(sum, FV_PI * env_radius(s) * env_radius(s) * FV_PI));
        } else if (l->kind == 1) {
            p = fv_add(p, fv_scale(l->emission, FV_PI * l->area * (l->two_sided ? 2.0f : 1.0f)));
        } else if (l->desc.type == FV_LIGHT_POINT) {
            p = fv_add(p, fv_scale(l->desc.intensity, 4.0f * FV_PI));
        } else {
            float ci = cosf(fv_radians(l->desc.inner_deg)), co = cosf(fv_radians(l->desc.outer_deg));
            p = fv_add(p, fv_scale(l->desc.intensity, 2.0f * FV_PI * (1.0f - 0.5f * (ci + co))));
        }
    }
    return p;
}
