// test_env_specular.c — the environment's light on a white sphere against exact integrals over the SOURCE
// captures (blender-data's studiolights, which assets/env/*.rse are baked from; skipped when absent):
// - specular: rouge's rendered specular (the key light as an area light + the prefiltered map through the
//   split sum) per N.V band against the Kelemen/Szirmay-Kalos lobe integrated texel by texel over the
//   capture, turned and normalised as the renderer does (issue 22: within 20 % at every angle), in the
//   reference pipeline and in the mobile one (whose grid of taps is lighter: env_light.glsl);
// - diffuse: the .rse's SH9 + its light(s) against the brute-force cosine integral of the capture, for
//   normals all over the sphere.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "env/env_bake.h"
#include "env/env_read.h"
#include "formats/env.h"
#include "render/render_kit.h"  // the renderer's exposure normalisation (r->env.scale)

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PI 3.14159265358979323846
#define SIZE 384
#define MM_PER_UNIT 47.0f
#define SPHERE_MM 20.0f
#define SKIN_M 0.265f      // the default "other" region's roughness (Weyrich's mean)
#define EXACT_WIDTH 256    // the capture is integrated at this width (1.4 deg texels, power kept; the lobe is ~15 deg)
#define BANDS 5
#define PER_BAND 80        // pixels integrated exactly per band

static rs_gl_context *gl;

static const struct {
    const char *name, *source;
} envs[] = {{"studio", "studio"}, {"daylight", "city"}, {"office", "interior"}, {"sunset", "sunset"}};
#define ENV_COUNT 4
#define WORLD "/usr/share/blender/datafiles/studiolights/world/"

// N.V bands, from facing the camera to grazing.
static const float band_lo[BANDS] = {0.8f, 0.6f, 0.4f, 0.25f, 0.12f};
static const float band_hi[BANDS] = {1.0f, 0.8f, 0.6f, 0.4f, 0.25f};

// A white sphere of radius SPHERE_MM (Fibonacci points about 0.62 mm apart, the head's spacing), one
// region with roughness m and the rho_s whose lobe is the physical one.
static rs_splat_cloud *make_sphere(float m)
{
    int k = (int)(4.0f * 3.14159f * SPHERE_MM * SPHERE_MM / (0.62f * 0.62f));
    rs_splat *s = calloc((size_t)k + 8, sizeof *s);
    if (!s) return NULL;
    for (int i = 0; i < k; i++) {
        float z = 1.0f - (2.0f * i + 1.0f) / k, r = sqrtf(1.0f - z * z), phi = 2.39996323f * i;
        float d[3] = {r * cosf(phi), r * sinf(phi), z};
        for (int c = 0; c < 3; c++) s[i].pos[c] = SPHERE_MM * d[c] / MM_PER_UNIT, s[i].normal[c] = d[c];
        s[i].radius = 0.95f / MM_PER_UNIT;
        s[i].rgb[0] = s[i].rgb[1] = s[i].rgb[2] = 255;
    }
    // Eight tiny splats at the corners of a 200 mm cube, out of the camera's view: the shadow map is fitted
    // to the cloud's bounding sphere, and on the bare 20 mm sphere its 4096^2 texels were 0.01 mm, each
    // disk 60k texels (seconds per environment on a software GPU); now 0.08 mm, finer than on a head
    // (0.14 mm), and the sphere's self-shadowing at the terminator is drawn as on a face.
    for (int i = 0; i < 8; i++) {
        rs_splat *c = &s[k + i];
        c->pos[0] = (i & 1 ? 100.0f : -100.0f) / MM_PER_UNIT, c->pos[1] = (i & 2 ? 100.0f : -100.0f) / MM_PER_UNIT;
        c->pos[2] = (i & 4 ? 100.0f : -100.0f) / MM_PER_UNIT;
        c->normal[2] = 1.0f;
        c->radius = 0.3f / MM_PER_UNIT;
        c->rgb[0] = c->rgb[1] = c->rgb[2] = 255;
    }
    k += 8;
    rs_splat_header h = {.mm_per_unit = MM_PER_UNIT, .forward = {0, 0, 1}, .up = {0, 1, 0},
                         .face_height = 2.0f * SPHERE_MM / MM_PER_UNIT, .region_count = RS_REGION_BUILTIN_COUNT};
    rs_splat_default_regions(&h);
    for (int r = 0; r < RS_REGION_BUILTIN_COUNT; r++) h.regions[r].m = m, h.regions[r].rho_s = RS_RHO_S_PHYSICAL;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    if (rs_splat_create(s, (uint32_t)k, &h, &c, &err) != RS_OK) printf("# sphere: %s\n", err.msg);
    free(s);
    return c;
}

