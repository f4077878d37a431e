// test_truth.c — rouge against the path tracer (issue 22): the bundled face in the reference pipeline under
// every bundled environment, from the views of tests/fixtures/truth/ (Blender Cycles renders of the scan
// face.rsf was made from, at rouge's own camera; tools/truth/, `make truth`; what differs: tests/fixtures/truth/README.md).
//
// Per view, at matched exposure (the one factor k on the path tracer's radiance that makes the median ratio of
// rouge's scene-linear luminance to its own over the face 1; rouge's frame is taken back through its sRGB
// encoding and tone curve, the path tracer's goes forward through them):
//   - mean CIEDE2000 over the face, both images blurred by a Gaussian of sigma 1 px;
//   - path tracer / rouge mean scene-linear luminance under the chin, on the lips, ears, nose, eye sockets
//     (the fixture's label plane: .rsf regions of the nearest splat, ears and under-chin by geometry);
//   - rouge / path tracer mean luminance of the contour band (3 px inside the silhouette and on the near side
//     of depth steps over 10 mm: where rouge drew dark outlines), over pixels both cover fully;
//   - glare: the share of the face where rouge is brighter than the path tracer by dE > 10 (a sheen or
//     highlight the reference does not show), held to what it was.
// Issue 22's goals: mean dE <= 2.0, every ratio within [0.87, 1.15], the band no darker (>= 1). Where a goal
// is not met the test guards the number measured when the fixtures were made (the `was` table) against
// regressions and reports the goal as a skip. Also checked: the silhouettes agree (IoU) and rouge's albedo
// view matches the path tracer's albedo, so a mismatch there is not mistaken for lighting.
// rouge | path tracer | dE map | band map PNGs go to the test output folder (truth_ENV_VIEW.png); the band
// map shows rouge / path tracer per band pixel over rouge's grey luminance: blue where rouge is darker,
// red where brighter, full colour at 25 %. The band is also split at the lips' lowest row: under the jaw
// (the jaw's and chin's underside and the neck's edges) and above it (scalp, ears, face outline, nose), and
// into the outline (within 4 px of the reference's) and the depth steps inside the face; the band's +-
// is the reference's sampling noise on it (one standard error).
#include "support/harness.h"
#include "gl/gl.h"
#include "rouge.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#define FACE "assets/face.rsf"
#define FIXTURES "tests/fixtures/truth"
#define HEADER 68
// Label plane values (tools/truth/render.py).
#define LABEL_REGION0 1
#define LABEL_EARS 16
#define LABEL_UNDER_CHIN 17
#define LABEL_CONTOUR 128
#define REGION_NOSE 2
#define REGION_LIPS 4
#define REGION_FOREHEAD 3
#define REGION_EYELID 5

enum { R_CHIN, R_LIPS, R_EARS, R_NOSE, R_EYES, R_COUNT };
static const char *region_names[R_COUNT] = {"under chin", "lips", "ears", "nose", "eye sockets"};

