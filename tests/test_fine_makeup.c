// test_fine_makeup.c — makeup as a makeup artist judges it, through the public face (issue 21): an
// opaque liner is one crisp, dark line of even width on both sides of a mirrored stroke (the fine layer:
// narrow brushes evaluated per pixel), gloss over lipstick reads in the default front view, a highlighter
// is a sheen without specks, lipstick fills each lip to its border without spill. Close-ups are written to
// RS_TEST_OUT (or build/test-out) for people to look at.
#include "support/harness.h"
#include "gl/gl.h"
#include "rouge.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#define FACE_PATH "assets/face.rsf"

static rouge_face *face;

static double lum(const uint8_t *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static bool render(int w, int h, uint8_t **out)
{
    rouge_error e = {0};
    *out = malloc((size_t)w * h * 4);
    return *out && rouge_face_render(face, &e) == ROUGE_OK &&
           rouge_face_read_rgba(face, *out, (size_t)w * h * 4, &e) == ROUGE_OK;
}

static void save(const char *name, const uint8_t *rgba, int w, int h)
{
    rs_image img = {.width = w, .height = h, .channels = 4, .pixels = (uint8_t *)rgba};
    rs_test_save(name, &img);
}

static void stroke(float x0, float y0, float x1, float y1, int steps)
{
    rouge_error e = {0};
    for (int i = 0; i <= steps; i++) {
        float t = (float)i / (float)steps;
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : ROUGE_POINTER_MOVE, 0, x0 + (x1 - x0) * t,
                                  y0 + (y1 - y0) * t, 1.0f, i / 60.0};
        rouge_face_pointer(face, &ev, NULL, &e);
    }
    rouge_pointer_event up = {ROUGE_POINTER_UP, 0, x1, y1, 1.0f, (steps + 1) / 60.0};
    rouge_face_pointer(face, &up, NULL, &e);
}

// A near-horizontal line's quality from the bare and painted pictures, over the columns [x0, x1): per
// column the coverage profile c(y) = (L_bare - L_paint) / (L_bare - L_ink); its width at half coverage,
// the 10-90 % rise on each side, and the darkest pixel.
typedef struct line_stats {
    double width_med, width_var;  // px; spread about the straight trend of width along x / median
    double width_trend;           // (max - min) / median, trend included
    double edge_max;              // worst 10-90 % rise of either side, px
    double centre_lum;            // the median over columns of the darkest pixel's luminance, 0..255
    int columns, gaps;            // columns measured, columns without a line or without ink
} line_stats;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double crossing(const double *c, int from, int step, int end, double level)
{
    // From the peak outwards: the first sample under `level`, interpolated with the one before.
    for (int y = from; y != end; y += step)
        if (c[y] < level) {
            double a = c[y - step], b = c[y];
            return (double)(y - step) + step * (a - level) / (a - b);
        }
    return NAN;
}

static line_stats measure_line(const uint8_t *bare, const uint8_t *paint, int w, int h, int x0, int x1)
{
    line_stats s = {0};
    double *c = malloc(sizeof *c * (size_t)h), *widths = malloc(sizeof(double) * (size_t)w), *centres = malloc(sizeof(double) * (size_t)w),
           *xs = malloc(sizeof(double) * (size_t)w);
    int n = 0;
    for (int x = x0; x < x1; x++) {
        int py = 0;
        for (int y = 0; y < h; y++) {
            size_t i = ((size_t)y * w + x) * 4;
            c[y] = lum(bare + i) - lum(paint + i);
            if (c[y] > c[py]) py = y;
        }
        if (c[py] < 10.0 || py < 2 || py > h - 3) continue;
        // Coverage: how far each pixel went from the bare skin towards the ink (the column's darkest).
        double ink = 255.0;
        for (int y = 0; y < h; y++) ink = fmin(ink, lum(paint + ((size_t)y * w + x) * 4));
        for (int y = 0; y < h; y++) {
            double lb = lum(bare + ((size_t)y * w + x) * 4);
            c[y] = lb - ink > 1.0 ? c[y] / (lb - ink) : 0.0;
        }
        double up50 = crossing(c, py, -1, -1, 0.5), dn50 = crossing(c, py, 1, h, 0.5);
        double up10 = crossing(c, py, -1, -1, 0.1), up90 = crossing(c, py, -1, -1, 0.9);
        double dn10 = crossing(c, py, 1, h, 0.1), dn90 = crossing(c, py, 1, h, 0.9);
        if (isnan(up50 + dn50 + up10 + up90 + dn10 + dn90)) continue;
        xs[n] = x;
        widths[n] = dn50 - up50;
        centres[n] = lum(paint + ((size_t)py * w + x) * 4);
        s.edge_max = fmax(s.edge_max, fmax(up90 - up10, dn10 - dn90));
        n++;
    }
    s.columns = n;
    if (n) {
        // Evenness about the line's own trend (a straight fit of width against x): a line drawn across a
        // curved lid narrows smoothly with the foreshortening; lumps and dents are what the eye objects to.
        double sx = 0, sy = 0, sxx = 0, sxy = 0, dmax = -1e9, dmin = 1e9;
        for (int k = 0; k < n; k++) sx += xs[k], sy += widths[k], sxx += xs[k] * xs[k], sxy += xs[k] * widths[k];
        double slope = (n * sxy - sx * sy) / fmax(n * sxx - sx * sx, 1e-9), icept = (sy - slope * sx) / n;
        for (int k = 0; k < n; k++) {
            double d = widths[k] - (icept + slope * xs[k]);
            dmax = fmax(dmax, d), dmin = fmin(dmin, d);
        }
        qsort(widths, (size_t)n, sizeof *widths, cmp_double);
        s.width_med = widths[n / 2];
        s.width_var = (dmax - dmin) / s.width_med;
        s.width_trend = (widths[n - 1] - widths[0]) / s.width_med;
        // A gap: a column whose darkest pixel is not ink.
        for (int k = 0; k < n; k++) s.gaps += centres[k] > 45.0;
        qsort(centres, (size_t)n, sizeof *centres, cmp_double);
        s.centre_lum = centres[n / 2];
    }
    s.gaps += (x1 - x0) - n;  // columns where no line was found are gaps too
    free(c), free(widths), free(centres), free(xs);
    return s;
}