// The capture as the bake sees it (mirrored, reduced to the work width, turned by the same whole columns
// so its light sits at the key yaw), light included, then reduced to EXACT_WIDTH. light_dir gets the
// light rs_env_find_light finds in it (turned).
static bool turned_source(const char *path, rs_envmap *out, rs_envmap *rest, float light_dir[3])
{
    rs_envmap src = {0}, work = {0}, probe = {0};
    rs_error err = {0};
    bool ok = RS_CHECK(rs_envmap_read(path, &src, &err) == RS_OK, "%s", err.msg) &&
              RS_CHECK(rs_envmap_resample(&src, RS_MIN(src.w, RS_ENV_BAKE_WORK_WIDTH), &work, &err) == RS_OK, "%s",
                       err.msg);
    rs_envmap_free(&src);
    if (ok) {
        rs_envmap_mirror(&work);
        ok = RS_CHECK(rs_envmap_alloc(&probe, work.w, work.h, &err) == RS_OK, "%s", err.msg);
    }
    rs_env_light L;
    if (ok) {
        memcpy(probe.rgb, work.rgb, sizeof(float) * 3 * (size_t)work.w * work.h);
        ok = RS_CHECK(rs_env_find_light(&probe, NULL, &L, NULL, &err) == RS_OK, "%s", err.msg);
    }
    if (ok) {
        double col = 2 * PI / work.w, phi = atan2(L.dir[0], L.dir[2]);
        int di = (int)lround((-35.0 * PI / 180 - phi) / col);
        rs_envmap_roll(&work, di);
        rs_envmap_roll(&probe, di);
        double s = hypot(L.dir[0], L.dir[2]), phi2 = phi + di * col;
        light_dir[0] = (float)(s * sin(phi2)), light_dir[1] = L.dir[1], light_dir[2] = (float)(s * cos(phi2));
        ok = RS_CHECK(rs_envmap_resample(&work, EXACT_WIDTH, out, &err) == RS_OK, "%s", err.msg) &&
             RS_CHECK(rs_envmap_resample(&probe, EXACT_WIDTH, rest, &err) == RS_OK, "%s", err.msg);
    }
    rs_envmap_free(&probe);
    rs_envmap_free(&work);
    return ok;
}

static double dot3(const float *a, const float *b) { return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2]; }

