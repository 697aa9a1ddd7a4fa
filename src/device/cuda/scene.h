/* fovea — the flat scene (kernel/scene.h) on the GPU, shared by the backends that trace it (pt.cu,
 * vpolar.cu): copied field by field at create (every array links by index, so no pointer needs
 * fixing beyond the arrays' own), and brought to a later time by re-copying only what time changes
 * (objects' transforms, instances, the top-level BVH, the light table). Host code only; included by
 * .cu files.
 */
#ifndef FV_DEVICE_CUDA_SCENE_H
#define FV_DEVICE_CUDA_SCENE_H

#include <cuda_runtime.h>
#include "device/cuda/common.h"
#include "fovea/status.h"
#include "kernel/scene.h"

typedef struct fv_cuda_scene {
    fv_kscene dev;           /* the scene with device pointers, passed to kernels by value */
    void *owned[32];         /* every device allocation of the scene, freed by fv_cuda_scene_free */
    int nowned;
    fv_ktexture *tex_host;   /* the texture records with device texel pointers, as uploaded */
} fv_cuda_scene;

/* Copies host (host memory) into c (zeroed by the caller). On failure what was allocated stays in c
 * for fv_cuda_scene_free. */
fv_status fv_cuda_scene_upload(fv_cuda_tally *k, fv_cuda_scene *c, const fv_kscene *host, fv_error *err);
/* Brings c to host's time (the same scene exported earlier): nothing when the time is the one
 * copied, else the arrays time changes, queued on stream st (0: the legacy stream). */
fv_status fv_cuda_scene_update(fv_cuda_tally *k, fv_cuda_scene *c, const fv_kscene *host, cudaStream_t st, fv_error *err);
void fv_cuda_scene_free(fv_cuda_tally *k, fv_cuda_scene *c);

#endif