// What rouge measured last (the regression guards; updated when a change improves them).
typedef struct measured {
    const char *env, *view;
    double delta_e, ratio[R_COUNT], band, glare;
    double dark_other;  // front views: the darkest tenth on the side the key does not reach (0: not checked)
} measured;
static const measured was[] = {
    // Measured with Burley's diffuse retro-reflection under environments and blocked reflections showing
    // the skin they run into (composite.frag.glsl; before: band 0.876-0.978 in 7 of 8 views, dE studio
    // 1.91 / 1.86, daylight 1.67 / 1.46, office 1.85 / 1.59, sunset 1.78 / 1.59), the band without rouge's
    // anti-aliased silhouette pixels, the lobe's occluded share reflecting the skin around (the bounce: dE
    // 0.01-0.05 lower in every view), and the environment's lamps reflected exactly and out of the map
    // (env_light.glsl, render_env.c): studio front's wet temple sheen, the map's blur of the back lamp
    // below the temple's horizon, is gone (dE 1.57 -> 1.40); studio 3/4's ears ~3 % brighter (0.951 ->
    // 0.925), its dE 1.72 -> 1.77. Daylight front and studio 3/4 stay under 1 by the band under the jaw
    // (0.985, 0.983), which the reference's skin lights mostly by reflecting the body below it, out of
    // reach of rouge's screen-space march (tests/fixtures/truth/README.md). Glare: the temple's sheen made
    // 1.13 % of studio front's face brighter than the reference by dE > 10; 0.41 after.
    // The environment's specular as one lookup from N.V 0.6 (was 0.8): office 1.50 / 1.53 -> 1.47 / 1.46.
    // Fixtures re-rendered with the subsurface radius that scatters like rouge's profile (3.37 / 0.52 / 0.30
    // mm, was the profile's mean radius 1.12 / 0.26 / 0.17 mm, which carried a third of it into shadows;
    // tools/truth/sss_calibrate.py) at 1024 samples (was 256): rouge unchanged, dE studio 1.40 / 1.76 ->
    // 1.33 / 1.61, daylight 1.22 / 1.38 -> 1.23 / 1.35, office 1.47 / 1.46 -> 1.41 / 1.38, sunset 1.18 /
    // 1.35 -> 1.18 / 1.33 (at 256 samples the calibrated walks' noise added 0.15-0.35 to each).
    // The environment's SH light through bent cones (the splats' bent normals, env_light.glsl rs_env_sky;
    // before: the hemisphere around the normal times the occlusion): dE studio 1.33 / 1.61 -> 1.31 / 1.64,
    // daylight 1.23 / 1.35 -> 1.15 / 1.16, office 1.41 / 1.38 -> 1.49 / 1.38, sunset 1.18 / 1.33 -> 0.88 /
    // 0.98 (with the bent normal per pixel in an RGBA8 target: 1.31 / 1.64, 1.14 / 1.17, 1.49 / 1.38, 0.89 /
    // 0.99); band studio 3/4 0.994 -> 1.001, daylight 0.993 / 1.005 -> 0.997 / 1.001 (which of 0.999 and
    // 1.001 daylight 3/4 reads is the per-pixel bent normal's storage precision, not the light).
    // A reflection that runs off the frame unblocked asks the splat's bent cone (composite.frag.glsl; the
    // neck under the jaw, cut off by the frame, which the path tracer's skin mirrors): dE studio 1.31 / 1.64
    // -> 1.29 / 1.61, daylight 1.14 / 1.17 -> 1.12 / 1.15, office 1.49 / 1.38 -> 1.44 / 1.37, sunset 0.89 /
    // 0.99 -> 0.87 / 0.96; bands within 0.002. Daylight front's band under the jaw stays 0.991: at 768 px
    // the reference's skin there is lit 3x more by its specular (its glossy passes: reflecting the neck)
    // while rouge's reflection march and bent cone both find that direction open.
    // The contours inside the face anti-aliased (edges.frag.glsl): the first pixel of a step's near side now
    // shows some of the surface behind it, which under the jaw is darker than the path tracer's neck: band
    // daylight front 0.998 -> 0.997 (inner steps 0.991 -> 0.989), the others within 0.002; dE within 0.01.
    // The outline anti-aliased by the same pass (the composite's 3x3 rule before), and rouge's partly
    // covered pixels found by rendering over black and white (before: a face pixel with background in
    // its 3x3): band daylight front 0.997 -> 0.999 (under the jaw 0.992 -> 0.997), the others within 0.002
    // (studio front 1.133 -> 1.134); IoU unchanged; glare studio front 0.21 -> 0.27 %.
    // Reflections that run off the frame marched through the cloud's grid (composite.frag.glsl body_seen:
    // the neck, shoulders and chest below the frame, lit through the shadow maps) instead of asking the
    // splat's bent cone: dE studio 1.31 / 1.62 -> 1.28 / 1.56, daylight 1.13 / 1.16 -> 1.11 / 1.12, office
    // 1.49 / 1.38 -> 1.44 / 1.38, sunset 0.88 / 0.97 -> 0.86 / 0.92; every band up (daylight front 0.9984
    // -> 0.9999, under the jaw 0.9975 -> 1.0104; studio 3/4 1.0002 -> 1.0017); under the chin rouge now a
    // little brighter than the reference (0.940-1.020); studio 3/4's ears 0.981 -> 0.963.
    // Fixtures re-rendered as the mean of two independent renders (Cycles seeds 1 and 2, 1024 samples
    // each; tools/truth/render.py SEEDS): rouge unchanged, the reference's noise halved in variance: dE
    // 0.04-0.08 lower in every view (studio 1.28 / 1.56 -> 1.22 / 1.48, daylight 1.11 / 1.12 -> 1.07 /
    // 1.07, office 1.44 / 1.38 -> 1.40 / 1.32, sunset 0.86 / 0.92 -> 0.83 / 0.87), ratios and bands within
    // 0.007 (daylight front's band 0.9999 against both; against seed 2 alone 0.9983).
    // The bounce lit by the walls each occluded pixel sees (composite.frag.glsl surround_seen) instead of
    // the face's mean front light: dE studio 1.22 / 1.48 -> 1.19 / 1.46, daylight 1.07 / 1.07 -> 1.06 /
    // 1.03, office 1.40 / 1.32 -> 1.40 / 1.31, sunset 0.83 / 0.87 -> 0.83 / 0.86; every band up (daylight
    // front 0.9999 -> 1.0010); eye sockets and ears darker against the reference (daylight front 1.031 ->
    // 1.054, 1.030 -> 1.038; studio 3/4's ears 0.960 -> 0.986).
    {"studio", "front", 1.19, {1.000, 1.041, 0.979, 1.016, 1.011}, 1.154, 0.21, 1.045},
    {"studio", "threequarter", 1.46, {0.993, 1.054, 0.986, 1.036, 1.015}, 1.005, 0.00, 0},
    {"daylight", "front", 1.06, {0.963, 1.060, 1.038, 1.019, 1.054}, 1.001, 0.00, 1.019},
    {"daylight", "threequarter", 1.03, {0.938, 1.059, 1.022, 1.015, 1.049}, 1.008, 0.00, 0},
    {"office", "front", 1.40, {1.018, 1.056, 1.049, 1.009, 1.020}, 1.061, 0.13, 1.050},
    {"office", "threequarter", 1.31, {0.944, 1.048, 1.035, 0.991, 0.984}, 1.072, 0.02, 0},
    {"sunset", "front", 0.83, {0.985, 1.067, 1.022, 1.021, 1.034}, 1.016, 0.01, 0.998},
    {"sunset", "threequarter", 0.86, {0.988, 1.067, 1.015, 1.017, 1.034}, 1.011, 0.00, 0},
};
#define GOAL_DELTA_E 2.0
#define GOAL_RATIO_LO 0.87
#define GOAL_RATIO_HI 1.15
#define GOAL_BAND 1.0

