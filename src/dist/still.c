/* fovea — one still over MPI ranks (docs/distributed.md, "A still"): pt's sample blocks or ppm's
 * blocks of passes (core/blocks.h) dealt to ranks as contiguous ranges, each range rendered as the
 * tree nodes that cover it, their double sums sent to rank 0, which evaluates the rest of the tree
 * in its fixed order. The image is therefore the one-process image bit for bit, whatever the number of ranks
 * (the one-process render sums the same nodes in the same order, only on one machine).
 *
 * Rank 0 always holds block 0, whose first samples give the auxiliary buffers (depth, normal,
 * albedo, id, position), so the EXR's layers are the one-process ones too.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/blocks.h"
#include "dist/dist.h"
#include "dist/split.h"
#include "film/film_sums.h"

/* Each rank's share of nb blocks: [lo, hi), rounded up so that rank 0 always holds block 0 (and
 * with it the auxiliary buffers) even with more ranks than blocks. */
static void share(int nb, int rank, int size, int *lo, int *hi)
{
    *lo = (int)(((long long)nb * rank + size - 1) / size);
    *hi = (int)(((long long)nb * (rank + 1) + size - 1) / size);
}

/* Progress through this rank's own nodes (dist_progress.h adds the ranks' shares up), stopping when
 * another rank failed. */
typedef struct node_progress {
    fv_dist *d;
    fv_progress_fn fn;
    void *user;
    double base, span;
} node_progress;

static bool on_progress(void *user, double f)
{
    node_progress *p = user;
    if (fv_dist_poll(p->d)) return false;
    return !p->fn || p->fn(p->user, p->base + p->span * f);
}

void fv_dist_still_job_init(fv_dist_still_job *job, const char *method, const fv_params *params, const fv_scene *scene, const fv_log *log,
                            fv_driver *driver, int frame)
{
    *job = (fv_dist_still_job){.method = method, .params = params, .scene = scene, .log = log, .driver = driver, .frame = frame};
    const char *spp_key = fv_technique_spp_param(fv_technique_index(method));
    for (int i = 0; i < fv_params_count(params); i++) {
        const char *k = fv_params_key(params, i), *v = fv_params_value(params, i);
        if (spp_key && !strcmp(k, spp_key)) job->spp = atoi(v);
        if (!strcmp(k, "device") && strcmp(v, "cpu")) job->other_device = true;
    }
}

double fv_dist_still_share(const fv_dist_still_job *job, int rank, int size)
{
    const int nb = fv_blocks_count(job->spp);
    int lo, hi;
    share(nb, rank, size, &lo, &hi);
    return nb > 0 ? (double)(hi - lo) / nb : 0.0;
}

bool fv_dist_still_splits(const fv_dist_still_job *job, int size)
{
    /* the methods whose estimate is core/blocks.h's sum (their class says so): pt's samples, ppm's passes */
    const bool blocked = fv_technique_block_unit(fv_technique_index(job->method)) != NULL;
    return size > 1 && job->spp > FV_SAMPLE_BLOCK && blocked && !job->other_device;
}

static fv_status render_node(const fv_dist_still_job *job, int lo, int hi, fv_film *const *films, fv_stats *stats,
                             node_progress *prog, fv_error *err)
{
    fv_params *p = NULL;
    fv_technique *t = NULL;
    char v[32];
    fv_status s = fv_params_clone(job->params, &p, err);
    if (s == FV_OK) snprintf(v, sizeof v, "%d", lo), s = fv_params_set(p, "block_first", v, err);
    if (s == FV_OK) snprintf(v, sizeof v, "%d", hi - lo), s = fv_params_set(p, "block_count", v, err);
    if (s == FV_OK) s = fv_technique_create(job->method, job->scene, p, job->log, &t, err);
    if (s == FV_OK) s = fv_driver_render(job->driver, t, job->frame, false, films, stats, on_progress, prog, err);
    fv_technique_destroy(t);
    fv_params_destroy(p);
    return s;
}

