/* fovea — the CUDA simulator's runtime (see cuda_runtime.h beside this file, docs/gpu.md "The CUDA
 * simulator"): the device's memory table, streams, events, counters, and what runs a launch's
 * blocks: the calling thread, one simulated thread after another, for a launch that promises no
 * __syncthreads (FV_CUDA_LAUNCH_NO_BARRIER); a pool of OS threads, one per simulated thread with a
 * barrier among them, for the others.
 *
 * The simulated device is one per process, as a real CUDA context is: its state lives in one object
 * (device()), created at first use and checked at exit for what was never freed.
 */
#include <limits.h>
#include <linux/futex.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <stdarg.h>
#include <stdio.h>
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>
#include "cuda_runtime.h"
#include "fv_cuda_sim.h"

namespace {
thread_local uint3 t_thread_idx, t_block_idx;
thread_local dim3 t_block_dim, t_grid_dim;
} // namespace

const uint3 &fv_cuda_sim_thread_idx(void) { return t_thread_idx; }
const uint3 &fv_cuda_sim_block_idx(void) { return t_block_idx; }
const dim3 &fv_cuda_sim_block_dim(void) { return t_block_dim; }
const dim3 &fv_cuda_sim_grid_dim(void) { return t_grid_dim; }

struct fv_cuda_sim_stream {
    int unused;
};

struct fv_cuda_sim_event {
    bool recorded;
    uint64_t at; /* the device's queued-work number when it was recorded */
    std::chrono::steady_clock::time_point t;
};

namespace {

[[noreturn]] __attribute__((format(printf, 3, 4))) void die(const char *file, int line, const char *fmt, ...)
{
    if (file) fprintf(stderr, "fovea CUDA simulator: %s:%d: ", file, line);
    else fprintf(stderr, "fovea CUDA simulator: ");
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    fflush(stderr);
    abort();
}

/* A barrier whose members may leave it: a thread whose kernel has returned takes no further part
 * in its block's __syncthreads (as on the GPU), so the others do not wait for it. One atomic word
 * holds the members (high half) and the arrivals (low half), and the waiters sleep on the phase
 * with a futex, so that a crossing wakes each thread once and no lock is contended (a block's
 * threads cross a barrier several times: this is most of the simulator's cost). */
class Barrier {
    std::atomic<uint64_t> state{0};
    std::atomic<uint32_t> phase{0};

