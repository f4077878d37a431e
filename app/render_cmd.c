// render_cmd.c — `rouge render`: a headless EGL context, the face through the public API (rouge.h, as any
// host uses it), --look, --strokes, --save-look, one frame written to a PNG (--supersample: drawn N times
// larger and averaged down).
#define _POSIX_C_SOURCE 200809L
#include "app.h"

#include "core/image.h"
#include "formats/look.h"
#include "rouge.h"
#include "splat/splat.h"

#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

// <prefix>/REL for the running program, <prefix> being the folder above the one holding it (<bin>/..,
// textually: a path through a missing folder would not resolve); false if unknown.
static bool beside_bin(const char *rel, char *buf, size_t n)
{
    char exe[512];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len <= 0) return false;
    exe[len] = 0;
    for (int k = 0; k < 2; k++) {
        char *slash = strrchr(exe, '/');
        if (!slash) return false;
        *slash = 0;
    }
    snprintf(buf, n, "%s/%s", exe, rel);
    return true;
}

const char *rs_app_default_face(char *buf, size_t n)
{
    snprintf(buf, n, "%s", RS_APP_DEFAULT_FACE);
    if (access(buf, R_OK) == 0) return buf;
    // Installed (<bin>/../share/rouge), or a source tree's build directory run from anywhere, like the
    // environments (rs_app_env_dir).
    if (beside_bin("share/rouge/face.rsf", buf, n) && access(buf, R_OK) == 0) return buf;
    if (beside_bin("assets/face.rsf", buf, n) && access(buf, R_OK) == 0) return buf;
    snprintf(buf, n, "%s", RS_APP_DEFAULT_FACE);
    return buf;
}

const char *rs_app_env_dir(char *buf, size_t n)
{
    if (beside_bin("share/rouge/env", buf, n) && access(buf, R_OK) == 0) return buf;
    // A program run from a source tree's build directory, from anywhere: <tree>/assets/env.
    if (beside_bin("assets/env", buf, n) && access(buf, R_OK) == 0) return buf;
    return NULL;
}

rouge_view rs_app_public_view(const rs_view *v, const char *env)
{
    rouge_view p = {
        .env = env, .env_rotation_deg = v->env_rotate_deg,
        .width = v->width, .height = v->height, .yaw_deg = v->yaw_deg, .pitch_deg = v->pitch_deg,
        .zoom = v->zoom, .fov_deg = v->fov_deg, .pan = {v->pan[0], v->pan[1]},
        // A key light with intensity 0 is still "given" (not the default): rouge.h's zero rule.
        .key = {v->key.yaw_deg, v->key.pitch_deg, {v->key.color[0], v->key.color[1], v->key.color[2]},
                v->key.intensity > 0 ? v->key.intensity : 1.0f},
        .fill = {v->fill.yaw_deg, v->fill.pitch_deg, {v->fill.color[0], v->fill.color[1], v->fill.color[2]},
                 v->fill.intensity},
        .ambient = v->ambient > 0 ? v->ambient : -1.0f,
        .mode = (rouge_mode)v->mode,
        .pipeline = v->pipeline == RS_PIPELINE_MOBILE ? ROUGE_PIPELINE_MOBILE : ROUGE_PIPELINE_REFERENCE,
        .composite = (rouge_composite)v->composite,
        .exposure = v->exposure,
        .background = {v->background[0], v->background[1], v->background[2], 1.0f},
        .no_shadows = v->no_shadows, .hide_makeup = v->hide_makeup, .specular_scale = v->rho_s_scale,
        .max_splats = v->max_splats, .kernel_count = v->kernel_count, .lod_density = v->lod_density,
        .primitive = (rouge_primitive)v->prim,
    };
    return p;
}

rs_result rs_app_error(rouge_result r, const rouge_error *e, rs_error *err)
{
    if (r != ROUGE_OK) rs_fail(err, (rs_result)r, "%s", e->msg);
    return (rs_result)r;
}

// --look, then --strokes (the camera follows the recording unless the command line chose it), then
// --save-look.
static rouge_result paint(const rs_cli *cli, rouge_face *face, rouge_error *e)
{
    rouge_result r = ROUGE_OK;
    if (cli->look) r = rouge_face_load_look(face, cli->look, e);
    if (!r && cli->strokes) {
        rouge_view cam = rouge_face_get_view(face), v = rs_app_public_view(&cli->view, cli->env);
        r = rouge_face_play_strokes(face, cli->strokes, e);
        cam = rouge_face_get_view(face);
        if (!cli->view_set[0]) v.yaw_deg = cam.yaw_deg;
        if (!cli->view_set[1]) v.pitch_deg = cam.pitch_deg;
        if (!cli->view_set[2]) v.zoom = cam.zoom;
        if (!cli->view_set[3]) v.fov_deg = cam.fov_deg;
        if (!cli->pan_set) v.pan[0] = cam.pan[0], v.pan[1] = cam.pan[1];
        if (!r) r = rouge_face_set_view(face, &v, e);
    }
    return r;
}

