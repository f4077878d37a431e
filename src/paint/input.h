// input.h — device-independent pointer input: stroke smoothing and resampling into brush stamps, and
// the gesture recogniser that tells painting from view navigation.
//
// Does: take pointer events (down/move/up/cancel, pointer id, pixels, pressure 0..1, seconds) from a
// mouse, a tablet or touch; smooth a stroke with a one-euro filter and resample it into stamps at a
// fixed spacing in pixels (pressure and time interpolated; at most max_stamps per event, respaced
// evenly beyond that) so hand speed and event rate do not change where stamps land; recognise one
// pointer = orbit (view mode) or paint (paint mode) and two pointers = pinch zoom + two-finger pan in
// both modes (a second finger cancels a stroke just begun). Pure state machines: no allocation.
// Does not: pick splats or paint (src/paint/paint.c), know the camera (gestures are pixel deltas), or read
// devices (the app translates GLFW / touch events into rs_input_event).
//
//   rs_input in;
//   rs_input_init(&in, &(rs_input_desc){.mode = RS_INPUT_PAINT, .filter = {.spacing_px = 3.0f}});
//   rs_input_output out;
//   rs_input_feed(&in, &(rs_input_event){RS_INPUT_DOWN, 0, 100, 80, 1.0f, 0.0}, &out);
//   for (uint32_t i = 0; i < out.stamp_count; i++) stamp_at(out.stamps[i].x_px, out.stamps[i].y_px);
#ifndef RS_INPUT_H
#define RS_INPUT_H

#include "core/core.h"

#define RS_INPUT_MAX_POINTERS 10
#define RS_INPUT_MAX_STAMPS 64  // per event: fast strokes are respaced evenly, never lag behind

// One-euro filter defaults (Casiez, Roussel, Vogel, CHI 2012). The cutoff rises with speed:
// cutoff = min_cutoff + beta * |velocity px/s|. At slow speeds (30 px/s) that is 1.6 Hz, which
// removes tremor; at a brisk 300 px/s, 7 Hz: about 7 px of lag, caught up at pointer-up.
#define RS_INPUT_MIN_CUTOFF_HZ 1.0f
#define RS_INPUT_BETA 0.02f
#define RS_INPUT_D_CUTOFF_HZ 1.0f

typedef enum rs_input_type {
    RS_INPUT_DOWN = 0,
    RS_INPUT_MOVE,
    RS_INPUT_UP,
    RS_INPUT_CANCEL,  // the system took the pointer back (palm rejection): roll the stroke back
} rs_input_type;

typedef struct rs_input_event {
    rs_input_type type;
    int32_t pointer_id;
    float x_px, y_px;  // window pixels, origin top-left
    float pressure;    // 0..1; a mouse passes 1
    double time_s;     // any monotonic clock
} rs_input_event;

typedef struct rs_input_stamp {
    float x_px, y_px, pressure;
    double time_s;
} rs_input_stamp;

typedef struct rs_input_filter_desc {
    float spacing_px;      // distance between stamps along the stroke; 0 = 4 px. Min 0.25 px
    uint32_t max_stamps;   // per event; 0 = RS_INPUT_MAX_STAMPS (also the upper limit)
    float min_cutoff_hz;   // 0 = RS_INPUT_MIN_CUTOFF_HZ
    float beta;            // 0 = RS_INPUT_BETA
    bool no_smoothing;     // raw positions (tests, replays of already smoothed data)
} rs_input_filter_desc;

// The stroke filter for one pointer. Fields are private.
typedef struct rs_input_stroke {
    rs_input_filter_desc desc;
    bool active, moved;
    float fx, fy;       // filtered position
    float dx, dy;       // filtered velocity, px/s
    double t;           // time of the last sample
    float px, py, pp;   // end of the resampled path so far (filtered position) and its pressure
    double pt;
    float since;        // path length since the last stamp, px
} rs_input_stroke;

// Stamps produced by one call are appended to out (capacity RS_INPUT_MAX_STAMPS + 1), *n counts them.
void rs_input_stroke_begin(rs_input_stroke *s, const rs_input_filter_desc *desc, const rs_input_event *ev,
                           rs_input_stamp *out, uint32_t *n);
void rs_input_stroke_move(rs_input_stroke *s, const rs_input_event *ev, rs_input_stamp *out, uint32_t *n);
// Catches up to the raw pointer-up position (so a stroke ends where the finger lifted) and ends there.
void rs_input_stroke_end(rs_input_stroke *s, const rs_input_event *ev, rs_input_stamp *out, uint32_t *n);

typedef enum rs_input_mode {
    RS_INPUT_VIEW = 0,  // one pointer orbits
    RS_INPUT_PAINT,     // one pointer paints
} rs_input_mode;

typedef struct rs_input_desc {
    rs_input_mode mode;
    rs_input_filter_desc filter;
} rs_input_desc;

typedef enum rs_input_state {
    RS_INPUT_IDLE = 0,
    RS_INPUT_ONE,       // one pointer: orbiting or painting
    RS_INPUT_TWO,       // pinch / pan
    RS_INPUT_WAIT_UP,   // a gesture ended with fingers still down: ignore them until all are up
} rs_input_state;

typedef struct rs_input_pointer {
    int32_t id;
    float x_px, y_px;
} rs_input_pointer;

// The recogniser. Fields are private (read state/painting for UI feedback).
typedef struct rs_input {
    rs_input_desc desc;
    rs_input_state state;
    bool painting;
    rs_input_pointer ptr[RS_INPUT_MAX_POINTERS];
    uint32_t count;
    int32_t gesture_id[2];       // ONE: [0]; TWO: both
    float centre[2], distance;   // TWO: last centroid and finger distance
    rs_input_stroke stroke;
} rs_input;

// What one event did. Deltas are for this event only; zoom is a factor (1 = unchanged).
typedef struct rs_input_output {
    float orbit_dx_px, orbit_dy_px;  // one-pointer drag in view mode
    float pan_dx_px, pan_dy_px;      // two-pointer centroid motion
    float zoom;                      // finger distance now / before (> 1: fingers spread, zoom in)
    float zoom_cx_px, zoom_cy_px;    // pinch centre
    bool stroke_begin, stroke_end, stroke_cancel;
    uint32_t stamp_count;
    rs_input_stamp stamps[RS_INPUT_MAX_STAMPS + 1];
} rs_input_output;

void rs_input_init(rs_input *in, const rs_input_desc *desc);
// Takes effect at the next gesture; a stroke in progress finishes normally.
void rs_input_set_mode(rs_input *in, rs_input_mode mode);
// Spacing for the following stamps (the app recomputes it from the brush's size on screen).
void rs_input_set_spacing(rs_input *in, float spacing_px);
void rs_input_feed(rs_input *in, const rs_input_event *ev, rs_input_output *out);

#endif