static bool check_line(const char *side, const line_stats *s)
{
    printf("# liner %s: %d columns, width %.1f px (varies %.1f %% about its trend, %.1f %% min-max), worst edge "
           "%.2f px, centre %.0f/255, gaps %d\n", side, s->columns, s->width_med, 100.0 * s->width_var,
           100.0 * s->width_trend, s->edge_max, s->centre_lum, s->gaps);
    bool ok = RS_CHECK(s->width_med >= 12.0, "%s: the line is %.1f px wide (the test needs >= 12)", side, s->width_med);
    ok &= RS_CHECK(s->edge_max <= 3.0, "%s: an edge rises over %.2f px (10-90 %%), > 3", side, s->edge_max);
    ok &= RS_CHECK(s->centre_lum <= 45.0, "%s: centre luminance %.0f/255 > 45", side, s->centre_lum);
    ok &= RS_CHECK(s->width_var <= 0.15, "%s: width varies %.0f %% along the line", side, 100.0 * s->width_var);
    ok &= RS_CHECK(s->gaps == 0, "%s: %d columns with a gap", side, s->gaps);
    return ok;
}

static void flip_x(uint8_t *rgba, int w, int h)
{
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w / 2; x++) {
            uint8_t *a = rgba + ((size_t)y * w + x) * 4, *b = rgba + ((size_t)y * w + (w - 1 - x)) * 4, t[4];
            memcpy(t, a, 4), memcpy(a, b, 4), memcpy(b, t, 4);
        }
}

// An eye close-up at 3x: a horizontal mirrored liner stroke across the lid; the original is measured in
// this view, the mirrored one in the mirrored view (flipped back, so the same columns hold it).
static void test_liner_is_one_crisp_even_dark_line_on_both_sides(void)
{
    rouge_error e = {0};
    const int w = 640, h = 480;
    rouge_face_clear(face, &e);
    // Drawn at the 287k-splat LOD level (of 600k; max_splats 300000): the line is evaluated per pixel at the
    // surface the splats give, and that level's surface gives the same line (width and evenness within 0.2
    // points, the mirrored side's worst edge 2.1 px against 1.9) at half the time; the 145k level's
    // coarser surface blurs its edges (4.6 px).
    rouge_view v = {.width = w, .height = h, .zoom = 3.0f, .yaw_deg = -10.0f, .pan = {0.42f, 0.22f}, .max_splats = 300000};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "view: %s", e.msg);
    rouge_view m = v;
    m.yaw_deg = -v.yaw_deg, m.pan[0] = -v.pan[0];
    uint8_t *bare = NULL, *paint = NULL, *mbare = NULL, *mpaint = NULL;
    rouge_face_set_view(face, &m, &e);
    RS_REQUIRE(render(w, h, &mbare), "bare mirrored render");
    rouge_face_set_view(face, &v, &e);
    RS_REQUIRE(render(w, h, &bare), "bare render");  // also the pointer's frame
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "eyeliner", .mirror = true, .opacity = 1.0f},
                                    &e) == ROUGE_OK, "brush: %s", e.msg);
    stroke(0.25f * w, 0.5f * h, 0.75f * w, 0.47f * h, 40);
    RS_REQUIRE(render(w, h, &paint), "painted render");
    rouge_face_set_view(face, &m, &e);
    RS_REQUIRE(render(w, h, &mpaint), "painted mirrored render");
    save("liner_eye_3x", paint, w, h);
    save("liner_eye_3x_mirrored", mpaint, w, h);
    flip_x(mbare, w, h), flip_x(mpaint, w, h);
    line_stats a = measure_line(bare, paint, w, h, (int)(0.35f * w), (int)(0.65f * w));
    line_stats b = measure_line(mbare, mpaint, w, h, (int)(0.35f * w), (int)(0.65f * w));
    check_line("original", &a);
    check_line("mirrored", &b);
    free(bare), free(paint), free(mbare), free(mpaint);
    rouge_face_set_view(face, &v, &e);
    rouge_face_clear(face, &e);
}

// A narrow line drawn in the front view across the cheek and off the face's side, seen from that side
// (yaw -70), with `brush`: per column of the side view (right of w / 2: the stroke's dots on the ear,
// which faces the front view, lie left of it), the line's strength, its largest drop of luminance over the
// bare picture's, relative to that (the ink's share, whatever the light there). Saved as NAME.png.
static bool line_off_the_cheek(const rouge_brush *brush, const char *name, double p[512], double *peak)
{
    rouge_error e = {0};
    const int w = 512, h = 512;
    rouge_face_clear(face, &e);
    rouge_view front = {.width = w, .height = h, .max_splats = 300000}, side = front;
    side.yaw_deg = -70.0f;
    uint8_t *bare = NULL, *paint = NULL, *scratch = NULL;
    bool ok = rouge_face_set_view(face, &side, &e) == ROUGE_OK && render(w, h, &bare) &&
              rouge_face_set_view(face, &front, &e) == ROUGE_OK && render(w, h, &scratch) &&  // the pointer's frame
              rouge_face_set_brush(face, brush, &e) == ROUGE_OK;
    if (ok) {
        stroke(0.36f * w, 0.58f * h, 0.02f * w, 0.58f * h, 80);
        ok = rouge_face_set_view(face, &side, &e) == ROUGE_OK && render(w, h, &paint);
    }
    *peak = 0;
    for (int x = 0; ok && x < w; x++) {
        p[x] = 0;
        for (int y = 0; x >= w / 2 && y < h; y++) {
            size_t i = ((size_t)y * w + x) * 4;
            double lb = lum(bare + i);
            if (lb > 20.0) p[x] = fmax(p[x], (lb - lum(paint + i)) / lb);
        }
        *peak = fmax(*peak, p[x]);
    }
    if (ok) save(name, paint, w, h);
    RS_CHECK(ok, "%s: %s", name, e.msg);
    free(bare), free(paint), free(scratch);
    rouge_face_clear(face, &e);
    return ok;
}

