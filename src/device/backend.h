/* fovea — the device backend (docs/architecture.md, "Devices"): what a family's frame asks of the
 * machine that runs its kernels, and nothing about any family. A frame is written once over this
 * interface (pbrt-v4's wavefront integrator writes its stages once over ParallelFor the same way):
 *
 *   buffers      device memory that only grows (fv_buffer), pinned host memory for the copies
 *                that must not block (fv_pinned), and tables the host builds that are copied
 *                only when their bytes change (fv_mirror);
 *   copies       upload, download, device to device and clears, queued in order;
 *   launches     of a kernel declared once (device/kernel_decl.h) over w x h items;
 *   marks        timestamps between stages, read after the wait;
 *   fences       points in the queue the host may wait for while what follows them runs;
 *   one wait     for everything queued.
 *
 * Two implementations: `portable` runs each launch at once over tiles on the CPU's threads
 * (core/parallel.h) and its "device" memory is host memory, which is what CI executes; `cuda`
 * (device/cuda/backend.cu) queues everything on one CUDA stream and its waits are the only points
 * where the host waits for the GPU. Both count what they asked of the runtime (fv_backend_calls), so
 * that a frame's host waits, blocking copies and allocations are figures the tests assert.
 *
 * Pointers: a device pointer (fv_buffer.p, fv_mirror.p) is valid on the backend that made it (on
 * portable it is host memory too). Kernels receive device pointers in their argument structs.
 */
#ifndef FV_DEVICE_BACKEND_H
#define FV_DEVICE_BACKEND_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include "device/kernel_decl.h"
#include "fovea/device.h"
#include "fovea/status.h"

typedef struct fv_backend fv_backend;

/* What a backend asked of its runtime, counted by its own calls so that a GPU and the simulator
 * report the same figures. A host wait is a call that holds the host until the device is done: a
 * wait after queued work, a synchronous copy, a free after queued work, and every copy between the
 * device and pageable host memory (CUDA stages it through a pinned buffer of its own while the host
 * waits). The portable backend runs everything at once: its only waits are fv_backend_wait's. */
typedef struct fv_backend_calls {
    uint64_t launches;
    uint64_t syncs;           /* fv_backend_wait calls */
    uint64_t host_waits;
    uint64_t pageable_copies; /* copies between the device and pageable host memory */
    uint64_t bytes_h2d, bytes_d2h;
    uint64_t allocations, frees; /* device memory taken and given back */
} fv_backend_calls;

/* device: FV_DEVICE_PORTABLE or FV_DEVICE_CUDA (FV_ERR_INVALID for another, and for cuda where no
 * usable GPU is or the build has no CUDA: the message says which). */
fv_status fv_backend_create(fv_device device, fv_backend **out, fv_error *err);
/* Waits for what is queued (nothing may outlive the buffers it uses), then frees the backend. Its
 * buffers, pinned memory and mirrors must have been released first. */
void fv_backend_destroy(fv_backend *b);
fv_device fv_backend_device(const fv_backend *b);
/* The CPU threads a portable launch uses (fv_thread_count's rule; 0: all); ignored by cuda. */
void fv_backend_set_threads(fv_backend *b, int threads);
void fv_backend_calls_get(const fv_backend *b, fv_backend_calls *out);
/* after - before, field by field. */
void fv_backend_calls_diff(const fv_backend_calls *after, const fv_backend_calls *before, fv_backend_calls *out);

/* True when a CUDA device can run our kernels; else false with the reason in why (a build without
 * CUDA says so). */
bool fv_backend_cuda_probe(char *why, size_t why_len);

/* ---- memory ---- */

/* Device memory that only grows: p holds at least the bytes asked for, reallocated (contents lost)
 * only when it must grow, so a sequence allocates in its first frame and never after. */
typedef struct fv_buffer {
    void *p;
    size_t cap; /* bytes */
} fv_buffer;
/* what names the buffer in an error line ("out of GPU memory for <what>"). */
fv_status fv_buffer_ensure(fv_backend *b, fv_buffer *buf, size_t bytes, const char *what, fv_error *err);
void fv_buffer_release(fv_backend *b, fv_buffer *buf);

/* Host memory the device copies to and from without blocking (cudaHostAlloc on cuda, plain memory
 * on portable); grows as fv_buffer does. */
