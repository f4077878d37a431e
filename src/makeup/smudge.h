// smudge.h — the smudge and blend tools: move and soften makeup already on the face by ordinary stamps.
//
// Does: sample the makeup under a brush footprint (the per-splat records and the per-pixel fine layer,
// stacked as the renderer stacks them), keep a brush "load" that picks up what it passes over, and turn
// each step of a stroke into one ordinary stamp (rs_makeup_stamp) of a product made from that load:
//   - smudge: the load starts as what lies under the first stamp, is laid down where the brush moves
//     (only where it is stronger than what lies there: dragging never builds a product up over itself)
//     and mixes with what it passes over, so the carried product fades along the drag (halving length
//     grows with the strength);
//   - blend: no drag: each stamp lays the footprint's own average into its weaker part, so a hard edge
//     becomes a ramp and an even area stays as it is.
// The deposits are plain stamps of a product ("smudge", or the very product sampled when the sample
// matches one the look already has), kept to no region: looks save and replay them as they are, and a
// stroke file replays the tool (its samples) to the same picture. A mirrored stroke samples each side
// on its own side.
// Does not: thin the source (a stamp only adds; blend feathers an edge outwards), read pointer input
// (src/paint/paint.c calls it per stamp), or touch GL.
//
//   rs_smudge sm;
//   rs_smudge_begin(&sm, RS_TOOL_SMUDGE);
//   rs_makeup_begin_stroke(mk);
//   for (each stamp position p) rs_smudge_stamp(&sm, mk, &(rs_smudge_stamp_desc){...}, &info, &err);
//   rs_makeup_end_stroke(mk, &err);
#ifndef RS_SMUDGE_H
#define RS_SMUDGE_H

#include "core/core.h"
#include "makeup/makeup.h"

// What a brush does with the makeup (stroke files: brush tool=paint|smudge|blend).
typedef enum rs_paint_tool {
    RS_TOOL_PAINT = 0,  // lays the brush's product down (or erases, with the eraser)
    RS_TOOL_SMUDGE,     // drags the product under the brush along the stroke
    RS_TOOL_BLEND,      // softens edges in place
    RS_TOOL_COUNT,
} rs_paint_tool;

const char *rs_paint_tool_name(rs_paint_tool t);          // "paint", "smudge", "blend"; "unknown"
bool rs_paint_tool_parse(const char *name, rs_paint_tool *out);

#define RS_SMUDGE_STRENGTH_DEFAULT 0.8f  // a smudge or blend brush's opacity when none is given
#define RS_SMUDGE_SAMPLES_MAX 96         // footprint points the sample evaluates (spread over its splats)
#define RS_SMUDGE_PRODUCTS_MAX 1024      // products in a layer's log beyond which a smudge reuses the nearest

// The makeup stacked at a footprint: intensity-weighted means (colour in linear light) of the records
// and the fine layer over them, and the footprint's mean and inner minimum of max(colour, finish)
// intensity.
typedef struct rs_smudge_sample {
    float lin[3], ci, cov;                  // colour, colour intensity, coverage
    float m, rho_s, coat, shimmer, si;      // finish and its intensity
    float level, level_min;                 // max(ci, si): footprint mean; minimum over its inner half
    uint32_t points;                        // footprint points evaluated (0: nothing under the brush)
} rs_smudge_sample;

typedef struct rs_smudge_side {
    bool loaded;
    float last[3];
    rs_smudge_sample load;
} rs_smudge_side;

typedef struct rs_smudge {
    rs_paint_tool tool;
    rs_smudge_side side[2];  // the stroke and its mirror image
} rs_smudge;

typedef struct rs_smudge_stamp_desc {
    float pos[3], view_dir[3];          // as rs_makeup_stamp_desc
    float radius;
    float strength;                     // 0..1: smudge: how far the load carries; blend: how much it evens
    float pressure;                     // 0..1, through pressure_map: scales what is laid down
    rs_makeup_pressure pressure_map;
    bool mirror;                        // also on the mirror image (sampled there)
} rs_smudge_stamp_desc;

// Starts a stroke of `tool` (smudge or blend): the load is empty.
void rs_smudge_begin(rs_smudge *s, rs_paint_tool tool);
// One step at d->pos: samples, lays down (0, 1 or 2 stamps through rs_makeup_stamp: info sums them) and
// updates the load. ROUGE_ERR_ARG-style failures come from rs_makeup_stamp (not finite, bad radius).
rs_result rs_smudge_stamp(rs_smudge *s, rs_makeup *mk, const rs_smudge_stamp_desc *d, rs_makeup_stamp_info *info,
                          rs_error *err);
// The makeup under a footprint of `radius` at pos, each splat weighted as a brush from view_dir would reach it
// (rs_makeup_facing; view_dir all zero: no facing test).
rs_result rs_smudge_sample_at(const rs_makeup *mk, const float pos[3], const float view_dir[3], float radius,
                              rs_smudge_sample *out, rs_error *err);

#endif
