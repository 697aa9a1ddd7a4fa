/* fovea — opening a scene by name: a built-in scene, a fovea JSON scene file, or any mesh file
 * assimp imports, with the view data it carries. On failure nothing is returned: the partly built
 * scene and view are destroyed. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "core/fileio.h"
#include "scene/load_impl.h"
#include "scene/scene_impl.h"

static bool is_builtin(const char *name)
{
    for (int i = 0; i < fv_builtin_count(); i++)
        if (strcmp(name, fv_builtin_name(i)) == 0) return true;
    return false;
}

static bool has_ext(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    return dot && (!slash || dot > slash) && strcasecmp(dot, ext) == 0;
}

/* Creates the scene and the view the loaders fill; the view is made even when the caller wants
 * none, so every loader checks the view blocks the same way. */
static fv_status create_pair(fv_scene **s, fv_view **v, fv_error *err)
{
    fv_status st = fv_scene_create(s, err);
    if (st == FV_OK && (st = fv_view_create(v, err)) != FV_OK) fv_scene_destroy(*s);
    return st;
}

fv_status fv_scene_open(const char *name, const fv_log *log, fv_scene **out, fv_view **view, fv_error *err)
{
    if (!name || !name[0]) return fv_error_set(err, FV_ERR_INVALID, "no scene given");
    fv_scene *s;
    fv_view *v;
    fv_status st;
    if (is_builtin(name)) {
        if ((st = create_pair(&s, &v, err)) != FV_OK) return st;
        st = fv_builtin_build(name, s, v, log, err);
    } else {
        struct stat sb;
        if (stat(name, &sb) != 0) {
            bool looks_like_file = strchr(name, '/') || strchr(name, '.');
            if (!looks_like_file) {
                char known[256] = "";
                size_t len = 0;
                for (int i = 0; i < fv_builtin_count(); i++) {
                    int w = snprintf(known + len, sizeof known - len, "%s%s", i ? ", " : "", fv_builtin_name(i));
                    if (w > 0 && (size_t)w < sizeof known - len) len += (size_t)w;
                }
                return fv_error_set(err, FV_ERR_INVALID, "unknown scene '%s': not a built-in (%s) nor an existing file", name, known);
            }
            return fv_error_set(err, FV_ERR_IO, "cannot open scene '%s': %s", name, strerror(errno));
        }
        /* assimp reports an unreadable file as a format error; say what it is before. Only a
         * regular file: /dev/zero would read forever, a FIFO block the reader (core/fileio.h). */
        if ((st = fv_file_check_read(name, "scene", err)) != FV_OK) return st;
        if (!has_ext(name, ".json") && !fv_load_assimp_supports(name))
            return fv_error_set(err, FV_ERR_INVALID,
                                "scene '%s': unknown file type (use .json, or a mesh format assimp reads: .obj, .gltf, .glb, .ply, ...)", name);
        if ((st = create_pair(&s, &v, err)) != FV_OK) return st;
        if (has_ext(name, ".json")) {
            st = fv_load_json(name, s, v, log, err);
        } else {
            fv_import_opts o = {-1, NULL, true, true, ""};
            st = fv_load_assimp(name, s, v, &o, log, NULL, NULL, err);
            /* The model's up axis, for the default camera and light: glTF says +y; the others
             * do not say, so it is guessed from the shape (fv_up_axis_guess). */
            if (st == FV_OK) {
                fv_vec3 lo, hi;
                fv_scene_world_bounds(s, &lo, &hi);
                fv_view_set_up_axis(v, has_ext(name, ".gltf") || has_ext(name, ".glb") ? fv_v3(0, 1, 0) : fv_up_axis_guess(lo, hi));
            }
        }
    }
    if (st != FV_OK) {
        fv_view_destroy(v);
        fv_scene_destroy(s);
        return st;
    }
    *out = s;
    if (view) *view = v;
    else fv_view_destroy(v);
    return FV_OK;
}

fv_status fv_scene_load(const char *name, const fv_log *log, fv_scene **out, fv_view **view, fv_error *err)
{
    fv_scene *s;
    fv_view *v = NULL;
    fv_view *own = NULL; /* the default light is placed by the view's camera, wanted or not */
    fv_status st = fv_scene_open(name, log, &s, &own, err);
    if (st != FV_OK) return st;
    if (!is_builtin(name)) st = fv_scene_add_default_lighting(s, own, log, NULL, err);
    if (view) v = own;
    else fv_view_destroy(own);
    if (st != FV_OK || (st = fv_scene_commit(s, log, err)) != FV_OK) {
        if (err && strncmp(err->msg, name, strlen(name)) != 0) fv_error_prefix(err, "%s: ", name);
        fv_view_destroy(v);
        fv_scene_destroy(s);
        return st;
    }
    *out = s;
    if (view) *view = v;
    return FV_OK;
}
