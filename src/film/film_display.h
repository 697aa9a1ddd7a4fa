/* fovea — a film's display output (fovea/film.h, fv_film_set_display), as the device frames fill
 * it (device/film_device.h): film's interface to them, private to the library. */
#ifndef FV_FILM_FILM_DISPLAY_H
#define FV_FILM_FILM_DISPLAY_H

#include <stdbool.h>
#include <stdint.h>
#include "fovea/film.h"

/* The RGBA8 buffer of a display-only film (NULL for any other) and the exposure it is asked for. */
uint8_t *fv_film_display_buffer(fv_film *film);
float fv_film_display_exposure(const fv_film *film);
/* The frame just delivered into film filled its display buffer (and not its float colour). */
void fv_film_display_filled(fv_film *film);

#endif
