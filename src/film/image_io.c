/* fovea — image files: PNG (8-bit sRGB, tone-mapped by exposure and clamp), PFM (linear float,
 * either byte order on read), OpenEXR (linear 32-bit float, plus the film's auxiliary buffers as
 * extra channels so a denoiser or a metric script can read them back).
 *
 * Every write goes through an fv_atomic_file (core/fileio.h): a failed or interrupted write never
 * leaves a truncated image under the requested name.
 * Metadata (how the image was made: fovea/film.h, fv_image_write_meta) goes into PNG text chunks
 * before the pixels and EXR string attributes, each named "fovea:KEY" (image_meta.h); PFM has no
 * place for it. The pixel data is the same with or without it.
 * Limits: PNG read is 8 bits per channel (16-bit files are reduced); EXR read takes the first
 * part, scanline or tiled images decoded by scanline chunks only (tiled files are refused).
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <OpenEXR/openexr.h>
#include "core/alloc.h"
#include "core/fileio.h"
#include "fovea/film.h"
#include "film/display.h"
#include "film/film_display.h"
#include "film/image_meta.h"
#include "film/png_errors.h"

fv_image_format fv_image_format_from_path(const char *path)
{
    const char *dot = path ? strrchr(path, '.') : NULL;
    const char *slash = path ? strrchr(path, '/') : NULL;
    if (!dot || (slash && dot < slash)) return FV_IMG_UNKNOWN;
    if (strcasecmp(dot, ".png") == 0) return FV_IMG_PNG;
    if (strcasecmp(dot, ".pfm") == 0) return FV_IMG_PFM;
    if (strcasecmp(dot, ".exr") == 0) return FV_IMG_EXR;
    return FV_IMG_UNKNOWN;
}

/* ---- PNG: written with libpng's full API (the simplified one has no text chunks), read with
 * the simplified one ---- */

/* True when the text is printable ASCII, the same in tEXt's Latin-1 and in UTF-8; anything else
 * goes into an iTXt chunk, whose text is UTF-8 (PNG 1.2, 11.3.4), so other readers see the same
 * characters. */
static bool ascii_text(const char *v)
{
    for (const unsigned char *c = (const unsigned char *)v; *c; c++)
        if ((*c < 32 && *c != '\n') || *c >= 127) return false;
    return true;
}

/* Writes the 8-bit rows and the text chunks into an open stream; false with c->msg on failure.
 * Everything the error path frees is allocated by the caller, so the longjmp leaks nothing. */
static bool png_write_stream(FILE *f, unsigned char *px, png_bytep *rows, png_text *texts, int nt, int w, int h, fv_png_ctx *c)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, c, fv_png_on_error, fv_png_on_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!png || !info) {
        snprintf(c->msg, sizeof c->msg, "out of memory");
        png_destroy_write_struct(&png, NULL);
        return false;
    }
    if (setjmp(c->jb)) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    /* The sRGB chunk the simplified writer added: the bytes are sRGB-encoded. */
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    if (nt > 0) png_set_text(png, info, texts, nt);
    for (int y = 0; y < h; y++) rows[y] = px + (size_t)y * (size_t)w * 3;
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    return true;
}

