// test_incremental.c — incremental frames (issue 13): after makeup changes with the view unchanged, the
// renderer redraws only the attribute and composite passes inside the rectangle the changed splats cover,
// over the last frame's depth, shadow map and diffusion. After a long random sequence of stamps (several
// products, an eraser, mirror strokes), each followed by a frame, the picture equals a from-scratch frame
// within 1/255 everywhere, in both pipelines, with float and RGBA8 targets, and under an environment.
// And the splats' irradiance kept across views: once the lights have held still for a frame, stage 4 reuses
// the per-splat light of every splat for any view (orbiting, another side of the head) until a light moves;
// each such frame equals a fresh renderer's of the same view and light within 1/255, under an environment
// and under the paper's lamps, and a turned environment or a moved key light is not served from the old.
#include "support/harness.h"
#include "formats/env_lookup.h"
#include "makeup/makeup.h"
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define SIZE 256
#define STAMPS 24

static rs_gl_context *gl;
static rs_splat_cloud *face;

static uint32_t rng(uint32_t *s)
{
    *s ^= *s << 13, *s ^= *s >> 17, *s ^= *s << 5;
    return *s;
}

// env: under an environment (the reflections the face blocks see the painted skin), else the paper's lamp.
static void run(rs_pipeline pipeline, bool rgba8, const char *env_name)
{
    rs_renderer *r = NULL;
    rs_makeup *mk = NULL;
    rs_env *env = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(gl), .force_no_float_targets = rgba8},
                                &r, &err) == RS_OK, "%s", err.msg);
    if (env_name && !RS_CHECK(rs_env_open(env_name, "assets/env", &env, &err) == RS_OK &&
                                  rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg)) {
        rs_env_destroy(env);
        rs_render_destroy(r);
        return;
    }
    if (!RS_CHECK(rs_makeup_create(face, NULL, &mk, &err) == RS_OK, "%s", err.msg)) {
        rs_render_destroy(r);
        return;
    }
    rs_makeup_uniforms u;
    rs_makeup_get_uniforms(mk, &u);
    rs_render_set_makeup_uniforms(r, &u);
    rs_view v = rs_view_defaults();
    v.width = v.height = SIZE, v.pipeline = pipeline, v.yaw_deg = -20;
    v.max_splats = pipeline == RS_PIPELINE_REFERENCE ? 150000 : 0;  // a reference frame of all 600k is slow here
    rs_image a = {0}, b = {0};
    bool ok = RS_CHECK(rs_render_frame(r, &v, &err) == RS_OK, "%s", err.msg);
    uint32_t drawn = rs_render_get_stats(r).splats_drawn, seed = 12345u + (uint32_t)pipeline * 7u + rgba8;
    static const char *products[] = {"lipstick_satin", "blush", "highlighter", "eyeliner", "lip_gloss", "foundation_3"};
    uint32_t inc0 = rs_render_incremental_frames(r);
    for (int k = 0; ok && k < STAMPS; k++) {
        // A splat of the drawn prefix that faces the camera.
        uint32_t i = 0;
        float dir[3] = {0, 0, 1};
        for (int tries = 0; tries < 1000; tries++) {
            i = rng(&seed) % drawn;
            rs_render_view_dir(r, &v, face->pos[i], dir);
            const float *n = face->normal[i];
            if (n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2] > 0.6f) break;
        }
        rs_makeup_stamp_desc d = {.pos = {face->pos[i][0], face->pos[i][1], face->pos[i][2]},
                                  .view_dir = {dir[0], dir[1], dir[2]},
                                  .radius = rs_makeup_brush_radius(&face->hdr, 0.03f + 0.1f * (float)(rng(&seed) % 100) / 100.0f),
                                  .opacity = 0.7f, .pressure = 1.0f, .mirror = k % 5 == 2, .eraser = k % 7 == 6,
                                  .cosmetic = rs_cosmetic_find(products[rng(&seed) % RS_COUNT_OF(products)])};
        ok = RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_OK, "stamp %d: %s", k, err.msg);
        rs_makeup_range ranges[RS_MAKEUP_MAX_RANGES];
        uint32_t nr = rs_makeup_take_dirty(mk, ranges, RS_MAKEUP_MAX_RANGES);
        for (uint32_t j = 0; ok && j < nr; j++)
            ok = RS_CHECK(rs_render_update_makeup(r, ranges[j].lo, ranges[j].hi - ranges[j].lo,
                                                  rs_makeup_records(mk) + ranges[j].lo, &err) == RS_OK, "%s", err.msg);
        ok = ok && RS_CHECK(rs_render_frame(r, &v, &err) == RS_OK, "%s", err.msg);
    }
    uint32_t incs = rs_render_incremental_frames(r) - inc0;
    ok = ok && RS_CHECK(rs_render_read(r, &a, &err) == RS_OK, "%s", err.msg);
    rs_render_invalidate(r);
    ok = ok && RS_CHECK(rs_render_image(r, &v, &b, &err) == RS_OK, "%s", err.msg);
    if (ok) {
        int worst = 0, changed = 0;
        for (size_t p = 0; p < (size_t)SIZE * SIZE * 4; p++) {
            int dd = abs(a.pixels[p] - b.pixels[p]);
            worst = RS_MAX(worst, dd);
            changed += dd > 1;
        }
        printf("# %s, %s targets, %s: %u of %d frames incremental; largest difference from a full frame %d/255\n",
               pipeline == RS_PIPELINE_MOBILE ? "mobile" : "reference", rgba8 ? "RGBA8" : "float",
               env_name ? env_name : "lamp", incs, STAMPS, worst);
        RS_CHECK(incs == STAMPS, "only %u of %d frames were incremental", incs, STAMPS);
        RS_CHECK(worst <= 1, "incremental differs from a full frame by up to %d/255 (%d values)", worst, changed);
        if (worst > 1) {
            rs_test_save("incremental_frame", &a);
            rs_test_save("incremental_full", &b);
        }
    }
    rs_image_free(&a);
    rs_image_free(&b);
    rs_makeup_destroy(mk);
    rs_render_destroy(r);
    rs_env_destroy(env);
}

