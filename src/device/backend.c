/* fovea — the device backend (device/backend.h): the interface, the portable implementation, and
 * the calls forwarded to the CUDA one (device/cuda/backend_api.h).
 *
 * Portable: device memory is host memory; a launch runs at once over FV_TILE_SIZE tiles on the
 * CPU's threads (core/parallel.h), each thread summing its items' counters before they are added
 * into the launch's; copies are memcpy; a mark reads the monotonic clock. Nothing is queued, so the
 * only host wait is fv_backend_wait's, kept so that a frame's figures read the same on both.
 */
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "core/parallel.h"
#include "device/backend.h"
#include "device/cuda/backend_api.h"

struct fv_backend {
    fv_device device;
    fv_cuda_backend *cuda; /* cuda: everything is forwarded */
    int threads;
    fv_backend_calls calls; /* portable */
    double mark_ms[FV_BACKEND_MARKS];
};

fv_status fv_backend_create(fv_device device, fv_backend **out, fv_error *err)
{
    *out = NULL;
    if (device != FV_DEVICE_PORTABLE && device != FV_DEVICE_CUDA)
        return fv_error_set(err, FV_ERR_INVALID, "device %s has no kernel backend (portable and cuda have)", fv_device_name(device));
    fv_backend *b = calloc(1, sizeof *b);
    if (!b) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    b->device = device;
    if (device == FV_DEVICE_CUDA) {
        fv_status s = fv_cuda_backend_create(&b->cuda, err);
        if (s != FV_OK) {
            free(b);
            return s;
        }
    }
    *out = b;
    return FV_OK;
}

void fv_backend_destroy(fv_backend *b)
{
    if (!b) return;
    fv_cuda_backend_destroy(b->cuda);
    free(b);
}

fv_device fv_backend_device(const fv_backend *b) { return b->device; }

void fv_backend_set_threads(fv_backend *b, int threads) { b->threads = threads; }

void fv_backend_calls_get(const fv_backend *b, fv_backend_calls *out)
{
    if (b->cuda)
        fv_cuda_backend_calls(b->cuda, out);
    else
        *out = b->calls;
}

void fv_backend_calls_diff(const fv_backend_calls *a, const fv_backend_calls *b, fv_backend_calls *d)
{
    d->launches = a->launches - b->launches, d->syncs = a->syncs - b->syncs, d->host_waits = a->host_waits - b->host_waits;
    d->pageable_copies = a->pageable_copies - b->pageable_copies;
    d->bytes_h2d = a->bytes_h2d - b->bytes_h2d, d->bytes_d2h = a->bytes_d2h - b->bytes_d2h;
    d->allocations = a->allocations - b->allocations, d->frees = a->frees - b->frees;
}

bool fv_backend_cuda_probe(char *why, size_t why_len) { return fv_cuda_backend_probe(why, why_len); }

/* ---- memory ---- */

static fv_status grow(fv_backend *b, fv_buffer *buf, size_t bytes, bool pinned, const char *what, fv_error *err)
{
    if (buf->p && buf->cap >= bytes) return FV_OK;
    if (pinned)
        fv_pinned_release(b, buf);
    else
        fv_buffer_release(b, buf);
    if (bytes == 0) return FV_OK;
    if (b->cuda) {
        fv_status s = pinned ? fv_cuda_backend_host_alloc(b->cuda, &buf->p, bytes, what, err) : fv_cuda_backend_alloc(b->cuda, &buf->p, bytes, what, err);
        if (s != FV_OK) return s;
    } else {
        if (!(buf->p = calloc(1, bytes))) return fv_error_set(err, FV_ERR_NOMEM, "out of memory for %s (%zu bytes)", what, bytes);
        if (!pinned) b->calls.allocations++;
    }
    buf->cap = bytes;
    return FV_OK;
}

fv_status fv_buffer_ensure(fv_backend *b, fv_buffer *buf, size_t bytes, const char *what, fv_error *err)
{
    return grow(b, buf, bytes, false, what, err);
}

