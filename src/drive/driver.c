/* fovea — the sequence driver (see include/fovea/drive.h). */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "fovea/drive.h"
#include "fovea/limits.h"

struct fv_driver {
    fv_scene *scene;
    const fv_view *view;
    fv_drive_opts o;
    fv_eye_model eye;
    fv_eye_model eye_whole; /* eye widened to the whole screen: FV_GAZE_MISSING_WIDEN's frames */
    /* The views of the last frame rendered: the viewer changes the camera between frames
     * (fv_driver_set_camera), so frame i-1's camera can only be known by remembering it, not by
     * deriving it again from today's overrides. */
    fv_frame_views last;
    int last_seen; /* the index the technique saw last (frame index + warm-up count); -1: none yet */
};

void fv_drive_opts_init(fv_drive_opts *o)
{
    memset(o, 0, sizeof *o);
    o->width = o->height = 512;
    o->fps = 30.0;
    o->seed = 1;
}

fv_status fv_driver_create(fv_scene *scene, const fv_view *view, const fv_drive_opts *opts, fv_driver **out, fv_error *err)
{
    *out = NULL;
    if (!scene) return fv_error_set(err, FV_ERR_INVALID, "driver: no scene");
    fv_status s = fv_film_check_size(opts->width, opts->height, err);
    if (s != FV_OK) return s;
    if (!(opts->fps > 0.0) || !isfinite(opts->fps)) return fv_error_set(err, FV_ERR_INVALID, "driver: fps %g must be positive", opts->fps);
    if (!isfinite(opts->time0)) return fv_error_set(err, FV_ERR_INVALID, "driver: start time must be finite");
    if (!(opts->eye_separation >= 0.0f) || !isfinite(opts->eye_separation))
        return fv_error_set(err, FV_ERR_INVALID, "driver: eye separation %g must be >= 0", opts->eye_separation);
    /* Each eye sits half the separation beside the camera: bounded like any coordinate. */
    double sep = opts->eye_separation;
    if ((s = fv_limit_coords("driver: eye separation", &sep, 1, err)) != FV_OK) return s;
    if (((opts->camera_set & FV_DRIVE_POS) && (s = fv_limit_vec3("driver: camera position", opts->pos, err)) != FV_OK) ||
        ((opts->camera_set & FV_DRIVE_LOOK) && (s = fv_limit_vec3("driver: camera look-at point", opts->look, err)) != FV_OK) ||
        ((opts->camera_set & FV_DRIVE_UP) && (s = fv_limit_vec3("driver: camera up vector", opts->up, err)) != FV_OK))
        return s;
    if (opts->threads < 0) return fv_error_set(err, FV_ERR_INVALID, "driver: thread count %d must be >= 0", opts->threads);
    if (opts->warmup < 0 || opts->warmup > FV_DRIVE_MAX_WARMUP)
        return fv_error_set(err, FV_ERR_INVALID, "driver: %d warm-up frames (expected 0 to %d)", opts->warmup, FV_DRIVE_MAX_WARMUP);
    fv_driver *d = calloc(1, sizeof *d);
    if (!d) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    d->scene = scene;
    d->view = view;
    d->o = *opts;
    /* The eye model: the caller's, else the view's display rescaled to this width, else the
     * default. A display's density is per display pixel; rendering it at another width must keep
     * the regions on the same part of the view, so pixels per inch scale with the width. */
    if (opts->eye_model) {
        d->eye = *opts->eye_model;
    } else {
        fv_eye_model_default(opts->width, opts->height, &d->eye);
        if (view && fv_view_display(view, &d->eye)) {
            d->eye.ppi *= (float)opts->width / (float)d->eye.width;
            d->eye.width = opts->width;
            d->eye.height = opts->height;
        }
    }
    d->o.eye_model = &d->eye;
    fv_eye_model_whole_screen(&d->eye, &d->eye_whole);
    d->last_seen = -1;
    *out = d;
    return FV_OK;
}

void fv_driver_destroy(fv_driver *d) { free(d); }

const fv_eye_model *fv_driver_eye_model(const fv_driver *d) { return &d->eye; }
int fv_driver_eye_count(const fv_driver *d) { return d->o.eye_separation > 0.0f ? 2 : 1; }