/* rgba (NULL: none): the pixels converted already (fv_film_display), taken as they are. */
static fv_status png_write(const char *path, const float *rgb, const uint8_t *rgba, int w, int h, float exposure, const fv_params *meta,
                           fv_error *err)
{
    size_t n = (size_t)w * (size_t)h * 3;
    int nm = fv_params_count(meta);
    unsigned char *px = fv_alloc_array(n, 1);
    png_bytep *rows = fv_alloc_array((size_t)h, sizeof *rows);
    png_text *texts = fv_calloc_array((size_t)nm + 1, sizeof *texts);
    char (*keys)[FV_IMAGE_META_KEY_MAX] = fv_calloc_array((size_t)nm + 1, FV_IMAGE_META_KEY_MAX);
    if (!px || !rows || !texts || !keys) {
        free(px), free(rows), free(texts), free(keys);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    }
    if (rgba)
        for (size_t i = 0; i < n; i++) px[i] = rgba[i / 3 * 4 + i % 3];
    else
        for (size_t i = 0; i < n; i++) px[i] = fv_display_byte(rgb[i], exposure);
    int nt = 0;
    for (int i = 0; i < nm; i++) {
        const char *v = fv_params_value(meta, i);
        if (!fv_image_meta_name(fv_params_key(meta, i), keys[nt], sizeof keys[nt])) continue;
        texts[nt].key = keys[nt];
        texts[nt].text = (png_charp)v;
        texts[nt].text_length = strlen(v);
        texts[nt].compression = ascii_text(v) ? PNG_TEXT_COMPRESSION_NONE : PNG_ITXT_COMPRESSION_NONE;
        nt++;
    }
    fv_atomic_file af;
    FILE *f = NULL;
    fv_status s = fv_atomic_file_begin(path, &af, err);
    if (s == FV_OK) s = fv_atomic_file_stream(&af, &f, err);
    if (s == FV_OK) {
        fv_png_ctx c;
        c.msg[0] = 0;
        bool ok = png_write_stream(f, px, rows, texts, nt, w, h, &c);
        if (ok) s = fv_atomic_file_commit(&af, err);
        /* libpng says only "Write Error" when the stream fails: the stream's own errno says why. */
        else if (af.werr) s = fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, strerror(af.werr));
        else s = fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, c.msg[0] ? c.msg : "libpng failed");
    }
    fv_atomic_file_abort(&af);
    free(px), free(rows), free(texts), free(keys);
    return s;
}

static fv_status png_read(const char *path, fv_image *out, fv_error *err)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path))
        return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, img.message[0] ? img.message : "not a PNG file");
    fv_error tmp;
    if (fv_film_check_size((int)img.width, (int)img.height, &tmp) != FV_OK) {
        png_image_free(&img);
        return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, tmp.msg);
    }
    img.format = PNG_FORMAT_RGB;
    size_t n = (size_t)img.width * img.height * 3;
    unsigned char *px = fv_alloc_array(n, 1);
    float *rgb = fv_alloc_array(n, sizeof(float));
    if (!px || !rgb) {
        png_image_free(&img);
        free(px);
        free(rgb);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
    }
    if (!png_image_finish_read(&img, NULL, px, 0, NULL)) {
        free(px);
        free(rgb);
        return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, img.message);
    }
    for (size_t i = 0; i < n; i++) rgb[i] = fv_srgb_decode(px[i] / 255.0f);
    free(px);
    out->width = (int)img.width;
    out->height = (int)img.height;
    out->rgb = rgb;
    return FV_OK;
}

/* ---- PFM: "PF\n<w> <h>\n<scale>\n" then rows bottom to top; scale < 0 means little-endian ---- */

static bool host_little_endian(void)
{
    const uint16_t one = 1;
    return *(const unsigned char *)&one == 1;
}

static fv_status pfm_write(const char *path, const float *rgb, int w, int h, fv_error *err)
{
    fv_atomic_file af;
    FILE *f = NULL;
    fv_status s = fv_atomic_file_begin(path, &af, err);
    if (s == FV_OK) s = fv_atomic_file_stream(&af, &f, err);
    if (s != FV_OK) {
        fv_atomic_file_abort(&af);
        return s;
    }
    /* A failed fprintf or fwrite leaves the stream's error flag set, which the commit reports. */
    bool ok = fprintf(f, "PF\n%d %d\n%s\n", w, h, host_little_endian() ? "-1.0" : "1.0") > 0;
    for (int y = h - 1; ok && y >= 0; y--)
        ok = fwrite(rgb + (size_t)y * w * 3, sizeof(float) * 3, (size_t)w, f) == (size_t)w;
    return fv_atomic_file_commit(&af, err);
}

/* Reads one whitespace-delimited token of the PFM header. */
static bool pfm_token(FILE *f, char *buf, size_t n)
{
    int c;
    while ((c = fgetc(f)) != EOF && isspace(c)) {
    }
    size_t k = 0;
    while (c != EOF && !isspace(c)) {
        if (k + 1 >= n) return false;
        buf[k++] = (char)c;
        c = fgetc(f);
    }
    buf[k] = '\0';
    return k > 0 && c != EOF; /* the single whitespace after the token has been consumed */
}

