/* fovea — the sphere-tracing family's four registered methods and their parameters: `sdf-gt`,
 * `sdf-relaxed`, `ipr` and `fipr` (sdf_pipeline.h says what each does). All four refuse a scene without
 * a signed distance field object (the registry checks the class's `sdf_only`).
 */
#include <stdlib.h>
#include <string.h>
#include "technique/class.h"
#include "technique/sdf/sdf_device.h"
#include "technique/sdf/sdf_pipeline.h"

typedef struct family_state {
    fv_sdf_pipeline *pipe; /* the cpu device */
    fv_sdf_device *dev;    /* portable and cuda (sdf_device.h) */
} family_state;

/* The show modes each method has, in fv_sdf_show's order: the baselines one level, ipr the level
 * each pixel came from, only fipr a mask and edges. The reader and the parameter tables share them. */
static const char *const k_show_traced[] = {"image", "steps", NULL};
static const char *const k_show_ipr[] = {"image", "steps", "level", NULL};
static const char *const k_show_fipr[] = {"image", "steps", "level", "mask", "edges", NULL};
/* The sample grids (1x1, 2x2, 4x4) and fipr's refresh periods: the only values of two int parameters. */
static const char *const k_spp[] = {"1", "4", "16", NULL};
static const char *const k_refresh[] = {"1", "2", "4", NULL};

static fv_status bad(fv_error *err, const char *key, double v, const char *what)
{
    return fv_error_set(err, FV_ERR_INVALID, "parameter %s=%g %s", key, v, what);
}

static fv_status read_opts(fv_sdf_method m, fv_params *p, fv_sdf_opts *o, fv_error *err)
{
    memset(o, 0, sizeof *o);
    o->method = m;
    fv_status s;
    int show;
    double hit, ambient, relax = 1.0;
    bool shadows, wide;
    const char *const *shows = m == FV_SDF_FIPR ? k_show_fipr : m == FV_SDF_IPR ? k_show_ipr : k_show_traced;
    if ((s = fv_params_int(p, "spp", 1, 1, 16, &o->spp, err)) ||
        (s = fv_params_int(p, "max_steps", 256, 1, 65535, &o->march.max_steps, err)) ||
        (s = fv_params_float(p, "hit", 0.25, 1e-4, 16.0, &hit, err)) ||
        (s = fv_params_float(p, "ambient", 0.0, 0.0, 1.0, &ambient, err)) || (s = fv_params_bool(p, "shadows", true, &shadows, err)) ||
        (s = fv_params_bool(p, "simd", true, &wide, err)) || (s = fv_params_choice(p, "show", 0, shows, &show, err)))
        return s;
    if (o->spp != 1 && o->spp != 4 && o->spp != 16) return bad(err, "spp", o->spp, "must be 1, 4 or 16 (1, 2 or 4 samples per pixel along each axis)");
    if (m == FV_SDF_RELAXED || m == FV_SDF_IPR || m == FV_SDF_FIPR) {
        if ((s = fv_params_float(p, "relax", m == FV_SDF_RELAXED ? 1.6 : 1.0, -1e9, 1e9, &relax, err))) return s;
        if (!(relax >= 1.0 && relax < 2.0)) return bad(err, "relax", relax, "must be in [1, 2) (1: plain sphere tracing)");
    }
    o->levels = 1;
    o->min_filter = true;
    if (m == FV_SDF_IPR || m == FV_SDF_FIPR) {
        int lo = m == FV_SDF_FIPR ? 3 : 1;
        if ((s = fv_params_int(p, "levels", 3, -1000000, 1000000, &o->levels, err)) ||
            (s = fv_params_bool(p, "min_filter", true, &o->min_filter, err)) ||
            (s = fv_params_bool(p, "shadow_reuse", false, &o->shadow_reuse, err)))
            return s;
        if (o->levels < lo || o->levels > FV_PYRAMID_MAX_LEVELS)
            return fv_error_set(err, FV_ERR_INVALID, "parameter levels=%d must be in [%d, %d]%s", o->levels, lo, FV_PYRAMID_MAX_LEVELS,
                                m == FV_SDF_FIPR ? " (fipr needs a tip, a middle and a target level)" : "");
    }
    if (m == FV_SDF_FIPR) {
        double fovea, outer, edge, sigma;
        int refresh;
        if ((s = fv_params_float(p, "fovea_deg", 7.5, -1e9, 1e9, &fovea, err)) ||
            (s = fv_params_float(p, "outer_deg", 30.0, -1e9, 1e9, &outer, err)) ||
            (s = fv_params_float(p, "edge", 0.25, 0.0, 1e6, &edge, err)) ||
            (s = fv_params_int(p, "refresh", 1, -1000000, 1000000, &refresh, err)) || (s = fv_params_bool(p, "blur", false, &o->blur, err)) ||
            (s = fv_params_float(p, "blur_sigma", 2.0, 0.0, 100.0, &sigma, err)))
            return s;
        if (!(fovea >= 0.0 && fovea < 180.0)) return bad(err, "fovea_deg", fovea, "must be in [0, 180) degrees of eccentricity");
        if (!(outer > fovea)) return bad(err, "outer_deg", outer, "must be greater than fovea_deg");
        if (refresh != 1 && refresh != 2 && refresh != 4) return bad(err, "refresh", refresh, "must be 1, 2 or 4 (frames between refreshes outside the mask)");
        o->fovea_deg = (float)fovea;
        o->outer_deg = (float)outer;
        o->edge = (float)edge;
        o->refresh = refresh;
        o->blur_sigma = (float)sigma;
    }
    o->march.relax = (float)relax;
    o->march.wide = wide;
    o->hit = (float)hit;
    o->shade.ambient = (float)ambient;
    o->shade.shadows = shadows;
    o->show = (fv_sdf_show)show;
    return FV_OK;
}

