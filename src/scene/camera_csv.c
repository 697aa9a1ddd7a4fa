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

fv_status fv_camera_path_load_csv(const char *path, const fv_camera *base, fv_camera_key **keys_out, int *count, fv_error *err)
{
    FILE *f = fopen(path, "r");
    if (!f) return fv_error_set(err, FV_ERR_IO, "cannot open camera trace '%s': %s", path, strerror(errno));
    fv_camera_key *keys = NULL;
    int n = 0, cap = 0, lineno = 0;
    bool before = true;
    char *line = NULL;
    size_t linecap = 0;
    fv_status st = FV_OK;
    while (getline(&line, &linecap, f) >= 0) {
        lineno++;
        double v[12];
        int c = 0;
        fv_csv_kind kind = fv_csv_line(line, before, v, 11, &c);
        if (kind == FV_CSV_SKIP) continue;
        before = false;
        if (kind == FV_CSV_HEADER) continue;
        if (kind == FV_CSV_BAD || (c != 7 && c != 10 && c != 11)) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: expected time,px,py,pz,lx,ly,lz[,ux,uy,uz[,fov]]", path, lineno);
            goto done;
        }
        fv_camera_key k;
        k.time = v[0];
        k.pos = fv_v3((float)v[1], (float)v[2], (float)v[3]);
        k.look = fv_v3((float)v[4], (float)v[5], (float)v[6]);
        k.up = c >= 10 ? fv_v3((float)v[7], (float)v[8], (float)v[9]) : base->up;
        k.fov_y = c == 11 ? (float)v[10] : base->fov_y;
        fv_camera cam = {k.pos, k.look, k.up, k.fov_y, 1, 1};
        fv_camera_basis b;
        fv_error e2;
        if (!isfinite(k.time) || fv_camera_basis_make(&cam, &b, &e2) != FV_OK) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s:%d: not a valid camera (%s)", path, lineno, isfinite(k.time) ? e2.msg : "time is not finite");
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
    if (n == 0) st = fv_error_set(err, FV_ERR_INVALID, "%s: the camera trace has no samples", path);
done:
    free(line);
    fclose(f);
    if (st != FV_OK) {
        free(keys);
        return st;
    }
    *keys_out = keys;
    *count = n;
    return FV_OK;
}