    void release(uint64_t s)
    {
        state.store(s & ~(uint64_t)0xffffffffu, std::memory_order_relaxed);
        phase.fetch_add(1, std::memory_order_release);
        syscall(SYS_futex, reinterpret_cast<uint32_t *>(&phase), FUTEX_WAKE_PRIVATE, INT_MAX, nullptr, nullptr, 0);
    }

public:
    /* Only while no thread is inside. */
    void reset(unsigned n) { state.store((uint64_t)n << 32, std::memory_order_relaxed); }
    /* Waits for the others; the last to arrive runs complete() first, while the rest still wait. */
    template <class F> void wait(F &&complete)
    {
        const uint32_t p = phase.load(std::memory_order_acquire);
        const uint64_t s = state.fetch_add(1, std::memory_order_acq_rel) + 1;
        if ((uint32_t)s == (uint32_t)(s >> 32)) {
            complete();
            release(s);
            return;
        }
        while (phase.load(std::memory_order_acquire) == p)
            syscall(SYS_futex, reinterpret_cast<uint32_t *>(&phase), FUTEX_WAIT_PRIVATE, p, nullptr, nullptr, 0);
    }
    void leave()
    {
        const uint64_t s = state.fetch_sub((uint64_t)1 << 32, std::memory_order_acq_rel) - ((uint64_t)1 << 32);
        if ((uint32_t)s > 0 && (uint32_t)s == (uint32_t)(s >> 32)) release(s);
    }
};

struct Job {
    const char *kernel, *file;
    int line;
    dim3 grid, block;
    unsigned threads; /* of a block */
    void (*body)(void *);
    void *ctx;
    bool reverse;     /* the blocks last to first */
};

class Pool;
thread_local Pool *t_pool;  /* set on the pool's threads: they are running a kernel */
thread_local const Job *t_serial; /* set on a thread running a barrier-free launch's threads in turn */
thread_local unsigned t_id; /* the thread's index in its block */
typedef std::array<uint64_t, FV_SIMT_KINDS> Steps;
thread_local Steps t_steps; /* kernel/ksimt.h: this thread's iterations in its current block */

/* A launch's SIMT sums (fv_cuda_sim_simt without the name). */
struct Simt {
    uint64_t warps = 0;
    Steps lane{}, warp{};
    uint64_t lane_total = 0, warp_total = 0;
};

/* The block's threads in warps of 32 by their linear index, as the hardware groups them (the last
 * warp of a block whose size is not a multiple of 32 has idle lanes too): each warp pays for 32
 * lanes times its busiest lane's iterations. lane_steps: each thread's counts in the block. */
void count_warps(Simt &simt, const std::vector<Steps> &lane_steps, unsigned threads)
{
    for (unsigned w0 = 0; w0 < threads; w0 += 32) {
        const unsigned w1 = w0 + 32 < threads ? w0 + 32 : threads;
        Steps most{};
        uint64_t most_total = 0;
        for (unsigned i = w0; i < w1; i++) {
            uint64_t total = 0;
            for (int k = 0; k < FV_SIMT_KINDS; k++) {
                simt.lane[k] += lane_steps[i][k];
                if (lane_steps[i][k] > most[k]) most[k] = lane_steps[i][k];
                total += lane_steps[i][k];
            }
            simt.lane_total += total;
            if (total > most_total) most_total = total;
        }
        for (int k = 0; k < FV_SIMT_KINDS; k++) simt.warp[k] += 32 * most[k];
        simt.warp_total += 32 * most_total;
        simt.warps++;
    }
}

/* A barrier-free launch (FV_CUDA_LAUNCH_NO_BARRIER): with no barrier to meet, a block's threads
 * need not be live at once, so they run one after another on the calling thread, in the blocks'
 * order as the pool's. No thread is woken and none switched to: a pooled launch costs a context
 * switch per simulated thread and block, which was most of the sim tests' time. Each thread's SIMT
 * counts are kept apart as the pool keeps them, so the warps' figures are the same. Returns the
 * blocks it ran, and its SIMT sums in *out. */
unsigned long long run_serial(const Job &j, Simt *out)
{
    std::vector<Steps> lane_steps(j.threads);
    Simt simt;
    unsigned long long blocks = 0;
    t_serial = &j;
    t_block_dim = j.block;
    t_grid_dim = j.grid;
    for (unsigned bz = 0; bz < j.grid.z; bz++)
        for (unsigned by = 0; by < j.grid.y; by++)
            for (unsigned bx = 0; bx < j.grid.x; bx++) {
                if (j.reverse) t_block_idx = uint3{j.grid.x - 1 - bx, j.grid.y - 1 - by, j.grid.z - 1 - bz};
                else t_block_idx = uint3{bx, by, bz};
                for (unsigned id = 0; id < j.threads; id++) {
                    t_thread_idx = uint3{id % j.block.x, id / j.block.x % j.block.y, id / (j.block.x * j.block.y)};
                    t_steps.fill(0);
                    j.body(j.ctx);
                    lane_steps[id] = t_steps;
                }
                count_warps(simt, lane_steps, j.threads);
                blocks++;
            }
    t_serial = nullptr;
    *out = simt;
    return blocks;
}

/* The threads that run a launch that may reach __syncthreads: as many as the largest block so far, each running one thread of
 * every block, the blocks one after another (in the order the launch's Job says). */
class Pool {
    std::mutex m;
    std::condition_variable start_cv, done_cv;
    std::vector<pthread_t> workers;
    unsigned long long generation = 0; /* one a launch: the workers start when it changes */
    const Job *job = nullptr;
    unsigned busy = 0;
    bool quit = false;
    Barrier sync;      /* __syncthreads */
    Barrier block_end; /* every thread of the block has returned */
    std::vector<unsigned> sync_calls; /* per thread of the running block */
    std::vector<Steps> lane_steps;    /* per thread of the running block: its SIMT counts */
    Simt simt;                        /* the running launch's */
    unsigned long long blocks_run = 0;

    struct Start {
        Pool *pool;
        unsigned id;
        unsigned long long seen;
    };

    static void *main_of(void *arg)
    {
        Start st = *static_cast<Start *>(arg);
        delete static_cast<Start *>(arg);
        st.pool->work(st.id, st.seen);
        return nullptr;
    }

