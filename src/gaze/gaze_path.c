/* fovea — gaze over time: fixed, keyframed, or a recorded eye-tracker trace (CSV).
 *
 * A trace is interpolated linearly between samples and held at its ends, so a trace recorded at
 * the tracker's rate can drive frames at any rate. Limits: no saccade detection or filtering; a
 * trace is read whole into memory.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/csv.h"
#include "fovea/gaze.h"

struct fv_gaze_path {
    fv_gaze_key *keys;
    int count;
};

static bool gaze_ok(fv_gaze g)
{
    return g.x >= 0.0f && g.x <= 1.0f && g.y >= 0.0f && g.y <= 1.0f; /* false for NaN too */
}

fv_status fv_gaze_path_create_keys(const fv_gaze_key *keys, int count, fv_gaze_path **out, fv_error *err)
{
    if (count < 1) return fv_error_set(err, FV_ERR_INVALID, "gaze path: no keys");
    for (int i = 0; i < count; i++) {
        if (!isfinite(keys[i].time))
            return fv_error_set(err, FV_ERR_INVALID, "gaze path: key %d has a non-finite time", i);
        if (!gaze_ok(keys[i].left) || !gaze_ok(keys[i].right))
            return fv_error_set(err, FV_ERR_INVALID, "gaze path: key %d: gaze (%g,%g) is outside [0,1]", i,
                                gaze_ok(keys[i].left) ? keys[i].right.x : keys[i].left.x,
                                gaze_ok(keys[i].left) ? keys[i].right.y : keys[i].left.y);
        if (i > 0 && !(keys[i].time > keys[i - 1].time))
            return fv_error_set(err, FV_ERR_INVALID, "gaze path: key times must increase (key %d at %g after %g)", i,
                                keys[i].time, keys[i - 1].time);
    }
    fv_gaze_path *p = calloc(1, sizeof *p);
    if (p) p->keys = fv_alloc_array((size_t)count, sizeof *p->keys);
    if (!p || !p->keys) {
        free(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a gaze path of %d keys", count);
    }
    memcpy(p->keys, keys, (size_t)count * sizeof *keys);
    p->count = count;
    *out = p;
    return FV_OK;
}

fv_status fv_gaze_path_create_fixed(fv_gaze g, fv_gaze_path **out, fv_error *err)
{
    fv_gaze_key k = {0.0, g, g};
    return fv_gaze_path_create_keys(&k, 1, out, err);
}

void fv_gaze_path_destroy(fv_gaze_path *p)
{
    if (!p) return;
    free(p->keys);
    free(p);
}

int fv_gaze_path_key_count(const fv_gaze_path *p) { return p->count; }

static fv_gaze lerp_gaze(fv_gaze a, fv_gaze b, float t)
{
    return (fv_gaze){a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

void fv_gaze_path_eval(const fv_gaze_path *p, double t, fv_gaze *left, fv_gaze *right)
{
    const fv_gaze_key *k = p->keys;
    int n = p->count;
    const fv_gaze_key *a = &k[0], *b = &k[0];
    float u = 0.0f;
    if (n > 1 && t >= k[n - 1].time) {
        a = b = &k[n - 1];
    } else if (n > 1 && t > k[0].time) {
        /* Binary search: traces can hold tens of thousands of samples. */
        int lo = 0, hi = n - 1;
        while (hi - lo > 1) {
            int mid = (lo + hi) / 2;
            if (k[mid].time <= t) lo = mid;
            else hi = mid;
        }
        a = &k[lo];
        b = &k[hi];
        u = (float)((t - a->time) / (b->time - a->time));
    }
    if (left) *left = lerp_gaze(a->left, b->left, u);
    if (right) *right = lerp_gaze(a->right, b->right, u);
}

typedef struct gaze_rows {
    fv_gaze_key *keys;
    int n, cap, columns;
} gaze_rows;

static fv_status gaze_row(void *ctx, const double *v, int c, const char *path, int line, fv_error *err)
{
    gaze_rows *g = ctx;
    if (c != 3 && c != 5) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected 'time,x,y' or 'time,xl,yl,xr,yr' numbers", path, line);
    if (g->columns && c != g->columns)
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: %d columns where earlier lines have %d", path, line, c, g->columns);
    g->columns = c;
    fv_gaze_key k;
    k.time = v[0];
    k.left = (fv_gaze){(float)v[1], (float)v[2]};
    k.right = c == 5 ? (fv_gaze){(float)v[3], (float)v[4]} : k.left;
    if (!gaze_ok(k.left) || !gaze_ok(k.right))
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: gaze coordinates must be in [0,1]", path, line);
    if (fv_grow((void **)&g->keys, &g->cap, g->n + 1, sizeof *g->keys)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    g->keys[g->n++] = k;
    return FV_OK;
}

fv_status fv_gaze_path_load_csv(const char *path, fv_gaze_path **out, fv_error *err)
{
    gaze_rows g = {NULL, 0, 0, 0};
    fv_status st = fv_csv_read(path, "gaze trace", 6, "'time,x,y' or 'time,xl,yl,xr,yr' numbers", gaze_row, &g, err);
    if (st == FV_OK) st = fv_gaze_path_create_keys(g.keys, g.n, out, err);
    free(g.keys);
    return st;
}
