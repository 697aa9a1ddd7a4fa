/* fovea — material defaults, names and validation (the BSDFs themselves are kernel/kbsdf.h). */
#include <stdio.h>
#include <string.h>
#include "fovea/limits.h"
#include "fovea/scene.h"

static const char *const k_type_names[] = {"diffuse", "mirror", "glossy", "dielectric"};

fv_material fv_material_default(fv_material_type type)
{
    fv_material m;
    memset(&m, 0, sizeof m);
    snprintf(m.name, sizeof m.name, "%s", k_type_names[type]);
    m.type = type;
    m.albedo = fv_v3s(type == FV_MAT_DIFFUSE || type == FV_MAT_GLOSSY ? 0.8f : 0.0f);
    m.specular = fv_v3s(type == FV_MAT_GLOSSY ? 0.04f : 1.0f);
    m.roughness = 0.2f;
    m.ior = 1.5f;
    return m;
}

bool fv_material_type_from_name(const char *name, fv_material_type *out)
{
    for (int i = 0; i < 4; i++)
        if (strcmp(name, k_type_names[i]) == 0) {
            *out = (fv_material_type)i;
            return true;
        }
    return false;
}

const char *fv_material_type_name(fv_material_type type)
{
    return (unsigned)type < 4 ? k_type_names[type] : "unknown";
}

static bool in01(fv_vec3 c) { return fv_is_finite3(c) && fv_min3(c) >= 0.0f && fv_max3(c) <= 1.0f; }

fv_status fv_material_validate(const fv_material *m, fv_error *err)
{
    if ((unsigned)m->type > FV_MAT_DIELECTRIC)
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': unknown type %d", m->name, (int)m->type);
    if (!in01(m->albedo))
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': albedo must be finite and in [0,1]", m->name);
    if (!in01(m->specular))
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': specular must be finite and in [0,1]", m->name);
    if (m->type == FV_MAT_GLOSSY && !(m->roughness >= 0.001f && m->roughness <= 1.0f))
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': roughness %g outside [0.001, 1]", m->name, m->roughness);
    if (m->type == FV_MAT_DIELECTRIC && !(m->ior > 1.0f && m->ior < 10.0f))
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': ior %g outside (1, 10)", m->name, m->ior);
    if (m->albedo_texture < 0)
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': albedo_texture %d is not a texture id (0: none)", m->name, m->albedo_texture);
    if (m->emission_texture < 0)
        return fv_error_set(err, FV_ERR_INVALID, "material '%s': emission_texture %d is not a texture id (0: none)", m->name, m->emission_texture);
    char what[FV_NAME_MAX + 32];
    snprintf(what, sizeof what, "material '%s': emission", m->name);
    return fv_limit_intensity3(what, m->emission, err);
}