fv_status fv_dist_still(fv_dist *d, const fv_dist_still_job *job, fv_film *const *films, int neyes, fv_stats *stats, bool *print_it,
                        bool *name_rank, fv_error *err)
{
    const int rank = fv_dist_rank(d), size = fv_dist_size(d);
    const int nb = fv_blocks_count(job->spp);
    /* a node's sums: every eye's image, eye after eye */
    const size_t npix = (size_t)fv_film_width(films[0]) * (size_t)fv_film_height(films[0]), nval = (size_t)neyes * npix * 3;
    int (*nodes)[2] = NULL, *owner = NULL, *ops = NULL;
    double **vals = NULL;
    int nnodes = 0, mine0 = -1, mine1 = -1;
    *print_it = *name_rank = false;
    fv_status s = FV_OK;

    /* Every rank lists every rank's nodes: the same cover, so the plan is known everywhere. */
    const int cap = size * 2 * FV_BLOCKS_MAX_DEPTH;
    nodes = fv_calloc_array((size_t)cap, sizeof *nodes);
    owner = fv_calloc_array((size_t)cap, sizeof *owner);
    vals = fv_calloc_array((size_t)cap, sizeof *vals);
    if (!nodes || !owner || !vals) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    for (int r = 0; r < size && s == FV_OK; r++) {
        int lo, hi;
        share(nb, r, size, &lo, &hi);
        if (r == rank) mine0 = nnodes;
        int k = lo < hi ? fv_blocks_cover(nb, lo, hi, nodes + nnodes, cap - nnodes) : 0;
        for (int i = 0; i < k; i++) owner[nnodes + i] = r;
        nnodes += k;
        if (r == rank) mine1 = nnodes;
    }
    for (int e = 0; e < neyes && s == FV_OK; e++) s = fv_film_want_sums(films[e], err);

    /* This rank's nodes in block order (only block 0's range writes the auxiliary buffers). */
    int my_blocks = 0;
    for (int k = mine0; k < mine1; k++) my_blocks += nodes[k][1] - nodes[k][0];
    node_progress prog = {d, job->progress, job->progress_user, 0.0, 0.0};
    for (int i = 0; i < mine1 - mine0 && s == FV_OK; i++) {
        int k = mine0 + i;
        int n = nodes[k][1] - nodes[k][0];
        prog.span = my_blocks > 0 ? (double)n / my_blocks : 1.0;
        if ((s = render_node(job, nodes[k][0], nodes[k][1], films, stats, &prog, err)) != FV_OK) break;
        prog.base += prog.span;
        if (!(vals[k] = fv_alloc_array(nval, sizeof(double)))) {
            s = fv_error_set(err, FV_ERR_NOMEM, "out of memory keeping %d sample blocks of a %zu-pixel image", n, npix);
            break;
        }
        for (int e = 0; e < neyes; e++) memcpy(vals[k] + (size_t)e * npix * 3, fv_film_sums(films[e]), npix * 3 * sizeof(double));
    }

    /* Nothing moves until every rank has its nodes. */
    s = fv_dist_agree(d, s, print_it, name_rank, err);
    const bool agreed = s == FV_OK;
    /* The job's counters: every rank's rays and samples (order-free sums of integers). */
    static const char *const counted[] = {"rays", "samples", "nan_samples"};
    double mine[3], total[3];
    for (int i = 0; i < 3; i++) mine[i] = total[i] = fv_stats_get_count(stats, counted[i]);
    if (s == FV_OK && (s = fv_dist_sum(d, total, 3, err)) == FV_OK)
        for (int i = 0; i < 3; i++) fv_stats_add_count(stats, counted[i], total[i] - mine[i]);
    if (s == FV_OK && rank != 0) {
        for (int k = mine0; k < mine1 && s == FV_OK; k++) s = fv_dist_send(d, 0, vals[k], nval, err);
    } else if (s == FV_OK) {
        for (int k = 0; k < nnodes && s == FV_OK; k++) {
            if (owner[k] == 0) continue;
            if (!(vals[k] = fv_alloc_array(nval, sizeof(double)))) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            else s = fv_dist_recv(d, owner[k], vals[k], nval, err);
        }
        int nops = 0;
        if (s == FV_OK) {
            int opcap = 4 * nnodes + 4;
            if (!(ops = fv_calloc_array((size_t)opcap, sizeof *ops))) s = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            else if ((nops = fv_blocks_plan(nb, (const int(*)[2])nodes, nnodes, ops, opcap)) < 0)
                s = fv_error_set(err, FV_ERR_INTERNAL, "the ranks' sample blocks do not cover the tree");
        }
        double bad = 0.0;
        for (int e = 0; e < neyes && s == FV_OK; e++) {
            float *color = fv_film_color(films[e]);
            for (size_t i = 0; i < npix; i++) {
                double t[3];
                fv_blocks_run(ops, nops, (const double *const *)vals, (size_t)e * npix + i, t);
                bad += fv_blocks_pixel(t, job->spp, color + 3 * i);
            }
        }
        if (s == FV_OK) fv_stats_add_count(stats, "nan_samples", bad);
    }
    /* a transfer failed after the agreement: said by the rank it happened on */
    if (agreed && s != FV_OK) *print_it = *name_rank = true;
    for (int k = 0; vals && k < nnodes; k++) free(vals[k]);
    free(vals);
    free(ops);
    free(owner);
    free(nodes);
    return s;
}
