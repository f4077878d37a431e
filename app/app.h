// app.h — the two things `rouge` does: render headlessly, or run the interactive viewer.
//
//   rs_cli cli;  rs_cli_parse(argc, argv, true, &cli, &err);
//   if (rs_app_render(&cli, &err) != RS_OK) fprintf(stderr, "rouge: %s\n", err.msg);
#ifndef RS_APP_APP_H
#define RS_APP_APP_H

#include "cli.h"
#include "rouge.h"

#define RS_APP_VERSION "0.1.0"
#define RS_APP_DEFAULT_FACE "assets/face.rsf"

// The face opened when none is named: assets/face.rsf in a source tree, else the installed copy next to
// the program (<bin>/../share/rouge/face.rsf, what `make install` puts there). Fills buf.
const char *rs_app_default_face(char *buf, size_t n);

// Headless: load the face, apply --look / --strokes, render the view to cli->output (atomic PNG write).
rs_result rs_app_render(const rs_cli *cli, rs_error *err);
// The command line's view (every field explicit) as the public API's view.
rouge_view rs_app_public_view(const rs_view *v, const char *env);
// The environments' directory next to the program: <bin>/../share/rouge/env when installed, else
// <bin>/../assets/env (a source tree's build/); NULL if neither.
const char *rs_app_env_dir(char *buf, size_t n);
// A public API failure as the app's error (same codes, same message); returns the code.
rs_result rs_app_error(rouge_result r, const rouge_error *e, rs_error *err);
// The GLFW viewer (viewer.c).
rs_result rs_app_view(const rs_cli *cli, rs_error *err);
void rs_app_print_viewer_help(FILE *f);

#endif
