/* fovea — the MPI job (dist.h): start and end, the failure protocol, held stderr and the few
 * transfers the splits need. */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "fovea/stats.h"
#include "dist/dist.h"

enum { TAG_FAIL = 7001, TAG_DATA = 7002, TAG_NOTE = 7003 };
/* What a rank contributes to an agreement. */
enum { AGREE_OK = 0, AGREE_STOPPED = 1, AGREE_FAILED = 2 };
/* The contribution: what the rank did, its status, and the signal that stopped it (0 none). */
enum { AGREE_INTS = 3 };

struct fv_dist {
    int rank, size;
    MPI_Request fail_req; /* the posted receive of another rank's failure */
    int fail_buf;
    bool peer_failed, told;
    int held_fd, saved_fd; /* fv_dist_hold: the file stderr goes to, and the real stderr */
    double comm_s, wait_s;
    /* notes: the one in flight from here (its buffer must outlive it), the posted receive */
    MPI_Request note_out, note_in;
    double note_out_buf[FV_DIST_NOTE_MAX], note_in_buf[FV_DIST_NOTE_MAX];
    bool note_out_busy, note_in_posted;
    int bars; /* progress bars started (fv_dist_bar_next) */
    int (*signal_of)(void); /* fv_dist_set_signal_source */
    int job_signal;         /* the signal that interrupted the job (the last agreement's), 0 none */
    void (*idle)(void *user);
    void *idle_user;
};

bool fv_dist_launched(void)
{
    /* OpenMPI's mpirun, any PMIx launcher (srun --mpi=pmix, prterun), and MPICH-style PMI. */
    const char *vars[] = {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"};
    for (size_t i = 0; i < sizeof vars / sizeof vars[0]; i++)
        if (getenv(vars[i])) return true;
    return false;
}

static fv_status mpi_fail(int rc, const char *what, fv_error *err)
{
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(rc, text, &len) != MPI_SUCCESS) snprintf(text, sizeof text, "error %d", rc);
    return fv_error_set(err, FV_ERR_IO, "MPI %s failed: %s", what, text);
}

fv_status fv_dist_start(int *argc, char ***argv, fv_dist **out, fv_error *err)
{
    *out = NULL;
    int provided = 0, rc;
    /* Only the main thread calls MPI (dist.h). */
    if ((rc = MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided)) != MPI_SUCCESS)
        return fv_error_set(err, FV_ERR_IO, "MPI_Init_thread failed (error %d)", rc);
    /* From here every error comes back to us instead of aborting the job behind our back. */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    fv_dist *d = calloc(1, sizeof *d);
    if (!d) {
        MPI_Finalize();
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    d->held_fd = d->saved_fd = -1;
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    if ((rc = MPI_Irecv(&d->fail_buf, 1, MPI_INT, MPI_ANY_SOURCE, TAG_FAIL, MPI_COMM_WORLD, &d->fail_req)) != MPI_SUCCESS) {
        free(d);
        fv_status s = mpi_fail(rc, "receive", err);
        MPI_Finalize();
        return s;
    }
    *out = d;
    return FV_OK;
}

/* Back to the real stderr; the held text is written there when replay, each line prefixed with
 * "rank R: " when name_rank. */
static void release_hold(fv_dist *d, bool replay, bool name_rank)
{
    if (d->held_fd < 0) return;
    fflush(stderr);
    dup2(d->saved_fd, STDERR_FILENO);
    close(d->saved_fd);
    if (replay && lseek(d->held_fd, 0, SEEK_SET) == 0) {
        FILE *f = fdopen(dup(d->held_fd), "r");
        char line[4096];
        while (f && fgets(line, sizeof line, f)) {
            if (name_rank) fprintf(stderr, "rank %d: ", d->rank);
            fputs(line, stderr);
        }
        if (f) fclose(f);
    }
    close(d->held_fd);
    d->held_fd = d->saved_fd = -1;
}

void fv_dist_end(fv_dist *d)
{
    if (!d) return;
    release_hold(d, d->rank == 0, false);
    /* a note still in flight completes (or not) with MPI_Finalize; its buffer is d's */
    if (d->note_out_busy) MPI_Request_free(&d->note_out);
    if (d->note_in_posted) {
        MPI_Cancel(&d->note_in);
        MPI_Wait(&d->note_in, MPI_STATUS_IGNORE);
    }
    if (!d->peer_failed) {
        MPI_Cancel(&d->fail_req);
        MPI_Wait(&d->fail_req, MPI_STATUS_IGNORE);
    }
    MPI_Finalize();
    free(d);
}

int fv_dist_rank(const fv_dist *d) { return d->rank; }
int fv_dist_size(const fv_dist *d) { return d->size; }
double fv_dist_comm_seconds(const fv_dist *d) { return d->comm_s; }
double fv_dist_wait_seconds(const fv_dist *d) { return d->wait_s; }

