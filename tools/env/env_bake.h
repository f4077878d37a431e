// env_bake.h — rouge-env's work: from a latitude-longitude HDR map to an rs_env (src/formats/env.h,
// docs/env.md). Tools-time only, pure C (no OpenEXR: env_read.h reads the files).
//
// Does: resample maps by solid angle; find the dominant light (the most energetic compact region) and
// take it out as a directional light with a colour and an angular radius; turn the map about up; project
// SH9 irradiance; prefilter radiance with the Beckmann lobe; all of it at once in rs_env_bake.
// Does not: read or write files, or pick names and notes (rouge_env.c does).
//
//   rs_envmap src;                                  // from rs_envmap_read (env_read.h)
//   rs_env *env = NULL;
//   rs_env_light light;
//   if (rs_env_bake(&src, &(rs_env_bake_desc){.name = "studio", .key_yaw_deg = -35}, &env, &light, NULL,
//                   &err) == RS_OK)
//       rs_env_save(env, "studio.rse", &err);
#ifndef RS_ENV_BAKE_H
#define RS_ENV_BAKE_H

#include "core/core.h"
#include "formats/env.h"

// A latitude-longitude map in the env frame's convention (docs/env.md): w == 2 h, rows top (up) first,
// linear RGB radiance, 3 floats a texel.
typedef struct rs_envmap {
    int w, h;
    float *rgb;
} rs_envmap;

rs_result rs_envmap_alloc(rs_envmap *m, int w, int h, rs_error *err);  // zeroed
void rs_envmap_free(rs_envmap *m);
// Direction of texel (i, j)'s centre, and its exact solid angle: (2 pi / w) (cos theta_top - cos theta_bottom).
void rs_envmap_texel_dir(int w, int h, int i, int j, float d[3]);
double rs_envmap_texel_sr(int w, int h, int j);
// Area-weighted resample to width w (height w / 2), up or down, any ratio: every target texel is the
// solid-angle-weighted mean of the source over its footprint, so integrals (a light's power) are kept.
rs_result rs_envmap_resample(const rs_envmap *src, int w, rs_envmap *out, rs_error *err);
// Turns the map about up by di texel columns: what was at yaw phi is then at phi + di * 2 pi / w.
void rs_envmap_roll(rs_envmap *m, int di);
// Mirrors u -> 1 - u (x -> -x): see rs_env_bake.
void rs_envmap_mirror(rs_envmap *m);

// The dominant light as rs_env_find_light found it.
typedef struct rs_env_light {
    float dir[3];       // unit, towards the light (luminance-weighted mean of its excess)
    float color[3];     // (1/pi) integral of the excess over the region (rs_env.light_color)
    float angle;        // angular radius, radians: sqrt(2 <theta^2>) of the excess (a uniform disc's radius)
    float solid_angle;  // of the region, steradians
    float peak;         // luminance of the brightest texel
    float threshold;    // luminance a texel needed to join the region
    float surround[3];  // the level its texels were clamped to
    int texels;         // in the region
} rs_env_light;

// Finds the dominant light of m and removes it (each region texel loses its excess over the surrounding
// level, so nothing is counted twice): seed = the brightest texel of a 64 x 32 copy smoothed by a tent
// (~10 degrees: the brightest compact region), or `near` (a unit direction, NULL: none) when given;
// peak = the brightest texel within 9 (near: 20) degrees of the seed; region = the texels connected to the
// peak within 45 degrees that are brighter than sqrt(peak x median luminance of the map); surround = the
// median level of a ring a few degrees wide around the region. mask (w * h bytes, optional) gets the region.
rs_result rs_env_find_light(rs_envmap *m, const float *near, rs_env_light *out, uint8_t *mask, rs_error *err);

// SH9 of the map's irradiance / pi (rs_env.sh): sh[k] = (A_l / pi) sum L Y_k dw, A_l / pi = 1, 2/3, 1/4.
void rs_env_project_sh(const rs_envmap *m, float sh[9][3]);

// Beckmann P_H as the skin BRDF uses it: exp(-tan^2 a / m^2) / (m^2 cos^4 a), cos a = ndoth.
float rs_env_beckmann(float ndoth, float m);
// Prefilters src into lvl (its size and texels set) for roughness m: Lpref(R) = sum w L / sum w,
// w = P_H(R.h) max(R.l, 0) dw, h = normalize(l + R) (N = V = R). The source is first resampled to twice
// the level's width (at least 64, and a whole multiple of it), and the sum runs over the texels where the
// lobe is above 1e-5 of its peak.
rs_result rs_env_prefilter(const rs_envmap *src, rs_env_level *lvl, float m, rs_error *err);

#define RS_ENV_BAKE_LEVELS 6
#define RS_ENV_BAKE_WIDTH 256       // level 0 of the prefiltered chain
#define RS_ENV_BAKE_WORK_WIDTH 1024 // the map is reduced to this first: detection, SH and prefiltering run on it
extern const float rs_env_bake_level_m[RS_ENV_BAKE_LEVELS];

typedef struct rs_env_bake_desc {
    const char *name;    // rs_env.name
    float key_yaw_deg;   // the light is turned to this yaw (-35: front-left in a frontal view, the paper's lamp)
    bool keep_yaw;       // leave the map's yaw as it is
    bool light_near;     // look for the light near light_near_uv (u, v of the source image, 0..1)
    float light_near_uv[2];
} rs_env_bake_desc;

// The whole bake. src is a latlong in the usual panorama convention (seen from inside: image right is
// the right of a viewer facing the image centre); the env frame's u grows towards +x, the left of a face
// looking along +z, so the map is mirrored to keep the scene's handedness (text reads right in
// reflections). Then: reduce to RS_ENV_BAKE_WORK_WIDTH, find and remove the light, turn the map by whole
// columns so the light sits at key_yaw (within half a column), SH, prefilter. notes are left empty.
// work (optional) receives the turned work map without the light; mask (optional, work w * h) the region.
rs_result rs_env_bake(const rs_envmap *src, const rs_env_bake_desc *desc, rs_env **out, rs_env_light *light,
                      rs_envmap *work, uint8_t **mask, rs_error *err);

#endif
