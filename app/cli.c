// cli.c — see cli.h.
#include "cli.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef enum { OPT_FLOAT, OPT_INT, OPT_SIZE, OPT_RGB, OPT_PAN, OPT_ENUM, OPT_FLAG, OPT_PATH } opt_kind;

typedef struct opt {
    const char *name;
    opt_kind kind;
    const char *arg;   // shown in help
    const char *help;
    float lo, hi;      // range for numbers
} opt;

static const char *const mode_names[RS_MODE_COUNT] = {"full", "albedo", "diffuse", "specular", "normals",
                                                      "regions", "shadow", "lod", "irradiance"};

static const opt opts[] = {
    {"-o", OPT_PATH, "PNG", "output image (render); written atomically", 0, 0},
    {"--size", OPT_SIZE, "WxH", "image size in pixels (default 512x512; 16..8192)", 16, RS_VIEW_MAX_SIZE_PX},
    {"--supersample", OPT_INT, "N", "render: draw N x N samples per pixel and average them (1..4; smooth edges for stills)", 1, 4},
    {"--yaw", OPT_FLOAT, "DEG", "camera yaw around the face (0 = frontal, + = towards the subject's left)", -360, 360},
    {"--pitch", OPT_FLOAT, "DEG", "camera pitch (+ = from above)", -89, 89},
    {"--zoom", OPT_FLOAT, "Z", "1 = face fills the view; 2 = twice as close", 0.1f, 20},
    {"--pan", OPT_PAN, "X,Y", "shift the picture by X,Y view heights (+x right, +y down; -2..2)", -RS_VIEW_PAN_MAX, RS_VIEW_PAN_MAX},
    {"--target", OPT_PATH, "REGION", "centre and zoom on a region of the face (lips, nose, cheek, forehead, ...)", 0, 0},
    {"--fov", OPT_FLOAT, "DEG", "vertical field of view (default 30; 1..150)", RS_VIEW_FOV_MIN_DEG, RS_VIEW_FOV_MAX_DEG},
    {"--env", OPT_PATH, "NAME", "lighting: " RS_ENV_NAME_LIST " (default " RS_ENV_DEFAULT "), or a .rse file", 0, 0},
    {"--env-rotate", OPT_FLOAT, "DEG", "turn the environment about the face's up axis (+ moves its light like +yaw)", -360, 360},
    {"--light-yaw", OPT_FLOAT, "DEG", "key light direction, yaw (--env paper)", -360, 360},
    {"--light-pitch", OPT_FLOAT, "DEG", "key light direction, pitch (+ = from above; --env paper)", -90, 90},
    {"--light-color", OPT_RGB, "R,G,B", "key light colour, linear 0..10", 0, 10},
    {"--light-intensity", OPT_FLOAT, "X", "key light intensity (default 1)", 0, 100},
    {"--fill-yaw", OPT_FLOAT, "DEG", "fill light yaw (enables the fill light; --env paper)", -360, 360},
    {"--fill-pitch", OPT_FLOAT, "DEG", "fill light pitch", -90, 90},
    {"--fill-intensity", OPT_FLOAT, "X", "fill light intensity (0 = off)", 0, 100},
    {"--mode", OPT_ENUM, "MODE", "full|albedo|diffuse|specular|normals|regions|shadow|lod|irradiance", 0, 0},
    {"--pipeline", OPT_ENUM, "P", "reference|mobile (render default: reference; viewer default: mobile)", 0, 0},
    {"--composite", OPT_ENUM, "C", "default (paper with --env paper, else physical) | paper: F = A(D+S) | physical: F = A D + S", 0, 0},
    {"--exposure", OPT_FLOAT, "X", "linear exposure before the filmic curve and sRGB (default 1)", 0.01f, 100},
    {"--background", OPT_RGB, "R,G,B", "background colour, sRGB 0..1", 0, 1},
    {"--no-shadows", OPT_FLAG, NULL, "disable the shadow map", 0, 0},
    {"--specular-scale", OPT_FLOAT, "X", "multiply every rho_s (1 = measured skin, physical strength; 2 = oily)", 0.01f, 10},
    {"--ambient", OPT_FLOAT, "X", "uniform sky light added to the irradiance (--env paper; default 0.05)", 0, 10},
    {"--max-splats", OPT_INT, "N", "draw at most N splats (an LOD prefix)", 1, 2e9f},
    {"--kernels", OPT_INT, "K", "mobile pipeline: number of Gaussians (2..4, default 3)", 2, 4},
    {"--lod-density", OPT_FLOAT, "D", "mobile pipeline: visible splats per face pixel (default 0.3)", 0.01f, 1000},
    {"--prim", OPT_ENUM, "P", "auto|points|quads: splat primitive", 0, 0},
    {"--strokes", OPT_PATH, "FILE", "replay a stroke file (painting) before rendering", 0, 0},
    {"--look", OPT_PATH, "FILE", "apply a saved look (makeup layer)", 0, 0},
    {"--save-look", OPT_PATH, "FILE", "save the look after replaying strokes", 0, 0},
    {"--looks", OPT_PATH, "DIR", "viewer: the look library (default $XDG_DATA_HOME/rouge/looks)", 0, 0},
    {"--record", OPT_PATH, "FILE", "viewer: record strokes to FILE", 0, 0},
    {"--fullscreen", OPT_FLAG, NULL, "viewer: start full-screen", 0, 0},
    {"--events", OPT_PATH, "FILE", "viewer: replay an event script (format: see 'event scripts' below)", 0, 0},
    {"--bench-orbit", OPT_INT, "N", "viewer: orbit for N frames, print the median frame time, exit", 1, 100000},
};

