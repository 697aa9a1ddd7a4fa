/* fovea — mesh files through assimp (OBJ/MTL, glTF 2.0, PLY and whatever else assimp reads).
 *
 * assimp runs in a child process (core/sandbox.h): on malformed files some of its importers
 * assert and abort, crash, loop, or allocate what a header claims (15 GB for a .off file of a few
 * bytes). The child imports, flattens and converts; it streams materials, triangle meshes, the
 * camera and the lights back as plain records, and the parent adds them to the scene. However the
 * child ends, the parent reports it as a bad file (exit status 2). Before that, counts a PLY or OFF
 * header declares are checked against the file's size, so the common runaway is refused at once.
 * The child's cost is one fork per mesh file and one copy of the mesh through a pipe.
 *
 * The node hierarchy is flattened: each mesh instance becomes one object with its node's
 * transform baked in. Materials map onto ours as documented in docs/scene-format.md (MTL: Kd, Ks,
 * Ns, Ni, d, illum, Ke, map_Kd, map_Ke; glTF: base colour and its texture, metallic/roughness,
 * transmission, emissive and its texture). A file's first camera and its point/spot/directional
 * lights are taken when asked. Base-colour and emission textures (glTF baseColorTexture and
 * emissiveTexture embedded in a .glb, in a data URI or in a file next to the model; MTL map_Kd and
 * map_Ke) are decoded in the child too (scene/texture.h) and sent once each; one that cannot be
 * read is a warning and its material keeps the constant colour or emission. Only the first UV
 * channel is read. Limits: other texture kinds are ignored; lines and points are skipped.
 */
#include <assimp/cimport.h>
#include <assimp/version.h>
#include <assimp/ObjMaterial.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <limits.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include "core/fileio.h"
#include "core/alloc.h"
#include "core/sandbox.h"
#include "fovea/limits.h"
#include "scene/load_impl.h"
#include "scene/scene_impl.h"
#include "scene/texture.h"

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

/* ---- the child: assimp's scene as records on a pipe ---- */

enum { REC_TEXTURE = 'T', REC_MATERIAL = 'M', REC_MESH = 'G', REC_CAMERA = 'C', REC_LIGHT = 'L', REC_WARN = 'W', REC_ERROR = 'E', REC_END = 'Z' };

typedef struct mesh_head {
    char name[FV_NAME_MAX];
    int material; /* assimp's material index */
    int nv, nt, has_normals, has_uvs;
} mesh_head;

typedef struct light_rec {
    fv_light_desc d;
    char name[64];
} light_rec;

typedef struct camera_rec {
    fv_camera c;
    char name[64];
} camera_rec;

/* A texture the child has already tried: its path as the file names it, the id it was sent with
 * (0: it could not be read, for `why`). */
typedef struct tex_seen {
    char path[1024];
    int id;
    char why[256];
} tex_seen;

typedef struct import_ctx {
    const char *path;
    const fv_import_opts *opts;
    const struct aiScene *ai;
    int fd;
    bool ok;
    tex_seen *seen;
    int nseen, capseen, ntex;
    char said[4][160];    /* the importer's data-loss warnings passed on so far (each once) */
    int nsaid;
} import_ctx;

static void put(import_ctx *c, char tag, const void *p, size_t n)
{
    if (c->ok) c->ok = fv_sandbox_write(c->fd, &tag, 1) && (n == 0 || fv_sandbox_write(c->fd, p, n));
}