// Where the cheek turns from the view the line was drawn in, a sheer line (a narrow blush) fades out
// over the last ~17 deg before edge-on (makeup_fine.glsl rs_fine_facing) instead of ending in a cut: from
// its first column at 3 % of the peak to the first at 40 % (measured: 31 px; the former cut at N.V 0.2:
// 2 px). An opaque pencil saturates and shows that fade only in its last few degrees.
static void test_narrow_line_fades_out_where_the_cheek_turns_away(void)
{
    double p[512], peak;
    rouge_brush b = {.cosmetic = "blush", .size = 0.012f, .opacity = 1.0f, .any_region = true};
    if (!line_off_the_cheek(&b, "line_cheek_side", p, &peak)) return;
    int first = -1, at40 = -1;
    for (int x = 256; x < 512 && at40 < 0; x++) {
        if (first < 0 && p[x] >= 0.03 * peak) first = x;
        if (p[x] >= 0.4 * peak) at40 = x;
    }
    printf("# narrow line off the cheek, seen from the side: the line takes %.0f %% of the skin's luminance at "
           "most; towards the ear it fades from 40 %% of that to nothing over %d px (columns %d..%d)\n",
           100.0 * peak, at40 - first, first, at40);
    RS_CHECK(peak > 0.05, "the line darkens the skin by %.0f %% at most (no line?)", 100.0 * peak);
    RS_CHECK(first >= 0 && at40 - first >= 6, "the line ends within %d px where the cheek turns away: a cut, not "
             "a fade", at40 - first);
}

// The same line with the eyeliner stays one line to its end: stamps sit at the surface point of the pixel
// under the pointer, and where the cheek turns away neighbouring pixels' points lie millimetres apart,
// wider than a pencil, so the line fell apart into dots (paint.c bridge() now fills such gaps). Gaps: the
// columns between the line's ends (at 1/4 of its peak) where it is under 1/4 (measured: none, the weakest
// column at 0.52 of the peak; without bridge(): a column at 0.18 between dots that nearly touch here).
static void test_liner_stays_one_line_where_the_cheek_turns_away(void)
{
    double p[512], peak;
    rouge_brush b = {.cosmetic = "eyeliner", .opacity = 1.0f};
    if (!line_off_the_cheek(&b, "liner_cheek_side", p, &peak)) return;
    int x0 = -1, x1 = -1, gaps = 0;
    for (int x = 256; x < 512; x++)
        if (p[x] >= 0.25 * peak) x1 = x, x0 = x0 < 0 ? x : x0;
    for (int x = x0; x0 >= 0 && x <= x1; x++) gaps += p[x] < 0.25 * peak;
    printf("# eyeliner off the cheek, seen from the side: ink share %.2f at most, columns %d..%d, %d of them "
           "gaps\n", peak, x0, x1, gaps);
    RS_CHECK(peak > 0.5, "the liner darkens the skin by %.0f %% at most (no line?)", 100.0 * peak);
    RS_CHECK(x0 >= 0 && gaps == 0, "the liner falls apart where the cheek turns away: %d columns of gaps", gaps);
}

// Writes tests/fixtures/strokes/lips.strokes with another cosmetic into the test folder; its path.
static const char *lips_strokes_with(const char *cosmetic)
{
    static char path[1024];
    snprintf(path, sizeof path, "%s/lips_%s.strokes", rs_test_out_dir(), cosmetic);
    FILE *in = fopen("tests/fixtures/strokes/lips.strokes", "r"), *out = fopen(path, "w");
    char line[512];
    while (in && out && fgets(line, sizeof line, in))
        fputs(strncmp(line, "cosmetic ", 9) ? line : "", out), strncmp(line, "cosmetic ", 9) ? 0 : fprintf(out, "cosmetic %s\n", cosmetic);
    if (in) fclose(in);
    if (out) fclose(out);
    return path;
}

static int cmp_int(const void *a, const void *b) { return *(const int *)a - *(const int *)b; }

// Per lip pixel, the largest channel change between two frames: median and 95th percentile.
static void lip_change(const uint8_t *a, const uint8_t *b, const uint8_t *mask, int n, int *med, int *p95)
{
    int *d = malloc(sizeof *d * (size_t)n), k = 0;
    for (int i = 0; i < 512 * 512; i++) {
        if (!mask[i]) continue;
        int m = 0;
        for (int c = 0; c < 3; c++) m = RS_MAX(m, abs(a[4 * i + c] - b[4 * i + c]));
        d[k++] = m;
    }
    qsort(d, (size_t)k, sizeof *d, cmp_int);
    *med = k ? d[k / 2] : 0, *p95 = k ? d[(k * 95) / 100] : 0;
    free(d);
}