static fv_status create_method(fv_sdf_method m, const fv_scene *scene, fv_params *params, fv_device device, const fv_log *log, void **state,
                               fv_error *err)
{
    fv_sdf_opts o;
    fv_status s = read_opts(m, params, &o, err);
    if (s != FV_OK) return s;
    if (device != FV_DEVICE_CPU && o.show != FV_SDF_SHOW_IMAGE)
        return fv_error_set(err, FV_ERR_INVALID, "parameter show=%s: only the cpu device draws diagnostics (device %s renders the image)",
                            k_show_fipr[o.show], fv_device_name(device));
    int meshes = fv_scene_object_count(scene) - fv_scene_sdf_object_count(scene);
    if (meshes > 0)
        fv_log_warn(log, "%d mesh object%s not sphere-traced: this method sees only the signed distance fields (pt renders both)",
                   meshes, meshes == 1 ? " is" : "s are");
    fv_env_desc env;
    if (fv_scene_env(scene, &env))
        fv_log_warn(log, "the environment light is not shaded: this method shades point, spot and directional lights only (ambient=A adds a constant term; pt sees it)");
    family_state *st = calloc(1, sizeof *st);
    if (!st) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    s = device == FV_DEVICE_CPU ? fv_sdf_pipeline_create(scene, &o, &st->pipe, err) : fv_sdf_device_create(scene, &o, device, &st->dev, err);
    if (s != FV_OK) {
        free(st);
        return s;
    }
    *state = st;
    return FV_OK;
}

static fv_status render(void *state, const fv_frame *frame, fv_film *film, fv_stats *stats, fv_error *err)
{
    family_state *st = state;
    return st->dev ? fv_sdf_device_render(st->dev, frame, film, stats, err) : fv_sdf_pipeline_render(st->pipe, frame, film, stats, err);
}

/* A stereo frame: both eyes at once on a device (one host wait on CUDA); the CPU pipeline renders
 * them one after the other, as two render calls do. */
static fv_status render_pair(void *state, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    family_state *st = state;
    if (st->dev) return fv_sdf_device_render_pair(st->dev, frames, films, stats, err);
    fv_status s = render(state, &frames[0], films[0], stats, err);
    return s == FV_OK ? render(state, &frames[1], films[1], stats, err) : s;
}

/* A frame queued (docs/gpu.md, "Frames in flight"): on a device without a host wait; on the CPU
 * rendered now, collect then only hands it over. */
static fv_status submit(void *state, int eyes, const fv_frame *frames, fv_film *const *films, fv_stats *stats, fv_error *err)
{
    family_state *st = state;
    if (st->dev) return fv_sdf_device_submit(st->dev, eyes, frames, films, stats, err);
    return eyes == 2 ? render_pair(state, frames, films, stats, err) : render(state, frames, films[0], stats, err);
}

