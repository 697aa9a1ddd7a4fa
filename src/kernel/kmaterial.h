/* fovea — the material at a hit on the flat scene (kernel/kscene.h): the same rule as the CPU's
 * fv_hit_material (scene/query.h), with the same texture lookup (kernel/ktexture.h): a textured
 * material on a mesh with UVs gets its albedo read at the hit, anything else the scene's own.
 */
#ifndef FV_KERNEL_KMATERIAL_H
#define FV_KERNEL_KMATERIAL_H

#include "kernel/khit.h"
#include "kernel/kscene.h"
#include "kernel/ktexture.h"

FV_HD static inline const fv_material *fv_kscene_material_at(const fv_kscene *s, const fv_hit *h, fv_material *buf)
{
    const fv_material *m = &s->mats[h->mat];
    if (!m->albedo_texture && !m->emission_texture) return m;
    const fv_kobject *o = &s->objs[h->obj];
    if (o->uv_off < 0 || o->is_sdf || h->prim < 0 || h->prim >= o->ntri) return m;
    const fv_ktexture *ta = fv_ktexture_id(s->tex, s->ntex, m->albedo_texture);
    const fv_ktexture *te = fv_ktexture_id(s->tex, s->ntex, m->emission_texture);
    if (!ta && !te) return m;
    const uint32_t *ix = &s->tri_vtx[3 * (o->first_tri + h->prim)];
    const fv_vec2 *uv = &s->uv[o->uv_off - o->vtx_off];
    return fv_kmaterial_textured(m, ta, te, uv[ix[0]], uv[ix[1]], uv[ix[2]], h->u, h->v, buf);
}

#endif
