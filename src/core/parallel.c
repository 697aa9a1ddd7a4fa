/* fovea — tile loop and parallel-for over OpenMP (see parallel.h). */
#include <omp.h>
#include <stddef.h>
#include "core/parallel.h"
#include "fovea/stats.h"

/* The one piece of mutable state in the library, and why it is per thread: regions are opened by
 * the thread that renders (nested regions are off), so its own count and clock are exactly those
 * of its frames' regions, whatever other renders other threads run; passing a counter to every
 * stage and filter that opens a region would thread one more argument through forty call sites
 * for numbers that never change a pixel. */
static _Thread_local struct {
    uint64_t regions;
    bool open;         /* between fv_region_begin and fv_region_end */
    double start;      /* fv_time_ms() at fv_region_begin */
    double parallel;   /* ms inside closed regions, less their serial parts (and the open one's) */
} t_clock;

uint64_t fv_region_count(void) { return t_clock.regions; }
void fv_region_opened(void) { t_clock.regions++; }

void fv_region_begin(void)
{
    t_clock.regions++;
    t_clock.open = true;
    t_clock.start = fv_time_ms();
}

void fv_region_end(void)
{
    if (!t_clock.open) return;
    t_clock.parallel += fv_time_ms() - t_clock.start;
    t_clock.open = false;
}

void fv_region_serial(double ms)
{
    if (ms > 0.0) t_clock.parallel -= ms;
}

double fv_region_parallel_ms(void) { return t_clock.parallel + (t_clock.open ? fv_time_ms() - t_clock.start : 0.0); }

void fv_team_for(int64_t n, int64_t chunk, fv_range_fn fn, void *ctx)
{
    if (chunk < 1) chunk = 1;
    const int64_t nchunks = (n + chunk - 1) / chunk;
    /* orphaned: binds to the enclosing region's team (a team of one outside any) */
#pragma omp for schedule(dynamic, 1)
    for (int64_t c = 0; c < nchunks; c++) {
        const int64_t b = c * chunk, e = b + chunk < n ? b + chunk : n;
        fn(ctx, b, e, omp_get_thread_num());
    }
}

void fv_team_progress_init(fv_team_progress *tp, fv_progress_fn fn, void *user)
{
    tp->fn = fn;
    tp->user = user;
    tp->done = 0;
    tp->stop = 0;
    tp->ok = 1;
}

bool fv_team_for_progress(int64_t n, int64_t chunk, fv_range_fn fn, void *ctx, fv_team_progress *tp)
{
    if (chunk < 1) chunk = 1;
    const int64_t nchunks = (n + chunk - 1) / chunk;
    /* Every thread enters the loop whatever the cancel says: a thread that skipped a work-sharing
     * construct its team entered would leave the team's barriers unmatched. */
#pragma omp for schedule(dynamic, 1)
    for (int64_t c = 0; c < nchunks; c++) {
        int halt;
#pragma omp atomic read
        halt = tp->stop;
        if (halt) continue;
        const int64_t b = c * chunk, e = b + chunk < n ? b + chunk : n;
        const int thread = omp_get_thread_num();
        fn(ctx, b, e, thread);
        int64_t d;
#pragma omp atomic capture
        d = ++tp->done;
        if (tp->fn && thread == 0 && !tp->fn(tp->user, (double)d / (double)nchunks)) {
#pragma omp atomic write
            tp->stop = 1;
        }
    }
    /* The loop's barrier has ordered every chunk; thread 0 resets the count and reports the end.
     * `ok` is written here only, and read by all after the barrier below, before any of them can
     * reach the next loop's barrier (and so before thread 0 can write it again): the team agrees. */
#pragma omp master
    {
        tp->done = 0;
        if (!tp->stop && tp->fn && !tp->fn(tp->user, 1.0)) tp->stop = 1;
        tp->ok = !tp->stop;
    }
#pragma omp barrier
    return tp->ok != 0;
}

typedef struct team_tiles {
    int width, height, tx;
    fv_tile_fn fn;
    void *ctx;
} team_tiles;

