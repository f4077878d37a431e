// makeup.h — the makeup layer: per-splat cosmetic colour, intensity and finish over the untouched base
// skin, painted by brush stamps (paper §3.1, §3.3, eqs. 2-3).
//
// Does: hold one 12-byte GPU record per splat (same order as the cloud) plus touch counts; gather the
// splats within a brush radius through a uniform grid built once per cloud; apply a stamp (eq. 3
// intensity, eq. 2 blend composed exactly into one record), an eraser, mirror stamps across the face's
// mid-plane, a per-stroke opacity cap; undo/redo per stroke; clear; report the dirty index range so the
// renderer uploads only what changed; the CPU mirror of shaders_es/makeup.glsl; a log of the stamps
// applied (model space) that src/formats/look.c saves and replays.
// Does not: touch GL (the renderer uploads rs_makeup_records and calls rs_makeup_apply in its shader),
// pick splats on screen (src/paint/paint.c with the renderer's ID buffer), or read pointer input.
//
//   rs_makeup *mk = NULL;
//   if (rs_makeup_create(cloud, NULL, &mk, &err) != RS_OK) return err.code;
//   rs_makeup_stamp_desc s = {.pos = {x, y, z}, .view_dir = {0, 0, 1}, .opacity = 0.6f, .pressure = 1.0f,
//       .radius = rs_makeup_brush_radius(&cloud->hdr, 0.2f), .cosmetic = rs_cosmetic_find("blush")};
//   rs_makeup_stamp_info info;
//   rs_makeup_begin_stroke(mk); rs_makeup_stamp(mk, &s, &info, &err); rs_makeup_end_stroke(mk, &err);
//   // upload rs_makeup_records(mk)[info.dirty.lo .. info.dirty.hi)
//   rs_makeup_destroy(mk);
#ifndef RS_MAKEUP_H
#define RS_MAKEUP_H

#include "core/core.h"
#include "makeup/cosmetics.h"
#include "splat/splat.h"

// The GPU record, one per splat, uploaded as a uvec3 per-instance attribute. Byte order in memory is
// the field order, so on the (little-endian) GPU: x = r | g << 8 | b << 16 | colour_i << 24,
// y = m | rho_s << 8 | spec_i << 16 | flags << 24, z = coat | shimmer << 8 | coverage << 16. All zero = no
// makeup: the base is drawn exactly.
typedef struct rs_makeup_gpu {
    uint8_t rgb[3];     // composed cosmetic colour Cp, sRGB8
    uint8_t colour_i;   // colour intensity I of eq. (2), q/255
    uint8_t m;          // composed finish roughness, q/255
    uint8_t rho_s;      // composed finish specular scale, q/255
    uint8_t spec_i;     // finish intensity (how much m/rho_s replace the base's), q/255
    uint8_t flags;      // skin detail ratio L_base / L_local, q/128 (set while colour_i > 0; see makeup.c)
    uint8_t coat;       // composed clear-coat weight, q/255 (applies with spec_i, like m and rho_s)
    uint8_t shimmer;    // composed flake weight, q/255 (likewise)
    uint8_t coverage;   // composed coverage, q/255 (applies with colour_i: how opaque the pigment is)
    uint8_t reserved;   // 0 (keeps the record a whole number of uint32 words)
} rs_makeup_gpu;

// Half-open range of splat indices [lo, hi); empty when lo >= hi.
typedef struct rs_makeup_range {
    uint32_t lo, hi;
} rs_makeup_range;

#define RS_MAKEUP_MAX_RANGES RS_SPLAT_MAX_LODS  // rs_makeup_take_dirty: one range per LOD band

// Uniforms of shaders_es/makeup.glsl (names there: rs_makeup_range_lo, rs_makeup_range_hi).
typedef struct rs_makeup_uniforms {
    float range_lo[3], range_hi[3];  // the face's colour range, linear RGB (0.01th/99.99th percentile)
} rs_makeup_uniforms;

