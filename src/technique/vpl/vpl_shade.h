/* fovea — deferred shading of the first-hit buffer for the instant-radiosity family (Foveated Instant
 * Radiosity, Sec. 3.4): a direct pass, an indirect pass over VPLs (all of them per pixel, or the
 * VPLs of the pixel's interleaved tile), and the composition
 *     L = emitted + albedo / pi * (E_direct + E_vpl).
 * The two sums are kept apart so fir can filter the interleaved indirect sum alone (the 5x5 box of
 * Sec. 3.4) before composing.
 *
 * Interleaved sampling (Keller and Heidrich; the paper's [21]): pixel (x, y) belongs to tile
 * (x mod nx) + nx (y mod ny) of an nx x ny pattern, and sees only that tile's VPLs, so a pixel pays
 * for about 1 / (nx ny) of the VPLs and a block of nx x ny neighbours together sees all of them.
 */
#ifndef FV_TECHNIQUE_VPL_VPL_SHADE_H
#define FV_TECHNIQUE_VPL_VPL_SHADE_H

#include "technique/kit.h"
#include "technique/vpl/vpl_gather.h"
#include "technique/vpl/gbuffer.h"

/* What the family says to `--spp N` (technique class spp_instead): it shades one point per pixel. */
#define FV_VPL_SPP_INSTEAD "one shading point per pixel centre: use --param vpls=N (and area_samples=N for area lights)"
/* The scene the family's benchmarks render (class.h, bench_scene): fir's Cornell box variant. */
#define FV_VPL_BENCH_SCENE "cornell-fir"

/* Counter slots the passes fill (the kit's RAYS counts every ray as well). */
enum { FV_VPL_SLOT_VPL_RAYS = FV_KIT_USER0, FV_VPL_SLOT_LOOKUPS = FV_KIT_USER1, FV_VPL_SLOT_DIRECT_RAYS = FV_KIT_USER2 };

/* The VPLs of each tile of an nx x ny pattern, concatenated: tile t has list[offset[t] ..
 * offset[t + 1]). nx = ny = 1 is one tile with every VPL. */
typedef struct fv_vpl_tiles {
    int nx, ny;
    const int *list;
    const int *offset;
} fv_vpl_tiles;

/* E_direct of every pixel that hit (0 elsewhere) into direct[]: fv_vpl_direct_irradiance with the
 * kit's camera stream. False when cancelled. */
bool fv_vpl_pass_direct(const fv_scene *s, const fv_gbuffer *gb, const fv_frame *frame, int area_samples, fv_vec3 *direct,
                        fv_kit_counters *counters, fv_kit_progress *prog);

/* Adds the VPL sum of every pixel that hit (its tile's list) to sum[]. False when cancelled. */
bool fv_vpl_pass_indirect(const fv_vpl_gather *g, const fv_gbuffer *gb, const fv_vpl_tiles *tiles, int threads,
                          fv_vec3 *sum, fv_kit_counters *counters, fv_kit_progress *prog);

/* The two passes as steps of a merged region (docs/threads.md): called by every thread of the
 * region's team with the same arguments, progress and cancel through tp (core/parallel.h, its fn
 * fv_kit_progress_fn); the same sums as the passes above. */
bool fv_vpl_pass_direct_team(const fv_scene *s, const fv_gbuffer *gb, const fv_frame *frame, int area_samples, fv_vec3 *direct,
                             fv_kit_counters *counters, fv_team_progress *tp);
bool fv_vpl_pass_indirect_team(const fv_vpl_gather *g, const fv_gbuffer *gb, const fv_vpl_tiles *tiles, fv_vec3 *sum,
                               fv_kit_counters *counters, fv_team_progress *tp);

/* ---- the buffers of one frame, and its first and last steps ---- */

/* What `show` selects: the image, or one of its two terms alone (without emitted light). */
typedef enum fv_vpl_show { FV_VPL_SHOW_ALL = 0, FV_VPL_SHOW_DIRECT, FV_VPL_SHOW_INDIRECT } fv_vpl_show;
extern const char *const fv_vpl_show_names[]; /* "all", "direct", "indirect", NULL */

/* The parameters every method of the family reads, as entries of its parameter table
 * (technique/class.h). */
#define FV_VPL_AREA_SAMPLES_PARAM                                                                                      \
    FV_PARAM_INT("area_samples", "16", 1, 4096, "light samples per pixel for area lights (point and spot lights are exact)")
#define FV_VPL_CLAMP_PARAM                                                                                             \
    FV_PARAM_FLOAT("clamp", "0.03", 0.0, 1.0, "geometry-term clamp, as a fraction of the scene's bounding-sphere radius (0 = off)")
#define FV_VPL_SHOW_PARAM                                                                                              \
    FV_PARAM_CHOICE("show", "all", fv_vpl_show_names, "the image, or one of its two terms alone (without emitted light)")
/* The viewer's steps of `vpls` (the paper: 2000 for IR, about 1000 for FIR). */
#define FV_VPL_STEPS "250", "500", "1000", "2000", "4000"

typedef struct fv_vpl_frame {
    fv_gbuffer gb;
    fv_vec3 *direct, *indirect; /* E_direct and the VPL sum per pixel */
    size_t npix;
    fv_camera_basis cam;
    fv_film_views out;
    fv_kit_counters *counters; /* kept from frame to frame (fv_kit_counters_reuse), zeroed by begin */
    fv_kit_progress prog;
    uint64_t rays; /* rays cast outside the passes (first hits, VPLs, cube maps) */
} fv_vpl_frame;

/* The first step of every frame of the family: camera and film checked, buffers (re)sized for the
 * film, counters created, the first-hit buffer traced (stage "gbuffer"), the VPL sum zeroed. */
fv_status fv_vpl_frame_begin(fv_vpl_frame *vf, const fv_scene *s, const fv_frame *frame, fv_film *film, fv_stats *stats,
                             fv_error *err);
/* The last: compose what `show` asks into the film (stage "compose"), report the counters (rays,
 * nan_samples, vpl_shadow_rays, cube_lookups, direct_rays). ok false (a pass was
 * cancelled) or status != FV_OK: nothing is composed or reported; the status to return. */
fv_status fv_vpl_frame_end(fv_vpl_frame *vf, fv_vpl_show show, bool ok, fv_status status, fv_stats *stats, fv_error *err);
void fv_vpl_frame_free(fv_vpl_frame *vf);

/* rgb = emit + albedo / pi (direct + indirect), with the kit's NaN guard (counted in *dropped).
 * direct or indirect NULL: left out; emitted false: no emitted light (to show one term alone). */
void fv_vpl_compose(const fv_gbuffer *gb, const fv_vec3 *direct, const fv_vec3 *indirect, bool emitted, float *rgb,
                    uint64_t *dropped);

#endif
