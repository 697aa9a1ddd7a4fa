/* fovea — the CUDA simulator (docs/gpu.md, "The CUDA simulator"): the part of the CUDA runtime API
 * that the .cu files of device/cuda use, implemented on the host, so that a build without nvcc
 * compiles those very files as C++ and the tests execute their host orchestration (allocations,
 * copies, launches and their order, streams, events, the host's waits, readback, counters) and
 * their kernels on the CPU. Only the simulator build (CMake FOVEA_CUDA_SIM: the test-only library fovea_sim) puts this
 * folder first on the include path; nvcc never sees it, and the shipped library does not contain it.
 *
 * What it checks, aborting with a line that names the call site: a cudaFree of a pointer that is
 * not a device allocation, a copy or memset whose device range is not inside one allocation (or
 * whose host side lies in device memory), an unknown or destroyed stream or event, threads of a
 * block that reach __syncthreads a different number of times, __syncthreads in a launch marked
 * barrier-free (FV_CUDA_LAUNCH_NO_BARRIER), a launch from inside a kernel, and
 * at exit any device allocation, stream or event never freed. A launch of an impossible shape sets
 * cudaErrorInvalidConfiguration for cudaGetLastError, and any call that fails (a cudaMalloc out of
 * memory included) leaves its error there too, as CUDA does. Device memory is host memory
 * (malloc, filled with 0xff bytes as CUDA does not clear it), so AddressSanitizer sees a kernel's
 * out-of-bounds access.
 *
 * Execution: a launch runs at once and to completion (one device, in-order streams): block after
 * block (first to last, then last to first on the kernel's next launch: CUDA promises no order).
 * A launch marked barrier-free (FV_CUDA_LAUNCH_NO_BARRIER: every declared kernel's) runs a block's
 * threads one after another on the calling thread, as nothing makes one wait for another; any
 * other runs them concurrently on a pool of OS threads, __syncthreads a barrier among them (far
 * dearer: a context switch per thread and block). __shared__ variables are function statics, which
 * is right because one block runs at a time.
 * Host waits are counted as CUDA makes the host wait (its "API synchronization behavior"): a
 * synchronize or a cudaFree that comes after work was queued (a launch, an async copy or memset) is
 * one wait of the host for the device (a cudaEventSynchronize only when work queued before its
 * event was not waited for, and work queued after the event stays queued); so is every synchronous cudaMemcpy, and every copy, async or
 * not, between the device and pageable host memory (host memory not from cudaHostAlloc or
 * cudaHostRegister), which CUDA stages through a pinned buffer while the host waits. An async copy
 * to or from pinned memory is queued like a kernel. Bytes each way, allocations and frees, and per
 * kernel the SIMT efficiency of its warps (kernel/ksimt.h) are counted too (tests/cuda_sim/
 * fv_cuda_sim.h reads the counts). With FOVEA_CUDA_SIM_CALLS_ONLY=1 in the environment launches are
 * counted but run nothing: the host's calls at a size whose kernels the simulator could not run in
 * time (test_gpu_counts' FOVEA_GPU_FIGURES).
 */
#ifndef FV_CUDA_SIM_RUNTIME_H
#define FV_CUDA_SIM_RUNTIME_H

#ifndef __cplusplus
#error "the CUDA simulator's runtime is C++: the .cu files are compiled as C++"
#endif

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmath>

#define FV_CUDA_SIM 1

/* ---- types ---- */

/* The error codes the simulator returns (their values are CUDA's). */
typedef enum cudaError {
    cudaSuccess = 0,
    cudaErrorInvalidValue = 1,
    cudaErrorMemoryAllocation = 2,
    cudaErrorInvalidConfiguration = 9,
    cudaErrorInvalidDevice = 101,
    cudaErrorInvalidResourceHandle = 400,
    cudaErrorNotReady = 600
} cudaError_t;

/* What cudaPointerGetAttributes says a pointer is (CUDA's values): host memory that is neither
 * pinned (cudaHostAlloc) nor registered (cudaHostRegister) is "unregistered", pageable. */
enum cudaMemoryType { cudaMemoryTypeUnregistered = 0, cudaMemoryTypeHost = 1, cudaMemoryTypeDevice = 2, cudaMemoryTypeManaged = 3 };

struct cudaPointerAttributes {
    cudaMemoryType type;
    int device;
    void *devicePointer;
    void *hostPointer;
};

#define cudaHostAllocDefault 0u
#define cudaHostRegisterDefault 0u

enum cudaMemcpyKind {
    cudaMemcpyHostToHost = 0,
    cudaMemcpyHostToDevice = 1,
    cudaMemcpyDeviceToHost = 2,
    cudaMemcpyDeviceToDevice = 3,
    cudaMemcpyDefault = 4
};

struct uint3 {
    unsigned x, y, z;
};

