/* fovea — mesh files through assimp (OBJ/MTL, glTF 2.0, PLY and whatever else assimp reads).
 *
 * The node hierarchy is flattened: each mesh instance becomes one object with its node's
 * transform baked in. Materials map onto ours as documented in docs/scene-format.md (MTL: Kd, Ks,
 * Ns, Ni, d, illum, Ke; glTF: base colour, metallic/roughness, transmission, emissive). A file's
 * first camera and its point/spot lights are taken when asked. Limits: textures are ignored (the
 * material's constant colour is used); lines and points are skipped.
 */
#include <assimp/cimport.h>
#include <assimp/version.h>
#include <assimp/ObjMaterial.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "core/alloc.h"
#include "scene/load_impl.h"

bool fv_load_assimp_supports(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash) || !dot[1]) return false;
    return aiIsExtensionSupported(dot) == AI_TRUE;
}

static float clamp01(float v) { return isfinite(v) ? fv_clampf(v, 0.0f, 1.0f) : 0.0f; }

static bool get_color(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, fv_vec3 *out)
{
    struct aiColor4D c;
    if (aiGetMaterialColor(m, key, type, idx, &c) != AI_SUCCESS) return false;
    *out = fv_v3(c.r, c.g, c.b);
    return fv_is_finite3(*out);
}

static bool get_float(const struct aiMaterial *m, const char *key, unsigned type, unsigned idx, float *out)
{
    ai_real v;
    unsigned n = 1;
    if (aiGetMaterialFloatArray(m, key, type, idx, &v, &n) != AI_SUCCESS || n < 1 || !isfinite(v)) return false;
    *out = (float)v;
    return true;
}

/* One assimp material -> ours. The rules (docs/scene-format.md, "Material mapping"):
 * glTF metallic/roughness when present, else MTL/Phong fields. */
static fv_material map_material(const struct aiMaterial *am, int index)
{
    fv_material m = fv_material_default(FV_MAT_DIFFUSE);
    struct aiString name;
    if (aiGetMaterialString(am, AI_MATKEY_NAME, &name) == AI_SUCCESS && name.length > 0) snprintf(m.name, sizeof m.name, "%.63s", name.data);
    else snprintf(m.name, sizeof m.name, "material%d", index);
    fv_vec3 kd = fv_v3s(0.8f), ks = fv_v3s(0.0f), ke = fv_v3s(0.0f), base;
    float ns = 0.0f, ni = 1.0f, d = 1.0f, metallic = -1.0f, rough = -1.0f, transmission = 0.0f, ke_scale = 1.0f;
    int illum = -1;
    unsigned n = 1;
    get_color(am, AI_MATKEY_COLOR_DIFFUSE, &kd);
    get_color(am, AI_MATKEY_COLOR_SPECULAR, &ks);
    get_color(am, AI_MATKEY_COLOR_EMISSIVE, &ke);
    get_float(am, AI_MATKEY_SHININESS, &ns);
    get_float(am, AI_MATKEY_REFRACTI, &ni);
    get_float(am, AI_MATKEY_OPACITY, &d);
    get_float(am, AI_MATKEY_EMISSIVE_INTENSITY, &ke_scale);
    if (aiGetMaterialIntegerArray(am, AI_MATKEY_OBJ_ILLUM, &illum, &n) != AI_SUCCESS) illum = -1;
    bool pbr = get_float(am, AI_MATKEY_METALLIC_FACTOR, &metallic);
    get_float(am, AI_MATKEY_ROUGHNESS_FACTOR, &rough);
    get_float(am, AI_MATKEY_TRANSMISSION_FACTOR, &transmission);
    if (get_color(am, AI_MATKEY_BASE_COLOR, &base)) kd = base;
    m.albedo = fv_v3(clamp01(kd.x), clamp01(kd.y), clamp01(kd.z));
    m.emission = fv_scale(fv_vmax(ke, fv_v3s(0.0f)), ke_scale > 0.0f ? ke_scale : 1.0f);

    if (pbr) {
        float r = rough >= 0.0f ? fv_clampf(rough, 0.0f, 1.0f) : 1.0f;
        if (transmission > 0.5f) {
            m.type = FV_MAT_DIELECTRIC;
            m.specular = fv_v3s(1.0f);
            m.ior = ni > 1.0f ? ni : 1.5f;
        } else if (metallic > 0.5f && r < 0.05f) {
            m.type = FV_MAT_MIRROR;
            m.specular = m.albedo;
        } else if (metallic > 0.5f || r < 0.5f) {
            /* Metals reflect their base colour; dielectric coats reflect about 4%. */
            m.type = FV_MAT_GLOSSY;
            m.specular = metallic > 0.5f ? m.albedo : fv_v3s(0.04f);
            if (metallic > 0.5f) m.albedo = fv_v3s(0.0f);
            m.roughness = fv_clampf(r * r, 0.001f, 1.0f);
        }
        return m;
    }
    bool glass = illum == 4 || illum == 6 || illum == 7 || (d < 0.5f && ni > 1.0f);
    if (glass) {
        m.type = FV_MAT_DIELECTRIC;
        m.specular = fv_v3s(1.0f);
        m.ior = ni > 1.0f ? ni : 1.5f;
    } else if (illum == 3 || illum == 5 || (fv_max3(ks) > 0.9f && fv_max3(kd) < 0.05f)) {
        m.type = FV_MAT_MIRROR;
        m.specular = fv_v3(clamp01(ks.x), clamp01(ks.y), clamp01(ks.z));
        if (fv_max3(m.specular) <= 0.0f) m.specular = fv_v3s(1.0f);
    } else if (fv_max3(ks) > 0.0f && ns > 0.0f) {
        /* Phong exponent -> GGX alpha with the usual correspondence alpha = sqrt(2 / (Ns + 2)). */
        m.type = FV_MAT_GLOSSY;
        m.specular = fv_v3(clamp01(ks.x), clamp01(ks.y), clamp01(ks.z));
        m.roughness = fv_clampf(sqrtf(2.0f / (ns + 2.0f)), 0.001f, 1.0f);
        /* Keep the sum of the lobes below one. */
        float sum = fv_max3(fv_add(m.albedo, m.specular));
        if (sum > 1.0f) m.albedo = fv_scale(m.albedo, 1.0f / sum), m.specular = fv_scale(m.specular, 1.0f / sum);
    }
    return m;
}