void fv_buffer_release(fv_backend *b, fv_buffer *buf)
{
    if (!buf->p) return;
    if (b->cuda) {
        fv_cuda_backend_free(b->cuda, buf->p);
    } else {
        free(buf->p);
        b->calls.frees++;
    }
    buf->p = NULL;
    buf->cap = 0;
}

fv_status fv_pinned_ensure(fv_backend *b, fv_buffer *buf, size_t bytes, const char *what, fv_error *err)
{
    return grow(b, buf, bytes, true, what, err);
}

void fv_pinned_release(fv_backend *b, fv_buffer *buf)
{
    if (!buf->p) return;
    if (b->cuda)
        fv_cuda_backend_host_free(b->cuda, buf->p);
    else
        free(buf->p);
    buf->p = NULL;
    buf->cap = 0;
}

fv_status fv_mirror_reserve(fv_backend *b, fv_mirror *m, size_t bytes, const char *what, fv_error *err)
{
    const void *was[3] = {m->dev.p, m->stage[0].p, m->stage[1].p};
    fv_status s;
    if ((s = fv_pinned_ensure(b, &m->stage[0], bytes, what, err)) == FV_OK && (s = fv_pinned_ensure(b, &m->stage[1], bytes, what, err)) == FV_OK)
        s = fv_buffer_ensure(b, &m->dev, bytes, what, err);
    if (m->dev.p != was[0] || m->stage[0].p != was[1] || m->stage[1].p != was[2]) {
        m->bytes = 0; /* what it held is gone */
        m->last = NULL;
    }
    return s;
}

fv_status fv_mirror_fill(fv_backend *b, fv_mirror *m, const void *src, size_t bytes, const void **dev, const char *what, fv_error *err)
{
    *dev = m->dev.p;
    if (bytes == 0) return FV_OK;
    if (m->bytes == bytes && m->last && memcmp(m->last, src, bytes) == 0) return FV_OK; /* unchanged since the last copy */
    fv_buffer *st = &m->stage[m->next];
    fv_status s = fv_mirror_reserve(b, m, bytes, what, err);
    if (s != FV_OK) return s;
    m->bytes = 0; /* stale until the copy is queued */
    memcpy(st->p, src, bytes);
    if ((s = fv_backend_upload(b, m->dev.p, st->p, bytes, what, err)) != FV_OK) return s;
    m->bytes = bytes;
    m->last = st->p;
    m->next ^= 1;
    *dev = m->dev.p;
    return FV_OK;
}

void fv_mirror_release(fv_backend *b, fv_mirror *m)
{
    fv_buffer_release(b, &m->dev);
    fv_pinned_release(b, &m->stage[0]);
    fv_pinned_release(b, &m->stage[1]);
    memset(m, 0, sizeof *m);
}

/* ---- queued work ---- */

fv_status fv_backend_upload(fv_backend *b, void *dev, const void *host, size_t bytes, const char *what, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (b->cuda) return fv_cuda_backend_copy(b->cuda, dev, host, bytes, FV_CUDA_H2D, what, err);
    memcpy(dev, host, bytes);
    b->calls.bytes_h2d += bytes;
    return FV_OK;
}

fv_status fv_backend_download(fv_backend *b, void *host, const void *dev, size_t bytes, const char *what, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (b->cuda) return fv_cuda_backend_copy(b->cuda, host, dev, bytes, FV_CUDA_D2H, what, err);
    memcpy(host, dev, bytes);
    b->calls.bytes_d2h += bytes;
    return FV_OK;
}

fv_status fv_backend_copy(fv_backend *b, void *dst, const void *src, size_t bytes, const char *what, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (b->cuda) return fv_cuda_backend_copy(b->cuda, dst, src, bytes, FV_CUDA_D2D, what, err);
    memcpy(dst, src, bytes);
    return FV_OK;
}

fv_status fv_backend_clear(fv_backend *b, void *dev, int byte, size_t bytes, const char *what, fv_error *err)
{
    if (bytes == 0) return FV_OK;
    if (b->cuda) return fv_cuda_backend_clear(b->cuda, dev, byte, bytes, what, err);
    memset(dev, byte, bytes);
    return FV_OK;
}

