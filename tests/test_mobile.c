// test_mobile.c — the mobile pipeline (issue 5; docs/mobile.md) against the reference pipeline on the bundled
// face (assets/face.rsf; RS_TEST_FACE may name another .rsf): the stated tolerance on a subset of the fixed
// view set at 256x256 (the reference drawing all 600k splats, the mobile pipeline its own LOD prefix; the
// bench holds it at the stated 512x512), the K = 3 fit at a shadow edge, the LOD choice by projected
// density, the bare (albedo) floor skipping shadows and diffusion, and the usual robustness checks on the new paths.
// The bench (make bench) runs the whole set: 8 views x 2 lights x 2 modes.
#include "support/harness.h"
#include "support/face_fixture.h"
#include "formats/env_lookup.h"
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rs_test_face tf;
static rs_splat_cloud *face;  // tf.cloud and tf.ren, by their short names
static rs_renderer *ren;

// The fixed view set of the tolerance (tools/rouge_bench.c uses the same): camera yaw/pitch, key light
// yaw/pitch.
static const float views[8][2] = {{0, 0}, {-30, 0}, {30, 0}, {-60, 5}, {60, 5}, {0, 25}, {-20, -15}, {25, -10}};
static const float lights[2][2] = {{-35, 30}, {50, 10}};
// The tolerance views' size. docs/mobile.md states the tolerance at 512x512 (make bench measures it there);
// the tests hold the same thresholds at 256x256, a quarter of the pixels: the face still spans ~150 px, the
// mobile pipeline still draws the same LOD prefix (145k of 600k splats, the floor two levels below the cap)
// with its half-size shadow map and reduced-resolution wide Gaussian, and the numbers stay those of 512
// (mean PSNR 42.8 dB here, 42.4 there; CIEDE2000 0.313 both). A reference frame's cost is mostly its
// splats (shadow map, 1.5M diffusion splats), so smaller views would save little and blur what differs.
#define TOL_SIZE 256

// ---- helpers ----

static rs_view test_view(rs_render_mode mode, int size)
{
    rs_view v = rs_view_defaults();
    v.width = v.height = size;
    v.mode = mode;
    return v;
}

static bool need_face(void) { return rs_test_face_ready(&tf); }

static bool render(rs_renderer *r, const rs_view *v, rs_image *img)
{
    rs_error err = {0};
    return RS_CHECK(rs_render_image(r, v, img, &err) == RS_OK, "render: %s", err.msg);
}

static const uint8_t *px(const rs_image *img, int x, int y)
{
    return img->pixels + ((size_t)y * img->width + x) * img->channels;
}

static bool same_rgb(const uint8_t *a, const uint8_t *b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

// Background: the colour of the top-left corner (the face never reaches it in these views).
static bool is_background(const rs_image *img, int x, int y) { return same_rgb(px(img, x, y), img->pixels); }

// Face pixels at least `margin` pixels away from the background.
static bool interior(const rs_image *img, int x, int y, int margin)
{
    for (int dy = -margin; dy <= margin; dy++)
        for (int dx = -margin; dx <= margin; dx++) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= img->width || yy >= img->height || is_background(img, xx, yy)) return false;
        }
    return true;
}

static void save_pair(const char *name, const rs_image *a, const rs_image *b)
{
    char n[128];
    snprintf(n, sizeof n, "%s.reference", name);
    rs_test_save(n, a);
    snprintf(n, sizeof n, "%s.mobile", name);
    rs_test_save(n, b);
}

// ---- the tolerance ----