// How pen pressure scales opacity (configurable, recorded in stroke files by name).
typedef enum rs_makeup_pressure {
    RS_MAKEUP_PRESSURE_FLOOR = 0,  // opacity * (0.3 + 0.7 p): a light touch still paints (default)
    RS_MAKEUP_PRESSURE_LINEAR,     // opacity * p
    RS_MAKEUP_PRESSURE_NONE,       // opacity, pressure ignored
    RS_MAKEUP_PRESSURE_COUNT,
} rs_makeup_pressure;

#define RS_MAKEUP_FACING_FULL 0.3f  // a brush deposits fully from this dot(normal, view_dir) on (rs_makeup_facing)
#define RS_MAKEUP_TOUCH_K 1.0f      // I_F = 1 - exp(-touches / K), touches = strokes that reached the splat
#define RS_MAKEUP_SIGMA_REL 0.5f    // I_G Gaussian sigma = 0.5 * brush radius (shifted to reach 0 at the rim)
#define RS_MAKEUP_MASK_EDGE_MM 1.5f // region masks fade in over this distance inside the region's border
#define RS_MAKEUP_LIP_SMOOTH_MM 3.0f // the lips mask: lip colour averaged over this radius (makeup.c)
#define RS_MAKEUP_FINE_RADIUS_MM 4.0f // brushes narrower than this are the fine layer: evaluated per pixel
#define RS_MAKEUP_FIELD_VOXEL_MM 0.4f // region fields (rs_makeup_field): voxel edge, at least
#define RS_MAKEUP_LIP_A_SPAN 4.0f     // the lips' field: CIELAB a* within this of the lip/skin cut (makeup.c)
#define RS_MAKEUP_LIP_FIELD_MM 3.0f   // the lips' field: lip colour averaged over this radius (makeup.c)
#define RS_MAKEUP_LIP_CUT_SHIFT -0.25f // the lips' field: its cut, CIELAB a* from Otsu's (makeup.c)
#define RS_MAKEUP_LIP_REACH_MM 1.5f   // the lips' field: splats this near the region give their colour (makeup.c)
#define RS_MAKEUP_LIP_LINE_BAND 0.1f  // the lipstick's edge: the field's rise over it (a* +-0.4 about the cut)

typedef struct rs_makeup_desc {
    uint32_t undo_levels;  // strokes kept for undo/redo; 0 = 64
    size_t undo_bytes;     // memory budget of the undo history; 0 = 64 MiB (the newest stroke is always kept)
} rs_makeup_desc;

typedef struct rs_makeup_stamp_desc {
    float pos[3];                     // stamp centre, model units (the picked splat's position)
    float view_dir[3];                // unit vector from the surface towards the eye; all zero = no facing test
    float radius;                     // brush radius, model units (rs_makeup_brush_radius)
    float opacity;                    // 0..1
    float pressure;                   // 0..1 (a mouse passes 1)
    rs_makeup_pressure pressure_map;
    const rs_cosmetic *cosmetic;      // required unless eraser
    bool eraser;                      // lower I towards 0 (colour and finish); 0 leaves the base exactly
    bool mirror;                      // also stamp the mirror image across the face mid-plane
    bool region_mask;                 // keep to the cosmetic's region (rs_cosmetic_region_of), soft-edged;
                                      // ignored for the eraser and where the face has no such region
} rs_makeup_stamp_desc;

typedef struct rs_makeup_stamp_info {
    rs_makeup_range dirty;  // records changed by this call (both sides when mirrored)
    uint32_t cells;         // grid cells visited
    uint32_t examined;      // splats in those cells (the cost)
    uint32_t touched;       // splats within the radius (and facing) that received the stamp
    bool mirrored;          // a mirror stamp found a surface within tolerance and was applied
} rs_makeup_stamp_info;