void rs_cli_print_options(FILE *f)
{
    for (size_t i = 0; i < RS_COUNT_OF(opts); i++) {
        char left[64];
        snprintf(left, sizeof left, "%s%s%s", opts[i].name, opts[i].arg ? " " : "", opts[i].arg ? opts[i].arg : "");
        fprintf(f, "  %-24s %s\n", left, opts[i].help);
    }
}

static rs_result parse_enum(const char *name, const char *v, rs_cli *c, rs_error *err)
{
    if (!strcmp(name, "--mode")) {
        for (int i = 0; i < RS_MODE_COUNT; i++)
            if (!strcmp(v, mode_names[i])) return c->view.mode = (rs_render_mode)i, RS_OK;
    } else if (!strcmp(name, "--pipeline")) {
        c->pipeline_set = true;
        if (!strcmp(v, "reference")) return c->view.pipeline = RS_PIPELINE_REFERENCE, RS_OK;
        if (!strcmp(v, "mobile")) return c->view.pipeline = RS_PIPELINE_MOBILE, RS_OK;
    } else if (!strcmp(name, "--composite")) {
        if (!strcmp(v, "default")) return c->view.composite = RS_COMPOSITE_DEFAULT, RS_OK;
        if (!strcmp(v, "paper")) return c->view.composite = RS_COMPOSITE_PAPER, RS_OK;
        if (!strcmp(v, "physical")) return c->view.composite = RS_COMPOSITE_PHYSICAL, RS_OK;
    } else if (!strcmp(name, "--prim")) {
        if (!strcmp(v, "auto")) return c->view.prim = RS_PRIM_AUTO, RS_OK;
        if (!strcmp(v, "points")) return c->view.prim = RS_PRIM_POINTS, RS_OK;
        if (!strcmp(v, "quads")) return c->view.prim = RS_PRIM_QUADS, RS_OK;
    }
    return rs_fail(err, RS_ERR_ARG, "%s: unknown value '%s' (see --help)", name, v);
}

