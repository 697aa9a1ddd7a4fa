/* fovea — pm-t's light photon maps: M_ls once, M_ld every frame (see pm_temporal.h). */
#include <string.h>
#include "scene/light.h"
#include "technique/photon/pm_temporal.h"

fv_status fv_pmt_maps_init(fv_pmt_maps *m, const fv_scene *s, fv_error *err)
{
    memset(m, 0, sizeof *m);
    fv_photon_map_init(&m->ls);
    fv_photon_map_init(&m->ld);
    m->lights_move = fv_scene_lights_move(s);
    return fv_dyn_dirs_create(&m->dirs, err);
}

void fv_pmt_maps_free(fv_pmt_maps *m)
{
    fv_photon_map_free(&m->ls);
    fv_photon_map_free(&m->ld);
    fv_dyn_dirs_destroy(m->dirs);
    m->dirs = NULL;
}

fv_status fv_pmt_maps_update(fv_pmt_maps *m, const fv_photon_job *frame_job, double n_light, double dyn_fraction, float cell, fv_stats *stats,
                             uint64_t *rays, fv_error *err)
{
    fv_photon_job job = *frame_job;
    const fv_scene *s = job.scene;
    const int frame = job.frame;
    fv_status rc = FV_OK;
    bool dyn = fv_scene_dynamic_object_count(s) > 0;
    double n_ls = dyn ? n_light * (1.0 - dyn_fraction) : n_light, n_ld = dyn ? n_light - n_ls : 0.0;
    bool fresh = !m->ls_done || m->lights_move;
    if (fresh) {
        fv_photon_map_clear(&m->ls);
        job.count = (int64_t)n_ls;
        /* traced once, valid for every frame, unless the lights move */
        job.frame = m->lights_move ? frame : 0;
        job.stream = 1;
        rc = fv_photon_trace_lights(&job, FV_TRACE_STATIC, &m->ls, rays, err);
        m->ls_done = rc == FV_OK;
        if (!m->ls_done) fv_photon_map_clear(&m->ls); /* a cancelled trace must not leave half a map */
        job.frame = frame;
    }
    if (rc == FV_OK && (fresh || m->ls.cell != cell)) rc = fv_photon_map_build_mt(&m->ls, cell, job.threads, err);
    fv_photon_map_clear(&m->ld);
    if (rc == FV_OK && n_ld >= 1.0) {
        if ((rc = fv_dyn_dirs_build(m->dirs, s, err)) == FV_OK) {
            job.count = (int64_t)n_ld;
            job.stream = 2;
            rc = fv_photon_trace_dynamic(&job, m->dirs, &m->ld, rays, err);
        }
    }
    if (rc == FV_OK) rc = fv_photon_map_build_mt(&m->ld, cell, job.threads, err);
    fv_stats_add_count(stats, "light_photons", m->ls.n + m->ld.n);
    fv_stats_add_count(stats, "dynamic_photons", m->ld.n);
    return rc;
}