static void test_gloss_over_lipstick_reads_in_the_default_front_view(void)
{
    rouge_error e = {0};
    rouge_face_clear(face, &e);
    rouge_view v = {.width = 512, .height = 512};
    uint8_t *bare = NULL;
    rouge_face_set_view(face, &v, &e);
    RS_REQUIRE(render(512, 512, &bare), "render");
    RS_REQUIRE(rouge_face_play_strokes(face, lips_strokes_with("lipstick_satin"), &e) == ROUGE_OK, "lipstick: %s",
               e.msg);
    uint8_t *lip[2] = {NULL, NULL}, *gloss[2] = {NULL, NULL};
    rouge_mode modes[2] = {ROUGE_MODE_FULL, ROUGE_MODE_DIFFUSE};
    for (int k = 0; k < 2; k++) {
        v.mode = modes[k];
        rouge_face_set_view(face, &v, &e);
        RS_REQUIRE(render(512, 512, &lip[k]), "render");
    }
    // The lip pixels: the lips region (the pick's region 4) where the lipstick shows (the region reaches
    // onto the skin around). Only the pixels the lipstick changed are picked: a pick per pixel costs seconds.
    int n = 0;
    uint8_t *mask = calloc(512 * 512, 1);
    for (int i = 0; mask && i < 512 * 512; i++) {
        int d = 0;
        for (int c = 0; c < 3; c++) d = RS_MAX(d, abs(bare[4 * i + c] - lip[0][4 * i + c]));
        rouge_pick p;
        if (d >= 10 && rouge_face_pick(face, i % 512 + 0.5f, i / 512 + 0.5f, &p) && p.region == 4) mask[i] = 1, n++;
    }
    free(bare);
    RS_REQUIRE(n > 500, "only %d lip pixels", n);
    RS_REQUIRE(rouge_face_play_strokes(face, lips_strokes_with("lip_gloss"), &e) == ROUGE_OK, "gloss: %s", e.msg);
    for (int k = 0; k < 2; k++) {
        v.mode = modes[k];
        rouge_face_set_view(face, &v, &e);
        RS_REQUIRE(render(512, 512, &gloss[k]), "render");
    }
    save("gloss_front_lipstick", lip[0], 512, 512);
    save("gloss_front_lipstick_gloss", gloss[0], 512, 512);
    int med, p95, dmed, dp95;
    lip_change(lip[0], gloss[0], mask, n, &med, &p95);
    lip_change(lip[1], gloss[1], mask, n, &dmed, &dp95);
    printf("# gloss over lipstick, %d lip pixels: full median %d p95 %d; diffuse median %d p95 %d\n", n, med, p95,
           dmed, dp95);
    // Issue 21's goal: median >= 8, p95 >= 15 in full, <= 8 in diffuse. Under the studio environment the
    // lips mirror drapes and ceiling, not lamps: the coat's reflection alone (F0 0.04) moves the median lip
    // pixel by ~3/255 (the p95 is its highlights). What carries the median is what a wet film does to the
    // colour under it (makeup_fine.glsl rs_fine_wet, Lekner & Dorf): deeper, more saturated. `diffuse` is
    // the dry surface's subsurface term; the coat is a layer above it, so it does not change there.
    // Before that model: full median 4, p95 26, diffuse 0.
    RS_CHECK(med >= 8 && p95 >= 15 && dmed <= 8,
             "gloss over lipstick: full median %d/255 (goal >= 8), p95 %d (>= 15), diffuse median %d (<= 8)", med,
             p95, dmed);
    for (int k = 0; k < 2; k++) free(lip[k]), free(gloss[k]);
    free(mask);
    rouge_face_clear(face, &e);
}

// CIELAB a* of an sRGB8 pixel (D65): the red-green axis that tells the vermilion from the skin.
static double lab_a(const uint8_t *p)
{
    double l[3];
    for (int c = 0; c < 3; c++) {
        double v = p[c] / 255.0;
        l[c] = v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
    }
    double x = (0.4124 * l[0] + 0.3576 * l[1] + 0.1805 * l[2]) / 0.95047, y = 0.2126 * l[0] + 0.7152 * l[1] + 0.0722 * l[2];
    double fx = x > 0.008856 ? cbrt(x) : 7.787 * x + 16.0 / 116.0, fy = y > 0.008856 ? cbrt(y) : 7.787 * y + 16.0 / 116.0;
    return 500.0 * (fx - fy);
}

// The lips region (the pick's region 4, a blob around the mouth that reaches onto the skin) over the middle
// of a close-up (rouge_face_target centres the lips), picked every 6 px (each pick fills its 6x6 block: a
// pick per pixel costs seconds), and that region widened by `grow` px.
static uint8_t *lips_region(int w, int h, int grow, uint8_t **grown)
{
    enum { B = 6 };
    uint8_t *region = calloc((size_t)w * h, 1), *tmp = calloc((size_t)w * h, 1);
    *grown = calloc((size_t)w * h, 1);
    if (!region || !tmp || !*grown) {
        free(tmp);
        return region;
    }
    for (int by = h / 5; by < h * 4 / 5; by += B)
        for (int bx = w / 10; bx < w * 9 / 10; bx += B) {
            rouge_pick p;
            if (!rouge_face_pick(face, bx + 0.5f * B, by + 0.5f * B, &p) || p.region != 4) continue;
            for (int y = by; y < RS_MIN(by + B, h); y++) memset(region + (size_t)y * w + bx, 1, (size_t)RS_MIN(B, w - bx));
        }
    for (int y = 0; y < h; y++)  // a box dilation, rows then columns
        for (int x = 0; x < w; x++)
            for (int k = RS_MAX(0, x - grow); k <= RS_MIN(w - 1, x + grow) && !tmp[(size_t)y * w + x]; k++)
                tmp[(size_t)y * w + x] = region[(size_t)y * w + k];
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = RS_MAX(0, y - grow); k <= RS_MIN(h - 1, y + grow) && !(*grown)[(size_t)y * w + x]; k++)
                (*grown)[(size_t)y * w + x] = tmp[(size_t)k * w + x];
    free(tmp);
    return region;
}