static rs_result apply(const opt *o, const char *v, rs_cli *c, rs_error *err)
{
    rs_view *w = &c->view;
    float f = 0;
    if (o->kind == OPT_FLOAT || o->kind == OPT_INT) {
        double d;
        if (!rs_parse_number(v, -FLT_MAX, FLT_MAX, &d))
            return rs_fail(err, RS_ERR_ARG, "%s: expected a number, got '%s'", o->name, v);
        f = (float)d;
        if (f < o->lo || f > o->hi)
            return rs_fail(err, RS_ERR_ARG, "%s: %s is out of range %g..%g", o->name, v, o->lo, o->hi);
        if (o->kind == OPT_INT && f != floorf(f))
            return rs_fail(err, RS_ERR_ARG, "%s: expected a whole number, got '%s'", o->name, v);
    }
    const char *n = o->name;
    if (o->kind == OPT_ENUM) return parse_enum(n, v, c, err);
    if (o->kind == OPT_SIZE) {
        // Digits only, each side at most 5 of them: sscanf's %d wraps 4294967312 to 16.
        long wd = 0, ht = 0;
        const char *p = v;
        int nw = 0, nh = 0;
        for (; *p >= '0' && *p <= '9' && nw < 6; p++, nw++) wd = wd * 10 + (*p - '0');
        bool sep = *p == 'x' || *p == 'X';
        if (sep) p++;
        for (; *p >= '0' && *p <= '9' && nh < 6; p++, nh++) ht = ht * 10 + (*p - '0');
        if (!sep || *p || nw == 0 || nh == 0 || nw > 5 || nh > 5 || wd < o->lo || ht < o->lo || wd > o->hi ||
            ht > o->hi)
            return rs_fail(err, RS_ERR_ARG, "--size: expected WxH with 16..8192 pixels each, got '%s'", v);
        w->width = (int)wd, w->height = (int)ht;
        c->size_set = true;
        return RS_OK;
    }
    if (o->kind == OPT_PAN) {
        double p[2];
        if (!rs_parse_list(v, ',', 2, o->lo, o->hi, p))
            return rs_fail(err, RS_ERR_ARG, "%s: expected X,Y within %g..%g, got '%s'", n, o->lo, o->hi, v);
        w->pan[0] = (float)p[0], w->pan[1] = (float)p[1];
        c->pan_set = true;
        return RS_OK;
    }
    if (o->kind == OPT_RGB) {
        double d[3];
        if (!rs_parse_list(v, ',', 3, -FLT_MAX, FLT_MAX, d))
            return rs_fail(err, RS_ERR_ARG, "%s: expected R,G,B, got '%s'", n, v);
        float rgb[3];
        for (int i = 0; i < 3; i++) {
            if (d[i] < o->lo || d[i] > o->hi)
                return rs_fail(err, RS_ERR_ARG, "%s: components must be %g..%g, got '%s'", n, o->lo, o->hi, v);
            rgb[i] = (float)d[i];
        }
        memcpy(!strcmp(n, "--background") ? w->background : w->key.color, rgb, sizeof rgb);
        return RS_OK;
    }
    if (!strcmp(n, "-o")) c->output = v;
    else if (!strcmp(n, "--yaw")) w->yaw_deg = f, c->view_set[0] = true;
    else if (!strcmp(n, "--pitch")) w->pitch_deg = f, c->view_set[1] = true;
    else if (!strcmp(n, "--zoom")) w->zoom = f, c->view_set[2] = true;
    else if (!strcmp(n, "--fov")) w->fov_deg = f, c->view_set[3] = true;
    else if (!strcmp(n, "--light-yaw")) w->key.yaw_deg = f;
    else if (!strcmp(n, "--light-pitch")) w->key.pitch_deg = f;
    else if (!strcmp(n, "--light-intensity")) w->key.intensity = f;
    else if (!strcmp(n, "--fill-yaw")) w->fill.yaw_deg = f, w->fill.intensity = w->fill.intensity > 0 ? w->fill.intensity : 0.35f;
    else if (!strcmp(n, "--fill-pitch")) w->fill.pitch_deg = f;
    else if (!strcmp(n, "--fill-intensity")) w->fill.intensity = f;
    else if (!strcmp(n, "--exposure")) w->exposure = f;
    else if (!strcmp(n, "--no-shadows")) w->no_shadows = true;
    else if (!strcmp(n, "--specular-scale")) w->rho_s_scale = f;
    else if (!strcmp(n, "--ambient")) w->ambient = f;
    else if (!strcmp(n, "--max-splats")) w->max_splats = (uint32_t)f;
    else if (!strcmp(n, "--kernels")) w->kernel_count = (int)f;
    else if (!strcmp(n, "--lod-density")) w->lod_density = f;
    else if (!strcmp(n, "--strokes")) c->strokes = v;
    else if (!strcmp(n, "--look")) c->look = v;
    else if (!strcmp(n, "--target")) c->target = v;
    else if (!strcmp(n, "--env")) c->env = v;
    else if (!strcmp(n, "--env-rotate")) w->env_rotate_deg = f;
    else if (!strcmp(n, "--save-look")) c->save_look = v;
    else if (!strcmp(n, "--record")) c->record = v;
    else if (!strcmp(n, "--looks")) c->looks = v;
    else if (!strcmp(n, "--fullscreen")) c->fullscreen = true;
    else if (!strcmp(n, "--events")) c->events = v;
    else if (!strcmp(n, "--bench-orbit")) c->bench_orbit = (int)f;
    else if (!strcmp(n, "--supersample")) c->supersample = (int)f;
    return RS_OK;
}

rs_result rs_cli_parse(int argc, char **argv, bool allow_output, rs_cli *out, rs_error *err)
{
    rs_cli c = {.view = rs_view_defaults()};
    bool seen[RS_COUNT_OF(opts)] = {0};
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            c.help = true;
            continue;
        }
        if (a[0] != '-' || a[1] == 0) {
            if (c.face) return rs_fail(err, RS_ERR_ARG, "unexpected argument '%s' (one face file only)", a);
            c.face = a;
            continue;
        }
        const opt *o = NULL;
        for (size_t k = 0; k < RS_COUNT_OF(opts); k++)
            if (!strcmp(a, opts[k].name)) o = &opts[k];
        if (!o) return rs_fail(err, RS_ERR_ARG, "unknown option '%s' (see --help)", a);
        // A second -o (or any option) silently winning hides a typo; say so instead.
        if (seen[o - opts]) return rs_fail(err, RS_ERR_ARG, "%s given twice", a);
        seen[o - opts] = true;
        if ((!strcmp(a, "-o") || !strcmp(a, "--supersample")) && !allow_output)
            return rs_fail(err, RS_ERR_ARG, "%s is only for 'rouge render'", a);
        const char *v = NULL;
        if (o->kind != OPT_FLAG) {
            if (i + 1 >= argc) return rs_fail(err, RS_ERR_ARG, "%s needs a value (%s)", a, o->arg);
            v = argv[++i];
        }
        rs_result r = apply(o, v, &c, err);
        if (r) return r;
    }
    *out = c;
    return RS_OK;
}