// One stamp as it was applied (after pressure mapping and mirroring): what a look file stores.
typedef struct rs_makeup_applied {
    float pos[3], view_dir[3];
    float radius;
    float amount;           // opacity after the pressure map
    uint16_t cosmetic;      // index into rs_makeup_log_cosmetic; unused for the eraser
    uint8_t eraser;
    uint8_t stroke_start;   // 1 on the first stamp of each stroke
    uint8_t region_mask;    // 1: kept to its cosmetic's region (rs_makeup_stamp_desc.region_mask)
} rs_makeup_applied;

// One stamp of the fine layer (a brush narrower than RS_MAKEUP_FINE_RADIUS_MM, a brush kept to a region
// that has a field, or an eraser after one): the renderer evaluates these per pixel at the picture's
// resolution instead of per splat (makeup.c, top). New fields go at the end (render_fine.c packs them).
typedef struct rs_makeup_fine_stamp {
    float pos[3], radius;       // model units
    float view_dir[3], amount;  // as rs_makeup_applied
    uint32_t cosmetic;          // index into rs_makeup_log_cosmetic; unused for the eraser
    uint32_t stroke;            // ordinal of its stroke: a stroke's stamps take the max, strokes stack
    uint32_t eraser;            // 1: lowers the fine layer's intensities
    uint32_t region;            // rs_cosmetic_region whose field (rs_makeup_region_field) masks it; 0 none
} rs_makeup_fine_stamp;

// A region mask as a smooth field over model space, for the renderer to evaluate per pixel (makeup.c,
// "Region masks per pixel"): voxel (i, j, k) holds the mask's smoothed value at origin + (i+.5, j+.5,
// k+.5) * voxel; the weight at a point is the field interpolated there, ramped linearly from 0 at
// threshold - band / 2 to 1 at threshold + band / 2.
typedef struct rs_makeup_field {
    float origin[3], voxel;  // model units
    int dim[3];
    uint8_t *value;          // q/255, x fastest; NULL: no field
    float threshold, band;
} rs_makeup_field;

typedef struct rs_makeup rs_makeup;

// Builds the grid, the per-splat detail ratios and the colour range for `cloud` (kept by pointer: it
// must outlive the layer). Cost O(count).
rs_result rs_makeup_create(const rs_splat_cloud *cloud, const rs_makeup_desc *desc, rs_makeup **out,
                           rs_error *err);
void rs_makeup_destroy(rs_makeup *mk);

const rs_splat_cloud *rs_makeup_cloud(const rs_makeup *mk);
uint32_t rs_makeup_count(const rs_makeup *mk);                  // == cloud->hdr.count
const rs_makeup_gpu *rs_makeup_records(const rs_makeup *mk);    // count records, upload as is
const uint8_t *rs_makeup_touches(const rs_makeup *mk);          // per splat: strokes that touched it
void rs_makeup_get_uniforms(const rs_makeup *mk, rs_makeup_uniforms *out);

// Strokes group stamps for undo and for the opacity cap (a splat gains at most the stroke's opacity).
// A stamp outside begin/end is a stroke of its own. end_stroke fails only on out-of-memory (the stroke
// then stays applied but cannot be undone).
void rs_makeup_begin_stroke(rs_makeup *mk);
rs_result rs_makeup_end_stroke(rs_makeup *mk, rs_error *err);
// Rolls back the open stroke (pointer cancelled, palm rejected); the dirty range covers it.
void rs_makeup_cancel_stroke(rs_makeup *mk, rs_makeup_range *dirty);
bool rs_makeup_in_stroke(const rs_makeup *mk);

rs_result rs_makeup_stamp(rs_makeup *mk, const rs_makeup_stamp_desc *desc, rs_makeup_stamp_info *info,
                          rs_error *err);