typedef struct import_ctx {
    const struct aiScene *ai;
    fv_scene *scene;
    fv_view *view;
    const fv_import_opts *opts;
    const fv_log *log;
    const char *path;
    int *matmap;          /* assimp material index -> ours */
    int first, count;
    fv_vec3 *pos, *nrm;
    uint32_t *idx;
} import_ctx;

static fv_xform ai_to_xform(const struct aiMatrix4x4 *m)
{
    fv_xform x;
    const float r[3][4] = {{m->a1, m->a2, m->a3, m->a4}, {m->b1, m->b2, m->b3, m->b4}, {m->c1, m->c2, m->c3, m->c4}};
    memcpy(x.m, r, sizeof x.m);
    return x;
}

static fv_xform xform_mul(const fv_xform *a, const fv_xform *b)
{
    fv_xform r;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 4; j++) {
            float v = a->m[i][0] * b->m[0][j] + a->m[i][1] * b->m[1][j] + a->m[i][2] * b->m[2][j];
            r.m[i][j] = v + (j == 3 ? a->m[i][3] : 0.0f);
        }
    return r;
}

static fv_status add_ai_mesh(import_ctx *c, const struct aiMesh *am, const fv_xform *x, fv_error *err)
{
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumVertices == 0) return FV_OK;
    int nv = (int)am->mNumVertices;
    c->pos = fv_alloc_array((size_t)nv, sizeof(fv_vec3));
    c->nrm = am->mNormals ? fv_alloc_array((size_t)nv, sizeof(fv_vec3)) : NULL;
    c->idx = fv_alloc_array((size_t)am->mNumFaces, 3 * sizeof(uint32_t));
    if (!c->pos || !c->idx || (am->mNormals && !c->nrm)) return fv_error_set(err, FV_ERR_NOMEM, "%s: out of memory", c->path);
    fv_xform inv = fv_xform_identity();
    bool has_inv = fv_xform_inverse(x, &inv);
    for (int i = 0; i < nv; i++) {
        const struct aiVector3D *p = &am->mVertices[i];
        c->pos[i] = fv_xform_point(x, fv_v3(p->x, p->y, p->z));
        if (c->nrm) {
            const struct aiVector3D *n = &am->mNormals[i];
            c->nrm[i] = has_inv ? fv_xform_normal(&inv, fv_v3(n->x, n->y, n->z)) : fv_v3(n->x, n->y, n->z);
        }
    }
    int nt = 0;
    for (unsigned f = 0; f < am->mNumFaces; f++) {
        const struct aiFace *face = &am->mFaces[f];
        if (face->mNumIndices != 3) continue;
        for (int k = 0; k < 3; k++) c->idx[3 * nt + k] = face->mIndices[k];
        nt++;
    }
    fv_status st = FV_OK;
    if (nt > 0) {
        char name[FV_NAME_MAX];
        snprintf(name, sizeof name, "%.31s%.32s", c->opts->prefix, am->mName.length ? am->mName.data : "mesh");
        fv_mesh_desc d = {name, c->pos, nv, c->nrm, c->idx, nt, NULL,
                          c->opts->material_override >= 0 ? c->opts->material_override : c->matmap[am->mMaterialIndex]};
        int id;
        st = fv_scene_add_mesh(c->scene, &d, c->log, &id, err);
        if (st == FV_OK) {
            if (c->count++ == 0) c->first = id;
        } else if (err && strstr(err->msg, "no valid triangles")) {
            /* A sub-mesh made only of degenerate or non-finite triangles is dropped like its triangles. */
            fv_log_warn(c->log, "%s: %s", c->path, err->msg);
            fv_error_clear(err);
            st = FV_OK;
        }
    }
    free(c->pos);
    free(c->nrm);
    free(c->idx);
    c->pos = c->nrm = NULL;
    c->idx = NULL;
    return st;
}

