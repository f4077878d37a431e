// test_quantize_render.c — the 16-byte .rsf record is visually lossless: rendering is insensitive to
// changes of the size of the quantization error, so a render of the quantized file equals one of the
// float data it came from (issue: PSNR >= 45 dB at 512x512).
//
// The renderer only draws packed records, so "float data" is built as the quantized splats moved by up
// to one quantization step in every field (position, octahedral normal, log radius) and re-encoded in a
// new bounding box: the float data and its quantization differ by at most half a step, this test by up
// to a whole step.
// Also the bent normals the low bits of the normal's code carry (RS_SPLAT_FLAG_BENT): where they are the
// normal and the sky is wide open the environment's light is the one without them, to the bit.
#include "support/harness.h"
#include "formats/env.h"
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 512
#define MAX_SPLATS 50000

static float jitter(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return (float)(*s >> 8) / (float)(1u << 24) * 2.0f - 1.0f;  // -1..1
}

static rs_result render(const rs_splat_cloud *c, rs_gl_context *gl, rs_image *out, rs_error *err)
{
    rs_renderer *r = NULL;
    rs_result res = rs_render_create(&(rs_render_desc){.cloud = c, .caps = rs_gl_get_caps(gl)}, &r, err);
    rs_view v = rs_view_defaults();
    v.width = v.height = SIZE;
    v.yaw_deg = -20.0f;
    v.zoom = 1.3f;
    v.mode = RS_MODE_FULL;
    if (!res) res = rs_render_image(r, &v, out, err);
    rs_render_destroy(r);
    return res;
}

static rs_gl_context *gl;

// The bundled face's first 50k splats open to the sky (AO 255), with bent normals `tilt` of the way from
// the normal to up (0: the normal itself), or none (tilt < 0); rendered under daylight.
static rs_result render_sky(float tilt, rs_image *out, rs_error *err)
{
    rs_splat_cloud *face = NULL;
    rs_env *env = NULL;
    rs_renderer *r = NULL;
    rs_result res = rs_splat_load("assets/face.rsf", &face, err);
    if (!res) res = rs_env_load("assets/env/daylight.rse", &env, err);
    uint32_t n = face ? face->hdr.count : 0;
    uint8_t *ao = malloc(RS_MAX(n, 1u));
    float(*bent)[3] = malloc(sizeof *bent * RS_MAX(n, 1u));
    if (!res && (!ao || !bent)) res = rs_fail(err, RS_ERR_NOMEM, "out of memory");
    if (!res) {
        memset(ao, 255, n);
        rs_splat_set_ao(face, ao);
        for (uint32_t i = 0; i < n; i++) {
            float *b = bent[i], l = 0;
            for (int k = 0; k < 3; k++) b[k] = face->normal[i][k] + (k == 1 ? RS_MAX(tilt, 0.0f) : 0.0f), l += b[k] * b[k];
            for (int k = 0; k < 3; k++) b[k] /= sqrtf(l);
        }
        // The same normals either way: set, then (tilt < 0) cleared, which keeps them.
        res = rs_splat_set_bent(face, (const float(*)[3])bent, err);
        if (!res && tilt < 0) res = rs_splat_set_bent(face, NULL, err);
        if (!res) res = rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(gl)}, &r, err);
    }
    if (!res) res = rs_render_set_env(r, env, err);
    if (!res) {
        rs_view v = rs_view_defaults();
        v.width = v.height = 256;
        v.max_splats = MAX_SPLATS;
        res = rs_render_image(r, &v, out, err);
    }
    rs_render_destroy(r);
    rs_env_destroy(env);
    rs_splat_destroy(face);
    free(ao);
    free(bent);
    return res;
}

static void test_open_unbent_sky_renders_as_without_bent_normals(void)
{
    rs_image none = {0}, same = {0}, up = {0};
    rs_error err = {0};
    rs_image_metrics m = {0}, mu = {0};
    bool ok = RS_CHECK(render_sky(-1.0f, &none, &err) == RS_OK && render_sky(0.0f, &same, &err) == RS_OK &&
                           render_sky(0.5f, &up, &err) == RS_OK,
                       "%s", err.msg) &&
              RS_CHECK(rs_image_compare(&none, &same, 3, &m, &err) == RS_OK &&
                           rs_image_compare(&none, &up, 3, &mu, &err) == RS_OK,
                       "%s", err.msg);
    if (ok) {
        printf("# open sky: bent = normal vs none max %d; bent turned towards up: PSNR %.1f dB\n", m.max_abs, mu.psnr);
        if (m.max_abs != 0) rs_test_save("quantize_sky.none", &none), rs_test_save("quantize_sky.bent", &same);
        RS_CHECK(m.max_abs == 0, "bent normals equal to the normals change the picture (max %d)", m.max_abs);
        RS_CHECK(mu.psnr < 40.0, "bent normals turned up do not change the light (%.1f dB)", mu.psnr);
    }
    rs_image_free(&none);
    rs_image_free(&same);
    rs_image_free(&up);
}

