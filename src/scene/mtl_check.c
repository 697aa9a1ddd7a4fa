/* fovea — naming the line of a material library that the importer could not read.
 *
 * assimp reads an OBJ's material libraries (`mtllib`) as part of the OBJ and reports a number it
 * cannot parse ("Cannot parse string ... as a real number") without saying which file or line it
 * was in, so a broken .mtl beside a good .obj read as a fault of the .obj. When an OBJ import has
 * failed, this looks through the libraries the OBJ names for the first statement whose numbers do
 * not parse and says where it is. It runs only after a failure: it never refuses what assimp reads.
 *
 * The statements checked are the MTL format's numeric ones (Ka, Kd, Ks, Ke, Tf: a colour; Ns, Ni,
 * d, Tr, sharpness, illum: one number). The format's "Kd spectral FILE" and "Kd xyz X Y Z" forms are
 * faults too: assimp reads numbers only. Reads are bounded:
 * the first 1 MiB of the OBJ (where `mtllib` lines sit), 8 libraries, lines of up to 4096 bytes.
 */
#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "core/fileio.h"
#include "scene/load_impl.h"

#define OBJ_SCAN_BYTES (1L << 20)
#define MAX_LIBS 8
#define LINE_MAX_BYTES 4096

/* The token at *p (advanced past it and the blanks after it) copied into tok; false at the end. */
static bool next_token(const char **p, char *tok, size_t n)
{
    const char *s = *p;
    while (*s == ' ' || *s == '\t') s++;
    if (!*s || *s == '\n' || *s == '\r' || *s == '#') return false;
    size_t k = 0;
    while (*s && !isspace((unsigned char)*s)) {
        if (k + 1 < n) tok[k++] = *s;
        s++;
    }
    tok[k] = '\0';
    *p = s;
    return true;
}

static bool is_number(const char *t)
{
    char *end;
    errno = 0;
    strtod(t, &end);
    return end != t && *end == '\0';
}

/* The printable form of token t: bytes outside printable ASCII as \xNN. */
static void printable(const char *t, char *out, size_t n)
{
    size_t k = 0;
    for (; *t && k + 5 < n; t++) {
        unsigned char c = (unsigned char)*t;
        if (c >= 0x20 && c < 0x7f) out[k++] = (char)c;
        else k += (size_t)snprintf(out + k, n - k, "\\x%02x", c);
    }
    out[k] = '\0';
}

/* The first fault of statement `line` (line number no of lib) in why; false when it has none. */
static bool line_fault(const char *line, const char *lib, long no, char *why, size_t n)
{
    static const char *const colours[] = {"Ka", "Kd", "Ks", "Ke", "Tf", NULL};
    static const char *const scalars[] = {"Ns", "Ni", "d", "Tr", "sharpness", "illum", NULL};
    const char *p = line;
    char key[32], tok[256], shown[64];
    if (!next_token(&p, key, sizeof key)) return false;
    bool colour = false, scalar = false;
    for (int i = 0; colours[i]; i++) colour |= !strcmp(key, colours[i]);
    for (int i = 0; scalars[i]; i++) scalar |= !strcmp(key, scalars[i]);
    if (!colour && !scalar) return false;
    int count = 0;
    while (next_token(&p, tok, sizeof tok)) {
        if (!is_number(tok)) {
            printable(tok, shown, sizeof shown);
            snprintf(why, n, "material library '%s', line %ld: %s wants a number, not '%s'", lib, no, key, shown);
            return true;
        }
        count++;
    }
    if (count == 0) {
        snprintf(why, n, "material library '%s', line %ld: %s without a number", lib, no, key);
        return true;
    }
    return false;
}

/* Looks through library file `path` (shown as `name`); true with the fault in why. */
static bool lib_fault(const char *path, const char *name, char *why, size_t n)
{
    FILE *f;
    fv_error err;
    if (fv_file_open_read(path, "material library", &f, &err) != FV_OK) return false; /* assimp said what it could */
    char *line = NULL;
    size_t cap = 0;
    long len, no = 0;
    bool found = false;
    while (!found && (len = fv_file_getline(f, &line, &cap, LINE_MAX_BYTES)) != 0) {
        no++;
        if (len < 0) {
            snprintf(why, n, "material library '%s', line %ld: longer than %d bytes", name, no, LINE_MAX_BYTES);
            found = true;
            break;
        }
        if (strlen(line) != (size_t)len) {
            snprintf(why, n, "material library '%s', line %ld: a NUL byte (not a text file?)", name, no);
            found = true;
            break;
        }
        found = line_fault(line, name, no, why, n);
    }
    free(line);
    fclose(f);
    return found;
}

bool fv_mtl_find_fault(const char *obj_path, char *why, size_t n)
{
    const char *dot = strrchr(obj_path, '.');
    if (!dot || strcasecmp(dot, ".obj") != 0) return false;
    FILE *f;
    fv_error err;
    if (fv_file_open_read(obj_path, "scene", &f, &err) != FV_OK) return false;
    char *line = NULL;
    size_t cap = 0;
    long len, read = 0;
    int libs = 0;
    bool found = false;
    const char *slash = strrchr(obj_path, '/');
    while (!found && libs < MAX_LIBS && read < OBJ_SCAN_BYTES && (len = fv_file_getline(f, &line, &cap, LINE_MAX_BYTES)) != 0) {
        read += len < 0 ? LINE_MAX_BYTES : len;
        if (len < 0) { /* the rest of an over-long line */
            int c;
            while ((c = fgetc(f)) != EOF && c != '\n') {}
            continue;
        }
        const char *p = line;
        char key[16], name[1024];
        if (!next_token(&p, key, sizeof key) || strcmp(key, "mtllib") != 0) continue;
        while (!found && libs < MAX_LIBS && next_token(&p, name, sizeof name)) {
            char path[4200];
            if (name[0] == '/' || !slash) snprintf(path, sizeof path, "%s", name);
            else snprintf(path, sizeof path, "%.*s/%s", (int)(slash - obj_path), obj_path, name);
            libs++;
            found = lib_fault(path, name, why, n);
        }
    }
    free(line);
    fclose(f);
    return found;
}