static fv_status collect(void *state, fv_error *err)
{
    family_state *st = state;
    return st->dev ? fv_sdf_device_collect(st->dev, err) : FV_OK;
}

static void destroy(void *state)
{
    family_state *st = state;
    if (!st) return;
    fv_sdf_pipeline_destroy(st->pipe);
    fv_sdf_device_destroy(st->dev);
    free(st);
}

/* All four also run on the device backends (sdf_device.h), so the registry hands them the device. */
static fv_status create_gt(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    return create_method(FV_SDF_GT, s, p, d, l, st, e);
}
static fv_status create_relaxed(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    return create_method(FV_SDF_RELAXED, s, p, d, l, st, e);
}
static fv_status create_ipr(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    return create_method(FV_SDF_IPR, s, p, d, l, st, e);
}
static fv_status create_fipr(const fv_scene *s, fv_params *p, fv_device d, const fv_log *l, void **st, fv_error *e)
{
    return create_method(FV_SDF_FIPR, s, p, d, l, st, e);
}

#define COMMON_PARAMS                                                                                                    \
    {.key = "spp", .type = FV_PARAM_INT, .def = "1", .min = 1, .max = 16, .choices = k_spp,                               \
     .help = "samples per pixel: a regular 1x1, 2x2 or 4x4 grid"},                                                          \
        FV_PARAM_INT("max_steps", "256", 1, 65535, "field evaluations per ray; a ray still marching then counts as a hit"), \
        FV_PARAM_FLOAT("hit", "0.25", 1e-4, 16.0, "hit distance as a fraction of the ray's footprint at its distance"),      \
        FV_PARAM_FLOAT("ambient", "0", 0.0, 1.0, "constant light, ambient x albedo (0: direct light only, as pt max_depth=1)"), \
        FV_PARAM_BOOL("shadows", "true", "hard shadows by sphere tracing towards each light"),                              \
        FV_PARAM_BOOL("simd", "true", "evaluate the field for 8 rays at once (false: the scalar loop; same image)")

/* relax: plain sphere tracing at 1; the over-relaxed step needs it below 2 (Keinert et al. 2014). */
#define RELAX_PARAM(d, h)                                                                                                \
    {.key = "relax", .type = FV_PARAM_FLOAT, .def = (d), .min = 1.0, .max = 2.0, .max_open = true, .help = (h)}

static const fv_param_info k_gt_params[] = {
    COMMON_PARAMS,
    FV_PARAM_CHOICE("show", "image", k_show_traced, "the image, or steps per ray from blue (1) to red (256)"),
};
static const fv_param_info k_relaxed_params[] = {
    COMMON_PARAMS,
    RELAX_PARAM("1.6", "step factor"),
    FV_PARAM_CHOICE("show", "image", k_show_traced, "the image, or steps per ray from blue (1) to red (256)"),
};
static const fv_param_info k_ipr_params[] = {
    COMMON_PARAMS,
    FV_PARAM_INT("levels", "3", 1, FV_PYRAMID_MAX_LEVELS, "pyramid levels, 1 = sdf-gt (the tip has 1/4^(levels-1) of the rays)"),
    FV_PARAM_BOOL("min_filter", "true", "start at the 3x3 minimum of the depths below (false: the parent's depth)"),
    RELAX_PARAM("1", "over-relaxation of every level's march"),
    FV_PARAM_BOOL("shadow_reuse", "false", "ours, for a CPU: take shadows from the level below where its 3x3 agree"),
    FV_PARAM_CHOICE("show", "image", k_show_ipr, "the image, steps per ray, or the level each pixel came from"),
};
static const fv_param_info k_fipr_params[] = {
    COMMON_PARAMS,
    FV_PARAM_INT("levels", "3", 3, FV_PYRAMID_MAX_LEVELS, "pyramid levels (a tip, a middle and a target level at least)"),
    FV_PARAM_BOOL("min_filter", "true", "start at the 3x3 minimum of the depths below"),
    RELAX_PARAM("1", "over-relaxation of every level's march"),
    FV_PARAM_BOOL("shadow_reuse", "false", "ours, for a CPU: take shadows from the level below where its 3x3 agree"),
    {.key = "fovea_deg", .type = FV_PARAM_FLOAT, .def = "7.5", .min = 0.0, .max = 180.0, .max_open = true,
     .help = "eccentricity traced at the target level (the mask is 1)"},
    {.key = "outer_deg", .type = FV_PARAM_FLOAT, .def = "30", .min = 0.0, .min_open = true, .max = 1e9,
     .help = "eccentricity beyond which the mask is 0, edges included; greater than fovea_deg"},
    FV_PARAM_FLOAT("edge", "0.25", 0.0, 1e6, "Sobel threshold on the tip's depth, relative to the depth"),
    {.key = "refresh", .type = FV_PARAM_INT, .def = "1", .min = 1, .max = 4, .choices = k_refresh,
     .help = "frames between refreshes of the pixels outside the mask"},
    FV_PARAM_BOOL("blur", "false", "pass 5, a Gaussian blur of the mask's transitions"),
    FV_PARAM_FLOAT("blur_sigma", "2", 0.0, 100.0, "its standard deviation in pixels"),
    FV_PARAM_CHOICE("show", "image", k_show_fipr, "the image or a pass's output"),
};