static void test_render_of_quantized_splats_matches_float_data(void)
{
    rs_error err = {0};
    rs_splat_cloud *face = NULL;
    RS_REQUIRE(rs_splat_load("assets/face.rsf", &face, &err) == RS_OK, "%s", err.msg);
    uint32_t n = rs_splat_lod_count(face, MAX_SPLATS);
    const rs_splat_header *h = &face->hdr;
    rs_splat *s = malloc(sizeof *s * n);
    rs_splat_cloud *a = NULL, *b = NULL;
    RS_REQUIRE(s != NULL, "out of memory");
    float step[3];
    for (int k = 0; k < 3; k++) step[k] = (h->bbox_max[k] - h->bbox_min[k]) / 65535.0f;
    float log_step = logf(h->radius_max / h->radius_min) / 255.0f;
    uint32_t seed = 12345;
    for (uint32_t i = 0; i < n; i++) rs_splat_get(face, i, &s[i]);
    rs_splat_header hq = *h;
    hq.flags &= ~RS_SPLAT_FLAG_BENT;  // float splats carry no bent normals
    hq.lod_count = 1;
    hq.lods[0] = n;
    // The prefix drawn as a whole cloud has coarser spacing: scale radii as the LOD would.
    float grow = rs_splat_lod_radius_scale(face, n);
    for (uint32_t i = 0; i < n; i++) s[i].radius *= grow;
    rs_result r = rs_splat_create(s, n, &hq, &a, &err);
    for (uint32_t i = 0; r == RS_OK && i < n; i++) {
        for (int k = 0; k < 3; k++) s[i].pos[k] += jitter(&seed) * step[k];
        // One snorm16 step of the octahedral code is at most ~0.005 degrees: tilt by that much.
        float t[3] = {jitter(&seed), jitter(&seed), jitter(&seed)}, len = 0;
        for (int k = 0; k < 3; k++) s[i].normal[k] += t[k] * 9e-5f, len += s[i].normal[k] * s[i].normal[k];
        for (int k = 0; k < 3; k++) s[i].normal[k] /= sqrtf(len);
        s[i].radius *= expf(jitter(&seed) * log_step);
    }
    if (r == RS_OK) r = rs_splat_create(s, n, &hq, &b, &err);
    free(s);
    rs_splat_destroy(face);
    rs_image ia = {0}, ib = {0};
    if (RS_CHECK(r == RS_OK, "%s", err.msg)) {
        r = render(a, gl, &ia, &err);
        if (!r) r = render(b, gl, &ib, &err);
        rs_image_metrics m;
        if (RS_CHECK(r == RS_OK, "%s", err.msg) && RS_CHECK(rs_image_compare(&ia, &ib, 3, &m, &err) == RS_OK, "%s",
                                                          err.msg)) {
            if (m.psnr < 45.0) rs_test_save("quantize_render.float", &ib), rs_test_save("quantize_render.packed", &ia);
            printf("# quantized vs float data: PSNR %.2f dB, SSIM %.5f, max %d\n", m.psnr, m.ssim, m.max_abs);
            RS_CHECK(m.psnr >= 45.0, "PSNR %.2f dB between quantized and float-data renders (need >= 45)", m.psnr);
            RS_CHECK(m.ssim >= 0.99, "SSIM %.4f", m.ssim);
        }
    }
    rs_image_free(&ia);
    rs_image_free(&ib);
    rs_splat_destroy(a);
    rs_splat_destroy(b);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("FAIL - quantize_render_gl_context: %s\n", err.msg);
        return 1;
    }
    RS_RUN(test_render_of_quantized_splats_matches_float_data);
    RS_RUN(test_open_unbent_sky_renders_as_without_bent_normals);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
