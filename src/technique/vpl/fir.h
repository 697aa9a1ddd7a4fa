/* fovea — what fir (fir.c) shares with its tests: how a VPL follows the object it lies on
 * (Foveated Instant Radiosity, Sec. 3.3: "the position of each VPL is transformed with the
 * transformation matrix of the corresponding object").
 */
#ifndef FV_TECHNIQUE_VPL_FIR_H
#define FV_TECHNIQUE_VPL_FIR_H

#include "scene/query.h"

/* The world position and unit normal now of a VPL stored in object obj's own space as (lp, ln). */
void fv_fir_follow(const fv_scene *s, int obj, fv_vec3 lp, fv_vec3 ln, fv_vec3 *p, fv_vec3 *n);

#endif