struct dim3 {
    unsigned x, y, z;
    constexpr dim3(unsigned vx = 1, unsigned vy = 1, unsigned vz = 1) : x(vx), y(vy), z(vz) {}
};

typedef struct fv_cuda_sim_stream *cudaStream_t;
typedef struct fv_cuda_sim_event *cudaEvent_t;

/* The fields of CUDA's cudaDeviceProp that a caller may read here. */
struct cudaDeviceProp {
    char name[256];
    size_t totalGlobalMem;
    size_t sharedMemPerBlock;
    int warpSize;
    int maxThreadsPerBlock;
    int maxThreadsDim[3];
    int maxGridSize[3];
    int multiProcessorCount;
    int major, minor;
};

/* ---- kernel code ---- */

#define __global__
#define __device__
#define __host__
#define __forceinline__ inline
#define __grid_constant__
/* One block runs at a time (in either way of running a launch), so a function static is the
 * block's shared memory. */
#define __shared__ static

/* Set for each simulated thread before it runs the kernel (thread-local; functions, since GCC's
 * UBSan misreads an extern thread_local object of another translation unit as a null pointer). */
const uint3 &fv_cuda_sim_thread_idx(void);
const uint3 &fv_cuda_sim_block_idx(void);
const dim3 &fv_cuda_sim_block_dim(void);
const dim3 &fv_cuda_sim_grid_dim(void);
#define threadIdx (fv_cuda_sim_thread_idx())
#define blockIdx (fv_cuda_sim_block_idx())
#define blockDim (fv_cuda_sim_block_dim())
#define gridDim (fv_cuda_sim_grid_dim())

void fv_cuda_sim_syncthreads(void);
#define __syncthreads() fv_cuda_sim_syncthreads()

/* Atomics: the overloads CUDA has for the types our kernels use. */
inline int atomicAdd(int *p, int v) { return __atomic_fetch_add(p, v, __ATOMIC_RELAXED); }
inline unsigned atomicAdd(unsigned *p, unsigned v) { return __atomic_fetch_add(p, v, __ATOMIC_RELAXED); }
inline unsigned long long atomicAdd(unsigned long long *p, unsigned long long v) { return __atomic_fetch_add(p, v, __ATOMIC_RELAXED); }
inline float atomicAdd(float *p, float v)
{
    float old, sum;
    __atomic_load(p, &old, __ATOMIC_RELAXED);
    do sum = old + v;
    while (!__atomic_compare_exchange(p, &old, &sum, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED));
    return old;
}

