/* fovea — the JSON keys of an "animation" array (docs/scene-format.md): the scene's one parser of
 * that format, for its own files' objects and lights (load_json.c, which implements it beside the
 * transforms it shares) and for the bench's "animate" field (bench/scenario.c). The rest of the
 * scene file's loaders stay private to scene/ (load_impl.h).
 */
#ifndef FV_SCENE_ANIM_JSON_H
#define FV_SCENE_ANIM_JSON_H

#include <cjson/cJSON.h>
#include "fovea/scene.h"

/* `where` names the block holding the array (errors read "FILE: WHERE.animation[i].FIELD: ...").
 * The rules between keys (increasing times, ...) are the scene's, checked when they are applied
 * (fv_scene_animate_*) or earlier with fv_anim_check (scene/anim.h). On success *keys (free())
 * holds *count. */
fv_status fv_load_json_anim_keys(const cJSON *arr, const char *file, const char *where, fv_anim_key **keys, int *count, fv_error *err);

#endif
