/* fovea — counter-based random numbers.
 *
 * A stream is a 64-bit key hashed from (seed, pixel, sample, frame) plus a dimension counter;
 * each draw hashes (key, dimension). No state is shared between pixels, so an image does not
 * depend on the thread count or tile order, and any single sample can be replayed alone.
 */
#ifndef FV_CORE_RNG_H
#define FV_CORE_RNG_H

#include <stdint.h>
#include "fovea/math.h" /* FV_HD: these run in CUDA kernels too */

typedef struct fv_rng {
    uint64_t key;
    uint32_t dim;
} fv_rng;

/* A strong 64-bit finaliser (the splitmix64 / murmur3 style xor-shift-multiply cascade). */
FV_HD static inline uint64_t fv_hash64(uint64_t x)
{
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ULL;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebULL;
    x ^= x >> 31;
    return x;
}

FV_HD static inline uint64_t fv_hash_combine(uint64_t h, uint64_t v)
{
    return fv_hash64(h ^ (v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2)));
}

FV_HD static inline fv_rng fv_rng_make(uint64_t seed, uint64_t pixel, uint64_t sample, uint64_t frame)
{
    fv_rng r;
    r.key = fv_hash_combine(fv_hash_combine(fv_hash_combine(fv_hash64(seed), pixel), sample), frame);
    r.dim = 0;
    return r;
}

FV_HD static inline uint32_t fv_rng_u32(fv_rng *r)
{
    return (uint32_t)(fv_hash64(r->key + 0x632be59bd9b4e019ULL * (uint64_t)(++r->dim)) >> 32);
}

/* ---- named streams ----
 *
 * Every random draw in the library belongs to one of these purposes. A stream's key is xor-ed into
 * the frame seed before hashing, so two purposes never share draws even for the same (pixel,
 * sample, frame). Camera paths use the plain seed (key 0).
 */
#define FV_STREAM_CAMERA 0x0ULL                  /* camera paths: (pixel * 2 + eye, sample, frame) */
#define FV_STREAM_KILL 0x6b696c6cULL             /* linear fall-off: the kill decision per sample */
#define FV_STREAM_FOVEATED 0x5851f42d4c957f2dULL /* fpm: foveated photon paths (pixel, attempt, frame) */
#define FV_STREAM_ORDER 0x6f72646572ULL          /* a random launch order (one permutation per seed) */
#define FV_STREAM_MASK 0x6d61736bULL             /* fipr: the foveation mask's xi per pixel (pixel * 2 + eye, 0, frame) */
#define FV_STREAM_VPL 0x76706cULL                /* ir: walk w (w, 0, frame); fir: (purpose << 40 + i, 0, frame) */
/* Light photon map k (1: static M_ls, 2: dynamic M_ld, 100 + pass: pm's maps, 2^32 + pass: ppm's):
 * (photon, sub, frame). */
#define FV_STREAM_PHOTONS(k) ((uint64_t)(k) * 0x9e3779b97f4a7c15ULL)

FV_HD static inline fv_rng fv_rng_stream(uint64_t seed, uint64_t stream, uint64_t index, uint64_t sample, uint64_t frame)
{
    return fv_rng_make(seed ^ stream, index, sample, frame);
}

/* The seed a reference image is rendered with, from a scenario's seed: no measured method ever
 * draws from it, so a 1-sample method's first sample is not the reference's first sample (which
 * would understate its error). */
FV_HD static inline uint64_t fv_seed_reference(uint64_t seed) { return fv_hash_combine(fv_hash64(seed), 0x7265666572656e63ULL); }
/* The seed of the probe that estimates a reference's own noise (src/bench/ref_noise.c): a stream
 * independent of the reference's and of every measured method's. */
FV_HD static inline uint64_t fv_seed_reference_probe(uint64_t seed) { return fv_hash_combine(fv_hash64(seed), 0x70726f6265ULL); }

/* Uniform float in [0, 1): 24 random mantissa bits. */
FV_HD static inline float fv_rng_next(fv_rng *r)
{
    return (float)(fv_rng_u32(r) >> 8) * (1.0f / 16777216.0f);
}

#endif
