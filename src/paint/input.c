// input.c — stroke filter (one-euro smoothing + arc-length resampling) and gesture recogniser.
#include "paint/input.h"

#include <math.h>
#include <string.h>

#define DEFAULT_SPACING_PX 4.0f
#define MIN_SPACING_PX 0.25f
#define MIN_DT_S 1e-4  // events with equal or backwards timestamps: treat as 0.1 ms apart

static float clamp_pressure(float p) { return isfinite(p) ? RS_CLAMP(p, 0.0f, 1.0f) : 1.0f; }

static rs_input_filter_desc filter_defaults(const rs_input_filter_desc *d)
{
    rs_input_filter_desc f = d ? *d : (rs_input_filter_desc){0};
    if (!(f.spacing_px > 0.0f) || !isfinite(f.spacing_px)) f.spacing_px = DEFAULT_SPACING_PX;
    f.spacing_px = RS_MAX(f.spacing_px, MIN_SPACING_PX);
    if (f.max_stamps == 0 || f.max_stamps > RS_INPUT_MAX_STAMPS) f.max_stamps = RS_INPUT_MAX_STAMPS;
    if (!(f.min_cutoff_hz > 0.0f) || !isfinite(f.min_cutoff_hz)) f.min_cutoff_hz = RS_INPUT_MIN_CUTOFF_HZ;
    if (!(f.beta > 0.0f) || !isfinite(f.beta)) f.beta = RS_INPUT_BETA;
    return f;
}

// Smoothing factor of a first-order low-pass with the given cutoff over dt (one-euro filter).
static float lowpass_alpha(float cutoff_hz, float dt)
{
    float tau = 1.0f / (2.0f * 3.14159265f * cutoff_hz);
    return 1.0f / (1.0f + tau / dt);
}

static void emit(rs_input_stamp *out, uint32_t *n, float x, float y, float p, double t)
{
    out[(*n)++] = (rs_input_stamp){x, y, p, t};
}

// Extends the resampled path to (x, y): a stamp every spacing px of arc length, pressure and time
// interpolated; more than max_stamps in one segment are respaced evenly over it.
static void extend_path(rs_input_stroke *s, float x, float y, float p, double t, rs_input_stamp *out, uint32_t *n)
{
    float ex = x - s->px, ey = y - s->py;
    float len = sqrtf(ex * ex + ey * ey);
    float spacing = s->desc.spacing_px;
    if (len > 0.0f) {
        double due = floor(((double)s->since + len) / spacing);
        if (due > s->desc.max_stamps) {
            uint32_t k = s->desc.max_stamps;
            for (uint32_t i = 1; i <= k; i++) {
                float u = (float)i / (float)k;
                emit(out, n, s->px + ex * u, s->py + ey * u, s->pp + (p - s->pp) * u, s->pt + (t - s->pt) * u);
            }
            s->since = 0.0f;
        } else {
            for (uint32_t i = 0; i < (uint32_t)due; i++) {
                float u = (spacing - s->since + spacing * (float)i) / len;
                u = RS_MIN(u, 1.0f);
                emit(out, n, s->px + ex * u, s->py + ey * u, s->pp + (p - s->pp) * u, s->pt + (t - s->pt) * u);
            }
            s->since = s->since + len - spacing * (float)due;
            s->since = RS_CLAMP(s->since, 0.0f, spacing);
        }
    }
    s->px = x, s->py = y, s->pp = p, s->pt = t;
}

void rs_input_stroke_begin(rs_input_stroke *s, const rs_input_filter_desc *desc, const rs_input_event *ev,
                           rs_input_stamp *out, uint32_t *n)
{
    memset(s, 0, sizeof *s);
    s->desc = filter_defaults(desc);
    s->active = true;
    s->fx = s->px = ev->x_px;
    s->fy = s->py = ev->y_px;
    s->t = s->pt = ev->time_s;
    s->pp = clamp_pressure(ev->pressure);
    emit(out, n, s->px, s->py, s->pp, s->pt);
}