static fv_status pfm_read(const char *path, fv_image *out, fv_error *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    char magic[8], ws[32], hs[32], ss[64];
    fv_status st = FV_OK;
    float *rgb = NULL, *row = NULL;
    if (!pfm_token(f, magic, sizeof magic) || (strcmp(magic, "PF") != 0 && strcmp(magic, "Pf") != 0) ||
        !pfm_token(f, ws, sizeof ws) || !pfm_token(f, hs, sizeof hs) || !pfm_token(f, ss, sizeof ss)) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': not a PFM file (bad header)", path);
        goto done;
    }
    char *end1, *end2, *end3;
    long w = strtol(ws, &end1, 10), h = strtol(hs, &end2, 10);
    double scale = strtod(ss, &end3);
    if (*end1 || *end2 || *end3 || !isfinite(scale) || scale == 0.0 || w < 1 || h < 1 || w > FV_FILM_MAX_DIM || h > FV_FILM_MAX_DIM) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': bad PFM size or scale ('%s %s %s')", path, ws, hs, ss);
        goto done;
    }
    fv_error tmp;
    if (fv_film_check_size((int)w, (int)h, &tmp) != FV_OK) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, tmp.msg);
        goto done;
    }
    int ch = magic[1] == 'F' ? 3 : 1;
    bool swap = (scale < 0) != host_little_endian();
    rgb = fv_alloc_array((size_t)w * h, 3 * sizeof(float));
    row = fv_alloc_array((size_t)w * ch, sizeof(float));
    if (!rgb || !row) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
        goto done;
    }
    for (long y = h - 1; y >= 0; y--) {
        if (fread(row, sizeof(float) * ch, (size_t)w, f) != (size_t)w) {
            st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': file is truncated (%ldx%ld PFM)", path, w, h);
            goto done;
        }
        for (long x = 0; x < w * ch; x++) {
            if (swap) {
                uint32_t u;
                memcpy(&u, &row[x], 4);
                u = (u >> 24) | ((u >> 8) & 0xff00u) | ((u << 8) & 0xff0000u) | (u << 24);
                memcpy(&row[x], &u, 4);
            }
        }
        float *dst = rgb + (size_t)y * w * 3;
        for (long x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) dst[3 * x + c] = row[ch == 3 ? 3 * x + c : x];
    }
    out->width = (int)w;
    out->height = (int)h;
    out->rgb = rgb;
    rgb = NULL;
done:
    free(rgb);
    free(row);
    fclose(f);
    return st;
}

/* ---- OpenEXR (C API of OpenEXR 3.1) ---- */

/* The library reports details through a callback; keep the last one for our one-line message. */
typedef struct exr_msg {
    char text[256];
} exr_msg;

static void exr_on_error(exr_const_context_t ctxt, exr_result_t code, const char *msg)
{
    void *ud = NULL;
    if (exr_get_user_data(ctxt, &ud) == EXR_ERR_SUCCESS && ud)
        snprintf(((exr_msg *)ud)->text, sizeof ((exr_msg *)ud)->text, "%s", msg ? msg : exr_get_error_code_as_string(code));
}

static exr_context_initializer_t exr_init(exr_msg *m)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = exr_on_error;
    init.user_data = m;
    m->text[0] = '\0';
    return init;
}

static const char *exr_why(const exr_msg *m, exr_result_t r)
{
    return m->text[0] ? m->text : exr_get_error_code_as_string(r);
}

typedef struct exr_plane {
    const char *name;
    const void *data; /* planar, one value per pixel */
    exr_pixel_type_t type;
} exr_plane;

