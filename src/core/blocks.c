/* fovea — the summation tree over sample blocks (blocks.h): covers of a range by tree nodes and
 * the plan that evaluates the tree from them. */
#include <stddef.h>
#include "core/blocks.h"

static int cover(int lo, int hi, int a, int b, int (*nodes)[2], int cap, int count)
{
    if (b <= lo || a >= hi || count < 0) return count;
    if (a <= lo && hi <= b) {
        if (count >= cap) return -1;
        nodes[count][0] = lo, nodes[count][1] = hi;
        return count + 1;
    }
    int mid = fv_blocks_mid(lo, hi);
    count = cover(lo, mid, a, b, nodes, cap, count);
    return cover(mid, hi, a, b, nodes, cap, count);
}

int fv_blocks_cover(int n, int lo, int hi, int (*nodes)[2], int cap)
{
    if (n < 1 || lo < 0 || hi > n || lo >= hi) return 0;
    return cover(0, n, lo, hi, nodes, cap, 0);
}

static int plan(int lo, int hi, const int (*nodes)[2], int count, int *ops, int cap, int nops)
{
    if (nops < 0) return -1;
    for (int k = 0; k < count; k++)
        if (nodes[k][0] == lo && nodes[k][1] == hi) {
            if (nops >= cap) return -1;
            ops[nops] = k;
            return nops + 1;
        }
    if (hi - lo < 2) return -1; /* a block no node holds: not a cover */
    int mid = fv_blocks_mid(lo, hi);
    nops = plan(lo, mid, nodes, count, ops, cap, nops);
    nops = plan(mid, hi, nodes, count, ops, cap, nops);
    if (nops < 0 || nops >= cap) return -1;
    ops[nops] = -1;
    return nops + 1;
}

int fv_blocks_plan(int n, const int (*nodes)[2], int count, int *ops, int cap)
{
    return n < 1 ? -1 : plan(0, n, nodes, count, ops, cap, 0);
}

void fv_blocks_run(const int *ops, int nops, const double *const *vals, size_t pix, double out[3])
{
    double st[2 * FV_BLOCKS_MAX_DEPTH + 2][3];
    int n = 0;
    for (int i = 0; i < nops; i++) {
        if (ops[i] >= 0) {
            const double *v = vals[ops[i]] + 3 * pix;
            st[n][0] = v[0], st[n][1] = v[1], st[n][2] = v[2];
            n++;
        } else {
            n--;
            /* left + right, the order the tree defines */
            st[n - 1][0] += st[n][0], st[n - 1][1] += st[n][1], st[n - 1][2] += st[n][2];
        }
    }
    out[0] = st[0][0], out[1] = st[0][1], out[2] = st[0][2];
}
