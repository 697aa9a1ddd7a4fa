/* fovea — the registry of rendering techniques, and the instance wrapper every driver uses.
 *
 * Adding a technique: define its fv_technique_class in its own folder and list it here. Nothing
 * else in the project switches on a technique's name.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fovea/technique.h"

extern const fv_technique_class fv_technique_pt;
extern const fv_technique_class fv_technique_pm;
extern const fv_technique_class fv_technique_pm_t;
extern const fv_technique_class fv_technique_fpm;
extern const fv_technique_class fv_technique_vpolar;
extern const fv_technique_class fv_technique_cartesian;
extern const fv_technique_class fv_technique_cartesian_full;
extern const fv_technique_class fv_technique_linear_falloff;
extern const fv_technique_class fv_technique_logpolar;

static const fv_technique_class *const k_classes[] = {
    &fv_technique_pt,       &fv_technique_pm,        &fv_technique_pm_t,           &fv_technique_fpm,
    &fv_technique_vpolar,   &fv_technique_cartesian, &fv_technique_cartesian_full, &fv_technique_linear_falloff,
    &fv_technique_logpolar,
};

#define N_CLASSES ((int)(sizeof k_classes / sizeof k_classes[0]))

int fv_technique_count(void) { return N_CLASSES; }

const fv_technique_class *fv_technique_at(int i) { return i >= 0 && i < N_CLASSES ? k_classes[i] : NULL; }

const fv_technique_class *fv_technique_find(const char *name)
{
    for (int i = 0; i < N_CLASSES; i++)
        if (strcmp(k_classes[i]->name, name) == 0) return k_classes[i];
    return NULL;
}

struct fv_technique {
    const fv_technique_class *cls;
    void *state;
};

fv_status fv_technique_create(const char *name, const fv_scene *scene, fv_params *params,
                              const fv_log *log, fv_technique **out, fv_error *err)
{
    *out = NULL;
    const fv_technique_class *cls = fv_technique_find(name);
    if (!cls) {
        char list[512] = "";
        for (int i = 0; i < N_CLASSES; i++) {
            size_t l = strlen(list);
            snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", k_classes[i]->name);
        }
        return fv_error_set(err, FV_ERR_INVALID, "unknown method '%s' (known: %s)", name, list);
    }
    fv_technique *t = calloc(1, sizeof *t);
    if (!t) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    t->cls = cls;
    fv_status s = cls->create(scene, params, log, &t->state, err);
    if (s != FV_OK) {
        free(t);
        return s;
    }
    *out = t;
    return FV_OK;
}

fv_status fv_technique_render(fv_technique *t, const fv_frame *frame, fv_film *film, fv_film *film_right,
                              fv_stats *stats, fv_error *err)
{
    if (frame->camera_right && !film_right)
        return fv_error_set(err, FV_ERR_INVALID, "stereo frame without a right-eye film");
    return t->cls->render(t->state, frame, film, film_right, stats, err);
}

const fv_technique_class *fv_technique_class_of(const fv_technique *t) { return t->cls; }

void fv_technique_destroy(fv_technique *t)
{
    if (!t) return;
    t->cls->destroy(t->state);
    free(t);
}

const fv_eye_model *fv_frame_eye(const fv_frame *frame, int width, int height, fv_eye_model *def)
{
    if (frame->eye) return frame->eye;
    fv_eye_model_default(width, height, def);
    return def;
}

fv_status fv_frame_camera(const fv_camera *cam, const fv_film *film, fv_camera_basis *out, fv_error *err)
{
    fv_status s = fv_camera_basis_make(cam, out, err);
    if (s == FV_OK && (cam->width != fv_film_width(film) || cam->height != fv_film_height(film)))
        s = fv_error_set(err, FV_ERR_INVALID, "camera size %dx%d differs from the film's %dx%d", cam->width, cam->height,
                         fv_film_width(film), fv_film_height(film));
    return s;
}