void fv_driver_set_gaze(fv_driver *d, fv_gaze g)
{
    d->o.fixed_gaze = true;
    d->o.gaze = g;
}

void fv_driver_set_camera(fv_driver *d, const fv_camera *c)
{
    /* the options' overrides, all four at once: the camera path still moves the view's camera
     * first, and then everything it set is replaced */
    d->o.camera_set = FV_DRIVE_POS | FV_DRIVE_LOOK | FV_DRIVE_UP | FV_DRIVE_FOV;
    d->o.pos = c->pos;
    d->o.look = c->look;
    d->o.up = c->up;
    d->o.fov_y = c->fov_y;
}

void fv_driver_views(const fv_driver *d, int index, fv_frame_views *out)
{
    const fv_drive_opts *o = &d->o;
    memset(out, 0, sizeof *out);
    double t = o->time0 + index / o->fps;
    out->time = t;
    out->eye_count = fv_driver_eye_count(d);
    fv_camera c;
    fv_view_camera(d->view, d->scene, t, o->width, o->height, &c);
    if (o->camera_path && o->camera_path->count > 0) fv_camera_path_eval(o->camera_path, t, &c, &c);
    if (o->camera_set & FV_DRIVE_POS) c.pos = o->pos;
    if (o->camera_set & FV_DRIVE_LOOK) c.look = o->look;
    if (o->camera_set & FV_DRIVE_UP) c.up = o->up;
    if (o->camera_set & FV_DRIVE_FOV) c.fov_y = o->fov_y;
    if (out->eye_count == 2) fv_camera_stereo(&c, o->eye_separation, &out->camera[0], &out->camera[1]);
    else out->camera[0] = out->camera[1] = c;
    const fv_gaze_path *gp = o->gaze_path ? o->gaze_path : d->view ? fv_view_gaze_path(d->view) : NULL;
    fv_gaze g = o->fixed_gaze ? o->gaze : (fv_gaze){0.5f, 0.5f};
    out->gaze[0] = out->gaze[1] = g;
    out->gaze_known = true;
    out->eye_model = &d->eye;
    if (!o->fixed_gaze && gp) out->gaze_known = fv_gaze_path_eval(gp, t, &out->gaze[0], &out->gaze[1]);
    fv_gaze_missing policy = o->gaze_missing != FV_GAZE_MISSING_PATH ? o->gaze_missing : gp ? fv_gaze_path_missing(gp) : FV_GAZE_MISSING_HOLD;
    if (!out->gaze_known && policy == FV_GAZE_MISSING_WIDEN) {
        out->gaze[0] = out->gaze[1] = (fv_gaze){0.5f, 0.5f};
        out->eye_model = &d->eye_whole;
    }
}

void fv_driver_prev_views(const fv_driver *d, int index, fv_frame_views *out)
{
    /* frame 0 goes on from the last warm-up frame, which had frame 0's views */
    if (index >= 0 && d->last_seen >= 0 && d->last_seen == index + d->o.warmup - 1) *out = d->last;
    else fv_driver_views(d, index - 1 > 0 ? index - 1 : 0, out);
}

/* Progress of one eye -> progress of the whole frame. */
typedef struct eye_progress {
    fv_progress_fn fn;
    void *user;
    int eye, eyes;
    int frame, frames; /* of a run of frames reported as one (the warm-up) */
} eye_progress;

static bool on_eye_progress(void *user, double f)
{
    eye_progress *p = user;
    return p->fn(p->user, (p->frame + (p->eye + f) / p->eyes) / p->frames);
}

/* How render_views hands the frame to the technique: rendered now, or submitted
 * (fv_technique_submit; fv_driver_collect delivers it). */
typedef enum { RENDER_NOW, SUBMIT } hand_over;

/* Renders views v as the technique's frame `seen` (its index: warm-up frames first); a stereo
 * frame as a pair (fv_technique_render_pair), so a device runs both eyes without a host round
 * trip between them. With SUBMIT the frame is queued instead; its progress is reported within
 * the submit, so the frames and their progress records may live on this stack. */