// docs/mobile.md: over the fixed views x lights at 512x512, in the diffuse and full modes, mobile vs
// reference: mean PSNR >= 38 dB, every view >= 34 dB, SSIM >= 0.97, mean CIEDE2000 <= 1.5; here at TOL_SIZE
// (above). A subset here
// (a reference frame of all 600k splats costs seconds on llvmpipe): eight pairs spread over views,
// lights and both modes, the reference drawing every splat and the mobile pipeline its default LOD.
static void test_mobile_matches_reference_within_tolerance_at_256(void)
{
    if (!need_face()) return;
    static const struct {
        int view, light;
        rs_render_mode mode;
    } set[] = {
        // (Grouped by light: the reference's 4096^2 shadow map is drawn once per light, not four times.)
        {0, 0, RS_MODE_FULL}, {3, 0, RS_MODE_FULL}, {5, 0, RS_MODE_FULL}, {6, 0, RS_MODE_DIFFUSE},
        {1, 1, RS_MODE_FULL}, {4, 1, RS_MODE_FULL}, {7, 1, RS_MODE_FULL}, {2, 1, RS_MODE_DIFFUSE},
    };
    double psnr_sum = 0, de_sum = 0;
    int n = 0;
    uint32_t drawn = 0;
    for (size_t i = 0; i < RS_COUNT_OF(set); i++) {
        rs_view v = test_view(set[i].mode, TOL_SIZE);
        v.yaw_deg = views[set[i].view][0], v.pitch_deg = views[set[i].view][1];
        v.key.yaw_deg = lights[set[i].light][0], v.key.pitch_deg = lights[set[i].light][1];
        rs_image ref = {0}, mob = {0};
        v.pipeline = RS_PIPELINE_REFERENCE;
        bool ok = render(ren, &v, &ref);
        v.pipeline = RS_PIPELINE_MOBILE;
        ok = ok && render(ren, &v, &mob);
        rs_image_metrics m = {0};
        rs_error err = {0};
        ok = ok && RS_CHECK(rs_image_compare(&ref, &mob, 8, &m, &err) == RS_OK, "%s", err.msg);
        if (ok) {
            drawn = rs_render_get_stats(ren).splats_drawn;
            double p = isinf(m.psnr) ? 99.0 : m.psnr;
            psnr_sum += p, de_sum += m.delta_e, n++;
            bool good = RS_CHECK(p >= 34.0 && m.ssim >= 0.97, "view %d light %d %s: PSNR %.2f dB, SSIM %.4f "
                                 "(%u splats)", set[i].view, set[i].light,
                                 set[i].mode == RS_MODE_FULL ? "full" : "diffuse", p, m.ssim, drawn);
            if (!good) {
                char name[64];
                snprintf(name, sizeof name, "mobile_tolerance_v%d_l%d", set[i].view, set[i].light);
                save_pair(name, &ref, &mob);
            }
        }
        rs_image_free(&ref);
        rs_image_free(&mob);
        if (!ok) return;
    }
    printf("# mobile vs reference at %dx%d, %d views: mean PSNR %.2f dB, mean CIEDE2000 %.3f, %u of %u splats\n",
           TOL_SIZE, TOL_SIZE, n, psnr_sum / n, de_sum / n, drawn, face->hdr.count);
    // The LOD decimation is exercised: the mobile pipeline drew a proper prefix.
    RS_CHECK(drawn > 0 && drawn < face->hdr.count, "mobile drew %u of %u splats", drawn, face->hdr.count);
    RS_CHECK(psnr_sum / n >= 38.0, "mean PSNR %.2f dB over %d views", psnr_sum / n, n);
    RS_CHECK(de_sum / n <= 1.5, "mean CIEDE2000 %.3f over %d views", de_sum / n, n);
}

