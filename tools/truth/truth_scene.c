// truth_scene.c — rouge-truth-scene: what the path-traced reference (tools/truth/, `make truth`) needs from
// rouge, written for Blender (tools/truth/render.py): rouge's own camera for each view, each bundled
// environment's radiance turned and scaled exactly as rouge sees it, the region table, the skin profile's
// scattering radius, and the splats' regions. Tools-time only.
//
//   rouge-truth-scene FACE.rsf ENV_DIR EXR_DIR OUT_DIR SIZE
//
// Environments: the bundled .rse files are made by rouge-env from blender-data's HDRIs (assets/env/README.md):
// reduced to 1024 x 512, mirrored into the env frame, turned by whole columns so the dominant light sits at
// yaw -35 deg. Here the same steps run on the same source, keeping the light in the map (the .rse takes it
// out as a separate light; a path tracer wants it where it was), and the result is checked against the
// bundled file's light direction. The map is then scaled by rouge's exposure normalisation (render_env.c:
// the mean irradiance of the SH + light over the front-facing normals is 0.5), so the reference is in the
// same units as rouge's linear frame before its tone curve.
//
// Output (OUT_DIR): scene.json; env_NAME.hdr (Radiance RGBE, W x H, rows from up, the env frame's
// convention of docs/env.md); splats.f32 (x, y, z, region per splat, float32).
#define _POSIX_C_SOURCE 200809L
#include "core/core.h"
#include "formats/env.h"
#include "gl/gl.h"
#include "render/profile.h"
#include "rouge.h"
#include "splat/splat.h"

#include "env/env_bake.h"
#include "env/env_read.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define COUNT(a) (sizeof(a) / sizeof(a)[0])
// The views the reference renders: name, camera yaw and pitch (degrees, rouge_view's orbit camera).
static const struct {
    const char *name;
    float yaw, pitch;
} views[] = {{"front", 0.0f, 0.0f}, {"threequarter", 35.0f, 0.0f}};
// Bundled environment -> its source in blender-data (the Makefile's `envs` target).
static const struct {
    const char *name, *exr;
} envs[] = {{"studio", "studio.exr"}, {"daylight", "city.exr"}, {"office", "interior.exr"}, {"sunset", "sunset.exr"}};

// Mean luminance of the SH + light irradiance over the front half-space of normals: render_env.c's
// front_irradiance, the same 256-point spiral (rouge's exposure normalisation divides by it).
static double front_irradiance(const rs_env *env)
{
    const int n = 256;
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        float z = ((float)i + 0.5f) / (float)n;
        float s = sqrtf(1.0f - z * z), phi = 2.39996323f * (float)i;
        float d[3] = {s * cosf(phi), s * sinf(phi), z}, e[3];
        rs_env_sh_irradiance(env, d, e);
        float nl = RS_MAX(d[0] * env->light_dir[0] + d[1] * env->light_dir[1] + d[2] * env->light_dir[2], 0.0f);
        for (int c = 0; c < 3; c++) e[c] += env->light_color[c] * nl;
        sum += 0.2126f * e[0] + 0.7152f * e[1] + 0.0722f * e[2];
    }
    return sum / n;
}

static rs_result write_file(const char *path, const void *data, size_t len, rs_error *err)
{
    FILE *f = fopen(path, "wb");
    if (!f) return rs_fail(err, RS_ERR_IO, "%s: cannot write", path);
    size_t w = fwrite(data, 1, len, f);
    if (fclose(f) != 0 || w != len) return rs_fail(err, RS_ERR_IO, "%s: write failed", path);
    return RS_OK;
}

