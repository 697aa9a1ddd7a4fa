/* fovea — the fovea JSON scene format (docs/scene-format.md): materials, objects (mesh files,
 * inline quads, boxes, spheres, or signed distance field trees), rigid animation of objects and lights into the scene; camera,
 * camera path, display (eye model) and gaze path into the view. Strict: unknown fields, wrong
 * types, non-finite or out-of-range numbers and unknown material names are errors naming the file
 * and the field.
 */
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "core/alloc.h"
#include "core/fileio.h"
#include "fovea/film.h"
#include "fovea/limits.h"
#include "core/json_util.h"
#include "gaze/gaze_json.h"
#include "scene/anim_json.h"
#include "scene/load_impl.h"
#include "scene/mesh_gen.h"
#include "scene/texture.h"

/* Lengths and coordinates: the ray kernels' range (fovea/limits.h). */
#define BIG FV_COORD_MAX

typedef struct json_ctx {
    const char *file;
    char dir[4096];
    fv_scene *scene;
    const fv_log *log;
} json_ctx;

static fv_status vec3(const cJSON *o, const char *key, double lo, double hi, const json_ctx *c, const char *where, fv_vec3 *out,
                      fv_error *err)
{
    double v[3] = {out->x, out->y, out->z};
    fv_status st = fv_json_numbers(o, key, 3, lo, hi, c->file, where, v, err);
    if (st == FV_OK) *out = fv_v3((float)v[0], (float)v[1], (float)v[2]);
    return st;
}

/* Coordinates (and intensities) checked against fovea/limits.h with its message. */
static fv_status limited3(const cJSON *o, const char *key, fv_json_limit_fn check, const json_ctx *c, const char *where, fv_vec3 *out,
                          fv_error *err)
{
    double v[3] = {out->x, out->y, out->z};
    fv_status st = fv_json_limited(o, key, 3, check, c->file, where, v, err);
    if (st == FV_OK) *out = fv_v3((float)v[0], (float)v[1], (float)v[2]);
    return st;
}
#define coord3(o, key, c, where, out, err) limited3(o, key, fv_limit_coords, c, where, out, err)
#define intensity3(o, key, c, where, out, err) limited3(o, key, fv_limit_intensity, c, where, out, err)

/* A material's texture named by key (a file relative to the scene file): its id in *id, 0 when
 * the key is absent. An unreadable image is a warning (texture.h), not an error. */
static fv_status json_texture(const cJSON *o, const char *key, const json_ctx *c, const char *where, int *id, fv_error *err)
{
    const char *tex = NULL;
    fv_status st = fv_json_string(o, key, c->file, where, &tex, err);
    if (st != FV_OK || !tex) return st;
    char path[8192], user[FV_NAME_MAX + 4200];
    snprintf(path, sizeof path, "%s%s%s", tex[0] == '/' ? "" : c->dir, tex[0] == '/' ? "" : "/", tex);
    snprintf(user, sizeof user, "%s: %s", c->file, where);
    /* A missing file is left to the warning; one that is there must be a regular file (a FIFO
     * would block the decoder, core/fileio.h). */
    struct stat sb;
    if (stat(path, &sb) == 0 && (st = fv_file_check_read(path, "texture", err)) != FV_OK) {
        fv_error_prefix(err, "%s: %s.%s: ", c->file, where, key);
        return st;
    }
    return fv_texture_load_file(c->scene, path, user, c->log, id, err);
}

static fv_status parse_material(const cJSON *o, const json_ctx *c, fv_error *err)
{
    static const char *const keys[] = {"type", "albedo", "albedo_texture", "specular", "roughness", "ior", "emission", "emission_texture", "two_sided", NULL};
    char where[FV_NAME_MAX + 16];
    snprintf(where, sizeof where, "materials.%s", o->string);
    if (strlen(o->string) >= FV_NAME_MAX)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: material name longer than %d characters", c->file, where, FV_NAME_MAX - 1);
    if (fv_scene_find_material(c->scene, o->string) >= 0)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: defined twice", c->file, where);
    fv_status st = fv_json_check_keys(o, keys, c->file, where, err);
    const char *type = "diffuse";
    if (st || (st = fv_json_string(o, "type", c->file, where, &type, err))) return st;
    fv_material_type t;
    if (!fv_material_type_from_name(type, &t))
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.type: unknown material type '%s' (diffuse, mirror, glossy, dielectric)", c->file,
                            where, type);
    fv_material m = fv_material_default(t);
    snprintf(m.name, sizeof m.name, "%s", o->string);
    double rough = m.roughness, ior = m.ior;
    if ((st = vec3(o, "albedo", 0, 1, c, where, &m.albedo, err)) || (st = vec3(o, "specular", 0, 1, c, where, &m.specular, err)) ||
        (st = intensity3(o, "emission", c, where, &m.emission, err)) ||
        (st = fv_json_number(o, "roughness", 0.001, 1, c->file, where, &rough, err)) ||
        (st = fv_json_number(o, "ior", 1.0001, 10, c->file, where, &ior, err)) ||
        (st = fv_json_bool(o, "two_sided", c->file, where, &m.two_sided_emission, err)))
        return st;
    m.roughness = (float)rough;
    m.ior = (float)ior;
    if ((st = json_texture(o, "albedo_texture", c, where, &m.albedo_texture, err)) ||
        (st = json_texture(o, "emission_texture", c, where, &m.emission_texture, err)))
        return st;
    /* An emission texture alone means the texture is the emitted radiance (emission 1). */
    if (m.emission_texture && !cJSON_GetObjectItemCaseSensitive(o, "emission")) m.emission = fv_v3s(1.0f);
    if ((st = fv_scene_add_material(c->scene, &m, NULL, err)) != FV_OK) fv_error_prefix(err, "%s: ", c->file);
    return st;
}

