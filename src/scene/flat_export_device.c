/* fovea — the flat scene on a device backend (scene/flat_export_device.h). */
#include <stdlib.h>
#include <string.h>
#include "scene/flat_export_device.h"

#define MAX_ARRAYS 32

/* The arrays time changes, each a mirror. */
enum { MOV_OBJS, MOV_INST, MOV_TNODES, MOV_LIGHTS, MOV_COUNT };

struct fv_scene_device {
    fv_backend *b;
    bool shared;             /* portable: the view is the host's */
    fv_kscene dev;           /* device pointers */
    fv_buffer owned[MAX_ARRAYS]; /* the arrays that do not change */
    int nowned;
    fv_mirror moving[MOV_COUNT];
    fv_ktexture *tex_host;   /* the texture records with device texel pointers, as copied */
};

/* n elements of `bytes` each, copied to a buffer of their own (NULL stays NULL). These copies come
 * from the export's pageable memory, once, when the scene is made. */
static fv_status upload(fv_scene_device *d, const void *src, size_t n, size_t bytes, const void **dst, fv_error *err)
{
    *dst = NULL;
    if (!src || n == 0) return FV_OK;
    if (d->nowned == MAX_ARRAYS) return fv_error_set(err, FV_ERR_INTERNAL, "device scene: too many arrays");
    fv_buffer *buf = &d->owned[d->nowned++];
    fv_status s = fv_buffer_ensure(d->b, buf, n * bytes, "the scene", err);
    if (s == FV_OK) s = fv_backend_upload(d->b, buf->p, src, n * bytes, "the scene", err);
    *dst = buf->p;
    return s;
}

#define UPLOAD(field, count, type)                                                                           \
    do {                                                                                                     \
        const void *p_;                                                                                      \
        if ((s = upload(d, h->field, (size_t)(count), sizeof(type), &p_, err)) != FV_OK) return s;           \
        d->dev.field = (const type *)p_;                                                                     \
    } while (0)

static fv_status copy_static(fv_scene_device *d, const fv_kscene *h, fv_error *err)
{
    fv_status s;
    const void *p;
    UPLOAD(vtx, h->nvtx, fv_vec3);
    UPLOAD(nrm, h->nnrm, fv_vec3);
    UPLOAD(uv, h->nuv, fv_vec2);
    UPLOAD(tri_vtx, h->ntri_vtx, uint32_t);
    UPLOAD(tri_mat, h->ntri, int32_t);
    UPLOAD(tri_light, h->ntri, int32_t);
    UPLOAD(sdf_ops, h->nsdf_ops, fv_sdf_op);
    UPLOAD(nodes, h->nnodes, fv_knode);
    UPLOAD(ktris, h->nktris, fv_ktri);
    UPLOAD(mats, h->nmat, fv_material);
    if ((s = upload(d, h->lights.cdf, (size_t)h->lights.n + 1, sizeof(float), &p, err)) != FV_OK) return s;
    d->dev.lights.cdf = (const float *)p;
    if (h->ntex > 0) {
        if (!(d->tex_host = calloc((size_t)h->ntex, sizeof *d->tex_host))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int i = 0; i < h->ntex; i++) {
            d->tex_host[i] = h->tex[i];
            if ((s = upload(d, h->tex[i].rgb, (size_t)h->tex[i].w * (size_t)h->tex[i].h * 3, sizeof(float), &p, err)) != FV_OK) return s;
            d->tex_host[i].rgb = (const float *)p;
        }
        if ((s = upload(d, d->tex_host, (size_t)h->ntex, sizeof(fv_ktexture), &p, err)) != FV_OK) return s;
        d->dev.tex = (const fv_ktexture *)p;
        d->dev.lights.tex = d->dev.tex; /* emission textures, read by light samples */
    }
    return FV_OK;
}

/* The arrays time changes, each copied only when its bytes differ from the last copy. */
static fv_status copy_moving(fv_scene_device *d, const fv_kscene *h, fv_error *err)
{
    const struct {
        const void *src;
        size_t bytes;
        const void **dst;
    } mov[MOV_COUNT] = {
        {h->objs, (size_t)h->nobj * sizeof(fv_kobject), (const void **)&d->dev.objs},
        {h->inst, (size_t)h->ninst * sizeof(fv_kinst), (const void **)&d->dev.inst},
        {h->tnodes, (size_t)h->ntnodes * sizeof(fv_knode), (const void **)&d->dev.tnodes},
        {h->lights.light, (size_t)h->lights.n * sizeof(fv_light), (const void **)&d->dev.lights.light},
    };
    for (int i = 0; i < MOV_COUNT; i++) {
        if (!mov[i].src || !mov[i].bytes) {
            *mov[i].dst = NULL;
            continue;
        }
        fv_status s = fv_mirror_fill(d->b, &d->moving[i], mov[i].src, mov[i].bytes, mov[i].dst, "the scene's moving parts", err);
        if (s != FV_OK) return s;
    }
    d->dev.time = h->time;
    return FV_OK;
}

fv_status fv_scene_device_create(fv_backend *b, const fv_kscene *host, fv_scene_device **out, fv_error *err)
{
    *out = NULL;
    fv_scene_device *d = calloc(1, sizeof *d);
    if (!d) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    d->b = b;
    d->dev = *host;
    d->shared = fv_backend_device(b) == FV_DEVICE_PORTABLE;
    fv_status s = d->shared ? FV_OK : copy_static(d, host, err);
    if (s == FV_OK && !d->shared) s = copy_moving(d, host, err);
    if (s != FV_OK) {
        fv_scene_device_destroy(d);
        return s;
    }
    *out = d;
    return FV_OK;
}

fv_status fv_scene_device_update(fv_scene_device *d, const fv_kscene *h, fv_error *err)
{
    if (h->nobj != d->dev.nobj || h->ninst != d->dev.ninst || h->ntnodes != d->dev.ntnodes || h->lights.n != d->dev.lights.n)
        return fv_error_set(err, FV_ERR_INTERNAL, "device scene: the scene's shape changed between frames");
    if (d->shared) {
        d->dev = *h; /* the export's arrays, at its time */
        return FV_OK;
    }
    return copy_moving(d, h, err);
}

const fv_kscene *fv_scene_device_view(const fv_scene_device *d) { return &d->dev; }

void fv_scene_device_destroy(fv_scene_device *d)
{
    if (!d) return;
    for (int i = 0; i < d->nowned; i++) fv_buffer_release(d->b, &d->owned[i]);
    for (int i = 0; i < MOV_COUNT; i++) fv_mirror_release(d->b, &d->moving[i]);
    free(d->tex_host);
    free(d);
}