static double beckmann_lambda(double c, double m)
{
    double a = c / (m * sqrt(fmax(1 - c * c, 1e-8)));
    return a >= 1.6 ? 0 : (1 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

// The lobe as skin_brdf.glsl's rs_ksk_lobe: P_H F G / (4 N.V), Schlick F0, Smith's height-correlated G.
static double ksk(const float N[3], const float L[3], const float V[3], double m, double f0)
{
    double nl = dot3(N, L), nv = fmax(dot3(N, V), 1e-3);
    if (nl <= 0) return 0;
    double h[3] = {L[0] + V[0], L[1] + V[1], L[2] + V[2]};
    double hh = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
    if (hh < 1e-12) return 0;
    double inv = 1 / sqrt(hh);
    double nh = (N[0] * h[0] + N[1] * h[1] + N[2] * h[2]) * inv;
    if (nh <= 0) return 0;
    double vh = (V[0] * h[0] + V[1] * h[1] + V[2] * h[2]) * inv;
    double c2 = nh * nh, m2 = m * m;
    double ph = exp((c2 - 1) / (c2 * m2)) / (m2 * c2 * c2);
    double e = pow(1 - fmin(fmax(vh, 0), 1), 5);
    double g = 1 / (1 + beckmann_lambda(nv, m) + beckmann_lambda(nl, m));
    return ph * (e + f0 * (1 - e)) * g / (4 * nv);
}

// Exact reflected luminance: (1/pi) sum L(l) lobe(N, l, V) dw over the whole capture (every light in the
// renderer is divided by pi: light_color is (1/pi) the integral of its radiance), for the capture and for
// the map the light was taken out of in one pass (the same texels and lobe: half the lobe evaluations).
static void exact_specular(const rs_envmap *m, const rs_envmap *rest, const float *dirs, const double *sr,
                           const float N[3], const float V[3], double rough, double *with, double *without)
{
    double sum = 0, sum_rest = 0;
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            size_t t = (size_t)j * m->w + i;
            const float *l = dirs + 3 * t;
            if (dot3(N, l) <= 0) continue;
            const float *c = m->rgb + 3 * t, *cr = rest->rgb + 3 * t;
            double L = 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
            double Lr = 0.2126 * cr[0] + 0.7152 * cr[1] + 0.0722 * cr[2];
            if (L <= 0 && Lr <= 0) continue;
            double w = ksk(N, l, V, rough, 0.028) * sr[j];
            if (L > 0) sum += L * w;
            if (Lr > 0) sum_rest += Lr * w;
        }
    *with = sum / PI, *without = sum_rest / PI;
}

static bool texel_tables(const rs_envmap *m, float **dirs, double **sr)
{
    *dirs = malloc(sizeof(float) * 3 * (size_t)m->w * m->h);
    *sr = malloc(sizeof(double) * (size_t)m->h);
    if (!*dirs || !*sr) return false;
    for (int j = 0; j < m->h; j++) {
        (*sr)[j] = rs_envmap_texel_sr(m->w, m->h, j);
        for (int i = 0; i < m->w; i++) rs_envmap_texel_dir(m->w, m->h, i, j, *dirs + 3 * ((size_t)j * m->w + i));
    }
    return true;
}

// Renders the specular (linear, clamped, 8 bits) at three exposures 16x apart: each pixel from the
// brightest one that does not clip it (a dark studio's drapes reflect ~0.004, its lamps ~1).
static bool render_specular(rs_renderer *r, rs_pipeline pipeline, float *lum)
{
    const float e[3] = {32.0f, 2.0f, 0.125f};
    for (int pass = 0; pass < 3; pass++) {
        rs_view v = rs_view_defaults();
        v.width = v.height = SIZE;
        v.pipeline = pipeline;
        v.mode = RS_MODE_SPECULAR;
        v.linear_output = true;
        v.tonemap = RS_TONEMAP_CLAMP;
        v.exposure = e[pass];
        v.background[0] = v.background[1] = v.background[2] = 0;
        rs_image img = {0};
        rs_error err = {0};
        if (!RS_CHECK(rs_render_image(r, &v, &img, &err) == RS_OK, "%s", err.msg)) return false;
        for (int p = 0; p < SIZE * SIZE; p++) {
            const uint8_t *q = img.pixels + 4 * p;
            float y = (0.2126f * q[0] + 0.7152f * q[1] + 0.0722f * q[2]) / 255.0f;
            bool clipped = q[0] >= 254 || q[1] >= 254 || q[2] >= 254;
            if (pass == 0 || lum[p] < 0) lum[p] = clipped && pass < 2 ? -1.0f : y / e[pass];
        }
        rs_image_free(&img);
    }
    return true;
}

// For the pixel (x, y) (top-left origin): the sphere's normal and the direction to the eye, in the model
// (= environment) frame, by intersecting the pixel's ray with the sphere. False off the sphere.
static bool pixel_geometry(const float vm[16], const float pm[16], int x, int y, float N[3], float V[3])
{
    double ndc[2] = {2.0 * (x + 0.5) / SIZE - 1.0, 1.0 - 2.0 * (y + 0.5) / SIZE};
    double de[3] = {(ndc[0] + pm[8]) / pm[0], (ndc[1] + pm[9]) / pm[5], -1.0};  // eye space, z = -1
    // Rigid model -> eye: eye = R model + t, so model = R^T (eye - t).
    double d[3], o[3];
    for (int i = 0; i < 3; i++) {
        d[i] = vm[4 * i] * de[0] + vm[4 * i + 1] * de[1] + vm[4 * i + 2] * de[2];
        o[i] = -(vm[4 * i] * vm[12] + vm[4 * i + 1] * vm[13] + vm[4 * i + 2] * vm[14]);
    }
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; i++) d[i] /= dl;
    double R = SPHERE_MM / MM_PER_UNIT, b = o[0] * d[0] + o[1] * d[1] + o[2] * d[2];
    double c = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] - R * R, disc = b * b - c;
    if (disc <= 0) return false;
    double t = -b - sqrt(disc);
    for (int i = 0; i < 3; i++) N[i] = (float)((o[i] + t * d[i]) / R), V[i] = (float)-d[i];
    return true;
}