static fv_status find_material(const cJSON *o, const json_ctx *c, const char *where, int *id, fv_error *err)
{
    const char *name = NULL;
    fv_status st = fv_json_string(o, "material", c->file, where, &name, err);
    if (st != FV_OK || !name) return st;
    if ((*id = fv_scene_find_material(c->scene, name)) < 0)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.material: unknown material '%s'", c->file, where, name);
    return FV_OK;
}

/* "transform" or one animation key: translate, rotate_deg (about x, then y, then z) or
 * rotate_quat [x, y, z, w] (normalised here), scale (a number or three). */
static fv_status parse_trs(const cJSON *o, const json_ctx *c, const char *where, const char *const *keys, fv_vec3 *t, fv_quat *q,
                           fv_vec3 *s, fv_error *err)
{
    fv_status st = fv_json_check_keys(o, keys, c->file, where, err);
    fv_vec3 rot = fv_v3s(0.0f);
    *t = fv_v3s(0.0f);
    *s = fv_v3s(1.0f);
    if (st || (st = coord3(o, "translate", c, where, t, err)) || (st = vec3(o, "rotate_deg", -1e6, 1e6, c, where, &rot, err)))
        return st;
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(o, "scale");
    if (cJSON_IsNumber(sc)) {
        double v = 1.0;
        if ((st = fv_json_number(o, "scale", 1e-9, BIG, c->file, where, &v, err))) return st;
        *s = fv_v3s((float)v);
    } else if ((st = vec3(o, "scale", 1e-9, BIG, c, where, s, err))) {
        return st;
    }
    *q = fv_quat_euler_deg(rot);
    if (cJSON_GetObjectItemCaseSensitive(o, "rotate_quat")) {
        if (cJSON_GetObjectItemCaseSensitive(o, "rotate_deg"))
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s: give rotate_deg or rotate_quat, not both", c->file, where);
        double v[4];
        if ((st = fv_json_numbers(o, "rotate_quat", 4, -1e30, 1e30, c->file, where, v, err))) return st;
        double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
        if (!(len > 1e-6) || !isfinite(len))
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.rotate_quat: not a rotation (length %g)", c->file, where, len);
        *q = (fv_quat){(float)(v[0] / len), (float)(v[1] / len), (float)(v[2] / len), (float)(v[3] / len)};
    }
    return FV_OK;
}

static fv_status parse_shape(const cJSON *o, const json_ctx *c, const char *where, int mat, fv_meshbuf *mb, fv_error *err)
{
    char w2[128];
    fv_status st;
    const cJSON *it;
    if ((it = cJSON_GetObjectItemCaseSensitive(o, "quad"))) {
        snprintf(w2, sizeof w2, "%s.quad", where);
        if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 4)
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected 4 corners [[x,y,z], ...]", c->file, w2);
        fv_vec3 p[4];
        int i = 0;
        for (const cJSON *e = it->child; e; e = e->next, i++) {
            float v[3];
            int k = 0;
            for (const cJSON *n = cJSON_IsArray(e) ? e->child : NULL; n && k < 4; n = n->next, k++)
                if (k < 3) v[k] = cJSON_IsNumber(n) && fabs(n->valuedouble) <= BIG ? (float)n->valuedouble : NAN;
            if (k != 3 || !isfinite(v[0]) || !isfinite(v[1]) || !isfinite(v[2]))
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s[%d]: expected 3 finite numbers within +-%g", c->file, w2, i, BIG);
            p[i] = fv_v3(v[0], v[1], v[2]);
        }
        fv_mesh_quad(mb, p[0], p[1], p[2], p[3], mat);
        return FV_OK;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(o, "box"))) {
        static const char *const keys[] = {"center", "half", "yaw_deg", NULL};
        snprintf(w2, sizeof w2, "%s.box", where);
        fv_vec3 ce = fv_v3s(0), h = fv_v3s(0.5f);
        double yaw = 0;
        if ((st = fv_json_check_keys(it, keys, c->file, w2, err)) || (st = fv_json_require(it, "half", c->file, w2, err)) ||
            (st = coord3(it, "center", c, w2, &ce, err)) || (st = vec3(it, "half", 1e-9, BIG, c, w2, &h, err)) ||
            (st = fv_json_number(it, "yaw_deg", -1e6, 1e6, c->file, w2, &yaw, err)))
            return st;
        fv_mesh_box(mb, ce, h, (float)yaw, mat);
        return FV_OK;
    }
    it = cJSON_GetObjectItemCaseSensitive(o, "sphere");
    static const char *const keys[] = {"center", "radius", "segments", NULL};
    snprintf(w2, sizeof w2, "%s.sphere", where);
    fv_vec3 ce = fv_v3s(0);
    double r = 1, seg[2] = {64, 32};
    if ((st = fv_json_check_keys(it, keys, c->file, w2, err)) || (st = fv_json_require(it, "radius", c->file, w2, err)) ||
        (st = coord3(it, "center", c, w2, &ce, err)) || (st = fv_json_number(it, "radius", 1e-9, BIG, c->file, w2, &r, err)) ||
        (st = fv_json_numbers(it, "segments", 2, 3, 2048, c->file, w2, seg, err)))
        return st;
    fv_mesh_sphere(mb, ce, (float)r, (int)seg[0], (int)seg[1], false, mat);
    return FV_OK;
}