// The same tolerance under environments (issue 12): three bundled environments of different character
// (outdoor daylight with a broad key and a blue sky; sunset with a low sun and a pink sky; office, a
// window and warm lamps indoors, where the mobile pipeline's lighter specular grid at grazing angles
// departs most from the reference's: docs/mobile.md), four views each over both modes, environment
// specular and SH irradiance through bent cones on both sides.
static void test_mobile_matches_reference_under_environments(void)
{
    if (!need_face()) return;
    static const char *envs[] = {"daylight", "sunset", "office"};
    static const struct {
        int view;
        rs_render_mode mode;
    } set[] = {{0, RS_MODE_FULL}, {3, RS_MODE_FULL}, {7, RS_MODE_FULL}, {2, RS_MODE_DIFFUSE}};
    for (size_t e = 0; e < RS_COUNT_OF(envs); e++) {
        rs_env *env = NULL;
        rs_error err = {0};
        RS_REQUIRE(rs_env_open(envs[e], NULL, &env, &err) == RS_OK, "%s", err.msg);
        rs_result r = rs_render_set_env(ren, env, &err);
        rs_env_destroy(env);
        RS_REQUIRE(r == RS_OK, "%s", err.msg);
        double psnr_sum = 0, de_sum = 0;
        int n = 0;
        for (size_t i = 0; i < RS_COUNT_OF(set); i++) {
            rs_view v = test_view(set[i].mode, TOL_SIZE);
            v.yaw_deg = views[set[i].view][0], v.pitch_deg = views[set[i].view][1];
            rs_image ref = {0}, mob = {0};
            v.pipeline = RS_PIPELINE_REFERENCE;
            bool ok = render(ren, &v, &ref);
            v.pipeline = RS_PIPELINE_MOBILE;
            ok = ok && render(ren, &v, &mob);
            rs_image_metrics m = {0};
            ok = ok && RS_CHECK(rs_image_compare(&ref, &mob, 8, &m, &err) == RS_OK, "%s", err.msg);
            if (ok) {
                double p = isinf(m.psnr) ? 99.0 : m.psnr;
                psnr_sum += p, de_sum += m.delta_e, n++;
                if (!RS_CHECK(p >= 34.0 && m.ssim >= 0.97, "%s view %d: PSNR %.2f dB, SSIM %.4f", envs[e],
                              set[i].view, p, m.ssim)) {
                    char name[64];
                    snprintf(name, sizeof name, "mobile_env_%s_v%d", envs[e], set[i].view);
                    save_pair(name, &ref, &mob);
                }
            }
            rs_image_free(&ref);
            rs_image_free(&mob);
            if (!ok) break;
        }
        if (n == 0) break;
        printf("# %s: mobile vs reference at %dx%d, %d views: mean PSNR %.2f dB, mean CIEDE2000 %.3f\n", envs[e],
               TOL_SIZE, TOL_SIZE, n,
               psnr_sum / n, de_sum / n);
        RS_CHECK(psnr_sum / n >= 38.0, "%s: mean PSNR %.2f dB", envs[e], psnr_sum / n);
        RS_CHECK(de_sum / n <= 1.5, "%s: mean CIEDE2000 %.3f", envs[e], de_sum / n);
    }
    rs_render_set_env(ren, NULL, NULL);
}

// ---- the K-Gaussian fit ----

// Error statistics over the shadow-edge band: face pixels (2 px inside the silhouette) within `reach`
// pixels of the key light's penumbra (visibility strictly between 0.1 and 0.9 in the shadow view).
typedef struct edge_error {
    int n;         // band pixels
    double mean;   // mean of the largest per-channel difference
    int p99;       // 99th percentile of it
} edge_error;

static edge_error shadow_edge_error(const rs_image *shadow, const rs_image *a, const rs_image *b, int reach)
{
    edge_error e = {0};
    int hist[256] = {0};
    int w = a->width, h = a->height;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            if (!interior(a, x, y, 2)) continue;
            bool near = false;
            for (int dy = -reach; dy <= reach && !near; dy++)
                for (int dx = -reach; dx <= reach && !near; dx++) {
                    int xx = x + dx, yy = y + dy;
                    if (xx < 0 || yy < 0 || xx >= w || yy >= h || is_background(shadow, xx, yy)) continue;
                    int s = px(shadow, xx, yy)[0];
                    near = s > 25 && s < 230;
                }
            if (!near) continue;
            int d = 0;
            for (int c = 0; c < 3; c++) d = RS_MAX(d, abs(px(a, x, y)[c] - px(b, x, y)[c]));
            hist[d]++;
            e.mean += d;
            e.n++;
        }
    if (e.n) e.mean /= e.n;
    for (int k = 0, acc = 0; k < 256; k++)
        if ((acc += hist[k]) >= 0.99 * e.n) {
            e.p99 = k;
            break;
        }
    return e;
}

