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

fv_status fv_gaze_path_load_csv(const char *path, fv_gaze_path **out, fv_error *err)
{
    FILE *f = fopen(path, "r");
    if (!f) return fv_error_set(err, FV_ERR_IO, "cannot open gaze trace '%s': %s", path, strerror(errno));
    fv_gaze_key *keys = NULL;
    int n = 0, cap = 0, columns = 0, lineno = 0;
    bool seen_data_or_header = false;
    char *line = NULL;
    size_t linecap = 0;
    fv_status st = FV_OK;
    while (getline(&line, &linecap, f) >= 0) {
        lineno++;
        double v[6];
        int c = 0;
        fv_csv_kind kind = fv_csv_line(line, !seen_data_or_header, v, 5, &c);
        if (kind == FV_CSV_SKIP) continue;
        if (kind == FV_CSV_HEADER) {
            seen_data_or_header = true;
            continue;
        }
        seen_data_or_header = true;
        if (kind == FV_CSV_BAD || (c != 3 && c != 5)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected 'time,x,y' or 'time,xl,yl,xr,yr' numbers", path, lineno);
            goto done;
        }
        if (columns && c != columns) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: %d columns where earlier lines have %d", path, lineno, c, columns);
            goto done;
        }
        columns = c;
        fv_gaze_key k;
        k.time = v[0];
        k.left = (fv_gaze){(float)v[1], (float)v[2]};
        k.right = c == 5 ? (fv_gaze){(float)v[3], (float)v[4]} : k.left;
        if (!isfinite(k.time) || !gaze_ok(k.left) || !gaze_ok(k.right)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: time must be finite and gaze coordinates in [0,1]", path, lineno);
            goto done;
        }
        if (n > 0 && !(k.time > keys[n - 1].time)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: time %g does not increase (previous %g)", path, lineno, k.time, keys[n - 1].time);
            goto done;
        }
        if (fv_grow((void **)&keys, &cap, n + 1, sizeof *keys)) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
            goto done;
        }
        keys[n++] = k;
    }
    if (ferror(f)) {
        st = fv_error_set(err, FV_ERR_IO, "cannot read gaze trace '%s': %s", path, strerror(errno));
        goto done;
    }
    if (n == 0) {
        st = fv_error_set(err, FV_ERR_INVALID, "%s: the gaze trace has no samples", path);
        goto done;
    }
    st = fv_gaze_path_create_keys(keys, n, out, err);
done:
    free(line);
    free(keys);
    fclose(f);
    return st;
}
