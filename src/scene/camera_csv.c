/* fovea — camera paths from recorded traces (CSV; docs/gaze.md gives the format): one key per
 * line, "time,px,py,pz,lx,ly,lz" with optional "ux,uy,uz" and then "fov" columns. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "core/csv.h"
#include "fovea/camera.h"
#include "fovea/limits.h"

typedef struct camera_rows {
    const fv_camera *base;
    fv_camera_key *keys;
    int n, cap;
} camera_rows;

static fv_status camera_row(void *ctx, const double *v, int c, const char *path, int line, fv_error *err)
{
    camera_rows *r = ctx;
    if (c != 7 && c != 10 && c != 11) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected time,px,py,pz,lx,ly,lz[,ux,uy,uz[,fov]]", path, line);
    /* Checked as read, before the float conversion turns 1e39 into inf (fovea/limits.h). */
    char what[4200];
    snprintf(what, sizeof what, "%s:%d", path, line);
    fv_status st = fv_limit_coords(what, v + 1, c >= 10 ? 9 : 6, err);
    if (st != FV_OK) return st;
    fv_camera_key k;
    k.time = v[0];
    k.pos = fv_v3((float)v[1], (float)v[2], (float)v[3]);
    k.look = fv_v3((float)v[4], (float)v[5], (float)v[6]);
    k.up = c >= 10 ? fv_v3((float)v[7], (float)v[8], (float)v[9]) : r->base->up;
    k.fov_y = c == 11 ? (float)v[10] : r->base->fov_y;
    fv_camera cam = {k.pos, k.look, k.up, k.fov_y, 1, 1};
    fv_camera_basis b;
    fv_error e2;
    if (fv_camera_basis_make(&cam, &b, &e2) != FV_OK) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: not a valid camera (%s)", path, line, e2.msg);
    if (fv_grow((void **)&r->keys, &r->cap, r->n + 1, sizeof *r->keys)) return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    r->keys[r->n++] = k;
    return FV_OK;
}

fv_status fv_camera_path_load_csv(const char *path, const fv_camera *base, fv_camera_key **keys_out, int *count, fv_error *err)
{
    camera_rows r = {base, NULL, 0, 0};
    fv_status st = fv_csv_read(path, "camera trace", 12, "time,px,py,pz,lx,ly,lz[,ux,uy,uz[,fov]]", camera_row, &r, err);
    if (st != FV_OK) {
        free(r.keys);
        return st;
    }
    *keys_out = r.keys;
    *count = r.n;
    return FV_OK;
}

void fv_camera_keys_free(fv_camera_key *keys) { free(keys); }