// Paints every splat of the first n pure white (albedo 1, makeup records at full intensity), or clears them.
static bool white_skin(uint32_t n, bool on)
{
    rs_makeup_gpu *rec = calloc(n, sizeof *rec);
    if (!RS_CHECK(rec != NULL, "out of memory")) return false;
    if (on)
        for (uint32_t i = 0; i < n; i++)
            rec[i] = (rs_makeup_gpu){.rgb = {255, 255, 255}, .colour_i = 255, .flags = 128};
    rs_error err = {0};
    bool ok = RS_CHECK(rs_render_update_makeup(ren, 0, n, rec, &err) == RS_OK, "%s", err.msg);
    free(rec);
    return ok;
}

// The K = 3 fit's worst-case edge error is under 1% of the lit level, K = 2's 2-3% (METHOD.md). On white
// skin (so the image is D itself, in linear light) lit from the side, along the shadow edges (the
// terminator, the nose's and brows' cast shadows), the mobile diffuse image stays within about an 8-bit
// step of the six Gaussians' on average, and closer with K = 3 than with K = 2. Both pipelines draw all
// splats here (lod_density asks for more than the cloud has), so what differs is the profile and the
// mobile economies of stages 1 and 4 (the half-size shadow map with the same filter, the narrow Gaussians
// as per-pixel irradiance, the wide one at reduced resolution); the largest differences sit on creases
// (eyelids, lips, nostrils) that the band crosses, hence a percentile rather than the maximum.
static void test_k3_fit_matches_six_gaussians_at_a_shadow_edge(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_SHADOW, 256);
    v.lod_density = 1000.0f;  // no decimation
    v.key.yaw_deg = 60.0f, v.key.pitch_deg = 10.0f;  // from the image's right: the nose shadows the left cheek
    v.linear_output = true;
    v.exposure = 0.8f;  // D reaches ~1.05 where the key light meets the skin square on
    uint32_t n = face->hdr.count;
    rs_image shadow = {0}, ref = {0}, k3 = {0}, k2 = {0};
    bool ok = white_skin(n, true);
    v.pipeline = RS_PIPELINE_REFERENCE;
    ok = ok && render(ren, &v, &shadow);
    v.mode = RS_MODE_DIFFUSE;
    ok = ok && render(ren, &v, &ref);
    v.pipeline = RS_PIPELINE_MOBILE;
    v.kernel_count = 3;
    ok = ok && render(ren, &v, &k3);
    uint32_t drawn = rs_render_get_stats(ren).splats_drawn;
    v.kernel_count = 2;
    ok = ok && render(ren, &v, &k2);
    white_skin(n, false);
    if (ok) {
        RS_CHECK(drawn == n, "mobile drew %u splats, not all %u", drawn, n);
        edge_error e3 = shadow_edge_error(&shadow, &ref, &k3, 4), e2 = shadow_edge_error(&shadow, &ref, &k2, 4);
        // (measured on llvmpipe: K = 3 mean 1.55, 99th percentile 13. With the normal-offset shadow bias it
        // was 0.98 / 12; the receiver-plane bias of issue 12 draws cast-shadow edges where they belong and
        // fades the terminator's attached shadow, both sharper than before, so the band around them holds
        // more of the crease pixels where the two profiles differ most.)
        bool good = RS_CHECK(e3.n > 2000 && e3.mean <= 1.75 && e3.p99 <= 15, "K = 3 vs six Gaussians along the "
                             "shadow edges (%d px): mean error %.2f, 99th percentile %d linear 8-bit steps", e3.n,
                             e3.mean, e3.p99);
        good = RS_CHECK(e3.mean < e2.mean, "K = 3 (mean error %.2f) not closer than K = 2 (%.2f)", e3.mean, e2.mean) &&
               good;
        if (!good) save_pair("mobile_k3_edge", &ref, &k3);
    }
    rs_image_free(&shadow);
    rs_image_free(&ref);
    rs_image_free(&k3);
    rs_image_free(&k2);
}