static rs_gl_context *gl;
static rouge_face *face;
static int current;  // index into `was` of the view under test

typedef struct truth {
    int w, h;
    float yaw, pitch;
    float *rgb, *albedo;  // linear, w * h * 3, rows from the top
    uint8_t *alpha, *label;
} truth;

static float half_to_float(uint16_t h)
{
    int s = h >> 15, e = (h >> 10) & 31, m = h & 1023;
    float v = e == 0 ? ldexpf((float)m, -24) : e == 31 ? INFINITY : ldexpf((float)(m | 1024), e - 25);
    return s ? -v : v;
}

static void truth_free(truth *t)
{
    free(t->rgb), free(t->albedo), free(t->alpha), free(t->label);
    memset(t, 0, sizeof *t);
}

static bool truth_load(const char *env, const char *view, truth *t)
{
    char path[256];
    snprintf(path, sizeof path, "%s/%s_%s.rtf.zst", FIXTURES, env, view);
    void *z = NULL;
    size_t zlen = 0;
    rs_error err = {0};
    if (!RS_CHECK(rs_file_read_all(path, 64u << 20, &z, &zlen, &err) == RS_OK, "%s", err.msg)) return false;
    unsigned long long n = ZSTD_getFrameContentSize(z, zlen);
    bool ok = RS_CHECK(n != ZSTD_CONTENTSIZE_ERROR && n != ZSTD_CONTENTSIZE_UNKNOWN && n > HEADER && n < (64u << 20),
                       "%s: not a zstd frame of known size", path);
    uint8_t *d = ok ? malloc(n) : NULL;
    ok = ok && d && RS_CHECK(ZSTD_decompress(d, n, z, zlen) == n, "%s: damaged", path);
    free(z);
    if (!ok) {
        free(d);
        return false;
    }
    uint32_t w, h;
    memcpy(&w, d + 8, 4), memcpy(&h, d + 12, 4);
    size_t px = (size_t)w * h;
    ok = RS_CHECK(memcmp(d, "RSTRUTH1", 8) == 0 && w >= 16 && w <= 2048 && h >= 16 && h <= 2048 &&
                      n == HEADER + px * (6 + 6 + 1 + 1),
                  "%s: not a truth fixture (tools/truth/render.py)", path);
    if (ok) {
        t->w = (int)w, t->h = (int)h;
        memcpy(&t->yaw, d + 48, 4), memcpy(&t->pitch, d + 52, 4);
        t->rgb = malloc(px * 3 * sizeof(float));
        t->albedo = malloc(px * 3 * sizeof(float));
        t->alpha = malloc(px);
        t->label = malloc(px);
        ok = t->rgb && t->albedo && t->alpha && t->label;
    }
    if (ok) {
        const uint8_t *p = d + HEADER;
        for (size_t i = 0; i < px * 3; i++) {
            uint16_t a, b;
            memcpy(&a, p + 2 * i, 2), memcpy(&b, p + px * 6 + 2 * i, 2);
            t->rgb[i] = half_to_float(a), t->albedo[i] = half_to_float(b);
        }
        memcpy(t->alpha, p + px * 12, px);
        memcpy(t->label, p + px * 13, px);
    }
    free(d);
    if (!ok) truth_free(t);
    return ok;
}

