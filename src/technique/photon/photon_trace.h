/* fovea — light photon tracing shared by pm, pm-t and fpm (Foveated Photon Mapping, Sec. 3).
 *
 * PT_s / full tracing: light paths of the shared transport (transport/light_path.h), a photon
 * stored at each of their diffuse or glossy vertices, up to `max_depth` bounces (8 in the paper,
 * Sec. 4.1).
 *
 * PT_d: photons for the dynamic objects. The paper renders a cube map of the dynamic objects from
 * the light and samples directions from its covered pixels. Our CPU equivalent samples, from each
 * photon's origin on the light, a direction in the cone of a dynamic object's bounding sphere
 * (fv_dyn_dirs): exact densities and no pixel-sized gaps at silhouettes, which the negative photons
 * need to cancel the static light exactly. A photon sent that way whose first hit is
 * a dynamic object spawns a positive photon path (reflected, refracted or absorbed by the object's
 * material, stored everywhere it lands) and a negative one that pierces the object and carries
 * the negated flux through the static scene, cancelling the light the object now blocks. Paths
 * whose first hit is static are dropped: the static map already holds them. Limits: light reaching
 * a dynamic object only after bouncing elsewhere is not re-traced (as in the paper).
 *
 * Results do not depend on the thread count: photon i always uses random stream i, and the
 * per-block outputs are concatenated in block order.
 */
#ifndef FV_PHOTON_TRACE_H
#define FV_PHOTON_TRACE_H

#include "scene/query.h"
#include "technique/kit.h"
#include "technique/photon/photon_map.h"

/* Where the dynamic objects are: their bounding spheres at the scene's current time. */
typedef struct fv_dyn_dirs fv_dyn_dirs;
fv_status fv_dyn_dirs_create(fv_dyn_dirs **out, fv_error *err);
void fv_dyn_dirs_destroy(fv_dyn_dirs *d);
fv_status fv_dyn_dirs_build(fv_dyn_dirs *d, const fv_scene *s, fv_error *err);
int fv_dyn_dirs_count(const fv_dyn_dirs *d);
/* Sphere k of the last build: centre and radius (a little over the object's box, plus the ray
 * offset). */
void fv_dyn_dirs_sphere(const fv_dyn_dirs *d, int k, fv_vec3 *c, float *r);

/* Photon guiding (technique/photon/guide.h): fills the five numbers a photon's emission uses
 * (fv_light_path_emit_u) from rng and returns their density relative to uniform numbers, by which
 * the photon's flux is divided so the map stays unbiased; a density <= 0 drops the photon. */
typedef float (*fv_photon_warp_fn)(const void *ctx, fv_rng *rng, float u[5]);

/* Room the tracers below keep from call to call: the blocks' photon buffers, grown, never shrunk,
 * so that a warmed-up frame traces its photons without allocating (docs/threads.md, "No
 * allocation in a frame"). One room serves one call at a time; a technique that traces several
 * maps a frame, one after the other, keeps one. */
typedef struct fv_photon_room fv_photon_room;
fv_photon_room *fv_photon_room_create(void); /* NULL when out of memory */
void fv_photon_room_destroy(fv_photon_room *r);

typedef struct fv_photon_job {
    const fv_scene *scene;
    int64_t count;         /* photons emitted */
    uint64_t seed;
    int frame;             /* decorrelates frames; use 0 for maps traced once */
    int max_depth;
    int threads;
    uint64_t stream;       /* distinguishes several maps traced in one frame: FV_STREAM_PHOTONS(stream) */
    fv_kit_progress *progress; /* optional: reported as blocks of photons finish; a cancel stops
                                  the tracing with FV_ERR_CANCELLED */
    fv_photon_warp_fn warp;     /* fv_photon_trace_lights: NULL for uniform emission */
    const void *warp_ctx;
    fv_photon_room *room;       /* optional: kept room for the blocks (NULL: room for the call only) */
} fv_photon_job;

/* The start of photon i of a job: its random stream (left where the walk goes on), the five numbers
 * its emission used (fv_light_sample_emission's u), origin, direction and flux (warped and
 * compensated when the job has a warp). False when nothing was emitted. Every tracer of light
 * photons starts here, so photon i is the same photon in all. */
bool fv_photon_emit(const fv_photon_job *job, int64_t i, fv_rng *rng, float u[5], fv_vec3 *o, fv_vec3 *d, fv_vec3 *flux);

/* Runs fn(ctx, b) for every block b in [0, nblocks) on job->threads threads in any order, reporting
 * progress to job->progress from one thread; false when the callback cancelled (the remaining
 * blocks are skipped). Callers keep each block's output apart and join them in block order, so
 * their results do not depend on the thread count. */
typedef void (*fv_photon_block_fn)(void *ctx, int64_t block);
bool fv_photon_blocks(const fv_photon_job *job, int64_t nblocks, fv_photon_block_fn fn, void *ctx);

/* Traces job->count photons from the lights through `set` (FV_TRACE_ALL for plain photon mapping,
 * FV_TRACE_STATIC for M_ls), appending the stored photons to out. Each carries 1/count of the
 * emitted power it represents. *rays receives the number of rays cast. */
fv_status fv_photon_trace_lights(const fv_photon_job *job, fv_trace_set set, fv_photon_map *out, uint64_t *rays, fv_error *err);

/* Traces job->count photons towards the dynamic objects (PT_d) with the maps in dirs; appends the
 * positive and negative photons to out. */
fv_status fv_photon_trace_dynamic(const fv_photon_job *job, const fv_dyn_dirs *dirs, fv_photon_map *out, uint64_t *rays,
                                  fv_error *err);

#endif