static fv_status exr_write_planes(const char *path, int w, int h, const exr_plane *planes, int np, const fv_params *meta, fv_error *err)
{
    fv_atomic_file af;
    fv_status s = fv_atomic_file_begin(path, &af, err);
    if (s != FV_OK) return s;
    exr_msg m;
    exr_context_initializer_t init = exr_init(&m);
    exr_context_t ctxt = NULL;
    exr_encode_pipeline_t enc;
    bool enc_init = false;
    int part = 0;
    exr_result_t r = exr_start_write(&ctxt, fv_atomic_file_path(&af), EXR_WRITE_FILE_DIRECTLY, &init);
    if (r == EXR_ERR_SUCCESS) r = exr_add_part(ctxt, "fovea", EXR_STORAGE_SCANLINE, &part);
    if (r == EXR_ERR_SUCCESS) r = exr_initialize_required_attr_simple(ctxt, part, w, h, EXR_COMPRESSION_ZIP);
    for (int i = 0; i < np && r == EXR_ERR_SUCCESS; i++)
        r = exr_add_channel(ctxt, part, planes[i].name, planes[i].type, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    for (int i = 0; i < fv_params_count(meta) && r == EXR_ERR_SUCCESS; i++) {
        char name[FV_IMAGE_META_KEY_MAX];
        if (fv_image_meta_name(fv_params_key(meta, i), name, sizeof name)) r = exr_attr_set_string(ctxt, part, name, fv_params_value(meta, i));
    }
    if (r == EXR_ERR_SUCCESS) r = exr_write_header(ctxt);
    int32_t lines = 1;
    if (r == EXR_ERR_SUCCESS) r = exr_get_scanlines_per_chunk(ctxt, part, &lines);
    for (int y = 0; y < h && r == EXR_ERR_SUCCESS; y += lines) {
        exr_chunk_info_t ci;
        r = exr_write_scanline_chunk_info(ctxt, part, y, &ci);
        if (r != EXR_ERR_SUCCESS) break;
        if (!enc_init) {
            memset(&enc, 0, sizeof enc);
            r = exr_encoding_initialize(ctxt, part, &ci, &enc);
            enc_init = r == EXR_ERR_SUCCESS;
        } else {
            r = exr_encoding_update(ctxt, part, &ci, &enc);
        }
        if (r != EXR_ERR_SUCCESS) break;
        /* The library keeps the channel list sorted by name: match our planes by name. */
        for (int c = 0; c < enc.channel_count; c++) {
            exr_coding_channel_info_t *cc = &enc.channels[c];
            const exr_plane *p = NULL;
            for (int i = 0; i < np; i++)
                if (strcmp(planes[i].name, cc->channel_name) == 0) p = &planes[i];
            if (!p) {
                r = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            cc->user_bytes_per_element = 4;
            cc->user_data_type = (uint16_t)p->type;
            cc->user_pixel_stride = 4;
            cc->user_line_stride = 4 * w;
            cc->encode_from_ptr = (const uint8_t *)p->data + (size_t)4 * w * (size_t)(y);
        }
        if (r == EXR_ERR_SUCCESS && y == 0) r = exr_encoding_choose_default_routines(ctxt, part, &enc);
        if (r == EXR_ERR_SUCCESS) r = exr_encoding_run(ctxt, part, &enc);
    }
    if (enc_init) exr_encoding_destroy(ctxt, &enc);
    exr_result_t rf = ctxt ? exr_finish(&ctxt) : EXR_ERR_SUCCESS;
    if (r == EXR_ERR_SUCCESS) r = rf;
    if (r != EXR_ERR_SUCCESS) {
        fv_atomic_file_abort(&af);
        return fv_error_set(err, FV_ERR_IO, "cannot write '%s': %s", path, exr_why(&m, r));
    }
    return fv_atomic_file_commit(&af, err);
}

/* Splits interleaved 3-channel data into planes. */
static float *deinterleave(const float *src, size_t n, int c)
{
    float *p = fv_alloc_array(n, sizeof(float));
    if (p)
        for (size_t i = 0; i < n; i++) p[i] = src[3 * i + c];
    return p;
}

static fv_status exr_write(const char *path, const float *rgb, int w, int h, const fv_film *film, const fv_params *meta, fv_error *err)
{
    static const char *const rgbn[3] = {"R", "G", "B"};
    static const char *const nn[3] = {"N.X", "N.Y", "N.Z"};
    static const char *const an[3] = {"albedo.R", "albedo.G", "albedo.B"};
    static const char *const pn[3] = {"P.X", "P.Y", "P.Z"};
    exr_plane planes[16];
    float *owned[16];
    int np = 0, no = 0;
    size_t n = (size_t)w * h;
    bool ok = true;
    const float *tri[4] = {rgb, NULL, NULL, NULL};
    const char *const *names[4] = {rgbn, nn, an, pn};
    if (film) {
        tri[1] = fv_film_aux_const(film, FV_AUX_NORMAL);
        tri[2] = fv_film_aux_const(film, FV_AUX_ALBEDO);
        tri[3] = fv_film_aux_const(film, FV_AUX_POSITION);
    }
    for (int k = 0; k < 4 && ok; k++) {
        if (!tri[k]) continue;
        for (int c = 0; c < 3 && ok; c++) {
            float *p = deinterleave(tri[k], n, c);
            if (!p) {
                ok = false;
                break;
            }
            owned[no++] = p;
            planes[np++] = (exr_plane){names[k][c], p, EXR_PIXEL_FLOAT};
        }
    }
    if (film && fv_film_aux_const(film, FV_AUX_DEPTH)) planes[np++] = (exr_plane){"Z", fv_film_aux_const(film, FV_AUX_DEPTH), EXR_PIXEL_FLOAT};
    if (film && fv_film_id_const(film)) planes[np++] = (exr_plane){"id", fv_film_id_const(film), EXR_PIXEL_UINT};
    fv_status s = ok ? exr_write_planes(path, w, h, planes, np, meta, err) : fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    for (int i = 0; i < no; i++) free(owned[i]);
    return s;
}

/* The colour (layer "": R, G, B, or Y) or layer L's L.R, L.G, L.B channels. */
static fv_status exr_read(const char *path, const char *layer, fv_image *out, fv_error *err)
{
    exr_msg m;
    exr_context_initializer_t init = exr_init(&m);
    exr_context_t ctxt = NULL;
    exr_result_t r = exr_start_read(&ctxt, path, &init);
    if (r != EXR_ERR_SUCCESS) {
        if (ctxt) exr_finish(&ctxt);
        return fv_error_set(err, r == EXR_ERR_FILE_ACCESS ? FV_ERR_IO : FV_ERR_INVALID, "cannot read '%s': %s", path, exr_why(&m, r));
    }
    fv_status st = FV_OK;
    float *planes[3] = {NULL, NULL, NULL};
    float *rgb = NULL;
    exr_decode_pipeline_t dec;
    bool dec_init = false;
    exr_attr_box2i_t dw;
    exr_storage_t storage;
    if ((r = exr_get_storage(ctxt, 0, &storage)) != EXR_ERR_SUCCESS || (r = exr_get_data_window(ctxt, 0, &dw)) != EXR_ERR_SUCCESS) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, exr_why(&m, r));
        goto done;
    }
    if (storage != EXR_STORAGE_SCANLINE) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': only scanline EXR images are supported", path);
        goto done;
    }
    int64_t w64 = (int64_t)dw.max.x - dw.min.x + 1, h64 = (int64_t)dw.max.y - dw.min.y + 1;
    fv_error tmp;
    if (w64 < 1 || h64 < 1 || w64 > FV_FILM_MAX_DIM || h64 > FV_FILM_MAX_DIM ||
        fv_film_check_size((int)w64, (int)h64, &tmp) != FV_OK) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': unsupported data window %lldx%lld", path, (long long)w64, (long long)h64);
        goto done;
    }
    int w = (int)w64, h = (int)h64;
    const exr_attr_chlist_t *chl = NULL;
    if ((r = exr_get_channels(ctxt, 0, &chl)) != EXR_ERR_SUCCESS) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, exr_why(&m, r));
        goto done;
    }
    /* R, G, B if present; a single Y (luminance) channel fills all three. */
    char names[3][80];
    for (int c = 0; c < 3; c++) snprintf(names[c], sizeof names[c], "%.64s%s%c", layer, layer[0] ? "." : "", "RGB"[c]);
    const char *want[3] = {names[0], names[1], names[2]};
    bool have[3] = {false, false, false}, have_y = false;
    for (int i = 0; i < chl->num_channels; i++) {
        const exr_attr_chlist_entry_t *e = &chl->entries[i];
        for (int c = 0; c < 3; c++)
            if (strcmp(e->name.str, want[c]) == 0 && e->x_sampling == 1 && e->y_sampling == 1) have[c] = true;
        if (!layer[0] && strcmp(e->name.str, "Y") == 0 && e->x_sampling == 1 && e->y_sampling == 1) have_y = true;
    }
    if (!(have[0] && have[1] && have[2]) && !have_y) {
        st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': no full-resolution %s,%s,%s%s channels", path, want[0], want[1], want[2],
                          layer[0] ? "" : " (or Y)");
        goto done;
    }
    if (!(have[0] && have[1] && have[2])) want[0] = want[1] = want[2] = "Y";
    for (int c = 0; c < 3; c++)
        if (!(planes[c] = fv_calloc_array((size_t)w * h, sizeof(float)))) {
            st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
            goto done;
        }
    int32_t lines = 1;
    if ((r = exr_get_scanlines_per_chunk(ctxt, 0, &lines)) != EXR_ERR_SUCCESS) goto fail;
    for (int64_t y = dw.min.y; y <= dw.max.y; y += lines) {
        exr_chunk_info_t ci;
        if ((r = exr_read_scanline_chunk_info(ctxt, 0, (int)y, &ci)) != EXR_ERR_SUCCESS) goto fail;
        if (!dec_init) {
            memset(&dec, 0, sizeof dec);
            if ((r = exr_decoding_initialize(ctxt, 0, &ci, &dec)) != EXR_ERR_SUCCESS) goto fail;
            dec_init = true;
        } else if ((r = exr_decoding_update(ctxt, 0, &ci, &dec)) != EXR_ERR_SUCCESS) {
            goto fail;
        }
        int64_t row = ci.start_y - dw.min.y;
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *cc = &dec.channels[c];
            cc->decode_to_ptr = NULL;
            for (int k = 0; k < 3; k++)
                if (strcmp(cc->channel_name, want[k]) == 0 && !cc->decode_to_ptr) {
                    cc->decode_to_ptr = (uint8_t *)(planes[k] + row * w);
                    cc->user_bytes_per_element = 4;
                    cc->user_data_type = EXR_PIXEL_FLOAT;
                    cc->user_pixel_stride = 4;
                    cc->user_line_stride = 4 * w;
                }
        }
        if (y == dw.min.y && (r = exr_decoding_choose_default_routines(ctxt, 0, &dec)) != EXR_ERR_SUCCESS) goto fail;
        if ((r = exr_decoding_run(ctxt, 0, &dec)) != EXR_ERR_SUCCESS) goto fail;
    }
    /* The Y fallback decodes one channel: copy it to the other two. */
    if (strcmp(want[0], "Y") == 0) {
        memcpy(planes[1], planes[0], (size_t)w * h * sizeof(float));
        memcpy(planes[2], planes[0], (size_t)w * h * sizeof(float));
    }
    if (!(rgb = fv_alloc_array((size_t)w * h, 3 * sizeof(float)))) {
        st = fv_error_set(err, FV_ERR_NOMEM, "out of memory reading '%s'", path);
        goto done;
    }
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int c = 0; c < 3; c++) rgb[3 * i + c] = planes[c][i];
    out->width = w;
    out->height = h;
    out->rgb = rgb;
    goto done;
