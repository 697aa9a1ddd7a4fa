/* fovea — decoding texture images with stb_image, in a sandbox child (see texture.h).
 *
 * stb_image reads PNG and JPEG (and TGA, BMP, GIF, PSD, HDR, PNM, which come with it). It is a
 * decoder of untrusted bytes, so it runs only in a child process with an address-space and a
 * CPU limit (core/sandbox.h): the mesh importer's child decodes the images a mesh file names,
 * and fv_texture_load_file starts one for a single file. The size in the header is checked
 * against FV_TEXTURE_MAX_TEXELS before any pixel is decoded.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <stb_image.h>
#include "core/alloc.h"
#include "fovea/limits.h"
#include "scene/texture.h"

/* The size a PNG (IHDR) or JPEG (its first start-of-frame marker) header declares; false for
 * anything else. stb_image refuses a huge image inside stbi_info and then reports the last format
 * it tried ("unknown image type"), so the size is read here first to say what is wrong. */
static bool header_size(const unsigned char *b, size_t n, long long *w, long long *h)
{
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n >= 24 && !memcmp(b, png, 8) && !memcmp(b + 12, "IHDR", 4)) {
        *w = ((long long)b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19];
        *h = ((long long)b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23];
        return true;
    }
    if (n < 4 || b[0] != 0xff || b[1] != 0xd8) return false;
    for (size_t i = 2; i + 9 < n;) {
        if (b[i] != 0xff) return false;
        unsigned m = b[i + 1];
        if (m == 0xff) { /* fill byte */
            i++;
            continue;
        }
        size_t len = ((size_t)b[i + 2] << 8) | b[i + 3];
        /* SOF0..SOF15 except DHT (c4), JPG (c8) and DAC (cc): precision, height, width. */
        if (m >= 0xc0 && m <= 0xcf && m != 0xc4 && m != 0xc8 && m != 0xcc) {
            *h = ((long long)b[i + 5] << 8) | b[i + 6];
            *w = ((long long)b[i + 7] << 8) | b[i + 8];
            return true;
        }
        if (len < 2) return false;
        i += 2 + len;
    }
    return false;
}

bool fv_texels_decode(const void *bytes, size_t n, fv_texels *out, char *why, size_t why_len)
{
    memset(out, 0, sizeof *out);
    int w, h, ch;
    if (n > (size_t)INT32_MAX) {
        snprintf(why, why_len, "larger than 2 GiB");
        return false;
    }
    long long hw, hh;
    if (header_size(bytes, n, &hw, &hh) && hw * hh > FV_TEXTURE_MAX_TEXELS) {
        snprintf(why, why_len, "%lldx%lld is more than the %d texels a texture may have", hw, hh, FV_TEXTURE_MAX_TEXELS);
        return false;
    }
    if (!stbi_info_from_memory(bytes, (int)n, &w, &h, &ch)) {
        snprintf(why, why_len, "not an image stb_image decodes (%s)", stbi_failure_reason());
        return false;
    }
    if (w < 1 || h < 1 || (long long)w * h > FV_TEXTURE_MAX_TEXELS) {
        snprintf(why, why_len, "%dx%d is more than the %d texels a texture may have", w, h, FV_TEXTURE_MAX_TEXELS);
        return false;
    }
    unsigned char *px = stbi_load_from_memory(bytes, (int)n, &w, &h, &ch, 0);
    if (!px || w < 1 || h < 1 || ch < 1 || ch > 4 || (long long)w * h > FV_TEXTURE_MAX_TEXELS) {
        snprintf(why, why_len, "cannot decode it (%s)", px ? "unexpected size" : stbi_failure_reason());
        free(px);
        return false;
    }
    *out = (fv_texels){w, h, ch, px};
    return true;
}

bool fv_texels_put(int fd, const fv_texels *t)
{
    int head[3] = {t->w, t->h, t->channels};
    return fv_sandbox_write(fd, head, sizeof head) && fv_sandbox_write(fd, t->px, (size_t)t->w * t->h * t->channels);
}