static fv_status walk(import_ctx *c, const struct aiNode *node, const fv_xform *parent, int depth, fv_error *err)
{
    if (depth > 256) return fv_error_set(err, FV_ERR_INVALID, "%s: node hierarchy deeper than 256 levels", c->path);
    fv_xform local = ai_to_xform(&node->mTransformation), x = xform_mul(parent, &local);
    for (unsigned i = 0; i < node->mNumMeshes; i++) {
        unsigned mi = node->mMeshes[i];
        if (mi >= c->ai->mNumMeshes) continue;
        fv_status st = add_ai_mesh(c, c->ai->mMeshes[mi], &x, err);
        if (st != FV_OK) return st;
    }
    for (unsigned i = 0; i < node->mNumChildren; i++) {
        fv_status st = walk(c, node->mChildren[i], &x, depth + 1, err);
        if (st != FV_OK) return st;
    }
    return FV_OK;
}

/* The world transform of the node called `name` (identity when there is none). */
static const struct aiNode *find_node(const struct aiNode *node, const char *name, const fv_xform *parent, fv_xform *out,
                                      int depth)
{
    fv_xform local = ai_to_xform(&node->mTransformation), x = xform_mul(parent, &local);
    if (strcmp(node->mName.data, name) == 0) {
        *out = x;
        return node;
    }
    for (unsigned i = 0; i < node->mNumChildren && depth < 256; i++) {
        const struct aiNode *found = find_node(node->mChildren[i], name, &x, out, depth + 1);
        if (found) return found;
    }
    return NULL;
}

/* aiCamera.mHorizontalFOV means different things per importer (assimp issues 2256, 4435, 5691):
 * half the horizontal angle as documented (FBX and most others), the full angle for Collada, and
 * for glTF the full angle computed from yfov, as yfov * aspect before assimp 5.3 and exactly
 * after. We invert what the importer did to get back the vertical angle. */
static bool is_gltf(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && (strcasecmp(dot, ".gltf") == 0 || strcasecmp(dot, ".glb") == 0);
}

static float vertical_fov(const char *path, float h, float aspect)
{
    const char *dot = strrchr(path, '.');
    bool gltf = is_gltf(path), dae = dot && strcasecmp(dot, ".dae") == 0;
    if (gltf && aiGetVersionMajor() == 5 && aiGetVersionMinor() < 3) return h / aspect;
    if (gltf || dae) return 2.0f * atanf(tanf(0.5f * h) / aspect);
    return 2.0f * atanf(tanf(h) / aspect);
}

