/* fovea example — render the built-in Cornell box with the reference path tracer to a PNG.
 *
 * What it shows, with the public API only (<fovea/fovea.h>):
 *   - load a built-in scene by name (no file needed; it comes back committed),
 *   - create a rendering method by name ("pt") with parameters from an fv_params bag,
 *   - fill an fv_frame: the scene's camera, a gaze at the centre, the defaults for the rest,
 *   - render one frame into an fv_film and write it (PNG, PFM or EXR by the file's extension),
 *   - check every fallible call: each returns an fv_status and fills the caller's fv_error with
 *     one line for the user.
 *
 * Build against an installed libfovea with examples/Makefile (pkg-config) or
 * examples/CMakeLists.txt (find_package(fovea)); run: ./render_cornell cornell.png
 */
#include <stdio.h>
#include <string.h>
#include <fovea/fovea.h>

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s OUT.png\n", argv[0]);
        return 2;
    }
    const int width = 64, height = 64;
    fv_error err;
    fv_error_clear(&err);
    fv_scene *scene = NULL;
    fv_params *params = NULL;
    fv_technique *pt = NULL;
    fv_film *film = NULL;

    if (fv_scene_load("cornell", NULL, &scene, &err) != FV_OK) goto done;
    if (fv_params_create(&params, &err) != FV_OK) goto done;
    if (fv_params_set(params, "spp", "4", &err) != FV_OK) goto done;
    if (fv_technique_create("pt", scene, params, NULL, &pt, &err) != FV_OK) goto done;
    if (fv_film_create(width, height, 0, &film, &err) != FV_OK) goto done;

    fv_camera camera;
    fv_scene_camera(scene, 0.0, width, height, &camera);
    fv_frame frame;
    memset(&frame, 0, sizeof frame); /* time 0, first frame, mono, all threads, default eye model */
    frame.seed = 1;
    frame.camera = &camera;
    frame.gaze.x = frame.gaze.y = 0.5f; /* looking at the centre of the image */
    fv_stats stats;
    fv_stats_clear(&stats);
    if (fv_technique_render(pt, &frame, film, NULL, &stats, &err) != FV_OK) goto done;
    if (fv_film_write(film, argv[1], 1.0f, &err) != FV_OK) goto done;
    printf("wrote %s\n", argv[1]);

done:
    if (err.status != FV_OK) fprintf(stderr, "render_cornell: %s\n", err.msg);
    fv_film_destroy(film);
    fv_technique_destroy(pt);
    fv_params_destroy(params);
    fv_scene_destroy(scene);
    return err.status == FV_OK ? 0 : 1;
}