fv_status fv_dist_hold(fv_dist *d, fv_error *err)
{
    if (d->held_fd >= 0) return FV_OK;
    FILE *f = tmpfile();
    int fd = f ? dup(fileno(f)) : -1;
    if (f) fclose(f); /* the dup keeps the unlinked file */
    if (fd < 0) return fv_error_set(err, FV_ERR_IO, "cannot create a temporary file to hold messages");
    fflush(stderr);
    d->saved_fd = dup(STDERR_FILENO);
    if (d->saved_fd < 0 || dup2(fd, STDERR_FILENO) < 0) {
        if (d->saved_fd >= 0) close(d->saved_fd);
        close(fd);
        d->saved_fd = -1;
        return fv_error_set(err, FV_ERR_IO, "cannot redirect stderr to hold messages");
    }
    d->held_fd = fd;
    return FV_OK;
}

void fv_dist_tell_failure(fv_dist *d)
{
    if (d->told) return;
    d->told = true;
    /* A one-int message goes out eagerly; the requests are freed, not waited on. */
    for (int r = 0; r < d->size; r++) {
        if (r == d->rank) continue;
        MPI_Request q;
        if (MPI_Isend(&d->rank, 1, MPI_INT, r, TAG_FAIL, MPI_COMM_WORLD, &q) == MPI_SUCCESS) MPI_Request_free(&q);
    }
}

bool fv_dist_poll(fv_dist *d)
{
    if (d->peer_failed) return true;
    int flag = 0;
    if (MPI_Test(&d->fail_req, &flag, MPI_STATUS_IGNORE) == MPI_SUCCESS && flag) d->peer_failed = true;
    return d->peer_failed;
}

void fv_dist_set_signal_source(fv_dist *d, int (*signal_of)(void))
{
    d->signal_of = signal_of;
}

int fv_dist_signal(const fv_dist *d)
{
    return d->job_signal;
}

/* Every rank's AGREE_INTS ints. A rank that arrives early waits without spinning (MPI's blocking
 * collectives busy-poll, which takes a core from a rank still rendering on the same host): the
 * non-blocking gather is tested every millisecond (running the idle hook between tests). */
static int wait_all(fv_dist *d, int mine[AGREE_INTS], int *all)
{
    MPI_Request q;
    int rc = MPI_Iallgather(mine, AGREE_INTS, MPI_INT, all, AGREE_INTS, MPI_INT, MPI_COMM_WORLD, &q);
    int done = 0;
    while (rc == MPI_SUCCESS && !done) {
        rc = MPI_Test(&q, &done, MPI_STATUS_IGNORE);
        if (rc == MPI_SUCCESS && !done) {
            if (d->idle) d->idle(d->idle_user);
            nanosleep(&(struct timespec){0, 1000000}, NULL);
        }
    }
    return rc;
}

fv_status fv_dist_agree(fv_dist *d, fv_status s, bool *print_it, bool *name_rank, fv_error *err)
{
    *print_it = *name_rank = false;
    d->job_signal = 0;
    /* A cancelled rank says whether a signal cancelled it: an interrupted job ends as one
     * interrupted process does, not as a failure of the rank that happened to be signalled. */
    const int sig = s == FV_ERR_CANCELLED && d->signal_of ? d->signal_of() : 0;
    int mine[AGREE_INTS] = {AGREE_OK, (int)s, sig};
    if (s != FV_OK) {
        mine[0] = s == FV_ERR_CANCELLED && fv_dist_poll(d) && !d->told ? AGREE_STOPPED : AGREE_FAILED;
        if (mine[0] == AGREE_FAILED) fv_dist_tell_failure(d);
    }
    int *all = malloc(sizeof(int) * AGREE_INTS * (size_t)d->size);
    double t0 = fv_time_ms();
    int rc = all ? wait_all(d, mine, all) : MPI_ERR_NO_MEM;
    d->wait_s += (fv_time_ms() - t0) * 1e-3;
    if (rc != MPI_SUCCESS) {
        /* no agreement to be had: this rank speaks for itself */
        free(all);
        release_hold(d, true, true);
        *print_it = *name_rank = true;
        return mpi_fail(rc, "agreement", err);
    }
    int first = -1, failed = 0, stopped = -1;
    for (int r = 0; r < d->size; r++) {
        if (all[AGREE_INTS * r] == AGREE_FAILED) {
            failed++;
            if (first < 0) first = r;
        } else if (all[AGREE_INTS * r] == AGREE_STOPPED && stopped < 0) stopped = r;
    }
    if (first < 0) first = stopped;
    fv_status job = first < 0 ? FV_OK : (fv_status)all[AGREE_INTS * first + 1];
    if (job == FV_ERR_CANCELLED) d->job_signal = all[AGREE_INTS * first + 2];
    free(all);
    if (job == FV_OK) {
        release_hold(d, d->rank == 0, false);
        return FV_OK;
    }
    /* Every rank failed: the input all of them saw, said once, as one process says it. */
    if (failed == d->size) first = 0;
    *print_it = d->rank == first;
    *name_rank = failed != d->size;
    release_hold(d, *print_it, *name_rank);
    return job;
}

