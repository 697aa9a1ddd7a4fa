/* fovea-raybench — the raw Embree ceiling on this machine: single-ray rtcIntersect1 throughput
 * on a scene, for coherent rays (camera rays in scanline order) and incoherent rays (random
 * origins inside the scene bounds, random directions), with no shading at all. The path tracer's
 * rays/s is reported against these numbers by scripts/bench-pt.
 *
 * usage: fovea-raybench SCENE [--size WxH] [--rays N] [--threads T]
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "core/rng.h"
#include "fovea/view.h"
#include "scene/scene_impl.h"

static double run(const fv_scene *s, const fv_camera_basis *cam, int coherent, long nrays, int threads, long *hits_out)
{
    long hits = 0;
    fv_vec3 lo = s->lo, ext = fv_sub(s->hi, s->lo);
    const long npix = (long)cam->width * cam->height;
    double t0 = omp_get_wtime();
#pragma omp parallel for schedule(dynamic, 4096) reduction(+ : hits) num_threads(threads)
    for (long i = 0; i < nrays; i++) {
        fv_vec3 o, d;
        if (coherent) {
            long p = i % npix;
            o = cam->pos;
            d = fv_camera_dir(cam, (float)(p % cam->width) + 0.5f, (float)(p / cam->width) + 0.5f);
        } else {
            fv_rng r = fv_rng_make(5, (uint64_t)i, 0, 0);
            o = fv_add(lo, fv_mul(ext, fv_v3(fv_rng_next(&r), fv_rng_next(&r), fv_rng_next(&r))));
            float z = 1.0f - 2.0f * fv_rng_next(&r), rr = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * FV_PI * fv_rng_next(&r);
            d = fv_v3(rr * cosf(phi), rr * sinf(phi), z);
        }
        struct RTCIntersectContext ctx;
        rtcInitIntersectContext(&ctx);
        struct RTCRayHit rh;
        memset(&rh, 0, sizeof rh);
        rh.ray.org_x = o.x; rh.ray.org_y = o.y; rh.ray.org_z = o.z;
        rh.ray.dir_x = d.x; rh.ray.dir_y = d.y; rh.ray.dir_z = d.z;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xffffffffu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(s->rtc_all, &ctx, &rh);
        hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    double dt = omp_get_wtime() - t0;
    *hits_out = hits;
    return (double)nrays / dt;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help")) {
        fprintf(argc < 2 ? stderr : stdout, "usage: fovea-raybench SCENE [--size WxH] [--rays N] [--threads T]\n");
        return argc < 2 ? 2 : 0;
    }
    int w = 512, h = 512, threads = omp_get_max_threads();
    long nrays = 20000000;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (!strcmp(argv[i], "--size") && sscanf(argv[i + 1], "%dx%d", &w, &h) == 2) continue;
        if (!strcmp(argv[i], "--rays")) { nrays = atol(argv[i + 1]); continue; }
        if (!strcmp(argv[i], "--threads")) { threads = atoi(argv[i + 1]); continue; }
        fprintf(stderr, "fovea-raybench: bad option '%s'\n", argv[i]);
        return 2;
    }
    if (w <= 0 || h <= 0 || nrays <= 0 || threads <= 0) {
        fprintf(stderr, "fovea-raybench: size, rays and threads must be positive\n");
        return 2;
    }
    fv_error err;
    fv_scene *s;
    fv_view *v;
    if (fv_scene_load(argv[1], NULL, &s, &v, &err) != FV_OK) {
        fprintf(stderr, "fovea-raybench: %s\n", err.msg);
        return err.status == FV_ERR_INVALID || err.status == FV_ERR_IO ? 2 : 1;
    }
    fv_camera c;
    fv_view_camera(v, s, 0.0, w, h, &c);
    fv_view_destroy(v);
    fv_camera_basis cam;
    if (fv_camera_basis_make(&c, &cam, &err) != FV_OK) {
        fprintf(stderr, "fovea-raybench: %s\n", err.msg);
        return 2;
    }
    long hc, hi;
    double coh = run(s, &cam, 1, nrays, threads, &hc);
    double inc = run(s, &cam, 0, nrays, threads, &hi);
    printf("{\"scene\": \"%s\", \"threads\": %d, \"rays\": %ld, \"coherent_mrays_per_s\": %.3f, "
           "\"incoherent_mrays_per_s\": %.3f, \"coherent_hit_fraction\": %.3f, \"incoherent_hit_fraction\": %.3f}\n",
           argv[1], threads, nrays, coh / 1e6, inc / 1e6, (double)hc / nrays, (double)hi / nrays);
    fv_scene_destroy(s);
    return 0;
}
