// test_render.c — the reference pipeline, stage by stage, on the bundled face (assets/face.rsf; the
// environment variable RS_TEST_FACE may name another .rsf), drawn from an LOD prefix of at most 50k splats
// at 256x256 or less so each image costs well under a second on llvmpipe.
//
// Lit-image checks read linear output (rs_view.linear_output) so sums and ratios are in light units.
#include "support/harness.h"
#include "support/face_fixture.h"
#include "render/render.h"
#include "core/image.h"
#include "formats/env.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SIZE 256
#define MAX_SPLATS 50000

static rs_test_face tf;
static rs_splat_cloud *face;  // tf.cloud and tf.ren, by their short names
static rs_renderer *ren;

// ---- helpers ----

// Test view: 256^2, 50k splats, no ambient or fill, pure magenta background (never a skin colour).
static rs_view test_view(rs_render_mode mode)
{
    rs_view v = rs_view_defaults();
    v.width = v.height = SIZE;
    v.max_splats = MAX_SPLATS;
    v.mode = mode;
    v.ambient = 0.0f;
    v.background[0] = 1.0f, v.background[1] = 0.0f, v.background[2] = 1.0f;
    return v;
}

static bool need_face(void) { return rs_test_face_ready(&tf); }

static bool render(const rs_view *v, rs_image *img) { return rs_test_render(ren, v, img); }

static const uint8_t *px(const rs_image *img, int x, int y) { return img->pixels + ((size_t)y * img->width + x) * img->channels; }

static bool is_background(const rs_image *img, int x, int y)
{
    const uint8_t *p = px(img, x, y);
    return p[0] == 255 && p[1] == 0 && p[2] == 255;
}

static double lin(const rs_image *img, int x, int y, int c) { return px(img, x, y)[c] / 255.0; }

// Face pixels at least `margin` pixels away from the background (gradients at the silhouette are not
// what the lighting tests are about).
static bool interior(const rs_image *img, int x, int y, int margin)
{
    for (int dy = -margin; dy <= margin; dy++)
        for (int dx = -margin; dx <= margin; dx++) {
            int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= img->width || yy >= img->height || is_background(img, xx, yy))
                return false;
        }
    return true;
}

// The splat furthest along the face's forward axis: the nose tip on a front-facing head.
static uint32_t nose_tip(void)
{
    const float *f = face->hdr.forward;
    uint32_t best = 0;
    float best_d = -INFINITY;
    for (uint32_t i = 0; i < face->hdr.count; i++) {
        float d = face->pos[i][0] * f[0] + face->pos[i][1] * f[1] + face->pos[i][2] * f[2];
        if (d > best_d) best_d = d, best = i;
    }
    return best;
}

static void save_pair(const char *name, const rs_image *a, const rs_image *b)
{
    char n[128];
    snprintf(n, sizeof n, "%s.a", name);
    rs_test_save(n, a);
    snprintf(n, sizeof n, "%s.b", name);
    rs_test_save(n, b);
}

// Sum of squared finite differences of channel c of img / (div (per pixel) or 1), over interior pixels.
static double gradient_energy(const rs_image *img, const rs_image *div, int c, const rs_image *mask_img)
{
    double e = 0;
    for (int y = 0; y < img->height - 1; y++)
        for (int x = 0; x < img->width - 1; x++) {
            if (!interior(mask_img, x, y, 3)) continue;
            double v[3];
            int xs[3] = {x, x + 1, x}, ys[3] = {y, y, y + 1};
            for (int k = 0; k < 3; k++) {
                v[k] = lin(img, xs[k], ys[k], c);
                if (div) v[k] /= fmax(lin(div, xs[k], ys[k], c), 0.02);
            }
            e += (v[1] - v[0]) * (v[1] - v[0]) + (v[2] - v[0]) * (v[2] - v[0]);
        }
    return e;
}

// ---- stage 2: visibility ----

static void test_visibility_leaves_no_holes_inside_silhouette(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_ALBEDO);
    rs_image img = {0};
    if (!render(&v, &img)) return;
    int fg = 0, holes = rs_test_count_holes(&img, (const uint8_t[3]){255, 0, 255}, &fg);
    RS_CHECK(fg > SIZE * SIZE / 8, "the face covers only %d pixels", fg);
    RS_CHECK(holes == 0, "%d background pixels inside the silhouette (of %d face pixels)", holes, fg);
    if (holes) rs_test_save("render_holes", &img);
    rs_image_free(&img);
}

static void test_coarse_lod_and_side_view_have_no_holes(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_ALBEDO);
    v.max_splats = 20000;
    v.yaw_deg = 60.0f;
    v.pitch_deg = 15.0f;
    rs_image img = {0};
    if (!render(&v, &img)) return;
    int fg = 0, holes = rs_test_count_holes(&img, (const uint8_t[3]){255, 0, 255}, &fg);
    RS_CHECK(holes == 0, "%d holes at 20k splats, yaw 60 (%d face pixels)", holes, fg);
    if (holes) rs_test_save("render_holes_coarse", &img);
    rs_image_free(&img);
}

// A synthetic scene's cloud from its n splats (freed here), in millimetres, framed by face_height.
static rs_splat_cloud *scene_cloud(rs_splat *s, int n, float face_height)
{
    rs_splat_header h = {.mm_per_unit = 1.0f, .forward = {0, 0, 1}, .up = {0, 1, 0}, .face_height = face_height,
                         .region_count = RS_REGION_BUILTIN_COUNT};
    rs_splat_default_regions(&h);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, (uint32_t)n, &h, &c, &err) == RS_OK, "scene: %s", err.msg);
    free(s);
    return c;
}

// A renderer of a synthetic scene; NULL, the cloud destroyed, when either could not be made.
static rs_renderer *scene_renderer(rs_splat_cloud *c)
{
    rs_renderer *r = NULL;
    rs_error err = {0};
    rs_render_desc desc = {.cloud = c, .caps = rs_gl_get_caps(tf.gl)};
    if (c && RS_CHECK(rs_render_create(&desc, &r, &err) == RS_OK, "%s", err.msg)) return r;
    rs_splat_destroy(c);
    return NULL;
}

