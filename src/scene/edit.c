/* fovea — library-internal edits of an uncommitted scene (scene/edit.h). */
#include <string.h>
#include "scene/edit.h"
#include "scene/scene_impl.h"

int fv_scene_find_object(const fv_scene *s, const char *name)
{
    for (int i = 0; name && i < s->nobj; i++)
        if (strcmp(s->objs[i].name, name) == 0) return i;
    return -1;
}

fv_status fv_scene_make_diffuse(fv_scene *s, fv_error *err)
{
    if (s->committed) return fv_error_set(err, FV_ERR_INTERNAL, "scene already committed: its materials cannot be changed");
    for (int i = 0; i < s->nmat; i++) {
        fv_material *m = &s->mats[i];
        /* A diffuse material's `specular` is unused (its default is 1), so it stays as it is. */
        if (m->type == FV_MAT_DIFFUSE) continue;
        /* The specular part is added rather than dropped: an all-specular surface (mirror, glass,
         * a metal with no diffuse albedo) keeps about the light it reflected instead of turning
         * black. 0.95 keeps every surface absorbing, so light paths still end. */
        fv_vec3 a = fv_add(m->albedo, m->specular);
        fv_material d = fv_material_default(FV_MAT_DIFFUSE);
        memcpy(d.name, m->name, sizeof d.name);
        d.albedo = fv_v3(a.x < 0.95f ? a.x : 0.95f, a.y < 0.95f ? a.y : 0.95f, a.z < 0.95f ? a.z : 0.95f);
        d.emission = m->emission;
        d.two_sided_emission = m->two_sided_emission;
        *m = d;
    }
    return FV_OK;
}
