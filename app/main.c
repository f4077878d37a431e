// main.c — the `rouge` program: `rouge render` (headless, to PNG) and `rouge view` / `rouge [FACE]`
// (the window). The only place in rouge that prints.
#include "app.h"

#include <stdio.h>
#include <string.h>

static void usage(FILE *f)
{
    fprintf(f,
            "rouge — realistic skin rendering and 3D makeup on point-sampled face scans\n"
            "\n"
            "usage:\n"
            "  rouge [view] [FACE.rsf] [options]        open the viewer (default face: assets/face.rsf); FACE '-'\n"
            "                                           reads standard input; a large .rsf (version 2) shows its\n"
            "                                           first LOD level at once and refines as the rest arrives\n"
            "  rouge render [FACE.rsf] -o OUT.png [options]  render headlessly (EGL) to a PNG\n"
            "  rouge looks list|save|rm|path ...         the look library (see below)\n"
            "  rouge --help | --version\n"
            "\n"
            "options:\n");
    rs_cli_print_options(f);
    fprintf(f, "\n");
    rs_app_print_viewer_help(f);
    fprintf(f, "\n");
    rs_app_print_looks_help(f);
    fprintf(f, "\nFace data: see assets/README.md for the bundled scan's attribution (CC BY 3.0).\n");
}

int main(int argc, char **argv)
{
    const char *cmd = argc > 1 ? argv[1] : "view";
    if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h") || !strcmp(cmd, "help")) {
        usage(stdout);
        return 0;
    }
    if (!strcmp(cmd, "--version")) {
        printf("rouge %s\n", RS_APP_VERSION);
        return 0;
    }
    if (!strcmp(cmd, "looks")) {
        if (argc > 2 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h"))) {
            rs_app_print_looks_help(stdout);
            return 0;
        }
        rs_error err = {0};
        rs_result r = rs_app_looks(argc - 2, argv + 2, &err);
        if (r != RS_OK) fprintf(stderr, "rouge: %s\n", err.msg);
        return r == RS_OK ? 0 : r == RS_ERR_ARG ? 2 : 1;
    }
    bool render = !strcmp(cmd, "render");
    int first = (render || !strcmp(cmd, "view")) ? 2 : 1;
    rs_cli cli;
    rs_error err = {0};
    if (rs_cli_parse(argc - first, argv + first, render, &cli, &err) != RS_OK) {
        fprintf(stderr, "rouge: %s\n", err.msg);
        return 2;
    }
    if (cli.help) {
        usage(stdout);
        return 0;
    }
    rs_result r = render ? rs_app_render(&cli, &err) : rs_app_view(&cli, &err);
    if (r != RS_OK) {
        fprintf(stderr, "rouge: %s\n", err.msg);
        return r == RS_ERR_ARG ? 2 : 1;
    }
    if (render) printf("rouge: wrote %s\n", cli.output);
    return 0;
}
