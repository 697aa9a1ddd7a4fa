/* fovea-view — the interactive viewer's shared declarations. Every piece of state lives in the
 * fv_vw_app struct that view_main.c owns and passes around (no mutable globals); each file is one
 * concern: arguments (view_args.c), techniques and their main parameter (view_tech.c), rendering
 * a frame through the sequence driver (view_render.c), the flying camera (view_camera.c), keys and
 * mouse (view_input.c), timed scripts (view_script.c), text in the library's font (view_font.c), the gaze
 * overlay and the on-screen text (view_overlay.c), gaze/camera recording (view_record.c). */
#ifndef FV_VIEW_H
#define FV_VIEW_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include "fovea/fovea.h"
#include "cli.h"

/* The driver's clock: frame index i is at time i / FV_VW_FPS, so the index is the animation
 * clock in milliseconds (2^31 ms is 24 days of viewing). */
#define FV_VW_FPS 1000.0
#define FV_VW_LUT 4096 /* entries of the linear -> sRGB byte table over [0,1] */

/* ---- command line ---- */
typedef struct fv_vw_args {
    const char *scene, *method, *gaze_trace, *script, *fps_log;
    const char *device; /* --device: for every method that has it (NULL: the CPU) */
    int width, height, threads;
    double scale, stereo;
    bool has_gaze;
    float gaze[2];
    fv_params *params; /* the --param bag, for the method named on the command line */
    fv_cli_scene_opts scene_opts; /* --env, --no-default-light, --frame-view, as fovea render's */
} fv_vw_args;
/* 0: go on; < 0: --help printed, exit 0; > 0: exit code (message printed). */
int fv_vw_args_parse(int argc, char **argv, fv_vw_args *a);

/* ---- the canvas: what the window shows, ARGB8888, window-sized ---- */
typedef struct fv_vw_canvas {
    uint32_t *px;
    int w, h;
} fv_vw_canvas;
typedef struct fv_vw_rect {
    int x, y, w, h;
} fv_vw_rect;
static inline uint32_t fv_vw_rgb(unsigned r, unsigned g, unsigned b) { return 0xFF000000u | (r << 16) | (g << 8) | b; }

/* ---- font: 5x7 glyphs in 6x9 cells, ASCII 32..126 ---- */
enum { FV_VW_CELL_W = 6, FV_VW_CELL_H = 9 };
/* Draws s at (x, y) (top-left) with a dark outline so it reads on any background; returns the
 * width drawn. Characters outside 32..126 draw as '?'. */
int fv_vw_text(fv_vw_canvas *c, int x, int y, uint32_t color, const char *s);

/* ---- overlay (gaze/overlay.h's shapes and colours: magenta r_f, cyan r_t, yellow gaze) ---- */
/* Fovea and transition circles of eye model m around gaze g, and a cursor, inside panel; the
 * model is in film pixels, film_w wide, drawn scaled to the panel. */
void fv_vw_overlay_gaze(fv_vw_canvas *c, fv_vw_rect panel, const fv_eye_model *m, int film_w, fv_gaze g);

/* ---- techniques ---- */
/* One rendering method in the viewer: its instance, films (one per eye) and what its last frame
 * cost. The films are at the render size; accum holds the running sum of progressive frames. */
typedef struct fv_vw_slot {
    int method;          /* registry index, -1 when empty */
    fv_technique *tech;
    int value;           /* step of the registry's main parameter (fv_technique_main_step), -1: --param's or the default */
    char label[48];      /* "key=value" of the main parameter as created */
    fv_film *film[2];
    int fw, fh, eyes;
    bool rendered;       /* has rendered since it was created (its history continues) */
    double ms;           /* last frame's render time */
    fv_stats stats;
    float *accum[2];
    int accum_n;
    uint64_t accum_key;
    fv_eye_model eye;    /* the driver's eye model of the last frame (film pixels) */
    fv_gaze gaze[2];     /* the gaze each eye was rendered with */
} fv_vw_slot;

/* (Re)creates slot s with registry method m and main-parameter step value (-1: default);
 * user_params (may be NULL) is the bag for that method; device (may be NULL) is --device, given to
 * the method when it has that device (the others run on the CPU); the slot keeps its old technique
 * when creation fails (err says why). */
fv_status fv_vw_slot_create(fv_vw_slot *s, const fv_scene *scene, int m, int value, const fv_params *user_params, const char *device,
                            const fv_log *log, fv_error *err);
void fv_vw_slot_destroy(fv_vw_slot *s);
/* Films of the given size and eye count (recreated only when they change). */
fv_status fv_vw_slot_films(fv_vw_slot *s, int w, int h, int eyes, fv_error *err);
/* A short "key=value" label of the main parameter ("" when the method has none). */
void fv_vw_slot_param_label(const fv_vw_slot *s, char *out, size_t n);

