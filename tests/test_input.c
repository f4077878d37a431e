// test_input.c — pointer input (src/paint/input.c): stroke smoothing and resampling, gestures.
#include "support/harness.h"
#include "paint/input.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REQUIRE(cond) RS_REQUIRE(cond, "%s", #cond)

typedef struct collected {
    rs_input_stamp s[20000];
    uint32_t n;
    int begins, ends, cancels;
    float orbit[2], pan[2], zoom;
} collected;

static void feed(rs_input *in, rs_input_type type, int id, float x, float y, float p, double t, collected *c)
{
    rs_input_output out;
    rs_input_feed(in, &(rs_input_event){type, id, x, y, p, t}, &out);
    for (uint32_t i = 0; i < out.stamp_count && c->n < RS_COUNT_OF(c->s); i++) c->s[c->n++] = out.stamps[i];
    c->begins += out.stroke_begin;
    c->ends += out.stroke_end;
    c->cancels += out.stroke_cancel;
    c->orbit[0] += out.orbit_dx_px, c->orbit[1] += out.orbit_dy_px;
    c->pan[0] += out.pan_dx_px, c->pan[1] += out.pan_dy_px;
    c->zoom *= out.zoom;
}

static collected *new_collected(void)
{
    collected *c = calloc(1, sizeof *c);
    c->zoom = 1.0f;
    return c;
}

// A curve through the canvas, parametrised by u in [0, 1].
static void curve(float u, float *x, float *y)
{
    *x = 40.0f + 300.0f * u;
    *y = 120.0f + 60.0f * sinf(6.0f * u);
}

// One stroke along the curve taking `duration` s, events at `rate` Hz.
static void draw_curve(rs_input *in, double rate, double duration, collected *c)
{
    int n = (int)(rate * duration);
    float x, y;
    curve(0.0f, &x, &y);
    feed(in, RS_INPUT_DOWN, 7, x, y, 1.0f, 0.0, c);
    for (int i = 1; i < n; i++) {
        curve((float)i / n, &x, &y);
        feed(in, RS_INPUT_MOVE, 7, x, y, 1.0f, i / rate, c);
    }
    curve(1.0f, &x, &y);
    feed(in, RS_INPUT_UP, 7, x, y, 1.0f, duration, c);
}

static float dist_to_set(const rs_input_stamp *p, const collected *c)
{
    float best = INFINITY;
    for (uint32_t i = 0; i < c->n; i++) best = fminf(best, hypotf(p->x_px - c->s[i].x_px, p->y_px - c->s[i].y_px));
    return best;
}

static void test_tap_gives_one_stamp_where_it_landed(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 5}});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 50, 60, 0.7f, 1.0, c);
    feed(&in, RS_INPUT_UP, 1, 50, 60, 0.7f, 1.05, c);
    RS_CHECK(c->n == 1 && c->s[0].x_px == 50 && c->s[0].y_px == 60 && c->s[0].pressure == 0.7f, "%u stamps", c->n);
    RS_CHECK(c->begins == 1 && c->ends == 1 && c->cancels == 0, "begin %d end %d", c->begins, c->ends);
    free(c);
}

static void test_straight_stroke_is_resampled_at_even_spacing(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 4, .no_smoothing = true}});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 10, 10, 1, 0.0, c);
    // Uneven events: 3 px, 17 px, 0.5 px, 29.5 px.
    float xs[] = {13, 30, 30.5f, 60};
    for (int i = 0; i < 4; i++) feed(&in, RS_INPUT_MOVE, 1, xs[i], 10, 1, 0.01 * (i + 1), c);
    feed(&in, RS_INPUT_UP, 1, 60, 10, 1, 0.05, c);
    // 50 px at 4 px spacing: stamps at 10, 14, ..., 58, then the lift point 60.
    if (!RS_CHECK(c->n == 14, "%u stamps, want 14", c->n)) return;
    for (uint32_t i = 0; i + 1 < 13; i++)
        RS_CHECK(fabsf(c->s[i + 1].x_px - c->s[i].x_px - 4.0f) < 1e-3f, "gap %u: %g", i,
                 c->s[i + 1].x_px - c->s[i].x_px);
    RS_CHECK(c->s[13].x_px == 60.0f, "stroke must end at the lift point, ends at %g", c->s[13].x_px);
    free(c);
}

static void test_pressure_and_time_are_interpolated_between_events(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 10, .no_smoothing = true}});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 0, 0, 0.0f, 0.0, c);
    feed(&in, RS_INPUT_MOVE, 1, 100, 0, 1.0f, 1.0, c);
    REQUIRE(c->n == 11);
    for (uint32_t i = 0; i < 11; i++) {
        RS_CHECK(fabsf(c->s[i].pressure - 0.1f * i) < 1e-5f, "stamp %u pressure %g", i, c->s[i].pressure);
        RS_CHECK(fabs(c->s[i].time_s - 0.1 * i) < 1e-5, "stamp %u time %g", i, c->s[i].time_s);
    }
    free(c);
}