fv_status fv_load_json_anim_keys(const cJSON *arr, const char *file, const char *where, fv_anim_key **out, int *count, fv_error *err)
{
    static const char *const keys[] = {"time", "translate", "rotate_deg", "rotate_quat", "scale", NULL};
    json_ctx c;
    memset(&c, 0, sizeof c);
    c.file = file;
    int n = cJSON_GetArraySize(arr);
    if (!cJSON_IsArray(arr) || n < 1 || n > 100000)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.animation: expected an array of keys", file, where);
    fv_anim_key *k = fv_alloc_array((size_t)n, sizeof *k);
    if (!k) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    fv_status st = FV_OK;
    int i = 0;
    for (const cJSON *e = arr->child; e && st == FV_OK; e = e->next, i++) {
        char w2[128];
        snprintf(w2, sizeof w2, "%s.animation[%d]", where, i);
        double t = 0;
        if ((st = parse_trs(e, &c, w2, keys, &k[i].translate, &k[i].rotate, &k[i].scale, err)) ||
            (st = fv_json_require(e, "time", file, w2, err)) || (st = fv_json_number(e, "time", -1e9, 1e9, file, w2, &t, err)))
            break;
        k[i].time = t;
    }
    if (st != FV_OK) {
        free(k);
        return st;
    }
    *out = k;
    *count = n;
    return FV_OK;
}

/* The "animation" array of objects[i] or lights[i] (where), applied to objects first .. first +
 * count - 1, or to light `light` when it is >= 0: one key format and one set of rules for both. */
static fv_status parse_animation(const cJSON *arr, const json_ctx *c, const char *where, int first, int count, int light, fv_error *err)
{
    fv_anim_key *k = NULL;
    int n = 0;
    fv_status st = fv_load_json_anim_keys(arr, c->file, where, &k, &n, err);
    for (int o = 0; o < count && st == FV_OK; o++)
        if ((st = fv_scene_animate_object(c->scene, first + o, k, n, err)) != FV_OK) fv_error_prefix(err, "%s: %s: ", c->file, where);
    if (light >= 0 && st == FV_OK && (st = fv_scene_animate_light(c->scene, light, k, n, err)) != FV_OK)
        fv_error_prefix(err, "%s: %s.animation: ", c->file, where);
    free(k);
    return st;
}

/* ---- "sdf": a signed distance field as a nested tree (docs/scene-format.md) ----
 *
 * Each JSON node becomes one fv_sdf_node, children before their parent, so the root is the last
 * node. The JSON path of every node is kept, so an error fv_sdf_create finds ("sdf node 7 ...")
 * is reported at the JSON path the user wrote, like the errors found here. */

typedef struct sdf_build {
    const json_ctx *c;
    fv_sdf_node *n;
    char **path;
    int count, cap_n, cap_path;
    int widest; /* the most children of an n-ary operator so far: for the node limit's message */
} sdf_build;

#define SDF_WHERE 512

static fv_status sdf_num(const cJSON *o, const char *key, bool required, int cond, const sdf_build *b, const char *where, float *out,
                         fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!it) return required ? fv_error_set(err, FV_ERR_INVALID, "%s: %s: missing '%s'", b->c->file, where, key) : FV_OK;
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble) || fabs(it->valuedouble) > BIG)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: expected a finite number within +-%g", b->c->file, where, key, BIG);
    double v = it->valuedouble;
    if (cond > 0 && !(v > 0)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: must be > 0", b->c->file, where, key);
    if (cond == 0 && !(v >= 0)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: must be >= 0", b->c->file, where, key);
    *out = (float)v;
    return FV_OK;
}

/* cond as sdf_num: > 0 (1), >= 0 (0), any finite (-1), per component. */
static fv_status sdf_vec(const cJSON *o, const char *key, bool required, int cond, const sdf_build *b, const char *where, fv_vec3 *out,
                         fv_error *err)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, key);
    if (!it) return required ? fv_error_set(err, FV_ERR_INVALID, "%s: %s: missing '%s'", b->c->file, where, key) : FV_OK;
    float v[3];
    int k = 0;
    if (cJSON_IsArray(it) && cJSON_GetArraySize(it) == 3)
        for (const cJSON *e = it->child; e; e = e->next, k++) {
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > BIG) break;
            v[k] = (float)e->valuedouble;
        }
    if (k != 3) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: expected 3 finite numbers within +-%g", b->c->file, where, key, BIG);
    for (k = 0; k < 3; k++) {
        if (cond > 0 && !(v[k] > 0)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: each must be > 0", b->c->file, where, key);
        if (cond == 0 && !(v[k] >= 0)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.%s: each must be >= 0", b->c->file, where, key);
    }
    *out = fv_v3(v[0], v[1], v[2]);
    return FV_OK;
}

static fv_status sdf_push(sdf_build *b, const fv_sdf_node *n, const char *where, int *id, fv_error *err)
{
    /* Said in what the file shows: compiled nodes are not the shapes a user counts (an n-way
     * union folds into n - 1 binary ones, a transform is a node of its own). */
    if (b->count >= FV_SDF_MAX_NODES) {
        if (b->widest > 2)
            return fv_error_set(err, FV_ERR_INVALID,
                                "%s: %s: the sdf compiles to more than %d nodes (each shape and transform is one, and an operator "
                                "of n children n - 1: its largest, of %d children, %d): split it over several objects",
                                b->c->file, where, FV_SDF_MAX_NODES, b->widest, b->widest - 1);
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: the sdf compiles to more than %d nodes (each shape, transform and operator is one): "
                            "split it over several objects", b->c->file, where, FV_SDF_MAX_NODES);
    }
    if (fv_grow((void **)&b->n, &b->cap_n, b->count + 1, sizeof *b->n) ||
        fv_grow((void **)&b->path, &b->cap_path, b->count + 1, sizeof *b->path))
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    char *p = malloc(strlen(where) + 1);
    if (!p) return fv_error_set(err, FV_ERR_NOMEM, "out of memory");
    strcpy(p, where);
    b->n[b->count] = *n;
    b->path[b->count] = p;
    *id = b->count++;
    return FV_OK;
}

