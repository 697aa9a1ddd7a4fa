/* Test support, never linked into fovea: counts the OpenMP parallel regions a process opens, as
 * the runtime sees them. Preloaded (LD_PRELOAD) in front of libgomp, it takes the calls GCC emits
 * for every `#pragma omp parallel` (with or without a combined `for`: GCC 12 lowers all of them to
 * GOMP_parallel, the one such entry point fovea imports; `nm -D fovea | grep GOMP_parallel` says),
 * counts them and passes them on; at exit it writes the count to the file FV_OMP_COUNT_FILE names.
 * Used by tests/cli/test_regions.sh to count regions per frame of every method. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

typedef void (*parallel_fn)(void (*)(void *), void *, unsigned, unsigned);

/* A preload library's own state: the process's count (only the thread that opens a region calls
 * this, and fovea opens regions from one thread, but the add is atomic anyway). */
static unsigned long long g_regions;

void GOMP_parallel(void (*fn)(void *), void *data, unsigned num_threads, unsigned flags)
{
    parallel_fn real = (parallel_fn)dlsym(RTLD_NEXT, "GOMP_parallel");
    __atomic_add_fetch(&g_regions, 1, __ATOMIC_RELAXED);
    real(fn, data, num_threads, flags);
}

__attribute__((destructor)) static void report(void)
{
    const char *path = getenv("FV_OMP_COUNT_FILE");
    if (!path) return;
    FILE *f = fopen(path, "w");
    if (!f) return;
    fprintf(f, "%llu\n", g_regions);
    fclose(f);
}