static void team_tile_range(void *ctx, int64_t b, int64_t e, int thread)
{
    const team_tiles *tt = ctx;
    for (int64_t i = b; i < e; i++) {
        fv_tile t;
        t.x0 = (int)(i % tt->tx) * FV_TILE_SIZE;
        t.y0 = (int)(i / tt->tx) * FV_TILE_SIZE;
        t.x1 = t.x0 + FV_TILE_SIZE < tt->width ? t.x0 + FV_TILE_SIZE : tt->width;
        t.y1 = t.y0 + FV_TILE_SIZE < tt->height ? t.y0 + FV_TILE_SIZE : tt->height;
        t.thread = thread;
        tt->fn(tt->ctx, &t);
    }
}

bool fv_team_tiles(int width, int height, fv_tile_fn fn, void *ctx, fv_team_progress *tp)
{
    /* each thread's own copy of the same description (fv_team_for's ctx is the caller's) */
    const int tx = (width + FV_TILE_SIZE - 1) / FV_TILE_SIZE, ty = (height + FV_TILE_SIZE - 1) / FV_TILE_SIZE;
    team_tiles tt = {width, height, tx, fn, ctx};
    if (!tp) {
        fv_team_for((int64_t)tx * ty, 1, team_tile_range, &tt);
        return true;
    }
    return fv_team_for_progress((int64_t)tx * ty, 1, team_tile_range, &tt, tp);
}

int fv_thread_count(int requested)
{
    int n = requested > 0 ? requested : omp_get_max_threads();
    if (n < 1) n = 1;
    if (n > FV_MAX_THREADS) n = FV_MAX_THREADS;
    return n;
}

bool fv_parallel_tiles(int width, int height, int threads, fv_tile_fn fn, void *ctx,
                       fv_progress_fn progress, void *progress_user)
{
    const int tx = (width + FV_TILE_SIZE - 1) / FV_TILE_SIZE;
    const int ty = (height + FV_TILE_SIZE - 1) / FV_TILE_SIZE;
    const int ntiles = tx * ty;
    const int nthreads = fv_thread_count(threads);
    int done = 0, stop = 0;
    fv_region_begin();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
    for (int i = 0; i < ntiles; i++) {
        int halt;
#pragma omp atomic read
        halt = stop;
        if (halt) continue; /* cancelled: an OpenMP loop cannot break, so the rest run empty */
        fv_tile t;
        t.x0 = (i % tx) * FV_TILE_SIZE;
        t.y0 = (i / tx) * FV_TILE_SIZE;
        t.x1 = t.x0 + FV_TILE_SIZE < width ? t.x0 + FV_TILE_SIZE : width;
        t.y1 = t.y0 + FV_TILE_SIZE < height ? t.y0 + FV_TILE_SIZE : height;
        t.thread = omp_get_thread_num();
        fn(ctx, &t);
        int d;
#pragma omp atomic capture
        d = ++done;
        /* Only thread 0 reports, so the callback never runs concurrently with itself. */
        if (progress && t.thread == 0 && !progress(progress_user, (double)d / ntiles)) {
#pragma omp atomic write
            stop = 1;
        }
    }
    fv_region_end();
    if (stop) return false;
    return !progress || progress(progress_user, 1.0);
}

bool fv_parallel_for_progress(int64_t n, int64_t chunk, int threads, fv_range_fn fn, void *ctx, fv_progress_fn progress,
                              void *progress_user)
{
    if (chunk < 1) chunk = 1;
    const int64_t nchunks = (n + chunk - 1) / chunk;
    const int nthreads = fv_thread_count(threads);
    int64_t done = 0;
    int stop = 0;
    fv_region_begin();
#pragma omp parallel for schedule(dynamic, 1) num_threads(nthreads)
    for (int64_t c = 0; c < nchunks; c++) {
        int halt;
#pragma omp atomic read
        halt = stop;
        if (halt) continue;
        int64_t b = c * chunk, e = b + chunk < n ? b + chunk : n;
        int thread = omp_get_thread_num();
        fn(ctx, b, e, thread);
        int64_t d;
#pragma omp atomic capture
        d = ++done;
        if (progress && thread == 0 && !progress(progress_user, (double)d / (double)nchunks)) {
#pragma omp atomic write
            stop = 1;
        }
    }
    fv_region_end();
    if (stop) return false;
    return !progress || progress(progress_user, 1.0);
}

void fv_parallel_for(int64_t n, int64_t chunk, int threads, fv_range_fn fn, void *ctx)
{
    fv_parallel_for_progress(n, chunk, threads, fn, ctx, NULL, NULL);
}
