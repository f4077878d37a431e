// env.h — a lighting environment (.rse file, docs/env.md): what the renderer needs of an HDR capture,
// precomputed by tools/env (rouge-env): SH irradiance, the dominant light, and the radiance prefiltered for
// a ladder of roughnesses, in the face frame.
//
// Does: hold an environment in memory; load and fully validate .rse files (magic, version, sizes, CRC,
// finite and in-range floats; claimed sizes checked before allocating); save them atomically; the SH
// evaluation, the equirect direction convention and the RGB9E5 codec, as the shaders use them.
// Does not: read EXR/HDR images (tools/env does, at tools time) or touch GL (render_env.c uploads).
//
//   rs_env *env = NULL;
//   if (rs_env_load("assets/env/studio.rse", &env, &err) != RS_OK) return fail(err.msg);
//   rs_render_set_env(renderer, env, &err);
//   rs_env_destroy(env);
#ifndef RS_ENV_H
#define RS_ENV_H

#include "core/core.h"

#define RS_ENV_MAX_LEVELS 8
#define RS_ENV_MAX_NOTES 4096
#define RS_ENV_MAX_WIDTH 4096   // level 0: width = 2 height

// One level of the prefiltered radiance: equirect, rows top (up) first, GL_RGB9_E5 bit layout (r bits 0-8,
// g 9-17, b 18-26, shared exponent 27-31, bias 15).
typedef struct rs_env_level {
    int width, height;
    uint32_t *rgb9e5;
} rs_env_level;

// Frame: the face frame, x = right (the subject's left, image right in a frontal view), y = up, z = forward
// (out of the face). Equirect texel (i, j) has its centre at u = (i + .5) / W, v = (j + .5) / H,
// phi = 2 pi (u - 0.5), theta = pi v, d = (sin theta sin phi, cos theta, sin theta cos phi): phi is a
// light's yaw, 90 deg - theta its pitch (render_view.c frame_dir).
typedef struct rs_env {
    char name[32];                     // "studio"
    char notes[RS_ENV_MAX_NOTES];      // source, author, licence, how it was made (shown by --help, README)
    // SH9 (real, l <= 2, Ramamoorthi & Hanrahan 2001 order) of the irradiance divided by pi with the dominant
    // light removed: E(n) = sum_k sh[k] Y_k(n) = (1/pi) integral L(w) max(n.w, 0) dw, so a uniform
    // environment of radiance 1 gives E = 1 (what a white Lambertian surface reflects).
    float sh[9][3];
    float light_dir[3];                // unit, towards the dominant light
    float light_color[3];              // (1/pi) integral of L over the light's region (linear RGB)
    float light_angle;                 // angular radius of that region, radians
    int level_count;                   // 1 .. RS_ENV_MAX_LEVELS
    float level_m[RS_ENV_MAX_LEVELS];  // Beckmann roughness level k was prefiltered with, increasing
    rs_env_level levels[RS_ENV_MAX_LEVELS];  // level k is (W >> k) x (H >> k): a partial mip chain
} rs_env;

rs_result rs_env_load(const char *path, rs_env **out, rs_error *err);
rs_result rs_env_load_memory(const void *data, size_t len, rs_env **out, rs_error *err);
// Validates (as the loader does) and writes atomically.
rs_result rs_env_save(const rs_env *env, const char *path, rs_error *err);
rs_result rs_env_save_memory(const rs_env *env, void **out_data, size_t *out_len, rs_error *err);
// A new environment with `levels` levels, level 0 width x (width / 2), texels zero (for the tool).
rs_result rs_env_create(int width, int levels, rs_env **out, rs_error *err);
void rs_env_destroy(rs_env *env);

// E(n) from the SH (clamped at 0), linear RGB; returns its luminance. The shaders' env_light.glsl mirror.
float rs_env_sh_irradiance(const rs_env *env, const float n[3], float out_rgb[3]);
// The 9 basis functions at unit direction d (the order of rs_env.sh).
void rs_env_sh_basis(const float d[3], float y[9]);
void rs_env_dir_to_uv(const float d[3], float uv[2]);
void rs_env_uv_to_dir(const float uv[2], float d[3]);
uint32_t rs_rgb9e5_pack(const float rgb[3]);
void rs_rgb9e5_unpack(uint32_t v, float rgb[3]);

#endif
