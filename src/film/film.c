/* fovea — film buffers: linear float RGB plus the auxiliary buffers (depth, normal, albedo, object
 * id, position) that techniques share. The denoiser of Visual-Polar path tracing, the reprojection
 * of the temporal techniques and the metrics all read these; a technique fills only what the
 * caller asked for (a NULL accessor means "not requested").
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "core/alloc.h"
#include "film/display.h"
#include "film/film_display.h"
#include "film/film_sums.h"
#include "fovea/film.h"

struct fv_film {
    int width, height;
    unsigned aux;
    float *color, *depth, *normal, *albedo, *position;
    uint32_t *id;
    double *sums; /* film_sums.h: only when a caller asked for it */
    /* fv_film_set_display: the RGBA8 pixels, their exposure, and whether the last frame filled
     * them (then its float colour was not written) */
    uint8_t *display;
    float display_exposure;
    bool display_filled;
};

fv_status fv_film_check_size(int width, int height, fv_error *err)
{
    if (width < 1 || height < 1)
        return fv_error_set(err, FV_ERR_INVALID, "image size %dx%d: width and height must be at least 1", width, height);
    if (width > FV_FILM_MAX_DIM || height > FV_FILM_MAX_DIM)
        return fv_error_set(err, FV_ERR_INVALID, "image size %dx%d: width and height must be at most %d", width, height,
                            FV_FILM_MAX_DIM);
    if ((long long)width * height > FV_FILM_MAX_PIXELS)
        return fv_error_set(err, FV_ERR_INVALID, "image size %dx%d: more than %lld pixels", width, height,
                            (long long)FV_FILM_MAX_PIXELS);
    return FV_OK;
}

fv_status fv_film_create(int width, int height, unsigned aux, fv_film **out, fv_error *err)
{
    fv_status s = fv_film_check_size(width, height, err);
    if (s != FV_OK) return s;
    if (aux & ~(unsigned)FV_AUX_ALL) return fv_error_set(err, FV_ERR_INVALID, "film: unknown auxiliary buffer flags 0x%x", aux);
    fv_film *f = calloc(1, sizeof *f);
    if (!f) return fv_error_set(err, FV_ERR_NOMEM, "out of memory creating a %dx%d film", width, height);
    size_t n = (size_t)width * (size_t)height;
    f->width = width;
    f->height = height;
    f->aux = aux;
    bool ok = (f->color = fv_alloc_array(n, 3 * sizeof(float))) != NULL;
    if (ok && (aux & FV_AUX_DEPTH)) ok = (f->depth = fv_alloc_array(n, sizeof(float))) != NULL;
    if (ok && (aux & FV_AUX_NORMAL)) ok = (f->normal = fv_alloc_array(n, 3 * sizeof(float))) != NULL;
    if (ok && (aux & FV_AUX_ALBEDO)) ok = (f->albedo = fv_alloc_array(n, 3 * sizeof(float))) != NULL;
    if (ok && (aux & FV_AUX_ID)) ok = (f->id = fv_alloc_array(n, sizeof(uint32_t))) != NULL;
    if (ok && (aux & FV_AUX_POSITION)) ok = (f->position = fv_alloc_array(n, 3 * sizeof(float))) != NULL;
    if (!ok) {
        fv_film_destroy(f);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory creating a %dx%d film", width, height);
    }
    fv_film_clear(f);
    *out = f;
    return FV_OK;
}

void fv_film_destroy(fv_film *f)
{
    if (!f) return;
    free(f->color);
    free(f->depth);
    free(f->normal);
    free(f->albedo);
    free(f->id);
    free(f->position);
    free(f->sums);
    free(f->display);
    free(f);
}

fv_status fv_film_want_sums(fv_film *f, fv_error *err)
{
    if (f->sums) return FV_OK;
    f->sums = fv_calloc_array((size_t)f->width * (size_t)f->height, 3 * sizeof(double));
    return f->sums ? FV_OK : fv_error_set(err, FV_ERR_NOMEM, "out of memory for a %dx%d film's sums", f->width, f->height);
}

double *fv_film_sums(fv_film *f) { return f->sums; }

void fv_film_clear(fv_film *f)
{
    size_t n = (size_t)f->width * (size_t)f->height;
    memset(f->color, 0, n * 3 * sizeof(float));
    if (f->depth)
        for (size_t i = 0; i < n; i++) f->depth[i] = INFINITY;
    if (f->normal) memset(f->normal, 0, n * 3 * sizeof(float));
    if (f->albedo) memset(f->albedo, 0, n * 3 * sizeof(float));
    if (f->position) memset(f->position, 0, n * 3 * sizeof(float));
    if (f->id) memset(f->id, 0, n * sizeof(uint32_t));
    f->display_filled = false;
}

int fv_film_width(const fv_film *f) { return f->width; }
int fv_film_height(const fv_film *f) { return f->height; }
unsigned fv_film_aux_flags(const fv_film *f) { return f->aux; }
float *fv_film_color(fv_film *f) { return f->color; }
const float *fv_film_color_const(const fv_film *f) { return f->color; }
float *fv_film_depth(fv_film *f) { return f->depth; }
float *fv_film_normal(fv_film *f) { return f->normal; }
float *fv_film_albedo(fv_film *f) { return f->albedo; }
float *fv_film_position(fv_film *f) { return f->position; }
uint32_t *fv_film_id(fv_film *f) { return f->id; }

/* Read-only views for the writers (image_io.c), which take a const film. */
const float *fv_film_aux_const(const fv_film *f, fv_film_aux which)
{
    switch (which) {
    case FV_AUX_DEPTH: return f->depth;
    case FV_AUX_NORMAL: return f->normal;
    case FV_AUX_ALBEDO: return f->albedo;
    case FV_AUX_POSITION: return f->position;
    default: return NULL;
    }
}

const uint32_t *fv_film_id_const(const fv_film *f) { return f->id; }

fv_film_views fv_film_views_of(fv_film *f)
{
    /* whoever writes the film now writes its float colour: the display output is a frame's, and
     * only a device frame's delivery says it filled it */
    f->display_filled = false;
    fv_film_views v = {f->color, f->depth, f->normal, f->albedo, f->position, f->id};
    return v;
}

float fv_srgb_encode(float x) { return fv_display_encode(x); }

fv_status fv_film_set_display(fv_film *f, float exposure, fv_error *err)
{
    if (!isfinite(exposure) || exposure < 0.0f) return fv_error_set(err, FV_ERR_INVALID, "film: display exposure %g must be finite and >= 0", exposure);
    if (!f->display && !(f->display = fv_alloc_array((size_t)f->width * (size_t)f->height, 4)))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory for the film's display output");
    f->display_exposure = exposure;
    f->display_filled = false;
    return FV_OK;
}

const uint8_t *fv_film_display(const fv_film *f) { return f->display_filled ? f->display : NULL; }
uint8_t *fv_film_display_buffer(fv_film *f) { return f->display; }
float fv_film_display_exposure(const fv_film *f) { return f->display_exposure; }
void fv_film_display_filled(fv_film *f) { f->display_filled = f->display != NULL; }

float fv_srgb_decode(float e)
{
    if (!(e > 0.0f)) return 0.0f;
    if (e >= 1.0f) return 1.0f;
    return e <= 0.04045f ? e / 12.92f : powf((e + 0.055f) / 1.055f, 2.4f);
}