// A fold (the lower lip over the chin's hollow): sheet A (green) ends at x = 0 over sheet B (red), which
// lies 1.5 eps behind it, both sampled every S with the head's radius-to-spacing ratio (0.95 / 0.62 mm).
// A's last disks overhang its sampled extent by their radius, 1.5 S, and on the face their rims drew pale
// scallops over the hollow. Seen head-on in the albedo view, each row's switch from A to B must lie nearer
// the sampled edge (S / 2, halfway to the next sample) than the overhang's end: 0.96 S (before: 1.59 S,
// past the disks' rim, on every row).
#define FOLD_S 0.62f
#define FOLD_R (1.53f * FOLD_S)
static rs_splat_cloud *make_fold(void)
{
    enum { NX = 41, NY = 31 };
    rs_splat *s = calloc(2 * NX * NY, sizeof *s);
    if (!s) return NULL;
    int n = 0;
    // eps is half the median radius (render_view.c); B 1.5 eps behind: a separate layer, within the push.
    float depth = 0.75f * FOLD_R;
    for (int sheet = 0; sheet < 2; sheet++)
        for (int j = 0; j < NY; j++)
            for (int i = 0; i < NX; i++) {
                float x = (float)(i - (NX - 1) / 2) * FOLD_S;
                if (sheet == 0 && x > 0.0f) continue;
                rs_splat *p = &s[n++];
                p->pos[0] = x, p->pos[1] = (float)(j - (NY - 1) / 2) * FOLD_S, p->pos[2] = sheet ? -depth : 0.0f;
                p->normal[2] = 1.0f;
                p->radius = FOLD_R;
                p->rgb[sheet ? 0 : 1] = 200;
            }
    return scene_cloud(s, n, (float)NY * FOLD_S);
}

static void test_fold_edge_shows_the_surface_behind(void)
{
    rs_splat_cloud *fold = make_fold();
    rs_renderer *r = scene_renderer(fold);
    if (!r) return;
    rs_view v = test_view(RS_MODE_ALBEDO);
    v.max_splats = 0;
    rs_image img = {0};
    float edge[3] = {0}, next[3] = {FOLD_S, 0, 0}, e_px[2], n_px[2];
    if (rs_test_render(r, &v, &img) &&
        RS_CHECK(rs_render_project(r, &v, edge, e_px) && rs_render_project(r, &v, next, n_px), "projection")) {
        double per_s = n_px[0] - e_px[0], sum = 0, worst = 0;
        int rows = 0;
        int y0 = RS_MAX((int)(e_px[1] - 5 * per_s), 0), y1 = RS_MIN((int)(e_px[1] + 5 * per_s), img.height - 1);
        for (int y = y0; y <= y1; y++) {
            int x = RS_MAX((int)e_px[0], 0);
            while (x < img.width - 1 && px(&img, x, y)[1] >= px(&img, x, y)[0]) x++;
            double at = (x + 0.5 - e_px[0]) / per_s;
            sum += at, worst = fmax(worst, at), rows++;
        }
        double mean = rows ? sum / rows : 0;
        printf("# fold: A gives way to B %.2f S past A's last samples on average, %.2f at most (%.1f px per S; "
               "sampled edge 0.5 S, disks' rim %.2f S)\n", mean, worst, per_s, FOLD_R / FOLD_S);
        RS_CHECK(per_s > 4.0, "the fold is too small on screen (%.1f px per sample)", per_s);
        double limit = 0.5 * (0.5 + FOLD_R / FOLD_S);
        if (!RS_CHECK(mean < limit, "A overhangs B by %.2f S (its rim: %.2f S)", mean, FOLD_R / FOLD_S))
            rs_test_save("render_fold", &img);
    }
    rs_image_free(&img);
    rs_render_destroy(r);
    rs_splat_destroy(fold);
}

// A contour in front of more surface (the lip line, the nose's base, the ear's rim over the head): sheet A
// (green), its edge a straight line at STEP_TILT to the rows, 10 mm in front of sheet B (red), seen head-on;
// and the outline: A alone over the (magenta) background. A's grid is turned with its edge, so the edge is
// straight, not the sampling's staircase. Measured against the same view drawn 4 x 4 times larger without
// the edges pass and averaged down (a box filter's coverage): the anti-aliased picture's mean error on the
// pixels the edge crosses must be under half the picture's without the pass (one surface per pixel inside;
// the composite's 3x3 coverage rule at the outline). Measured: 0.25 and 0.41 of it.
#define STEP_S 0.1f
#define STEP_TILT 0.12f  // radians: a long run before each stair
static rs_splat_cloud *make_step(bool behind)
{
    enum { N = 161 };
    rs_splat *s = calloc(2 * N * N, sizeof *s);
    if (!s) return NULL;
    int n = 0;
    float c = cosf(STEP_TILT), sn = sinf(STEP_TILT), half = (float)(N - 1) / 2 * STEP_S;
    for (int sheet = 0; sheet < (behind ? 2 : 1); sheet++)
        for (int j = 0; j < N; j++)
            for (int i = 0; i < N; i++) {
                float u = (float)i * STEP_S - half, v = (float)j * STEP_S - half;
                if (sheet == 0 && v > 0.0f) continue;  // A: below its edge, on a turned grid
                rs_splat *p = &s[n++];
                p->pos[0] = sheet ? u : c * u - sn * v;
                p->pos[1] = sheet ? v : sn * u + c * v;
                p->pos[2] = sheet ? -10.0f : 0.0f;
                p->normal[2] = 1.0f;
                p->radius = 1.5f * STEP_S;
                p->rgb[sheet ? 0 : 1] = 200;
            }
    return scene_cloud(s, n, 0.5f * (float)N * STEP_S);
}

static double srgb_channel(uint8_t v)
{
    return rs_srgb_to_linear(v / 255.0f);
}