static bool render(const rouge_view *v, uint8_t *rgba)
{
    rouge_error e = {0};
    if (!RS_CHECK(rouge_face_set_view(face, v, &e) == ROUGE_OK, "view: %s", e.msg)) return false;
    if (!RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render: %s", e.msg)) return false;
    return RS_CHECK(rouge_face_read_rgba(face, rgba, (size_t)v->width * v->height * 4, &e) == ROUGE_OK, "read: %s",
                    e.msg);
}

// rouge's tone curve (composite.frag.glsl: the ACES fit of Narkowicz 2015) and its inverse.
static double filmic(double x)
{
    x = fmax(x, 0.0);
    return fmin(fmax(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0), 1.0);
}

static double filmic_inverse(double y)
{
    // (2.43 y - 2.51) x^2 + (0.59 y - 0.03) x + 0.14 y = 0, the root >= 0 (y below the curve's limit 1.033).
    y = fmin(fmax(y, 0.0), 0.995);
    double a = 2.43 * y - 2.51, b = 0.59 * y - 0.03, c = 0.14 * y;
    return (-b - sqrt(b * b - 4 * a * c)) / (2 * a);
}

static double srgb_decode(double c) { return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4); }
static double srgb_encode(double c)
{
    c = fmin(fmax(c, 0.0), 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

static double lum(const double c[3]) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// Display-encoded sRGB (0..1) -> CIELAB, D65.
static void srgb_to_lab(const double s[3], double lab[3])
{
    double r = srgb_decode(s[0]), g = srgb_decode(s[1]), b = srgb_decode(s[2]);
    double xyz[3] = {(0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047, 0.2126 * r + 0.7152 * g + 0.0722 * b,
                     (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883};
    double f[3];
    for (int k = 0; k < 3; k++)
        f[k] = xyz[k] > 216.0 / 24389.0 ? cbrt(xyz[k]) : (24389.0 / 27.0 * xyz[k] + 16.0) / 116.0;
    lab[0] = 116.0 * f[1] - 16.0, lab[1] = 500.0 * (f[0] - f[1]), lab[2] = 200.0 * (f[1] - f[2]);
}

// Gaussian blur (sigma 1 px, radius 3) of a 3-channel image over the mask only: normalised convolution, so
// the background never bleeds into the face.
static void blur_masked(const double *in, const uint8_t *mask, int w, int h, double *out)
{
    double k[7], *tmp = calloc((size_t)w * h * 4, sizeof(double));
    for (int i = -3; i <= 3; i++) k[i + 3] = exp(-0.5 * i * i);
    if (!tmp) return;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc[4] = {0};
            for (int i = -3; i <= 3; i++) {
                int xx = x + i;
                if (xx < 0 || xx >= w || !mask[(size_t)y * w + xx]) continue;
                for (int c = 0; c < 3; c++) acc[c] += k[i + 3] * in[((size_t)y * w + xx) * 3 + c];
                acc[3] += k[i + 3];
            }
            memcpy(tmp + ((size_t)y * w + x) * 4, acc, sizeof acc);
        }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double acc[4] = {0};
            for (int i = -3; i <= 3; i++) {
                int yy = y + i;
                if (yy < 0 || yy >= h) continue;
                const double *t = tmp + ((size_t)yy * w + x) * 4;
                for (int c = 0; c < 4; c++) acc[c] += k[i + 3] * t[c];
            }
            for (int c = 0; c < 3; c++) out[((size_t)y * w + x) * 3 + c] = acc[3] > 0 ? acc[c] / acc[3] : 0.0;
        }
    free(tmp);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// dE 0 black, 5 red, 10 yellow, 15 and over white.
static void heat(double de, uint8_t *p)
{
    double t = fmin(de / 15.0, 1.0) * 3.0;
    p[0] = (uint8_t)lround(255 * fmin(t, 1.0));
    p[1] = (uint8_t)lround(255 * fmin(fmax(t - 1.0, 0.0), 1.0));
    p[2] = (uint8_t)lround(255 * fmin(fmax(t - 2.0, 0.0), 1.0));
}

typedef struct result {
    double k, iou, albedo_diff, delta_e, ratio[R_COUNT], band;
    double band_low, band_high;  // the band below the lips' lowest row (under the jaw) and above it
    double band_outline, band_inner;  // within 4 px of the outline, and at depth steps inside the face
    double band_noise;  // the path tracer's sampling noise on the band's ratio (one standard error)
    double forehead, highlights;  // path tracer / rouge: specular-dominated areas (diagnostics, not goals)
    double dark_key, dark_other;  // rouge / path tracer over the darkest tenth of a front view, by side
    double glare;                 // % of face pixels where rouge is brighter by dE > 10 (a sheen the reference lacks)
    int region_px[R_COUNT], band_px, band_low_px;
} result;

static int region_of(uint8_t label)
{
    int l = label & (LABEL_CONTOUR - 1);
    if (l == LABEL_UNDER_CHIN) return R_CHIN;
    if (l == LABEL_EARS) return R_EARS;
    if (l == LABEL_REGION0 + REGION_LIPS) return R_LIPS;
    if (l == LABEL_REGION0 + REGION_NOSE) return R_NOSE;
    if (l == LABEL_REGION0 + REGION_EYELID) return R_EYES;
    return -1;
}

// Renders rouge at the fixture's view and measures everything in `result`. false: a check failed.
static bool measure(const char *env, const truth *t, result *res, const char *png_name)
{
    int w = t->w, h = t->h;
    size_t n = (size_t)w * h;
    uint8_t *img = malloc(n * 4), *img_w = malloc(n * 4), *alb = malloc(n * 4), *mask = calloc(n, 1);
    uint8_t *face_px = calloc(n, 1), *partial = calloc(n, 1), *in_band = calloc(n, 1);
    double *ro = malloc(n * 3 * sizeof(double)), *pt = malloc(n * 3 * sizeof(double));
    double *rb = malloc(n * 3 * sizeof(double)), *pb = malloc(n * 3 * sizeof(double));
    double *ratio = malloc(n * sizeof(double)), *de = calloc(n, sizeof(double));
    bool ok = RS_CHECK(img && img_w && alb && mask && face_px && partial && in_band && ro && pt && rb && pb && ratio && de,
                       "out of memory");
    rouge_view v = {.width = w, .height = h, .yaw_deg = t->yaw, .pitch_deg = t->pitch, .env = env,
                    .pipeline = ROUGE_PIPELINE_REFERENCE, .background = {0, 0, 0, 1}};
    ok = ok && render(&v, img);
    // Over white too: a pixel that changes with the background is partly covered (the outline's
    // anti-aliasing), by the share it changes in linear light.
    v.background[0] = v.background[1] = v.background[2] = 1.0f;
    ok = ok && render(&v, img_w);
    v.background[0] = v.background[1] = v.background[2] = 0.0f;
    // The albedo view does not depend on the environment: checked once per view (under studio).
    bool check_albedo = strcmp(env, "studio") == 0;
    v.mode = ROUGE_MODE_ALBEDO;
    ok = ok && (!check_albedo || render(&v, alb));
    if (!ok) goto out;
    // Silhouettes: rouge's face is every pixel at least half covered; the reference's its alpha.
    size_t inter = 0, uni = 0;
    for (size_t i = 0; i < n; i++) {
        double bg = 0;
        for (int c = 0; c < 3; c++) bg += (srgb_decode(img_w[i * 4 + c] / 255.0) - srgb_decode(img[i * 4 + c] / 255.0)) / 3;
        face_px[i] = bg <= 0.5;
        partial[i] = memcmp(img + i * 4, img_w + i * 4, 3) != 0;
        bool a = face_px[i], b = t->alpha[i] >= 128;
        inter += a && b, uni += a || b;
    }
    res->iou = uni ? (double)inter / uni : 0.0;
    // The measured face: both cover the pixel fully, 2 px from any edge of the reference's coverage.
    for (int y = 2; y < h - 2; y++)
        for (int x = 2; x < w - 2; x++) {
            bool in = true;
            for (int dy = -2; dy <= 2 && in; dy++)
                for (int dx = -2; dx <= 2 && in; dx++) in = t->alpha[(size_t)(y + dy) * w + x + dx] == 255;
            size_t i = (size_t)y * w + x;
            mask[i] = in && face_px[i];
        }
    // Scene-linear rouge (back through sRGB and the tone curve) and the exposure factor k.
    size_t m = 0;
    double alb_sum = 0;
    size_t alb_n = 0;
    for (size_t i = 0; i < n; i++) {
        for (int c = 0; c < 3; c++) ro[i * 3 + c] = filmic_inverse(srgb_decode(img[i * 4 + c] / 255.0));
        if (!mask[i]) continue;
        const uint8_t *p = img + i * 4;
        double lr = lum(ro + i * 3), tp[3] = {t->rgb[i * 3], t->rgb[i * 3 + 1], t->rgb[i * 3 + 2]}, lp = lum(tp);
        if (p[0] < 250 && p[1] < 250 && p[2] < 250 && lp > 1e-4) ratio[m++] = lr / lp;
        for (int c = 0; c < 3 && check_albedo; c++)
            alb_sum += fabs(alb[i * 4 + c] / 255.0 - srgb_encode(t->albedo[i * 3 + c])), alb_n++;
    }
    if (!RS_CHECK(m > n / 10, "only %zu face pixels to compare", m)) {
        ok = false;
        goto out;
    }
    res->albedo_diff = alb_n ? alb_sum / (double)alb_n : -1.0;
    qsort(ratio, m, sizeof *ratio, cmp_double);
    res->k = ratio[m / 2];
    // Displayed images (0..1 sRGB): rouge's as read, the path tracer's through the same curve at k.
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            rb[i * 3 + c] = img[i * 4 + c] / 255.0;
            pt[i * 3 + c] = res->k * t->rgb[i * 3 + c];
            pb[i * 3 + c] = srgb_encode(filmic(pt[i * 3 + c]));
        }
    double *rblur = malloc(n * 3 * sizeof(double)), *pblur = malloc(n * 3 * sizeof(double));
    if (!RS_CHECK(rblur && pblur, "out of memory")) {
        free(rblur), free(pblur);
        ok = false;
        goto out;
    }
    blur_masked(rb, mask, w, h, rblur);
    blur_masked(pb, mask, w, h, pblur);
    double de_sum = 0;
    size_t de_n = 0;
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) continue;
        double la[3], lb[3];
        srgb_to_lab(rblur + i * 3, la);
        srgb_to_lab(pblur + i * 3, lb);
        de[i] = rs_ciede2000(la, lb);
        de_sum += de[i], de_n++;
    }
    free(rblur), free(pblur);
    res->delta_e = de_sum / (double)de_n;
    size_t glare = 0;
    for (size_t i = 0; i < n; i++)
        if (mask[i] && de[i] > 10.0 && lum(ro + i * 3) > lum(pt + i * 3)) glare++;
    res->glare = 100.0 * (double)glare / (double)de_n;
    // Region and contour luminance. The band compares surfaces, both fully covered: the path tracer's pixel
    // at coverage 255 (its radiance unpremultiplied), rouge's the same over black and over white (not one
    // of its anti-aliased outline pixels). Counting those compared a pixel part background with one all
    // skin: a difference of where the outline falls within a pixel (the IoU's business), not of the light;
    // it was a quarter of the band's deficit in the front views.
    double reg[R_COUNT][2] = {{0}}, band[2] = {0}, band_low[2] = {0}, band_out[2] = {0}, band_var = 0;
    memset(res->region_px, 0, sizeof res->region_px);
    res->band_px = res->band_low_px = 0;
    size_t jaw_row = n;  // first pixel index below the lips' lowest row (n: no lips in view)
    for (size_t i = 0; i < n; i++)
        if (region_of(t->label[i]) == R_LIPS) jaw_row = (i / (size_t)w + 1) * (size_t)w;
    for (size_t i = 0; i < n; i++) {
        int r = region_of(t->label[i]);
        if (r >= 0 && mask[i]) {
            reg[r][0] += lum(pt + i * 3), reg[r][1] += lum(ro + i * 3);
            res->region_px[r]++;
        }
        if ((t->label[i] & LABEL_CONTOUR) && t->alpha[i] == 255 && face_px[i] && !partial[i]) {
            band[0] += lum(ro + i * 3), band[1] += lum(pt + i * 3);
            res->band_px++;
            in_band[i] = 1;
            if (i >= jaw_row) band_low[0] += lum(ro + i * 3), band_low[1] += lum(pt + i * 3), res->band_low_px++;
            int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
            bool outline = false;
            for (int dy = -4; dy <= 4 && !outline; dy++)
                for (int dx = -4; dx <= 4 && !outline; dx++) {
                    int xx = x + dx, yy = y + dy;
                    outline = xx < 0 || yy < 0 || xx >= w || yy >= h || t->alpha[(size_t)yy * w + xx] < 128;
                }
            if (outline) band_out[0] += lum(ro + i * 3), band_out[1] += lum(pt + i * 3);
            // The reference's per-pixel Monte Carlo noise: what is left of its luminance after the straight
            // line through its two neighbours, across and along (variance 1.5 sigma^2 for independent
            // noise; the image's own curvature adds to it, so this errs high).
            if (x > 0 && y > 0 && x < w - 1 && y < h - 1) {
                double ph = lum(pt + i * 3) - 0.5 * (lum(pt + (i - 1) * 3) + lum(pt + (i + 1) * 3));
                double pv = lum(pt + i * 3) - 0.5 * (lum(pt + (i - (size_t)w) * 3) + lum(pt + (i + (size_t)w) * 3));
                band_var += 0.5 * (ph * ph + pv * pv) / 1.5;
            }
        }
    }
    for (int r = 0; r < R_COUNT; r++) res->ratio[r] = reg[r][1] > 0 ? reg[r][0] / reg[r][1] : 0.0;
    // Where the specular shows (the fixtures have no specular pass): the forehead, and the highlights, the
    // 3 % of face pixels brightest in the path tracer relative to their albedo (the lit rim, the nose's ridge).
    double fh[2] = {0}, hl[2] = {0};
    size_t shade_n = 0;
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) continue;
        double a[3] = {t->albedo[i * 3], t->albedo[i * 3 + 1], t->albedo[i * 3 + 2]};
        ratio[shade_n++] = lum(pt + i * 3) / fmax(lum(a), 1e-3);
        if ((t->label[i] & (LABEL_CONTOUR - 1)) == LABEL_REGION0 + REGION_FOREHEAD)
            fh[0] += lum(pt + i * 3), fh[1] += lum(ro + i * 3);
    }
    qsort(ratio, shade_n, sizeof *ratio, cmp_double);
    double shade_hi = ratio[shade_n - 1 - shade_n * 3 / 100];
    for (size_t i = 0; i < n; i++) {
        if (!mask[i]) continue;
        double a[3] = {t->albedo[i * 3], t->albedo[i * 3 + 1], t->albedo[i * 3 + 2]};
        if (lum(pt + i * 3) / fmax(lum(a), 1e-3) >= shade_hi) hl[0] += lum(pt + i * 3), hl[1] += lum(ro + i * 3);
    }
    // The darkest tenth of a front view's face (by the path tracer's luminance), on the side the key light
    // reaches (rouge-env turns it to yaw -35: the picture's left) and on the other: the hollows whose
    // walls the key lights and those whose walls it does not. A bounce lit by the face's mean light for
    // every hollow drew the other side's 1.00-1.09 of the path tracer's (composite.frag.glsl surround_seen).
    res->dark_key = res->dark_other = 0.0;
    if (t->yaw == 0.0f) {
        size_t m = 0;
        for (size_t i = 0; i < n; i++)
            if (t->alpha[i] == 255 && face_px[i] && !partial[i]) ratio[m++] = lum(pt + i * 3);
        qsort(ratio, m, sizeof *ratio, cmp_double);
        double cut = m > 0 ? ratio[m / 10] : 0.0, side[2][2] = {{0}};
        for (size_t i = 0; i < n; i++) {
            if (t->alpha[i] != 255 || !face_px[i] || partial[i] || lum(pt + i * 3) >= cut) continue;
            int k = (int)(i % (size_t)w) >= w / 2;
            side[k][0] += lum(ro + i * 3), side[k][1] += lum(pt + i * 3);
        }
        res->dark_key = side[0][1] > 0 ? side[0][0] / side[0][1] : 0.0;
        res->dark_other = side[1][1] > 0 ? side[1][0] / side[1][1] : 0.0;
    }
    res->forehead = fh[1] > 0 ? fh[0] / fh[1] : 0.0;
    res->highlights = hl[1] > 0 ? hl[0] / hl[1] : 0.0;
    res->band = band[1] > 0 ? band[0] / band[1] : 0.0;
    res->band_low = band_low[1] > 0 ? band_low[0] / band_low[1] : 0.0;
    res->band_high = band[1] - band_low[1] > 0 ? (band[0] - band_low[0]) / (band[1] - band_low[1]) : 0.0;
    res->band_outline = band_out[1] > 0 ? band_out[0] / band_out[1] : 0.0;
    res->band_inner = band[1] - band_out[1] > 0 ? (band[0] - band_out[0]) / (band[1] - band_out[1]) : 0.0;
    res->band_noise = band[1] > 0 ? res->band * sqrt(band_var) / band[1] : 0.0;
    // rouge | path tracer | dE | band map (all over black).
    rs_image side = {0};
    if (rs_image_create(4 * w, h, 3, &side, NULL) == RS_OK) {
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                size_t i = (size_t)y * w + x;
                uint8_t *o = side.pixels + ((size_t)y * 4 * w + x) * 3;
                double a = t->alpha[i] / 255.0;
                for (int c = 0; c < 3; c++) {
                    o[c] = img[i * 4 + c];
                    o[3 * w + c] = (uint8_t)lround(255 * pb[i * 3 + c] * a);
                }
                heat(mask[i] ? de[i] : 0.0, o + 6 * w);
                uint8_t *b = o + 9 * w;
                double lp = lum(pt + i * 3), g = 0.5 * srgb_encode(lum(ro + i * 3));
                if (in_band[i] && lp > 1e-4) {
                    double d = fmin(fmax((lum(ro + i * 3) / lp - 1.0) / 0.25, -1.0), 1.0);
                    b[0] = (uint8_t)lround(255 * (d < 0 ? 1.0 + d : 1.0));
                    b[1] = (uint8_t)lround(255 * (1.0 - fabs(d)));
                    b[2] = (uint8_t)lround(255 * (d > 0 ? 1.0 - d : 1.0));
                } else {
                    b[0] = b[1] = b[2] = face_px[i] ? (uint8_t)lround(255 * g) : 0;
                }
            }
        rs_test_save(png_name, &side);
        rs_image_free(&side);
    }
