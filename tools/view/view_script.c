/* fovea-view — scripts: one timed command per line, "FRAME COMMAND ARGS". FRAME counts the
 * frames the viewer has shown (0 is the first), not seconds: a test then sees the same sequence
 * however fast the machine renders. Commands:
 *   key NAME            a key press as SDL names it (Tab, O, V, P, F12, +, -, ...); a prefix
 *                       "shift+" adds Shift (shift+Tab)
 *   mouse X Y           the gaze at normalised panel coordinates X, Y in [0,1]
 *   move R U F          the flying camera moves R right, U up and F forward (scene units), as
 *                       the held keys D/E/W would; a script cannot hold a key
 *   look YAW PITCH      the flying camera turns by YAW (right) and PITCH (down), in degrees, as
 *                       a right-drag would
 *   screenshot FILE     the window as PNG
 *   quit                exit 0
 * '#' starts a comment; blank lines are skipped; frames must not decrease. */
#include <SDL.h>
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "view.h"

static char *next_word(char **p)
{
    char *s = *p;
    while (*s && isspace((unsigned char)*s)) s++;
    if (!*s) return NULL;
    char *w = s;
    while (*s && !isspace((unsigned char)*s)) s++;
    if (*s) *s++ = '\0';
    *p = s;
    return w;
}

static fv_status parse_line(char *line, const char *path, int ln, long last, fv_vw_cmd *c, fv_error *err)
{
    memset(c, 0, sizeof *c);
    char *p = line, *end;
    char *w = next_word(&p);
    c->frame = strtol(w, &end, 10);
    if (*end || c->frame < 0) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: '%s' is not a frame number", path, ln, w);
    if (c->frame < last) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: frame %ld comes before the previous line's %ld", path, ln, c->frame, last);
    char *cmd = next_word(&p);
    if (!cmd) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: a command must follow the frame number", path, ln);
    char *a = next_word(&p), *b = a ? next_word(&p) : NULL, *c3 = b ? next_word(&p) : NULL;
    if (!strcmp(cmd, "key") && a) {
        c->kind = FV_VW_CMD_KEY;
        if (!strncasecmp(a, "shift+", 6)) c->mod = KMOD_LSHIFT, a += 6;
        c->key = SDL_GetKeyFromName(a);
        if (c->key == SDLK_UNKNOWN) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: unknown key '%s'", path, ln, a);
    } else if (!strcmp(cmd, "mouse") && b) {
        c->kind = FV_VW_CMD_MOUSE;
        c->x = strtof(a, &end);
        bool ok = !*end;
        c->y = strtof(b, &end);
        ok = ok && !*end && c->x >= 0 && c->x <= 1 && c->y >= 0 && c->y <= 1;
        if (!ok) return fv_error_set(err, FV_ERR_INVALID, "%s:%d: mouse needs X Y in [0,1]", path, ln);
    } else if ((!strcmp(cmd, "move") && c3) || (!strcmp(cmd, "look") && b)) {
        const bool move = cmd[0] == 'm';
        c->kind = move ? FV_VW_CMD_MOVE : FV_VW_CMD_LOOK;
        char *words[3] = {a, b, c3};
        bool ok = true;
        for (int k = 0; k < (move ? 3 : 2); k++) {
            c->v[k] = strtof(words[k], &end);
            ok = ok && !*end && isfinite(c->v[k]) && fabsf(c->v[k]) < (move ? 1e6f : 360.0f);
        }
        if (!ok)
            return fv_error_set(err, FV_ERR_INVALID, move ? "%s:%d: move needs R U F, finite numbers below 1e6"
                                                          : "%s:%d: look needs YAW PITCH in degrees, each in (-360, 360)",
                                path, ln);
        if (!move) c->v[0] *= 0.017453292f, c->v[1] *= 0.017453292f;
    } else if (!strcmp(cmd, "screenshot") && a) {
        c->kind = FV_VW_CMD_SHOT;
        if (!(c->path = strdup(a))) return fv_error_set(err, FV_ERR_NOMEM, "%s: out of memory", path);
    } else if (!strcmp(cmd, "quit")) {
        c->kind = FV_VW_CMD_QUIT;
    } else {
        return fv_error_set(err, FV_ERR_INVALID, "%s:%d: unknown or incomplete command '%s' (key NAME, mouse X Y, move R U F, look YAW PITCH, screenshot FILE, quit)", path,
                            ln, cmd);
    }
    return FV_OK;
}

fv_status fv_vw_script_load(const char *path, fv_vw_script *out, fv_error *err)
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "r");
    if (!f) return fv_error_set(err, FV_ERR_IO, "--script %s: cannot open", path);
    char line[1024];
    int ln = 0, cap = 0;
    fv_status s = FV_OK;
    while (s == FV_OK && fgets(line, sizeof line, f)) {
        ln++;
        char *hash = strchr(line, '#');
        if (hash) *hash = '\0';
        char *q = line;
        while (*q && isspace((unsigned char)*q)) q++;
        if (!*q) continue;
        if (out->count == cap) {
            cap = cap ? 2 * cap : 16;
            fv_vw_cmd *n = realloc(out->cmd, (size_t)cap * sizeof *n);
            if (!n) {
                s = fv_error_set(err, FV_ERR_NOMEM, "%s: out of memory", path);
                break;
            }
            out->cmd = n;
        }
        long last = out->count ? out->cmd[out->count - 1].frame : 0;
        if ((s = parse_line(q, path, ln, last, &out->cmd[out->count], err)) == FV_OK) out->count++;
    }
    fclose(f);
    if (s != FV_OK) fv_vw_script_free(out);
    return s;
}

void fv_vw_script_free(fv_vw_script *s)
{
    for (int i = 0; i < s->count; i++) free(s->cmd[i].path);
    free(s->cmd);
    memset(s, 0, sizeof *s);
}
