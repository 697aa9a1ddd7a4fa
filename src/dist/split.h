/* fovea — how a `fovea render` job is split over MPI ranks (docs/distributed.md): a still's sample
 * blocks (still.c) and a sequence's frames (frames.c). */
#ifndef FV_DIST_SPLIT_H
#define FV_DIST_SPLIT_H

#include <stdbool.h>
#include "dist/dist.h"
#include "fovea/drive.h"
#include "fovea/film.h"
#include "fovea/params.h"
#include "fovea/stats.h"

/* ---- a still ---- */
typedef struct fv_dist_still_job {
    const char *method;      /* the method's name */
    const fv_params *params; /* its parameters (cloned per range; the bag is not changed) */
    const fv_scene *scene;
    const fv_log *log;
    fv_driver *driver;       /* frame `frame` of it is the still */
    int spp;                 /* the method's samples per pixel (pt) or passes (ppm); 0: its default */
    bool other_device;       /* a device other than the cpu was asked for */
    fv_progress_fn progress; /* every rank's progress through its own share (optional) */
    void *progress_user;
    int frame;               /* the driver's frame that is the still (0 for `fovea render`) */
} fv_dist_still_job;

/* A job for frame `frame` of driver with method and params, spp and other_device read from the
 * parameters (the method's samples-per-pixel parameter, a device other than "cpu"). */
void fv_dist_still_job_init(fv_dist_still_job *job, const char *method, const fv_params *params, const fv_scene *scene, const fv_log *log,
                            fv_driver *driver, int frame);

/* Rank `rank`'s share of the still's work when it is split (its sample blocks over all). */
double fv_dist_still_share(const fv_dist_still_job *job, int rank, int size);
/* True when the still is split over `size` ranks: pt on the cpu or ppm with more than one block
 * of samples or passes. Otherwise rank 0 renders it alone. */
bool fv_dist_still_splits(const fv_dist_still_job *job, int size);
/* Renders the still over all ranks into films (one per eye: both eyes of a stereo still are split
 * by the same sample blocks). On rank 0 the films then hold the images, bit for bit the one-process
 * images; elsewhere they hold nothing to write. Stats on rank 0 count every rank's rays and
 * samples. Ends with the job's status on every rank (*print_it: this rank prints
 * err's line, starting "rank R: " when *name_rank; fv_dist_agree). */
fv_status fv_dist_still(fv_dist *d, const fv_dist_still_job *job, fv_film *const *films, int neyes, fv_stats *stats, bool *print_it,
                        bool *name_rank, fv_error *err);

/* ---- a sequence ---- */
/* Rank `rank` of `size` writes frames [*first, *end) of `frames`, contiguous blocks in rank order;
 * a method with temporal state renders from *start = first - warmup (not before 0) without writing
 * the warm-up frames, so each block's history is rebuilt as the method needs. */
void fv_dist_frames(int frames, int rank, int size, int warmup, int *start, int *first, int *end);
/* Rank `rank`'s share of a sequence's work: the frames it renders (its warm-up frames and, for the
 * block that starts at frame 0, the still's warm-up frames too) over every rank's. */
double fv_dist_frames_share(int frames, int rank, int size, int warmup, int still_warmup);
/* Rank 0 writes how the sequence was split (ranks, each block, the warm-up) as JSON next to the
 * frames, whole or not at all. */
fv_status fv_dist_frames_manifest(const char *path, const char *method, int frames, int size, int warmup, fv_error *err);

#endif
