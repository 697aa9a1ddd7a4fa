/* fovea — `pt`, the reference unidirectional path tracer: the ground truth every technique is
 * measured against.
 *
 * Next-event estimation at every non-delta vertex, combined with BSDF sampling by multiple
 * importance sampling (balance heuristic, Veach 1997 ch. 9) for area lights; delta lights are
 * sampled only by NEE, delta lobes only by the BSDF. Russian roulette from `rr_depth` on, with
 * survival probability max(throughput) capped at 0.95. `max_depth` is the number of path vertices
 * that gather light: 1 = direct light only (emission seen directly plus one light connection),
 * which is the convention of Embree's `--max-path-length`. No environment
 * light: rays leaving the scene carry nothing.
 */
#include <stdlib.h>
#include <string.h>
#include "core/parallel.h"
#include "core/rng.h"
#include "fovea/technique.h"
#include "scene/bsdf.h"
#include "scene/light.h"
#include "technique/pt/pt.h"

typedef struct pt_state {
    const fv_scene *scene;
    fv_pt_options opt;
} pt_state;

static float mis_weight(float a, float b) { return a / (a + b); }

fv_vec3 fv_pt_trace(const fv_scene *s, const fv_pt_options *opt, fv_vec3 o, fv_vec3 d, fv_rng *rng,
                    fv_pt_first_hit *first, uint64_t *rays)
{
    return fv_pt_trace_from(s, opt, o, d, NULL, false, rng, first, rays);
}

fv_vec3 fv_pt_trace_from(const fv_scene *s, const fv_pt_options *opt, fv_vec3 o, fv_vec3 d, const fv_hit *pre, bool pre_ok, fv_rng *rng,
                         fv_pt_first_hit *first, uint64_t *rays)
{
    fv_vec3 L = fv_v3s(0.0f), beta = fv_v3s(1.0f);
    bool delta_prev = true;
    float pdf_prev = 1.0f;
    fv_vec3 p_prev = o;
    uint64_t nrays = 0;
    for (int depth = 1; depth <= opt->max_depth; depth++) {
        fv_hit h;
        nrays++;
        if (depth == 1 && pre) {
            if (!pre_ok) break;
            h = *pre;
        } else if (!fv_scene_intersect(s, FV_TRACE_ALL, o, d, INFINITY, &h)) {
            break;
        }
        const fv_material *m = &s->mats[h.mat];
        fv_vec3 wo = fv_neg(d);
        if (depth == 1 && first) {
            first->hit = true;
            first->t = h.t;
            first->p = h.p;
            first->n = h.ns;
            first->obj = h.obj;
            first->albedo = m->type == FV_MAT_DIFFUSE || m->type == FV_MAT_GLOSSY ? m->albedo : m->specular;
        }
        if (fv_max3(m->emission) > 0.0f) {
            fv_vec3 le = fv_light_emitted(s, m, h.ng, wo);
            float w = 1.0f;
            if (!delta_prev) w = mis_weight(pdf_prev, fv_light_pdf_li(s, h.obj, h.prim, p_prev, h.p, h.ng, d));
            L = fv_add(L, fv_mul(beta, fv_scale(le, w)));
        }
        fv_shading sh;
        fv_shading_make(m, h.ng, h.ns, wo, &sh);

        if (fv_bsdf_is_smooth(m)) {
            fv_light_sample ls;
            float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
            if (fv_light_sample_li(s, h.p, u0, u1, u2, &ls) && fv_dot(ls.wi, sh.ng) > 0.0f) {
                float pdf_b;
                fv_vec3 f = fv_bsdf_eval(m, sh.wo, fv_shading_to_local(&sh, ls.wi), &pdf_b);
                float cosv = fabsf(fv_dot(ls.wi, sh.n));
                if (fv_max3(f) > 0.0f) {
                    nrays++;
                    if (fv_scene_visible(s, FV_TRACE_ALL, h.p, sh.ng, fv_madd(h.p, ls.wi, ls.dist))) {
                        /* At the last vertex BSDF sampling does not continue, so light sampling
                         * is the only strategy for these paths and takes the full weight. */
                        float w = ls.delta || depth == opt->max_depth ? 1.0f : mis_weight(ls.pdf, pdf_b);
                        L = fv_add(L, fv_mul(beta, fv_scale(fv_mul(f, ls.li), cosv * w / ls.pdf)));
                    }
                }
            }
        } else {
            /* keep the random stream aligned across material types */
            rng->dim += 3;
        }
        if (depth == opt->max_depth) break;

        fv_bsdf_sample bs;
        float u0 = fv_rng_next(rng), u1 = fv_rng_next(rng), u2 = fv_rng_next(rng);
        if (!fv_bsdf_sample_dir(m, sh.wo, FV_TRANSPORT_RADIANCE, u0, u1, u2, &bs)) break;
        fv_vec3 wi = fv_shading_to_world(&sh, bs.wi);
        /* Reflection must leave on the geometric side it arrived on (and refraction cross it);
         * shading normals can disagree, which would leak light through surfaces. */
        bool reflect = bs.wi.z * sh.wo.z > 0.0f;
        if ((fv_dot(wi, h.ng) * fv_dot(wo, h.ng) > 0.0f) != reflect) break;
        beta = fv_mul(beta, bs.weight);
        delta_prev = bs.delta;
        pdf_prev = bs.pdf;
        p_prev = h.p;
        o = fv_offset_point(s, h.p, h.ng, wi);
        d = wi;
        if (depth >= opt->rr_depth) {
            float q = fv_minf(0.95f, fv_max3(beta));
            if (!(fv_rng_next(rng) < q)) break;
            beta = fv_scale(beta, 1.0f / q);
        } else {
            rng->dim++;
        }
    }
    if (rays) *rays += nrays;
    return L;
}