// A fresh renderer's picture of view v (nothing kept from other frames).
static bool fresh_image(const rs_view *v, const rs_env *env, rs_image *out)
{
    rs_renderer *r = NULL;
    rs_error err = {0};
    bool ok = RS_CHECK(rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK,
                       "%s", err.msg) &&
              RS_CHECK(!env || rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg) &&
              RS_CHECK(rs_render_image(r, v, out, &err) == RS_OK, "%s", err.msg);
    rs_render_destroy(r);
    return ok;
}

// Renders v on r and compares it with a fresh renderer's; kept: whether r must have reused the light.
static bool kept_frame(rs_renderer *r, const rs_view *v, const rs_env *env, bool kept, const char *what)
{
    rs_image a = {0}, b = {0};
    rs_error err = {0};
    bool ok = RS_CHECK(rs_render_image(r, v, &a, &err) == RS_OK, "%s: %s", what, err.msg) && fresh_image(v, env, &b);
    if (ok) {
        bool k = rs_render_get_stats(r).irradiance_kept;
        int worst = 0;
        for (size_t p = 0; p < (size_t)v->width * v->height * 4; p++) worst = RS_MAX(worst, abs(a.pixels[p] - b.pixels[p]));
        printf("# %s: irradiance %s; largest difference from a fresh renderer %d/255\n", what, k ? "kept" : "computed", worst);
        ok = RS_CHECK(k == kept, "%s: irradiance %s, expected %s", what, k ? "kept" : "computed", kept ? "kept" : "computed");
        ok = RS_CHECK(worst <= 1, "%s: differs from a fresh renderer by %d/255", what, worst) && ok;
        if (worst > 1) {
            rs_test_save("kept_frame", &a);
            rs_test_save("kept_fresh", &b);
        }
    }
    rs_image_free(&a);
    rs_image_free(&b);
    return ok;
}