// ---- LOD by projected density ----

static void test_lod_prefix_follows_projected_density(void)
{
    if (!need_face()) return;
    const rs_splat_header *h = &face->hdr;
    if (h->lod_count < 4) {
        rs_test_skip("the face has %u LOD levels", h->lod_count);
        return;
    }
    rs_view v = test_view(RS_MODE_FULL, 512);
    v.pipeline = RS_PIPELINE_MOBILE;
    uint32_t base = rs_render_auto_splats(ren, &v);
    RS_CHECK(base < h->count, "the default view draws all %u splats", base);
    // Denser asks for more, a sparser density for fewer.
    v.lod_density = 0.6f;
    uint32_t denser = rs_render_auto_splats(ren, &v);
    v.lod_density = 0.15f;
    uint32_t sparser = rs_render_auto_splats(ren, &v);
    RS_CHECK(denser > base && sparser <= base, "density 0.15/0.3/0.6 give %u/%u/%u splats", sparser, base, denser);
    // Twice as close: four times the face's pixels, so a larger prefix.
    v.lod_density = 0;
    v.zoom = 2.0f;
    uint32_t zoomed = rs_render_auto_splats(ren, &v);
    RS_CHECK(zoomed > base, "zoom 2 draws %u splats, zoom 1 %u", zoomed, base);
    // A small view stops at two LOD levels below the cap (the tolerance's floor).
    v.zoom = 1.0f;
    v.width = v.height = 64;
    v.lod_density = 0.01f;
    uint32_t tiny = rs_render_auto_splats(ren, &v);
    RS_CHECK(tiny == h->lods[2], "a 64x64 view at density 0.01 draws %u splats, not LOD level 2 (%u)", tiny,
             h->lods[2]);
    // max_splats caps it; the reference pipeline ignores the density.
    v = test_view(RS_MODE_FULL, 512);
    v.pipeline = RS_PIPELINE_MOBILE;
    v.max_splats = h->lods[3];
    RS_CHECK(rs_render_auto_splats(ren, &v) <= h->lods[3], "max_splats %u not respected", h->lods[3]);
    v.max_splats = 0;
    v.pipeline = RS_PIPELINE_REFERENCE;
    RS_CHECK(rs_render_auto_splats(ren, &v) == h->count, "the reference pipeline decimates");
}

// The screen-area estimate behind the density (a sum over the coarsest LOD level) agrees with the pixels
// the face covers, and a frame draws the prefix rs_render_auto_splats announced.
static void test_face_area_estimate_matches_covered_pixels(void)
{
    if (!need_face()) return;
    for (int i = 0; i < 2; i++) {
        rs_view v = test_view(RS_MODE_ALBEDO, 256);
        v.pipeline = RS_PIPELINE_MOBILE;
        v.yaw_deg = views[i * 3][0], v.pitch_deg = views[i * 3][1];
        rs_image img = {0};
        if (!render(ren, &v, &img)) return;
        rs_render_stats st = rs_render_get_stats(ren);
        int fg = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) fg += !is_background(&img, x, y);
        RS_CHECK(fabs(st.face_pixels - fg) < 0.1 * fg, "yaw %g: estimated %.0f face pixels, %d covered",
                 v.yaw_deg, st.face_pixels, fg);
        RS_CHECK(st.splats_drawn == rs_render_auto_splats(ren, &v), "frame drew %u splats, auto_splats says %u",
                 st.splats_drawn, rs_render_auto_splats(ren, &v));
        rs_image_free(&img);
    }
}