fv_status fv_pt_read_options(fv_params *p, fv_pt_options *opt, fv_error *err)
{
    fv_status s;
    if ((s = fv_params_int(p, "spp", 16, 1, 1 << 20, &opt->spp, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "max_depth", 8, 1, 1024, &opt->max_depth, err)) != FV_OK) return s;
    if ((s = fv_params_int(p, "rr_depth", 3, 1, 1024, &opt->rr_depth, err)) != FV_OK) return s;
    return FV_OK;
}

static fv_status pt_create(const fv_scene *scene, fv_params *params, const fv_log *log, void **state, fv_error *err)
{
    pt_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    st->scene = scene;
    fv_status s = fv_pt_read_options(params, &st->opt, err);
    if (s == FV_OK) s = fv_params_check_used(params, "pt", err);
    if (s != FV_OK) {
        free(st);
        return s;
    }
    *state = st;
    return FV_OK;
}

typedef struct pt_job {
    const pt_state *st;
    const fv_frame *frame;
    fv_camera_basis cam;
    fv_film *film;
    fv_film_views out;
    int eye;
    struct {
        uint64_t rays, bad;
        char pad[48]; /* one cache line per thread */
    } counters[FV_MAX_THREADS];
} pt_job;

/* Pixels go eight at a time: their camera rays share an origin and a direction, so Embree traces
 * them as one packet; the rest of each path is traced alone. Each pixel keeps its own random
 * stream, so the image does not depend on the packing. */