// Records changed since the last call (stamps, undo, redo, clear, cancel, reset, look loads), as up to
// RS_MAKEUP_MAX_RANGES ranges, one per LOD band, and forgets them. Upload these each frame: a stamp's
// records are compact within each LOD level but spread across levels, so the single [lo, hi) span the
// other calls return covers most of the cloud (bundled face, size 0.3: 574k records in one span,
// 55k in the bands). A smaller cap merges the last ranges.
uint32_t rs_makeup_take_dirty(rs_makeup *mk, rs_makeup_range *out, uint32_t cap);

// Undo/redo one stroke (closing an open one first). False when there is nothing to undo/redo.
bool rs_makeup_undo(rs_makeup *mk, rs_makeup_range *dirty);
bool rs_makeup_redo(rs_makeup *mk, rs_makeup_range *dirty);
bool rs_makeup_can_undo(const rs_makeup *mk);
bool rs_makeup_can_redo(const rs_makeup *mk);
// Removes all makeup (undoable like a stroke).
rs_result rs_makeup_clear(rs_makeup *mk, rs_makeup_range *dirty, rs_error *err);
// Removes all makeup, the stamp log and the undo history (loading a look starts from here).
void rs_makeup_reset(rs_makeup *mk, rs_makeup_range *dirty);
// Drops undo/redo history, keeping the layer and its log.
void rs_makeup_forget_history(rs_makeup *mk);

// The stamps that make the current layer, oldest first, since the last clear (undone strokes
// excluded). Replaying them into a reset layer, stroke by stroke, reproduces it.
uint32_t rs_makeup_log_count(const rs_makeup *mk);
const rs_makeup_applied *rs_makeup_log_stamps(const rs_makeup *mk);
uint32_t rs_makeup_log_cosmetic_count(const rs_makeup *mk);
const rs_cosmetic *rs_makeup_log_cosmetic(const rs_makeup *mk, uint32_t i);

// Per-splat weights (q/255) of a region mask, built on first use and kept: 0 outside the regions the
// mask allows, rising as a smoothstep to 255 over RS_MAKEUP_MASK_EDGE_MM from the region's border (the
// distance to the nearest splat outside, in 3D, less about half the local spacing: alike on every LOD), so
// products fade in at a region's border instead of stopping at a hard line. *out = NULL when no splat of this face is in the mask (a file without eyelids: the mask is
// then ignored) or for RS_COSMETIC_REGION_ANY. Fails only on out-of-memory.
rs_result rs_makeup_region_weights(rs_makeup *mk, rs_cosmetic_region region, const uint8_t **out, rs_error *err);

// Whether a stamp of this radius (model units) belongs to the fine layer whatever its region (erasers
// never alone: see rs_makeup_fine_stamps).
bool rs_makeup_is_fine(const rs_makeup *mk, float radius);
// The field of a region's mask, built with the mask (rs_makeup_region_weights) for the lips and the eyes;
// NULL for other regions, before the mask is built, or where the face has no such region. Brushes kept
// to a region with a field are drawn per pixel, masked by it.
const rs_makeup_field *rs_makeup_region_field(const rs_makeup *mk, rs_cosmetic_region region);
// The field's weight at a model-space point, as the renderer samples it (makeup_fine.glsl
// rs_fine_region_weight: trilinear, clamped to the field's box, ramped); 1 where there is no field.
float rs_makeup_field_weight(const rs_makeup_field *f, const float p[3]);
// Counts every change of the stamp log (stamp, undo, redo, clear, reset, cancel): the renderer re-reads
// the fine layer when it moves.
uint32_t rs_makeup_fine_version(const rs_makeup *mk);
// The fine layer as applied now, oldest first: the fine stamps of the log and the erasers that follow the
// first of them. *out is malloc'd (NULL when *count is 0); the caller frees it.
rs_result rs_makeup_fine_stamps(const rs_makeup *mk, rs_makeup_fine_stamp **out, uint32_t *count, rs_error *err);

// Splat nearest to pos within max_dist (model units), through the grid; false when none.
bool rs_makeup_nearest(const rs_makeup *mk, const float pos[3], float max_dist, uint32_t *idx);