static fv_status render_views(fv_driver *d, fv_technique *t, const fv_frame_views *v, int seen, const fv_frame_views *pv,
                              fv_film *const *films, fv_stats *stats, eye_progress *ep, hand_over how, fv_error *err)
{
    fv_status s = fv_scene_set_time(d->scene, v->time, err);
    fv_frame fr[2];
    eye_progress eps[2];
    /* a stereo frame with no film for the right eye: the left eye alone, as a mono frame (a
     * bench reference, measured against the left eye only) */
    const int eyes = v->eye_count == 2 && !films[1] ? 1 : v->eye_count;
    for (int e = 0; e < eyes && s == FV_OK; e++) {
        if (!films[e]) return fv_error_set(err, FV_ERR_INVALID, "driver: no film for eye %d", e);
        fv_frame_init(&fr[e], &v->camera[e]);
        fr[e].time = v->time;
        fr[e].index = seen;
        fr[e].seed = d->o.seed;
        fr[e].threads = d->o.threads;
        fr[e].eye = e;
        fr[e].eye_count = eyes;
        fr[e].prev_camera = pv ? &pv->camera[e] : NULL;
        fr[e].left_camera = e == 1 ? &v->camera[0] : NULL;
        fr[e].gaze = v->gaze[e];
        fr[e].eye_model = v->eye_model;
        if (ep->fn) {
            eps[e] = *ep;
            eps[e].eye = e;
            eps[e].eyes = eyes;
            fr[e].progress = on_eye_progress;
            fr[e].progress_user = &eps[e];
        }
    }
    if (s == FV_OK && how == SUBMIT) s = fv_technique_submit(t, eyes, fr, films, stats, err);
    else if (s == FV_OK) s = eyes == 2 ? fv_technique_render_pair(t, fr, films, stats, err) : fv_technique_render(t, &fr[0], films[0], stats, err);
    if (s == FV_OK) {
        d->last = *v;
        d->last_seen = seen;
    }
    return s;
}

/* Frame `index` handed to t as `how` says: its views, and its previous frame's when it continues. */
static fv_status render_index(fv_driver *d, fv_technique *t, int index, bool continues, fv_film *const *films, fv_stats *stats,
                              fv_progress_fn progress, void *progress_user, hand_over how, fv_error *err)
{
    if (index < 0) return fv_error_set(err, FV_ERR_INVALID, "driver: frame index %d must be >= 0", index);
    if (index > INT_MAX - d->o.warmup) return fv_error_set(err, FV_ERR_INVALID, "driver: frame index %d is too large", index);
    const int seen = index + d->o.warmup;
    fv_frame_views v, pv;
    fv_driver_views(d, index, &v);
    bool has_prev = continues && seen > 0;
    if (has_prev) fv_driver_prev_views(d, index, &pv);
    eye_progress ep = {progress, progress_user, 0, v.eye_count, 0, 1};
    return render_views(d, t, &v, seen, has_prev ? &pv : NULL, films, stats, &ep, how, err);
}

fv_status fv_driver_render(fv_driver *d, fv_technique *t, int index, bool continues, fv_film *const *films, fv_stats *stats,
                           fv_progress_fn progress, void *progress_user, fv_error *err)
{
    return render_index(d, t, index, continues, films, stats, progress, progress_user, RENDER_NOW, err);
}

fv_status fv_driver_submit(fv_driver *d, fv_technique *t, int index, bool continues, fv_film *const *films, fv_stats *stats,
                           fv_progress_fn progress, void *progress_user, fv_error *err)
{
    return render_index(d, t, index, continues, films, stats, progress, progress_user, SUBMIT, err);
}

fv_status fv_driver_collect(fv_driver *d, fv_technique *t, fv_error *err)
{
    (void)d;
    return fv_technique_collect(t, err);
}

fv_status fv_driver_warm_up(fv_driver *d, fv_technique *t, fv_film *const *films, fv_stats *stats, fv_progress_fn progress,
                            void *progress_user, fv_error *err)
{
    fv_frame_views v;
    fv_driver_views(d, 0, &v);
    fv_status s = FV_OK;
    for (int k = 0; k < d->o.warmup && s == FV_OK; k++) {
        eye_progress ep = {progress, progress_user, 0, v.eye_count, k, d->o.warmup};
        /* a still: each warm-up frame's previous frame had the same views */
        s = render_views(d, t, &v, k, k > 0 ? &v : NULL, films, stats, &ep, RENDER_NOW, err);
    }
    return s;
}
