/* fovea — a kernel declared once (docs/architecture.md, "Devices"). A family lists its kernels in
 * one X-macro table, each entry
 *
 *     K(name, args_type, item_fn, dims, ncounts)
 *
 * where item_fn is an FV_HD function `void item_fn(const args_type *a, int x, int y, uint64_t *c)`
 * that does item (x, y) of a w x h launch (y is 0 for dims 1) and adds to its ncounts counters c[i]
 * (0 .. FV_KERNEL_MAX_COUNTS; the launch sums them over all items). From that one entry come:
 *
 *   - in the family's header, FV_KERNEL_EXTERN: `extern const fv_kernel name;`, what a frame passes
 *     to fv_backend_launch (device/backend.h);
 *   - in the family's .c file, FV_KERNEL_DEFINE: the portable tile function (the items of a tile,
 *     row by row) and the descriptor, which points at the CUDA launcher in a build with CUDA;
 *   - in the family's .cu file, FV_KERNEL_CUDA (device/cuda/kernel_cuda.h): the __global__ kernel
 *     (a thread an item, 8 x 8 blocks for dims 2, 256 threads for dims 1; a thread's counters added
 *     to the launch's with one atomic each) and its launcher.
 *
 * So adding a GPU stage to a family is one line in its table and one launch in its frame; there is
 * no hand-written wrapper on either side.
 *
 * The .c files that define descriptors (named *_kernels.c) are compiled once per backend set: in
 * what ships with FOVEA_HAVE_CUDA exactly when the CUDA backend is built, and again for the CUDA
 * simulator's test library with it (CMakeLists.txt, cmake/cuda_sim.cmake), as the launchers exist
 * only where a CUDA backend does.
 */
#ifndef FV_DEVICE_KERNEL_DECL_H
#define FV_DEVICE_KERNEL_DECL_H

#include <stddef.h>
#include <stdint.h>

/* 8: the sphere tracers count seven costs per pass (technique/sdf/sdf_kernels.h) */
#define FV_KERNEL_MAX_COUNTS 8

/* The CUDA side of a kernel (device/cuda/kernel_cuda.h); opaque here. */
typedef struct fv_kernel_cuda fv_kernel_cuda;

/* The items [x0, x1) x [y0, y1) of a launch, their counters added into counts. */
typedef void (*fv_kernel_tile_fn)(const void *args, int x0, int x1, int y0, int y1, uint64_t *counts);

typedef struct fv_kernel {
    const char *name;
    int dims;                   /* 1 or 2 */
    int ncounts;                /* counters its items add to */
    size_t args_size;           /* bytes of its argument struct */
    fv_kernel_tile_fn tile;     /* the portable backend's */
    const fv_kernel_cuda *cuda; /* NULL in a build without a CUDA backend */
} fv_kernel;

#define FV_KERNEL_EXTERN(name, args_t, fn, dims, ncounts) extern const fv_kernel name;

#if defined(FOVEA_HAVE_CUDA)
#define FV_KERNEL_CUDA_DECL_(name) extern const fv_kernel_cuda name##_cuda;
#define FV_KERNEL_CUDA_REF_(name) &name##_cuda
#else
#define FV_KERNEL_CUDA_DECL_(name)
#define FV_KERNEL_CUDA_REF_(name) NULL
#endif

#define FV_KERNEL_DEFINE(name, args_t, fn, dims_, ncounts_)                                                        \
    static void name##_tile(const void *args_, int x0_, int x1_, int y0_, int y1_, uint64_t *counts_)            \
    {                                                                                                             \
        const args_t *a_ = (const args_t *)args_;                                                                 \
        for (int y_ = y0_; y_ < y1_; y_++)                                                                        \
            for (int x_ = x0_; x_ < x1_; x_++) fn(a_, x_, y_, counts_);                                          \
    }                                                                                                             \
    FV_KERNEL_CUDA_DECL_(name)                                                                                    \
    const fv_kernel name = {#name, (dims_), (ncounts_), sizeof(args_t), name##_tile, FV_KERNEL_CUDA_REF_(name)};

#endif
