/* fovea — the CUDA implementation of the device backend as device/backend.c calls it: plain C
 * declarations, no CUDA header. device/cuda/backend.cu implements them with nvcc (or, in the CUDA
 * simulator's test library, as C++ over tests/cuda_sim); in a build without CUDA, device/
 * cuda_none.c answers "built without CUDA". Nothing else includes this header: families reach the
 * GPU only through device/backend.h.
 */
#ifndef FV_DEVICE_CUDA_BACKEND_API_H
#define FV_DEVICE_CUDA_BACKEND_API_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "device/backend.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_cuda_backend fv_cuda_backend;

enum fv_cuda_copy_kind { FV_CUDA_H2D, FV_CUDA_D2H, FV_CUDA_D2D };

bool fv_cuda_backend_probe(char *why, size_t why_len);
fv_status fv_cuda_backend_create(fv_cuda_backend **out, fv_error *err);
void fv_cuda_backend_destroy(fv_cuda_backend *c);
void fv_cuda_backend_calls(const fv_cuda_backend *c, fv_backend_calls *out);
fv_status fv_cuda_backend_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err);
void fv_cuda_backend_free(fv_cuda_backend *c, void *p);
fv_status fv_cuda_backend_host_alloc(fv_cuda_backend *c, void **p, size_t bytes, const char *what, fv_error *err);
void fv_cuda_backend_host_free(fv_cuda_backend *c, void *p);
fv_status fv_cuda_backend_copy(fv_cuda_backend *c, void *dst, const void *src, size_t bytes, enum fv_cuda_copy_kind kind, const char *what,
                               fv_error *err);
fv_status fv_cuda_backend_clear(fv_cuda_backend *c, void *p, int byte, size_t bytes, const char *what, fv_error *err);
fv_status fv_cuda_backend_launch(fv_cuda_backend *c, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts, fv_error *err);
void fv_cuda_backend_mark(fv_cuda_backend *c, int slot);
double fv_cuda_backend_elapsed_ms(fv_cuda_backend *c, int from, int to);
void fv_cuda_backend_fence(fv_cuda_backend *c, int slot);
fv_status fv_cuda_backend_wait_fence(fv_cuda_backend *c, int slot, const char *what, fv_error *err);
fv_status fv_cuda_backend_wait(fv_cuda_backend *c, const char *what, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
