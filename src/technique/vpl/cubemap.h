/* fovea — a pool of depth cube maps, one per virtual point light (VPL), for the visibility of
 * VPLs (Foveated Instant Radiosity, Sec. 3.4 and Sec. 4.1: each VPL's light is
 * shadowed by a low-resolution shadow map, 128x128 in the paper). A map is built either by
 * rasterising the scene's triangles into its faces, as the paper's GPU does (cube_raster.h), or by
 * casting one ray per texel with Embree from the VPL, in packets of eight rays sharing the VPL as
 * origin (fv_scene_intersect8). Both store the same depths (up to rounding and ties on shared
 * edges); rasterising costs per triangle and covered texel, rays per texel, so the automatic choice
 * rasterises scenes up to FV_CUBE_RASTER_MAX_TRIANGLES triangles and traces larger ones and any
 * scene with signed distance fields, which have no triangles.
 *
 * Cube face convention (one mapping, used by build and lookup alike):
 *   face f = 2 a + k looks along axis a (0 x, 1 y, 2 z), positive for k = 0, negative for k = 1:
 *   0 +X, 1 -X, 2 +Y, 3 -Y, 4 +Z, 5 -Z. With s = +1 (k = 0) or -1 (k = 1), the face's axes are
 *       U = s e[(a + 1) % 3],   V = e[(a + 2) % 3]     (so U x V = s e[a]: +X: U +Y, V +Z;
 *       -X: U -Y, V +Z; +Y: U +Z, V +X; -Y: U -Z, V +X; +Z: U +X, V +Y; -Z: U -X, V +Y),
 *   and (u, v) in [0, 1]^2 is the direction  s e[a] + (2u - 1) U + (2v - 1) V  (not unit).
 *   Texel (x, y) of a face of n x n covers u in [x, x + 1) / n, v in [y, y + 1) / n; its centre is
 *   ((x + 0.5) / n, (y + 0.5) / n). A direction goes to the face of its largest |component| (ties:
 *   x before y before z; a zero direction reads as +X's centre).
 *
 * Depths: a texel stores the distance from the map's centre (the VPL point moved off its surface
 * by fv_offset_point along its normal) to the first surface along the ray through the texel
 * centre, +inf when the ray leaves the scene. A VPL lights only the hemisphere of its normal
 * (its cosine is zero behind), so when a normal is given texels whose centre direction is not in
 * front of it are not traced and store 0 (everything there reads as occluded); a face with no
 * texel in front (the face behind the VPL) is skipped whole. Without a normal all six faces are
 * traced from the point itself. A map never built reads +inf everywhere (all visible).
 *
 * Bias rule (lookup): q at distance r from the centre is visible when r <= depth + b(r) with
 *     b(r) = FV_CUBE_BIAS_TEXELS * (2 r / n) + eps,
 * 2 r / n bounding the width of one texel at distance r over a whole face (a texel spans 2 / n of
 * the face plane at unit distance along the axis, and less elsewhere), eps the scene's ray offset.
 * The stored depth belongs to the texel's centre ray, while q lies on a ray up to half a texel
 * diagonal (0.71 texel) away: on a receiving surface at angle theta to that ray the depths differ
 * by up to 0.71 x width x tan(theta), so 2 texel widths accept surfaces up to ~70 degrees from
 * head-on; grazing receivers and occluders thinner than b(r) are the known failures (leaks and
 * acne both near silhouettes). The 2x2 filter's taps lie up to 1.41 texels from q: each tap gets
 * twice the bias.
 *
 * Threads: building map i writes only map i; fv_cubemaps_build_many builds each map on one thread,
 * so the depths do not depend on the thread count. Lookups are read-only and thread-safe while no
 * map is being built. Memory (count x 6 x n^2 floats) is allocated once by create.
 */
#ifndef FV_TECHNIQUE_VPL_CUBEMAP_H
#define FV_TECHNIQUE_VPL_CUBEMAP_H

#include <math.h>
#include <stdbool.h>
#include "fovea/math.h"
#include "fovea/scene.h"
#include "fovea/status.h"