// A line's smoothed row at column x: over the columns [x - half, x + half] within [x0, x1) that have one
// (ys not NAN), the mean (bend 0) or a local quadratic least-squares fit's value (bend 1, Savitzky-Golay:
// it follows the line's bend, where a mean cuts across it).
static double smoothed_row(const double *ys, int x0, int x1, int x, int half, int bend)
{
    double m[5] = {0}, r[3] = {0};  // sums of t^0..t^4 and y t^0..t^2, t = j - x
    for (int j = RS_MAX(x0, x - half); j < RS_MIN(x1, x + half + 1); j++) {
        if (isnan(ys[j])) continue;
        double t = j - x, tp = 1;
        for (int k = 0; k < 5; k++) {
            m[k] += tp;
            if (k < 3) r[k] += ys[j] * tp;
            tp *= t;
        }
    }
    if (m[0] == 0) return NAN;
    double fit = r[0] / m[0];
    if (bend) {
        // [m0 m1 m2; m1 m2 m3; m2 m3 m4] (c0 c1 c2) = r: the fit's value at t = 0 is c0 (Cramer).
        double det = m[0] * (m[2] * m[4] - m[3] * m[3]) - m[1] * (m[1] * m[4] - m[3] * m[2]) +
                     m[2] * (m[1] * m[3] - m[2] * m[2]);
        double d0 = r[0] * (m[2] * m[4] - m[3] * m[3]) - m[1] * (r[1] * m[4] - m[3] * r[2]) +
                    m[2] * (r[1] * m[3] - m[2] * r[2]);
        if (fabs(det) > 1e-6 * m[0] * m[2] * m[4]) fit = d0 / det;
    }
    return fit;
}

// The lips of a bare close-up, as a makeup artist sees them: where the scan's own colour changes from skin
// to vermilion. The truth is read from the albedo view at the same camera (rouge's ALBEDO mode: the
// splats' colour, no light), so the same lips give the same border under any lighting; it shares nothing
// with the lips' field the lipstick is masked by (a different source: pixels, not splats; no 3D blur),
// so the check can fail. Pixels whose a* (CIELAB, smoothed over 5x5 pixels against the skin's texture) is
// above Otsu's threshold between the lips region's two colour classes are lip colour, within 12 px (~1.6
// mm) of that region: the region only keeps far-off red skin out; its own border is splat-ragged and must
// not cut the lip line.
// 1 upper lip, 2 lower lip (above / below the mouth line: per column, the darkest albedo pixel between
// them), 0 not lip; the outer borders smoothed along the mouth.
static uint8_t *lips_truth(const uint8_t *albedo, int w, int h, int *mouth_y)
{
    const uint8_t *bare = albedo;
    uint8_t *near = NULL, *region = lips_region(w, h, 12, &near), *lip = calloc((size_t)w * h, 1);
    double *a = calloc((size_t)w * h, sizeof *a);
    int hist[256] = {0}, total = 0, *tops = calloc((size_t)w, sizeof *tops), *bottoms = calloc((size_t)w, sizeof *bottoms);
    double *a1 = malloc(sizeof *a1 * (size_t)w * h);  // a* per pixel, then its 5x5 mean in a
    for (size_t i = 0; i < (size_t)w * h; i++) a1[i] = lab_a(bare + 4 * i);
    for (int y = 2; y < h - 2; y++)
        for (int x = 2; x < w - 2; x++) {
            size_t i = (size_t)y * w + x;
            if (!near[i]) continue;
            for (int k = 0; k < 25; k++) a[i] += a1[(size_t)(y + k / 5 - 2) * w + (x + k % 5 - 2)] / 25.0;
            if (region[i]) hist[RS_CLAMP((int)(a[i] * 4.0), 0, 255)]++, total++;
        }
    double sum = 0, s0 = 0, w0 = 0, best = -1;
    int cut = 0;
    for (int b = 0; b < 256; b++) sum += (double)b * hist[b];
    for (int b = 0; b < 255; b++) {
        w0 += hist[b], s0 += (double)b * hist[b];
        double w1 = total - w0;
        if (w0 < 1 || w1 < 1) continue;
        double d = s0 / w0 - (sum - s0) / w1, v = w0 * w1 * d * d;
        if (v > best) best = v, cut = b;
    }
    for (int x = 0; x < w; x++) {
        int top = -1, bottom = -1;
        for (int y = 0; y < h; y++)
            if (near[(size_t)y * w + x] && a[(size_t)y * w + x] * 4.0 > cut) bottom = y, top = top < 0 ? y : top;
        mouth_y[x] = -1;
        if (top < 0 || bottom - top < 8) continue;
        // The mouth line: the darkest pixel of the column's middle half between the lips' outer borders.
        double dark = 1e9;
        for (int y = top + (bottom - top) / 4; y <= bottom - (bottom - top) / 4; y++)
            if (lum(bare + ((size_t)y * w + x) * 4) < dark) dark = lum(bare + ((size_t)y * w + x) * 4), mouth_y[x] = y;
        // Each lip is the lip colour joined to the mouth line (gaps up to 3 px: the mouth line's own dark
        // pixels): red skin cut off from the lips above them, like the philtrum's flush under the nose, is skin.
        top = bottom = mouth_y[x];
        for (int y = mouth_y[x], gap = 0; y >= 0 && gap <= 3; y--)
            if (near[(size_t)y * w + x] && a[(size_t)y * w + x] * 4.0 > cut) top = y, gap = 0; else gap++;
        for (int y = mouth_y[x], gap = 0; y < h && gap <= 3; y++)
            if (near[(size_t)y * w + x] && a[(size_t)y * w + x] * 4.0 > cut) bottom = y, gap = 0; else gap++;
        tops[x] = top, bottoms[x] = bottom;
    }
    // The vermilion border is a smooth curve; the colour's texture is not: the outer borders are the
    // columns' extremes smoothed over +-20 columns (the wander check's scale) by a local quadratic fit (a mean would cut the lips'
    // round corners and bottom, moving the border inwards there).
    double *ft = malloc(sizeof *ft * (size_t)w), *fb = malloc(sizeof *fb * (size_t)w);
    for (int x = 0; x < w; x++) ft[x] = mouth_y[x] < 0 ? NAN : tops[x], fb[x] = mouth_y[x] < 0 ? NAN : bottoms[x];
    for (int x = 0; x < w; x++) {
        if (mouth_y[x] < 0) continue;
        int t = (int)lrint(smoothed_row(ft, 0, w, x, 20, 1)), b = (int)lrint(smoothed_row(fb, 0, w, x, 20, 1));
        for (int y = RS_MAX(t, 0); y <= RS_MIN(b, h - 1); y++) lip[(size_t)y * w + x] = y < mouth_y[x] ? 1 : 2;
    }
    free(ft), free(fb);
    free(region), free(near), free(a), free(a1), free(tops), free(bottoms);
    return lip;
}

