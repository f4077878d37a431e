// paint.c — glue from pointer events to layer stamps through the renderer's picker.
#include "paint/paint.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEFAULT_SPACING_REL 0.15f       // stamp spacing = 15 % of the brush radius (Blender: 10 % of diameter)
#define REPLAY_POINTER_ID (-0x7fff0000)  // an id no device hands out
#define BRIDGE_MIN_REL 0.5f   // consecutive stamps further apart than this many brush radii get stamps between
#define BRIDGE_MAX_REL 4.0f   // ... unless further than this (a jump across a fold or off an edge: not bridged)
#define BRIDGE_MAX 16         // at most this many stamps between two

struct rs_paint {
    rs_makeup *mk;
    rs_paint_picker picker;
    rs_paint_brush brush;         // as set (zeros = defaults)
    rs_paint_brush stroke_brush;  // resolved, fixed for the stroke in progress
    float spacing_rel;
    rs_input input;
    rs_strokes *rec;
    rs_strokes_view rec_view;
    rs_smudge smudge;             // the load of a smudge or blend stroke in progress
    float last[3];                // the stroke's last paint stamp (has_last): where bridge() starts
    bool has_last;
    bool rec_open;
    int32_t rec_pointer;
    double rec_t0;
};

static rs_paint_brush resolve_brush(const rs_paint_brush *b)
{
    rs_paint_brush r = *b;
    if (r.cosmetic.name[0] == '\0') r.cosmetic = *rs_cosmetic_find("foundation_1");
    if (!(r.size_rel > 0.0f) || !isfinite(r.size_rel)) r.size_rel = r.cosmetic.size_rel;
    if (!(r.opacity > 0.0f) || !isfinite(r.opacity)) r.opacity = r.cosmetic.opacity;
    r.size_rel = RS_MIN(r.size_rel, 1.0f);
    r.opacity = RS_MIN(r.opacity, 1.0f);
    if ((unsigned)r.pressure >= RS_MAKEUP_PRESSURE_COUNT) r.pressure = RS_MAKEUP_PRESSURE_FLOOR;
    if ((unsigned)r.tool >= RS_TOOL_COUNT) r.tool = RS_TOOL_PAINT;
    // A smudge or blend brush's strength is its own, not the selected product's opacity.
    if (r.tool != RS_TOOL_PAINT) r.eraser = false, r.opacity = b->opacity > 0.0f && isfinite(b->opacity)
                                                                  ? RS_MIN(b->opacity, 1.0f)
                                                                  : RS_SMUDGE_STRENGTH_DEFAULT;
    return r;
}

rs_result rs_paint_create(rs_makeup *mk, const rs_paint_picker *picker, const rs_paint_desc *desc, rs_paint **out,
                          rs_error *err)
{
    if (!picker || !picker->pick) return rs_fail(err, RS_ERR_ARG, "paint: a picker with pick() is required");
    rs_paint *p = calloc(1, sizeof *p);
    if (!p) return rs_fail(err, RS_ERR_NOMEM, "paint: out of memory");
    static const rs_paint_desc none;
    if (!desc) desc = &none;
    p->mk = mk;
    p->picker = *picker;
    p->brush = desc->brush;
    p->stroke_brush = resolve_brush(&p->brush);
    p->spacing_rel = desc->spacing_rel > 0.0f && isfinite(desc->spacing_rel) ? desc->spacing_rel : DEFAULT_SPACING_REL;
    rs_input_init(&p->input, &desc->input);
    *out = p;
    return RS_OK;
}

void rs_paint_destroy(rs_paint *p) { free(p); }

void rs_paint_set_brush(rs_paint *p, const rs_paint_brush *brush) { p->brush = *brush; }
const rs_paint_brush *rs_paint_get_brush(const rs_paint *p) { return &p->brush; }
void rs_paint_set_mode(rs_paint *p, rs_input_mode mode) { rs_input_set_mode(&p->input, mode); }

float rs_paint_radius(const rs_paint *p)
{
    rs_paint_brush b = resolve_brush(&p->brush);
    return rs_makeup_brush_radius(&rs_makeup_cloud(p->mk)->hdr, b.size_rel);
}

void rs_paint_set_recorder(rs_paint *p, rs_strokes *doc, const rs_strokes_view *view)
{
    // Same document: only the view changes (for the next stroke); the open stroke keeps recording.
    if (doc != p->rec) {
        if (p->rec && p->rec_open) rs_strokes_drop_open(p->rec);
        p->rec = doc;
        p->rec_open = false;
    }
    if (view) p->rec_view = *view;
}

