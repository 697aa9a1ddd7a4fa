/* fovea — running a third-party parser in a child process (core/sandbox.c).
 *
 * Some libraries we read files with abort, loop or allocate without bound on malformed input
 * (assimp's importers assert, or reserve what a header claims: 15 GB for a 1 kB .off file). A
 * failure in the child cannot take fovea down: the child runs under an address-space and a CPU
 * time limit, streams its result back through a pipe, and the parent turns however it ended
 * (a signal, a limit, silence) into an error for the user. POSIX only (fork).
 *
 * The child never outlives the parent: on Linux it is killed (PR_SET_PDEATHSIG) when the thread
 * that started it ends, so a parent stopped by a signal (the CLI exits at once on SIGINT/SIGTERM
 * while a scene loads) leaves no importer running. It takes SIGINT and SIGTERM as the default
 * action (the parent's handlers are reset). Start, read and finish a child on one thread.
 */
#ifndef FV_CORE_SANDBOX_H
#define FV_CORE_SANDBOX_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/status.h"

typedef struct fv_sandbox fv_sandbox;

/* The child's work: writes its result to fd with fv_sandbox_write; the return value is its exit
 * status. It must not touch threads the parent started (OpenMP, Embree). */
typedef int (*fv_sandbox_fn)(void *user, int fd);

/* Forks and runs fn in the child with at most mem_bytes of address space (0: no limit) and
 * cpu_seconds of CPU time. */
fv_status fv_sandbox_start(fv_sandbox_fn fn, void *user, size_t mem_bytes, int cpu_seconds, fv_sandbox **out, fv_error *err);
/* Child side: writes all n bytes (false when the parent went away). */
bool fv_sandbox_write(int fd, const void *p, size_t n);
/* Parent side: reads exactly n bytes; false at the end of the stream, on a short read or when the
 * child sends nothing for twice its CPU limit. */
bool fv_sandbox_read(fv_sandbox *sb, void *dst, size_t n);
/* Ends the child (killed if it still runs) and frees sb. FV_OK when it exited with status 0;
 * else FV_ERR_INVALID with "<what>: <how it ended>" ("the importer crashed (signal 6, Aborted)",
 * "... ran out of memory (limit 2048 MiB)", "... took more than 60 s"). */
fv_status fv_sandbox_finish(fv_sandbox *sb, const char *what, fv_error *err);

#endif