static void test_fast_jump_is_capped_and_respaced_evenly(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT,
                                        .filter = {.spacing_px = 1, .max_stamps = 16, .no_smoothing = true}});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 0, 0, 1, 0.0, c);
    feed(&in, RS_INPUT_MOVE, 1, 0, 320, 1, 0.01, c);
    if (!RS_CHECK(c->n == 17, "%u stamps, want 1 + 16", c->n)) return;
    for (uint32_t i = 1; i < 17; i++)
        RS_CHECK(fabsf(c->s[i].y_px - 20.0f * i) < 1e-3f, "stamp %u at %g", i, c->s[i].y_px);
    free(c);
}

static void test_event_rate_does_not_change_where_stamps_land(void)
{
    collected *slow = new_collected(), *fast = new_collected();
    rs_input a, b;
    rs_input_desc d = {.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 3}};
    rs_input_init(&a, &d);
    rs_input_init(&b, &d);
    draw_curve(&a, 60.0, 1.0, slow);    // a mouse at 60 Hz
    draw_curve(&b, 240.0, 1.0, fast);   // a pen at 240 Hz
    RS_CHECK(abs((int)slow->n - (int)fast->n) <= slow->n / 20 + 2, "stamp counts %u vs %u", slow->n, fast->n);
    float worst = 0.0f;
    for (uint32_t i = 0; i < slow->n; i++) worst = fmaxf(worst, dist_to_set(&slow->s[i], fast));
    for (uint32_t i = 0; i < fast->n; i++) worst = fmaxf(worst, dist_to_set(&fast->s[i], slow));
    RS_CHECK(worst < 3.0f, "paths differ by %.2f px between 60 and 240 Hz", worst);
    RS_CHECK(slow->s[slow->n - 1].x_px == fast->s[fast->n - 1].x_px, "strokes end apart");
    free(slow);
    free(fast);
}

static void test_smoothing_removes_jitter(void)
{
    rs_input raw, smooth;
    rs_input_init(&raw, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 2, .no_smoothing = true}});
    rs_input_init(&smooth, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 2}});
    collected *a = new_collected(), *b = new_collected();
    // A slow horizontal line at y = 100 with +-3 px tremor, 120 Hz.
    uint32_t seed = 1;
    feed(&raw, RS_INPUT_DOWN, 1, 0, 100, 1, 0, a);
    feed(&smooth, RS_INPUT_DOWN, 1, 0, 100, 1, 0, b);
    for (int i = 1; i < 240; i++) {
        seed = seed * 1664525u + 1013904223u;
        float jitter = ((seed >> 8) / 16777216.0f - 0.5f) * 6.0f;
        feed(&raw, RS_INPUT_MOVE, 1, 0.5f * i, 100 + jitter, 1, i / 120.0, a);
        feed(&smooth, RS_INPUT_MOVE, 1, 0.5f * i, 100 + jitter, 1, i / 120.0, b);
    }
    double ea = 0, eb = 0;
    for (uint32_t i = 0; i < a->n; i++) ea += fabsf(a->s[i].y_px - 100.0f);
    for (uint32_t i = 0; i < b->n; i++) eb += fabsf(b->s[i].y_px - 100.0f);
    ea /= a->n, eb /= b->n;
    RS_CHECK(eb < 0.5 * ea, "smoothed deviation %.2f px vs raw %.2f px", eb, ea);
    free(a);
    free(b);
}

static void test_view_mode_drag_orbits_without_stamps(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_VIEW});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 3, 10, 10, 1, 0, c);
    feed(&in, RS_INPUT_MOVE, 3, 25, 4, 1, 0.1, c);
    feed(&in, RS_INPUT_MOVE, 3, 30, 0, 1, 0.2, c);
    feed(&in, RS_INPUT_UP, 3, 30, 0, 1, 0.3, c);
    RS_CHECK(c->n == 0 && c->begins == 0, "view mode painted");
    RS_CHECK(c->orbit[0] == 20.0f && c->orbit[1] == -10.0f, "orbit %g %g", c->orbit[0], c->orbit[1]);
    RS_CHECK(in.state == RS_INPUT_IDLE, "state %d after up", in.state);
    free(c);
}

