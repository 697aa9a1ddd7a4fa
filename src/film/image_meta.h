/* fovea — the names image metadata takes in files: "fovea:KEY" for the key KEY of the bag
 * (fovea/film.h), as PNG text keywords (1-79 Latin-1 bytes) and EXR attribute names. */
#ifndef FV_FILM_IMAGE_META_H
#define FV_FILM_IMAGE_META_H

#include <stdbool.h>
#include <stddef.h>

#define FV_IMAGE_META_PREFIX "fovea:"
#define FV_IMAGE_META_KEY_MAX 80 /* a PNG keyword's 79 bytes and its terminator */

/* "fovea:KEY" into out; false when it would not fit a PNG keyword (the key is then skipped). */
bool fv_image_meta_name(const char *key, char *out, size_t n);

#endif