    void grow(unsigned n)
    {
        std::lock_guard<std::mutex> l(m);
        while (workers.size() < n) {
            pthread_attr_t attr;
            pthread_attr_init(&attr);
            /* a kernel runs on this stack: as large as a main thread's usual one */
            pthread_attr_setstacksize(&attr, (size_t)8 << 20);
            pthread_t t;
            Start *st = new Start{this, (unsigned)workers.size(), generation};
            int e = pthread_create(&t, &attr, main_of, st);
            pthread_attr_destroy(&attr);
            if (e != 0) die(__FILE__, __LINE__, "cannot start a thread for a block of %u threads", n);
            workers.push_back(t);
        }
    }

    void work(unsigned id, unsigned long long seen)
    {
        for (;;) {
            const Job *j;
            {
                std::unique_lock<std::mutex> l(m);
                start_cv.wait(l, [&] { return quit || generation != seen; });
                if (quit) return;
                seen = generation;
                j = job;
            }
            if (id < j->threads) execute(*j, id);
            std::lock_guard<std::mutex> l(m);
            if (--busy == 0) done_cv.notify_all();
        }
    }

    void execute(const Job &j, unsigned id)
    {
        t_pool = this;
        t_id = id;
        t_block_dim = j.block;
        t_grid_dim = j.grid;
        t_thread_idx = uint3{id % j.block.x, id / j.block.x % j.block.y, id / (j.block.x * j.block.y)};
        for (unsigned bz = 0; bz < j.grid.z; bz++)
            for (unsigned by = 0; by < j.grid.y; by++)
                for (unsigned bx = 0; bx < j.grid.x; bx++) {
                    if (j.reverse)
                        t_block_idx = uint3{j.grid.x - 1 - bx, j.grid.y - 1 - by, j.grid.z - 1 - bz};
                    else
                        t_block_idx = uint3{bx, by, bz};
                    t_steps.fill(0);
                    j.body(j.ctx);
                    lane_steps[id] = t_steps; /* read by end_block, after the barrier below */
                    sync.leave();
                    block_end.wait([&] { end_block(j); });
                }
        t_pool = nullptr;
    }

    /* Run by the block's last thread to return, before any thread starts the next block. */
    void end_block(const Job &j)
    {
        for (unsigned i = 1; i < j.threads; i++)
            if (sync_calls[i] != sync_calls[0])
                die(j.file, j.line,
                    "kernel %s, block (%u, %u, %u): thread %u reached __syncthreads %u times, thread 0 %u times (CUDA leaves this "
                    "undefined)",
                    j.kernel, t_block_idx.x, t_block_idx.y, t_block_idx.z, i, sync_calls[i], sync_calls[0]);
        sync_calls.assign(j.threads, 0);
        sync.reset(j.threads);
        count_warps(simt, lane_steps, j.threads);
        blocks_run++;
    }

public:
    ~Pool()
    {
        {
            std::lock_guard<std::mutex> l(m);
            quit = true;
            start_cv.notify_all();
        }
        for (pthread_t t : workers) pthread_join(t, nullptr);
    }

    /* Runs j to completion; returns the blocks it ran, and its SIMT sums in *out. */
    unsigned long long run(const Job &j, Simt *out)
    {
        grow(j.threads);
        sync.reset(j.threads);
        block_end.reset(j.threads);
        sync_calls.assign(j.threads, 0);
        lane_steps.assign(j.threads, Steps{});
        simt = Simt();
        const unsigned long long before = blocks_run;
        std::unique_lock<std::mutex> l(m);
        job = &j;
        busy = (unsigned)workers.size();
        generation++;
        start_cv.notify_all();
        done_cv.wait(l, [&] { return busy == 0; });
        job = nullptr;
        *out = simt;
        return blocks_run - before;
    }