static void put_text(import_ctx *c, char tag, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void put_text(import_ctx *c, char tag, const char *fmt, ...)
{
    char msg[FV_ERROR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int n = (int)strlen(msg);
    put(c, tag, &n, sizeof n);
    if (c->ok) c->ok = fv_sandbox_write(c->fd, msg, (size_t)n);
}

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

/* One mesh instance, its node's transform baked in, as a REC_MESH record. */
static void put_mesh(import_ctx *c, const struct aiMesh *am, const fv_xform *x)
{
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || am->mNumVertices == 0 || am->mNumVertices > INT_MAX ||
        am->mNumFaces > INT_MAX / 3)
        return;
    mesh_head h;
    memset(&h, 0, sizeof h);
    snprintf(h.name, sizeof h.name, "%.63s", am->mName.length ? am->mName.data : "mesh");
    h.material = (int)am->mMaterialIndex;
    h.nv = (int)am->mNumVertices;
    h.has_normals = am->mNormals != NULL;
    h.has_uvs = am->mTextureCoords[0] != NULL;
    for (unsigned f = 0; f < am->mNumFaces; f++) h.nt += am->mFaces[f].mNumIndices == 3;
    if (h.nt == 0) return;
    fv_vec3 *pos = fv_alloc_array((size_t)h.nv, sizeof(fv_vec3));
    fv_vec3 *nrm = h.has_normals ? fv_alloc_array((size_t)h.nv, sizeof(fv_vec3)) : NULL;
    fv_vec2 *uv = h.has_uvs ? fv_alloc_array((size_t)h.nv, sizeof(fv_vec2)) : NULL;
    uint32_t *idx = fv_alloc_array((size_t)h.nt, 3 * sizeof(uint32_t));
    if (!pos || !idx || (h.has_normals && !nrm) || (h.has_uvs && !uv)) {
        put_text(c, REC_ERROR, "out of memory for a mesh of %d vertices", h.nv);
    } else {
        fv_xform inv = fv_xform_identity();
        bool has_inv = fv_xform_inverse(x, &inv);
        for (int i = 0; i < h.nv; i++) {
            const struct aiVector3D *p = &am->mVertices[i];
            pos[i] = fv_xform_point(x, fv_v3(p->x, p->y, p->z));
            if (nrm) {
                const struct aiVector3D *n = &am->mNormals[i];
                nrm[i] = has_inv ? fv_xform_normal(&inv, fv_v3(n->x, n->y, n->z)) : fv_v3(n->x, n->y, n->z);
            }
            if (uv) uv[i] = (fv_vec2){am->mTextureCoords[0][i].x, am->mTextureCoords[0][i].y};
        }
        int t = 0;
        for (unsigned f = 0; f < am->mNumFaces; f++) {
            const struct aiFace *face = &am->mFaces[f];
            if (face->mNumIndices != 3) continue;
            for (int k = 0; k < 3; k++) idx[3 * t + k] = face->mIndices[k];
            t++;
        }
        put(c, REC_MESH, &h, sizeof h);
        if (c->ok) c->ok = fv_sandbox_write(c->fd, pos, (size_t)h.nv * sizeof *pos);
        if (c->ok && nrm) c->ok = fv_sandbox_write(c->fd, nrm, (size_t)h.nv * sizeof *nrm);
        if (c->ok && uv) c->ok = fv_sandbox_write(c->fd, uv, (size_t)h.nv * sizeof *uv);
        if (c->ok) c->ok = fv_sandbox_write(c->fd, idx, (size_t)h.nt * 3 * sizeof *idx);
    }
    free(pos);
    free(nrm);
    free(uv);
    free(idx);
}

static void walk(import_ctx *c, const struct aiNode *node, const fv_xform *parent, int depth)
{
    if (depth > 256) {
        put_text(c, REC_ERROR, "node hierarchy deeper than 256 levels");
        return;
    }
    fv_xform local = ai_to_xform(&node->mTransformation), x = xform_mul(parent, &local);
    for (unsigned i = 0; i < node->mNumMeshes && c->ok; i++) {
        unsigned mi = node->mMeshes[i];
        if (mi < c->ai->mNumMeshes) put_mesh(c, c->ai->mMeshes[mi], &x);
    }
    for (unsigned i = 0; i < node->mNumChildren && c->ok; i++) walk(c, node->mChildren[i], &x, depth + 1);
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

static void put_camera_and_lights(import_ctx *c, const fv_xform *base)
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
        float aspect = cam->mAspect > 0.0f && isfinite(cam->mAspect) ? cam->mAspect : 1.0f;
        float fov_y = vertical_fov(c->path, cam->mHorizontalFOV, aspect);
        float hgt = 512.0f / aspect;
        camera_rec r;
        memset(&r, 0, sizeof r);
        r.c = (fv_camera){p, fv_add(p, fv_normalize(dir)), up, fv_degrees(fov_y), 512, hgt >= 1.0f && hgt < 1e6f ? (int)lroundf(hgt) : 512};
        snprintf(r.name, sizeof r.name, "%.63s", cam->mName.data);
        put(c, REC_CAMERA, &r, sizeof r);
    }
    if (!c->opts->import_lights) return;
    for (unsigned i = 0; i < ai->mNumLights && c->ok; i++) {
        const struct aiLight *l = ai->mLights[i];
        if (l->mType != aiLightSource_POINT && l->mType != aiLightSource_SPOT && l->mType != aiLightSource_DIRECTIONAL) {
            put_text(c, REC_WARN, "ignoring light '%.63s' (only point, spot and directional lights are imported)", l->mName.data);
            continue;
        }
        fv_xform x = *base;
        find_node(ai->mRootNode, l->mName.data, base, &x, 0);
        light_rec r;
        memset(&r, 0, sizeof r);
        fv_light_desc *d = &r.d;
        d->type = l->mType == aiLightSource_POINT ? FV_LIGHT_POINT : l->mType == aiLightSource_SPOT ? FV_LIGHT_SPOT : FV_LIGHT_DIRECTIONAL;
        d->pos = fv_xform_point(&x, fv_v3(l->mPosition.x, l->mPosition.y, l->mPosition.z));
        d->dir = fv_xform_vector(&x, fv_v3(l->mDirection.x, l->mDirection.y, l->mDirection.z));
        d->intensity = fv_v3(l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b);
        d->outer_deg = fv_degrees(fminf(l->mAngleOuterCone, 1.5f));
        d->inner_deg = fminf(fv_degrees(l->mAngleInnerCone), d->outer_deg);
        snprintf(r.name, sizeof r.name, "%.63s", l->mName.data);
        put(c, REC_LIGHT, &r, sizeof r);
    }
}