// Radiance RGBE, flat (no run-length), rows from the top: Blender reads it as scene-linear radiance as is.
static rs_result write_hdr(const char *path, const rs_envmap *m, rs_error *err)
{
    FILE *f = fopen(path, "wb");
    if (!f) return rs_fail(err, RS_ERR_IO, "%s: cannot write", path);
    fprintf(f, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n", m->h, m->w);
    for (size_t i = 0; i < (size_t)m->w * m->h; i++) {
        const float *c = m->rgb + i * 3;
        float v = RS_MAX(c[0], RS_MAX(c[1], c[2]));
        uint8_t e[4] = {0, 0, 0, 0};
        if (v > 1e-32f) {
            int ex;
            float s = frexpf(v, &ex) * 256.0f / v;
            for (int k = 0; k < 3; k++) e[k] = (uint8_t)(RS_MAX(c[k], 0.0f) * s);
            e[3] = (uint8_t)(ex + 128);
        }
        fwrite(e, 1, 4, f);
    }
    if (fclose(f) != 0) return rs_fail(err, RS_ERR_IO, "%s: write failed", path);
    return RS_OK;
}

// The environment `k` as rouge sees it: source map reduced, mirrored, turned like rouge-env's bake, scaled
// like rs_render_set_env. Writes env_NAME.f32, returns the scale and the width in *scale, *w.
static rs_result make_env(int k, const char *env_dir, const char *exr_dir, const char *out_dir, double *scale,
                          int *w, rs_error *err)
{
    char path[1024];
    rs_env *bundled = NULL;
    rs_envmap src = {0}, work = {0}, probe = {0};
    snprintf(path, sizeof path, "%s/%s.rse", env_dir, envs[k].name);
    rs_result r = rs_env_load(path, &bundled, err);
    if (r != RS_OK) return r;
    snprintf(path, sizeof path, "%s/%s", exr_dir, envs[k].exr);
    r = rs_envmap_read(path, &src, err);
    if (r == RS_OK) r = rs_envmap_resample(&src, RS_MIN(src.w, RS_ENV_BAKE_WORK_WIDTH), &work, err);
    if (r == RS_OK) {
        rs_envmap_mirror(&work);
        r = rs_envmap_alloc(&probe, work.w, work.h, err);
    }
    rs_env_light L;
    if (r == RS_OK) {
        // The light is found on a copy: the finder takes it out of the map it is given.
        memcpy(probe.rgb, work.rgb, sizeof(float) * 3 * (size_t)work.w * work.h);
        r = rs_env_find_light(&probe, NULL, &L, NULL, err);
    }
    if (r == RS_OK) {
        // rs_env_bake's turn: whole columns, the light to yaw -35 deg.
        double col = 2 * PI / work.w, phi = atan2(L.dir[0], L.dir[2]);
        int di = (int)lround((-35.0 * PI / 180 - phi) / col);
        rs_envmap_roll(&work, di);
        double phi2 = phi + di * col, s = hypot(L.dir[0], L.dir[2]);
        float d[3] = {(float)(s * sin(phi2)), L.dir[1], (float)(s * cos(phi2))};
        float dot = d[0] * bundled->light_dir[0] + d[1] * bundled->light_dir[1] + d[2] * bundled->light_dir[2];
        if (dot < 0.99999f)
            r = rs_fail(err, RS_ERR_FORMAT, "%s: its light is %.3f deg from %s/%s.rse's: that file was not made "
                        "from this source (make envs)", path, acos(RS_MIN(dot, 1.0f)) * 180 / PI, env_dir,
                        envs[k].name);
    }
    if (r == RS_OK) {
        double front = front_irradiance(bundled);
        *scale = front > 1e-6 ? 0.5 / front : 1.0;
        *w = work.w;
        size_t n = (size_t)work.w * work.h * 3;
        for (size_t i = 0; i < n; i++) work.rgb[i] = (float)(work.rgb[i] * *scale);
        snprintf(path, sizeof path, "%s/env_%s.hdr", out_dir, envs[k].name);
        r = write_hdr(path, &work, err);
    }
    rs_env_destroy(bundled);
    rs_envmap_free(&src);
    rs_envmap_free(&work);
    rs_envmap_free(&probe);
    return r;
}

static void put_floats(FILE *f, const float *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) fprintf(f, "%s%.9g", i ? ", " : "", v[i]);
    fputc(']', f);
}