bool fv_texels_get(fv_sandbox *sb, fv_texels *out)
{
    int head[3];
    memset(out, 0, sizeof *out);
    if (!fv_sandbox_read(sb, head, sizeof head)) return false;
    if (head[0] < 1 || head[1] < 1 || (long long)head[0] * head[1] > FV_TEXTURE_MAX_TEXELS || head[2] < 1 || head[2] > 4) return false;
    size_t n = (size_t)head[0] * head[1] * head[2];
    unsigned char *px = fv_alloc_array(n, 1);
    if (!px || !fv_sandbox_read(sb, px, n)) {
        free(px);
        return false;
    }
    *out = (fv_texels){head[0], head[1], head[2], px};
    return true;
}

/* ---- one file, in a child of its own ---- */

typedef struct file_job {
    const char *path;
} file_job;

bool fv_texels_decode_file(const char *path, fv_texels *out, char *why, size_t why_len)
{
    why[0] = '\0';
    FILE *f = fopen(path, "rb");
    unsigned char *bytes = NULL;
    size_t n = 0;
    if (!f) {
        snprintf(why, why_len, "cannot open it (%s)", strerror(errno));
    } else {
        struct stat sb;
        if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode) || sb.st_size < 0 || (unsigned long long)sb.st_size > (unsigned long long)INT32_MAX)
            snprintf(why, why_len, "cannot read it (not a regular file under 2 GiB)");
        else if (!(bytes = fv_alloc_array((size_t)sb.st_size, 1)) || fread(bytes, 1, (size_t)sb.st_size, f) != (size_t)sb.st_size)
            snprintf(why, why_len, "cannot read it");
        else
            n = (size_t)sb.st_size;
        fclose(f);
    }
    bool ok = !why[0] && fv_texels_decode(bytes, n, out, why, why_len);
    free(bytes);
    return ok;
}

/* The child's answer: 'T' and the texels, or 'W', a length and why not. */
static int decode_file_child(void *user, int fd)
{
    const file_job *j = user;
    char why[512];
    fv_texels t;
    bool ok = fv_texels_decode_file(j->path, &t, why, sizeof why), sent;
    if (ok) {
        sent = fv_sandbox_write(fd, "T", 1) && fv_texels_put(fd, &t);
        free(t.px);
    } else {
        int len = (int)strlen(why);
        sent = fv_sandbox_write(fd, "W", 1) && fv_sandbox_write(fd, &len, sizeof len) && fv_sandbox_write(fd, why, (size_t)len);
    }
    return sent ? 0 : 3;
}

fv_status fv_texture_load_file(fv_scene *scene, const char *path, const char *user, const fv_log *log, int *id, fv_error *err)
{
    *id = 0;
    file_job j = {path};
    fv_sandbox *box;
    fv_error e2;
    /* A 4096 x 4096 RGBA image decodes into 64 MiB; the decoder's own buffers need a few times
     * that. JPEG and PNG decode at tens of MB a second. */
    fv_status st = fv_sandbox_start(decode_file_child, &j, (size_t)1 << 30, 20, &box, &e2);
    if (st != FV_OK) {
        fv_log_warn(log, "texture '%s' of %s: %s; using the constant colour", path, user, e2.msg);
        return FV_OK;
    }
    char tag = 0, why[512] = "the decoder stopped early";
    fv_texels t = {0, 0, 0, NULL};
    bool got = false;
    if (fv_sandbox_read(box, &tag, 1)) {
        int len;
        if (tag == 'T') got = fv_texels_get(box, &t);
        else if (tag == 'W' && fv_sandbox_read(box, &len, sizeof len) && len >= 0 && len < (int)sizeof why && fv_sandbox_read(box, why, (size_t)len))
            why[len] = '\0';
    }
    char what[600];
    snprintf(what, sizeof what, "the image decoder");
    if (fv_sandbox_finish(box, what, &e2) != FV_OK && !got && tag != 'W') snprintf(why, sizeof why, "%s", e2.msg);
    if (got) {
        fv_texture_desc d = {path, t.w, t.h, t.channels, t.px};
        st = fv_scene_add_texture(scene, &d, id, &e2);
        free(t.px);
        if (st == FV_ERR_NOMEM) return fv_error_set(err, st, "%s", e2.msg);
        if (st == FV_OK) return FV_OK;
        snprintf(why, sizeof why, "%s", e2.msg);
    }
    fv_log_warn(log, "texture '%s' of %s: %s; using the constant colour", path, user, why);
    return FV_OK;
}