typedef struct tile_job {
    const fv_kernel *k;
    const void *args;
    uint64_t (*counts)[FV_KERNEL_MAX_COUNTS]; /* per thread */
} tile_job;

static void run_tile(void *ctx, const fv_tile *t)
{
    const tile_job *j = ctx;
    j->k->tile(j->args, t->x0, t->x1, t->y0, t->y1, j->counts[t->thread]);
}

/* A one-dimensional kernel in long runs rather than 16-item tiles. */
static void run_range(void *ctx, int64_t begin, int64_t end, int thread)
{
    const tile_job *j = ctx;
    j->k->tile(j->args, (int)begin, (int)end, 0, 1, j->counts[thread]);
}

fv_status fv_backend_launch_progress(fv_backend *b, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts,
                                     const fv_launch_progress *progress, bool *done, fv_error *err)
{
    if (done) *done = true;
    if (w < 0 || h < 0 || (k->dims == 1 && h > 1) || k->ncounts < 0 || k->ncounts > FV_KERNEL_MAX_COUNTS || (k->ncounts && !counts))
        return fv_error_set(err, FV_ERR_INTERNAL, "kernel %s: a launch of %dx%d items that does not fit its declaration", k->name, w, h);
    if (w == 0 || h == 0) return FV_OK;
    if (b->cuda) return fv_cuda_backend_launch(b->cuda, k, w, h, args, counts, err);
    b->calls.launches++;
    const int nt = fv_thread_count(b->threads);
    uint64_t (*per)[FV_KERNEL_MAX_COUNTS] = calloc((size_t)nt, sizeof *per);
    if (!per) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    tile_job j = {k, args, per};
    fv_progress_fn pf = progress ? progress->fn : NULL;
    void *pu = progress ? progress->user : NULL;
    const bool ran = k->dims == 1 ? fv_parallel_for_progress(w, 4096, b->threads, run_range, &j, pf, pu)
                                  : fv_parallel_tiles(w, h, b->threads, run_tile, &j, pf, pu);
    for (int t = 0; t < nt; t++)
        for (int i = 0; i < k->ncounts; i++) counts[i] += per[t][i];
    free(per);
    if (done) *done = ran;
    return FV_OK;
}

fv_status fv_backend_launch(fv_backend *b, const fv_kernel *k, int w, int h, const void *args, uint64_t *counts, fv_error *err)
{
    return fv_backend_launch_progress(b, k, w, h, args, counts, NULL, NULL, err);
}

void fv_backend_mark(fv_backend *b, int slot)
{
    if (slot < 0 || slot >= FV_BACKEND_MARKS) return;
    if (b->cuda) {
        fv_cuda_backend_mark(b->cuda, slot);
        return;
    }
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    b->mark_ms[slot] = (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

double fv_backend_elapsed_ms(fv_backend *b, int from, int to)
{
    if (from < 0 || to < 0 || from >= FV_BACKEND_MARKS || to >= FV_BACKEND_MARKS) return 0.0;
    if (b->cuda) return fv_cuda_backend_elapsed_ms(b->cuda, from, to);
    return b->mark_ms[from] > 0.0 && b->mark_ms[to] > 0.0 ? b->mark_ms[to] - b->mark_ms[from] : 0.0;
}

void fv_backend_fence(fv_backend *b, int slot)
{
    if (b->cuda && slot >= 0 && slot < FV_BACKEND_FENCES) fv_cuda_backend_fence(b->cuda, slot);
}

fv_status fv_backend_wait_fence(fv_backend *b, int slot, const char *what, fv_error *err)
{
    if (slot < 0 || slot >= FV_BACKEND_FENCES) return fv_error_set(err, FV_ERR_INTERNAL, "%s: fence %d of %d", what, slot, FV_BACKEND_FENCES);
    if (b->cuda) return fv_cuda_backend_wait_fence(b->cuda, slot, what, err);
    return fv_backend_wait(b, what, err);
}

fv_status fv_backend_wait(fv_backend *b, const char *what, fv_error *err)
{
    if (b->cuda) return fv_cuda_backend_wait(b->cuda, what, err);
    b->calls.syncs++;
    b->calls.host_waits++;
    return FV_OK;
}
