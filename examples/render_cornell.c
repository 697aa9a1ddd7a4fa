/* fovea example — render the built-in Cornell box with the reference path tracer to a PNG.
 *
 * What it shows, with the public API only (<fovea/fovea.h>):
 *   - load a built-in scene by name (no file needed; it comes back committed) with its view data
 *     (camera, display, gaze a scene file may carry),
 *   - create a rendering method by name ("pt") with parameters from an fv_params bag,
 *   - let the sequence driver build the frame (camera, gaze, eye model) the way `fovea render`
 *     does, and render it into an fv_film,
 *   - write the film (PNG, PFM or EXR by the file's extension),
 *   - check every fallible call: each returns an fv_status and fills the caller's fv_error with
 *     one line for the user.
 *
 * Build against an installed libfovea with examples/Makefile (pkg-config) or
 * examples/CMakeLists.txt (find_package(fovea)); run: ./render_cornell cornell.png
 */
#include <stdio.h>
#include <fovea/fovea.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.png\n", argv[0]);
        return 2;
    }
    fv_error err;
    fv_error_clear(&err);
    fv_scene *scene = NULL;
    fv_view *view = NULL;
    fv_params *params = NULL;
    fv_technique *pt = NULL;
    fv_driver *driver = NULL;
    fv_film *film = NULL;

    if (fv_scene_load("cornell", NULL, &scene, &view, &err) != FV_OK) goto done;
    if (fv_params_create(&params, &err) != FV_OK) goto done;
    if (fv_params_set(params, "spp", "4", &err) != FV_OK) goto done;
    if (fv_technique_create("pt", scene, params, NULL, &pt, &err) != FV_OK) goto done;

    fv_drive_opts opts;
    fv_drive_opts_init(&opts); /* time 0, seed 1, mono, all threads, the scene's camera and gaze */
    opts.width = opts.height = 64;
    if (fv_driver_create(scene, view, &opts, &driver, &err) != FV_OK) goto done;
    if (fv_film_create(opts.width, opts.height, 0, &film, &err) != FV_OK) goto done;
    fv_stats stats;
    fv_stats_clear(&stats);
    if (fv_driver_render(driver, pt, 0, false, &film, &stats, NULL, NULL, &err) != FV_OK) goto done;
    if (fv_film_write(film, argv[1], 1.0f, &err) != FV_OK) goto done;
    printf("wrote %s (%.0f rays)\n", argv[1], fv_stats_get_count(&stats, "rays"));

done:
    if (err.status != FV_OK) fprintf(stderr, "render_cornell: %s\n", err.msg);
    fv_film_destroy(film);
    fv_driver_destroy(driver);
    fv_technique_destroy(pt); /* techniques before the scene they render */
    fv_params_destroy(params);
    fv_view_destroy(view);
    fv_scene_destroy(scene);
    return err.status == FV_OK ? 0 : 1;
}