// The per-column position (sub-pixel) where the paint's change first reaches `level` coming from `from`
// towards `to` (rows), or NAN.
static double edge_row(const double *d, int w, int x, int from, int to, double level)
{
    int step = to > from ? 1 : -1;
    for (int y = from; y != to; y += step)
        if (d[(size_t)y * w + x] >= level) {
            if (y == from) return NAN;
            double a = d[(size_t)(y - step) * w + x], b = d[(size_t)y * w + x];
            return (y - step) + step * (level - a) / (b - a);
        }
    return NAN;
}

// How far an edge wanders from its own smoothed line: mean |y - smoothed y| over the columns, px, the
// smoothing over +-20 columns (about 5 mm at the lips' close-up: the lip line is smooth over that;
// splat-sized teeth are not). `bend` 0: the moving average, which also cuts across the lip line's own bend
// (a lower lip's round bottom reads as wander with no tooth at all); 1: the local quadratic fit, which
// follows the bend and leaves the teeth and waves.
static double edge_wander(const double *ys, int x0, int x1, int bend)
{
    double sum = 0;
    int n = 0;
    for (int x = x0; x < x1; x++) {
        if (isnan(ys[x])) continue;
        sum += fabs(ys[x] - smoothed_row(ys, x0, x1, x, 20, bend)), n++;
    }
    return n ? sum / n : NAN;
}

