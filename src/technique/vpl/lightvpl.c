/* fovea — VPLs from light random walks (see lightvpl.h). */
#include <math.h>
#include "transport/light_path.h"
#include "technique/vpl/lightvpl.h"

typedef struct walk_ctx {
    const fv_scene *s;
    fv_vpl_light *vpls;
    int count, made;
} walk_ctx;

/* The light-path kernel's visit: a VPL reflects what arrives with its surface's diffuse albedo. */
static void visit(void *ctx, const fv_hit *h, const fv_material *m, fv_vec3 dir, fv_vec3 flux)
{
    walk_ctx *w = ctx;
    if (w->made >= w->count) return;
    fv_vpl_light *v = &w->vpls[w->made++];
    v->p = h->p;
    v->n = fv_dot(h->ng, dir) < 0.0f ? h->ng : fv_neg(h->ng); /* the side the light arrived on */
    v->power = fv_scale(fv_mul(flux, m->albedo), 1.0f / (float)M_PI); /* the albedo at the hit */
    v->map = -1;
}

int fv_vpl_from_light_walks(const fv_scene *s, uint64_t seed, uint64_t frame, int count, int bounces, fv_vpl_light *vpls,
                            int64_t *walks, uint64_t *rays)
{
    walk_ctx w = {s, vpls, count, 0};
    int64_t started = 0;
    const int64_t limit = 100 * (int64_t)count;
    while (w.made < count && started < limit) {
        fv_rng rng = fv_rng_stream(seed, FV_STREAM_VPL, (uint64_t)started, 0, frame);
        started++;
        fv_vec3 o, d, flux;
        if (!fv_light_path_emit(s, &rng, 1, &o, &d, &flux)) continue;
        fv_light_path_trace(s, FV_TRACE_ALL, o, d, flux, 0, bounces, &rng, visit, &w, rays);
    }
    *walks = started;
    const float inv = started > 0 ? 1.0f / (float)started : 0.0f;
    for (int i = 0; i < w.made; i++) vpls[i].power = fv_scale(vpls[i].power, inv);
    return w.made;
}
