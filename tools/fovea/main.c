/* fovea — command-line entry point: dispatches to one subcommand per file (cmd_*.c). */
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include "cli.h"
#include "core/provenance_json.h"

typedef struct fv_command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} fv_command;

static const fv_command k_commands[] = {
    {"render", fv_cmd_render, "render a scene with a method to image files"},
    {"methods", fv_cmd_methods, "list the rendering methods and their parameters"},
    {"scenes", fv_cmd_scenes, "list the built-in scenes"},
    {"compare", fv_cmd_compare, "error metrics per region between two images"},
    {"bench", fv_cmd_bench, "run a benchmark scenario: timings and errors side by side"},
    {"view", fv_cmd_view, "interactive viewer: the fovea follows the mouse (needs SDL2)"},
    {"gaze", fv_cmd_gaze, "gaze import: an eye tracker's recording into a gaze trace"},
};

static void usage(FILE *f)
{
    fprintf(f, "usage: fovea <command> [options]   (fovea <command> --help for details)\n\ncommands:\n");
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; i++)
        fprintf(f, "  %-9s %s\n", k_commands[i].name, k_commands[i].summary);
    fprintf(f, "\nfovea renders global illumination where the effort follows the viewer's gaze.\n"
               "Exit status: 0 success, 1 internal error, 2 bad input (the message names it), 128+N interrupted\n"
               "by signal N (130 SIGINT, 143 SIGTERM; also HUP, PIPE, QUIT, USR1, USR2, ALRM: no temporary or partial\n"
               "file is left).\n");
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        usage(stderr);
        return FV_EXIT_USAGE;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") || !strcmp(argv[1], "help")) {
        usage(stdout);
        return FV_EXIT_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        /* The version and the build it is (commit, dirty flag, type, compiler, Embree). */
        char line[512];
        fv_provenance_line(line, sizeof line);
        printf("%s\n", line);
        return FV_EXIT_OK;
    }
    for (size_t i = 0; i < sizeof k_commands / sizeof k_commands[0]; i++)
        if (!strcmp(argv[1], k_commands[i].name)) {
            /* SIGINT, SIGTERM and the like end any command in one line with 128 + N and leave no temporary
             * file or child behind (cli.h); the line names the command as its errors do. */
            bool import = !strcmp(argv[1], "gaze") && argc > 2 && !strcmp(argv[2], "import");
            /* Commands that render run under the thread policy: before anything else, since it
             * may execute the program again (cli_threads.c). */
            if (!strcmp(argv[1], "render") || !strcmp(argv[1], "bench") || !strcmp(argv[1], "view")) {
                int rc = fv_cli_thread_policy(argc, argv, argv[1]);
                if (rc >= 0) return rc;
            }
            fv_cli_interrupt_install(import ? "gaze import" : argv[1]);
            return k_commands[i].run(argc - 1, argv + 1);
        }
    fprintf(stderr, "fovea: unknown command '%s' (try fovea --help)\n", argv[1]);
    return FV_EXIT_USAGE;
}
