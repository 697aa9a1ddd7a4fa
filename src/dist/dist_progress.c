/* fovea — the job's progress (dist_progress.h). Each rank other than 0 sends rank 0 its part of the
 * job's fraction as a note (dist.h: a few doubles, sent without waiting) whenever it has grown by a
 * hundredth of the job and its previous note has left: at most about a hundred notes per rank,
 * whatever the job's length, and a rank never waits for one mid-render (a note that cannot go yet
 * is simply sent later, with a newer value). Rank 0 takes the notes that have arrived whenever its
 * own render reports progress and, through the idle hook (fv_dist_set_idle), while it waits for
 * the others in an agreement; it adds them to its own part and draws one bar. Nothing here touches
 * pixels or decides anything about the render: progress never changes an image.
 *
 * Deadlock-free: the only waits are in fv_dist_progress_end of a job that succeeded, after its
 * agreement and its transfers: a rank waits for its last note to leave, rank 0 for every rank's
 * last note to arrive (at most END_WAIT_S, and not once another rank has failed), and neither
 * waits on anything else meanwhile. A note names its bar (every rank numbers its bars alike,
 * fv_dist_bar_next), so that a late note from an earlier bar is ignored.
 */
#include <stdlib.h>
#include <time.h>
#include "dist/dist_progress.h"
#include "fovea/stats.h"

/* A note: the bar it belongs to, the sender's part of the job, 1 for its last. */
enum { NOTE_BAR, NOTE_PART, NOTE_LAST, NOTE_LEN };
/* A rank sends when its part has grown by this much of the job. */
#define STEP 0.01
/* The most rank 0 waits for the others' last notes (they are on their way; a bar is not worth a
 * hang if one is lost). */
#define END_WAIT_S 5.0

struct fv_dist_progress {
    fv_dist *d;
    int bar;          /* which bar of the job this is (the same count on every rank) */
    double share;     /* this rank's share of the job */
    double mine;      /* this rank's part so far: share x its fraction */
    double sent;      /* the part in this rank's last note */
    double shown;     /* rank 0: the largest job fraction shown */
    double *part;     /* rank 0: each rank's part as last heard */
    bool *last;       /* rank 0: each rank's last note arrived */
    fv_dist_show_fn show;
    void *user;
};

static double job_fraction(fv_dist_progress *p)
{
    double sum = 0.0;
    for (int r = 1; r < fv_dist_size(p->d); r++) sum += p->part[r];
    sum += p->mine;
    return sum > 1.0 ? 1.0 : sum;
}

/* Rank 0: takes every note that has arrived. */
static void take_notes(fv_dist_progress *p)
{
    double v[FV_DIST_NOTE_MAX];
    int from;
    while (fv_dist_note_take(p->d, v, &from)) {
        if ((int)v[NOTE_BAR] != p->bar || from <= 0 || from >= fv_dist_size(p->d)) continue;
        if (v[NOTE_PART] > p->part[from]) p->part[from] = v[NOTE_PART];
        if (v[NOTE_LAST] != 0.0) p->last[from] = true;
    }
}

static void show(fv_dist_progress *p)
{
    double job = job_fraction(p);
    if (job < p->shown) job = p->shown;
    p->shown = job;
    if (p->show) p->show(p->user, job);
}

/* While rank 0 waits in an agreement: the others' progress goes on arriving. */
static void on_idle(void *user)
{
    fv_dist_progress *p = user;
    take_notes(p);
    show(p);
}

fv_status fv_dist_progress_start(fv_dist *d, double share, fv_dist_show_fn show_fn, void *user, fv_dist_progress **out, fv_error *err)
{
    *out = NULL;
    fv_dist_progress *p = calloc(1, sizeof *p);
    const bool zero = fv_dist_rank(d) == 0;
    if (p && zero) {
        p->part = calloc((size_t)fv_dist_size(d), sizeof *p->part);
        p->last = calloc((size_t)fv_dist_size(d), sizeof *p->last);
    }
    if (!p || (zero && (!p->part || !p->last))) {
        if (p) free(p->part), free(p->last);
        free(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    }
    p->d = d;
    p->bar = fv_dist_bar_next(d);
    p->share = share;
    p->show = show_fn;
    p->user = user;
    if (zero) fv_dist_set_idle(d, on_idle, p);
    *out = p;
    return FV_OK;
}

double fv_dist_progress_update(fv_dist_progress *p, double fraction)
{
    if (!p) return fraction;
    fraction = fraction < 0.0 ? 0.0 : fraction > 1.0 ? 1.0 : fraction;
    p->mine = p->share * fraction;
    if (fv_dist_rank(p->d) == 0) {
        take_notes(p);
        show(p);
        return p->shown;
    }
    if (p->mine - p->sent >= STEP) {
        const double note[NOTE_LEN] = {p->bar, p->mine, 0.0};
        if (fv_dist_note_send(p->d, 0, note, NOTE_LEN)) p->sent = p->mine;
    }
    return p->mine;
}

void fv_dist_progress_end(fv_dist_progress *p, bool complete)
{
    if (!p) return;
    fv_dist *d = p->d;
    if (fv_dist_rank(d) == 0) {
        fv_dist_set_idle(d, NULL, NULL);
        /* every rank sent its last note before the job's agreement: they are on their way */
        p->mine = p->share;
        const double t0 = fv_time_ms();
        for (int r = 1; complete && r < fv_dist_size(d); r++)
            while (!p->last[r] && !fv_dist_poll(d) && fv_time_ms() - t0 < END_WAIT_S * 1e3) {
                take_notes(p);
                if (!p->last[r]) nanosleep(&(struct timespec){0, 1000000}, NULL);
            }
        if (complete) show(p);
        free(p->part);
        free(p->last);
    } else if (complete) {
        const double note[NOTE_LEN] = {p->bar, p->share, 1.0};
        fv_dist_note_flush(d);
        if (fv_dist_note_send(d, 0, note, NOTE_LEN)) fv_dist_note_flush(d);
    }
    free(p);
}
