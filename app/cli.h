// cli.h — command-line parsing shared by `rouge render` and `rouge view`: one table of options that
// fill an rs_view plus the file arguments. Errors are returned as one-line messages, never printed here.
//
//   rs_cli cli;
//   if (rs_cli_parse(argc - 2, argv + 2, &cli, &err) != RS_OK) { fprintf(stderr, "rouge: %s\n", err.msg); }
//   rs_render_image(r, &cli.view, &img, &err);
#ifndef RS_APP_CLI_H
#define RS_APP_CLI_H

#include "formats/env_lookup.h"
#include "render/render.h"

#include <stdio.h>

// The viewer's options below exist (viewer.c reads them only then).

typedef struct rs_cli {
    const char *face;       // FACE.rsf (positional)
    const char *output;     // -o PNG
    const char *strokes;    // --strokes FILE: replay painting
    const char *look;       // --look FILE: apply a saved look
    const char *target;     // --target REGION: frame a region of the face
    const char *env;        // --env NAME|FILE.rse (NULL: RS_ENV_DEFAULT; "paper": the key light)
    bool pan_set;           // --pan given (it then also shifts a --target or stroke file's framing)
    const char *save_look;  // --save-look FILE: save the look after replaying strokes
    const char *record;     // --record FILE: viewer records strokes
    const char *looks;      // --looks DIR: the viewer's look library (NULL: rs_looklib_default_dir)
    const char *events;     // --events FILE: viewer replays an event script (tests, demos)
    int bench_orbit;        // --bench-orbit N: viewer orbits N frames, prints frame times, exits (0: off)
    int supersample;        // --supersample N: render draws N x N samples per pixel (0 or 1: one)
    rs_view view;
    bool view_set[4];       // which of yaw/pitch/zoom/fov were given (strokes files carry a view)
    bool size_set;          // --size given (the viewer's window size; default 1024x768)
    bool pipeline_set;      // --pipeline given (the viewer defaults to mobile)
    bool fullscreen;
    bool help;
} rs_cli;

rs_result rs_cli_parse(int argc, char **argv, bool allow_output, rs_cli *out, rs_error *err);
// The options table as help text (one option per line).
void rs_cli_print_options(FILE *f);

#endif
