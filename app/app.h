// app.h — the two things `rouge` does: render headlessly, or run the interactive viewer.
//
//   rs_cli cli;  rs_cli_parse(argc, argv, true, &cli, &err);
//   if (rs_app_render(&cli, &err) != RS_OK) fprintf(stderr, "rouge: %s\n", err.msg);
#ifndef RS_APP_APP_H
#define RS_APP_APP_H

#include "cli.h"
#include "core/image.h"
#include "rouge.h"

#define RS_APP_VERSION "0.1.0"
#define RS_APP_DEFAULT_FACE "assets/face.rsf"

// The face opened when none is named: assets/face.rsf in a source tree, else the installed copy next to
// the program (<bin>/../share/rouge/face.rsf, what `make install` puts there). Fills buf.
const char *rs_app_default_face(char *buf, size_t n);

// Headless: load the face, apply --look / --strokes, render the view to cli->output (atomic PNG write).
rs_result rs_app_render(const rs_cli *cli, rs_error *err);
// The face's current view drawn n times wider and taller (the same camera: framing does not depend on the
// size) and averaged down in linear light into out (RGBA): a still whose every pixel, highlights and the
// splats' detail included, is the mean of n x n samples, as a camera's would be (the renderer's own
// anti-aliasing reaches its contours only). The face keeps the larger view: set it back before the next frame.
rs_result rs_app_render_supersampled(rouge_face *face, int n, rs_image *out, rs_error *err);
// The command line's view (every field explicit) as the public API's view.
rouge_view rs_app_public_view(const rs_view *v, const char *env);
// The environments' directory next to the program: <bin>/../share/rouge/env when installed, else
// <bin>/../assets/env (a source tree's build/); NULL if neither.
const char *rs_app_env_dir(char *buf, size_t n);
// A public API failure as the app's error (same codes, same message); returns the code.
rs_result rs_app_error(rouge_result r, const rouge_error *e, rs_error *err);
// `rouge looks ...` (looks_cmd.c): argv after "looks".
rs_result rs_app_looks(int argc, char **argv, rs_error *err);
void rs_app_print_looks_help(FILE *f);
// Thumbnails of the look library: a frontal close-up from brows to chin, the same from the CLI and the
// viewer. rs_app_thumbnail renders one headlessly (its own EGL context) as an RGB image.
#define RS_APP_THUMB_ZOOM 1.7f
#define RS_APP_THUMB_PAN_Y (-0.2f)  // view heights: the face moves up, the lips come into the frame
rouge_view rs_app_thumbnail_view(void);
rs_result rs_app_thumbnail(const char *face_path, const void *look, size_t len, rs_image *out, rs_error *err);
// The GLFW viewer (viewer.c).
rs_result rs_app_view(const rs_cli *cli, rs_error *err);
void rs_app_print_viewer_help(FILE *f);

#endif