out:
    free(img), free(img_w), free(alb), free(mask), free(face_px), free(partial), free(in_band);
    free(ro), free(pt), free(rb), free(pb), free(ratio), free(de);
    return ok;
}

static double outside(double r) { return r < GOAL_RATIO_LO ? GOAL_RATIO_LO - r : r > GOAL_RATIO_HI ? r - GOAL_RATIO_HI : 0; }

static void test_view(void)
{
    const measured *ref = &was[current];
    truth t = {0};
    if (!truth_load(ref->env, ref->view, &t)) return;
    result r = {0};
    char png[64];
    snprintf(png, sizeof png, "truth_%s_%s", ref->env, ref->view);
    bool ok = measure(ref->env, &t, &r, png);
    truth_free(&t);
    if (!ok) return;
    printf("# truth %s %s: k %.3f, silhouette IoU %.4f, albedo |diff| %.4f, mean dE2000 %.2f; path tracer / rouge:",
           ref->env, ref->view, r.k, r.iou, r.albedo_diff, r.delta_e);
    for (int i = 0; i < R_COUNT; i++)
        if (r.region_px[i] >= 20) printf(" %s %.3f", region_names[i], r.ratio[i]);
    printf("; contour band rouge / path tracer %.4f +- %.3f (%d px: under the jaw %.4f, %d px; above it %.4f; along"
           " the outline %.4f, at inner depth steps %.4f); specular areas, path tracer / rouge: forehead %.3f"
           " highlights %.3f; glare %.2f %% of the face", r.band, r.band_noise, r.band_px, r.band_low,
           r.band_low_px, r.band_high, r.band_outline, r.band_inner, r.forehead, r.highlights, r.glare);
    if (r.dark_other > 0)
        printf("; darkest tenth, rouge / path tracer: key side %.3f, other side %.3f", r.dark_key, r.dark_other);
    printf("\n");
    // The fixture is the scene rouge renders: same camera and outline, same albedo.
    RS_CHECK(r.iou >= 0.98, "silhouettes differ: IoU %.4f", r.iou);
    // albedo_diff -1: not checked under this environment.
    RS_CHECK(r.albedo_diff <= 0.03, "albedo differs by %.4f (mean |sRGB| difference)", r.albedo_diff);
    RS_CHECK(r.k > 0.5 && r.k < 2.0, "exposure factor %.3f: the fixture is not at rouge's scale", r.k);
    bool goal = r.delta_e <= GOAL_DELTA_E && r.band >= GOAL_BAND, held = true;
    char unmet[512] = "";
    size_t len = 0;
    if (r.delta_e > GOAL_DELTA_E) len += snprintf(unmet + len, sizeof unmet - len, " dE %.2f (goal <= 2.0)", r.delta_e);
    // A view that met the goal is held to it and to 0.25 over what it measured; one that did not, to the latter.
    double de_limit = ref->delta_e <= GOAL_DELTA_E ? fmin(GOAL_DELTA_E, ref->delta_e + 0.25) : ref->delta_e + 0.25;
    held &= RS_CHECK(r.delta_e <= de_limit, "mean dE %.2f (was %.2f, limit %.2f)", r.delta_e, ref->delta_e, de_limit);
    for (int i = 0; i < R_COUNT; i++) {
        if (r.region_px[i] < 20) continue;  // not in view
        if (outside(r.ratio[i]) > 0) {
            goal = false;
            len += snprintf(unmet + len, sizeof unmet - len, " %s %.3f", region_names[i], r.ratio[i]);
        }
        held &= RS_CHECK(outside(r.ratio[i]) <= outside(ref->ratio[i]) + 0.05, "%s: %.3f (was %.3f)",
                         region_names[i], r.ratio[i], ref->ratio[i]);
    }
    if (r.band < GOAL_BAND) len += snprintf(unmet + len, sizeof unmet - len, " contour band %.4f (goal >= 1)", r.band);
    held &= RS_CHECK(r.band >= fmin(GOAL_BAND, ref->band - 0.03), "contour band %.3f (was %.3f)", r.band, ref->band);
    // The jaw's underside reflects the body the frame cuts off (the reference pipeline's grid march,
    // composite.frag.glsl body_seen): daylight front's band under the jaw 1.010 with it, 0.998 with the bent
    // cone alone, its reflection of the sunlit neck and chest missing.
    if (!strcmp(ref->env, "daylight") && !strcmp(ref->view, "front"))
        held &= RS_CHECK(r.band_low >= 1.0, "contour band under the jaw %.4f: the body below the frame not "
                         "reflected (want >= 1)", r.band_low);
    // The shadowed side's hollows lit as if their walls were lit (the bounce's mean light) read 1.05-1.09
    // here in daylight and office.
    if (ref->dark_other > 0)
        held &= RS_CHECK(r.dark_other <= ref->dark_other + 0.015, "darkest tenth on the side the key does not "
                         "reach %.3f of the path tracer's (was %.3f)", r.dark_other, ref->dark_other);
    // A sheen or highlight the reference does not show (the temple's, before the lamps were reflected
    // exactly): more of the face brighter than the path tracer by dE > 10.
    held &= RS_CHECK(r.glare <= ref->glare + 0.3, "glare %.2f %% of the face (was %.2f %%)", r.glare, ref->glare);
    if (!goal && held) rs_test_skip("issue 22's goal not met yet (%s %s):%s", ref->env, ref->view, unmet);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - truth: no GLES 3 context (%s)\n", err.msg);
        return rs_test_finish();
    }
    rouge_error e = {0};
    if (rouge_face_create(&(rouge_face_desc){.path = FACE}, &face, &e) != ROUGE_OK) {
        printf("FAIL - truth: %s\n", e.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    for (current = 0; current < (int)(sizeof was / sizeof was[0]); current++) {
        char name[64];
        snprintf(name, sizeof name, "truth_%s_%s", was[current].env, was[current].view);
        rs_test_run(name, test_view);
    }
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
