/* fovea-view — recording (key R): the gaze and the camera of every frame, in the CSV formats
 * `fovea render --gaze-trace` and `--camera-trace` read (docs/gaze.md), with the scene time as
 * the time column, so `fovea render --time T0 --fps F --frames N --gaze-trace ... --camera-trace
 * ...` replays the session and `fovea bench` can measure it. */
#include <stdio.h>
#include "view.h"

fv_status fv_vw_record_start(fv_vw_record *r, fv_error *err)
{
    char g[64], c[64];
    r->take++;
    snprintf(g, sizeof g, "fovea-view-gaze-%03d.csv", r->take);
    snprintf(c, sizeof c, "fovea-view-camera-%03d.csv", r->take);
    r->gaze = fopen(g, "w");
    r->camera = r->gaze ? fopen(c, "w") : NULL;
    if (!r->camera) {
        const char *bad = r->gaze ? c : g;
        if (r->gaze) fclose(r->gaze);
        r->gaze = NULL;
        return fv_error_set(err, FV_ERR_IO, "recording: cannot write %s in the current folder", bad);
    }
    fprintf(r->gaze, "# recorded by fovea view: scene time in seconds, gaze in normalised screen coordinates\ntime,x,y\n");
    fprintf(r->camera, "# recorded by fovea view: scene time, position, look-at point, up, vertical fov\ntime,px,py,pz,lx,ly,lz,ux,uy,uz,fov\n");
    r->last_time = -1e300;
    return FV_OK;
}

void fv_vw_record_sample(fv_vw_record *r, double t, fv_gaze g, const fv_camera *c)
{
    if (!r->gaze || !(t > r->last_time)) return;
    r->last_time = t;
    fprintf(r->gaze, "%.4f,%.5f,%.5f\n", t, g.x, g.y);
    fprintf(r->camera, "%.4f,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", t, c->pos.x, c->pos.y, c->pos.z, c->look.x, c->look.y,
            c->look.z, c->up.x, c->up.y, c->up.z, c->fov_y);
}

void fv_vw_record_stop(fv_vw_record *r)
{
    if (r->gaze) fclose(r->gaze);
    if (r->camera) fclose(r->camera);
    r->gaze = r->camera = NULL;
}