/* MPI counts are ints: a large image goes in pieces. */
#define PIECE ((size_t)1 << 26)

/* n items of `type` (size bytes each) to or from peer, in pieces below MPI's int count. */
static fv_status transfer(fv_dist *d, bool send, int peer, void *v, size_t n, MPI_Datatype type, size_t size, fv_error *err)
{
    double t0 = fv_time_ms();
    for (size_t i = 0; i < n; i += PIECE) {
        size_t m = n - i < PIECE ? n - i : PIECE;
        char *at = (char *)v + i * size;
        int rc = send ? MPI_Send(at, (int)m, type, peer, TAG_DATA, MPI_COMM_WORLD)
                      : MPI_Recv(at, (int)m, type, peer, TAG_DATA, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (rc != MPI_SUCCESS) return mpi_fail(rc, send ? "send" : "receive", err);
    }
    d->comm_s += (fv_time_ms() - t0) * 1e-3;
    return FV_OK;
}

fv_status fv_dist_send(fv_dist *d, int peer, const double *v, size_t n, fv_error *err)
{
    return transfer(d, true, peer, (void *)v, n, MPI_DOUBLE, sizeof *v, err);
}

fv_status fv_dist_recv(fv_dist *d, int peer, double *v, size_t n, fv_error *err) { return transfer(d, false, peer, v, n, MPI_DOUBLE, sizeof *v, err); }

fv_status fv_dist_send_bytes(fv_dist *d, int peer, const void *v, size_t n, fv_error *err)
{
    return transfer(d, true, peer, (void *)v, n, MPI_BYTE, 1, err);
}

fv_status fv_dist_recv_bytes(fv_dist *d, int peer, void *v, size_t n, fv_error *err) { return transfer(d, false, peer, v, n, MPI_BYTE, 1, err); }

fv_status fv_dist_sum(fv_dist *d, double *v, int n, fv_error *err)
{
    double t0 = fv_time_ms();
    int rc = MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    d->comm_s += (fv_time_ms() - t0) * 1e-3;
    return rc == MPI_SUCCESS ? FV_OK : mpi_fail(rc, "sum", err);
}

void fv_dist_set_idle(fv_dist *d, void (*fn)(void *user), void *user)
{
    d->idle = fn;
    d->idle_user = user;
}

/* Whether the note in flight has left (its request then completed). */
static bool note_gone(fv_dist *d)
{
    if (!d->note_out_busy) return true;
    int flag = 0;
    if (MPI_Test(&d->note_out, &flag, MPI_STATUS_IGNORE) != MPI_SUCCESS || flag) d->note_out_busy = false;
    return !d->note_out_busy;
}

bool fv_dist_note_send(fv_dist *d, int peer, const double *v, int n)
{
    if (n > FV_DIST_NOTE_MAX || !note_gone(d)) return false;
    memcpy(d->note_out_buf, v, (size_t)n * sizeof *v);
    if (MPI_Isend(d->note_out_buf, n, MPI_DOUBLE, peer, TAG_NOTE, MPI_COMM_WORLD, &d->note_out) != MPI_SUCCESS) return false;
    d->note_out_busy = true;
    return true;
}

void fv_dist_note_flush(fv_dist *d)
{
    while (!note_gone(d) && !fv_dist_poll(d)) nanosleep(&(struct timespec){0, 1000000}, NULL);
}

bool fv_dist_note_take(fv_dist *d, double *v, int *from)
{
    if (!d->note_in_posted) {
        if (MPI_Irecv(d->note_in_buf, FV_DIST_NOTE_MAX, MPI_DOUBLE, MPI_ANY_SOURCE, TAG_NOTE, MPI_COMM_WORLD, &d->note_in) != MPI_SUCCESS)
            return false;
        d->note_in_posted = true;
    }
    int flag = 0;
    MPI_Status st;
    if (MPI_Test(&d->note_in, &flag, &st) != MPI_SUCCESS || !flag) return false;
    d->note_in_posted = false;
    memcpy(v, d->note_in_buf, sizeof d->note_in_buf);
    *from = st.MPI_SOURCE;
    return true;
}

int fv_dist_bar_next(fv_dist *d) { return d->bars++; }
