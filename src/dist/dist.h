/* fovea — a job over MPI ranks (docs/distributed.md): what the CLI asks of MPI, and nothing else
 * in fovea knows MPI. Built only with FOVEA_MPI (CMake), into the CLI, never into libfovea.
 *
 * A job is started only when a launcher (mpirun, srun) started the process; a plain `fovea` run
 * stays one process and never touches MPI. Every MPI call returns its error (MPI_ERRORS_RETURN),
 * mapped onto fovea's statuses with MPI's own string.
 *
 * Failures: a rank that fails tells the others (a small message they poll from their progress
 * callbacks, so a long render stops within a progress step), then every rank agrees on the job's
 * status (fv_dist_agree) and exactly one line is printed: by the first rank that failed, prefixed
 * with "rank R: ", or once without a prefix when every rank failed alike (bad input all of them
 * see). What a rank prints before an agreement is held back (fv_dist_hold) and replayed only by
 * the rank whose words stand. A rank that dies (killed, out of memory) is the launcher's to
 * report: mpirun ends the job and prints which rank died of which signal.
 *
 * Threads: MPI is called from the main thread only (MPI_THREAD_FUNNELED); the tile loop's progress
 * callback runs there (core/parallel.c calls it from thread 0 of the team).
 */
#ifndef FV_DIST_H
#define FV_DIST_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/status.h"

typedef struct fv_dist fv_dist;

/* True when a launcher started this process as one rank of several. */
bool fv_dist_launched(void);
/* Initialises MPI (rank, size, MPI_ERRORS_RETURN). Release with fv_dist_end, which finalises. */
fv_status fv_dist_start(int *argc, char ***argv, fv_dist **out, fv_error *err);
void fv_dist_end(fv_dist *d);
int fv_dist_rank(const fv_dist *d);
int fv_dist_size(const fv_dist *d);

/* Holds this rank's stderr from now until fv_dist_agree, which replays it where it stands. */
fv_status fv_dist_hold(fv_dist *d, fv_error *err);

/* Every rank passes its status s. Returns the job's status: FV_OK when all succeeded, else the
 * first failing rank's (a rank stopped by another's failure counts last). On failure *print_it is
 * true on the one rank whose message is printed, and *name_rank when that line should start
 * "rank R: " (not every rank failed). Held stderr is replayed by rank 0 on success, by the
 * printing rank on failure (its lines prefixed likewise). err is set only when MPI itself fails. */
fv_status fv_dist_agree(fv_dist *d, fv_status s, bool *print_it, bool *name_rank, fv_error *err);

/* Interrupts (docs/distributed.md): signal_of() returns the signal that stopped this rank, 0 when
 * none (the CLI's fv_cli_interrupted). A rank whose status is FV_ERR_CANCELLED passes it to the
 * agreement, so a job stopped by a signal, on any rank, is known as interrupted on every rank. */
void fv_dist_set_signal_source(fv_dist *d, int (*signal_of)(void));
/* After an agreement whose job status is FV_ERR_CANCELLED: the signal that stopped the rank the
 * agreement chose, 0 when no signal did. Every rank gets the same. */
int fv_dist_signal(const fv_dist *d);

/* Tells the other ranks this one failed (their fv_dist_poll turns true). */
void fv_dist_tell_failure(fv_dist *d);
/* True once another rank has failed; cheap enough to call from a progress callback. */
bool fv_dist_poll(fv_dist *d);

/* Sends / receives n doubles to / from rank `peer` (in pieces below MPI's int count). */
fv_status fv_dist_send(fv_dist *d, int peer, const double *v, size_t n, fv_error *err);
fv_status fv_dist_recv(fv_dist *d, int peer, double *v, size_t n, fv_error *err);
/* The same for n bytes (a bench row's result, images). */
fv_status fv_dist_send_bytes(fv_dist *d, int peer, const void *v, size_t n, fv_error *err);
fv_status fv_dist_recv_bytes(fv_dist *d, int peer, void *v, size_t n, fv_error *err);
/* The sum over ranks of n doubles, the result on every rank. Used for counters only (order-free
 * values), never for pixels. */
fv_status fv_dist_sum(fv_dist *d, double *v, int n, fv_error *err);
/* Notes: a few doubles (at most FV_DIST_NOTE_MAX) sent without waiting, for what must never hold a
 * rank up (progress). At most one note of this rank is in flight: fv_dist_note_send returns false
 * and sends nothing while the previous one has not left. fv_dist_note_flush tests until it has
 * left, or another rank failed (then it is left to MPI_Finalize: its buffer lives in d). */
#define FV_DIST_NOTE_MAX 4
bool fv_dist_note_send(fv_dist *d, int peer, const double *v, int n);
void fv_dist_note_flush(fv_dist *d);
/* One note from any rank, if one has arrived (v: FV_DIST_NOTE_MAX doubles): true and *from. */
bool fv_dist_note_take(fv_dist *d, double *v, int *from);
/* While this rank waits in fv_dist_agree, fn(user) runs about every millisecond (rank 0's bar
 * goes on showing the others' progress); NULL stops it. */
void fv_dist_set_idle(fv_dist *d, void (*fn)(void *user), void *user);
/* 0, 1, 2, ...: the number of the job's next progress bar (dist_progress.h), counted alike on every rank. */
int fv_dist_bar_next(fv_dist *d);

/* Seconds this rank spent moving data (sends, receives, sums): the communication share of the
 * figures; and waiting in agreements for the other ranks (load imbalance, not communication). */
double fv_dist_comm_seconds(const fv_dist *d);
double fv_dist_wait_seconds(const fv_dist *d);

#endif