static void test_environment_specular_matches_the_lobe_over_the_capture(void)
{
    rs_splat_cloud *cloud = make_sphere(SKIN_M);
    RS_REQUIRE(cloud, "sphere");
    rs_renderer *r = NULL;
    rs_error err = {0};
    if (!RS_CHECK(rs_render_create(&(rs_render_desc){.cloud = cloud, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK,
                  "%s", err.msg)) {
        rs_splat_destroy(cloud);
        return;
    }
    // Both pipelines: the mobile one's grid has no taps across the plane of incidence and starts its one
    // lookup nearer grazing (env_light.glsl); the goal holds for both.
    float *lum = malloc(sizeof(float) * SIZE * SIZE), *lum_mobile = malloc(sizeof(float) * SIZE * SIZE);
    int done = 0;
    for (int k = 0; k < ENV_COUNT && lum && lum_mobile; k++) {
        char path[256], rse[64];
        snprintf(path, sizeof path, WORLD "%s.exr", envs[k].source);
        snprintf(rse, sizeof rse, "assets/env/%s.rse", envs[k].name);
        if (access(path, R_OK) != 0) {
            printf("# %s: %s absent (blender-data: make deps)\n", envs[k].name, path);
            continue;
        }
        rs_env *env = NULL;
        rs_envmap src = {0}, rest = {0};
        float *dirs = NULL, light[3];
        double *sr = NULL;
        if (!RS_CHECK(rs_env_load(rse, &env, &err) == RS_OK, "%s", err.msg)) continue;
        if (turned_source(path, &src, &rest, light) && texel_tables(&src, &dirs, &sr) &&
            RS_CHECK(acos(fmin(dot3(light, env->light_dir), 1.0)) < 0.5 * PI / 180, "%s: the capture's light is "
                     "%.2f deg from the .rse's: not the same turn", envs[k].name,
                     acos(fmin(dot3(light, env->light_dir), 1.0)) * 180 / PI) &&
            RS_CHECK(rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg) &&
            render_specular(r, RS_PIPELINE_REFERENCE, lum) && render_specular(r, RS_PIPELINE_MOBILE, lum_mobile)) {
            rs_view v = rs_view_defaults();
            v.width = v.height = SIZE;
            float vm[16], pm[16];
            rs_render_view_matrices(r, &v, vm, pm);
            double scale = r->env.scale;
            // Candidate pixels per band: on the sphere with a 5x5 neighbourhood on it too (the composite's
            // anti-aliased rim blends the background into the last pixels).
            printf("# %s (exposure normalisation %.4g): band N.V, rouge/exact, median per pixel\n", envs[k].name,
                   scale);
            for (int b = 0; b < BANDS; b++) {
                int cand[SIZE * 8], nc = 0, seen = 0;
                for (int y = 2; y < SIZE - 2 && nc < SIZE * 8; y++)
                    for (int x = 2; x < SIZE - 2 && nc < SIZE * 8; x++) {
                        float N[3], V[3];
                        if (!pixel_geometry(vm, pm, x, y, N, V)) continue;
                        float nv = (float)dot3(N, V);
                        if (nv < band_lo[b] || nv >= band_hi[b]) continue;
                        bool inside = true;
                        for (int dy = -2; dy <= 2 && inside; dy++)
                            for (int dx = -2; dx <= 2 && inside; dx++)
                                inside = pixel_geometry(vm, pm, x + dx, y + dy, N, V);
                        // Every 3rd candidate: spread over the whole band's ring.
                        if (inside && seen++ % 3 == 0) cand[nc++] = y * SIZE + x;
                    }
                double sr_sum = 0, sm_sum = 0, se_sum = 0, ratios[PER_BAND], key_r = 0, key_e = 0;
                int n = 0;
                for (int i = 0; i < PER_BAND && nc > 0; i++) {
                    int p = cand[(int)((long)i * nc / PER_BAND)];
                    float N[3], V[3];
                    pixel_geometry(vm, pm, p % SIZE, p / SIZE, N, V);
                    double ex, ex_rest;
                    exact_specular(&src, &rest, dirs, sr, N, V, SKIN_M, &ex, &ex_rest);
                    ex *= scale, ex_rest *= scale;
                    sr_sum += lum[p], sm_sum += lum_mobile[p], se_sum += ex;
                    // The key light's share: rouge's (its colour through the widened lobe) and exact (the
                    // capture minus the map the light was taken out of).
                    double mk = sqrt(SKIN_M * SKIN_M + 0.25 * env->light_angle * env->light_angle);
                    key_r += scale * (0.2126 * env->light_color[0] + 0.7152 * env->light_color[1] +
                                      0.0722 * env->light_color[2]) * ksk(N, env->light_dir, V, mk, 0.028);
                    key_e += ex - ex_rest;
                    ratios[n++] = ex > 0 ? lum[p] / ex : 1.0;
                }
                for (int i = 1; i < n; i++)  // insertion sort for the median
                    for (int j = i; j > 0 && ratios[j] < ratios[j - 1]; j--) {
                        double t = ratios[j]; ratios[j] = ratios[j - 1]; ratios[j - 1] = t;
                    }
                double ratio = se_sum > 0 ? sr_sum / se_sum : 0, ratio_m = se_sum > 0 ? sm_sum / se_sum : 0;
                printf("#   %.2f-%.2f: %+6.1f %%, median %+6.1f %%, mobile %+6.1f %% (%d px, exact mean %.4f; key light "
                       "%.4f of exact %.4f, the map %.4f of %.4f)\n", band_lo[b], band_hi[b], 100 * (ratio - 1),
                       n ? 100 * (ratios[n / 2] - 1) : 0.0, 100 * (ratio_m - 1), n, n ? se_sum / n : 0.0,
                       key_r / RS_MAX(n, 1), key_e / RS_MAX(n, 1), (sr_sum - key_r) / RS_MAX(n, 1),
                       (se_sum - key_e) / RS_MAX(n, 1));
                RS_CHECK(n >= PER_BAND / 2 && fabs(ratio - 1) <= 0.20, "%s, N.V %.2f-%.2f: rouge's specular %+.1f %% "
                         "of the exact integral (want within 20 %%)", envs[k].name, band_lo[b], band_hi[b],
                         100 * (ratio - 1));
                RS_CHECK(fabs(ratio_m - 1) <= 0.20, "%s, N.V %.2f-%.2f: the mobile pipeline's specular %+.1f %% of the "
                         "exact integral (want within 20 %%)", envs[k].name, band_lo[b], band_hi[b], 100 * (ratio_m - 1));
            }
            done++;
        }
        free(dirs);
        free(sr);
        rs_envmap_free(&src);
        rs_envmap_free(&rest);
        rs_env_destroy(env);
    }
    free(lum);
    free(lum_mobile);
    rs_render_destroy(r);
    rs_splat_destroy(cloud);
    if (done == 0) rs_test_skip("no blender-data captures (make deps)");
}

// Brute-force irradiance / pi of the capture at normal n: (1/pi) sum L max(n.l, 0) dw (luminance).
static double exact_irradiance(const rs_envmap *m, const float *dirs, const double *sr, const float n[3])
{
    double sum = 0;
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            size_t t = (size_t)j * m->w + i;
            double c = dot3(n, dirs + 3 * t);
            if (c <= 0) continue;
            const float *p = m->rgb + 3 * t;
            sum += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) * c * sr[j];
        }
    return sum / PI;
}

