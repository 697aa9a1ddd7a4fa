/* fovea — outputs that are not inputs (see inputs.h). */
#include <string.h>
#include <sys/stat.h>
#include "core/fileio.h"
#include "core/inputs.h"

void fv_inputs_init(fv_inputs *s)
{
    memset(s, 0, sizeof *s);
}

void fv_inputs_add(fv_inputs *s, const char *path, const char *what)
{
    struct stat sb;
    if (!path || !path[0] || s->n == FV_INPUTS_MAX || stat(path, &sb) != 0) return;
    s->in[s->n].dev = (unsigned long long)sb.st_dev;
    s->in[s->n].ino = (unsigned long long)sb.st_ino;
    s->in[s->n].path = path;
    s->in[s->n].what = what;
    s->n++;
}

fv_status fv_inputs_check_output(const fv_inputs *s, const char *path, const char *what, fv_error *err)
{
    /* stat follows links, as the atomic writer does to find the file it replaces. */
    struct stat sb;
    if (path && path[0] && stat(path, &sb) == 0)
        for (int i = 0; i < s->n; i++)
            if (s->in[i].dev == (unsigned long long)sb.st_dev && s->in[i].ino == (unsigned long long)sb.st_ino)
                return fv_error_set(err, FV_ERR_IO, "%s %s is the %s %s", what, path, s->in[i].what, s->in[i].path);
    return fv_file_check_write(path, err);
}