    void syncthreads()
    {
        sync_calls[t_id]++;
        sync.wait([] {});
    }
};

struct Allocation {
    size_t bytes;
    const char *file;
    int line;
};

/* The simulated device. */
class Device {
public:
    std::mutex m;          /* everything below but the pool */
    std::mutex launch_m;   /* one launch at a time: a kernel's __shared__ statics are its block's */
    std::map<uintptr_t, Allocation> allocs; /* by base address */
    std::map<uintptr_t, Allocation> pinned; /* pinned or registered host ranges, by base address */
    std::set<uintptr_t> pinned_owned;       /* those cudaHostAlloc made (cudaFreeHost frees them) */
    std::map<std::string, fv_cuda_sim_simt> simt; /* by kernel name */
    std::set<const fv_cuda_sim_stream *> streams;
    std::set<const fv_cuda_sim_event *> events;
    cudaError_t last = cudaSuccess; /* for cudaGetLastError: set by every call that fails, as CUDA's */
    std::map<std::string, unsigned long long> launches_of; /* by kernel name: odd ones run their blocks reversed */
    bool queued = false;            /* work was queued since the host last waited */
    uint64_t seq = 0, waited = 0;   /* work queued so far (numbered), and up to where the host waited */
    std::set<cudaStream_t> launched; /* streams a kernel was launched on since the host last waited */
    int64_t fail_in = -1;           /* fv_cuda_sim_fail_allocation */
    /* FOVEA_CUDA_SIM_CALLS_ONLY=1: launches are checked and counted but run nothing, so the host's
     * calls of a frame can be counted at a size whose kernels would take the simulator hours (the
     * headset's 1440x1600); what the kernels would have written is left as it was. */
    const bool calls_only = getenv("FOVEA_CUDA_SIM_CALLS_ONLY") && *getenv("FOVEA_CUDA_SIM_CALLS_ONLY") == '1';
    fv_cuda_sim_counts counts = {};
    Pool pool;

    ~Device()
    {
        if (allocs.empty() && streams.empty() && events.empty() && pinned.empty()) return;
        for (const auto &a : allocs)
            fprintf(stderr, "fovea CUDA simulator: %s:%d: %zu bytes of device memory allocated here were never freed\n", a.second.file,
                    a.second.line, a.second.bytes);
        for (const auto &a : pinned)
            fprintf(stderr, "fovea CUDA simulator: %s:%d: %zu bytes of host memory pinned here were never freed or unregistered\n",
                    a.second.file, a.second.line, a.second.bytes);
        if (!streams.empty()) fprintf(stderr, "fovea CUDA simulator: %zu streams were never destroyed\n", streams.size());
        if (!events.empty()) fprintf(stderr, "fovea CUDA simulator: %zu events were never destroyed\n", events.size());
        fflush(stderr);
        abort();
    }

    /* The range of table t holding address p, or null. */
    static const std::pair<const uintptr_t, Allocation> *find_in(const std::map<uintptr_t, Allocation> &t, const void *p)
    {
        const uintptr_t a = (uintptr_t)p;
        auto it = t.upper_bound(a);
        if (it == t.begin()) return nullptr;
        --it;
        return a < it->first + it->second.bytes ? &*it : nullptr;
    }
    /* The device allocation holding address p, or null. */
    const std::pair<const uintptr_t, Allocation> *find(const void *p) const { return find_in(allocs, p); }
    /* Whether [p, p + bytes) lies in one pinned or registered host range. */
    bool is_pinned(const void *p, size_t bytes) const
    {
        const auto *a = find_in(pinned, p);
        return a && (uintptr_t)p + bytes <= a->first + a->second.bytes;
    }

    /* Checks that [p, p + bytes) lies inside one device allocation. */
    void check_range(const void *p, size_t bytes, const char *what, const char *file, int line) const
    {
        const auto *a = find(p);
        if (!a) die(file, line, "%s: %p is not in device memory", what, p);
        if ((uintptr_t)p + bytes > a->first + a->second.bytes)
            die(file, line, "%s: %zu bytes from offset %zu run past the end of the %zu-byte allocation made at %s:%d", what, bytes,
                (size_t)((uintptr_t)p - a->first), a->second.bytes, a->second.file, a->second.line);
    }

    void check_stream(cudaStream_t s, const char *what, const char *file, int line) const
    {
        if (s && !streams.count(s)) die(file, line, "%s: stream %p was not created or is destroyed", what, (void *)s);
    }

    void check_event(cudaEvent_t e, const char *what) const
    {
        if (!e || !events.count(e)) die(nullptr, 0, "%s: event %p was not created or is destroyed", what, (void *)e);
    }

    /* A call's error, kept for cudaGetLastError as CUDA keeps it (a failed cudaMalloc included):
     * a backend that checks cudaGetLastError after its launches sees what an earlier failure left
     * unless it cleared it. Called with m held. */
    cudaError_t fail(cudaError_t e)
    {
        last = e;
        return e;
    }

    /* The host waits here for what was queued, if anything was; with `always`, for the call's own
     * transfer too (a copy that blocks), so it is a wait even with nothing queued. */
    void host_wait(bool always = false)
    {
        if (queued || always) counts.host_waits++;
        queued = false;
        waited = seq;
        launched.clear();
    }