static void contour_is_anti_aliased(bool behind)
{
    const char *what = behind ? "step edge" : "outline";
    rs_splat_cloud *step = make_step(behind);
    rs_renderer *r = scene_renderer(step);
    if (!r) return;
    rs_error err = {0};
    rs_view v = test_view(RS_MODE_ALBEDO);
    v.max_splats = 0;
    rs_image smooth = {0}, sharp = {0}, big = {0}, truth = {0};
    bool ok = rs_test_render(r, &v, &smooth);
    v.sharp_contours = true;
    ok = ok && rs_test_render(r, &v, &sharp);
    v.width = v.height = 4 * SIZE;
    ok = ok && rs_test_render(r, &v, &big) &&
         RS_CHECK(rs_image_downsample(&big, 4, &truth, &err) == RS_OK, "%s", err.msg);
    if (ok) {
        // The pixels the edge crosses: neither A's pure green nor what lies beyond it (B's red, the
        // background's magenta) in the reference.
        double e_smooth = 0, e_sharp = 0;
        int n = 0;
        for (int y = 0; y < SIZE; y++)
            for (int x = SIZE / 4; x < 3 * SIZE / 4; x++) {
                const uint8_t *t = px(&truth, x, y);
                double g = srgb_channel(t[1]), rd = srgb_channel(t[0]);
                if (g < 0.03 || rd < 0.03) continue;
                for (int k = 0; k < 3; k++) {
                    e_smooth += fabs(srgb_channel(px(&smooth, x, y)[k]) - srgb_channel(t[k]));
                    e_sharp += fabs(srgb_channel(px(&sharp, x, y)[k]) - srgb_channel(t[k]));
                }
                n++;
            }
        printf("# %s: %d pixels crossed; mean error against 4x4 supersampling %.4f anti-aliased, %.4f without "
               "the edges pass (%.2f)\n", what, n, e_smooth / RS_MAX(n, 1) / 3, e_sharp / RS_MAX(n, 1) / 3,
               e_smooth / fmax(e_sharp, 1e-9));
        RS_CHECK(n > SIZE / 4, "%s: the edge crosses only %d pixels", what, n);
        if (!RS_CHECK(e_smooth < 0.5 * e_sharp, "%s: anti-aliased error %.4f, without the pass %.4f (limit half)", what,
                      e_smooth / RS_MAX(n, 1) / 3, e_sharp / RS_MAX(n, 1) / 3)) {
            rs_test_save(behind ? "render_step_smooth" : "render_outline_smooth", &smooth);
            rs_test_save(behind ? "render_step_truth" : "render_outline_truth", &truth);
        }
    }
    rs_image_free(&smooth);
    rs_image_free(&sharp);
    rs_image_free(&big);
    rs_image_free(&truth);
    rs_render_destroy(r);
    rs_splat_destroy(step);
}

static void test_contours_and_outline_are_anti_aliased(void)
{
    contour_is_anti_aliased(true);
    contour_is_anti_aliased(false);
}

// A reflection the face blocks (on a lip close-up, the upper lip's underside mirroring the lower lip in
// front of it; here turned over so that the open directions see the sky): sheet A (green) faces up and
// forward, sheet B (red) stands REFL_Z mm in front of it and above, so A's mirror directions run into B
// down to some depth on A. Each step of the reflections' march decides "blocked" at one pixel, so the
// blocked region ended in a sharp line, a copy of B's lower edge shifted by the step's projection (thin
// light lines along the upper lip). Under an environment, in the specular view, the blocked share must fade
// in over the lobe's width: along each column of A, no pixel-to-pixel change may exceed a quarter of the
// whole change from blocked to open (measured 0.20; before: 0.75).
#define REFL_S 0.4f
#define REFL_Z 25.0f
static rs_splat_cloud *make_ledge(void)
{
    enum { NX = 51, NA = 76, NB = 51 };
    rs_splat *s = calloc(NX * (NA + NB), sizeof *s);
    if (!s) return NULL;
    int n = 0;
    for (int sheet = 0; sheet < 2; sheet++)
        for (int j = 0; j < (sheet ? NB : NA); j++)
            for (int i = 0; i < NX; i++) {
                rs_splat *p = &s[n++];
                float x = (float)(i - (NX - 1) / 2) * REFL_S, v = (float)j * REFL_S;
                p->pos[0] = x;
                if (sheet == 0) {  // A: down its slope from B's lower edge, normal (0, 0.6, 0.8)
                    p->pos[1] = -0.8f * v, p->pos[2] = 0.6f * v;
                    p->normal[1] = 0.6f, p->normal[2] = 0.8f;
                } else {  // B: up from its lower edge, facing the camera
                    p->pos[1] = v, p->pos[2] = REFL_Z;
                    p->normal[2] = 1.0f;
                }
                p->radius = 1.5f * REFL_S;
                p->rgb[sheet ? 0 : 1] = 200;
            }
    return scene_cloud(s, n, 50.0f);
}

static void test_blocked_reflection_fades_in_over_the_lobe(void)
{
    rs_splat_cloud *ledge = make_ledge();
    rs_renderer *r = scene_renderer(ledge);
    if (!r) return;
    rs_error err = {0};
    rs_env *env = NULL;
    rs_image spec = {0}, alb = {0};
    rs_view v = test_view(RS_MODE_SPECULAR);
    v.max_splats = 0;
    v.no_shadows = true;  // B's shadow on A is another sharp edge
    bool ok = RS_CHECK(rs_env_load("assets/env/daylight.rse", &env, &err) == RS_OK, "%s", err.msg) &&
              RS_CHECK(rs_render_set_env(r, env, &err) == RS_OK, "%s", err.msg) && rs_test_render(r, &v, &spec);
    v.mode = RS_MODE_ALBEDO;
    ok = ok && rs_test_render(r, &v, &alb);
    if (ok) {
        double worst = 0, sum_range = 0;
        int cols = 0;
        for (int x = SIZE / 3; x < 2 * SIZE / 3; x += 4) {
            // A's pixels down the column, 3 px clear of its contours (B's lower edge, the background).
            double l[SIZE];
            int n = 0, y = 0;
            while (y < SIZE - 1 && !(px(&alb, x, y)[1] > 100 && px(&alb, x, y)[0] < 50)) y++;
            for (y += 3; y < SIZE - 1; y++) {
                bool a = true;
                for (int k = -3; k <= 3 && a; k++) {
                    const uint8_t *q = px(&alb, x, RS_CLAMP(y + k, 0, SIZE - 1));
                    a = q[1] > 100 && q[0] < 50;
                }
                if (!a) break;
                const uint8_t *q = px(&spec, x, y);
                l[n++] = 0.2126 * srgb_channel(q[0]) + 0.7152 * srgb_channel(q[1]) + 0.0722 * srgb_channel(q[2]);
            }
            double lo = 1e9, hi = -1e9, jump = 0;
            for (int i = 0; i < n; i++) {
                lo = fmin(lo, l[i]), hi = fmax(hi, l[i]);
                if (i) jump = fmax(jump, fabs(l[i] - l[i - 1]));
            }
            if (n < 20 || hi - lo < 1e-3) continue;
            worst = fmax(worst, jump / (hi - lo)), sum_range += hi - lo, cols++;
        }
        printf("# blocked reflection: %d columns, change blocked to open %.3f (linear), largest step between two "
               "pixels %.2f of it\n", cols, sum_range / RS_MAX(cols, 1), worst);
        RS_CHECK(cols > 10 && sum_range / cols > 0.02, "the scene shows no blocked reflection (%d columns)", cols);
        if (!RS_CHECK(worst < 0.25, "the blocked share jumps by %.2f of its change between two pixels", worst))
            rs_test_save("render_ledge_specular", &spec);
    }
    rs_image_free(&spec);
    rs_image_free(&alb);
    rs_env_destroy(env);
    rs_render_destroy(r);
    rs_splat_destroy(ledge);
}