/* The embedded image a texture path names: "*N" (assimp's index), or one whose file name matches
 * the path's last component (how .glb images are named). NULL when none. */
static const struct aiTexture *embedded(const struct aiScene *ai, const char *p)
{
    if (p[0] == '*') {
        char *end;
        long i = strtol(p + 1, &end, 10);
        return *end == '\0' && i >= 0 && i < (long)ai->mNumTextures ? ai->mTextures[i] : NULL;
    }
    const char *base = strrchr(p, '/') ? strrchr(p, '/') + 1 : p;
    for (unsigned i = 0; i < ai->mNumTextures; i++) {
        const char *f = ai->mTextures[i]->mFilename.data, *fb = strrchr(f, '/') ? strrchr(f, '/') + 1 : f;
        if (ai->mTextures[i]->mFilename.length && strcmp(fb, base) == 0) return ai->mTextures[i];
    }
    return NULL;
}

/* Decodes the image texture path tp names: embedded (compressed, or assimp's raw BGRA texels) or
 * a file relative to the model's folder. */
static bool texels_of(const import_ctx *c, const char *tp, fv_texels *t, char *why, size_t n)
{
    const struct aiTexture *e = embedded(c->ai, tp);
    if (e && e->mHeight == 0) return fv_texels_decode(e->pcData, e->mWidth, t, why, n);
    if (e) {
        if (e->mWidth < 1 || (long long)e->mWidth * e->mHeight > FV_TEXTURE_MAX_TEXELS) {
            snprintf(why, n, "%ux%u is more than the %d texels a texture may have", e->mWidth, e->mHeight, FV_TEXTURE_MAX_TEXELS);
            return false;
        }
        size_t count = (size_t)e->mWidth * e->mHeight;
        unsigned char *px = fv_alloc_array(count, 4);
        if (!px) {
            snprintf(why, n, "out of memory");
            return false;
        }
        for (size_t i = 0; i < count; i++) {
            const struct aiTexel *x = &e->pcData[i];
            px[4 * i] = x->r, px[4 * i + 1] = x->g, px[4 * i + 2] = x->b, px[4 * i + 3] = x->a;
        }
        *t = (fv_texels){(int)e->mWidth, (int)e->mHeight, 4, px};
        return true;
    }
    if (tp[0] == '*') {
        snprintf(why, n, "the file embeds no image %.20s", tp);
        return false;
    }
    char full[4096], rel[1024];
    snprintf(rel, sizeof rel, "%s", tp);
    for (char *q = rel; *q; q++)
        if (*q == '\\') *q = '/'; /* paths written on Windows */
    const char *slash = strrchr(c->path, '/');
    if (rel[0] == '/' || !slash) snprintf(full, sizeof full, "%s", rel);
    else snprintf(full, sizeof full, "%.*s/%s", (int)(slash - c->path), c->path, rel);
    return fv_texels_decode_file(full, t, why, n);
}