static fv_sdf_node sdf_blank(fv_sdf_kind k)
{
    fv_sdf_node n;
    memset(&n, 0, sizeof n);
    n.kind = k;
    n.q = (fv_quat){0, 0, 0, 1};
    n.a = n.b = -1;
    return n;
}

static fv_status sdf_node(sdf_build *b, const cJSON *o, const char *where, int mat, int depth, int *id, fv_error *err);

/* The children of an n-ary operator (>= 2), folded left: op(op(c0, c1), c2) ... */
static fv_status sdf_children(sdf_build *b, const cJSON *arr, const char *where, fv_sdf_node proto, int mat, int depth, int *id,
                              fv_error *err)
{
    if (!cJSON_IsArray(arr) || cJSON_GetArraySize(arr) < 2)
        return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an array of at least 2 nodes", b->c->file, where);
    if (cJSON_GetArraySize(arr) > b->widest) b->widest = cJSON_GetArraySize(arr);
    int acc = -1, i = 0;
    fv_status st = FV_OK;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        char w[SDF_WHERE + 16];
        snprintf(w, sizeof w, "%s[%d]", where, i);
        int child;
        if ((st = sdf_node(b, e, w, mat, depth + 1, &child, err))) return st;
        if (acc < 0) {
            acc = child;
            continue;
        }
        fv_sdf_node n = proto;
        n.a = acc;
        n.b = child;
        if ((st = sdf_push(b, &n, where, &acc, err))) return st;
    }
    *id = acc;
    return FV_OK;
}

/* The single "child" of a TRANSFORM or REPEAT object `it` at JSON path `w`, parsed one level deeper. */
static fv_status sdf_child(sdf_build *b, const cJSON *it, const char *w, int mat, int depth, int *id, fv_error *err)
{
    const json_ctx *c = b->c;
    char w2[SDF_WHERE + 32];
    snprintf(w2, sizeof w2, "%s.child", w);
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(it, "child");
    if (!ch) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: missing 'child'", c->file, w);
    return sdf_node(b, ch, w2, mat, depth + 1, id, err);
}

