/* fovea — the table of built-in scenes: scenes that need no file (docs/scenes.md describes each).
 * The table is constant; builders live in builtin_*.c.
 */
#include <stdio.h>
#include <string.h>
#include "scene/builtin_impl.h"

typedef struct builtin {
    const char *name;
    const char *summary;
    fv_status (*build)(fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err);
} builtin;

static const builtin k_builtins[] = {
    {"cornell", "classic Cornell box (measured geometry): red/green walls, two blocks, ceiling light; 32 triangles",
     fv_builtin_cornell},
    {"cornell-glossy", "the Cornell box with a glossy copper tall block and a glossy plastic short block; 32 triangles",
     fv_builtin_cornell_glossy},
    {"cornell-fpm", "Foveated Photon Mapping Fig. 2: glass sphere (caustic), moving mirror cube, camera path, 0-4 s",
     fv_builtin_cornell_fpm},
    {"cornell-fir", "Foveated Instant Radiosity: all-diffuse Cornell box, circling point light, moving yellow cube, 0-4 s",
     fv_builtin_cornell_fir},
    {"city", "performance scene: 180,906 triangles of towers and spheres, mixed materials, sun + lamps",
     fv_builtin_city},
    {"sdf-primitives", "signed distance fields (IPR paper Sec. 4.1, open): seven primitives and a smooth union on a checkerboard",
     fv_builtin_sdf_primitives},
    {"sdf-columns", "signed distance fields (IPR paper Sec. 4.1, enclosed): a room of 3x3 repeated columns, five moving lights",
     fv_builtin_sdf_columns},
    {"sdf-temple", "signed distance fields (IPR paper Sec. 4.1): noise cliff terrain with a temple of columns and steps",
     fv_builtin_sdf_temple},
    {"sdf-furnace", "hollow SDF sphere lit from its centre: sphere tracers see radiance exactly 1 (albedo 0.5, I = 2 pi)",
     fv_builtin_sdf_furnace},
    {"furnace", "white furnace test: inside a sphere of albedo 0.5 emitting 0.5, radiance is exactly 1",
     fv_builtin_furnace},
};
#define N_BUILTINS ((int)(sizeof k_builtins / sizeof k_builtins[0]))

int fv_builtin_count(void) { return N_BUILTINS; }
const char *fv_builtin_name(int i) { return i >= 0 && i < N_BUILTINS ? k_builtins[i].name : NULL; }
const char *fv_builtin_summary(int i) { return i >= 0 && i < N_BUILTINS ? k_builtins[i].summary : NULL; }

fv_status fv_builtin_build(const char *name, fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err)
{
    if (!name) name = "";
    for (int i = 0; i < N_BUILTINS; i++) {
        if (strcmp(name, k_builtins[i].name) != 0) continue;
        /* Without a view the builder fills a scratch one, so builders never test for NULL. */
        fv_view *scratch = NULL;
        fv_status st = view ? FV_OK : fv_view_create(&scratch, err);
        if (st == FV_OK) st = k_builtins[i].build(scene, view ? view : scratch, log, err);
        fv_view_destroy(scratch);
        return st;
    }
    char known[256] = "";
    size_t len = 0;
    for (int i = 0; i < N_BUILTINS; i++) {
        int w = snprintf(known + len, sizeof known - len, "%s%s", i ? ", " : "", k_builtins[i].name);
        if (w < 0 || (size_t)w >= sizeof known - len) break;
        len += (size_t)w;
    }
    return fv_error_set(err, FV_ERR_INVALID, "unknown built-in scene '%s' (known: %s)", name, known);
}

fv_status fv_builtin_material(fv_scene *scene, const char *name, fv_material m, int *id, fv_error *err)
{
    snprintf(m.name, sizeof m.name, "%s", name);
    return fv_scene_add_material(scene, &m, id, err);
}
