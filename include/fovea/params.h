/* fovea — the method parameter bag: a list of key=value strings a caller fills and hands to
 * fv_technique_create, which validates them (a key the method does not know, or a malformed value,
 * is refused with a message naming it).
 *
 * Ownership: the caller creates and destroys a bag; setters copy their strings. A bag is not
 * thread-safe; fv_technique_create only reads it (it validates a private copy).
 */
#ifndef FOVEA_PARAMS_H
#define FOVEA_PARAMS_H

#include "fovea/export.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct fv_params fv_params;

/* A new empty bag; release with fv_params_destroy. */
FV_API fv_status fv_params_create(fv_params **out, fv_error *err);
/* NULL is ignored. */
FV_API void fv_params_destroy(fv_params *p);
/* Sets key to value (both copied; a later set of the same key replaces it). Keys are
 * [a-z0-9_-]+, non-empty. */
FV_API fv_status fv_params_set(fv_params *p, const char *key, const char *value, fv_error *err);
/* Parses "key=value" and sets it. */
FV_API fv_status fv_params_parse(fv_params *p, const char *key_eq_value, fv_error *err);
/* Entries in the order first set; a NULL bag has none. The strings belong to the bag and live
 * until it is destroyed or the key is set again. */
FV_API int fv_params_count(const fv_params *p);
FV_API const char *fv_params_key(const fv_params *p, int i);
FV_API const char *fv_params_value(const fv_params *p, int i);
/* A new bag with the same entries (p may be NULL: an empty bag); release with fv_params_destroy. */
FV_API fv_status fv_params_clone(const fv_params *p, fv_params **out, fv_error *err);

#ifdef __cplusplus
}
#endif
#endif