// A lips close-up at 3x: an artist's two passes along each lip, corner to corner, with a lipstick kept to the
// lips. Each lip is covered to its vermilion border (>= 95 % of its pixels take at least half the
// lipstick's full change), nothing spills onto the skin (<= 0.5 % of the lips' area, beyond 2 px of the
// border), and the outer edges are smooth (on average within 1 px of their own smoothed line: a local
// quadratic fit over +-20 columns).
static void test_lipstick_fills_each_lip_to_its_border_without_spill(void)
{
    rouge_error e = {0};
    const int w = 640, h = 480;
    rouge_face_clear(face, &e);
    rouge_view v = {.width = w, .height = h};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "view: %s", e.msg);
    RS_REQUIRE(rouge_face_target(face, "lips", 0.55f, &e) == ROUGE_OK, "target: %s", e.msg);
    v = rouge_face_get_view(face);
    v.max_splats = 300000;  // the 287k LOD level, as the liner's: the lipstick and its truth are per pixel
    printf("# lips close-up: zoom %.2f\n", v.zoom);
    uint8_t *bare = NULL, *paint = NULL;
    uint8_t *albedo = NULL;
    v.mode = ROUGE_MODE_ALBEDO;
    rouge_face_set_view(face, &v, &e);
    RS_REQUIRE(render(w, h, &albedo), "albedo render");
    v.mode = ROUGE_MODE_FULL;
    rouge_face_set_view(face, &v, &e);
    RS_REQUIRE(render(w, h, &bare), "bare render");
    save("lipstick_lips_3x_bare", bare, w, h);
    save("lipstick_lips_3x_albedo", albedo, w, h);
    int *mouth = malloc(sizeof *mouth * (size_t)w);
    uint8_t *lip = lips_truth(albedo, w, h, mouth);
    free(albedo);
    // Each lip's extent and centre line (per column, the middle of its pixels).
    int x0[3] = {w, w, w}, x1[3] = {0, 0, 0}, count[3] = {0};
    double *mid[3] = {NULL, calloc((size_t)w, sizeof(double)), calloc((size_t)w, sizeof(double))};
    for (int x = 0; x < w; x++)
        for (int k = 1; k <= 2; k++) {
            int n = 0;
            double sy = 0;
            for (int y = 0; y < h; y++)
                if (lip[(size_t)y * w + x] == k) n++, sy += y;
            count[k] += n;
            mid[k][x] = n ? sy / n : NAN;
            if (n > 6) x0[k] = RS_MIN(x0[k], x), x1[k] = RS_MAX(x1[k], x);
        }
    printf("# lips: upper %d px (x %d..%d), lower %d px (x %d..%d)\n", count[1], x0[1], x1[1], count[2], x0[2], x1[2]);
    RS_REQUIRE(count[1] > 3000 && count[2] > 3000, "the lips are not in the close-up");
    // The lipstick's full colour at every pixel: the mouth and the skin around painted over anywhere
    // with a wide brush, three times.
    uint8_t *full = NULL;
    // (The bare render, the last frame, is the pointer's frame.)
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_matte", .opacity = 1.0f, .size = 0.2f,
                                                         .any_region = true}, &e) == ROUGE_OK, "brush: %s", e.msg);
    for (int pass = 0; pass < 3; pass++) stroke(0.15f * w, 0.5f * h, 0.85f * w, 0.5f * h, 40);
    RS_REQUIRE(render(w, h, &full), "full render");
    rouge_face_clear(face, &e);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_matte", .opacity = 1.0f}, &e) ==
                   ROUGE_OK, "brush: %s", e.msg);
    for (int k = 1; k <= 2; k++)
        for (int pass = 0; pass < 2; pass++) {
            rouge_pointer_event ev = {ROUGE_POINTER_DOWN, 0, 0, 0, 1.0f, 0.0};
            int a = x0[k] + (x1[k] - x0[k]) / 25, b = x1[k] - (x1[k] - x0[k]) / 25, steps = 0;
            for (int x = a; x <= b; x += 4, steps++) {
                if (isnan(mid[k][x])) continue;
                ev.x = (float)x, ev.y = (float)mid[k][x], ev.time_s = steps / 60.0;
                rouge_face_pointer(face, &ev, NULL, &e);
                ev.type = ROUGE_POINTER_MOVE;
            }
            ev.type = ROUGE_POINTER_UP;
            rouge_face_pointer(face, &ev, NULL, &e);
        }
    RS_REQUIRE(render(w, h, &paint), "painted render");
    save("lipstick_lips_3x", paint, w, h);
    // Coverage per pixel: how far the paint moved the pixel from the bare face towards the full colour.
    double *d = calloc((size_t)w * h, sizeof *d), level = 0.5;
    int nl = 0, unseen = 0;
    for (size_t i = 0; i < (size_t)w * h; i++) {
        double num = 0, den = 0;
        for (int c = 0; c < 3; c++) {
            double f = full[4 * i + c] - bare[4 * i + c];
            num += f * (paint[4 * i + c] - bare[4 * i + c]), den += f * f;
        }
        d[i] = den > 100.0 ? num / den : 0.0;
        // A lip pixel whose full colour is the bare one tells nothing (no lipstick reaches it: the lip rolling
        // into the mouth line, seen edge-on): neither covered nor uncovered (3).
        if (lip[i] && den <= 100.0) count[lip[i]]--, lip[i] = 3, unseen++;
        nl += lip[i] == 1 || lip[i] == 2;
    }
    int covered[4] = {0}, spill = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            if (lip[i]) { covered[lip[i] & 3] += lip[i] < 3 && d[i] >= level; continue; }
            if (d[i] < level) continue;
            bool near = false;  // within 2 px of the border: the border's own anti-aliasing
            for (int k = 0; k < 25 && !near; k++) {
                int yy = RS_CLAMP(y + k / 5 - 2, 0, h - 1), xx = RS_CLAMP(x + k % 5 - 2, 0, w - 1);
                near = lip[(size_t)yy * w + xx] != 0;
            }
            spill += !near;
        }
    // The painted close-up with the truth's border drawn over it (green), the lip pixels it leaves
    // uncovered (blue), those no lipstick reaches (magenta) and its spill (yellow), to look at.
    uint8_t *drawn = malloc((size_t)w * h * 4);
    memcpy(drawn, paint, (size_t)w * h * 4);
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++) {
            size_t i = (size_t)y * w + x;
            if (lip[i] && (!lip[i - 1] || !lip[i + 1] || !lip[i - w] || !lip[i + w]))
                memcpy(drawn + 4 * i, (uint8_t[4]){0, 255, 0, 255}, 4);
            else if (lip[i] == 3)
                memcpy(drawn + 4 * i, (uint8_t[4]){255, 0, 255, 255}, 4);
            else if (lip[i] && d[i] < level)
                memcpy(drawn + 4 * i, (uint8_t[4]){0, 0, 255, 255}, 4);
            else if (!lip[i] && d[i] >= level)
                memcpy(drawn + 4 * i, (uint8_t[4]){255, 255, 0, 255}, 4);
        }
    save("lipstick_lips_3x_truth", drawn, w, h);
    free(drawn);
    // The outer edges: the upper lip's top and the lower lip's bottom, over the middle 80 % of each lip.
    double *top = malloc(sizeof(double) * (size_t)w), *bottom = malloc(sizeof(double) * (size_t)w);
    for (int x = 0; x < w; x++) {
        top[x] = isnan(mid[1][x]) ? NAN : edge_row(d, w, x, RS_MAX(0, (int)mid[1][x] - 80), (int)mid[1][x], level);
        bottom[x] = isnan(mid[2][x]) ? NAN : edge_row(d, w, x, RS_MIN(h - 1, (int)mid[2][x] + 80), (int)mid[2][x], level);
    }
    double wt = edge_wander(top, x0[1] + (x1[1] - x0[1]) / 10, x1[1] - (x1[1] - x0[1]) / 10, 1);
    double wb = edge_wander(bottom, x0[2] + (x1[2] - x0[2]) / 10, x1[2] - (x1[2] - x0[2]) / 10, 1);
    double mt = edge_wander(top, x0[1] + (x1[1] - x0[1]) / 10, x1[1] - (x1[1] - x0[1]) / 10, 0);
    double mb = edge_wander(bottom, x0[2] + (x1[2] - x0[2]) / 10, x1[2] - (x1[2] - x0[2]) / 10, 0);
    double cu = (double)covered[1] / count[1], cl = (double)covered[2] / count[2], sp = (double)spill / nl;
    printf("# lipstick at 3x: covers %.1f %% of the upper lip, %.1f %% of the lower (%d lip pixels no lipstick "
           "reaches left out); spill %.2f %%; edges wander %.2f px (top) / %.2f px (bottom) from their smoothed "
           "lines (from their moving averages %.2f / %.2f)\n", 100 * cu, 100 * cl, unseen, 100 * sp, wt, wb, mt, mb);
    // Issue 21's goal: >= 95 % of each lip, <= 0.5 % spill, edges within 1 px of their smoothed lines. The
    // lipstick is drawn per pixel, masked by the lips' field (makeup.c, "Region masks per pixel": the
    // splats' a* about their Otsu cut, over 3 mm) and fills it within the brush's reach (makeup_fine.glsl).
    // The truth is the albedo's border (lips_truth), so lighting does not move it; against the lit
    // picture's truth the same painted pixels had moved from 94.4 / 96.6 %, spill 5.6 % to 93.6 / 96.4 %,
    // 9.7 % when the bounce light came. Measured now (2026-11-28): 96.7 / 95.6 %, spill 0.21 %, wander
    // 0.23 / 0.50 px (moving averages 0.69 / 2.09 px; first measured 96.9 / 96.1 %, 0.40 %, 0.18 / 0.49 px;
    // then with all 600k splats drawn 96.2 / 96.1 %, 0.36 %); the former field (a* +-12, cut at Otsu's, the
    // region's border cutting the lower lip) measured 88.9 / 91.9 %, 0.38 %, wander against the moving
    // average 0.67 / 1.66.
    // lipstick_lips_3x_truth.png shows the border (green), lip left uncovered (blue), the mouth line no
    // lipstick reaches (magenta, not counted) and spill (yellow).
    RS_CHECK(cu >= 0.95 && cl >= 0.95,
             "the lipstick covers %.1f %% of the upper lip, %.1f %% of the lower (goal >= 95 each)", 100 * cu, 100 * cl);
    RS_CHECK(sp <= 0.005, "the lipstick spills onto %.2f %% of the lips' area of skin (goal <= 0.5 %%)", 100 * sp);
    RS_CHECK(wt <= 1.0 && wb <= 1.0, "the lipstick's edges wander %.2f / %.2f px from their smoothed lines (goal <= 1)",
             wt, wb);
    free(top), free(bottom), free(d), free(full), free(mid[1]), free(mid[2]), free(lip), free(mouth);
    free(bare), free(paint);
    rouge_face_clear(face, &e);
}