// Calls fn(user, splat, squared distance) for every splat within radius of pos (grid order, each once)
// until fn returns false. The smudge tool (src/makeup/smudge.c) samples the layer through it.
typedef bool (*rs_makeup_near_fn)(void *user, uint32_t splat, float dist2);
void rs_makeup_for_each_near(const rs_makeup *mk, const float pos[3], float radius, rs_makeup_near_fn fn, void *user);

// --- the arithmetic, exposed for tests, the renderer's CPU reference and docs ----------------------

// Brush radius in model units for a size given as a diameter relative to the face height.
float rs_makeup_brush_radius(const rs_splat_header *hdr, float size_rel);
// Mirror image of a point / a direction across the face mid-plane (through centre, normal up x forward).
void rs_makeup_mirror_point(const rs_splat_header *hdr, const float p[3], float out[3]);
void rs_makeup_mirror_dir(const rs_splat_header *hdr, const float d[3], float out[3]);
float rs_makeup_pressure_scale(rs_makeup_pressure map, float pressure);
// I_G: Gaussian falloff (sigma = RS_MAKEUP_SIGMA_REL * radius), shifted and rescaled so it is 1 at the
// centre and exactly 0 at and beyond the radius.
float rs_makeup_falloff(float dist, float radius);
// The tip's hardness 0..1 by product kind (pencils and liquid liners: a flat top over that fraction of
// the radius, then a smooth fall to 0 at the rim; 0 = the Gaussian I_G of rs_makeup_falloff).
float rs_makeup_tip_hardness(const rs_cosmetic *c);
// I_G of a tip of that hardness (rs_makeup_falloff when hardness is 0).
float rs_makeup_tip_falloff(float dist, float radius, float hardness);
// How much of a stamp reaches a surface of unit normal n from view_dir v (|v| = vl, not normalised:
// replays compute the same bits; vl 0: no facing test, 1): 0 facing away; an eraser, or a product kept to a region by its field
// (`whole`), all of it; a brush fades out over the last RS_MAKEUP_FACING_FULL of N.V before edge-on, as
// bristles pushed along v glance off a surface turning away (smoothstep), so a stroke leaves no edge
// where the surface turns from the view (makeup_fine.glsl rs_fine_facing mirrors it).
float rs_makeup_facing(const float n[3], const float v[3], float vl, bool whole);
// I_F from the touch count.
float rs_makeup_touch_weight(uint32_t touches);
// Eq. (3) with the brush footprint over every term: I = I_G * (0.3 + 0.3 I_M + 0.3 I_F); equals the
// paper's 0.3 I_G + 0.3 I_M + 0.3 I_F at the brush centre (I_G = 1) and fades to 0 at the rim.
float rs_makeup_intensity(float i_g, float i_m, float i_f);
// Stacks a cosmetic applied with intensity `amount` (0..1) on top of rec (eq. 2 composed exactly:
// I' = 1 - (1 - I1)(1 - I2), Cp' = (Cp1 I1 (1 - I2) + Cp2 I2) / I', in linear light; same for the finish
// with spec_i). `detail` is the splat's detail byte (stored in flags).
void rs_makeup_compose(rs_makeup_gpu *rec, const rs_cosmetic *c, float amount, uint8_t detail);
// Eraser: I *= 1 - amount for colour and finish; a record whose intensities reach 0 becomes all zero.
void rs_makeup_erase(rs_makeup_gpu *rec, float amount);
// CPU mirror of rs_makeup_apply in shaders_es/makeup.glsl (same operations, same order).
void rs_makeup_apply_cpu(const rs_makeup_gpu *rec, const rs_makeup_uniforms *u, float albedo_lin[3], float *m,
                         float *rho_s);
// The finish layers a record puts on a splat (bare skin has none): clear-coat and flake weights, 0..1.
void rs_makeup_layers_cpu(const rs_makeup_gpu *rec, float *coat, float *shimmer);

#endif