    void queue()
    {
        queued = true;
        seq++;
    }

    /* The host waits for an event: for what was queued before it, if the host had not waited for
     * that yet; what was queued after it stays queued. */
    void event_wait(const fv_cuda_sim_event *e)
    {
        if (e->at > waited) {
            counts.host_waits++;
            waited = e->at;
        }
        if (waited == seq) {
            queued = false;
            launched.clear();
        }
    }
};

Device &device()
{
    static Device d;
    return d;
}

/* Device::fail for a call that does not hold the device's lock. */
cudaError_t fail_unlocked(cudaError_t e)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    return d.fail(e);
}

} // namespace

void fv_cuda_sim_syncthreads(void)
{
    if (t_serial)
        die(t_serial->file, t_serial->line,
            "kernel %s, block (%u, %u, %u), thread (%u, %u, %u): __syncthreads in a launch marked barrier-free "
            "(FV_CUDA_LAUNCH_NO_BARRIER runs a block's threads one after another); launch it with FV_CUDA_LAUNCH",
            t_serial->kernel, t_block_idx.x, t_block_idx.y, t_block_idx.z, t_thread_idx.x, t_thread_idx.y, t_thread_idx.z);
    if (!t_pool) die(nullptr, 0, "__syncthreads called outside a kernel");
    t_pool->syncthreads();
}

void fv_cuda_sim::run(const char *kernel, dim3 grid, dim3 block, cudaStream_t s, const char *file, int line, void (*body)(void *), void *ctx,
                      bool no_barrier)
{
    if (t_pool || t_serial) die(file, line, "kernel %s launched from inside a kernel (dynamic parallelism is not simulated)", kernel);
    Device &d = device();
    bool reverse = false;
    {
        std::lock_guard<std::mutex> l(d.m);
        d.check_stream(s, kernel, file, line);
        const unsigned long long threads = (unsigned long long)block.x * block.y * block.z;
        if (threads == 0 || threads > 1024 || block.x > 1024 || block.y > 1024 || block.z > 64 || grid.x == 0 || grid.y == 0 ||
            grid.z == 0 || grid.x > 2147483647u || grid.y > 65535 || grid.z > 65535) {
            d.last = cudaErrorInvalidConfiguration; /* as CUDA: the launch does not happen, cudaGetLastError says why */
            return;
        }
        d.counts.launches++;
        d.queue();
        d.launched.insert(s);
        /* CUDA runs a launch's blocks in no order: every other launch of a kernel runs them last
         * to first, so a kernel that reads what another block of its launch writes finds it
         * unwritten one way or the other (a race on a GPU), and a test comparing images sees it. */
        reverse = d.launches_of[kernel]++ % 2 == 1;
        if (d.calls_only) return;
    }
    std::lock_guard<std::mutex> one(d.launch_m);
    Job j = {kernel, file, line, grid, block, block.x * block.y * block.z, body, ctx, reverse};
    Simt simt;
    const unsigned long long blocks = no_barrier ? run_serial(j, &simt) : d.pool.run(j, &simt);
    std::lock_guard<std::mutex> l(d.m);
    d.counts.blocks += blocks;
    fv_cuda_sim_simt &r = d.simt[kernel];
    if (!r.kernel[0]) snprintf(r.kernel, sizeof r.kernel, "%s", kernel);
    r.launches++;
    r.threads_per_block = j.threads;
    r.warps += simt.warps;
    for (int k = 0; k < FV_SIMT_KINDS; k++) {
        r.lane_steps[k] += simt.lane[k];
        r.warp_steps[k] += simt.warp[k];
    }
    r.lane_total += simt.lane_total;
    r.warp_total += simt.warp_total;
}

void fv_cuda_sim_simt_step(int kind)
{
    if ((t_pool || t_serial) && kind >= 0 && kind < FV_SIMT_KINDS) t_steps[kind]++;
}

cudaError_t cudaGetDeviceCount(int *count)
{
    if (!count) return fail_unlocked(cudaErrorInvalidValue);
    *count = 1;
    return cudaSuccess;
}