/* The viewer's steps of spp: every grid there is. */
#define SDF_STEPS {"spp", {"1", "4", "16"}, false}

/* The conformance suite's scenes for this family are its SDF twins (tests/conformance): in
 * sdf-furnace the camera and a point light of intensity 2 pi sit at the centre of a hollow sphere
 * of radius 1 and albedo 0.5, so every pixel sees albedo / pi x I / r^2 = 1 (the hit stops a hit
 * distance short of the wall: well under the tolerance). */
/* fipr keeps the colour of pixels outside the mask for up to refresh - 1 frames (at most 3): a
 * block of an MPI-split sequence that starts 3 frames early has every such pixel shaded as one
 * process shades it (the refresh pattern follows the frame index), so its frames are the
 * one-process frames bit for bit (tests/cli/test_mpi.sh). */
#define FIPR_WARMUP 3

/* The devices beyond the CPU of the family. */
#define SDF_DEVICES ((1u << FV_DEVICE_PORTABLE) | (1u << FV_DEVICE_CUDA))

#define SDF_CLASS(id, nm, sum, base, table, fn, fn_on, devs, fov, warmup)                                             \
    const fv_technique_class id = {.name = nm, .summary = sum, .family = FV_FAMILY_SDF, .baseline = base, FV_CLASS_PARAMS(table), \
                                   .main = SDF_STEPS, .create = fn, .create_on = fn_on, .devices = devs, .render = render, .render_pair = render_pair, .submit = submit, .collect = collect, .destroy = destroy, .sdf_only = true, \
                                   .test_params = "spp=1", .furnace_radiance = 1.0, .furnace_tolerance = 0.01, .spp_param = "spp", \
                                   .foveated = fov, .warmup_frames = warmup, .bench_scene = "sdf-temple"}

/* Baselines: sdf-gt is the ground truth of the paper's Sec. 4.5, which pt with direct light only
 * renders too (docs/sdf-tracing.md, "Shading"); the others are measured against sdf-gt (Table 1,
 * the sdf-* benchmarks). */
SDF_CLASS(fv_technique_sdf_gt, "sdf-gt", "sphere tracing of every target sample from the camera (ground truth of ipr/fipr)", "pt",
          k_gt_params, NULL, create_gt, SDF_DEVICES, false, 0);
SDF_CLASS(fv_technique_sdf_relaxed, "sdf-relaxed", "over-relaxed sphere tracing (Keinert et al. 2014) of every target sample", "sdf-gt",
          k_relaxed_params, NULL, create_relaxed, SDF_DEVICES, false, 0);
SDF_CLASS(fv_technique_ipr, "ipr", "inverted-pyramid sphere tracing: each level starts at the min-filtered depth of the one below", "sdf-gt",
          k_ipr_params, NULL, create_ipr, SDF_DEVICES, false, 0);
SDF_CLASS(fv_technique_fipr, "fipr", "foveated inverted-pyramid sphere tracing: the five passes of Polychronakis et al. 2023", "sdf-gt",
          k_fipr_params, NULL, create_fipr, SDF_DEVICES, true, FIPR_WARMUP);
