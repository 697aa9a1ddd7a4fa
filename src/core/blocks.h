/* fovea — sample blocks and the one summation tree over them.
 *
 * A pixel's estimate over many samples is defined, once, as a sum whose shape does not depend on
 * who computed which part, so that a still split over processes (src/dist) is bit-identical to
 * the one-process render with the same seed:
 *   - samples are cut into blocks of FV_SAMPLE_BLOCK in sample-index order; a block's samples are
 *     added in float, in order (what pt always did, so a render of one block is unchanged);
 *   - blocks are added in double along a fixed binary tree: the node over blocks [lo, hi) is the
 *     sum of its children [lo, mid) and [mid, hi), mid = lo + the largest power of two below
 *     hi - lo (pairwise summation, Higham, "The accuracy of floating point summation", SIAM J.
 *     Sci. Comput. 14(4), 1993: error growing with log2 of the block count, not linearly);
 *   - the pixel is that double root divided by the sample count, rounded to float once.
 * Any range of blocks is a union of tree nodes (fv_blocks_cover): a process renders the nodes of
 * its range, and whoever holds every node's value evaluates the rest of the tree in the same
 * order. The binary-counter accumulator below computes a node's value while streaming its blocks
 * left to right (equal to the recursive definition for any node, which starts aligned).
 */
#ifndef FV_CORE_BLOCKS_H
#define FV_CORE_BLOCKS_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* Samples per block: pt's renders up to 64 spp (its default and every test's) stay one block, so
 * their images are those of the plain float loop. */
#define FV_SAMPLE_BLOCK 64
/* Deep enough for 2^30 blocks: more than any sample count the CLI accepts. */
#define FV_BLOCKS_MAX_DEPTH 32

static inline int fv_blocks_count(int spp) { return (spp + FV_SAMPLE_BLOCK - 1) / FV_SAMPLE_BLOCK; }

/* Samples in block b of an spp-sample estimate (the last block may be short). */
static inline int fv_blocks_samples(int spp, int b)
{
    int rest = spp - b * FV_SAMPLE_BLOCK;
    return rest < FV_SAMPLE_BLOCK ? rest : FV_SAMPLE_BLOCK;
}

/* Where the node [lo, hi) (hi - lo >= 2) splits. */
static inline int fv_blocks_mid(int lo, int hi)
{
    int p = 1;
    while (2 * p < hi - lo) p *= 2;
    return lo + p;
}

/* The maximal tree nodes inside [lo, hi) of the tree over [0, n), left to right, into nodes (pairs
 * lo, hi); returns their count (at most 2 * FV_BLOCKS_MAX_DEPTH). */
int fv_blocks_cover(int n, int lo, int hi, int (*nodes)[2], int cap);

/* Streams one node's blocks: push each block's sum (one colour channel triple) left to right,
 * then fv_blocks_acc_total. Sizes on the stack are powers of two merged as a binary counter, the
 * last fold runs right to left: exactly the tree's order. */
typedef struct fv_blocks_acc {
    double v[FV_BLOCKS_MAX_DEPTH][3];
    int size[FV_BLOCKS_MAX_DEPTH];
    int n;
} fv_blocks_acc;

static inline void fv_blocks_acc_push(fv_blocks_acc *a, double x, double y, double z)
{
    int k = a->n++;
    a->v[k][0] = x, a->v[k][1] = y, a->v[k][2] = z;
    a->size[k] = 1;
    while (a->n >= 2 && a->size[a->n - 1] == a->size[a->n - 2]) {
        int r = --a->n, l = r - 1;
        a->v[l][0] += a->v[r][0], a->v[l][1] += a->v[r][1], a->v[l][2] += a->v[r][2];
        a->size[l] *= 2;
    }
}

static inline void fv_blocks_acc_total(const fv_blocks_acc *a, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    if (a->n == 0) return;
    int k = a->n - 1;
    out[0] = a->v[k][0], out[1] = a->v[k][1], out[2] = a->v[k][2];
    while (k-- > 0) out[0] = a->v[k][0] + out[0], out[1] = a->v[k][1] + out[1], out[2] = a->v[k][2] + out[2];
}

/* A pixel from its root: the double sum over `samples` samples divided once and rounded to float;
 * not finite (finite samples can still sum past the float range) -> black, returning 1 to count. */
static inline int fv_blocks_pixel(const double t[3], int samples, float out[3])
{
    for (int c = 0; c < 3; c++) out[c] = (float)(t[c] / (double)samples);
    if (isfinite(out[0]) && isfinite(out[1]) && isfinite(out[2])) return 0;
    out[0] = out[1] = out[2] = 0.0f;
    return 1;
}

/* A plan that evaluates the tree over [0, n) from the values of a cover of it (fv_blocks_cover's
 * nodes, in order): a postfix program of "push node k" (k >= 0) and "add the top two" (-1). */
int fv_blocks_plan(int n, const int (*nodes)[2], int count, int *ops, int cap);
/* Runs the plan for one value per node (vals[k], 3 doubles each) into out. */
void fv_blocks_run(const int *ops, int nops, const double *const *vals, size_t pix, double out[3]);

#endif
