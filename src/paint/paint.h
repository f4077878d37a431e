// paint.h — the painting session: pointer events in, stamps on the makeup layer out.
//
// Does: run pointer events through the gesture recogniser and stroke filter (src/paint/input.h), turn each
// stamp's pixel into a splat through the renderer's picker (ID buffer), stamp the layer at the picked
// splat's position with the current brush (cosmetic, size, opacity, pressure map, eraser, mirror),
// keep stamp spacing at a fraction of the brush radius on screen, open/close/cancel layer strokes with
// the pointer, optionally record what happened into a stroke document, and replay a recorded stroke.
// Does not: render or read the ID buffer (the picker does), move the camera (navigation deltas are
// returned for the app), or upload records (the dirty range is returned).
//
//   rs_paint_picker pk = {.user = renderer, .pick = my_pick, .pixels_per_unit = my_ppu, .view_dir = my_dir};
//   rs_paint *pt = NULL;
//   rs_paint_create(layer, &pk, &(rs_paint_desc){.input.mode = RS_INPUT_PAINT}, &pt, &err);
//   rs_paint_result res;
//   rs_paint_feed(pt, &event, &res, &err);   // then upload records [res.dirty.lo, res.dirty.hi)
#ifndef RS_PAINT_H
#define RS_PAINT_H

#include "core/core.h"
#include "makeup/cosmetics.h"
#include "paint/input.h"
#include "makeup/makeup.h"
#include "makeup/smudge.h"
#include "formats/strokes.h"

// Implemented by the renderer for the current camera and frame.
typedef struct rs_paint_picker {
    void *user;
    // Splat index visible at the pixel (ID buffer) and the surface point under the pixel (the stamp
    // centre); false on background.
    bool (*pick)(void *user, float x_px, float y_px, uint32_t *splat_index, float hit[3]);
    // On-screen pixels per model unit at a model-space point (for stamp spacing).
    float (*pixels_per_unit)(void *user, const float pos[3]);
    // Unit vector from pos TOWARDS the eye (for the facing test); zero to disable the test.
    void (*view_dir)(void *user, const float pos[3], float dir_out[3]);
} rs_paint_picker;

typedef struct rs_paint_brush {
    rs_cosmetic cosmetic;         // by value, so custom colours need no storage elsewhere
    float size_rel;               // diameter / face height; 0 = the cosmetic's default
    float opacity;                // 0..1; 0 = the cosmetic's default
    rs_makeup_pressure pressure;  // how pressure scales opacity
    bool eraser, mirror;
    bool any_region;              // paint anywhere; default: keep to the cosmetic's region (soft-edged)
    rs_paint_tool tool;           // paint (with or without eraser), smudge or blend (src/makeup/smudge.h)
} rs_paint_brush;

typedef struct rs_paint_desc {
    rs_paint_brush brush;  // empty cosmetic name = "foundation_1"
    float spacing_rel;     // stamp spacing / brush radius; 0 = 0.15
    rs_input_desc input;   // mode and smoothing (spacing is managed here)
} rs_paint_desc;

typedef struct rs_paint_result {
    float orbit_dx_px, orbit_dy_px;  // for the app's camera (view mode one-pointer drag)
    float pan_dx_px, pan_dy_px;      // two-pointer drag
    float zoom, zoom_cx_px, zoom_cy_px;  // pinch factor (1 = none) and centre
    rs_makeup_range dirty;           // records to upload (union over everything this call did)
    uint32_t stamps, misses;         // stamps applied, stamps whose pixel hit background
    double cover;                    // rs_paint_replay: stamps x (radius / face height)^2, its work
    bool stroke_begin, stroke_end, stroke_cancel;
} rs_paint_result;

typedef struct rs_paint rs_paint;

// The layer and picker must outlive the session.
rs_result rs_paint_create(rs_makeup *mk, const rs_paint_picker *picker, const rs_paint_desc *desc, rs_paint **out,
                          rs_error *err);
void rs_paint_destroy(rs_paint *p);

void rs_paint_set_brush(rs_paint *p, const rs_paint_brush *brush);  // takes effect at the next stroke
const rs_paint_brush *rs_paint_get_brush(const rs_paint *p);
void rs_paint_set_mode(rs_paint *p, rs_input_mode mode);
// Brush radius in model units for the current brush.
float rs_paint_radius(const rs_paint *p);

rs_result rs_paint_feed(rs_paint *p, const rs_input_event *ev, rs_paint_result *res, rs_error *err);

// While set, each painted stroke (raw pointer samples, brush, cosmetic and the given view) is appended
// to doc; cancelled strokes are dropped. NULL stops recording (dropping a stroke in progress). Calling
// again with the same doc only updates the view (copied; NULL keeps it) for the strokes that follow.
void rs_paint_set_recorder(rs_paint *p, rs_strokes *doc, const rs_strokes_view *view);

// Replays one recorded stroke: sets the brush from it and feeds its samples as one pointer in paint
// mode, coordinates scaled by (frame size / stroke view size). The caller has set the camera to
// stroke->view first (the picker must see that view). The brush and mode are restored afterwards.
// Work bound of a replay (files are untrusted): the stamps a replay makes, summed as face areas
// (stamps x (brush radius / face height)^2), may not pass this; a stroke file's replays share it.
#define RS_PAINT_MAX_REPLAY_COVER 256.0
rs_result rs_paint_replay(rs_paint *p, const rs_strokes *doc, uint32_t stroke, uint32_t frame_w_px,
                          uint32_t frame_h_px, rs_paint_result *res, rs_error *err);

#endif