cudaError_t cudaGetDeviceProperties(cudaDeviceProp *prop, int dev)
{
    if (!prop) return fail_unlocked(cudaErrorInvalidValue);
    if (dev != 0) return fail_unlocked(cudaErrorInvalidDevice);
    memset(prop, 0, sizeof *prop);
    snprintf(prop->name, sizeof prop->name, "fovea CUDA simulator");
    /* an H100's shape: compute capability 9.0, the limits the launch checks use */
    prop->totalGlobalMem = (size_t)80 << 30;
    prop->sharedMemPerBlock = 48 << 10;
    prop->warpSize = 32;
    prop->maxThreadsPerBlock = 1024;
    prop->maxThreadsDim[0] = prop->maxThreadsDim[1] = 1024;
    prop->maxThreadsDim[2] = 64;
    prop->maxGridSize[0] = 2147483647;
    prop->maxGridSize[1] = prop->maxGridSize[2] = 65535;
    prop->multiProcessorCount = 132;
    prop->major = 9;
    prop->minor = 0;
    return cudaSuccess;
}

const char *cudaGetErrorString(cudaError_t e)
{
    switch (e) {
    case cudaSuccess: return "no error";
    case cudaErrorInvalidValue: return "invalid argument";
    case cudaErrorMemoryAllocation: return "out of memory";
    case cudaErrorInvalidConfiguration: return "invalid configuration argument";
    case cudaErrorInvalidDevice: return "invalid device ordinal";
    case cudaErrorInvalidResourceHandle: return "invalid resource handle";
    case cudaErrorNotReady: return "device not ready";
    }
    return "unrecognized error code";
}

cudaError_t cudaGetLastError(void)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    cudaError_t e = d.last;
    d.last = cudaSuccess;
    return e;
}

cudaError_t cudaPeekAtLastError(void)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    return d.last;
}

cudaError_t cudaDeviceSynchronize(void)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.counts.syncs++;
    d.host_wait();
    return cudaSuccess;
}

cudaError_t cudaStreamCreate(cudaStream_t *s)
{
    if (!s) return fail_unlocked(cudaErrorInvalidValue);
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    *s = new fv_cuda_sim_stream();
    d.streams.insert(*s);
    return cudaSuccess;
}

cudaError_t cudaStreamDestroy(cudaStream_t s)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (!s || !d.streams.erase(s)) die(nullptr, 0, "cudaStreamDestroy: stream %p was not created or is destroyed", (void *)s);
    delete s;
    return cudaSuccess;
}

cudaError_t cudaStreamSynchronize(cudaStream_t s)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_stream(s, "cudaStreamSynchronize", nullptr, 0);
    d.counts.syncs++;
    d.host_wait();
    return cudaSuccess;
}

cudaError_t cudaStreamWaitEvent(cudaStream_t s, cudaEvent_t e, unsigned int flags)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_stream(s, "cudaStreamWaitEvent", nullptr, 0);
    d.check_event(e, "cudaStreamWaitEvent");
    if (flags != 0) return d.fail(cudaErrorInvalidValue);
    /* the work before the event has run already (launches run when queued): the stream need not
     * wait, and the host does not */
    return cudaSuccess;
}

cudaError_t cudaEventCreate(cudaEvent_t *e)
{
    if (!e) return fail_unlocked(cudaErrorInvalidValue);
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    *e = new fv_cuda_sim_event();
    d.events.insert(*e);
    return cudaSuccess;
}

cudaError_t cudaEventDestroy(cudaEvent_t e)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_event(e, "cudaEventDestroy");
    d.events.erase(e);
    delete e;
    return cudaSuccess;
}

cudaError_t cudaEventRecord(cudaEvent_t e, cudaStream_t s)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_event(e, "cudaEventRecord");
    d.check_stream(s, "cudaEventRecord", nullptr, 0);
    /* the work before it has run already: the host clock now is when the device reaches it */
    e->recorded = true;
    e->at = d.seq;
    e->t = std::chrono::steady_clock::now();
    return cudaSuccess;
}

cudaError_t cudaEventSynchronize(cudaEvent_t e)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_event(e, "cudaEventSynchronize");
    d.counts.syncs++;
    d.event_wait(e);
    return cudaSuccess;
}

