// look.h — look files: save a makeup layer and load it back, on any LOD of the same face.
//
// Does: write the stamps that make the current layer (model-space centre, view direction, radius,
// intensity after the pressure map, cosmetic, eraser, stroke boundaries; rs_makeup_log_*) as a text
// file ("rouge-look 1", docs/makeup.md), atomically; parse such a file with hard caps; replay it into
// a layer. Stamps live in model space, so replaying them on another splat set of the same face (a
// LOD prefix, a re-decimated cloud) paints the same surface; a per-splat dump would not.
// Does not: keep camera or pointer data (that is a stroke file, src/formats/strokes.h) or the undo history.
//
//   if (rs_look_save(mk, "my.look", &err) != RS_OK) puts(err.msg);
//   rs_makeup_range dirty;
//   if (rs_look_load(mk_other_lod, "my.look", &dirty, &err) != RS_OK) puts(err.msg);
//   // upload rs_makeup_records(mk_other_lod)[dirty.lo .. dirty.hi)
#ifndef RS_LOOK_H
#define RS_LOOK_H

#include "core/core.h"
#include "makeup/cosmetics.h"
#include "makeup/makeup.h"

#define RS_LOOK_VERSION 1
#define RS_LOOK_MAX_BYTES (256u << 20)
#define RS_LOOK_MAX_LINE 1024
#define RS_LOOK_MAX_STAMPS (1u << 20)  // == the layer's log cap
#define RS_LOOK_MAX_COSMETICS 4096
#define RS_LOOK_MAX_COORD 1.0e6f
// Work bound: the stamps' areas summed, in face-height^2 units (sum of (radius / face height)^2). A
// stamp's cost grows with the splats under it, so this bounds a look's replay by the face, not by what
// the file claims. A face painted over fully with the largest brush is ~3.3; 2000 stamps as wide as the
// face (a 121 s replay) are ~2000.
#define RS_LOOK_MAX_COVER 256.0

typedef struct rs_look {
    float face_height;              // of the face it was painted on (model units)
    uint32_t cosmetic_count;
    rs_cosmetic *cosmetics;
    uint32_t stamp_count;
    rs_makeup_applied *stamps;      // stroke_start marks stroke boundaries
} rs_look;

// Parses a look held in memory (need not be NUL-terminated). Errors: "line N: field: why".
rs_result rs_look_parse(const void *data, size_t len, rs_look **out, rs_error *err);
void rs_look_destroy(rs_look *look);

// Replaces the layer's makeup by the look (reset, replay stroke by stroke, fresh undo history). Fails
// with RS_ERR_ARG when the look was made on a face of another height (more than 10 % off).
rs_result rs_look_apply(const rs_look *look, rs_makeup *mk, rs_makeup_range *dirty, rs_error *err);
// Reads and parses a look file without applying it (a host checks its input before making a context).
// Errors: "PATH: line N: field: why".
rs_result rs_look_read(const char *path, rs_look **out, rs_error *err);
rs_result rs_look_load(rs_makeup *mk, const char *path, rs_makeup_range *dirty, rs_error *err);

rs_result rs_look_write_memory(const rs_makeup *mk, char **out, size_t *out_len, rs_error *err);
rs_result rs_look_save(const rs_makeup *mk, const char *path, rs_error *err);  // temp + rename

#endif