fail:
    st = fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': %s", path, exr_why(&m, r));
done:
    if (dec_init) exr_decoding_destroy(ctxt, &dec);
    exr_finish(&ctxt);
    for (int c = 0; c < 3; c++) free(planes[c]);
    return st;
}

/* ---- public entry points ---- */

static fv_status check_args(const char *path, int w, int h, fv_image_format *fmt, fv_error *err)
{
    fv_status s = fv_film_check_size(w, h, err);
    if (s != FV_OK) return s;
    *fmt = fv_image_format_from_path(path);
    if (*fmt == FV_IMG_UNKNOWN)
        return fv_error_set(err, FV_ERR_INVALID, "cannot write '%s': unknown image format (use .png, .pfm or .exr)", path ? path : "");
    return FV_OK;
}

fv_status fv_image_write(const char *path, const float *rgb, int w, int h, float exposure, fv_error *err)
{
    return fv_image_write_meta(path, rgb, w, h, exposure, NULL, err);
}

fv_status fv_image_write_meta(const char *path, const float *rgb, int w, int h, float exposure, const fv_params *meta, fv_error *err)
{
    fv_image_format fmt;
    fv_status s = check_args(path, w, h, &fmt, err);
    if (s != FV_OK) return s;
    if (!isfinite(exposure) || exposure < 0.0f)
        return fv_error_set(err, FV_ERR_INVALID, "cannot write '%s': exposure %g must be finite and >= 0", path, exposure);
    if (err) fv_error_clear(err);
    switch (fmt) {
    case FV_IMG_PNG: return png_write(path, rgb, NULL, w, h, exposure, meta, err);
    case FV_IMG_PFM: return pfm_write(path, rgb, w, h, err);
    default: return exr_write(path, rgb, w, h, NULL, meta, err);
    }
}