void rs_input_stroke_move(rs_input_stroke *s, const rs_input_event *ev, rs_input_stamp *out, uint32_t *n)
{
    if (!s->active) return;
    float x = ev->x_px, y = ev->y_px;
    if (!s->desc.no_smoothing) {
        double dtd = ev->time_s - s->t;
        float dt = (float)(dtd > MIN_DT_S && isfinite(dtd) ? dtd : MIN_DT_S);
        // One-euro: low-pass the velocity, let its magnitude raise the position filter's cutoff.
        // The first move seeds the velocity directly: starting from rest, a quick flick would otherwise
        // be filtered at the minimum cutoff for its whole (short) life and cut its curves.
        float a_d = s->moved ? lowpass_alpha(RS_INPUT_D_CUTOFF_HZ, dt) : 1.0f;
        s->moved = true;
        s->dx += a_d * ((x - s->fx) / dt - s->dx);
        s->dy += a_d * ((y - s->fy) / dt - s->dy);
        float cutoff = s->desc.min_cutoff_hz + s->desc.beta * sqrtf(s->dx * s->dx + s->dy * s->dy);
        float a = lowpass_alpha(cutoff, dt);
        s->fx += a * (x - s->fx);
        s->fy += a * (y - s->fy);
        x = s->fx, y = s->fy;
    }
    s->t = RS_MAX(ev->time_s, s->t);
    extend_path(s, x, y, clamp_pressure(ev->pressure), s->t, out, n);
}

void rs_input_stroke_end(rs_input_stroke *s, const rs_input_event *ev, rs_input_stamp *out, uint32_t *n)
{
    if (!s->active) return;
    s->t = RS_MAX(ev->time_s, s->t);
    extend_path(s, ev->x_px, ev->y_px, clamp_pressure(ev->pressure), s->t, out, n);
    // The stroke ends exactly where the pointer lifted, whatever the spacing.
    if (s->since > 0.0f) emit(out, n, s->px, s->py, s->pp, s->pt);
    s->active = false;
}

// --- gestures ----------------------------------------------------------------------------------------

void rs_input_init(rs_input *in, const rs_input_desc *desc)
{
    memset(in, 0, sizeof *in);
    if (desc) in->desc = *desc;
    in->desc.filter = filter_defaults(&in->desc.filter);
}

void rs_input_set_mode(rs_input *in, rs_input_mode mode) { in->desc.mode = mode; }

void rs_input_set_spacing(rs_input *in, float spacing_px)
{
    in->desc.filter.spacing_px = spacing_px;
    in->desc.filter = filter_defaults(&in->desc.filter);
    // Also for the stroke in progress: brush size on screen changes when the stroke crosses depth.
    if (in->stroke.active) in->stroke.desc.spacing_px = in->desc.filter.spacing_px;
}

static int find_ptr(const rs_input *in, int32_t id)
{
    for (uint32_t i = 0; i < in->count; i++)
        if (in->ptr[i].id == id) return (int)i;
    return -1;
}

static const rs_input_pointer *ptr_of(const rs_input *in, int32_t id)
{
    int i = find_ptr(in, id);
    return i >= 0 ? &in->ptr[i] : NULL;
}

static void remove_ptr(rs_input *in, int i)
{
    in->ptr[i] = in->ptr[--in->count];
}

static void two_finger_frame(const rs_input *in, float centre[2], float *distance)
{
    const rs_input_pointer *a = ptr_of(in, in->gesture_id[0]), *b = ptr_of(in, in->gesture_id[1]);
    centre[0] = 0.5f * (a->x_px + b->x_px);
    centre[1] = 0.5f * (a->y_px + b->y_px);
    *distance = hypotf(a->x_px - b->x_px, a->y_px - b->y_px);
}

static void pointer_down(rs_input *in, const rs_input_event *ev, rs_input_output *out)
{
    if (find_ptr(in, ev->pointer_id) >= 0 || in->count >= RS_INPUT_MAX_POINTERS) return;
    in->ptr[in->count++] = (rs_input_pointer){ev->pointer_id, ev->x_px, ev->y_px};
    if (in->state == RS_INPUT_IDLE && in->count == 1) {
        in->state = RS_INPUT_ONE;
        in->gesture_id[0] = ev->pointer_id;
        if (in->desc.mode == RS_INPUT_PAINT) {
            in->painting = true;
            out->stroke_begin = true;
            rs_input_stroke_begin(&in->stroke, &in->desc.filter, ev, out->stamps, &out->stamp_count);
        }
    } else if (in->state == RS_INPUT_ONE && in->count == 2) {
        // A second finger means navigation: the stroke the first finger began was not meant.
        if (in->painting) {
            in->painting = false;
            in->stroke.active = false;
            out->stroke_cancel = true;
        }
        in->state = RS_INPUT_TWO;
        in->gesture_id[1] = ev->pointer_id;
        two_finger_frame(in, in->centre, &in->distance);
    }
}