static void merge(rs_makeup_range *into, rs_makeup_range r)
{
    if (r.lo >= r.hi) return;
    if (into->lo >= into->hi) {
        *into = r;
    } else {
        into->lo = RS_MIN(into->lo, r.lo);
        into->hi = RS_MAX(into->hi, r.hi);
    }
}

// Keeps stamps spacing_rel of a brush radius apart on screen at the point being painted.
static void set_spacing(const rs_paint *p, rs_input *in, float size_rel, const float pos[3])
{
    if (!p->picker.pixels_per_unit) return;
    float ppu = p->picker.pixels_per_unit(p->picker.user, pos);
    float radius = rs_makeup_brush_radius(&rs_makeup_cloud(p->mk)->hdr, size_rel);
    if (isfinite(ppu) && ppu > 0.0f) rs_input_set_spacing(in, p->spacing_rel * radius * ppu);
}

static void update_spacing(rs_paint *p, const float pos[3]) { set_spacing(p, &p->input, p->stroke_brush.size_rel, pos); }

static bool pick(const rs_paint *p, float x, float y, uint32_t *idx, float hit[3])
{
    return p->picker.pick(p->picker.user, x, y, idx, hit) && *idx < rs_makeup_count(p->mk);
}

// Stamps to put between two consecutive ones a and b, radius r: stamps are spaced on screen and placed at
// the surface point of the pixel under the pointer, so where the surface turns from the view neighbouring
// pixels' points lie millimetres apart and a narrow brush fell apart into dots there. A gap of more than
// half a radius is filled at the stroke's spacing (a jump of more than 4 radii, across a fold or off an
// edge, is left: the stroke left that surface).
static uint32_t bridge(const rs_paint *p, const float a[3], const float b[3], float r)
{
    float dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2], d = sqrtf(dx * dx + dy * dy + dz * dz);
    if (!(d > BRIDGE_MIN_REL * r) || d > BRIDGE_MAX_REL * r) return 0;
    return (uint32_t)RS_MIN(ceilf(d / (p->spacing_rel * r)) - 1.0f, (float)BRIDGE_MAX);
}

static rs_result stamp_at(rs_paint *p, const rs_input_stamp *s, rs_paint_result *res, rs_error *err)
{
    uint32_t idx;
    float pos[3];
    if (!pick(p, s->x_px, s->y_px, &idx, pos)) {
        res->misses++;  // background: stamp nothing
        p->has_last = false;
        return RS_OK;
    }
    const rs_splat_cloud *cloud = rs_makeup_cloud(p->mk);
    const rs_paint_brush *b = &p->stroke_brush;
    rs_makeup_stamp_info info;
    if (b->tool != RS_TOOL_PAINT) {
        p->has_last = false;
        rs_smudge_stamp_desc sd = {.pos = {pos[0], pos[1], pos[2]},
                                   .radius = rs_makeup_brush_radius(&cloud->hdr, b->size_rel),
                                   .strength = b->opacity,
                                   .pressure = s->pressure,
                                   .pressure_map = b->pressure,
                                   .mirror = b->mirror};
        if (p->picker.view_dir) p->picker.view_dir(p->picker.user, pos, sd.view_dir);
        rs_result r = rs_smudge_stamp(&p->smudge, p->mk, &sd, &info, err);
        if (r != RS_OK) return r;
        merge(&res->dirty, info.dirty);
        res->stamps++;
        update_spacing(p, pos);
        return RS_OK;
    }
    rs_makeup_stamp_desc d = {
        .pos = {pos[0], pos[1], pos[2]},
        .radius = rs_makeup_brush_radius(&cloud->hdr, b->size_rel),
        .opacity = b->opacity,
        .pressure = s->pressure,
        .pressure_map = b->pressure,
        .cosmetic = &b->cosmetic,
        .eraser = b->eraser,
        .mirror = b->mirror,
        .region_mask = !b->any_region,
    };
    uint32_t n = p->has_last ? bridge(p, p->last, pos, d.radius) : 0;
    for (uint32_t k = 1; k <= n + 1; k++) {
        float t = (float)k / (float)(n + 1);
        for (int a = 0; a < 3; a++) d.pos[a] = k > n ? pos[a] : p->last[a] + (pos[a] - p->last[a]) * t;
        if (p->picker.view_dir) p->picker.view_dir(p->picker.user, d.pos, d.view_dir);
        rs_result r = rs_makeup_stamp(p->mk, &d, &info, err);
        if (r != RS_OK) return r;
        merge(&res->dirty, info.dirty);
        res->stamps++;
    }
    memcpy(p->last, pos, sizeof p->last);
    p->has_last = true;
    update_spacing(p, pos);
    return RS_OK;
}