// The diffuse light the renderer uses (SH9 of the rest + the key light + the lamps it takes out of the SH,
// render_env.c) against the
// brute-force irradiance of the capture, for 400 normals all over the sphere. The error is relative to
// the environment's mean irradiance over the front half (what the exposure normalisation sets to 0.5),
// so a dark back side does not blow a small absolute error up.
static void test_sh_and_light_match_the_capture_irradiance(void)
{
    rs_splat_cloud *cloud = make_sphere(SKIN_M);
    RS_REQUIRE(cloud, "sphere");
    rs_renderer *r = NULL;
    rs_error rerr = {0};
    if (!RS_CHECK(rs_render_create(&(rs_render_desc){.cloud = cloud, .caps = rs_gl_get_caps(gl)}, &r, &rerr) == RS_OK,
                  "%s", rerr.msg)) {
        rs_splat_destroy(cloud);
        return;
    }
    int done = 0;
    for (int k = 0; k < ENV_COUNT; k++) {
        char path[256], rse[64];
        snprintf(path, sizeof path, WORLD "%s.exr", envs[k].source);
        snprintf(rse, sizeof rse, "assets/env/%s.rse", envs[k].name);
        if (access(path, R_OK) != 0) continue;
        rs_env *env = NULL;
        rs_envmap src = {0}, rest = {0};
        float *dirs = NULL, light[3];
        double *sr = NULL;
        rs_error err = {0};
        if (!RS_CHECK(rs_env_load(rse, &env, &err) == RS_OK, "%s", err.msg)) continue;
        if (turned_source(path, &src, &rest, light) && texel_tables(&src, &dirs, &sr) &&
            RS_CHECK(rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg)) {
            const rs_render_env *re = &r->env;
            int lamps = 0;
            for (int q = 0; q < RS_ENV_LAMPS; q++) lamps += re->lamp_color[q][0] + re->lamp_color[q][1] > 0;
            enum { NN = 400 };
            double ex[NN], got[NN], front = 0;
            int nf = 0;
            for (int i = 0; i < NN; i++) {
                float z = 1.0f - (2.0f * i + 1.0f) / NN, r = sqrtf(1.0f - z * z), phi = 2.39996323f * i;
                float n[3] = {r * cosf(phi), z, r * sinf(phi)}, e[3];
                ex[i] = exact_irradiance(&src, dirs, sr, n);
                // As env_light.glsl's rs_env_irradiance, undoing the exposure normalisation.
                float y[9];
                rs_env_sh_basis(n, y);
                double nl = fmax(dot3(n, re->light_dir), 0);
                for (int c = 0; c < 3; c++) {
                    e[c] = 0;
                    for (int b = 0; b < 9; b++) e[c] += re->sh[b][c] * y[b];
                    for (int q = 0; q < RS_ENV_LAMPS; q++) e[c] += re->lamp_color[q][c] * fmax(dot3(n, re->lamp_dir[q]), 0);
                    e[c] = (float)((fmax(e[c], 0) + re->light_color[c] * nl) / re->scale);
                }
                got[i] = 0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2];
                if (n[2] > 0) front += ex[i], nf++;
            }
            front /= RS_MAX(nf, 1);
            double worst = 0, mean = 0, worst_rel = 0;
            for (int i = 0; i < NN; i++) {
                double d = fabs(got[i] - ex[i]);
                worst = fmax(worst, d / front), mean += d / front / NN;
                worst_rel = fmax(worst_rel, d / fmax(ex[i], 1e-9));
            }
            printf("# %s: SH9 + key + %d lamps vs the capture's irradiance: mean %.1f %%, max %.1f %% of the front "
                   "mean; max %.1f %% of the normal's own\n", envs[k].name, lamps, 100 * mean, 100 * worst,
                   100 * worst_rel);
            // Before the lamps (key light + SH9 only): studio mean 3.1 %, max 11.6 % of the front mean, 36 % of
            // the normal's own.
            RS_CHECK(mean <= 0.01 && worst <= 0.04 && worst_rel <= 0.10, "%s: irradiance error mean %.1f %%, max "
                     "%.1f %% of the front mean, %.1f %% of the normal's own (want <= 1, 4, 10 %%)", envs[k].name,
                     100 * mean, 100 * worst, 100 * worst_rel);
            done++;
        }
        free(dirs);
        free(sr);
        rs_envmap_free(&src);
        rs_envmap_free(&rest);
        rs_env_destroy(env);
    }
    rs_render_destroy(r);
    rs_splat_destroy(cloud);
    if (done == 0) rs_test_skip("no blender-data captures (make deps)");
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - env_specular: no GLES 3 context (%s)\n", err.msg);
        return rs_test_finish();
    }
    RS_RUN(test_environment_specular_matches_the_lobe_over_the_capture);
    RS_RUN(test_sh_and_light_match_the_capture_irradiance);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
