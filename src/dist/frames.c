/* fovea — a sequence over MPI ranks (docs/distributed.md, "A sequence"): contiguous blocks of
 * frames, one per rank, each frame written by the rank that rendered it (fv_film_write is atomic).
 * A method that keeps state between frames (fv_technique_warmup_frames, fovea/technique.h) starts
 * each block that many frames early and discards them: its first written frame then has the
 * history a one-process run would have built over those frames. Methods whose history decays
 * (exponential averages) converge to, but do not equal bit for bit, the one-process frames; the
 * manifest says which frames were warm-ups on which rank.
 */
#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include "core/fileio.h"
#include "dist/split.h"

void fv_dist_frames(int frames, int rank, int size, int warmup, int *start, int *first, int *end)
{
    *first = (int)((long long)frames * rank / size);
    *end = (int)((long long)frames * (rank + 1) / size);
    *start = *first - warmup < 0 ? 0 : *first - warmup;
}

double fv_dist_frames_share(int frames, int rank, int size, int warmup, int still_warmup)
{
    double mine = 0.0, all = 0.0;
    for (int r = 0; r < size; r++) {
        int start, first, end;
        fv_dist_frames(frames, r, size, warmup, &start, &first, &end);
        const double n = (end > start ? end - start : 0) + (start == 0 ? still_warmup : 0);
        all += n;
        if (r == rank) mine = n;
    }
    return all > 0.0 ? mine / all : 0.0;
}

fv_status fv_dist_frames_manifest(const char *path, const char *method, int frames, int size, int warmup, fv_error *err)
{
    cJSON *root = cJSON_CreateObject(), *blocks = cJSON_CreateArray();
    if (!root || !blocks) {
        cJSON_Delete(root);
        cJSON_Delete(blocks);
        return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    }
    bool ok = true;
    cJSON_AddStringToObject(root, "method", method);
    cJSON_AddNumberToObject(root, "frames", frames);
    cJSON_AddNumberToObject(root, "ranks", size);
    cJSON_AddNumberToObject(root, "warmup_frames", warmup);
    cJSON_AddItemToObject(root, "blocks", blocks);
    for (int r = 0; ok && r < size; r++) {
        int start, first, end;
        fv_dist_frames(frames, r, size, warmup, &start, &first, &end);
        cJSON *b = cJSON_CreateObject();
        if (!(ok = b != NULL)) break;
        cJSON_AddNumberToObject(b, "rank", r);
        cJSON_AddNumberToObject(b, "first", first);
        cJSON_AddNumberToObject(b, "end", end);
        cJSON_AddNumberToObject(b, "rendered_from", first < end ? start : first);
        cJSON_AddItemToArray(blocks, b);
    }
    char *text = ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) return fv_error_set(err, FV_ERR_NOMEM, "out of memory writing '%s'", path);
    fv_status s = fv_file_write_atomic(path, text, strlen(text), err);
    cJSON_free(text);
    return s;
}