static void record(rs_paint *p, const rs_input_event *ev)
{
    if (!p->rec_open || ev->pointer_id != p->rec_pointer) return;
    rs_strokes_sample s = {(float)(ev->time_s - p->rec_t0), ev->x_px, ev->y_px,
                           isfinite(ev->pressure) ? RS_CLAMP(ev->pressure, 0.0f, 1.0f) : 1.0f};
    // A sample the file could not hold (a driver's odd value) is left out rather than failing the stroke.
    rs_strokes_add_sample(p->rec, &s, NULL);
}

rs_result rs_paint_feed(rs_paint *p, const rs_input_event *ev, rs_paint_result *res, rs_error *err)
{
    memset(res, 0, sizeof *res);
    res->zoom = 1.0f;
    bool starts = ev->type == RS_INPUT_DOWN && p->input.state == RS_INPUT_IDLE &&
                  p->input.desc.mode == RS_INPUT_PAINT;
    if (starts) {
        p->stroke_brush = resolve_brush(&p->brush);
        uint32_t idx;
        float hit[3];
        if (isfinite(ev->x_px) && isfinite(ev->y_px) && pick(p, ev->x_px, ev->y_px, &idx, hit))
            update_spacing(p, hit);
    }
    rs_input_output out;
    rs_input_feed(&p->input, ev, &out);
    res->orbit_dx_px = out.orbit_dx_px, res->orbit_dy_px = out.orbit_dy_px;
    res->pan_dx_px = out.pan_dx_px, res->pan_dy_px = out.pan_dy_px;
    res->zoom = out.zoom, res->zoom_cx_px = out.zoom_cx_px, res->zoom_cy_px = out.zoom_cy_px;
    res->stroke_begin = out.stroke_begin, res->stroke_end = out.stroke_end, res->stroke_cancel = out.stroke_cancel;

    if (out.stroke_begin) {
        p->has_last = false;
        rs_makeup_begin_stroke(p->mk);
        rs_smudge_begin(&p->smudge, p->stroke_brush.tool);
        if (p->rec) {
            rs_strokes_brush sb = {p->stroke_brush.size_rel, p->stroke_brush.opacity, p->stroke_brush.pressure,
                                   p->stroke_brush.mirror, p->stroke_brush.eraser, p->stroke_brush.any_region,
                                   p->stroke_brush.tool};
            p->rec_open = rs_strokes_begin(p->rec, &p->rec_view, &sb, &p->stroke_brush.cosmetic, NULL) == RS_OK;
            p->rec_pointer = ev->pointer_id;
            p->rec_t0 = ev->time_s;
        }
    }
    if (ev->type != RS_INPUT_CANCEL && (out.stroke_begin || p->input.painting || out.stroke_end)) record(p, ev);

    rs_result r = RS_OK;
    for (uint32_t i = 0; i < out.stamp_count && r == RS_OK; i++) r = stamp_at(p, &out.stamps[i], res, err);

    if (out.stroke_cancel || r != RS_OK) {
        rs_makeup_range d;
        rs_makeup_cancel_stroke(p->mk, &d);
        merge(&res->dirty, d);
        if (p->rec_open) rs_strokes_drop_open(p->rec);
        p->rec_open = false;
        if (r != RS_OK) {
            // Keep the input in step with the layer: the stroke is gone.
            p->input.painting = false;
            p->input.stroke.active = false;
            res->stroke_cancel = true;
        }
    } else if (out.stroke_end) {
        r = rs_makeup_end_stroke(p->mk, err);
        if (p->rec_open) rs_strokes_end(p->rec);
        p->rec_open = false;
    }
    return r;
}

static rs_input_event replay_event(const rs_strokes_sample *sm, uint32_t n, uint32_t k, float sx, float sy)
{
    // The live sequence was down (first sample), moves, up (last sample).
    uint32_t j = RS_MIN(k, n - 1);
    rs_input_type type = k == 0 ? RS_INPUT_DOWN : k + 1 >= n + (n == 1) ? RS_INPUT_UP : RS_INPUT_MOVE;
    return (rs_input_event){type, REPLAY_POINTER_ID, sm[j].x_px * sx, sm[j].y_px * sy, sm[j].pressure, sm[j].t_s};
}