static void pt_tile(void *ctx, const fv_tile *tile)
{
    pt_job *j = ctx;
    const fv_pt_options *opt = &j->st->opt;
    const int w = j->cam.width;
    uint64_t rays = 0, bad = 0;
    for (int y = tile->y0; y < tile->y1; y++) {
        for (int x0 = tile->x0; x0 < tile->x1; x0 += 8) {
            int n = tile->x1 - x0 < 8 ? tile->x1 - x0 : 8;
            fv_vec3 sum[8], dir[8];
            fv_pt_first_hit first[8];
            fv_rng rng[8];
            fv_hit hits[8];
            bool ok[8];
            memset(first, 0, sizeof first);
            for (int k = 0; k < n; k++) sum[k] = fv_v3s(0.0f);
            for (int sidx = 0; sidx < opt->spp; sidx++) {
                for (int k = 0; k < n; k++) {
                    size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                    /* The eye is folded into the pixel index so both eyes get independent noise. */
                    rng[k] = fv_rng_make(j->frame->seed, pix * 2 + (size_t)j->eye, (uint64_t)sidx, (uint64_t)j->frame->index);
                    float jx = fv_rng_next(&rng[k]), jy = fv_rng_next(&rng[k]);
                    dir[k] = fv_camera_dir(&j->cam, (float)(x0 + k) + jx, (float)y + jy);
                }
                fv_scene_intersect8(j->st->scene, j->cam.pos, dir, n, hits, ok);
                for (int k = 0; k < n; k++) {
                    fv_vec3 L = fv_pt_trace_from(j->st->scene, opt, j->cam.pos, dir[k], &hits[k], ok[k], &rng[k], sidx == 0 ? &first[k] : NULL,
                                                 &rays);
                    if (!fv_is_finite3(L)) { /* the NaN/Inf guard: count it, keep it off the film */
                        bad++;
                        continue;
                    }
                    sum[k] = fv_add(sum[k], L);
                }
            }
            for (int k = 0; k < n; k++) {
                size_t pix = (size_t)y * (size_t)w + (size_t)(x0 + k);
                fv_vec3 v = fv_scale(sum[k], 1.0f / (float)opt->spp);
                const fv_pt_first_hit *f = &first[k];
                j->out.color[3 * pix] = v.x;
                j->out.color[3 * pix + 1] = v.y;
                j->out.color[3 * pix + 2] = v.z;
                fv_film_store_first_hit(&j->out, pix, f->hit, f->t, f->p, f->n, f->albedo, f->obj);
            }
        }
    }
    j->counters[tile->thread].rays += rays;
    j->counters[tile->thread].bad += bad;
}

typedef struct pt_progress {
    const fv_frame *frame;
    double base, span;
} pt_progress;

static void pt_report(void *user, double f)
{
    pt_progress *p = user;
    p->frame->progress(p->frame->progress_user, p->base + p->span * f);
}

static fv_status render_eye(const pt_state *st, const fv_frame *frame, const fv_camera *cam, fv_film *film, int eye,
                            int neyes, fv_stats *stats, fv_error *err)
{
    pt_job *j = calloc(1, sizeof *j);
    if (!j) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status s = fv_frame_camera(cam, film, &j->cam, err);
    if (s != FV_OK) {
        free(j);
        return s;
    }
    j->st = st;
    j->frame = frame;
    j->film = film;
    j->eye = eye;
    j->out = fv_film_views_of(film);
    pt_progress prog = {frame, (double)eye / neyes, 1.0 / neyes};
    double t0 = fv_time_ms();
    fv_parallel_tiles(cam->width, cam->height, frame->threads, pt_tile, j, frame->progress ? pt_report : NULL, &prog);
    fv_stats_add_ms(stats, "trace", fv_time_ms() - t0);
    uint64_t rays = 0, bad = 0;
    for (int i = 0; i < FV_MAX_THREADS; i++) {
        rays += j->counters[i].rays;
        bad += j->counters[i].bad;
    }
    fv_stats_add_count(stats, "rays", (double)rays);
    fv_stats_add_count(stats, "samples", (double)cam->width * cam->height * st->opt.spp);
    fv_stats_add_count(stats, "nan_samples", (double)bad);
    free(j);
    return FV_OK;
}

static fv_status pt_render(void *state, const fv_frame *frame, fv_film *film, fv_film *film_right, fv_stats *stats,
                           fv_error *err)
{
    const pt_state *st = state;
    int neyes = frame->camera_right ? 2 : 1;
    fv_status s = render_eye(st, frame, frame->camera, film, 0, neyes, stats, err);
    if (s == FV_OK && frame->camera_right) s = render_eye(st, frame, frame->camera_right, film_right, 1, neyes, stats, err);
    return s;
}

static void pt_destroy(void *state) { free(state); }

const fv_technique_class fv_technique_pt = {
    "pt",
    "reference path tracer: NEE + MIS, Russian roulette (ground truth)",
    "spp=int (16): samples per pixel\n"
    "max_depth=int (8): path vertices that gather light, 1 = direct light only\n"
    "rr_depth=int (3): depth from which Russian roulette may end paths\n",
    pt_create,
    pt_render,
    pt_destroy,
};