static void pointer_move(rs_input *in, const rs_input_event *ev, rs_input_output *out)
{
    int i = find_ptr(in, ev->pointer_id);
    if (i < 0) return;
    float ox = in->ptr[i].x_px, oy = in->ptr[i].y_px;
    in->ptr[i].x_px = ev->x_px;
    in->ptr[i].y_px = ev->y_px;
    if (in->state == RS_INPUT_ONE && ev->pointer_id == in->gesture_id[0]) {
        if (in->painting) {
            rs_input_stroke_move(&in->stroke, ev, out->stamps, &out->stamp_count);
        } else {
            out->orbit_dx_px = ev->x_px - ox;
            out->orbit_dy_px = ev->y_px - oy;
        }
    } else if (in->state == RS_INPUT_TWO &&
               (ev->pointer_id == in->gesture_id[0] || ev->pointer_id == in->gesture_id[1])) {
        float c[2], d;
        two_finger_frame(in, c, &d);
        out->pan_dx_px = c[0] - in->centre[0];
        out->pan_dy_px = c[1] - in->centre[1];
        // Fingers closer than a pixel carry no usable scale.
        if (in->distance >= 1.0f && d >= 1.0f) out->zoom = d / in->distance;
        out->zoom_cx_px = c[0];
        out->zoom_cy_px = c[1];
        in->centre[0] = c[0], in->centre[1] = c[1];
        in->distance = d;
    }
}

static void pointer_up(rs_input *in, const rs_input_event *ev, bool cancel, rs_input_output *out)
{
    int i = find_ptr(in, ev->pointer_id);
    if (i < 0) return;
    if (in->state == RS_INPUT_ONE && ev->pointer_id == in->gesture_id[0] && in->painting) {
        in->painting = false;
        if (cancel) {
            in->stroke.active = false;
            out->stroke_cancel = true;
        } else {
            rs_input_stroke_end(&in->stroke, ev, out->stamps, &out->stamp_count);
            out->stroke_end = true;
        }
    }
    bool gesture_ptr = (in->state == RS_INPUT_ONE && ev->pointer_id == in->gesture_id[0]) ||
                       (in->state == RS_INPUT_TWO &&
                        (ev->pointer_id == in->gesture_id[0] || ev->pointer_id == in->gesture_id[1]));
    remove_ptr(in, i);
    if (gesture_ptr || in->state == RS_INPUT_WAIT_UP)
        in->state = in->count ? RS_INPUT_WAIT_UP : RS_INPUT_IDLE;
}

void rs_input_feed(rs_input *in, const rs_input_event *ev, rs_input_output *out)
{
    memset(out, 0, offsetof(rs_input_output, stamps));
    out->zoom = 1.0f;
    // Hostile or broken drivers: non-finite positions are dropped (a cancel still cancels).
    bool finite = isfinite(ev->x_px) && isfinite(ev->y_px) && isfinite(ev->time_s);
    rs_input_event e = *ev;
    e.pressure = clamp_pressure(ev->pressure);
    switch (ev->type) {
    case RS_INPUT_DOWN:
        if (finite) pointer_down(in, &e, out);
        break;
    case RS_INPUT_MOVE:
        if (finite) pointer_move(in, &e, out);
        break;
    case RS_INPUT_UP:
        if (!finite) {
            // Lift at the last known position.
            const rs_input_pointer *p = ptr_of(in, ev->pointer_id);
            if (!p) break;
            e.x_px = p->x_px, e.y_px = p->y_px, e.time_s = in->stroke.t;
        }
        pointer_up(in, &e, false, out);
        break;
    case RS_INPUT_CANCEL:
        pointer_up(in, &e, true, out);
        break;
    }
}