// A highlighter stroke along the cheekbone at 3x: a lift of the painted area, and no isolated specks
// (dots more than 20/255 above the median of their 7x7 neighbourhood where the bare face had none).
static void test_highlighter_is_a_sheen_without_specks(void)
{
    rouge_error e = {0};
    const int w = 640, h = 480;
    rouge_face_clear(face, &e);
    // The sheen and its glints are per pixel (composite.frag.glsl flakes()); the skin's finest LOD levels
    // are not what is looked at here: the 145k-splat level (of 600k) draws it at a third of the time.
    rouge_view v = {.width = w, .height = h, .zoom = 3.0f, .yaw_deg = -30.0f, .pan = {0.45f, 0.2f}, .max_splats = 150000};
    rouge_face_set_view(face, &v, &e);
    uint8_t *bare = NULL, *paint = NULL;
    RS_REQUIRE(render(w, h, &bare), "render");
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "highlighter", .size = 0.08f, .any_region = true},
                                    &e) == ROUGE_OK, "brush");
    stroke(0.3f * w, 0.5f * h, 0.7f * w, 0.45f * h, 30);
    stroke(0.3f * w, 0.5f * h, 0.7f * w, 0.45f * h, 30);
    RS_REQUIRE(render(w, h, &paint), "render");
    save("highlighter_cheek_3x", paint, w, h);
    int painted = 0, specks = 0;
    double lift = 0;
    for (int y = 1; y < h - 1; y++)
        for (int x = 1; x < w - 1; x++) {
            size_t i = ((size_t)y * w + x) * 4;
            double d = lum(paint + i) - lum(bare + i);
            if (fabs(d) < 2.0) continue;
            painted++, lift += d;
            // A speck: a dot (1-3 px) well above the median of its 7x7 neighbourhood where the bare skin
            // had none. (Against the brightest neighbour alone, a 2-px glint hid behind its own twin.)
            double lp = lum(paint + i), lb = lum(bare + i), vp[49], vb[49];
            int n = 0;
            for (int dy = -3; dy <= 3; dy++)
                for (int dx = -3; dx <= 3; dx++) {
                    int yy = RS_CLAMP(y + dy, 0, h - 1), xx = RS_CLAMP(x + dx, 0, w - 1);
                    size_t j = ((size_t)yy * w + xx) * 4;
                    vp[n] = lum(paint + j), vb[n++] = lum(bare + j);
                }
            qsort(vp, 49, sizeof *vp, cmp_double), qsort(vb, 49, sizeof *vb, cmp_double);
            specks += lp - vp[24] > 20.0 && !(lb - vb[24] > 20.0);
        }
    double frac = painted ? (double)specks / painted : 0.0;
    printf("# highlighter: %d painted pixels, mean lift %.1f/255, specks %.2f %%\n", painted,
           painted ? lift / painted : 0.0, 100.0 * frac);
    RS_CHECK(painted > 2000, "only %d pixels changed", painted);
    RS_CHECK(painted && lift / painted >= 3.0, "mean lift %.1f/255 < 3", painted ? lift / painted : 0.0);
    // Issue 21's goal: a sheen, sparkle only as fine glints (shimmer flakes filtered over the pixel's
    // footprint, composite.frag.glsl flakes()); 1.72 % of the painted pixels were specks before.
    RS_CHECK(frac <= 0.001, "%.2f %% of the painted pixels are isolated specks (goal <= 0.1 %%)", 100.0 * frac);
    free(bare), free(paint);
    rouge_face_clear(face, &e);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_gl_context *gl = NULL;
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - fine_makeup: no GL context: %s\n", err.msg);
        return rs_test_finish();
    }
    rouge_error e = {0};
    if (rouge_face_create(&(rouge_face_desc){.path = FACE_PATH}, &face, &e) != ROUGE_OK) {
        printf("FAIL - fine_makeup: %s\n", e.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    RS_RUN(test_liner_is_one_crisp_even_dark_line_on_both_sides);
    RS_RUN(test_narrow_line_fades_out_where_the_cheek_turns_away);
    RS_RUN(test_liner_stays_one_line_where_the_cheek_turns_away);
    RS_RUN(test_gloss_over_lipstick_reads_in_the_default_front_view);
    RS_RUN(test_highlighter_is_a_sheen_without_specks);
    RS_RUN(test_lipstick_fills_each_lip_to_its_border_without_spill);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
