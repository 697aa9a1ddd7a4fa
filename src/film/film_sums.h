/* fovea — a film's double-precision sums: the unnormalised sample sums of a range of sample blocks
 * (core/blocks.h), which a still split over processes sends to the process that adds them along
 * the blocks' tree (src/dist). film's interface to them, not FV_API and not private: the methods
 * that sum sample blocks (pt, ppm: fv_technique_block_unit) fill them, only when asked, and
 * src/dist, which the tool links beside the library, asks and reads them; the float colour is
 * written as always. */
#ifndef FV_FILM_SUMS_H
#define FV_FILM_SUMS_H

#include "fovea/film.h"

/* Allocates (once) 3 zeroed doubles per pixel; the film frees them. */
fv_status fv_film_want_sums(fv_film *film, fv_error *err);
/* The sums, NULL unless asked for. */
double *fv_film_sums(fv_film *film);

#endif