static void test_points_and_quads_give_the_same_image(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_FULL);
    v.prim = RS_PRIM_POINTS;
    rs_image a = {0}, b = {0};
    if (!render(&v, &a)) return;
    RS_CHECK(rs_render_get_stats(ren).used_points, "forced points not used");
    v.prim = RS_PRIM_QUADS;
    if (render(&v, &b)) {
        RS_CHECK(!rs_render_get_stats(ren).used_points, "forced quads not used");
        rs_image_metrics m;
        rs_error err = {0};
        RS_REQUIRE(rs_image_compare(&a, &b, 2, &m, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(m.psnr >= 50.0 && m.frac_over <= 0.001, "points vs quads: PSNR %.1f dB, %.3f%% pixels off by > 2",
                 m.psnr, 100 * m.frac_over);
        if (m.psnr < 50.0) save_pair("render_points_quads", &a, &b);
    }
    rs_image_free(&a);
    rs_image_free(&b);
}

// ---- stage 1: shadow map ----

// Light from straight above the face: the nose shadows the philtrum.
static void test_shadow_darkens_region_under_nose(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_FULL);
    v.key.yaw_deg = 0.0f;
    v.key.pitch_deg = 60.0f;
    v.linear_output = true;
    rs_image lit = {0}, shadowed = {0}, vis = {0};
    if (!render(&v, &shadowed)) return;
    v.no_shadows = true;
    if (!render(&v, &lit)) goto done;
    v.no_shadows = false;
    v.mode = RS_MODE_SHADOW;
    if (!render(&v, &vis)) goto done;
    float tip[2];
    RS_REQUIRE(rs_render_project(ren, &v, face->pos[nose_tip()], tip), "nose tip behind the camera");
    // Between the nose and the mouth: 6-10% of the face height below the tip (the view shows the face
    // height at 80% of the image; the nose's own underside reaches ~5% below its tip).
    double fh = 0.8 * SIZE;
    int x0 = (int)(tip[0] - 0.025 * fh), x1 = (int)(tip[0] + 0.025 * fh);
    int y0 = (int)(tip[1] + 0.06 * fh), y1 = (int)(tip[1] + 0.10 * fh);
    double sum_lit = 0, sum_sh = 0, sum_vis = 0;
    int n = 0;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            if (x < 0 || y < 0 || x >= SIZE || y >= SIZE || is_background(&lit, x, y)) continue;
            for (int c = 0; c < 3; c++) sum_lit += lin(&lit, x, y, c), sum_sh += lin(&shadowed, x, y, c);
            sum_vis += lin(&vis, x, y, 0);
            n++;
        }
    RS_REQUIRE(n > 20, "under-nose box (%d..%d, %d..%d) has %d face pixels", x0, x1, y0, y1, n);
    RS_CHECK(sum_vis / n < 0.5, "under the nose only %.0f%% occluded", 100 * (1 - sum_vis / n));
    RS_CHECK(sum_sh < 0.8 * sum_lit, "under the nose: %.3f with shadows vs %.3f without", sum_sh / n, sum_lit / n);
    if (sum_sh >= 0.8 * sum_lit) save_pair("render_shadow_nose", &shadowed, &lit);
done:
    rs_image_free(&lit);
    rs_image_free(&shadowed);
    rs_image_free(&vis);
}

// Bias and PCF: a forehead facing the light is fully lit (no acne), with the light from above or the side.
static void test_shadow_map_has_no_acne_on_lit_forehead(void)
{
    if (!need_face()) return;
    float lights[3][2] = {{-35.0f, 30.0f}, {40.0f, 10.0f}, {0.0f, 60.0f}};  // the order: see main
    for (int l = 0; l < 3; l++) {
        rs_view v = test_view(RS_MODE_SHADOW);
        v.key.yaw_deg = lights[l][0];
        v.key.pitch_deg = lights[l][1];
        rs_image img = {0};
        if (!render(&v, &img)) return;
        // Forehead: 32-45% of the face height above the nose tip, +-8% across.
        float tip[2];
        RS_REQUIRE(rs_render_project(ren, &v, face->pos[nose_tip()], tip), "nose tip behind the camera");
        double fh = 0.8 * SIZE;
        int n = 0, dark = 0;
        for (int y = (int)(tip[1] - 0.45 * fh); y <= (int)(tip[1] - 0.32 * fh); y++)
            for (int x = (int)(tip[0] - 0.08 * fh); x <= (int)(tip[0] + 0.08 * fh); x++) {
                if (x < 0 || y < 0 || x >= SIZE || y >= SIZE || is_background(&img, x, y)) continue;
                n++;
                dark += px(&img, x, y)[0] < 242;  // visibility below 0.95
            }
        RS_CHECK(n > 100 && dark <= n / 200, "light yaw %g pitch %g: %d of %d forehead pixels in shadow",
                 lights[l][0], lights[l][1], dark, n);
        if (dark > n / 200) rs_test_save("render_shadow_acne", &img);
        rs_image_free(&img);
    }
}