/* ---- the flying camera ---- */
typedef struct fv_vw_fly {
    bool active;           /* the user has moved it: it overrides the view's camera */
    fv_vec3 pos, fwd, up;  /* fwd unit; up is the world's up the yaw turns about */
    float dist, fov_y;     /* look-at distance along fwd, vertical fov */
} fv_vw_fly;
void fv_vw_fly_init(fv_vw_fly *f, const fv_camera *c);
/* Moves by (right, up, forward) in camera space, distances in scene units. */
void fv_vw_fly_move(fv_vw_fly *f, float right, float up, float forward);
/* Turns by yaw (about up) and pitch (about the camera's right), radians. */
void fv_vw_fly_look(fv_vw_fly *f, float yaw, float pitch);
void fv_vw_fly_camera(const fv_vw_fly *f, fv_camera *out);

/* ---- script: timed commands by viewer frame number ---- */
typedef enum { FV_VW_CMD_KEY, FV_VW_CMD_MOUSE, FV_VW_CMD_MOVE, FV_VW_CMD_LOOK, FV_VW_CMD_SHOT, FV_VW_CMD_QUIT } fv_vw_cmd_kind;
typedef struct fv_vw_cmd {
    long frame;
    fv_vw_cmd_kind kind;
    int key;          /* SDL_Keycode */
    unsigned mod;     /* SDL_Keymod */
    float x, y;       /* gaze, normalised */
    float v[3];       /* move: right, up, forward (scene units); look: yaw, pitch (radians) */
    char *path;       /* screenshot file (owned) */
} fv_vw_cmd;
typedef struct fv_vw_script {
    fv_vw_cmd *cmd;
    int count, next;
} fv_vw_script;
fv_status fv_vw_script_load(const char *path, fv_vw_script *out, fv_error *err);
void fv_vw_script_free(fv_vw_script *s);

/* ---- recording: gaze and camera in the CSV formats --gaze-trace / --camera-trace read ---- */
typedef struct fv_vw_record {
    FILE *gaze, *camera;
    double last_time;
    int take;
} fv_vw_record;
/* Starts take n: files fovea-view-gaze-NNN.csv and fovea-view-camera-NNN.csv in the current folder. */
fv_status fv_vw_record_start(fv_vw_record *r, fv_error *err);
/* One sample at scene time t; samples whose time does not increase (paused) are skipped, as the
 * trace formats need strictly increasing times. */
void fv_vw_record_sample(fv_vw_record *r, double t, fv_gaze g, const fv_camera *c);
void fv_vw_record_stop(fv_vw_record *r);

/* ---- the application ---- */
typedef struct fv_vw_app {
    fv_vw_args args;
    fv_log log;
    bool quiet;
    fv_scene *scene;
    fv_view *view;
    fv_gaze_path *gaze_trace;
    int user_method;                 /* the method --param applies to */
    fv_vw_slot main, base;           /* the technique, and its baseline in the split view */
    bool split, overlay, paused, running, cancelled, hide_text;
    fv_gaze gaze;                    /* mouse or scripted gaze (normalised, in a panel) */
    bool script_gaze;                /* a script drives the gaze: the real mouse does not */
    fv_vw_fly fly;
    float fly_speed;                 /* scene units per second */
    double anim_time;                /* the animation clock in seconds */
    long frame;                      /* viewer frames shown so far */
    double frame_ms;                 /* last frame, wall clock, render + display */
    char message[160];               /* last status message shown at the bottom */
    double message_until;
    fv_vw_record rec;
    FILE *fps_log;
    uint64_t base_seed;
    uint8_t srgb[FV_VW_LUT + 1];
} fv_vw_app;

void fv_vw_say(fv_vw_app *app, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Switches the main slot to the next (dir +1) or previous (-1) method that accepts the scene. */
void fv_vw_cycle(fv_vw_app *app, int dir);
/* Steps the main parameter of the main slot (dir +1 / -1). */
void fv_vw_step_param(fv_vw_app *app, int dir);
/* Creates (or drops) the baseline slot for the split view: the registry's baseline of the main
 * method (fv_technique_baseline); the reference, which has none, leaves the split view. */
void fv_vw_update_baseline(fv_vw_app *app);

/* The panels the window is split into this frame: rect, slot and eye each; returns the count. */
typedef struct fv_vw_panel {
    fv_vw_rect r;
    fv_vw_slot *slot;
    int eye;
} fv_vw_panel;
int fv_vw_panels(fv_vw_app *app, int win_w, int win_h, fv_vw_panel out[2]);
/* Renders every slot the panels show; FV_ERR_CANCELLED when the window was closed meanwhile. */
fv_status fv_vw_render(fv_vw_app *app, const fv_vw_panel *p, int np, fv_error *err);
/* Film -> panel (nearest-neighbour scaling, sRGB), progressive average when the slot has one. */
void fv_vw_blit(fv_vw_canvas *c, const fv_vw_panel *p, const uint8_t *srgb_lut);

/* The text lines: per panel its method and ms, at the bottom fps, stages, counters, gaze. */
void fv_vw_hud(fv_vw_canvas *c, fv_vw_app *app, const fv_vw_panel *p, int np);
/* The canvas as a PNG through fv_image_write. */
fv_status fv_vw_screenshot(const fv_vw_canvas *c, const char *path, fv_error *err);

/* Keys, from the keyboard or a script. */
void fv_vw_on_key(fv_vw_app *app, int key, unsigned mod, const char *shot_path, fv_vw_canvas *c);

#endif