// rouge's camera for each view at size x size, from the library itself (rouge_face_camera_matrices).
static rs_result cameras(const char *face_path, int size, float view_m[][16], float proj_m[][16], rs_error *err)
{
    rs_gl_context *gl = NULL;
    rs_result r = rs_gl_create(&(rs_gl_desc){0}, &gl, err);
    if (r != RS_OK) return r;
    rouge_face *face = NULL;
    rouge_error e = {0};
    if (rouge_face_create(&(rouge_face_desc){.path = face_path}, &face, &e) != ROUGE_OK)
        r = rs_fail(err, RS_ERR_IO, "%s", e.msg);
    for (size_t i = 0; r == RS_OK && i < COUNT(views); i++) {
        rouge_view v = {.width = size, .height = size, .yaw_deg = views[i].yaw, .pitch_deg = views[i].pitch,
                        .pipeline = ROUGE_PIPELINE_REFERENCE};
        if (rouge_face_set_view(face, &v, &e) != ROUGE_OK ||
            rouge_face_camera_matrices(face, view_m[i], proj_m[i], &e) != ROUGE_OK)
            r = rs_fail(err, RS_ERR_ARG, "%s", e.msg);
    }
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return r;
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: rouge-truth-scene FACE.rsf ENV_DIR EXR_DIR OUT_DIR SIZE\n");
        return 2;
    }
    const char *face_path = argv[1], *env_dir = argv[2], *exr_dir = argv[3], *out_dir = argv[4];
    int size = atoi(argv[5]);
    rs_error err = {0};
    rs_splat_cloud *cloud = NULL;
    float view_m[COUNT(views)][16], proj_m[COUNT(views)][16];
    double scale[COUNT(envs)];
    int env_w[COUNT(envs)];
    float *sp = NULL;
    FILE *f = NULL;
    char path[1024];
    rs_result r = size >= 16 && size <= 4096 ? RS_OK : rs_fail(&err, RS_ERR_ARG, "size %s: 16..4096", argv[5]);
    if (r == RS_OK) r = rs_splat_load(face_path, &cloud, &err);
    if (r == RS_OK) r = cameras(face_path, size, view_m, proj_m, &err);
    for (size_t k = 0; r == RS_OK && k < COUNT(envs); k++)
        r = make_env((int)k, env_dir, exr_dir, out_dir, &scale[k], &env_w[k], &err);
    if (r == RS_OK) {
        const rs_splat_header *h = &cloud->hdr;
        sp = malloc(sizeof(float) * 4 * h->count);
        if (!sp) r = rs_fail(&err, RS_ERR_NOMEM, "out of memory");
        for (uint32_t i = 0; sp && i < h->count; i++) {
            rs_splat s;
            rs_splat_get(cloud, i, &s);
            memcpy(sp + 4 * i, cloud->pos[i], sizeof(float) * 3);
            sp[4 * i + 3] = (float)s.region;
        }
        snprintf(path, sizeof path, "%s/splats.f32", out_dir);
        if (r == RS_OK) r = write_file(path, sp, sizeof(float) * 4 * h->count, &err);
    }
    if (r == RS_OK) {
        snprintf(path, sizeof path, "%s/scene.json", out_dir);
        f = fopen(path, "w");
        if (!f) r = rs_fail(&err, RS_ERR_IO, "%s: cannot write", path);
    }
    if (r == RS_OK) {
        const rs_splat_header *h = &cloud->hdr;
        // What the skin profile carries into a shadow per channel: behind a straight shadow edge on a flat
        // surface, the integral of the lit fraction over the shadow side, mm. A 2D Gaussian of variance v
        // gives sqrt(v / (2 pi)) (half the mean |x| of its line spread); the profile (weights summing to 1
        // per channel), their weighted sum. sss_calibrate.py finds the Cycles subsurface radius that carries
        // as much (issue 22).
        rs_profile p = rs_profile_deon();
        float edge[3] = {0};
        for (int i = 0; i < p.count; i++)
            for (int c = 0; c < 3; c++) edge[c] += p.weight[i][c] * sqrtf(p.variance_mm2[i] / (2.0f * (float)PI));
        fprintf(f, "{\n  \"size\": %d,\n  \"mm_per_unit\": %.9g,\n  \"sss_edge_mm\": ", size, h->mm_per_unit);
        put_floats(f, edge, 3);
        fprintf(f, ",\n  \"centre\": ");
        put_floats(f, h->centre, 3);
        fprintf(f, ",\n  \"forward\": ");
        put_floats(f, h->forward, 3);
        fprintf(f, ",\n  \"up\": ");
        put_floats(f, h->up, 3);
        fprintf(f, ",\n  \"face_height\": %.9g,\n  \"regions\": [", h->face_height);
        for (uint32_t k = 0; k < h->region_count; k++)
            fprintf(f, "%s\n    {\"name\": \"%s\", \"m\": %.9g, \"rho_s\": %.9g}", k ? "," : "", h->regions[k].name,
                    h->regions[k].m, h->regions[k].rho_s);
        fprintf(f, "\n  ],\n  \"views\": [");
        for (size_t i = 0; i < COUNT(views); i++) {
            fprintf(f, "%s\n    {\"name\": \"%s\", \"yaw\": %g, \"pitch\": %g, \"view\": ", i ? "," : "", views[i].name,
                    views[i].yaw, views[i].pitch);
            put_floats(f, view_m[i], 16);
            fprintf(f, ", \"proj\": ");
            put_floats(f, proj_m[i], 16);
            fputc('}', f);
        }
        fprintf(f, "\n  ],\n  \"envs\": [");
        for (size_t k = 0; k < COUNT(envs); k++)
            fprintf(f, "%s\n    {\"name\": \"%s\", \"source\": \"%s\", \"map\": \"env_%s.hdr\", \"width\": %d, "
                    "\"scale\": %.9g}", k ? "," : "", envs[k].name, envs[k].exr, envs[k].name, env_w[k], scale[k]);
        fprintf(f, "\n  ]\n}\n");
        if (fclose(f) != 0) r = rs_fail(&err, RS_ERR_IO, "%s: write failed", path);
    }
    free(sp);
    rs_splat_destroy(cloud);
    if (r != RS_OK) {
        fprintf(stderr, "rouge-truth-scene: %s\n", err.msg);
        return 1;
    }
    return 0;
}