/* The path of material am's texture of kind `type` (or else of `alt`), false when it has none. */
static bool texture_path(const struct aiMaterial *am, enum aiTextureType type, enum aiTextureType alt, struct aiString *p)
{
    return (aiGetMaterialString(am, AI_MATKEY_TEXTURE(type, 0), p) == AI_SUCCESS && p->length > 0) ||
           (aiGetMaterialString(am, AI_MATKEY_TEXTURE(alt, 0), p) == AI_SUCCESS && p->length > 0);
}

/* The id the texture of material am (named mat_name) of kind `type` (or else `alt`: a glTF base
 * colour, else an MTL map_Kd) was sent with, sending it the first time it is asked for; 0 when it
 * has none, or when it cannot be read: then a warning names the file, the material and what the
 * material does instead (`instead`). */
static int material_texture(import_ctx *c, const struct aiMaterial *am, const char *mat_name, enum aiTextureType type,
                            enum aiTextureType alt, const char *instead)
{
    struct aiString p;
    if (!texture_path(am, type, alt, &p)) return 0;
    int k = 0;
    while (k < c->nseen && strcmp(c->seen[k].path, p.data) != 0) k++;
    if (k == c->nseen) {
        if (fv_grow((void **)&c->seen, &c->capseen, c->nseen + 1, sizeof *c->seen)) {
            put_text(c, REC_ERROR, "out of memory");
            return 0;
        }
        tex_seen *ts = &c->seen[c->nseen++];
        memset(ts, 0, sizeof *ts);
        snprintf(ts->path, sizeof ts->path, "%s", p.data);
        fv_texels t;
        if (texels_of(c, p.data, &t, ts->why, sizeof ts->why)) {
            ts->id = ++c->ntex;
            put(c, REC_TEXTURE, &ts->id, sizeof ts->id);
            if (c->ok) c->ok = fv_texels_put(c->fd, &t);
            free(t.px);
        }
    }
    if (c->seen[k].id == 0)
        put_text(c, REC_WARN, "texture '%.200s' of material '%s': %s; %s", c->seen[k].path, mat_name, c->seen[k].why, instead);
    return c->seen[k].id;
}

/* assimp's log, in the child: the warnings that say the importer itself dropped data ("Some faces
 * had out-of-range indices. Those faces were dropped.") are passed on, each once and at most four,
 * since fovea cannot see that loss in what it receives; the importer's other chatter is not. */
