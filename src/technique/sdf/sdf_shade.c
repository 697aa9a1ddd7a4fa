/* fovea — the SDF family's shading (sdf_shade.h): many hits at once, each step technique/sdf/ksdf_shade.h's. */
#include <math.h>
#include <stdlib.h>
#include "technique/sdf/sdf_shade.h"

size_t fv_sdf_shade_room_bound(int n)
{
    /* the takes of fv_sdf_shade below, at n hits */
    const size_t h = (size_t)n;
    return fv_scratch_bytes(h, sizeof(int)) + fv_scratch_bytes(h * 4, sizeof(fv_vec3)) + fv_scratch_bytes(h * 4, sizeof(float)) +
           2 * fv_scratch_bytes(h, sizeof(fv_vec3)) + fv_scratch_bytes(h, sizeof(float)) + fv_scratch_bytes(h, sizeof(fv_march_ray)) +
           fv_scratch_bytes(h, sizeof(fv_march_hit)) + 2 * fv_scratch_bytes(h, sizeof(int)) + fv_scratch_bytes(h, sizeof(uint32_t)) +
           fv_scratch_bytes(h, sizeof(fv_ksdf_lobe));
}

fv_status fv_sdf_shade(const fv_sdf_world *w, const fv_march_opts *mo, const fv_sdf_shade_opts *so, const fv_march_ray *rays,
                       const fv_march_hit *hits, int n, const uint32_t *vis_in, uint32_t *vis_out, fv_vec3 *color, fv_vec3 *normal,
                       fv_sdf_shade_counts *counts, fv_scratch *room, fv_error *err)
{
    int nh = 0;
    for (int i = 0; i < n; i++) nh += hits[i].hit;
    for (int i = 0; i < n; i++) {
        if (color) color[i] = fv_v3s(0.0f);
        if (normal) normal[i] = fv_v3s(0.0f);
        if (vis_out) vis_out[i] = FV_SDF_VIS_UNKNOWN;
    }
    /* visibility is known per light as one bit, for the first 31 lights */
    const bool bits = w->k.nlights <= 31;
    if (nh == 0) return FV_OK;
    /* the temporaries, from the caller's room, given back at the end */
    const size_t mark = fv_scratch_mark(room);
    int *idx = fv_scratch_take(room, (size_t)nh, sizeof *idx);
    fv_vec3 *pt = fv_scratch_take(room, (size_t)nh * 4, sizeof *pt);
    float *val = fv_scratch_take(room, (size_t)nh * 4, sizeof *val);
    fv_vec3 *nrm = fv_scratch_take(room, (size_t)nh, sizeof *nrm), *pos = fv_scratch_take(room, (size_t)nh, sizeof *pos);
    float *hd = fv_scratch_take(room, (size_t)nh, sizeof *hd);
    fv_march_ray *sray = fv_scratch_take(room, (size_t)nh, sizeof *sray);
    fv_march_hit *shit = fv_scratch_take(room, (size_t)nh, sizeof *shit);
    int *sidx = fv_scratch_take(room, (size_t)nh, sizeof *sidx), *lit = fv_scratch_take(room, (size_t)nh, sizeof *lit);
    uint32_t *vis = fv_scratch_take_zero(room, (size_t)nh, sizeof *vis);
    fv_ksdf_lobe *lobes = color ? fv_scratch_take(room, (size_t)nh, sizeof *lobes) : NULL;
    fv_status st = FV_OK;
    if (!idx || !pt || !val || !nrm || !pos || !hd || !sray || !shit || !sidx || !lit || !vis || (color && !lobes)) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory shading %d hits", nh);
        goto done;
    }
    /* Normals: the gradient with a step of the ray's own hit distance, so a coarse level's
     * normal is as smooth as its footprint. */
    for (int i = 0, k = 0; i < n; i++) {
        if (!hits[i].hit) continue;
        const fv_march_ray *r = &rays[i];
        idx[k] = i;
        pos[k] = fv_madd(r->o, r->d, hits[i].t);
        hd[k] = fv_ksdf_hit_distance(r, hits[i].t);
        for (int j = 0; j < 4; j++) pt[4 * k + j] = fv_madd(pos[k], fv_ksdf_tet(j), hd[k]);
        k++;
    }
    fv_march_eval_points(w, mo->wide, pt, val, nh * 4);
    counts->normal_evals += (uint64_t)nh * 4;
    for (int k = 0; k < nh; k++) {
        nrm[k] = fv_ksdf_normal_of(&val[4 * k], rays[idx[k]].d);
        const fv_material *m = fv_ksdf_material(&w->k, hits[idx[k]].mat);
        if (color) {
            color[idx[k]] = fv_scale(m->albedo, so->ambient);
            lobes[k] = fv_ksdf_lobe_of(m);
        }
        if (normal) normal[idx[k]] = nrm[k];
    }
    for (int li = 0; li < w->k.nlights; li++) {
        const fv_ksdf_light *L = &w->k.lights[li];
        int ns = 0, nl = 0;
        for (int k = 0; k < nh; k++) {
            fv_march_ray *s = &sray[ns];
            if (!fv_ksdf_shadow_ray(&w->k, L, pos[k], nrm[k], hd[k], s)) continue;
            uint32_t known = vis_in && bits ? vis_in[idx[k]] : FV_SDF_VIS_UNKNOWN;
            if (known != FV_SDF_VIS_UNKNOWN || !so->shadows) {
                /* the caller knows this point's visibility (ipr's shadow_reuse), or no shadows */
                if (!so->shadows || (known >> li & 1u)) lit[nl++] = k;
                continue;
            }
            sidx[ns++] = k;
        }
        if (so->shadows && ns > 0) {
            fv_march_opts shadow = *mo;
            shadow.relax = FV_SDF_SHADOW_RELAX;
            fv_march(w, &shadow, sray, shit, ns, true);
            counts->shadow_rays += (uint64_t)ns;
        }
        for (int s = 0; s < ns; s++) {
            counts->shadow_steps += shit[s].steps;
            if (!shit[s].hit) lit[nl++] = sidx[s];
        }
        for (int q = 0; q < nl; q++) {
            int k = lit[q], i = idx[k];
            if (bits) vis[k] |= 1u << li;
            if (!color) continue;
            fv_vec3 term;
            if (fv_ksdf_light_term(L, &lobes[k], pos[k], nrm[k], hd[k], fv_neg(rays[i].d), &term)) color[i] = fv_add(color[i], term);
        }
    }
    if (vis_out && bits)
        for (int k = 0; k < nh; k++) vis_out[idx[k]] = vis[k];
done:
    fv_scratch_release(room, mark);
    return st;
}