static fv_status sdf_node(sdf_build *b, const cJSON *o, const char *where, int mat, int depth, int *id, fv_error *err)
{
    static const char *const kinds[] = {"sphere", "box", "round_box", "torus", "capsule", "cylinder", "cone", "plane", "heightfield",
                                        "union", "subtract", "intersect", "smooth_union", "transform", "repeat", NULL};
    static const char *const keys[] = {"sphere", "box", "round_box", "torus", "capsule", "cylinder", "cone", "plane", "heightfield",
                                       "union", "subtract", "intersect", "smooth_union", "transform", "repeat", "material", NULL};
    const json_ctx *c = b->c;
    if (depth > FV_SDF_MAX_DEPTH)
        /* the reason before the path, which at this depth is long enough to be cut off */
        return fv_error_set(err, FV_ERR_INVALID, "%s: sdf nested deeper than %d levels (a flat list of children is one level) at %s",
                            c->file, FV_SDF_MAX_DEPTH, where);
    if (!cJSON_IsObject(o)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an sdf node object", c->file, where);
    fv_status st = fv_json_check_keys(o, keys, c->file, where, err);
    if (st) return st;
    if (cJSON_GetObjectItemCaseSensitive(o, "material") && (st = find_material(o, c, where, &mat, err))) return st;
    int kind = -1, nk = 0;
    for (int k = 0; kinds[k]; k++)
        if (cJSON_GetObjectItemCaseSensitive(o, kinds[k])) kind = k, nk++;
    if (nk != 1)
        return fv_error_set(err, FV_ERR_INVALID,
                            "%s: %s: give exactly one of sphere, box, round_box, torus, capsule, cylinder, cone, plane, heightfield, "
                            "union, subtract, intersect, smooth_union, transform, repeat",
                            c->file, where);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, kinds[kind]);
    char w[SDF_WHERE + 16];
    snprintf(w, sizeof w, "%s.%s", where, kinds[kind]);
    fv_sdf_node n = sdf_blank((fv_sdf_kind)kind);
    if (kind <= FV_SDF_HEIGHTFIELD) {
        if (mat < 0) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: a leaf needs a 'material' (here or on an enclosing node)", c->file, where);
        n.material = mat;
        if (!cJSON_IsObject(it)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object", c->file, w);
    }
    /* The primitives whose fields are plain numbers and vectors: one table, read in order after
     * the key check (cond: 1 positive, 0 non-negative, -1 any finite value; slot: p[] or v[]). */
    typedef struct sdf_field {
        const char *key;
        bool vec, required;
        int cond, slot;
    } sdf_field;
    static const struct {
        int kind;
        sdf_field f[4];
    } k_prims[] = {
        {FV_SDF_SPHERE, {{"radius", false, true, 1, 0}}},
        {FV_SDF_BOX, {{"half", true, true, 1, 0}}},
        {FV_SDF_ROUND_BOX, {{"half", true, true, 1, 0}, {"radius", false, true, 1, 0}}},
        {FV_SDF_TORUS, {{"major", false, true, 1, 0}, {"minor", false, true, 1, 1}}},
        {FV_SDF_CAPSULE, {{"a", true, true, -1, 0}, {"b", true, true, -1, 1}, {"radius", false, true, 1, 0}}},
        {FV_SDF_CYLINDER, {{"radius", false, true, 1, 0}, {"half_height", false, true, 1, 1}}},
        {FV_SDF_CONE, {{"radius_bottom", false, true, 1, 0}, {"radius_top", false, false, 0, 1}, {"half_height", false, true, 1, 2}}},
    };
    for (size_t i = 0; i < sizeof k_prims / sizeof k_prims[0]; i++) {
        if (k_prims[i].kind != kind) continue;
        const char *names[5] = {NULL};
        for (int f = 0; f < 4 && k_prims[i].f[f].key; f++) names[f] = k_prims[i].f[f].key;
        if ((st = fv_json_check_keys(it, names, c->file, w, err))) return st;
        for (int f = 0; f < 4 && k_prims[i].f[f].key; f++) {
            const sdf_field *fd = &k_prims[i].f[f];
            st = fd->vec ? sdf_vec(it, fd->key, fd->required, fd->cond, b, w, &n.v[fd->slot], err)
                         : sdf_num(it, fd->key, fd->required, fd->cond, b, w, &n.p[fd->slot], err);
            if (st) return st;
        }
        if (kind == FV_SDF_ROUND_BOX && n.p[0] > fv_min3(n.v[0]))
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.radius: must be <= the smallest half extent (%g)", c->file, w, fv_min3(n.v[0]));
        break;
    }
    switch (kind) {
    case FV_SDF_PLANE: {
        static const char *const k[] = {"normal", "offset", NULL};
        if ((st = fv_json_check_keys(it, k, c->file, w, err)) || (st = sdf_vec(it, "normal", true, -1, b, w, &n.v[0], err)) ||
            (st = sdf_num(it, "offset", false, -1, b, w, &n.p[0], err)))
            return st;
        float len = fv_length(n.v[0]);
        if (!(len > 1e-6f) || !isfinite(len)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s.normal: must not be zero", c->file, w);
        n.v[0] = fv_scale(n.v[0], 1.0f / len);
        break;
    }
    case FV_SDF_HEIGHTFIELD: {
        static const char *const k[] = {"base", "amplitude", "frequency", "octaves", "seed", NULL};
        int oct = 4, seed = 0;
        if ((st = fv_json_check_keys(it, k, c->file, w, err)) || (st = sdf_num(it, "base", false, -1, b, w, &n.p[0], err)) ||
            (st = sdf_num(it, "amplitude", true, 0, b, w, &n.p[1], err)) || (st = sdf_num(it, "frequency", true, 1, b, w, &n.p[2], err)) ||
            (st = fv_json_int(it, "octaves", 1, 8, c->file, w, &oct, err)) || (st = fv_json_int(it, "seed", 0, 1 << 24, c->file, w, &seed, err)))
            return st;
        n.p[3] = (float)oct;
        n.p[4] = (float)seed;
        break;
    }
    case FV_SDF_UNION:
    case FV_SDF_SUBTRACT:
    case FV_SDF_INTERSECT: return sdf_children(b, it, w, n, mat, depth, id, err);
    case FV_SDF_SMOOTH_UNION: {
        static const char *const k[] = {"k", "children", NULL};
        if (!cJSON_IsObject(it)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected {\"k\": ..., \"children\": [...]}", c->file, w);
        if ((st = fv_json_check_keys(it, k, c->file, w, err)) || (st = sdf_num(it, "k", true, 1, b, w, &n.p[0], err))) return st;
        char w2[SDF_WHERE + 32];
        snprintf(w2, sizeof w2, "%s.children", w);
        return sdf_children(b, cJSON_GetObjectItemCaseSensitive(it, "children"), w2, n, mat, depth, id, err);
    }
    case FV_SDF_TRANSFORM: {
        static const char *const k[] = {"translate", "rotate_deg", "rotate_quat", "scale", "child", NULL};
        if (!cJSON_IsObject(it)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object", c->file, w);
        fv_vec3 sc;
        if ((st = parse_trs(it, c, w, k, &n.v[0], &n.q, &sc, err))) return st;
        if (sc.x != sc.y || sc.y != sc.z)
            return fv_error_set(err, FV_ERR_INVALID, "%s: %s.scale: must be one number (a non-uniform scale breaks the distance bound)", c->file, w);
        n.p[0] = sc.x;
        if ((st = sdf_child(b, it, w, mat, depth, &n.a, err))) return st;
        break;
    }
    case FV_SDF_REPEAT: {
        static const char *const k[] = {"period", "count", "child", NULL};
        if (!cJSON_IsObject(it)) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: expected an object", c->file, w);
        if ((st = fv_json_check_keys(it, k, c->file, w, err)) || (st = sdf_vec(it, "period", true, 0, b, w, &n.v[0], err)) ||
            (st = sdf_vec(it, "count", false, 0, b, w, &n.v[1], err)))
            return st;
        const float *cn = &n.v[1].x;
        for (int a = 0; a < 3; a++)
            if (cn[a] != floorf(cn[a]))
                return fv_error_set(err, FV_ERR_INVALID, "%s: %s.count: each must be an integer (0: unlimited)", c->file, w);
        if ((st = sdf_child(b, it, w, mat, depth, &n.a, err))) return st;
        break;
    }
    default: break;
    }
    return sdf_push(b, &n, w, id, err);
}

static void sdf_build_free(sdf_build *b)
{
    for (int i = 0; i < b->count; i++) free(b->path[i]);
    free(b->path);
    free(b->n);
}

/* objects[i] with "sdf": the tree, the object's "material" as the leaves' default, its
 * "transform" as a TRANSFORM node around the root. */
static fv_status parse_sdf_object(const cJSON *o, const json_ctx *c, const char *where, const char *oname, int mat, int *first,
                                  fv_error *err)
{
    static const char *const tkeys[] = {"translate", "rotate_deg", "rotate_quat", "scale", NULL};
    sdf_build b = {c, NULL, NULL, 0, 0, 0, 0};
    char w[SDF_WHERE];
    snprintf(w, sizeof w, "%s.sdf", where);
    int root = -1;
    fv_status st = sdf_node(&b, cJSON_GetObjectItemCaseSensitive(o, "sdf"), w, mat, 0, &root, err);
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(o, "transform");
    if (st == FV_OK && tr) {
        char w2[SDF_WHERE + 32];
        snprintf(w2, sizeof w2, "%s.transform", where);
        fv_sdf_node n = sdf_blank(FV_SDF_TRANSFORM);
        fv_vec3 sc;
        if ((st = parse_trs(tr, c, w2, tkeys, &n.v[0], &n.q, &sc, err)) == FV_OK) {
            if (sc.x != sc.y || sc.y != sc.z)
                st = fv_error_set(err, FV_ERR_INVALID, "%s: %s.scale: an sdf object takes one number (uniform scale)", c->file, w2);
            n.p[0] = sc.x;
            n.a = root;
            if (st == FV_OK) st = sdf_push(&b, &n, w2, &root, err);
        }
    }
    if (st == FV_OK && (st = fv_scene_add_sdf(c->scene, oname, b.n, b.count, root, c->log, first, err)) != FV_OK) {
        /* Name the JSON node behind "node K" of the library's message. */
        const char *k = strstr(err->msg, "node ");
        int idx = -1;
        if (k && sscanf(k + 5, "%d", &idx) == 1 && idx >= 0 && idx < b.count) fv_error_prefix(err, "%s: %s: ", c->file, b.path[idx]);
        else fv_error_prefix(err, "%s: %s: ", c->file, w);
    }
    sdf_build_free(&b);
    return st;
}

static fv_status parse_object(const cJSON *o, const json_ctx *c, int index, fv_error *err)
{
    static const char *const keys[] = {"name", "mesh", "quad", "box", "sphere", "sdf", "material", "transform", "animation", NULL};
    static const char *const tkeys[] = {"translate", "rotate_deg", "rotate_quat", "scale", NULL};
    char where[64];
    snprintf(where, sizeof where, "objects[%d]", index);
    fv_status st = fv_json_check_keys(o, keys, c->file, where, err);
    if (st != FV_OK) return st;
    int kinds = !!cJSON_GetObjectItemCaseSensitive(o, "mesh") + !!cJSON_GetObjectItemCaseSensitive(o, "quad") +
                !!cJSON_GetObjectItemCaseSensitive(o, "box") + !!cJSON_GetObjectItemCaseSensitive(o, "sphere") +
                !!cJSON_GetObjectItemCaseSensitive(o, "sdf");
    if (kinds != 1) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: give exactly one of mesh, quad, box, sphere, sdf", c->file, where);
    const char *name = NULL, *mesh = NULL;
    int mat = -1;
    if ((st = fv_json_string(o, "name", c->file, where, &name, err)) || (st = fv_json_string(o, "mesh", c->file, where, &mesh, err)) ||
        (st = find_material(o, c, where, &mat, err)))
        return st;
    char oname[FV_NAME_MAX];
    snprintf(oname, sizeof oname, "%s", name ? name : where);
    int first = -1, count = 0;
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(o, "animation");
    if (cJSON_GetObjectItemCaseSensitive(o, "sdf")) {
        if ((st = parse_sdf_object(o, c, where, oname, mat, &first, err)) != FV_OK) return st;
        return an ? parse_animation(an, c, where, first, 1, -1, err) : FV_OK;
    }
    fv_xform x = fv_xform_identity();
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(o, "transform");
    if (tr) {
        fv_vec3 t, s;
        fv_quat q;
        char w2[80];
        snprintf(w2, sizeof w2, "%s.transform", where);
        if ((st = parse_trs(tr, c, w2, tkeys, &t, &q, &s, err))) return st;
        x = fv_xform_trs(t, q, s);
    }
    if (mesh) {
        char path[8192];
        snprintf(path, sizeof path, "%s%s%s", mesh[0] == '/' ? "" : c->dir, mesh[0] == '/' ? "" : "/", mesh);
        if ((st = fv_file_check_read(path, "mesh", err)) != FV_OK) {
            fv_error_prefix(err, "%s: %s.mesh: ", c->file, where);
            return st;
        }
        char prefix[FV_NAME_MAX];
        snprintf(prefix, sizeof prefix, "%.30s/", oname);
        fv_import_opts io = {mat, &x, false, false, prefix};
        if ((st = fv_load_assimp(path, c->scene, NULL, &io, c->log, &first, &count, err)) != FV_OK) {
            fv_error_prefix(err, "%s: %s: ", c->file, where);
            return st;
        }
    } else {
        if (mat < 0) return fv_error_set(err, FV_ERR_INVALID, "%s: %s: an inline shape needs a 'material'", c->file, where);
        fv_meshbuf mb;
        fv_meshbuf_init(&mb);
        st = parse_shape(o, c, where, mat, &mb, err);
        if (st == FV_OK && tr) {
            fv_xform inv = fv_xform_identity();
            bool has_inv = fv_xform_inverse(&x, &inv);
            for (int i = 0; i < mb.nv; i++) {
                mb.pos[i] = fv_xform_point(&x, mb.pos[i]);
                if (has_inv) mb.nrm[i] = fv_normalize(fv_xform_normal(&inv, mb.nrm[i]));
            }
        }
        if (st == FV_OK && (st = fv_meshbuf_add(&mb, c->scene, oname, c->log, &first, err)) != FV_OK)
            fv_error_prefix(err, "%s: %s: ", c->file, where);
        fv_meshbuf_free(&mb);
        if (st != FV_OK) return st;
        count = 1;
    }
    return an ? parse_animation(an, c, where, first, count, -1, err) : FV_OK;
}

static fv_status parse_light(const cJSON *o, const json_ctx *c, int index, fv_error *err)
{
    static const char *const keys[] = {"type", "pos", "dir", "intensity", "inner_deg", "outer_deg", "animation", NULL};
    char where[64];
    snprintf(where, sizeof where, "lights[%d]", index);
    fv_status st = fv_json_check_keys(o, keys, c->file, where, err);
    const char *type = "point";
    fv_light_desc d;
    memset(&d, 0, sizeof d);
    d.dir = fv_v3(0, -1, 0);
    d.intensity = fv_v3s(1.0f);
    double inner = 20, outer = 30;
    if (st || (st = fv_json_string(o, "type", c->file, where, &type, err)) ||
        (strcmp(type, "directional") != 0 && (st = fv_json_require(o, "pos", c->file, where, err))) ||
        (strcmp(type, "directional") == 0 && (st = fv_json_require(o, "dir", c->file, where, err))) ||
        (st = coord3(o, "pos", c, where, &d.pos, err)) || (st = coord3(o, "dir", c, where, &d.dir, err)) ||
        (st = intensity3(o, "intensity", c, where, &d.intensity, err)) ||
        (st = fv_json_number(o, "inner_deg", 0, 89.9, c->file, where, &inner, err)) ||
        (st = fv_json_number(o, "outer_deg", 0.01, 89.9, c->file, where, &outer, err)))
        return st;
    if (strcmp(type, "point") == 0) d.type = FV_LIGHT_POINT;
    else if (strcmp(type, "spot") == 0) d.type = FV_LIGHT_SPOT;
    else if (strcmp(type, "directional") == 0) d.type = FV_LIGHT_DIRECTIONAL;
    else return fv_error_set(err, FV_ERR_INVALID, "%s: %s.type: unknown light type '%s' (point, spot, directional; area lights are emissive materials)", c->file, where, type);
    d.inner_deg = (float)inner;
    d.outer_deg = (float)outer;
    if ((st = fv_scene_add_light(c->scene, &d, err)) != FV_OK) {
        fv_error_prefix(err, "%s: %s: ", c->file, where);
        return st;
    }
    /* The light just added is the scene's last; lights[i] is not always light i (a loader may
     * come after lights added by other means). */
    const cJSON *an = cJSON_GetObjectItemCaseSensitive(o, "animation");
    return an ? parse_animation(an, c, where, 0, 0, fv_scene_light_count(c->scene) - 1, err) : FV_OK;
}

/* "environment": [r, g, b] (uniform) or {"horizon": [...], "zenith", "ground", "up"}, a colour
 * left out taking the horizon's. */
static fv_status parse_environment(const cJSON *root, const json_ctx *c, fv_error *err)
{
    static const char *const keys[] = {"zenith", "horizon", "ground", "up", NULL};
    const cJSON *o = cJSON_GetObjectItemCaseSensitive(root, "environment");
    fv_env_desc e = fv_env_uniform(fv_v3s(0.0f));
    fv_status st;
    if (!cJSON_IsArray(o) && !cJSON_IsObject(o))
        return fv_error_set(err, FV_ERR_INVALID, "%s: environment: expected [r, g, b] or an object with horizon, zenith, ground, up", c->file);
    if (cJSON_IsArray(o)) {
        if ((st = vec3(root, "environment", 0, FV_RADIANCE_MAX, c, "", &e.horizon, err)) != FV_OK) return st;
        e.zenith = e.ground = e.horizon;
    } else {
        if ((st = fv_json_check_keys(o, keys, c->file, "environment", err)) || (st = fv_json_require(o, "horizon", c->file, "environment", err)) ||
            (st = vec3(o, "horizon", 0, FV_RADIANCE_MAX, c, "environment", &e.horizon, err)))
            return st;
        e.zenith = e.ground = e.horizon;
        if ((st = vec3(o, "zenith", 0, FV_RADIANCE_MAX, c, "environment", &e.zenith, err)) ||
            (st = vec3(o, "ground", 0, FV_RADIANCE_MAX, c, "environment", &e.ground, err)) ||
            (st = vec3(o, "up", -BIG, BIG, c, "environment", &e.up, err)))
            return st;
    }
    /* fv_scene_set_env's messages start "environment: " already. */
    if ((st = fv_scene_set_env(c->scene, &e, err)) != FV_OK) fv_error_prefix(err, "%s: ", c->file);
    return st;
}

static fv_status parse_camera_key(const cJSON *o, const json_ctx *c, const char *where, bool timed, fv_camera_key *k, fv_error *err)
{
    static const char *const keys[] = {"time", "pos", "look", "up", "fov", NULL};
    static const char *const ckeys[] = {"pos", "look", "up", "fov", NULL};
    fv_status st = fv_json_check_keys(o, timed ? keys : ckeys, c->file, where, err);
    double t = 0, fov = 40;
    k->up = fv_v3(0, 1, 0);
    if (st || (st = fv_json_require(o, "pos", c->file, where, err)) || (st = fv_json_require(o, "look", c->file, where, err)) ||
        (timed && (st = fv_json_require(o, "time", c->file, where, err))) || (st = coord3(o, "pos", c, where, &k->pos, err)) ||
        (st = coord3(o, "look", c, where, &k->look, err)) || (st = coord3(o, "up", c, where, &k->up, err)) ||
        (st = fv_json_number(o, "fov", 0.01, 179.9, c->file, where, &fov, err)) ||
        (st = fv_json_number(o, "time", -1e9, 1e9, c->file, where, &t, err)))
        return st;
    k->time = t;
    k->fov_y = (float)fov;
    fv_camera cam = {k->pos, k->look, k->up, k->fov_y, 1, 1};
    fv_camera_basis b;
    if ((st = fv_camera_basis_make(&cam, &b, err)) != FV_OK) {
        /* camera.c names the camera "camera: "; where names it better ("camera_path[3]"). */
        static const char own[] = "camera: ";
        if (!strncmp(err->msg, own, sizeof own - 1)) memmove(err->msg, err->msg + sizeof own - 1, strlen(err->msg) - (sizeof own - 1) + 1);
        fv_error_prefix(err, "%s: %s: ", c->file, where);
    }
    return st;
}

fv_status fv_load_json(const char *path, fv_scene *scene, fv_view *view, const fv_log *log, fv_error *err)
{
    static const char *const keys[] = {"materials", "objects", "lights", "environment", "camera", "camera_path", "display", "gaze", "description", NULL};
    cJSON *root = NULL;
    fv_status st = fv_json_parse_file(path, &root, err);
    if (st != FV_OK) return st;
    json_ctx c;
    c.file = path;
    c.scene = scene;
    c.log = log;
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s", path);
    snprintf(c.dir, sizeof c.dir, "%s", dirname(tmp));
    if ((st = fv_json_check_keys(root, keys, path, "", err)) != FV_OK) goto done;
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(root, "materials");
    if (it && !cJSON_IsObject(it)) {
        st = fv_error_set(err, FV_ERR_INVALID, "%s: materials: expected an object of name: material", path);
        goto done;
    }
    for (const cJSON *m = it ? it->child : NULL; m && st == FV_OK; m = m->next) st = parse_material(m, &c, err);
    if (st != FV_OK) goto done;
    it = cJSON_GetObjectItemCaseSensitive(root, "objects");
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) == 0) {
        st = fv_error_set(err, FV_ERR_INVALID, "%s: objects: expected a non-empty array", path);
        goto done;
    }
    int i = 0;
    for (const cJSON *o = it->child; o && st == FV_OK; o = o->next, i++) st = parse_object(o, &c, i, err);
    if (st != FV_OK) goto done;
    it = cJSON_GetObjectItemCaseSensitive(root, "lights");
    if (it && !cJSON_IsArray(it)) {
        st = fv_error_set(err, FV_ERR_INVALID, "%s: lights: expected an array", path);
        goto done;
    }
    i = 0;
    for (const cJSON *l = it ? it->child : NULL; l && st == FV_OK; l = l->next, i++) st = parse_light(l, &c, i, err);
    if (st != FV_OK) goto done;
    if (cJSON_GetObjectItemCaseSensitive(root, "environment") && (st = parse_environment(root, &c, err)) != FV_OK) goto done;
    if ((it = cJSON_GetObjectItemCaseSensitive(root, "camera"))) {
        fv_camera_key k;
        if ((st = parse_camera_key(it, &c, "camera", false, &k, err)) != FV_OK) goto done;
        fv_camera cam = {k.pos, k.look, k.up, k.fov_y, 512, 512};
        fv_view_set_camera(view, &cam);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(root, "camera_path")) && cJSON_IsString(it)) {
        /* A recorded trace next to the scene file. */
        char full[8192];
        snprintf(full, sizeof full, "%s%s%s", it->valuestring[0] == '/' ? "" : c.dir, it->valuestring[0] == '/' ? "" : "/", it->valuestring);
        fv_camera base;
        fv_view_camera(view, scene, 0.0, 512, 512, &base);
        fv_camera_key *k = NULL;
        int n = 0;
        if ((st = fv_camera_path_load_csv(full, &base, &k, &n, err)) != FV_OK || (st = fv_view_set_camera_path(view, k, n, err)) != FV_OK)
            fv_error_prefix(err, "%s: camera_path: ", path);
        fv_camera_keys_free(k);
        if (st != FV_OK) goto done;
    } else if (it) {
        int n = cJSON_GetArraySize(it);
        if (!cJSON_IsArray(it) || n < 1) {
            st = fv_error_set(err, FV_ERR_INVALID, "%s: camera_path: expected a non-empty array", path);
            goto done;
        }
        fv_camera_key *k = fv_alloc_array((size_t)n, sizeof *k);
        if (!k) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            goto done;
        }
        i = 0;
        for (const cJSON *e = it->child; e && st == FV_OK; e = e->next, i++) {
            char w[48];
            snprintf(w, sizeof w, "camera_path[%d]", i);
            st = parse_camera_key(e, &c, w, true, &k[i], err);
        }
        if (st == FV_OK && (st = fv_view_set_camera_path(view, k, n, err)) != FV_OK) fv_error_prefix(err, "%s: ", path);
        fv_camera_keys_free(k);
        if (st != FV_OK) goto done;
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(root, "display"))) {
        fv_eye_model eye;
        fv_eye_model_default(1, 1, &eye);
        double size[2] = {0, 0};
        /* "size" is the display's pixels per eye; the rest is the eye model of docs/gaze.md. */
        cJSON *copy = cJSON_Duplicate(it, 1);
        if (!copy) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory");
            goto done;
        }
        st = fv_json_numbers(copy, "size", 2, 1, FV_FILM_MAX_DIM, path, "display", size, err);
        cJSON_DeleteItemFromObjectCaseSensitive(copy, "size");
        if (st == FV_OK) {
            eye.width = size[0] > 0 ? (int)size[0] : 1;
            eye.height = size[1] > 0 ? (int)size[1] : 1;
            st = fv_gaze_json_eye(copy, path, "display", &eye, err);
        }
        cJSON_Delete(copy);
        if (st != FV_OK) goto done;
        fv_view_set_display(view, &eye);
    }
    if ((it = cJSON_GetObjectItemCaseSensitive(root, "gaze"))) {
        fv_gaze_path *g;
        if ((st = fv_gaze_json_path(it, path, "gaze", c.dir, &g, err)) != FV_OK) goto done;
        fv_view_set_gaze_path(view, g);
    }
done:
    cJSON_Delete(root);
    return st;
}