fv_status fv_pinned_ensure(fv_backend *b, fv_buffer *buf, size_t bytes, const char *what, fv_error *err);
void fv_pinned_release(fv_backend *b, fv_buffer *buf);

/* A table the host builds (per screen size, per gaze) with its copy on the device, refilled only
 * when the host's bytes differ from what was copied last. The bytes go through one of two pinned
 * buffers in turn, so the copy never blocks and a copy still queued from the frame before is never
 * overwritten: fills alternate, so a stage is refilled two fills later, and with at most two frames
 * in flight (technique/class.h's submit) the frame that last used it has been collected. */
typedef struct fv_mirror {
    fv_buffer dev;
    fv_buffer stage[2]; /* pinned */
    int next;           /* the stage the next fill uses */
    size_t bytes;       /* what dev holds, 0: nothing yet */
    const void *last;   /* the stage holding dev's bytes (compared with the next fill) */
} fv_mirror;
/* Room for `bytes` on the device and in both pinned buffers, made now (a fill makes it as it first
 * needs it): a frame that knows a table's size before it fills it, say a table used in turn with
 * another, allocates in the first frame rather than the second. Contents are kept only when
 * nothing grows. */
fv_status fv_mirror_reserve(fv_backend *b, fv_mirror *m, size_t bytes, const char *what, fv_error *err);
/* Makes m hold src's bytes (nothing when it already does); *dev receives the device copy. The
 * first fill makes both pinned buffers, so a later change allocates nothing. */
fv_status fv_mirror_fill(fv_backend *b, fv_mirror *m, const void *src, size_t bytes, const void **dev, const char *what, fv_error *err);
void fv_mirror_release(fv_backend *b, fv_mirror *m);

/* ---- queued work: copies, clears, launches, marks ---- */

/* host: pinned memory (fv_pinned_ensure) for a copy that does not block; other host memory is
 * allowed and counted as a blocking copy (a host wait). */
fv_status fv_backend_upload(fv_backend *b, void *dev, const void *host, size_t bytes, const char *what, fv_error *err);
fv_status fv_backend_download(fv_backend *b, void *host, const void *dev, size_t bytes, const char *what, fv_error *err);
fv_status fv_backend_copy(fv_backend *b, void *dst, const void *src, size_t bytes, const char *what, fv_error *err);
fv_status fv_backend_clear(fv_backend *b, void *dev, int byte, size_t bytes, const char *what, fv_error *err);

/* A launch of kernel k over w x h items (h 1 for a one-dimensional kernel), each item
 * k's function with args (k->args_size bytes, copied at the launch) and its counters added into
 * counts (device memory of k->ncounts uint64_t; NULL when k counts nothing). progress (optional,
 * portable only; NULL: none) is called as fv_parallel_tiles calls it and may cancel: *done then
 * false (always true on cuda, whose launches cannot be cancelled). */
typedef struct fv_launch_progress {
    bool (*fn)(void *user, double fraction);
    void *user;
} fv_launch_progress;
fv_status fv_backend_launch(fv_backend *b, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts, fv_error *err);
fv_status fv_backend_launch_progress(fv_backend *b, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts,
                                     const fv_launch_progress *progress, bool *done, fv_error *err);

/* Timestamps: mark slot i (0 .. FV_BACKEND_MARKS-1) where the queue has got to; the milliseconds
 * between two marks, read after a wait (0 when either was not marked since). */
#define FV_BACKEND_MARKS 32
void fv_backend_mark(fv_backend *b, int slot);
double fv_backend_elapsed_ms(fv_backend *b, int from, int to);

/* The one host wait: returns when everything queued has run, with the first error any of it met. */
fv_status fv_backend_wait(fv_backend *b, const char *what, fv_error *err);

/* Fences: fence slot i (0 .. FV_BACKEND_FENCES-1) records where the queue has got to;
 * fv_backend_wait_fence returns when everything queued before it has run, while what was queued
 * after it runs on. How a sequence collects frame N with frame N+1 already queued (the films' two
 * read-back slots, device/film_device.h). A wait as fv_backend_wait's (counted in syncs, and as a
 * host wait when something before the fence was not waited for yet); on portable, where
 * everything ran when it was queued, a fence is nothing and its wait counts as fv_backend_wait's. */
#define FV_BACKEND_FENCES 2
void fv_backend_fence(fv_backend *b, int slot);
fv_status fv_backend_wait_fence(fv_backend *b, int slot, const char *what, fv_error *err);

#endif