// ---- stage 4: diffusion ----

// D (diffuse / albedo) has softer light-to-shadow transitions than the plain per-pixel N.L * shadow, and
// red light (the profile's wide Gaussians) reaches farther into the shadow than blue light.
static void test_diffusion_softens_terminator_and_red_reaches_farther(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_IRRADIANCE);
    v.key.yaw_deg = -60.0f;  // a long terminator across the face, and the nose's shadow
    v.key.pitch_deg = 20.0f;
    v.linear_output = true;
    rs_image irr = {0}, dif = {0}, alb = {0}, bright = {0};
    if (!render(&v, &irr)) return;
    v.mode = RS_MODE_DIFFUSE;
    if (!render(&v, &dif)) goto done;
    // The light that leaks into the shadow is a few percent: exposed x8 it isn't lost to 8-bit rounding.
    v.exposure = 8.0f;
    if (!render(&v, &bright)) goto done;
    v.mode = RS_MODE_ALBEDO;
    if (!render(&v, &alb)) goto done;
    // Red is the channel the profile spreads widest; green and blue spread less than a pixel here but
    // must not come out sharper than N.L.
    double g_irr = gradient_energy(&irr, NULL, 1, &irr), g_dif[3];
    for (int c = 0; c < 3; c++) g_dif[c] = gradient_energy(&dif, &alb, c, &irr);
    RS_CHECK(g_dif[0] < 0.8 * g_irr, "diffuse red gradient energy %.2f not below 0.8 x N.L's %.2f", g_dif[0], g_irr);
    RS_CHECK(g_dif[1] < 1.1 * g_irr && g_dif[2] < 1.1 * g_irr, "diffuse green/blue gradient energy %.2f/%.2f "
             "above N.L's %.2f", g_dif[1], g_dif[2], g_irr);
    // Light that arrived in the dark: D per channel over pixels that N.L * shadow leaves black, within
    // 4 pixels (~4 mm) of lit skin.
    double dark[3] = {0, 0, 0};
    int n = 0;
    for (int y = 4; y < SIZE - 4; y++)
        for (int x = 4; x < SIZE - 4; x++) {
            if (!interior(&irr, x, y, 3) || px(&irr, x, y)[1] > 2) continue;
            bool near_lit = false;
            for (int k = 0; k < 81 && !near_lit; k++) near_lit = px(&irr, x + k % 9 - 4, y + k / 9 - 4)[1] > 25;
            if (!near_lit) continue;
            for (int c = 0; c < 3; c++) dark[c] += lin(&bright, x, y, c) / 8.0 / fmax(lin(&alb, x, y, c), 0.02);
            n++;
        }
    RS_REQUIRE(n > 200, "only %d dark face pixels", n);
    RS_CHECK(dark[0] > 1.3 * dark[2], "light in the shadow: red %.2f, blue %.2f (mean over %d px)", dark[0] / n,
             dark[2] / n, n);
    if (g_dif[0] >= 0.8 * g_irr || dark[0] <= 1.3 * dark[2]) save_pair("render_diffusion", &bright, &irr);
done:
    rs_image_free(&bright);
    rs_image_free(&irr);
    rs_image_free(&dif);
    rs_image_free(&alb);
}

// Across the terminator, lit skin light leaks into the shadow side: the diffuse image is brighter than
// N.L just inside the shadow, and darker just inside the light (energy moves, it is not created).
static void test_diffusion_conserves_energy_on_average(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_IRRADIANCE);
    v.key.yaw_deg = -60.0f;
    v.key.pitch_deg = 20.0f;
    v.linear_output = true;
    rs_image irr = {0}, dif = {0}, alb = {0};
    if (!render(&v, &irr)) return;
    v.mode = RS_MODE_DIFFUSE;
    if (!render(&v, &dif)) goto done;
    v.mode = RS_MODE_ALBEDO;
    if (!render(&v, &alb)) goto done;
    double si = 0, sd = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            if (!interior(&irr, x, y, 3)) continue;
            si += lin(&irr, x, y, 1);
            sd += lin(&dif, x, y, 1) / fmax(lin(&alb, x, y, 1), 0.02);
        }
    RS_CHECK(fabs(sd / si - 1.0) < 0.08, "mean D / mean N.L = %.3f", sd / si);
done:
    rs_image_free(&irr);
    rs_image_free(&dif);
    rs_image_free(&alb);
}

// ---- stage 5: specular and composite ----

static double image_sum(const rs_image *img, int c)
{
    double s = 0;
    for (int y = 0; y < img->height; y++)
        for (int x = 0; x < img->width; x++) s += lin(img, x, y, c);
    return s;
}

static void test_specular_energy_doubles_with_rho_s(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_SPECULAR);
    v.linear_output = true;
    v.exposure = 6.0f;  // S peaks near 0.05: keep the doubled image below 1 without rounding it away
    v.background[0] = v.background[1] = v.background[2] = 0.0f;
    rs_image a = {0}, b = {0};
    if (!render(&v, &a)) return;
    v.rho_s_scale = 2.0f;
    if (render(&v, &b)) {
        double sa = image_sum(&a, 1), sb = image_sum(&b, 1);
        RS_CHECK(sa > 100.0, "specular image nearly black (sum %.1f)", sa);
        RS_CHECK(sb / sa > 1.9 && sb / sa < 2.1, "doubling rho_s scaled the specular energy by %.3f", sb / sa);
    }
    rs_image_free(&a);
    rs_image_free(&b);
}

