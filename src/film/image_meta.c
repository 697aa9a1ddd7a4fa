/* fovea — reading back the metadata fovea writes into images (fovea/film.h: fv_image_read_meta):
 * PNG text chunks (tEXt, zTXt, iTXt) before the pixel data and EXR string attributes of the first
 * part, each named "fovea:KEY" (image_meta.h). Other software's chunks and attributes are left
 * out; a PFM has no metadata. Text chunks after the pixel data are not read (fovea writes none
 * there).
 */
#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <OpenEXR/openexr.h>
#include "film/image_meta.h"
#include "fovea/film.h"
#include "film/png_errors.h"

bool fv_image_meta_name(const char *key, char *out, size_t n)
{
    int w = snprintf(out, n, "%s%s", FV_IMAGE_META_PREFIX, key);
    return w > 0 && (size_t)w < n && (size_t)w < FV_IMAGE_META_KEY_MAX;
}

/* One name/value into the bag when the name is ours; keys the bag refuses are skipped (a file
 * written by something else may carry any name after the prefix). */
static fv_status keep(fv_params *out, const char *name, const char *value, fv_error *err)
{
    size_t np = strlen(FV_IMAGE_META_PREFIX);
    if (strncmp(name, FV_IMAGE_META_PREFIX, np) != 0) return FV_OK;
    fv_error tmp;
    fv_status st = fv_params_set(out, name + np, value, &tmp);
    if (st == FV_ERR_NOMEM) return fv_error_set(err, st, "%s", tmp.msg);
    return FV_OK;
}

static fv_status png_meta(const char *path, FILE *f, fv_params *out, fv_error *err)
{
    fv_png_ctx c;
    c.msg[0] = 0;
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &c, fv_png_on_error, fv_png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        png_destroy_read_struct(&png, NULL, NULL);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    }
    if (setjmp(c.jb)) {
        png_destroy_read_struct(&png, &info, NULL);
        return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, c.msg[0] ? c.msg : "not a PNG file");
    }
    png_init_io(png, f);
    png_read_info(png, info);
    png_textp texts = NULL;
    int nt = 0;
    png_get_text(png, info, &texts, &nt);
    fv_status st = FV_OK;
    for (int i = 0; i < nt && st == FV_OK; i++)
        if (texts[i].key && texts[i].text) st = keep(out, texts[i].key, texts[i].text, err);
    png_destroy_read_struct(&png, &info, NULL);
    return st;
}

/* OpenEXR's default error handler prints every detail on stderr, a line each (2 to 4 for a
 * malformed header): ours keeps the last, the most specific, for fovea's one line. */
typedef struct exr_meta_msg {
    char text[256];
} exr_meta_msg;

static void exr_meta_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *ud = NULL;
    if (exr_get_user_data(ctxt, &ud) != EXR_ERR_SUCCESS || !ud) return;
    exr_meta_msg *m = ud;
    snprintf(m->text, sizeof m->text, "%s", msg ? msg : exr_get_error_code_as_string(code));
}

static fv_status exr_meta(const char *path, fv_params *out, fv_error *err)
{
    exr_context_t ctxt = NULL;
    exr_meta_msg m = {{0}};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_meta_on_error;
    init.user_data = &m;
    exr_result_t r = exr_start_read(&ctxt, path, &init);
    int32_t n = 0;
    if (r == EXR_ERR_SUCCESS) r = exr_get_attribute_count(ctxt, 0, &n);
    fv_status st = FV_OK;
    for (int32_t i = 0; i < n && r == EXR_ERR_SUCCESS && st == FV_OK; i++) {
        const exr_attribute_t *a = NULL;
        r = exr_get_attribute_by_index(ctxt, 0, EXR_ATTR_LIST_FILE_ORDER, i, &a);
        if (r != EXR_ERR_SUCCESS || !a || a->type != EXR_ATTR_STRING || !a->string || !a->string->str) continue;
        /* EXR strings carry a length and need no terminator: copy before use. */
        char value[4096];
        snprintf(value, sizeof value, "%.*s", (int)a->string->length, a->string->str);
        st = keep(out, a->name, value, err);
    }
    if (ctxt) exr_finish(&ctxt);
    if (r != EXR_ERR_SUCCESS && st == FV_OK)
        st = fv_error_set(err, r == EXR_ERR_FILE_ACCESS ? FV_ERR_IO : FV_ERR_INVALID, "cannot read '%s': %s", path, m.text[0] ? m.text : exr_get_error_code_as_string(r));
    return st;
}

fv_status fv_image_read_meta(const char *path, fv_params **out, fv_error *err)
{
    *out = NULL;
    struct stat sb;
    if (stat(path, &sb) != 0) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    if (S_ISDIR(sb.st_mode)) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': is a directory", path);
    fv_image_format fmt = fv_image_format_from_path(path);
    if (fmt == FV_IMG_UNKNOWN) return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': unknown image format (use .png, .pfm or .exr)", path);
    fv_params *p;
    fv_status st = fv_params_create(&p, err);
    if (st != FV_OK) return st;
    if (fmt == FV_IMG_PNG) {
        FILE *f = fopen(path, "rb");
        if (!f) st = fv_error_set(err, FV_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
        else {
            st = png_meta(path, f, p, err);
            fclose(f);
        }
    } else if (fmt == FV_IMG_EXR) {
        st = exr_meta(path, p, err);
    }
    if (st != FV_OK) {
        fv_params_destroy(p);
        return st;
    }
    *out = p;
    return FV_OK;
}
