/* fovea — one progress bar for a job over MPI ranks (docs/distributed.md, "Progress and messages"):
 * every rank says how far it is through its own share of the job; rank 0 alone shows the job's
 * fraction, every rank's work included. */
#ifndef FV_DIST_DIST_PROGRESS_H
#define FV_DIST_DIST_PROGRESS_H

#include <stdbool.h>
#include "dist/dist.h"

typedef struct fv_dist_progress fv_dist_progress;
/* Rank 0's display of the job's fraction in [0, 1] (never decreasing). */
typedef void (*fv_dist_show_fn)(void *user, double job);

/* Every rank at the same point of the job, each with its share of the job's work (the shares over
 * the ranks add up to 1; 0 for a rank with nothing to do). show is called on rank 0 only, also
 * while rank 0 waits in an agreement for the others. */
fv_status fv_dist_progress_start(fv_dist *d, double share, fv_dist_show_fn show, void *user, fv_dist_progress **out, fv_error *err);
/* This rank is `fraction` of the way through its share. Returns the job's fraction as this rank
 * knows it: on rank 0 everyone's, elsewhere its own part. Never blocks. */
double fv_dist_progress_update(fv_dist_progress *p, double fraction);
/* Every rank at the same point, after the job's agreement: complete when the job succeeded (rank 0
 * then waits for every rank's last note and shows 1; the others make sure theirs has left). */
void fv_dist_progress_end(fv_dist_progress *p, bool complete);

#endif