#define FV_CUBE_MIN_SIZE 8
#define FV_CUBE_MAX_SIZE 2048
#define FV_CUBE_BIAS_TEXELS 2.0f
/* Above this many triangles FV_CUBE_BUILD_AUTO casts rays. Measured (docs/results.md, "Cube maps:
 * rasterised or traced"): a rasterised 128^2 map costs about 0.2 us per triangle and thread, a
 * traced one 4-7 ms per thread whatever the triangle count, so they cross near 20-35 thousand
 * triangles (cornell-fir's 32: raster 7x faster; city's 180,906: rays 8x faster). */
#define FV_CUBE_RASTER_MAX_TRIANGLES 20000
#define FV_CUBE_STR_(x) #x
#define FV_CUBE_STR(x) FV_CUBE_STR_(x)

typedef struct fv_cubemaps fv_cubemaps;

typedef enum fv_cube_build {
    FV_CUBE_BUILD_AUTO = 0, /* raster up to FV_CUBE_RASTER_MAX_TRIANGLES and without SDFs, else rays */
    FV_CUBE_BUILD_RASTER,   /* rasterise (rays when the scene has SDF objects) */
    FV_CUBE_BUILD_RAYS      /* cast a ray per texel */
} fv_cube_build;

typedef enum fv_cube_filter {
    FV_CUBE_NEAREST = 0, /* the texel q falls in: 0 or 1 */
    FV_CUBE_PCF2X2       /* percentage-closer: the four texels around q, bilinear weights, across face edges */
} fv_cube_filter;

/* ---- the face mapping ---- */

static inline float fv_cube_comp(fv_vec3 d, int k) { return k == 0 ? d.x : (k == 1 ? d.y : d.z); }