static void test_kept_irradiance(void)
{
    rs_renderer *r = NULL;
    rs_env *env = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_env_open(RS_ENV_DEFAULT, "assets/env", &env, &err) == RS_OK, "%s", err.msg);
    bool ok = RS_CHECK(rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(gl)}, &r, &err) == RS_OK,
                       "%s", err.msg) &&
              RS_CHECK(rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg);
    rs_view v = rs_view_defaults();
    v.width = v.height = SIZE, v.pipeline = RS_PIPELINE_MOBILE;
    // One side of the head (again: the same view reuses what it computed), then the other (the first frame
    // computed only what it saw), then the front.
    v.yaw_deg = -70;
    ok = ok && kept_frame(r, &v, env, false, "environment, left profile");
    rs_render_invalidate(r);  // a full frame, not an incremental one (which runs no stage 4)
    ok = ok && kept_frame(r, &v, env, true, "environment, left profile again");
    // Another kernel count in the same view: kept only while its levels reach no farther than the pass
    // that computed the view's splats (on this face the widest level is the splats' floor either way).
    for (int k = 2; k <= 4; k += 2) {
        v.kernel_count = k;
        rs_render_invalidate(r);
        char what[64];
        snprintf(what, sizeof what, "environment, left profile, %d Gaussians", k);
        ok = ok && kept_frame(r, &v, env, true, what);
    }
    v.kernel_count = 0;
    v.yaw_deg = 70;
    ok = ok && kept_frame(r, &v, env, false, "environment, right profile (lights held: every splat)");
    v.yaw_deg = 10, v.pitch_deg = -15;
    ok = ok && kept_frame(r, &v, env, true, "environment, front from below");
    v.env_rotate_deg = 40;
    ok = ok && kept_frame(r, &v, env, false, "environment turned by 40 deg");
    // The paper's lamps: a key light that moves.
    v.lighting = RS_LIGHTING_LIGHTS, v.env_rotate_deg = 0;
    ok = ok && kept_frame(r, &v, NULL, false, "lamp");
    v.yaw_deg = -30;
    ok = ok && kept_frame(r, &v, NULL, false, "lamp, lights held");
    v.yaw_deg = 30;
    ok = ok && kept_frame(r, &v, NULL, true, "lamp, orbited");
    v.key.yaw_deg += 20;
    ok = ok && kept_frame(r, &v, NULL, false, "lamp, key light moved");
    (void)ok;
    rs_render_destroy(r);
    rs_env_destroy(env);
}

static void test_incremental_mobile_float(void) { run(RS_PIPELINE_MOBILE, false, NULL); }
static void test_incremental_mobile_rgba8(void) { run(RS_PIPELINE_MOBILE, true, NULL); }
static void test_incremental_reference_float(void) { run(RS_PIPELINE_REFERENCE, false, NULL); }
static void test_incremental_reference_rgba8(void) { run(RS_PIPELINE_REFERENCE, true, NULL); }
static void test_incremental_mobile_environment(void) { run(RS_PIPELINE_MOBILE, false, "studio"); }

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - incremental: no GLES 3 context (%s)\n", err.msg);
        return rs_test_finish();
    }
    if (rs_splat_load("assets/face.rsf", &face, &err) != RS_OK) {
        printf("FAIL - incremental: %s\n", err.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    RS_RUN(test_incremental_mobile_float);
    RS_RUN(test_incremental_mobile_rgba8);
    RS_RUN(test_incremental_reference_float);
    RS_RUN(test_incremental_reference_rgba8);
    RS_RUN(test_incremental_mobile_environment);
    RS_RUN(test_kept_irradiance);
    rs_splat_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