cudaError_t cudaEventElapsedTime(float *ms, cudaEvent_t start, cudaEvent_t end)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_event(start, "cudaEventElapsedTime");
    d.check_event(end, "cudaEventElapsedTime");
    if (!ms) return d.fail(cudaErrorInvalidValue);
    if (!start->recorded || !end->recorded) return d.fail(cudaErrorInvalidResourceHandle); /* as CUDA: an event never recorded */
    *ms = std::chrono::duration<float, std::milli>(end->t - start->t).count();
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_malloc(void **p, size_t bytes, const char *file, int line)
{
    if (!p) return fail_unlocked(cudaErrorInvalidValue);
    *p = nullptr;
    if (bytes == 0) return cudaSuccess;
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (d.fail_in >= 0 && d.fail_in-- == 0) {
        d.counts.injected_failures++;
        return d.fail(cudaErrorMemoryAllocation);
    }
    void *q = malloc(bytes);
    if (!q) return d.fail(cudaErrorMemoryAllocation);
    /* CUDA does not clear new memory: NaN floats and all-ones integers make a read before a write show */
    memset(q, 0xff, bytes);
    d.allocs[(uintptr_t)q] = Allocation{bytes, file, line};
    d.counts.allocations++;
    d.counts.live_allocations++;
    d.counts.live_bytes += bytes;
    *p = q;
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_free(void *p, const char *file, int line)
{
    if (!p) return cudaSuccess;
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    auto it = d.allocs.find((uintptr_t)p);
    if (it == d.allocs.end()) {
        const auto *a = d.find(p);
        if (a) die(file, line, "cudaFree of %p, %zu bytes into the allocation made at %s:%d, not its start", p, (size_t)((uintptr_t)p - a->first),
                   a->second.file, a->second.line);
        die(file, line, "cudaFree of %p, which is not device memory (never allocated, or freed already)", p);
    }
    d.counts.frees++;
    d.counts.live_allocations--;
    d.counts.live_bytes -= it->second.bytes;
    d.allocs.erase(it);
    free(p);
    d.host_wait(); /* cudaFree waits for the device */
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_memcpy(void *dst, const void *src, size_t bytes, cudaMemcpyKind kind, bool async, cudaStream_t s, const char *file, int line)
{
    const char *what = async ? "cudaMemcpyAsync" : "cudaMemcpy";
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_stream(s, what, file, line);
    if (bytes == 0) return cudaSuccess;
    if (!dst || !src) return d.fail(cudaErrorInvalidValue);
    bool dst_dev = d.find(dst) != nullptr, src_dev = d.find(src) != nullptr;
    switch (kind) {
    case cudaMemcpyHostToHost: break;
    case cudaMemcpyHostToDevice: dst_dev = true; break;
    case cudaMemcpyDeviceToHost: src_dev = true; break;
    case cudaMemcpyDeviceToDevice: dst_dev = src_dev = true; break;
    case cudaMemcpyDefault: break;
    default: return d.fail(cudaErrorInvalidValue);
    }
    static const char *const kinds[] = {"host to host", "host to device", "device to host", "device to device", "default"};
    if (dst_dev) d.check_range(dst, bytes, what, file, line);
    else if (d.find(dst)) die(file, line, "%s %s: the destination %p is device memory", what, kinds[kind], dst);
    if (src_dev) d.check_range(src, bytes, what, file, line);
    else if (d.find(src)) die(file, line, "%s %s: the source %p is device memory", what, kinds[kind], src);
    if (dst_dev && !src_dev) d.counts.bytes_h2d += bytes;
    if (src_dev && !dst_dev) d.counts.bytes_d2h += bytes;
    /* Between the device and pageable host memory CUDA stages the copy through a pinned buffer of
     * its own, and the host takes part: such a copy, async or not, returns only once its stream's
     * work before it and (device to host) the copy itself are done, or (host to device) the bytes
     * are staged. Either way the host waits, mid-frame if kernels are queued: a wait of its own,
     * even with nothing queued. An upload behind a kernel of its stream (or any, on the legacy
     * stream 0, which waits for the others) is the worst of these: the host waits for the kernel
     * before it can queue the rest of the frame. */
    const bool host_side = src_dev != dst_dev;
    const bool pageable = host_side && !d.is_pinned(src_dev ? dst : src, bytes);
    if (pageable && dst_dev && (s ? d.launched.count(s) || d.launched.count(nullptr) : !d.launched.empty()))
        d.counts.uploads_behind_kernels++;
    memmove(dst, src, bytes);
    if (pageable) {
        d.counts.pageable_copies++;
        d.host_wait(true);
    } else if (async) {
        if (src_dev || dst_dev) d.queue(); /* pinned memory, or device to device: queued like a kernel */
    } else if (src_dev || dst_dev) {
        d.host_wait(true); /* a synchronous copy waits for the work before it and for itself */
    }
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_memset(void *p, int value, size_t bytes, bool async, cudaStream_t s, const char *file, int line)
{
    const char *what = async ? "cudaMemsetAsync" : "cudaMemset";
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.check_stream(s, what, file, line);
    if (bytes == 0) return cudaSuccess;
    d.check_range(p, bytes, what, file, line);
    memset(p, value, bytes);
    d.queue(); /* the host does not wait for a memset of device memory */
    return cudaSuccess;
}

cudaError_t cudaPointerGetAttributes(cudaPointerAttributes *attr, const void *p)
{
    if (!attr) return fail_unlocked(cudaErrorInvalidValue);
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    memset(attr, 0, sizeof *attr);
    if (d.find(p)) {
        attr->type = cudaMemoryTypeDevice;
        attr->devicePointer = const_cast<void *>(p);
    } else if (Device::find_in(d.pinned, p)) {
        attr->type = cudaMemoryTypeHost;
        attr->hostPointer = attr->devicePointer = const_cast<void *>(p); /* mapped, as CUDA's unified addressing has it */
    } else {
        attr->type = cudaMemoryTypeUnregistered; /* as CUDA 11 on: pageable memory is no error */
        attr->device = -2;
    }
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_host_alloc(void **p, size_t bytes, unsigned flags, const char *file, int line)
{
    if (!p) return fail_unlocked(cudaErrorInvalidValue);
    *p = nullptr;
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (flags != 0) return d.fail(cudaErrorInvalidValue); /* the flags fovea would use: none */
    /* pinned memory runs out too (it is page-locked host memory): the same injected failures */
    if (d.fail_in >= 0 && d.fail_in-- == 0) {
        d.counts.injected_failures++;
        return d.fail(cudaErrorMemoryAllocation);
    }
    void *q = malloc(bytes ? bytes : 1);
    if (!q) return d.fail(cudaErrorMemoryAllocation);
    d.pinned[(uintptr_t)q] = Allocation{bytes ? bytes : 1, file, line};
    d.pinned_owned.insert((uintptr_t)q);
    *p = q;
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_host_free(void *p, const char *file, int line)
{
    if (!p) return cudaSuccess;
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (!d.pinned_owned.erase((uintptr_t)p)) die(file, line, "cudaFreeHost of %p, which cudaHostAlloc did not return (or was freed)", p);
    d.pinned.erase((uintptr_t)p);
    free(p);
    d.host_wait(); /* as cudaFree: it waits for the device */
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_host_register(void *p, size_t bytes, unsigned flags, const char *file, int line)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (!p || bytes == 0 || flags != 0) return d.fail(cudaErrorInvalidValue);
    if (d.find(p)) die(file, line, "cudaHostRegister of %p, which is device memory", p);
    const auto *a = Device::find_in(d.pinned, p);
    const auto next = d.pinned.lower_bound((uintptr_t)p);
    if (a || (next != d.pinned.end() && next->first < (uintptr_t)p + bytes))
        die(file, line, "cudaHostRegister of %zu bytes at %p overlaps host memory already pinned", bytes, p);
    d.pinned[(uintptr_t)p] = Allocation{bytes, file, line};
    return cudaSuccess;
}

cudaError_t fv_cuda_sim_host_unregister(void *p, const char *file, int line)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    if (d.pinned_owned.count((uintptr_t)p) || !d.pinned.erase((uintptr_t)p))
        die(file, line, "cudaHostUnregister of %p, which cudaHostRegister did not register", p);
    return cudaSuccess;
}

extern "C" void fv_cuda_sim_counts_get(fv_cuda_sim_counts *out)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    *out = d.counts;
    out->live_streams = d.streams.size();
    out->live_events = d.events.size();
    out->live_pinned = d.pinned.size();
}

extern "C" size_t fv_cuda_sim_simt_get(fv_cuda_sim_simt *out, size_t n)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    size_t i = 0;
    for (const auto &r : d.simt) {
        if (i < n) out[i] = r.second;
        i++;
    }
    return d.simt.size();
}

extern "C" void fv_cuda_sim_simt_reset(void)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.simt.clear();
}

extern "C" void fv_cuda_sim_fail_allocation(int64_t n)
{
    Device &d = device();
    std::lock_guard<std::mutex> l(d.m);
    d.fail_in = n < 0 ? -1 : n;
}
