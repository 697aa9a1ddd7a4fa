/* fovea — the flat scene on the GPU (see device/cuda/scene.h). */
#include <cuda_runtime.h>
#include <stdlib.h>
#include "device/cuda/common.h"
#include "device/cuda/scene.h"

/* A copy of n elements of `bytes` each to the GPU, remembered for free; NULL stays NULL. */
static fv_status upload(fv_cuda_tally *k, fv_cuda_scene *c, const void *src, size_t n, size_t bytes, void **dst, fv_error *err)
{
    *dst = NULL;
    if (!src || n == 0) return FV_OK;
    if (c->nowned == (int)(sizeof c->owned / sizeof c->owned[0]))
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: too many scene arrays");
    cudaError_t e = fv_cuda_alloc(k, dst, n * bytes);
    if (e != cudaSuccess) return e == cudaErrorMemoryAllocation ? fv_error_set(err, FV_ERR_NOMEM, "CUDA: out of GPU memory for the scene")
                                                                : fv_cuda_fail(e, "allocating the scene", err);
    c->owned[c->nowned++] = *dst;
    if ((e = fv_cuda_copy_now(k, *dst, src, n * bytes, cudaMemcpyHostToDevice)) != cudaSuccess) return fv_cuda_fail(e, "copying the scene", err);
    return FV_OK;
}

#define UPLOAD(field, count, type)                                                                      \
    do {                                                                                                \
        void *p_;                                                                                       \
        if ((s = upload(k, c, h->field, (size_t)(count), sizeof(type), &p_, err)) != FV_OK) return s;      \
        c->dev.field = (const type *)p_;                                                                \
    } while (0)

fv_status fv_cuda_scene_upload(fv_cuda_tally *k, fv_cuda_scene *c, const fv_kscene *h, fv_error *err)
{
    fv_status s;
    c->dev = *h;
    UPLOAD(vtx, h->nvtx, fv_vec3);
    UPLOAD(nrm, h->nnrm, fv_vec3);
    UPLOAD(uv, h->nuv, fv_vec2);
    UPLOAD(tri_vtx, h->ntri_vtx, uint32_t);
    UPLOAD(tri_mat, h->ntri, int32_t);
    UPLOAD(tri_light, h->ntri, int32_t);
    UPLOAD(objs, h->nobj, fv_kobject);
    UPLOAD(sdf_ops, h->nsdf_ops, fv_sdf_op);
    UPLOAD(nodes, h->nnodes, fv_knode);
    UPLOAD(ktris, h->nktris, fv_ktri);
    UPLOAD(inst, h->ninst, fv_kinst);
    UPLOAD(tnodes, h->ntnodes, fv_knode);
    UPLOAD(mats, h->nmat, fv_material);
    void *p;
    if ((s = upload(k, c, h->lights.light, (size_t)h->lights.n, sizeof(fv_light), &p, err)) != FV_OK) return s;
    c->dev.lights.light = (const fv_light *)p;
    if ((s = upload(k, c, h->lights.cdf, (size_t)h->lights.n + 1, sizeof(float), &p, err)) != FV_OK) return s;
    c->dev.lights.cdf = (const float *)p;
    if (h->ntex > 0) {
        c->tex_host = (fv_ktexture *)calloc((size_t)h->ntex, sizeof *c->tex_host);
        if (!c->tex_host) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
        for (int i = 0; i < h->ntex; i++) {
            c->tex_host[i] = h->tex[i];
            if ((s = upload(k, c, h->tex[i].rgb, (size_t)h->tex[i].w * (size_t)h->tex[i].h * 3, sizeof(float), &p, err)) != FV_OK) return s;
            c->tex_host[i].rgb = (const float *)p;
        }
        if ((s = upload(k, c, c->tex_host, (size_t)h->ntex, sizeof(fv_ktexture), &p, err)) != FV_OK) return s;
        c->dev.tex = (const fv_ktexture *)p;
        c->dev.lights.tex = c->dev.tex; /* emission textures, read by light samples */
    }
    return FV_OK;
}

/* Re-copies an array whose contents time changes, in place (its size does not change). */
static fv_status refresh(fv_cuda_tally *k, const void *dst, const void *src, size_t bytes, cudaStream_t st, fv_error *err)
{
    if (!dst || !src || !bytes) return FV_OK;
    cudaError_t e = fv_cuda_copy(k, (void *)dst, src, bytes, cudaMemcpyHostToDevice, st);
    return e == cudaSuccess ? FV_OK : fv_cuda_fail(e, "updating the scene", err);
}

fv_status fv_cuda_scene_update(fv_cuda_tally *k, fv_cuda_scene *c, const fv_kscene *h, cudaStream_t st, fv_error *err)
{
    if (h->nobj != c->dev.nobj || h->ninst != c->dev.ninst || h->ntnodes != c->dev.ntnodes || h->lights.n != c->dev.lights.n)
        return fv_error_set(err, FV_ERR_INTERNAL, "CUDA: the scene's shape changed between frames");
    /* The snapshot changes only with its time (scene/export.c), so a time already copied has
     * nothing new: a still scene is copied once. */
    if (h->time == c->dev.time) return FV_OK;
    fv_status s;
    if ((s = refresh(k, c->dev.objs, h->objs, (size_t)h->nobj * sizeof(fv_kobject), st, err)) != FV_OK) return s;
    if ((s = refresh(k, c->dev.inst, h->inst, (size_t)h->ninst * sizeof(fv_kinst), st, err)) != FV_OK) return s;
    if ((s = refresh(k, c->dev.tnodes, h->tnodes, (size_t)h->ntnodes * sizeof(fv_knode), st, err)) != FV_OK) return s;
    if ((s = refresh(k, c->dev.lights.light, h->lights.light, (size_t)h->lights.n * sizeof(fv_light), st, err)) != FV_OK) return s;
    c->dev.time = h->time;
    return FV_OK;
}

void fv_cuda_scene_free(fv_cuda_tally *k, fv_cuda_scene *c)
{
    for (int i = 0; i < c->nowned; i++) fv_cuda_release(k, c->owned[i]);
    free(c->tex_host);
    c->nowned = 0;
    c->tex_host = NULL;
}