// ---- robustness of the mobile paths ----

// Smaller radii on the decimated prefix (RS_MOBILE_COVER) still close the surface, frontal and from the side.
static void test_mobile_lod_leaves_no_holes(void)
{
    if (!need_face()) return;
    for (int i = 0; i < 2; i++) {
        rs_view v = test_view(RS_MODE_ALBEDO, 384);
        v.pipeline = RS_PIPELINE_MOBILE;
        v.yaw_deg = i ? 60.0f : 0.0f, v.pitch_deg = i ? 15.0f : 0.0f;
        rs_image img = {0};
        if (!render(ren, &v, &img)) return;
        int fg = 0, holes = rs_test_count_holes(&img, img.pixels, &fg);
        RS_CHECK(rs_render_get_stats(ren).splats_drawn < face->hdr.count, "no decimation at 384x384");
        RS_CHECK(holes == 0, "yaw %g: %d holes in %d face pixels (%u splats)", v.yaw_deg, holes, fg,
                 rs_render_get_stats(ren).splats_drawn);
        if (holes) rs_test_save("mobile_holes", &img);
        rs_image_free(&img);
    }
}

// The bare floor of the bench: the albedo mode draws no shadow map and no diffusion level, in either pipeline.
static void test_albedo_mode_skips_shadow_and_diffusion(void)
{
    if (!need_face()) return;
    rs_renderer *r = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(tf.gl)}, &r, &err) == RS_OK, "%s",
               err.msg);
    size_t bytes[3] = {0};
    for (int p = 0; p < 2; p++) {
        rs_view v = test_view(RS_MODE_ALBEDO, 256);
        v.pipeline = p ? RS_PIPELINE_MOBILE : RS_PIPELINE_REFERENCE;
        v.max_splats = p ? 0 : 74225;
        if (!RS_CHECK(rs_render_frame(r, &v, &err) == RS_OK, "%s", err.msg)) break;
        rs_render_stats st = rs_render_get_stats(r);
        RS_CHECK(st.diffusion_splats == 0 && st.kernel_count == 0, "albedo frame drew %u diffusion splats in %d levels",
                 st.diffusion_splats, st.kernel_count);
        bytes[p] = st.gpu_bytes;
    }
    // A lit frame then adds the shadow map (at least 1024^2 x 4 bytes) to what the renderer holds.
    rs_view v = test_view(RS_MODE_DIFFUSE, 256);
    v.pipeline = RS_PIPELINE_MOBILE;
    if (RS_CHECK(rs_render_frame(r, &v, &err) == RS_OK, "%s", err.msg)) {
        bytes[2] = rs_render_get_stats(r).gpu_bytes;
        RS_CHECK(bytes[0] == bytes[1] && bytes[2] >= bytes[1] + 1024u * 1024u * 4u, "GPU bytes after albedo "
                 "(reference, mobile) and a lit frame: %zu, %zu, %zu", bytes[0], bytes[1], bytes[2]);
        RS_CHECK(rs_render_get_stats(r).kernel_count > 0, "the diffuse frame drew no diffusion level");
    }
    rs_render_destroy(r);
}