template <class T> inline T fv_cuda_sim_atomic_pick(T *p, T v, bool want_max)
{
    T old = __atomic_load_n(p, __ATOMIC_RELAXED);
    while ((want_max ? v > old : v < old) && !__atomic_compare_exchange_n(p, &old, v, true, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
    }
    return old;
}
inline int atomicMax(int *p, int v) { return fv_cuda_sim_atomic_pick(p, v, true); }
inline unsigned atomicMax(unsigned *p, unsigned v) { return fv_cuda_sim_atomic_pick(p, v, true); }
inline unsigned long long atomicMax(unsigned long long *p, unsigned long long v) { return fv_cuda_sim_atomic_pick(p, v, true); }
inline int atomicMin(int *p, int v) { return fv_cuda_sim_atomic_pick(p, v, false); }
inline unsigned atomicMin(unsigned *p, unsigned v) { return fv_cuda_sim_atomic_pick(p, v, false); }
inline unsigned long long atomicMin(unsigned long long *p, unsigned long long v) { return fv_cuda_sim_atomic_pick(p, v, false); }

inline unsigned __float_as_uint(float f)
{
    unsigned u;
    memcpy(&u, &f, sizeof u);
    return u;
}
inline float __uint_as_float(unsigned u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}
inline int __float_as_int(float f) { return (int)__float_as_uint(f); }
inline float __int_as_float(int i) { return __uint_as_float((unsigned)i); }

/* ---- host API ---- */

cudaError_t cudaGetDeviceCount(int *count);
cudaError_t cudaGetDeviceProperties(cudaDeviceProp *prop, int device);
const char *cudaGetErrorString(cudaError_t e);
cudaError_t cudaGetLastError(void);
cudaError_t cudaPeekAtLastError(void);
cudaError_t cudaDeviceSynchronize(void);

cudaError_t cudaStreamCreate(cudaStream_t *s);
cudaError_t cudaStreamDestroy(cudaStream_t s);
cudaError_t cudaStreamSynchronize(cudaStream_t s);
cudaError_t cudaStreamWaitEvent(cudaStream_t s, cudaEvent_t e, unsigned int flags = 0);

cudaError_t cudaEventCreate(cudaEvent_t *e);
cudaError_t cudaEventDestroy(cudaEvent_t e);
cudaError_t cudaEventRecord(cudaEvent_t e, cudaStream_t s = 0);
cudaError_t cudaEventSynchronize(cudaEvent_t e);
cudaError_t cudaEventElapsedTime(float *ms, cudaEvent_t start, cudaEvent_t end);

cudaError_t cudaPointerGetAttributes(cudaPointerAttributes *attr, const void *p);

/* Memory calls carry their call site into the simulator's messages. Pinned host memory (cudaHostAlloc,
 * cudaMallocHost, cudaHostRegister) is host memory the simulator remembers as pinned: a copy between
 * it and the device is queued like a kernel; a copy between the device and any other host memory
 * (pageable) blocks the host until it is done, as CUDA stages it through a pinned buffer of its own. */
cudaError_t fv_cuda_sim_host_alloc(void **p, size_t bytes, unsigned flags, const char *file, int line);
cudaError_t fv_cuda_sim_host_free(void *p, const char *file, int line);
cudaError_t fv_cuda_sim_host_register(void *p, size_t bytes, unsigned flags, const char *file, int line);
cudaError_t fv_cuda_sim_host_unregister(void *p, const char *file, int line);
#define cudaHostAlloc(p, bytes, flags) fv_cuda_sim_host_alloc((void **)(p), (bytes), (flags), __FILE__, __LINE__)
#define cudaMallocHost(p, bytes) fv_cuda_sim_host_alloc((void **)(p), (bytes), 0u, __FILE__, __LINE__)
#define cudaFreeHost(p) fv_cuda_sim_host_free((p), __FILE__, __LINE__)
#define cudaHostRegister(p, bytes, flags) fv_cuda_sim_host_register((p), (bytes), (flags), __FILE__, __LINE__)
#define cudaHostUnregister(p) fv_cuda_sim_host_unregister((p), __FILE__, __LINE__)
cudaError_t fv_cuda_sim_malloc(void **p, size_t bytes, const char *file, int line);
cudaError_t fv_cuda_sim_free(void *p, const char *file, int line);
cudaError_t fv_cuda_sim_memcpy(void *dst, const void *src, size_t bytes, cudaMemcpyKind kind, bool async, cudaStream_t s, const char *file,
                               int line);
cudaError_t fv_cuda_sim_memset(void *p, int value, size_t bytes, bool async, cudaStream_t s, const char *file, int line);
#define cudaMalloc(p, bytes) fv_cuda_sim_malloc((p), (bytes), __FILE__, __LINE__)
#define cudaFree(p) fv_cuda_sim_free((p), __FILE__, __LINE__)
#define cudaMemcpy(dst, src, bytes, kind) fv_cuda_sim_memcpy((dst), (src), (bytes), (kind), false, 0, __FILE__, __LINE__)
#define cudaMemcpyAsync(dst, src, bytes, kind, ...) \
    fv_cuda_sim_memcpy((dst), (src), (bytes), (kind), true, fv_cuda_sim_stream_arg(__VA_ARGS__), __FILE__, __LINE__)
#define cudaMemset(p, value, bytes) fv_cuda_sim_memset((p), (value), (bytes), false, 0, __FILE__, __LINE__)
#define cudaMemsetAsync(p, value, bytes, ...) fv_cuda_sim_memset((p), (value), (bytes), true, fv_cuda_sim_stream_arg(__VA_ARGS__), __FILE__, __LINE__)
/* The async calls' stream argument is optional, as in CUDA. */
inline cudaStream_t fv_cuda_sim_stream_arg(cudaStream_t s = 0) { return s; }

/* ---- launches (device/cuda/launch.h's FV_CUDA_LAUNCH) ---- */

namespace fv_cuda_sim {

/* Runs body(ctx) as every thread of every block of grid x block; returns after the last.
 * no_barrier: the launch promises never to reach __syncthreads (FV_CUDA_LAUNCH_NO_BARRIER), so a
 * block's threads run one after another on the calling thread; otherwise each on a thread of the
 * pool, concurrently, with a barrier among them. */
void run(const char *kernel, dim3 grid, dim3 block, cudaStream_t s, const char *file, int line, void (*body)(void *), void *ctx,
         bool no_barrier);

template <class K> struct launcher {
    K *kernel;
    const char *name;
    dim3 grid, block;
    cudaStream_t stream;
    const char *file;
    int line;
    bool no_barrier;
    /* The arguments are evaluated once, by the host, as for a real launch; each simulated thread
     * passes them to the kernel by value, so a kernel that changes a parameter changes its own. */
    template <class... A> void operator()(A &&...args) const
    {
        K *k = kernel;
        auto call = [&] { k(args...); };
        run(name, grid, block, stream, file, line, [](void *c) { (*static_cast<decltype(call) *>(c))(); }, &call, no_barrier);
    }
};

template <class K>
inline launcher<K> launch(K *kernel, const char *name, dim3 grid, dim3 block, cudaStream_t s, const char *file, int line, bool no_barrier = false)
{
    return launcher<K>{kernel, name, grid, block, s, file, line, no_barrier};
}

} // namespace fv_cuda_sim

#endif