// Stamps a replay would paint, counted without painting: the same input filter, picks and spacing as
// rs_paint_feed (the ID buffer does not depend on the makeup), so a work bomb is refused before its work.
// Stops once the cover bound is passed; *stamps is then the count the painting replay would fail at.
static bool replay_within_bound(const rs_paint *p, const rs_strokes_sample *sm, uint32_t n, float sx, float sy,
                                double q, uint32_t *stamps)
{
    rs_input in = p->input;
    rs_paint_brush b = resolve_brush(&p->brush);
    float size_rel = b.size_rel, radius = rs_makeup_brush_radius(&rs_makeup_cloud(p->mk)->hdr, size_rel), last[3];
    bool has_last = false;
    rs_input_output out;
    *stamps = 0;
    for (uint32_t k = 0; k < n + (n == 1); k++) {
        rs_input_event ev = replay_event(sm, n, k, sx, sy);
        uint32_t idx;
        float hit[3];
        if (k == 0 && isfinite(ev.x_px) && isfinite(ev.y_px) && pick(p, ev.x_px, ev.y_px, &idx, hit))
            set_spacing(p, &in, size_rel, hit);
        rs_input_feed(&in, &ev, &out);
        for (uint32_t i = 0; i < out.stamp_count; i++) {
            if (!pick(p, out.stamps[i].x_px, out.stamps[i].y_px, &idx, hit)) {
                has_last = false;
                continue;
            }
            // As stamp_at: with the stamps it bridges to the last one.
            *stamps += 1 + (has_last && b.tool == RS_TOOL_PAINT ? bridge(p, last, hit, radius) : 0);
            memcpy(last, hit, sizeof last);
            has_last = true;
            set_spacing(p, &in, size_rel, hit);
        }
        if (*stamps * q * q > RS_PAINT_MAX_REPLAY_COVER) return false;
    }
    return true;
}

rs_result rs_paint_replay(rs_paint *p, const rs_strokes *doc, uint32_t stroke, uint32_t frame_w_px,
                          uint32_t frame_h_px, rs_paint_result *res, rs_error *err)
{
    memset(res, 0, sizeof *res);
    res->zoom = 1.0f;
    if (stroke >= doc->count) return rs_fail(err, RS_ERR_ARG, "paint replay: stroke %u of %u", stroke, doc->count);
    if (p->input.state != RS_INPUT_IDLE) return rs_fail(err, RS_ERR_ARG, "paint replay: a pointer is down");
    const rs_strokes_stroke *st = &doc->strokes[stroke];
    const rs_strokes_sample *sm = doc->samples + st->first_sample;
    if (st->sample_count == 0) return RS_OK;
    rs_paint_brush saved = p->brush;
    rs_input_mode saved_mode = p->input.desc.mode;
    rs_strokes *saved_rec = p->rec;
    p->rec = NULL;  // a replay is not something the person did
    p->brush = (rs_paint_brush){st->cosmetic,        st->brush.size_rel, st->brush.opacity, st->brush.pressure,
                                st->brush.eraser,    st->brush.mirror,   st->brush.any_region,
                                st->brush.tool};
    rs_input_set_mode(&p->input, RS_INPUT_PAINT);
    double q = rs_paint_radius(p) / rs_makeup_cloud(p->mk)->hdr.face_height;
    float sx = (float)frame_w_px / (float)st->view.width_px, sy = (float)frame_h_px / (float)st->view.height_px;
    rs_result r = RS_OK;
    // Each stamp costs the splats under it: a long zigzag with a wide brush is refused before it paints.
    uint32_t counted;
    if (!replay_within_bound(p, sm, st->sample_count, sx, sy, q, &counted))
        r = rs_fail(err, RS_ERR_LIMIT, "stroke %u paints more than %.0f face areas (%u stamps)", stroke,
                    RS_PAINT_MAX_REPLAY_COVER, counted);
    for (uint32_t k = 0; k < st->sample_count + (st->sample_count == 1) && r == RS_OK; k++) {
        rs_input_event ev = replay_event(sm, st->sample_count, k, sx, sy);
        rs_paint_result one;
        r = rs_paint_feed(p, &ev, &one, err);
        merge(&res->dirty, one.dirty);
        res->stamps += one.stamps;
        res->cover = res->stamps * q * q;
        res->misses += one.misses;
        res->stroke_begin |= one.stroke_begin;
        res->stroke_end |= one.stroke_end;
        res->stroke_cancel |= one.stroke_cancel;
    }
    if (r != RS_OK && p->input.state != RS_INPUT_IDLE) {
        // Leave no phantom pointer behind a failed replay.
        rs_input_output out;
        rs_input_feed(&p->input, &(rs_input_event){RS_INPUT_CANCEL, REPLAY_POINTER_ID, 0, 0, 0, 0}, &out);
    }
    p->brush = saved;
    rs_input_set_mode(&p->input, saved_mode);
    p->rec = saved_rec;
    return r;
}