// Same geometry, two region tables: with the nose's measured (m, rho_s) the nose's highlight is brighter
// than with the cheek's parameters (higher rho_s, sharper lobe), and cheek pixels don't change. Compared
// where the lobe is (pixels at >= 40% of the nose's peak): away from it a sharper lobe is darker.
static void test_nose_specular_brighter_than_cheek_at_matching_geometry(void)
{
    if (!need_face()) return;
    rs_splat_header *h = &face->hdr;
    if (face->region_counts[RS_REGION_NOSE] == 0 || face->region_counts[RS_REGION_CHEEK] == 0) {
        RS_CHECK(false, "the face has no nose or no cheek splats: region segmentation missing");
        return;
    }
    rs_view v = test_view(RS_MODE_REGIONS);
    // Light from the camera: the highlight sits where the surface faces the viewer (nose tip, cheeks).
    v.key.yaw_deg = 0.0f;
    v.key.pitch_deg = 5.0f;
    rs_image reg = {0}, a = {0}, b = {0};
    if (!render(&v, &reg)) return;
    v.mode = RS_MODE_SPECULAR;
    v.linear_output = true;
    v.exposure = 4.0f;
    if (!render(&v, &a)) goto done;
    rs_region_info nose = h->regions[RS_REGION_NOSE];
    h->regions[RS_REGION_NOSE] = h->regions[RS_REGION_CHEEK];
    bool ok = render(&v, &b);
    h->regions[RS_REGION_NOSE] = nose;
    if (!ok) goto done;
    // The regions view paints the nose green and the cheeks red (render_attribute.c palette).
    double peak = 0;
    for (int pass = 0; pass < 2; pass++) {
        double sn[2] = {0, 0}, sc[2] = {0, 0};
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++) {
                const uint8_t *p = px(&reg, x, y);
                bool is_nose = p[1] > 150 && p[0] < 110 && p[2] < 110;
                bool is_cheek = p[0] > 200 && p[1] < 120 && p[2] < 120;
                double sa = lin(&a, x, y, 1), sb = lin(&b, x, y, 1);
                if (pass == 0) {
                    if (is_nose) peak = fmax(peak, sb);
                    continue;
                }
                if (is_nose && sb >= 0.4 * peak) sn[0] += sa, sn[1] += sb;
                if (is_cheek) sc[0] += sa, sc[1] += sb;
            }
        if (pass == 0) continue;
        RS_REQUIRE(peak > 0.05 && sc[1] > 1.0, "no specular on the nose (peak %.3f) or cheeks (%.2f)", peak, sc[1]);
        RS_CHECK(sn[0] / sn[1] > 1.2, "nose highlight with its own parameters / with the cheek's = %.3f",
                 sn[0] / sn[1]);
        RS_CHECK(fabs(sc[0] / sc[1] - 1.0) < 0.02, "cheek specular changed by %.3f", sc[0] / sc[1]);
    }
done:
    rs_image_free(&reg);
    rs_image_free(&a);
    rs_image_free(&b);
}

// F = A (D + S) per pixel against the separately rendered albedo, diffuse (= A D) and specular (= S)
// images, and F = A D + S for the physical composite; linear 8-bit output, so within rounding. The
// contours' anti-aliasing mixes neighbours after the composite (a mix of products is not the product of
// mixes), so it is off here.
static void test_composite_is_albedo_times_diffuse_plus_specular(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_ALBEDO);
    v.linear_output = true;
    v.sharp_contours = true;
    v.exposure = 0.6f;  // keep F and S below 1 (no clamping)
    v.background[0] = v.background[1] = v.background[2] = 0.0f;
    rs_image A = {0}, D = {0}, S = {0}, F = {0}, P = {0};
    rs_image *imgs[5] = {&A, &D, &S, &F, &P};
    rs_render_mode modes[5] = {RS_MODE_ALBEDO, RS_MODE_DIFFUSE, RS_MODE_SPECULAR, RS_MODE_FULL, RS_MODE_FULL};
    for (int i = 0; i < 5; i++) {
        v.mode = modes[i];
        v.composite = i == 4 ? RS_COMPOSITE_PHYSICAL : RS_COMPOSITE_PAPER;
        if (!render(&v, imgs[i])) goto done;
    }
    int worst = 0, worst_phys = 0, n = 0, clipped = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++)
            for (int c = 0; c < 3; c++) {
                const uint8_t a = px(&A, x, y)[c], d = px(&D, x, y)[c], s = px(&S, x, y)[c];
                if (px(&F, x, y)[c] == 255 || s == 255) clipped++;
                double paper = d + a * s / 255.0, phys = d + s;
                worst = RS_MAX(worst, (int)lround(fabs(px(&F, x, y)[c] - paper)));
                worst_phys = RS_MAX(worst_phys, (int)lround(fabs(px(&P, x, y)[c] - fmin(phys, 255.0))));
                n += s > 0;
            }
    RS_CHECK(n > 500, "specular nearly absent (%d samples)", n);
    RS_CHECK(clipped == 0, "%d clipped samples: lower the exposure", clipped);
    // Each 8-bit image rounds by half a step: F, D, A and S together by at most 2.
    RS_CHECK(worst <= 2, "F vs A (D + S): largest difference %d/255", worst);
    RS_CHECK(worst_phys <= 2, "F vs A D + S: largest difference %d/255", worst_phys);
done:
    for (int i = 0; i < 5; i++) rs_image_free(imgs[i]);
}