static void test_two_fingers_pinch_and_pan_in_both_modes(void)
{
    for (int mode = 0; mode < 2; mode++) {
        rs_input in;
        rs_input_init(&in, &(rs_input_desc){.mode = (rs_input_mode)mode});
        collected *c = new_collected();
        feed(&in, RS_INPUT_DOWN, 1, 100, 100, 1, 0.00, c);
        feed(&in, RS_INPUT_DOWN, 2, 200, 100, 1, 0.02, c);
        // Spread to twice the distance, then both move down 30 px.
        feed(&in, RS_INPUT_MOVE, 1, 50, 100, 1, 0.1, c);
        feed(&in, RS_INPUT_MOVE, 2, 250, 100, 1, 0.1, c);
        feed(&in, RS_INPUT_MOVE, 1, 50, 130, 1, 0.2, c);
        feed(&in, RS_INPUT_MOVE, 2, 250, 130, 1, 0.2, c);
        RS_CHECK(fabsf(c->zoom - 2.0f) < 1e-4f, "mode %d: zoom %g, want 2", mode, c->zoom);
        RS_CHECK(fabsf(c->pan[0]) < 1e-4f && fabsf(c->pan[1] - 30.0f) < 1e-4f, "mode %d: pan %g %g", mode, c->pan[0],
                 c->pan[1]);
        RS_CHECK(c->orbit[0] == 0 && c->orbit[1] == 0, "mode %d: orbit during pinch", mode);
        if (mode == RS_INPUT_PAINT)
            RS_CHECK(c->begins == 1 && c->cancels == 1 && c->ends == 0,
                     "paint: the first finger's stroke must be cancelled");
        // One finger lifts: the other must neither paint nor orbit until it lifts too.
        feed(&in, RS_INPUT_UP, 2, 250, 130, 1, 0.3, c);
        uint32_t n = c->n;
        feed(&in, RS_INPUT_MOVE, 1, 80, 160, 1, 0.4, c);
        RS_CHECK(c->n == n && c->orbit[0] == 0 && c->begins == (mode == RS_INPUT_PAINT),
                 "mode %d: leftover finger acted", mode);
        feed(&in, RS_INPUT_UP, 1, 80, 160, 1, 0.5, c);
        RS_CHECK(in.state == RS_INPUT_IDLE, "mode %d: not idle after all up", mode);
        free(c);
    }
}

static void test_cancel_rolls_back_stroke_and_bad_events_are_ignored(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 10, 10, 1, 0, c);
    feed(&in, RS_INPUT_MOVE, 1, NAN, 10, 1, 0.1, c);
    feed(&in, RS_INPUT_MOVE, 1, 20, INFINITY, 1, 0.1, c);
    feed(&in, RS_INPUT_MOVE, 99, 20, 20, 1, 0.1, c);  // unknown pointer
    feed(&in, RS_INPUT_MOVE, 1, 30, 10, NAN, 0.2, c);
    RS_CHECK(c->n > 1, "valid move after bad ones produced no stamps");
    for (uint32_t i = 0; i < c->n; i++)
        RS_CHECK(isfinite(c->s[i].x_px) && isfinite(c->s[i].y_px) && c->s[i].pressure >= 0 && c->s[i].pressure <= 1,
                 "bad stamp %u", i);
    feed(&in, RS_INPUT_CANCEL, 1, 0, 0, 0, 0.3, c);
    RS_CHECK(c->cancels == 1 && c->ends == 0 && in.state == RS_INPUT_IDLE, "cancel: %d cancels, state %d", c->cancels,
             in.state);
    // More pointers than tracked, repeated downs, ups of unknown ids: no crash, back to idle.
    for (int i = 0; i < 2 * RS_INPUT_MAX_POINTERS; i++) feed(&in, RS_INPUT_DOWN, i % 13, i, i, 1, 1.0, c);
    for (int i = 0; i < 20; i++) feed(&in, RS_INPUT_UP, i, 0, 0, 1, 2.0, c);
    RS_CHECK(in.state == RS_INPUT_IDLE && in.count == 0, "state %d with %u pointers", in.state, in.count);
    free(c);
}

static void test_spacing_change_applies_to_the_stroke_in_progress(void)
{
    rs_input in;
    rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 10, .no_smoothing = true}});
    collected *c = new_collected();
    feed(&in, RS_INPUT_DOWN, 1, 0, 0, 1, 0, c);
    feed(&in, RS_INPUT_MOVE, 1, 40, 0, 1, 0.1, c);
    uint32_t n = c->n;
    rs_input_set_spacing(&in, 2.0f);
    feed(&in, RS_INPUT_MOVE, 1, 80, 0, 1, 0.2, c);
    RS_CHECK(n == 5 && c->n - n == 20, "stamps %u then %u, want 5 then 20", n, c->n - n);
    free(c);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_tap_gives_one_stamp_where_it_landed);
    RS_RUN(test_straight_stroke_is_resampled_at_even_spacing);
    RS_RUN(test_pressure_and_time_are_interpolated_between_events);
    RS_RUN(test_fast_jump_is_capped_and_respaced_evenly);
    RS_RUN(test_event_rate_does_not_change_where_stamps_land);
    RS_RUN(test_smoothing_removes_jitter);
    RS_RUN(test_view_mode_drag_orbits_without_stamps);
    RS_RUN(test_two_fingers_pinch_and_pan_in_both_modes);
    RS_RUN(test_cancel_rolls_back_stroke_and_bad_events_are_ignored);
    RS_RUN(test_spacing_change_applies_to_the_stroke_in_progress);
    return rs_test_finish();
}