fv_status fv_film_write(const fv_film *film, const char *path, float exposure, fv_error *err)
{
    return fv_film_write_meta(film, path, exposure, NULL, err);
}

fv_status fv_film_write_meta(const fv_film *film, const char *path, float exposure, const fv_params *meta, fv_error *err)
{
    int w = fv_film_width(film), h = fv_film_height(film);
    fv_image_format fmt;
    fv_status s = check_args(path, w, h, &fmt, err);
    if (s != FV_OK) return s;
    if (fv_film_display(film)) {
        /* the frame left its float colour unwritten: only the PNG it was converted for */
        if (fmt != FV_IMG_PNG || exposure != fv_film_display_exposure(film))
            return fv_error_set(err, FV_ERR_INVALID, "cannot write '%s': the film holds display output only (PNG at exposure %g)", path,
                                fv_film_display_exposure(film));
        if (err) fv_error_clear(err);
        return png_write(path, NULL, fv_film_display(film), w, h, exposure, meta, err);
    }
    if (fmt != FV_IMG_EXR) return fv_image_write_meta(path, fv_film_color_const(film), w, h, exposure, meta, err);
    if (err) fv_error_clear(err);
    return exr_write(path, fv_film_color_const(film), w, h, film, meta, err);
}

fv_status fv_image_read(const char *path, fv_image *out, fv_error *err) { return fv_image_read_layer(path, "", out, err); }

fv_status fv_image_read_layer(const char *path, const char *layer, fv_image *out, fv_error *err)
{
    out->width = out->height = 0;
    out->rgb = NULL;
    struct stat sb;
    if (stat(path, &sb) != 0) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': %s", path, strerror(errno));
    if (S_ISDIR(sb.st_mode)) return fv_error_set(err, FV_ERR_IO, "cannot open '%s': is a directory", path);
    fv_image_format fmt = fv_image_format_from_path(path);
    if (layer[0] && fmt != FV_IMG_EXR) return fv_error_set(err, FV_ERR_INVALID, "cannot read layer '%s' of '%s': only EXR files have layers", layer, path);
    switch (fmt) {
    case FV_IMG_PNG: return png_read(path, out, err);
    case FV_IMG_PFM: return pfm_read(path, out, err);
    case FV_IMG_EXR: return exr_read(path, layer, out, err);
    default: return fv_error_set(err, FV_ERR_INVALID, "cannot read '%s': unknown image format (use .png, .pfm or .exr)", path);
    }
}

void fv_image_free(fv_image *img)
{
    if (!img) return;
    free(img->rgb);
    img->rgb = NULL;
    img->width = img->height = 0;
}
