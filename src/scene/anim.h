/* fovea — rigid keyframe animation, shared by dynamic objects and moving delta lights: the rules a
 * list of keys must follow and the interpolation between them, written once so an object and a
 * light given the same keys move the same way.
 *
 * Keys are times strictly increasing, finite, with a non-zero rotation and positive scales. Before
 * the first key the first one holds, after the last key the last one; in between translation and
 * scale are lerped and the rotation is slerped (fovea/scene.h, fv_anim_key).
 */
#ifndef FV_SCENE_ANIM_H
#define FV_SCENE_ANIM_H

#include <stdbool.h>
#include "fovea/scene.h"

/* A validated copy of the keys (rotations unit length); {NULL, 0}: not animated. */
typedef struct fv_anim {
    fv_anim_key *keys;
    int nkeys;
} fv_anim;

/* Checks the keys; the message reads "animation of <who>: ..." (who: "'box'", "light 2"). */
fv_status fv_anim_check(const char *who, const fv_anim_key *keys, int count, fv_error *err);

/* Checks the keys, then replaces what a held by a copy with normalised rotations; a is unchanged
 * on failure. */
fv_status fv_anim_set(fv_anim *a, const char *who, const fv_anim_key *keys, int count, fv_error *err);

void fv_anim_free(fv_anim *a);

/* The key at time t (its `time` field is t); a must hold at least one key. */
fv_anim_key fv_anim_at(const fv_anim *a, double t);

/* The key's transform: scale, then rotation, then translation. */
static inline fv_xform fv_anim_key_xform(const fv_anim_key *k) { return fv_xform_trs(k->translate, k->rotate, k->scale); }

#endif