static void importer_log(const char *msg, char *user)
{
    import_ctx *c = (import_ctx *)user;
    if (strncmp(msg, "Warn,", 5) != 0) return;
    if (!strstr(msg, "dropped") && !strstr(msg, "out-of-range") && !strstr(msg, "out of range")) return;
    const char *text = strchr(msg, ':'); /* "Warn,  T0: text" */
    text = text ? text + 1 : msg + 5;
    while (*text == ' ') text++;
    char line[160];
    snprintf(line, sizeof line, "%s", text);
    for (size_t n = strlen(line); n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'); n--) line[n - 1] = '\0';
    for (int i = 0; i < c->nsaid; i++)
        if (!strcmp(c->said[i], line)) return;
    if (c->nsaid == (int)(sizeof c->said / sizeof c->said[0])) return;
    snprintf(c->said[c->nsaid++], sizeof c->said[0], "%s", line);
    put_text(c, REC_WARN, "the importer (assimp): %s", line);
}

static int import_child(void *user, int fd)
{
    import_ctx *c = user;
    c->fd = fd;
    c->ok = true;
    struct aiLogStream log_stream = {importer_log, (char *)c};
    aiAttachLogStream(&log_stream);
    struct aiPropertyStore *props = aiCreatePropertyStore();
    /* Points and lines would only be dropped later; ask assimp not to produce them. */
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const struct aiScene *ai = aiImportFileExWithProperties(
        c->path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType, NULL, props);
    aiReleasePropertyStore(props);
    c->ai = ai;
    if (!ai) {
        const char *why = aiGetErrorString();
        put_text(c, REC_ERROR, "%s", why && why[0] ? why : "assimp could not read it");
    } else if (!ai->mRootNode || ai->mNumMeshes == 0) {
        put_text(c, REC_ERROR, "the file holds no meshes");
    } else {
        for (unsigned i = 0; c->ok && i < ai->mNumMaterials && c->opts->material_override < 0; i++) {
            fv_material m = map_material(ai->mMaterials[i], (int)i);
            const struct aiMaterial *am = ai->mMaterials[i];
            /* the child's numbering */
            m.albedo_texture = material_texture(c, am, m.name, aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE, "using the constant colour");
            m.emission_texture = material_texture(c, am, m.name, aiTextureType_EMISSIVE, aiTextureType_EMISSION_COLOR, "using the constant emission");
            /* An emission texture with no emissive colour: glTF defines emissiveFactor's default as
             * 0 (nothing emitted, whatever the texture); an MTL map_Ke without Ke is the texture
             * alone, as the exporters that write it mean (Ke 1). */
            if (m.emission_texture && !(fv_max3(m.emission) > 0.0f) && !is_gltf(c->path)) m.emission = fv_v3s(1.0f);
            put(c, REC_MATERIAL, &m, sizeof m);
        }
        fv_xform base = c->opts->xform ? *c->opts->xform : fv_xform_identity();
        walk(c, ai->mRootNode, &base, 0);
        put_camera_and_lights(c, &base);
        put(c, REC_END, NULL, 0);
    }
    if (ai) aiReleaseImport(ai);
    aiDetachAllLogStreams();
    free(c->seen);
    return c->ok ? 0 : 3;
}

/* ---- before the child: counts a header declares against the file's size ---- */

/* A PLY header must be whole, and its format, element and property lines well formed: assimp
 * loops without end on a header cut short or with a mangled declaration. Any other line is skipped
 * as the reader skips it (comment, obj_info, and free text such as Blender 2.47's "Created by
 * Blender3D 247 ..." line): the check must not refuse what the format's reader takes. Sets
 * *elements to the sum of the element counts. */
/* True when a header line starts with one of the keywords that declare something (format,
 * element, property): those must parse; the reader skips every other line. */
static bool ply_declares(const char *line)
{
    static const char *const words[] = {"format", "element", "property", NULL};
    for (int i = 0; words[i]; i++) {
        size_t n = strlen(words[i]);
        if (!strncmp(line, words[i], n) && (line[n] == '\0' || line[n] == ' ' || line[n] == '\t')) return true;
    }
    return false;
}

static bool ply_header_ok(const char *head, long double *elements, int *line_no)
{
    static const char *const types[] = {"char", "uchar", "short", "ushort", "int", "uint", "float", "double", "int8", "uint8",
                                        "int16", "uint16", "int32", "uint32", "float32", "float64", NULL};
    *elements = 0;
    int n = 0;
    for (const char *l = head; *l; n++) {
        const char *nl = strchr(l, '\n');
        if (!nl) break; /* no end_header within the first 64 kB */
        char line[256];
        size_t len = (size_t)(nl - l) < sizeof line - 1 ? (size_t)(nl - l) : sizeof line - 1;
        memcpy(line, l, len);
        line[len] = '\0';
        if (len && line[len - 1] == '\r') line[--len] = '\0';
        *line_no = n + 1;
        char a[64], b[64], c[64], d[64], e[64];
        long double cnt;
        int k;
        if (n == 0) {
            if (strcmp(line, "ply")) return false;
        } else if (!strcmp(line, "end_header")) {
            return n > 1;
        } else if (!ply_declares(line)) {
            /* a comment, obj_info or free text: skipped */
        } else if (sscanf(line, "format %63s %63s %n", a, b, &k) == 2) {
            if (strcmp(a, "ascii") && strcmp(a, "binary_little_endian") && strcmp(a, "binary_big_endian")) return false;
        } else if (sscanf(line, "element %63s %Lf %n", a, &cnt, &k) == 2 && line[k] == '\0') {
            if (!(cnt >= 0) || cnt != floorl(cnt)) return false;
            *elements += cnt;
        } else if (sscanf(line, "property list %63s %63s %63s %n", a, b, c, &k) == 3 && line[k] == '\0') {
            bool ta = false, tb = false;
            for (int t = 0; types[t]; t++) ta |= !strcmp(a, types[t]), tb |= !strcmp(b, types[t]);
            if (!ta || !tb) return false;
        } else if (sscanf(line, "property %63s %63s %n", d, e, &k) == 2 && line[k] == '\0') {
            bool td = false;
            for (int t = 0; types[t]; t++) td |= !strcmp(d, types[t]);
            if (!td) return false;
        } else {
            return false;
        }
        l = nl + 1;
    }
    return false;
}

/* PLY and OFF headers declare element counts: every element takes at least one byte (binary) or
 * two (text), so a count beyond that is a lie that would make the importer reserve gigabytes.
 * Other formats are left to the child's limits. */
static fv_status check_header(const char *path, long long size, fv_error *err)
{
    const char *dot = strrchr(path, '.');
    bool ply = dot && strcasecmp(dot, ".ply") == 0, off = dot && strcasecmp(dot, ".off") == 0;
    if (!ply && !off) return FV_OK;
    FILE *f = fopen(path, "rb");
    if (!f) return FV_OK; /* the importer says why */
    static const size_t cap = 65536;
    char *head = malloc(cap);
    if (!head) {
        fclose(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    size_t n = fread(head, 1, cap - 1, f);
    fclose(f);
    head[n] = '\0';
    long double total = 0;
    int per = 2, line = 0;
    fv_status st = FV_OK;
    if (ply) {
        per = strstr(head, "format ascii") ? 2 : 1;
        if (!ply_header_ok(head, &total, &line))
            st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': PLY header line %d is malformed or the header does not end (end_header)", path,
                              line ? line : 1);
    } else {
        const char *l = head;
        while (*l == ' ' || *l == '\t') l++;
        while (*l == 'C' || *l == 'N' || *l == 'S' || *l == 'T' || *l == '4' || *l == 'n') l++; /* COFF, NOFF, STOFF, 4OFF, nOFF */
        const char *nl = strchr(l, '\n');
        long double nv, nf;
        if (nl && sscanf(nl + 1, "%Lf %Lf", &nv, &nf) == 2 && nv > 0 && nf > 0) total = nv + nf;
    }
    free(head);
    if (st == FV_OK && total * per > (long double)size)
        st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': its header declares %.0Lf elements, more than its %lld bytes can hold", path, total,
                          size);
    return st;
}

/* ---- the parent: records into the scene ---- */

/* Dropped triangles over a whole file. */
typedef struct drop_tally {
    long long tris, of; /* dropped, and the triangles of the meshes that dropped some */
    int meshes;         /* meshes (instances) that dropped any */
    char worst[FV_NAME_MAX];
    int worst_n;
} drop_tally;

static void drop_add(drop_tally *t, const char *mesh, int dropped, int of)
{
    if (dropped <= 0) return;
    t->tris += dropped;
    t->of += of;
    t->meshes++;
    if (dropped > t->worst_n) {
        t->worst_n = dropped;
        snprintf(t->worst, sizeof t->worst, "%s", mesh);
    }
}

fv_status fv_load_assimp(const char *path, fv_scene *scene, fv_view *view, const fv_import_opts *opts, const fv_log *log,
                         int *first_object, int *object_count, fv_error *err)
{
    /* A regular file only (core/fileio.h): the child would read /dev/zero until its limits, or
     * block on a FIFO. */
    fv_status st = fv_file_check_read(path, "scene", err);
    if (st != FV_OK) return st;
    struct stat sb;
    if (stat(path, &sb) != 0) return fv_error_set(err, FV_ERR_IO, "cannot open scene '%s': %s", path, strerror(errno));
    st = check_header(path, (long long)sb.st_size, err);
    if (st != FV_OK) return st;
    /* Limits for the child: room for meshes many times the file's size, at least 2 GiB (a .gltf
     * file may name large .bin buffers), and 10 s of CPU time plus 2 s per MB (assimp reads tens of MB a second). */
    size_t mem = (size_t)2 << 30;
    if ((size_t)sb.st_size < ((size_t)64 << 30) / 64 && (size_t)sb.st_size * 64 > mem) mem = (size_t)sb.st_size * 64;
    int cpu = 10 + 2 * (int)(sb.st_size >> 20);
    import_ctx c;
    memset(&c, 0, sizeof c);
    c.path = path;
    c.opts = opts;
    c.fd = -1;
    c.ok = true;
    fv_sandbox *box;
    if ((st = fv_sandbox_start(import_child, &c, mem, cpu, &box, err)) != FV_OK) return st;

    int *matmap = NULL, nmat = 0, cap = 0, first = -1, count = 0;
    /* Triangles the scene refused, said once for the whole file: a CAD export can drop a few in
     * each of dozens of meshes, and name the same mesh once per instance. */
    drop_tally drops = {0};
    char camera[FV_NAME_MAX] = ""; /* the file's camera the view took (the last one sent) */
    int ncameras = 0;
    int *texmap = NULL, ntex = 0, captex = 0; /* the child's texture numbers -> the scene's ids (0: refused) */
    bool ended = false;
    char tag;
    while (st == FV_OK && !ended && fv_sandbox_read(box, &tag, 1)) {
        if (tag == REC_TEXTURE) {
            int local;
            fv_texels t;
            if (!fv_sandbox_read(box, &local, sizeof local) || local != ntex + 1 || !fv_texels_get(box, &t)) break;
            if (fv_grow((void **)&texmap, &captex, ntex + 1, sizeof *texmap)) {
                free(t.px);
                st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
                break;
            }
            char name[FV_NAME_MAX];
            snprintf(name, sizeof name, "%.40s texture %d", opts->prefix, local);
            fv_texture_desc d = {name, t.w, t.h, t.channels, t.px};
            fv_error e2;
            texmap[ntex] = 0;
            fv_status ts = fv_scene_add_texture(scene, &d, &texmap[ntex], &e2);
            free(t.px);
            ntex++;
            if (ts == FV_ERR_NOMEM) st = fv_error_set(err, ts, "scene '%s': %s", path, e2.msg);
            else if (ts != FV_OK) fv_log_warn(log, "%s: %s; its materials use their constant colour", path, e2.msg);
        } else if (tag == REC_MATERIAL) {
            fv_material m;
            if (!fv_sandbox_read(box, &m, sizeof m)) break;
            m.albedo_texture = m.albedo_texture >= 1 && m.albedo_texture <= ntex ? texmap[m.albedo_texture - 1] : 0;
            m.emission_texture = m.emission_texture >= 1 && m.emission_texture <= ntex ? texmap[m.emission_texture - 1] : 0;
            char name[FV_NAME_MAX];
            m.name[FV_NAME_MAX - 1] = '\0';
            snprintf(name, sizeof name, "%.31s%.32s", opts->prefix, m.name);
            snprintf(m.name, sizeof m.name, "%s", name);
            if (fv_grow((void **)&matmap, &cap, nmat + 1, sizeof *matmap)) st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            else if ((st = fv_scene_add_material(scene, &m, &matmap[nmat++], err)) != FV_OK) fv_error_prefix(err, "scene '%s': ", path);
        } else if (tag == REC_MESH) {
            mesh_head h;
            if (!fv_sandbox_read(box, &h, sizeof h)) break;
            h.name[FV_NAME_MAX - 1] = '\0';
            if (h.nv < 1 || h.nt < 1 || h.nt > INT_MAX / 3) break; /* not what the child sends: treat as a failed child */
            fv_vec3 *pos = fv_alloc_array((size_t)h.nv, sizeof *pos), *nrm = h.has_normals ? fv_alloc_array((size_t)h.nv, sizeof *nrm) : NULL;
            fv_vec2 *uv = h.has_uvs ? fv_alloc_array((size_t)h.nv, sizeof *uv) : NULL;
            uint32_t *idx = fv_alloc_array((size_t)h.nt, 3 * sizeof *idx);
            bool alloc = pos && idx && (!h.has_normals || nrm) && (!h.has_uvs || uv);
            bool got = alloc && fv_sandbox_read(box, pos, (size_t)h.nv * sizeof *pos) &&
                       (!nrm || fv_sandbox_read(box, nrm, (size_t)h.nv * sizeof *nrm)) &&
                       (!uv || fv_sandbox_read(box, uv, (size_t)h.nv * sizeof *uv)) && fv_sandbox_read(box, idx, (size_t)h.nt * 3 * sizeof *idx);
            if (got) {
                int mat = opts->material_override;
                if (mat < 0) mat = h.material >= 0 && h.material < nmat ? matmap[h.material] : -1;
                char name[FV_NAME_MAX];
                snprintf(name, sizeof name, "%.31s%.32s", opts->prefix, h.name);
                fv_mesh_desc d = {name, pos, h.nv, nrm, idx, h.nt, NULL, mat, uv};
                int id, dropped = 0;
                if (mat < 0) {
                    st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': mesh '%s' uses material %d, which the file does not define", path,
                                      name, h.material);
                } else if ((st = fv_scene_add_mesh_counted(scene, &d, &dropped, &id, err)) == FV_OK) {
                    if (count++ == 0) first = id;
                    drop_add(&drops, name, dropped, h.nt);
                } else if (strstr(err->msg, "no valid triangles")) {
                    /* A sub-mesh made only of degenerate or non-finite triangles is dropped like its triangles. */
                    drop_add(&drops, name, h.nt, h.nt);
                    fv_error_clear(err);
                    st = FV_OK;
                } else {
                    fv_error_prefix(err, "scene '%s': ", path);
                }
            } else if (!alloc) {
                st = fv_error_set(err, FV_ERR_NOMEM, "scene '%s': out of memory for a mesh of %d vertices", path, h.nv);
            }
            free(pos);
            free(nrm);
            free(uv);
            free(idx);
            if (!got && st == FV_OK) break;
        } else if (tag == REC_CAMERA) {
            camera_rec r;
            if (!fv_sandbox_read(box, &r, sizeof r)) break;
            r.name[sizeof r.name - 1] = '\0';
            fv_camera_basis b;
            fv_error e2;
            if (view && fv_camera_basis_make(&r.c, &b, &e2) == FV_OK) {
                fv_view_set_camera(view, &r.c);
                snprintf(camera, sizeof camera, "%s", r.name);
                ncameras++;
            }
            else if (view) fv_log_warn(log, "%s: ignoring camera '%s' (%s)", path, r.name, e2.msg);
        } else if (tag == REC_LIGHT) {
            light_rec r;
            if (!fv_sandbox_read(box, &r, sizeof r)) break;
            r.name[sizeof r.name - 1] = '\0';
            fv_error e2;
            if (fv_scene_add_light(scene, &r.d, &e2) != FV_OK) fv_log_warn(log, "%s: ignoring light '%s': %s", path, r.name, e2.msg);
        } else if (tag == REC_WARN || tag == REC_ERROR) {
            int n;
            char msg[FV_ERROR_MSG_MAX];
            if (!fv_sandbox_read(box, &n, sizeof n) || n < 0 || n >= (int)sizeof msg || !fv_sandbox_read(box, msg, (size_t)n)) break;
            msg[n] = '\0';
            /* Our messages are one line (status.c escapes control bytes); drop assimp's trailing ones. */
            while (n > 0 && (msg[n - 1] == '\n' || msg[n - 1] == '\r' || msg[n - 1] == ' ')) msg[--n] = '\0';
            if (tag == REC_WARN) fv_log_warn(log, "%s: %s", path, msg);
            else {
                /* assimp names neither the file nor the line of a bad number in a material
                 * library: find it, so that the message points at the .mtl, not the .obj */
                char where[FV_ERROR_MSG_MAX];
                if (fv_mtl_find_fault(path, where, sizeof where)) st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': %s", path, where);
                else st = fv_error_set(err, FV_ERR_INVALID, "scene '%s': %s", path, msg);
            }
        } else if (tag == REC_END) {
            ended = true;
        } else {
            break;
        }
    }
    if (ncameras > 0)
        fv_log_warn(log, "%s: the view is the file's camera '%s'%s (--frame-view replaces it; --camera-pos, --camera-look, --camera-up and "
                    "--fov override its fields)", path,
                    camera, ncameras > 1 ? ", the last of its cameras" : "");
    if (drops.meshes > 0)
        fv_log_warn(log,
                    "%s: dropped %lld of %lld triangles in %d mesh%s (degenerate, non-finite, beyond +-%g or bad index); the most in '%s' "
                    "(%d)",
                    path, drops.tris, drops.of, drops.meshes, drops.meshes == 1 ? "" : "es", FV_COORD_MAX, drops.worst, drops.worst_n);
    fv_error e2;
    char what[4200];
    snprintf(what, sizeof what, "scene '%s': the mesh importer (assimp)", path);
    fv_status fin = fv_sandbox_finish(box, what, &e2);
    free(matmap);
    free(texmap);
    if (st != FV_OK) return st;
    if (!ended) return fin != FV_OK ? fv_error_set(err, fin, "%s", e2.msg) : fv_error_set(err, FV_ERR_INVALID, "%s: stopped early", what);
    if (count == 0) return fv_error_set(err, FV_ERR_INVALID, "scene '%s': no usable triangles in the file", path);
    if (first_object) *first_object = first;
    if (object_count) *object_count = count;
    return FV_OK;
}
