/* fovea — gaze over time: fixed, keyframed, or a recorded eye-tracker trace (CSV).
 *
 * A trace is interpolated linearly between samples and held at its ends, so a trace recorded at
 * the tracker's rate can drive frames at any rate. Real recordings have blinks and track loss: a
 * sample whose coordinates are missing (an empty field or nan, docs/gaze.md) marks the gaze as
 * unknown from its time until the next known sample. While unknown, the gaze holds the last known
 * one (the first known one before any), and eval says it is unknown so the driver can apply its
 * policy (hold, or widen the fovea to the whole screen). A known sample next to a missing one is
 * not interpolated towards it. Limits: no saccade detection or filtering; a trace is read whole
 * into memory.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include "core/alloc.h"
#include "core/csv.h"
#include "fovea/gaze.h"

struct fv_gaze_path {
    fv_gaze_key *keys;     /* a missing eye holds the last known gaze (see the banner) */
    uint8_t *known;        /* per key: bit 0 left eye known, bit 1 right eye known */
    int count;
    fv_gaze_missing missing;
};

static bool gaze_ok(fv_gaze g)
{
    return g.x >= 0.0f && g.x <= 1.0f && g.y >= 0.0f && g.y <= 1.0f; /* false for NaN too */
}

static bool gaze_missing(fv_gaze g) { return isnan(g.x) || isnan(g.y); }

fv_status fv_gaze_path_create_keys(const fv_gaze_key *keys, int count, fv_gaze_path **out, fv_error *err)
{
    if (count < 1) return fv_error_set(err, FV_ERR_INVALID, "gaze path: no keys");
    int known_l = -1, known_r = -1;
    for (int i = 0; i < count; i++) {
        if (!isfinite(keys[i].time))
            return fv_error_set(err, FV_ERR_INVALID, "gaze path: key %d has a non-finite time", i);
        const fv_gaze *e[2] = {&keys[i].left, &keys[i].right};
        for (int k = 0; k < 2; k++)
            if (!gaze_missing(*e[k]) && !gaze_ok(*e[k]))
                return fv_error_set(err, FV_ERR_INVALID, "gaze path: key %d: gaze (%g,%g) is outside [0,1]", i, e[k]->x, e[k]->y);
        if (known_l < 0 && !gaze_missing(keys[i].left)) known_l = i;
        if (known_r < 0 && !gaze_missing(keys[i].right)) known_r = i;
        if (i > 0 && !(keys[i].time > keys[i - 1].time))
            return fv_error_set(err, FV_ERR_INVALID, "gaze path: key times must increase (key %d at %g after %g)", i,
                                keys[i].time, keys[i - 1].time);
    }
    if (known_l < 0 || known_r < 0)
        return fv_error_set(err, FV_ERR_INVALID, "gaze path: every sample of the %s eye is missing", known_l < 0 ? "left" : "right");
    fv_gaze_path *p = calloc(1, sizeof *p);
    if (p) p->keys = fv_alloc_array((size_t)count, sizeof *p->keys);
    if (p) p->known = fv_alloc_array((size_t)count, 1);
    if (!p || !p->keys || !p->known) {
        if (p) free(p->keys);
        free(p);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for a gaze path of %d keys", count);
    }
    /* Missing eyes hold the last known gaze, or the first known one before any. */
    fv_gaze hold_l = keys[known_l].left, hold_r = keys[known_r].right;
    for (int i = 0; i < count; i++) {
        p->keys[i] = keys[i];
        p->known[i] = 0;
        if (gaze_missing(keys[i].left)) p->keys[i].left = hold_l;
        else hold_l = keys[i].left, p->known[i] |= 1;
        if (gaze_missing(keys[i].right)) p->keys[i].right = hold_r;
        else hold_r = keys[i].right, p->known[i] |= 2;
    }
    p->count = count;
    p->missing = FV_GAZE_MISSING_HOLD;
    *out = p;
    return FV_OK;
}

void fv_gaze_path_set_missing(fv_gaze_path *p, fv_gaze_missing policy)
{
    p->missing = policy == FV_GAZE_MISSING_WIDEN ? FV_GAZE_MISSING_WIDEN : FV_GAZE_MISSING_HOLD;
}

fv_gaze_missing fv_gaze_path_missing(const fv_gaze_path *p) { return p->missing; }

bool fv_gaze_missing_from_name(const char *name, fv_gaze_missing *out)
{
    if (strcmp(name, "hold") == 0) *out = FV_GAZE_MISSING_HOLD;
    else if (strcmp(name, "widen") == 0) *out = FV_GAZE_MISSING_WIDEN;
    else return false;
    return true;
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
    free(p->known);
    free(p);
}

int fv_gaze_path_key_count(const fv_gaze_path *p) { return p->count; }

static fv_gaze lerp_gaze(fv_gaze a, fv_gaze b, float t)
{
    return (fv_gaze){a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

bool fv_gaze_path_eval(const fv_gaze_path *p, double t, fv_gaze *left, fv_gaze *right)
{
    const fv_gaze_key *k = p->keys;
    int n = p->count, a = 0, b = 0;
    float u = 0.0f;
    if (n > 1 && t >= k[n - 1].time) {
        a = b = n - 1;
    } else if (n > 1 && t > k[0].time) {
        /* Binary search: traces can hold tens of thousands of samples. */
        int lo = 0, hi = n - 1;
        while (hi - lo > 1) {
            int mid = (lo + hi) / 2;
            if (k[mid].time <= t) lo = mid;
            else hi = mid;
        }
        a = lo;
        b = hi;
        u = (float)((t - k[a].time) / (k[b].time - k[a].time));
    }
    /* Interpolate an eye only between two known samples; else hold the sample at or before t
     * (its held value when it is missing). */
    uint8_t ka = p->known[a], kb = p->known[b];
    if (left) *left = (ka & kb & 1) ? lerp_gaze(k[a].left, k[b].left, u) : k[a].left;
    if (right) *right = (ka & kb & 2) ? lerp_gaze(k[a].right, k[b].right, u) : k[a].right;
    return ka == 3;
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
    /* A missing coordinate (empty or nan) makes that eye's sample missing. */
    if (gaze_missing(k.left)) k.left = (fv_gaze){NAN, NAN};
    if (gaze_missing(k.right)) k.right = (fv_gaze){NAN, NAN};
    if ((!gaze_missing(k.left) && !gaze_ok(k.left)) || (!gaze_missing(k.right) && !gaze_ok(k.right)))
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: gaze coordinates must be in [0,1] (or empty or nan for a missing sample)", path, line);
    if (fv_grow((void **)&g->keys, &g->cap, g->n + 1, sizeof *g->keys)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    g->keys[g->n++] = k;
    return FV_OK;
}

fv_status fv_gaze_path_load_csv(const char *path, fv_gaze_path **out, fv_error *err)
{
    gaze_rows g = {NULL, 0, 0, 0};
    fv_status st = fv_csv_read(path, "gaze trace", 6, "'time,x,y' or 'time,xl,yl,xr,yr' numbers", gaze_row, &g, err);
    if (st == FV_OK && (st = fv_gaze_path_create_keys(g.keys, g.n, out, err)) != FV_OK) fv_error_prefix(err, "%s: ", path);
    free(g.keys);
    return st;
}
