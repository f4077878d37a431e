// strokes.h — stroke files: what a person did (view, brush, cosmetic, pointer samples), for headless
// replay (`rouge render FACE.rsf --strokes FILE`) and for the viewer's recorder. Format: docs/makeup.md.
//
// Does: parse a text stroke file (versioned, "rouge-strokes 1") with hard caps and line-numbered
// errors; build a document stroke by stroke while recording; write it (atomically to a path).
// Does not: replay (src/paint/paint.c feeds the samples through the input filter and the picker), set the
// camera (the app maps view yaw/pitch/zoom/fov onto its camera), or touch the makeup layer.
//
//   rs_strokes *doc = NULL;
//   if (rs_strokes_load("tests/fixtures/strokes/lips.strokes", &doc, &err) != RS_OK) return err.code;
//   for (uint32_t i = 0; i < doc->count; i++)
//       printf("%s: %u samples\n", doc->strokes[i].cosmetic.name, doc->strokes[i].sample_count);
//   rs_strokes_destroy(doc);
#ifndef RS_STROKES_H
#define RS_STROKES_H

#include "core/core.h"
#include "makeup/cosmetics.h"
#include "makeup/makeup.h"
#include "makeup/smudge.h"

#define RS_STROKES_VERSION 1
#define RS_STROKES_MAX_BYTES (32u << 20)   // whole file
#define RS_STROKES_MAX_LINE 1024           // bytes per line, without the newline
#define RS_STROKES_MAX_STROKES 4096
#define RS_STROKES_MAX_SAMPLES (1u << 20)  // over all strokes
#define RS_STROKES_MAX_COORD 1.0e5f        // |x|, |y| in pixels
#define RS_STROKES_MAX_SIZE_PX RS_VIEW_MAX_SIZE_PX

// The camera the samples' pixel coordinates refer to. yaw/pitch in degrees about the face frame
// (0, 0 = looking at the face from hdr.forward), zoom as the app's camera defines it (1 = the face
// fills the view's height), vertical field of view in degrees, image size in pixels.
typedef struct rs_strokes_view {
    float yaw_deg, pitch_deg, zoom, fov_deg;
    uint32_t width_px, height_px;
    float pan[2];  // screen shift, fractions of the view height; file: pan=X,Y (optional, default 0,0)
} rs_strokes_view;

typedef struct rs_strokes_brush {
    float size_rel;                 // diameter / face height (the paper's 0.1, 0.2, 0.3)
    float opacity;                  // 0..1
    rs_makeup_pressure pressure;    // file: pressure=floor|linear|none
    bool mirror, eraser;
    bool any_region;                // file: mask=0 (paint anywhere); mask=1 or absent: keep to the product's region
    rs_paint_tool tool;             // file: tool=smudge|blend (absent: paint; written only when not paint)
} rs_strokes_brush;

typedef struct rs_strokes_sample {
    float t_s;       // seconds since the stroke's first sample (non-decreasing)
    float x_px, y_px;  // pixel position in the view's image, origin top-left
    float pressure;  // 0..1
} rs_strokes_sample;

typedef struct rs_strokes_stroke {
    rs_strokes_view view;
    rs_strokes_brush brush;
    rs_cosmetic cosmetic;
    uint32_t first_sample, sample_count;  // into rs_strokes.samples
} rs_strokes_stroke;

// A document. Fields are read-only for callers; build with rs_strokes_begin/add_sample.
typedef struct rs_strokes {
    uint32_t count;               // strokes
    rs_strokes_stroke *strokes;
    uint32_t sample_count;
    rs_strokes_sample *samples;
    uint32_t stroke_cap, sample_cap;
    bool open;                    // a stroke is being recorded
} rs_strokes;

rs_result rs_strokes_create(rs_strokes **out, rs_error *err);  // empty document (for recording)
void rs_strokes_destroy(rs_strokes *doc);

// Parses a whole file held in memory (need not be NUL-terminated). Errors: "line N: field: why".
rs_result rs_strokes_parse(const void *data, size_t len, rs_strokes **out, rs_error *err);
rs_result rs_strokes_load(const char *path, rs_strokes **out, rs_error *err);

// Recording: begin a stroke with the current view/brush/cosmetic, add samples, end (or drop it when
// the stroke was cancelled). Values are validated as the parser would.
rs_result rs_strokes_begin(rs_strokes *doc, const rs_strokes_view *view, const rs_strokes_brush *brush,
                           const rs_cosmetic *cosmetic, rs_error *err);
rs_result rs_strokes_add_sample(rs_strokes *doc, const rs_strokes_sample *sample, rs_error *err);
void rs_strokes_end(rs_strokes *doc);        // a stroke with no samples is dropped
void rs_strokes_drop_open(rs_strokes *doc);  // discards the open stroke

// Text of the document (malloc'd, caller frees). Writes only the view/brush/cosmetic lines that change.
rs_result rs_strokes_write_memory(const rs_strokes *doc, char **out, size_t *out_len, rs_error *err);
rs_result rs_strokes_save(const rs_strokes *doc, const char *path, rs_error *err);  // atomic

const char *rs_strokes_pressure_name(rs_makeup_pressure p);

#endif