static void test_rgba8_fallback_is_close_to_float_targets(void)
{
    if (!need_face()) return;
    rs_renderer *r8 = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_render_create(&(rs_render_desc){.cloud = face, .caps = rs_gl_get_caps(tf.gl),
                                                  .force_no_float_targets = true},
                                &r8, &err) == RS_OK,
               "%s", err.msg);
    rs_view v = test_view(RS_MODE_FULL);
    rs_image a = {0}, b = {0};
    if (render(&v, &a) && RS_CHECK(rs_render_image(r8, &v, &b, &err) == RS_OK, "%s", err.msg)) {
        RS_CHECK(!rs_render_get_stats(r8).float_targets, "fallback renderer reports float targets");
        rs_image_metrics m;
        // 8-bit blending is noisy where few splats overlap (render_attribute.c): a loose bound.
        RS_REQUIRE(rs_image_compare(&a, &b, 16, &m, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(m.psnr >= 33.0 && m.ssim >= 0.95 && m.frac_over < 0.04, "RGBA8 vs float: PSNR %.1f dB, SSIM %.3f, "
                 "%.2f%% pixels off by > 16", m.psnr, m.ssim, 100 * m.frac_over);
        if (m.psnr < 33.0 || m.ssim < 0.95 || m.frac_over >= 0.04) save_pair("render_rgba8", &a, &b);
    }
    rs_image_free(&a);
    rs_image_free(&b);
    rs_render_destroy(r8);
}

// ---- golden images: the paper's Fig. 7 modes from one view ----

static void golden(const char *name, rs_render_mode mode)
{
    if (!need_face()) return;
    rs_view v = test_view(mode);
    v.width = v.height = 192;
    v.background[0] = v.background[1] = v.background[2] = 0.16f;
    v.ambient = 0.06f;
    rs_image img = {0};
    // Rasterisation differs a little between GPUs: a few percent of pixels may differ by more than 10.
    if (render(&v, &img)) rs_test_golden(name, &img, 10, 0.03, 30.0);
    rs_image_free(&img);
}

static void test_golden_albedo(void) { golden("render_albedo", RS_MODE_ALBEDO); }
static void test_golden_diffuse(void) { golden("render_diffuse", RS_MODE_DIFFUSE); }
static void test_golden_full(void) { golden("render_full", RS_MODE_FULL); }

// ---- picking ----

static void test_pick_returns_visible_splat_under_pixel_and_false_on_background(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_FULL);
    uint32_t tip = nose_tip();
    float p[2];
    RS_REQUIRE(rs_render_project(ren, &v, face->pos[tip], p), "nose tip behind the camera");
    uint32_t got = UINT32_MAX;
    RS_REQUIRE(rs_render_pick(ren, &v, p[0], p[1], &got, NULL), "no splat at the nose tip (%.1f, %.1f)", p[0], p[1]);
    uint32_t n = rs_splat_lod_count(face, MAX_SPLATS);
    RS_CHECK(got < n, "picked splat %u outside the drawn prefix of %u", got, n);
    // The picked disk covers the clicked pixel: its projected centre is within its projected radius.
    float q[2];
    RS_REQUIRE(rs_render_project(ren, &v, face->pos[got], q), "picked splat behind the camera");
    float reach = face->radius[got] * rs_splat_lod_radius_scale(face, n) * 1.3f *
                  rs_render_pixels_per_unit(ren, &v, face->pos[got]) + 1.0f;
    float d = hypotf(q[0] - p[0], q[1] - p[1]);
    RS_CHECK(d <= reach, "picked splat's centre is %.2f px from the click, its disk reaches %.2f px", d, reach);
    // It is on the front surface: within a few radii of the tip along the view direction.
    float dir[3];
    rs_render_view_dir(ren, &v, face->pos[tip], dir);
    float along = 0;
    for (int a = 0; a < 3; a++) along += (face->pos[got][a] - face->pos[tip][a]) * dir[a];
    RS_CHECK(fabsf(along) < 4.0f * face->radius[got] * rs_splat_lod_radius_scale(face, n), "picked splat %.4f units "
             "off the front surface", along);
    uint32_t none = 7;
    RS_CHECK(!rs_render_pick(ren, &v, 2.0f, 2.0f, &none, NULL) && none == 7, "corner pixel picked splat %u", none);
    RS_CHECK(!rs_render_pick(ren, &v, -1.0f, 10.0f, &none, NULL) &&
                 !rs_render_pick(ren, &v, 10.0f, (float)SIZE, &none, NULL),
             "a pixel outside the view picked something");
}

// The stamp centre is the surface point under the pixel: it projects back onto the clicked pixel,
// where the picked splat's centre may be pixels away at coarse LOD.
static void test_pick_hit_point_projects_back_to_the_clicked_pixel(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_FULL);
    float worst = 0;
    int picked = 0;
    for (int y = SIZE / 4; y < 3 * SIZE / 4; y += SIZE / 16)
        for (int x = SIZE / 4; x < 3 * SIZE / 4; x += SIZE / 16) {
            uint32_t idx;
            float hit[3], q[2];
            if (!rs_render_pick(ren, &v, (float)x, (float)y, &idx, hit)) continue;
            picked++;
            RS_REQUIRE(rs_render_project(ren, &v, hit, q), "hit point behind the camera");
            worst = fmaxf(worst, hypotf(q[0] - ((float)x + 0.5f), q[1] - ((float)y + 0.5f)));
        }
    RS_CHECK(picked > 30, "only %d of the central pixels hit the face", picked);
    RS_CHECK(worst < 0.05f, "hit point projects %.3f px from the clicked pixel centre", worst);
}

// ---- API behaviour ----

static void test_bad_views_are_refused_with_a_message(void)
{
    if (!need_face()) return;
    rs_error err = {0};
    rs_view v = test_view(RS_MODE_FULL);
    v.width = 0;
    RS_CHECK(rs_render_frame(ren, &v, &err) == RS_ERR_ARG && strstr(err.msg, "size"), "width 0: %s", err.msg);
    v = test_view(RS_MODE_FULL);
    v.height = 1 << 20;
    RS_CHECK(rs_render_frame(ren, &v, &err) == RS_ERR_ARG, "height 2^20 accepted");
    v = test_view(RS_MODE_FULL);
    v.zoom = NAN;
    RS_CHECK(rs_render_frame(ren, &v, &err) == RS_ERR_ARG, "NaN zoom accepted");
    v = test_view(RS_MODE_FULL);
    v.mode = RS_MODE_COUNT;
    RS_CHECK(rs_render_frame(ren, &v, &err) == RS_ERR_ARG, "mode out of range accepted");
    uint8_t rec[8] = {0};
    RS_CHECK(rs_render_update_makeup(ren, face->hdr.count, 1, rec, &err) == RS_ERR_ARG, "makeup past the end");
    RS_CHECK(rs_render_update_makeup(ren, 1, UINT32_MAX, rec, &err) == RS_ERR_ARG, "makeup count overflow");
}