// Reduced-resolution levels at a size that does not divide by 4, and the upsampling at the silhouette: the
// image stays close to the reference (no seams, no dark rims where reduced samples fall off the face).
static void test_reduced_resolution_levels_at_odd_size(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_DIFFUSE, 0);
    v.width = 403, v.height = 317;  // the wide Gaussian at half size: 202x159
    v.lod_density = 1000.0f;  // all splats: what differs is stage 4
    rs_image ref = {0}, mob = {0};
    v.pipeline = RS_PIPELINE_REFERENCE;
    bool ok = render(ren, &v, &ref);
    v.pipeline = RS_PIPELINE_MOBILE;
    ok = ok && render(ren, &v, &mob);
    if (ok) {
        rs_image_metrics m;
        rs_error err = {0};
        RS_REQUIRE(rs_image_compare(&ref, &mob, 16, &m, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(m.psnr >= 44.0 && m.frac_over <= 0.002, "403x317: PSNR %.2f dB, %.2f%% pixels off by > 16", m.psnr,
                 100 * m.frac_over);
        if (m.psnr < 44.0 || m.frac_over > 0.002) save_pair("mobile_odd_size", &ref, &mob);
    }
    rs_image_free(&ref);
    rs_image_free(&mob);
}

// The mobile pipeline on the RGBA8 fallback (no float targets): it runs and stays near the float path.
static void test_mobile_rgba8_fallback_runs_and_is_close(void)
{
    if (!need_face()) return;
    rs_renderer *r8 = NULL;
    rs_error err = {0};
    rs_render_desc desc = {.cloud = face, .caps = rs_gl_get_caps(tf.gl), .force_no_float_targets = true};
    RS_REQUIRE(rs_render_create(&desc, &r8, &err) == RS_OK, "%s", err.msg);
    rs_view v = test_view(RS_MODE_FULL, 256);
    v.pipeline = RS_PIPELINE_MOBILE;
    rs_image a = {0}, b = {0};
    if (render(ren, &v, &a) && render(r8, &v, &b)) {
        rs_image_metrics m;
        RS_REQUIRE(rs_image_compare(&a, &b, 16, &m, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(m.psnr >= 30.0 && m.ssim >= 0.93, "mobile RGBA8 vs float: PSNR %.1f dB, SSIM %.3f", m.psnr, m.ssim);
        if (m.psnr < 30.0 || m.ssim < 0.93) save_pair("mobile_rgba8", &a, &b);
    }
    rs_image_free(&a);
    rs_image_free(&b);
    rs_render_destroy(r8);
}

// Picking in the mobile pipeline finds a splat of the prefix it draws; switching pipelines keeps both
// working (each has its own shadow map and ID buffer geometry).
static void test_mobile_pick_returns_splat_of_drawn_prefix(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_FULL, 256);
    v.pipeline = RS_PIPELINE_MOBILE;
    uint32_t n = rs_render_auto_splats(ren, &v), got = UINT32_MAX;
    RS_REQUIRE(rs_render_pick(ren, &v, 128.0f, 128.0f, &got, NULL), "no splat at the centre of the face");
    RS_CHECK(got < n, "picked splat %u outside the mobile prefix of %u", got, n);
    v.pipeline = RS_PIPELINE_REFERENCE;
    RS_CHECK(rs_render_pick(ren, &v, 128.0f, 128.0f, &got, NULL) && got < face->hdr.count, "reference pick failed");
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    if (!rs_test_face_open("mobile", &tf)) return 1;
    face = tf.cloud, ren = tf.ren;
    RS_RUN(test_lod_prefix_follows_projected_density);
    RS_RUN(test_face_area_estimate_matches_covered_pixels);
    RS_RUN(test_mobile_lod_leaves_no_holes);
    RS_RUN(test_albedo_mode_skips_shadow_and_diffusion);
    RS_RUN(test_mobile_pick_returns_splat_of_drawn_prefix);
    RS_RUN(test_reduced_resolution_levels_at_odd_size);
    RS_RUN(test_mobile_rgba8_fallback_runs_and_is_close);
    RS_RUN(test_k3_fit_matches_six_gaussians_at_a_shadow_edge);
    RS_RUN(test_mobile_matches_reference_within_tolerance_at_256);
    RS_RUN(test_mobile_matches_reference_under_environments);
    rs_test_face_close(&tf);
    return rs_test_finish();
}
