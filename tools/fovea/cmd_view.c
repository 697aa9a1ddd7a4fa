/* fovea CLI — `fovea view`: hands over to the interactive viewer, a separate executable
 * (fovea-view) because it needs SDL2 and the CLI must build and run without it. It is looked up
 * next to the running `fovea`, not on PATH, so a build folder or an install prefix always pairs
 * a viewer with the library it was built against. */
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "cli.h"

int fv_cmd_view(int argc, char **argv)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    char path[PATH_MAX + 16];
    path[0] = '\0';
    if (n > 0) {
        self[n] = '\0';
        char *slash = strrchr(self, '/');
        if (slash) {
            *slash = '\0';
            snprintf(path, sizeof path, "%s/fovea-view", self);
        }
    }
    if (!path[0] || access(path, X_OK) != 0)
        return fv_cli_usage_error("view", "the viewer was not built (install libsdl2-dev and rebuild)");
    /* argv[0] is "view"; the viewer gets the rest unchanged */
    char **args = calloc((size_t)argc + 1, sizeof *args);
    if (!args) return fv_cli_usage_error("view", "out of memory");
    args[0] = path;
    for (int i = 1; i < argc; i++) args[i] = argv[i];
    execv(path, args);
    int e = errno;
    free(args);
    return fv_cli_usage_error("view", "cannot run %s: %s", path, strerror(e));
}