static void test_frame_restores_gl_state(void)
{
    if (!need_face()) return;
    glViewport(3, 4, 50, 60);
    rs_view v = test_view(RS_MODE_ALBEDO);
    v.width = v.height = 64;
    rs_error err = {0};
    RS_REQUIRE(rs_render_frame(ren, &v, &err) == RS_OK, "%s", err.msg);
    GLint vp[4], fbo = -1;
    glGetIntegerv(GL_VIEWPORT, vp);
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &fbo);
    RS_CHECK(vp[0] == 3 && vp[1] == 4 && vp[2] == 50 && vp[3] == 60, "viewport %d %d %d %d", vp[0], vp[1], vp[2], vp[3]);
    RS_CHECK(fbo == 0, "framebuffer %d left bound", fbo);
    RS_CHECK(!glIsEnabled(GL_BLEND) && !glIsEnabled(GL_DEPTH_TEST), "blend or depth test left on");
    int w = 0, h = 0;
    RS_CHECK(rs_render_output_texture(ren, &w, &h) != 0 && w == 64 && h == 64, "output texture %dx%d", w, h);
}

// A makeup record colours its splat's albedo; hide_makeup shows the base; zero records change nothing.
static void test_makeup_records_reach_the_attribute_pass(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_ALBEDO);
    rs_image base = {0}, painted = {0}, hidden = {0};
    if (!render(&v, &base)) return;
    uint32_t n = rs_splat_lod_count(face, MAX_SPLATS);
    rs_makeup_gpu *rec = calloc(n, sizeof *rec);
    RS_REQUIRE(rec != NULL, "out of memory");
    // Pure blue at full intensity on every drawn splat; the colour range clamp allows all of 0..1.
    for (uint32_t i = 0; i < n; i++) rec[i] = (rs_makeup_gpu){.rgb = {0, 0, 255}, .colour_i = 255, .flags = 128};
    rs_error err = {0};
    bool ok = RS_CHECK(rs_render_update_makeup(ren, 0, n, rec, &err) == RS_OK, "%s", err.msg);
    ok = ok && render(&v, &painted);
    v.hide_makeup = true;
    ok = ok && render(&v, &hidden);
    memset(rec, 0, n * sizeof *rec);
    RS_CHECK(rs_render_update_makeup(ren, 0, n, rec, &err) == RS_OK, "%s", err.msg);
    free(rec);
    if (ok) {
        int x = SIZE / 2, y = SIZE / 2;
        const uint8_t *p = px(&painted, x, y);
        RS_CHECK(p[2] > 200 && p[0] < 60, "painted centre pixel is %d %d %d, not blue", p[0], p[1], p[2]);
        rs_image_metrics m;
        RS_REQUIRE(rs_image_compare(&base, &hidden, 0, &m, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(m.max_abs == 0, "hide_makeup differs from the base by %d", m.max_abs);
    }
    rs_image_free(&base);
    rs_image_free(&painted);
    rs_image_free(&hidden);
}

static void test_debug_views_show_what_they_name(void)
{
    if (!need_face()) return;
    rs_view v = test_view(RS_MODE_NORMALS);
    rs_image nrm = {0}, lod = {0};
    if (!render(&v, &nrm)) return;
    float tip[2];
    RS_REQUIRE(rs_render_project(ren, &v, face->pos[nose_tip()], tip), "nose tip behind the camera");
    // At the nose tip the surface faces the camera: view-space normal ~ (0, 0, 1) -> (128, 128, 255).
    const uint8_t *p = px(&nrm, (int)tip[0], (int)tip[1]);
    RS_CHECK(p[2] > 220 && abs(p[0] - 128) < 60 && abs(p[1] - 128) < 60, "nose tip normal colour %d %d %d", p[0],
             p[1], p[2]);
    v.mode = RS_MODE_LOD;
    if (render(&v, &lod) && face->hdr.lod_count > 1) {
        // Several LOD levels are drawn, so several colours appear.
        int seen_red = 0, seen_other = 0;
        for (int y = 0; y < SIZE; y++)
            for (int x = 0; x < SIZE; x++) {
                if (is_background(&lod, x, y)) continue;
                const uint8_t *q = px(&lod, x, y);
                if (q[0] > 200 && q[1] < 80 && q[2] < 80) seen_red++;
                else seen_other++;
            }
        RS_CHECK(seen_red > 0 && seen_other > 0, "LOD view: %d coarsest-level pixels, %d others", seen_red, seen_other);
    }
    rs_image_free(&nrm);
    rs_image_free(&lod);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    if (!rs_test_face_open("render", &tf)) return 1;
    face = tf.cloud, ren = tf.ren;
    // Grouped by key light: the shadow map (4096^2, seconds on llvmpipe) is kept while the light stays, so
    // the default light (-35, 30) first (the RGBA8 check's float frame among them), then (40, 10) and
    // (0, 60) (the acne check ends on the shadow check's light), (-60, 20), (0, 5): 6 maps, not 8.
    RS_RUN(test_visibility_leaves_no_holes_inside_silhouette);
    RS_RUN(test_coarse_lod_and_side_view_have_no_holes);
    RS_RUN(test_points_and_quads_give_the_same_image);
    RS_RUN(test_fold_edge_shows_the_surface_behind);
    RS_RUN(test_contours_and_outline_are_anti_aliased);
    RS_RUN(test_blocked_reflection_fades_in_over_the_lobe);
    RS_RUN(test_specular_energy_doubles_with_rho_s);
    RS_RUN(test_composite_is_albedo_times_diffuse_plus_specular);
    RS_RUN(test_rgba8_fallback_is_close_to_float_targets);
    RS_RUN(test_golden_albedo);
    RS_RUN(test_golden_diffuse);
    RS_RUN(test_golden_full);
    RS_RUN(test_pick_returns_visible_splat_under_pixel_and_false_on_background);
    RS_RUN(test_pick_hit_point_projects_back_to_the_clicked_pixel);
    RS_RUN(test_bad_views_are_refused_with_a_message);
    RS_RUN(test_frame_restores_gl_state);
    RS_RUN(test_makeup_records_reach_the_attribute_pass);
    RS_RUN(test_debug_views_show_what_they_name);
    RS_RUN(test_shadow_map_has_no_acne_on_lit_forehead);
    RS_RUN(test_shadow_darkens_region_under_nose);
    RS_RUN(test_diffusion_softens_terminator_and_red_reaches_farther);
    RS_RUN(test_diffusion_conserves_energy_on_average);
    RS_RUN(test_nose_specular_brighter_than_cheek_at_matching_geometry);
    rs_test_face_close(&tf);
    return rs_test_finish();
}