// Bad input fails in milliseconds, before the GL context (hundreds of ms on llvmpipe; seconds under
// valgrind). The face is decoded once more than needed: a small price beside the upload and shaders.
static rs_result check_inputs(const char *face, const char *look, rs_error *err)
{
    rs_splat_cloud *c = NULL;
    rs_result r = rs_splat_load(face, &c, err);
    rs_splat_destroy(c);
    if (r || !look) return r;
    rs_look *l = NULL;
    r = rs_look_read(look, &l, err);
    rs_look_destroy(l);
    return r;
}

rs_result rs_app_render_supersampled(rouge_face *face, int n, rs_image *out, rs_error *err)
{
    rouge_view v = rouge_face_get_view(face);
    v.width = (v.width ? v.width : 512) * n, v.height = (v.height ? v.height : 512) * n;
    rouge_error e = {0};
    rs_image big = {0};
    rs_result r = rs_app_error(rouge_face_set_view(face, &v, &e), &e, err);
    if (!r) r = rs_app_error(rouge_face_render(face, &e), &e, err);
    if (!r) r = rs_image_create(v.width, v.height, 4, &big, err);
    if (!r) r = rs_app_error(rouge_face_read_rgba(face, big.pixels, (size_t)v.width * v.height * 4, &e), &e, err);
    if (!r) r = rs_image_downsample(&big, n, out, err);
    rs_image_free(&big);
    if (r && err) {
        // The sizes in the message are the larger frame's: say where they come from.
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        rs_fail(err, r, "supersampled %dx: %s", n, msg);
    }
    return r;
}

rs_result rs_app_render(const rs_cli *cli, rs_error *err)
{
    if (!cli->output) return rs_fail(err, RS_ERR_ARG, "render: no output given (-o OUT.png)");
    if (cli->save_look && !cli->look && !cli->strokes)
        return rs_fail(err, RS_ERR_ARG, "--save-look needs --look or --strokes to save");
    char def[600];
    const char *path = cli->face ? cli->face : rs_app_default_face(def, sizeof def);
    const char *inputs[] = {path, cli->look, cli->strokes};
    for (size_t i = 0; i < RS_COUNT_OF(inputs); i++)
        if (rs_same_file(cli->output, inputs[i]))
            return rs_fail(err, RS_ERR_ARG, "-o %s is an input of this render; refusing to overwrite it", cli->output);
    if (rs_same_file(cli->save_look, path) || rs_same_file(cli->save_look, cli->strokes))
        return rs_fail(err, RS_ERR_ARG, "--save-look %s is an input of this render; refusing to overwrite it",
                       cli->save_look);
    int w = cli->view.width, h = cli->view.height, n = cli->supersample;
    if (n > 1 && (w * n > RS_VIEW_MAX_SIZE_PX || h * n > RS_VIEW_MAX_SIZE_PX))
        return rs_fail(err, RS_ERR_ARG, "--supersample %d: %dx%d would be drawn at %dx%d, over %d pixels a side "
                       "(use a smaller --size or N)", n, w, h, w * n, h * n, RS_VIEW_MAX_SIZE_PX);
    rs_result rr = check_inputs(path, cli->look, err);
    if (rr) return rr;
    rs_gl_context *gl = NULL;
    rr = rs_gl_create(&(rs_gl_desc){0}, &gl, err);
    if (rr) return rr;
    rouge_error e = {0};
    rouge_face *face = NULL;
    rouge_view view = rs_app_public_view(&cli->view, cli->env);
    char env_dir[600];
    rouge_result r = rouge_face_create(
        &(rouge_face_desc){.path = path, .view = &view, .env_dir = rs_app_env_dir(env_dir, sizeof env_dir)}, &face,
        &e);
    if (!r) r = paint(cli, face, &e);
    if (!r && cli->target) {
        r = rouge_face_target(face, cli->target, 0, &e);
        // --pan then shifts the framed region.
        rouge_view t = rouge_face_get_view(face);
        t.pan[0] += cli->view.pan[0], t.pan[1] += cli->view.pan[1];
        if (!r) r = rouge_face_set_view(face, &t, &e);
    }
    rs_image still = {0};
    rs_result res = rs_app_error(r, &e, err);
    if (!res && cli->supersample > 1) res = rs_app_render_supersampled(face, cli->supersample, &still, err);
    else if (!res) res = rs_app_error(rouge_face_render(face, &e), &e, err);
    // The look is saved only once the render it belongs to has succeeded, and before the PNG, so a look
    // that cannot be written leaves no picture claiming it was.
    if (!res && cli->save_look) res = rs_app_error(rouge_face_save_look(face, cli->save_look, &e), &e, err);
    if (!res && still.pixels) res = rs_image_write_png(cli->output, &still, err);
    else if (!res) res = rs_app_error(rouge_face_write_png(face, cli->output, &e), &e, err);
    rs_image_free(&still);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return res;
}