static void import_camera_and_lights(import_ctx *c, const fv_xform *base, fv_error *err)
{
    const struct aiScene *ai = c->ai;
    if (c->opts->import_camera && ai->mNumCameras > 0) {
        const struct aiCamera *cam = ai->mCameras[0];
        fv_xform x = *base;
        const struct aiNode *node = find_node(ai->mRootNode, cam->mName.data, base, &x, 0);
        fv_vec3 local = fv_v3(cam->mPosition.x, cam->mPosition.y, cam->mPosition.z);
        /* assimp 5.2's glTF importer copies the node's translation into the camera, which is
         * relative to that node: the translation would count twice. */
        const struct aiMatrix4x4 *nt = node ? &node->mTransformation : NULL;
        if (nt && is_gltf(c->path) && local.x == nt->a4 && local.y == nt->b4 && local.z == nt->c4) local = fv_v3s(0.0f);
        fv_vec3 p = fv_xform_point(&x, local);
        fv_vec3 dir = fv_xform_vector(&x, fv_v3(cam->mLookAt.x, cam->mLookAt.y, cam->mLookAt.z));
        fv_vec3 up = fv_xform_vector(&x, fv_v3(cam->mUp.x, cam->mUp.y, cam->mUp.z));
        float aspect = cam->mAspect > 0.0f ? cam->mAspect : 1.0f;
        float fov_y = vertical_fov(c->path, cam->mHorizontalFOV, aspect);
        fv_camera fc = {p, fv_add(p, fv_normalize(dir)), up, fv_degrees(fov_y), 512, (int)lroundf(512 / aspect)};
        fv_camera_basis b;
        fv_error e2;
        if (fv_is_finite3(fc.look) && fv_camera_basis_make(&fc, &b, &e2) == FV_OK) fv_view_set_camera(c->view, &fc);
        else fv_log_warn(c->log, "%s: ignoring camera '%s' (%s)", c->path, cam->mName.data, e2.msg);
    }
    if (!c->opts->import_lights) return;
    for (unsigned i = 0; i < ai->mNumLights; i++) {
        const struct aiLight *l = ai->mLights[i];
        if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT) {
            fv_log_warn(c->log, "%s: ignoring light '%s' (only point and spot lights are imported)", c->path, l->mName.data);
            continue;
        }
        fv_xform x = *base;
        find_node(ai->mRootNode, l->mName.data, base, &x, 0);
        fv_light_desc d;
        memset(&d, 0, sizeof d);
        d.type = l->mType == aiLightSource_POINT ? FV_LIGHT_POINT : FV_LIGHT_SPOT;
        d.pos = fv_xform_point(&x, fv_v3(l->mPosition.x, l->mPosition.y, l->mPosition.z));
        d.dir = fv_xform_vector(&x, fv_v3(l->mDirection.x, l->mDirection.y, l->mDirection.z));
        d.intensity = fv_v3(l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b);
        d.outer_deg = fv_degrees(fminf(l->mAngleOuterCone, 1.5f));
        d.inner_deg = fminf(fv_degrees(l->mAngleInnerCone), d.outer_deg);
        fv_error e2;
        if (fv_scene_add_light(c->scene, &d, &e2) != FV_OK) fv_log_warn(c->log, "%s: ignoring light '%s': %s", c->path, l->mName.data, e2.msg);
    }
    (void)err;
}

fv_status fv_load_assimp(const char *path, fv_scene *scene, fv_view *view, const fv_import_opts *opts, const fv_log *log,
                         int *first_object, int *object_count, fv_error *err)
{
    struct aiPropertyStore *props = aiCreatePropertyStore();
    /* Points and lines would only be dropped later; ask assimp not to produce them. */
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const struct aiScene *ai = aiImportFileExWithProperties(
        path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType, NULL, props);
    aiReleasePropertyStore(props);
    if (!ai) {
        /* Our messages are one line; some of assimp's are not. */
        const char *why = aiGetErrorString();
        char line[256];
        snprintf(line, sizeof line, "%s", why && why[0] ? why : "assimp could not read it");
        for (char *ch = line; *ch; ch++)
            if (*ch == '\n' || *ch == '\r' || *ch == '\t') *ch = ' ';
        for (size_t n = strlen(line); n > 0 && line[n - 1] == ' '; n--) line[n - 1] = '\0';
        return fv_error_set(err, FV_ERR_INVALID, "scene '%s': %s", path, line);
    }
    import_ctx c;
    memset(&c, 0, sizeof c);
    c.ai = ai;
    c.scene = scene;
    c.view = view;
    c.opts = opts;
    c.log = log;
    c.path = path;
    fv_status st = FV_OK;
    if (!ai->mRootNode || ai->mNumMeshes == 0) st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': the file holds no meshes", path);
    if (st == FV_OK && !(c.matmap = fv_alloc_array(ai->mNumMaterials + 1, sizeof(int))))
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (unsigned i = 0; st == FV_OK && i < ai->mNumMaterials && opts->material_override < 0; i++) {
        fv_material m = map_material(ai->mMaterials[i], (int)i);
        char name[FV_NAME_MAX];
        snprintf(name, sizeof name, "%.31s%.32s", opts->prefix, m.name);
        snprintf(m.name, sizeof m.name, "%s", name);
        if ((st = fv_scene_add_material(scene, &m, &c.matmap[i], err)) != FV_OK) fv_error_prefix(err, "scene '%s': ", path);
    }
    fv_xform base = opts->xform ? *opts->xform : fv_xform_identity();
    if (st == FV_OK) st = walk(&c, ai->mRootNode, &base, 0, err);
    if (st == FV_OK && c.count == 0) st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': no usable triangles in the file", path);
    if (st == FV_OK) import_camera_and_lights(&c, &base, err);
    free(c.matmap);
    aiReleaseImport(ai);
    if (st == FV_OK) {
        if (first_object) *first_object = c.first;
        if (object_count) *object_count = c.count;
    }
    return st;
}