/* The axes of face f: its outward axis A (s e[a]) and the directions U and V grow along. */
static inline void fv_cube_face_axes(int f, fv_vec3 *A, fv_vec3 *U, fv_vec3 *V)
{
    const int a = f >> 1;
    const float s = (f & 1) ? -1.0f : 1.0f;
    fv_vec3 e[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    *A = fv_scale(e[a], s);
    *U = fv_scale(e[(a + 1) % 3], s);
    *V = e[(a + 2) % 3];
}

/* (face, u, v) -> direction (not unit; its component along the face axis is 1). u, v outside
 * [0, 1] give directions past the face's edge, which fv_cube_face_of maps to the neighbour face. */
static inline fv_vec3 fv_cube_dir(int f, float u, float v)
{
    fv_vec3 A, U, V;
    fv_cube_face_axes(f, &A, &U, &V);
    return fv_add(A, fv_add(fv_scale(U, 2.0f * u - 1.0f), fv_scale(V, 2.0f * v - 1.0f)));
}

/* direction -> face, and (u, v) in [0, 1]^2 on it. */
static inline int fv_cube_face_of(fv_vec3 d, float *u, float *v)
{
    const float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    const int a = (ax >= ay && ax >= az) ? 0 : (ay >= az ? 1 : 2);
    const float da = fv_cube_comp(d, a);
    const int f = 2 * a + (da < 0.0f);
    const float m = fabsf(da);
    if (!(m > 0.0f)) {
        *u = *v = 0.5f;
        return 0;
    }
    fv_vec3 A, U, V;
    fv_cube_face_axes(f, &A, &U, &V);
    *u = fv_clampf(0.5f * (fv_dot(d, U) / m + 1.0f), 0.0f, 1.0f);
    *v = fv_clampf(0.5f * (fv_dot(d, V) / m + 1.0f), 0.0f, 1.0f);
    return f;
}

/* ---- the pool ---- */

/* count maps of 6 faces of face_size^2 texels. count < 1 -> FV_ERR_INVALID naming `vpls`,
 * face_size outside [FV_CUBE_MIN_SIZE, FV_CUBE_MAX_SIZE] -> FV_ERR_INVALID naming `cube_size`
 * (*out NULL); no memory -> FV_ERR_NOMEM. */
fv_status fv_cubemaps_create(int count, int face_size, fv_cubemaps **out, fv_error *err);
void fv_cubemaps_destroy(fv_cubemaps *maps);
/* fv_cubemaps_create for a technique's parameters: running out of memory is then the parameters'
 * fault, refused as FV_ERR_INVALID naming vpls and cube_size and the size they asked for. */
fv_status fv_vpl_cubemaps_create(int count, int face_size, fv_cubemaps **out, fv_error *err);
/* The parameter cube_build=auto|raster|rays of the techniques with cube maps, in enum order. */
extern const char *const fv_cube_build_names[];
/* The parameter cube_filter=nearest|pcf, in fv_cube_filter's order. */
extern const char *const fv_cube_filter_names[];
/* The two parameters' entries in a class's parameter table (technique/class.h). */
#define FV_CUBE_BUILD_PARAM                                                                                             \
    FV_PARAM_CHOICE("cube_build", "auto", fv_cube_build_names,                                                         \
                    "how depth cube maps are made: rasterising the triangles (the paper's way), a ray per texel, or auto " \
                    "(raster up to " FV_CUBE_STR(FV_CUBE_RASTER_MAX_TRIANGLES) " triangles and without SDFs)")
#define FV_CUBE_FILTER_PARAM(h) FV_PARAM_CHOICE("cube_filter", "nearest", fv_cube_filter_names, h)
/* How maps are built from now on (FV_CUBE_BUILD_AUTO at creation). */
void fv_cubemaps_set_build(fv_cubemaps *maps, fv_cube_build how);
/* Whether `how` rasterises in scene s. */
bool fv_cube_build_rasterises(fv_cube_build how, const fv_scene *s);
int fv_cubemaps_count(const fv_cubemaps *maps);
int fv_cubemaps_face_size(const fv_cubemaps *maps);

/* Builds map i for a VPL at surface point p with unit normal *n (n NULL: a point in free space, all
 * six faces, no offset) in the committed scene s, on the calling thread. i outside [0, count) or a
 * non-finite p -> FV_ERR_INVALID, the map untouched. */
fv_status fv_cubemaps_build(fv_cubemaps *maps, const fv_scene *s, int i, fv_vec3 p, const fv_vec3 *n, fv_error *err);

/* Builds maps indices[k] for VPLs at positions[k] with normals[k] (normals NULL: none), k < count,
 * each map on one of `threads` threads (0: all). indices must be distinct. An index out of range or
 * a non-finite position -> FV_ERR_INVALID before anything is built. */
fv_status fv_cubemaps_build_many(fv_cubemaps *maps, const fv_scene *s, const int *indices, const fv_vec3 *positions,
                                 const fv_vec3 *normals, int count, int threads, fv_error *err);

/* fv_cubemaps_build_many in steps, for one parallel region that builds batch after batch of maps
 * and uses each in turn (ir-low, docs/threads.md): fv_cubemaps_prepare once before the region (the
 * triangles to rasterise in the frame's scene, *soup; NULL when maps are traced), then per batch
 * fv_cubemaps_check (one thread; its error is fv_cubemaps_build_many's) and fv_cubemaps_build_team
 * (every thread of the region, same arguments: each map on one thread, the team's barrier after).
 * The soup is the pool's own, kept from frame to frame and refreshed by prepare (its room grown,
 * never shrunk): valid until the next prepare or build. Same depths as fv_cubemaps_build_many. */
typedef struct fv_tri_soup fv_tri_soup; /* cube_raster.h */
fv_status fv_cubemaps_prepare(fv_cubemaps *maps, const fv_scene *s, fv_tri_soup **soup, fv_error *err);
fv_status fv_cubemaps_check(const fv_cubemaps *maps, const int *indices, const fv_vec3 *positions, const fv_vec3 *normals,
                            int count, fv_error *err);
void fv_cubemaps_build_team(fv_cubemaps *maps, const fv_scene *s, const fv_tri_soup *soup, const int *indices,
                            const fv_vec3 *positions, const fv_vec3 *normals, int count);

/* Visibility of point q from VPL i (its map's centre), by the bias rule above: the nearest
 * texel's test. A non-finite q reads as not visible; q within 2 eps of the centre as visible. */
bool fv_cubemaps_visible(const fv_cubemaps *maps, int i, fv_vec3 q);
/* The same as a fraction in [0, 1]; FV_CUBE_NEAREST gives exactly fv_cubemaps_visible's 0 or 1. */
float fv_cubemaps_visibility(const fv_cubemaps *maps, int i, fv_vec3 q, fv_cube_filter filter);

/* Map i's centre (the point rays start from) and its depths: 6 faces of n x n, face-major, rows
 * of v, texel (f, x, y) at [(f n + y) n + x]. Read-only. */
fv_vec3 fv_cubemaps_centre(const fv_cubemaps *maps, int i);
const float *fv_cubemaps_depths(const fv_cubemaps *maps, int i);

#endif
