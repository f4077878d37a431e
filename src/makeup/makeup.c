// makeup.c — the makeup layer (paper §3.1, §3.3): brush stamps compose a cosmetic onto per-splat GPU
// records; the base skin in the cloud is never modified.
//
// Readings of the paper this file commits to (docs/makeup.md explains them with pictures in words):
//
// * Eq. (2), C = Cb (1 - I) + Cp I, in linear light. One record per splat represents the whole stack of
//   products: applying (Cp1, I1) then (Cp2, I2) equals applying (Cp', I') with I' = 1 - (1-I1)(1-I2) and
//   Cp' = (Cp1 I1 (1-I2) + Cp2 I2) / I' (expand the two blends to check). The finish (m, rho_s) stacks
//   the same way with its own intensity spec_i, so a colourless gloss (colour weight 0) changes only
//   the finish.
//
// * Eq. (3), I = 0.3 I_G + 0.3 I_M + 0.3 I_F. Taken literally, the I_M and I_F terms are constant over
//   the brush, so every dab would end in a hard rim of height 0.3 (I_M + I_F) at the radius: paint, not
//   makeup. We let the brush footprint carry every term, I = I_G (0.3 + 0.3 I_M + 0.3 I_F), which is the
//   paper's value at the brush centre and fades smoothly to 0 at the rim. I_G is a Gaussian with sigma
//   = radius / 2, shifted and rescaled to reach exactly 0 at the radius; I_M is the cosmetic's material
//   weight; I_F = 1 - exp(-touches / K), K = 1 (RS_MAKEUP_TOUCH_K), with touches = the number of strokes that have reached the
//   splat (counting strokes, not stamps, keeps the result independent of stamp spacing). The stamp's
//   intensity is then scaled by opacity x pressure map.
//
// * Stroke opacity cap: within one stroke a splat takes the MAX of the intensities its stamps offer
//   (composed over the splat's record from before the stroke), not their sum. A stroke therefore adds
//   at most its opacity, and spacing / hand speed do not change the result: the max over stamps along
//   a path converges to the value at the nearest point of the path. Build-up comes from repeated
//   strokes, as with a real brush.
//
// * "The final colour is normalised back into the face's original colour range rather than simply
//   overwriting it." We read this as: the pigment must not replace the skin by a flat colour and must
//   not leave the range of colours the face already has. So (a) the product colour is clamped, per
//   channel, into the face's original colour range (the darkest and brightest base colours of the whole
//   cloud, per channel, ignoring the outermost 0.01 % as strays; brows, lips and highlights included,
//   so most products stay as they are, but a white cannot glow and a black liner stays as dark as the
//   darkest hair the scan has); and (b) it is modulated per splat by the skin's detail ratio
//   L_base / L_local (the splat's linear luminance over the mean luminance of its neighbourhood, about
//   two grid cells = 6 mm on a face): pores, fine lines and hairs the scan carries show through the
//   product at the scale of the skin texture, while the product's tone replaces the skin's at larger
//   scale. Clamping before the modulation keeps the texture even at the range's edge; the modulated
//   pigment varies about its clamped value exactly as much as the skin varied about its local mean.
//   Then eq. (2) mixes it in. The detail ratio rides in the record's flags byte (q/128), computed once
//   per cloud here, so the shader needs no neighbourhood.
//
// * Two resolutions. A splat record samples a stamp at the splat's centre, and the attribute pass
//   blends records with the splats' Gaussian filter (~1-2 mm on the bundled head): exact enough for a
//   brush many splats wide (its falloff is smooth on that scale), but a liner 2 mm wide becomes a lumpy,
//   blurred chain of splats. So stamps of a brush narrower than RS_MAKEUP_FINE_RADIUS_MM are the *fine
//   layer*: they are logged but change no record; the renderer evaluates them per pixel at the surface
//   point the pixel sees (shaders_es/makeup_fine.glsl: the same eqs. 2-3, stroke max, I_F and stacking
//   as here, over the splat layer). Erasers change both. A fine stamp keeps no skin-detail ratio (its
//   pigment is flat). A narrow brush ignores the region mask (a pencil is its own mask: a lip or eye
//   pencil traces the region's border, which would cut it in half).
//
// * Region masks per pixel. A brush kept to the lips or the eyes is a fine stamp too, whatever its width:
//   a per-splat mask makes the product's edge the splats' staircase (lipstick's ragged lip line). Its
//   mask is a *field* (rs_makeup_field) over model space, built once with the region's mask: per voxel
//   (~0.4 mm) the Gaussian average of a per-splat source, the same average the mask takes at the splats,
//   so between splats it is smooth, and the renderer samples it (trilinear) at the point each pixel
//   sees and ramps it over a narrow band: the edge is a smooth level line at the picture's resolution.
//   The lips' source is the lip colour (CIELAB a* about Otsu's lip/skin cut, over RS_MAKEUP_LIP_FIELD_MM),
//   so the line is where the vermilion visibly ends; the eyes' is the soft mask itself. Wide brushes kept
//   to the skin (foundation, blush, contour: most strokes of a look, each tens of mm) stay per splat: their
//   falloff is smooth on the splats' scale and their region's border is soft by design, while per pixel
//   each would be listed in hundreds of grid cells and looked at by every pixel it covers. Fine stamps
//   compose over the splat layer, so a splat-layer product stroked after a lipstick shows under it.
#include "makeup/makeup.h"
#include "core/image.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define GRID_CELLS_PER_FACE 64     // cell edge = face height / 64 (about 3 mm on a face)
#define GRID_DIM_MAX 1024u         // per axis: keys pack into 30 bits
#define LOG_STAMPS_MAX (1u << 20)  // 1M stamps (36 MB here, ~130 MB as a look file) per session
#define DEFAULT_UNDO_LEVELS 64u
#define DEFAULT_UNDO_BYTES ((size_t)64 << 20)

// sRGB8 <-> linear tables: a stamp composes thousands of splats, and powf per channel would be most
// of its cost. Built once per layer (and per call of the public rs_makeup_compose).
#define SEED_BINS 4096  // to_srgb8's first guess: one bin spans at most 0.8 codes (the curve's steepest part)
typedef struct colour_tables {
    float to_lin[256];            // linear value of sRGB8 q
    float mid[255];               // linear value at sRGB (q + 0.5) / 255: rounding thresholds back to sRGB8
    uint8_t seed[SEED_BINS + 1];  // code of the linear value k / SEED_BINS: where to_srgb8 starts
} colour_tables;

typedef struct grid_cell {
    uint32_t key, start, count;
} grid_cell;

typedef struct stroke_slot {
    uint32_t idx;
    rs_makeup_gpu before;
    uint8_t touch_before;
    float amount;  // the largest intensity this stroke offered the splat so far
} stroke_slot;

typedef struct delta {
    uint32_t idx;
    rs_makeup_gpu before, after;
    uint8_t touch_before, touch_after;
} delta;

typedef struct hist_entry {
    delta *d;
    uint32_t n;
} hist_entry;

typedef struct log_stroke {
    uint32_t first, count;  // stamps
    bool clear;
} log_stroke;

struct rs_makeup {
    const rs_splat_cloud *cloud;
    uint32_t n;
    rs_makeup_gpu *rec;
    uint8_t *touch;
    uint8_t *detail;
    rs_makeup_uniforms uni;
    colour_tables tables;
    float touch_w[256];  // I_F per touch count
    // Records changed since rs_makeup_take_dirty, per LOD band: the splat order is LOD level by level,
    // each level spatially sorted, so a stamp's records are compact within a band but spread over all
    // bands (one span would cover nearly the whole cloud on the bundled face, the bands ~1/10 of it).
    uint32_t band_count;
    uint32_t band_end[RS_SPLAT_MAX_LODS];  // ascending
    rs_makeup_range band_dirty[RS_SPLAT_MAX_LODS];

    float origin[3], cell, inv_cell;
    uint32_t dim[3];
    grid_cell *cells;
    uint32_t cell_count;
    uint32_t *hash;  // cell index + 1, 0 = empty
    uint32_t hash_mask, hash_shift;
    uint32_t *order;  // splat indices grouped by cell

    bool in_stroke;
    bool stroke_fine;      // the open stroke holds fine stamps (it changes the picture without records)
    uint32_t fine_version; // rs_makeup_fine_version
    bool stroke_reserved;  // a log stroke slot exists for the open stroke
    uint32_t stroke_first_stamp;
    int32_t *slot_of;
    stroke_slot *slots;
    uint32_t slot_count, slot_cap;

    hist_entry *hist;
    uint32_t hist_count, hist_cap, hist_first;
    size_t hist_bytes, undo_bytes;
    uint32_t undo_levels;

    log_stroke *strokes;
    uint32_t stroke_count, stroke_cap, applied;
    rs_makeup_applied *stamps;
    uint32_t stamp_count, stamp_cap;
    rs_cosmetic *cosmetics;
    uint32_t cosmetic_count, cosmetic_cap;

    // Region masks by rs_cosmetic_region, built on first use (rs_makeup_region_weights).
    uint8_t *mask[RS_COSMETIC_REGION_COUNT];
    bool mask_built[RS_COSMETIC_REGION_COUNT];
    rs_makeup_field field[RS_COSMETIC_REGION_COUNT];  // built with the mask, lips and eyes only
};

// --- arithmetic ------------------------------------------------------------------------------------

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }
static uint8_t q255(float x) { return (uint8_t)(clamp01(x) * 255.0f + 0.5f); }  // round half up; x >= 0

static void extend(rs_makeup_range *r, uint32_t i)
{
    if (r->lo >= r->hi) {
        r->lo = i, r->hi = i + 1;
    } else {
        r->lo = RS_MIN(r->lo, i);
        r->hi = RS_MAX(r->hi, i + 1);
    }
}

// Marks record i changed for rs_makeup_take_dirty.
static void mark(rs_makeup *mk, uint32_t i)
{
    uint32_t b = 0;
    while (b + 1 < mk->band_count && i >= mk->band_end[b]) b++;
    extend(&mk->band_dirty[b], i);
}

static void mark_all(rs_makeup *mk)
{
    for (uint32_t b = 0; b < mk->band_count; b++)
        mk->band_dirty[b] = (rs_makeup_range){b ? mk->band_end[b - 1] : 0, mk->band_end[b]};
}

// LOD bands [0, lods[L-1]), [lods[L-1], lods[L-2]) ... [lods[1], count); one band if the table is odd.
static void build_bands(rs_makeup *mk)
{
    const rs_splat_header *h = &mk->cloud->hdr;
    bool ok = h->lod_count >= 1 && h->lod_count <= RS_SPLAT_MAX_LODS && h->lods[0] == mk->n;
    for (uint32_t k = 1; ok && k < h->lod_count; k++) ok = h->lods[k] > 0 && h->lods[k] < h->lods[k - 1];
    mk->band_count = ok ? h->lod_count : 1;
    for (uint32_t b = 0; b < mk->band_count; b++) mk->band_end[b] = ok ? h->lods[h->lod_count - 1 - b] : mk->n;
}

float rs_makeup_brush_radius(const rs_splat_header *hdr, float size_rel)
{
    // Size is the DIAMETER as a fraction of the face height: the paper's Fig. 8 sizes 0.1 / 0.2 / 0.3
    // (top of the head to the chin, ~23 cm) then give dabs of about 2.3 / 4.6 / 7 cm: small, medium and
    // large dabs on a cheek, as in the figure.
    return 0.5f * size_rel * hdr->face_height;
}

static void frame_normal(const rs_splat_header *hdr, float n[3])
{
    const float *u = hdr->up, *f = hdr->forward;
    n[0] = u[1] * f[2] - u[2] * f[1];
    n[1] = u[2] * f[0] - u[0] * f[2];
    n[2] = u[0] * f[1] - u[1] * f[0];
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0f)
        for (int a = 0; a < 3; a++) n[a] /= len;
}

void rs_makeup_mirror_dir(const rs_splat_header *hdr, const float d[3], float out[3])
{
    float n[3];
    frame_normal(hdr, n);
    float k = 2.0f * (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]);
    for (int a = 0; a < 3; a++) out[a] = d[a] - k * n[a];
}

void rs_makeup_mirror_point(const rs_splat_header *hdr, const float p[3], float out[3])
{
    float n[3];
    frame_normal(hdr, n);
    const float *c = hdr->centre;
    float k = 2.0f * ((p[0] - c[0]) * n[0] + (p[1] - c[1]) * n[1] + (p[2] - c[2]) * n[2]);
    for (int a = 0; a < 3; a++) out[a] = p[a] - k * n[a];
}

float rs_makeup_pressure_scale(rs_makeup_pressure map, float pressure)
{
    float p = clamp01(pressure);
    switch (map) {
    case RS_MAKEUP_PRESSURE_LINEAR: return p;
    case RS_MAKEUP_PRESSURE_NONE: return 1.0f;
    default: return 0.3f + 0.7f * p;  // FLOOR: opacity 30-100 % (research/product_anchors.md §2.6)
    }
}

// I_G from the squared distance ratio t = d^2 / r^2, for a tip of hardness `hard` (0 = Gaussian).
static float falloff_t(float t, float hard)
{
    if (!(t < 1.0f)) return 0.0f;
    if (hard > 0.0f) {
        float x = RS_CLAMP((1.0f - sqrtf(t)) / (1.0f - hard), 0.0f, 1.0f);
        return x * x * (3.0f - 2.0f * x);
    }
    const float k = 1.0f / (2.0f * RS_MAKEUP_SIGMA_REL * RS_MAKEUP_SIGMA_REL);
    const float rim = expf(-k);
    return (expf(-k * t) - rim) / (1.0f - rim);
}

float rs_makeup_tip_falloff(float dist, float radius, float hardness)
{
    if (!(radius > 0.0f)) return 0.0f;
    float u = dist / radius;
    return falloff_t(u * u, RS_CLAMP(hardness, 0.0f, 0.95f));
}

float rs_makeup_falloff(float dist, float radius) { return rs_makeup_tip_falloff(dist, radius, 0.0f); }

float rs_makeup_tip_hardness(const rs_cosmetic *c)
{
    // A liquid liner or a mascara wand leaves a crisp edge (~0.2 mm on a 2 mm line); a brow pencil a
    // slightly softer one. Everything else is a blending brush.
    switch (c->kind) {
    case RS_COSMETIC_EYELINER: return 0.8f;
    case RS_COSMETIC_MASCARA: return 0.8f;
    case RS_COSMETIC_BROW: return 0.6f;
    default: return 0.0f;
    }
}

float rs_makeup_facing(const float n[3], const float v[3], float vl, bool whole)
{
    if (!(vl > 0.0f)) return 1.0f;  // no view: no facing test
    float d = n[0] * v[0] + n[1] * v[1] + n[2] * v[2];
    if (!(d > 0.0f)) return 0.0f;
    if (whole || d >= RS_MAKEUP_FACING_FULL * vl) return 1.0f;
    float t = d / (RS_MAKEUP_FACING_FULL * vl);
    return t * t * (3.0f - 2.0f * t);
}

float rs_makeup_touch_weight(uint32_t touches) { return 1.0f - expf(-(float)touches / RS_MAKEUP_TOUCH_K); }

float rs_makeup_intensity(float i_g, float i_m, float i_f)
{
    // eq. (3) with the footprint on every term (see the top of this file).
    return i_g * (0.3f + 0.3f * i_m + 0.3f * i_f);
}

static void build_tables(colour_tables *t)
{
    for (int q = 0; q < 256; q++) t->to_lin[q] = rs_srgb_to_linear(q / 255.0f);
    for (int q = 0; q < 255; q++) t->mid[q] = rs_srgb_to_linear((q + 0.5f) / 255.0f);
    uint32_t q = 0;
    for (int k = 0; k <= SEED_BINS; k++) {
        float x = (float)k / SEED_BINS;
        while (q < 255 && x >= t->mid[q]) q++;
        t->seed[k] = (uint8_t)q;
    }
}

// Nearest sRGB8 code of a linear value (round in the sRGB domain): the thresholds at or below x, counted
// from the seed of x's bin (a step or none; a binary search's eight unpredictable branches were a third
// of a stamp's time, and more of it in WebAssembly).
static uint8_t to_srgb8(const colour_tables *t, float x)
{
    if (!(x > 0.0f)) return 0;  // NaN too
    uint32_t lo = t->seed[x < 1.0f ? (int)(x * SEED_BINS) : SEED_BINS];
    while (lo < 255 && x >= t->mid[lo]) lo++;
    return (uint8_t)lo;
}

// A cosmetic prepared for composing: colour in linear light, weights clamped.
typedef struct prepared {
    float lin[3], colour_w, finish_w, m, rho_s, material_w, coat, shimmer, coverage, hard;
} prepared;

static prepared prepare(const colour_tables *t, const rs_cosmetic *c)
{
    prepared p = {{t->to_lin[c->rgb[0]], t->to_lin[c->rgb[1]], t->to_lin[c->rgb[2]]},
                  clamp01(c->colour_weight), clamp01(c->finish_weight), clamp01(c->m), clamp01(c->rho_s),
                  clamp01(c->material_weight), clamp01(c->coat), clamp01(c->shimmer), clamp01(c->coverage),
                  rs_makeup_tip_hardness(c)};
    return p;
}

static void compose(const colour_tables *t, rs_makeup_gpu *rec, const prepared *c, float amount, uint8_t detail)
{
    float a = clamp01(amount);
    float i2 = a * c->colour_w;
    if (i2 > 0.0f) {
        // eq. (2) stacked: I' = 1 - (1-I1)(1-I2), Cp' = (Cp1 I1 (1-I2) + Cp2 I2) / I', linear light.
        float i1 = rec->colour_i / 255.0f;
        float ii = 1.0f - (1.0f - i1) * (1.0f - i2);
        uint8_t q = q255(ii);
        if (q > 0) {
            for (int ch = 0; ch < 3; ch++) {
                float cp = (t->to_lin[rec->rgb[ch]] * i1 * (1.0f - i2) + c->lin[ch] * i2) / ii;
                rec->rgb[ch] = to_srgb8(t, cp);
            }
            rec->coverage = q255(((rec->coverage / 255.0f) * i1 * (1.0f - i2) + c->coverage * i2) / ii);
            rec->colour_i = q;
            rec->flags = detail;
        }
    }
    float s2 = a * c->finish_w;
    if (s2 > 0.0f) {
        float s1 = rec->spec_i / 255.0f;
        float ss = 1.0f - (1.0f - s1) * (1.0f - s2);
        uint8_t q = q255(ss);
        if (q > 0) {
            rec->m = q255(((rec->m / 255.0f) * s1 * (1.0f - s2) + c->m * s2) / ss);
            rec->rho_s = q255(((rec->rho_s / 255.0f) * s1 * (1.0f - s2) + c->rho_s * s2) / ss);
            rec->coat = q255(((rec->coat / 255.0f) * s1 * (1.0f - s2) + c->coat * s2) / ss);
            rec->shimmer = q255(((rec->shimmer / 255.0f) * s1 * (1.0f - s2) + c->shimmer * s2) / ss);
            rec->spec_i = q;
        }
    }
}

void rs_makeup_compose(rs_makeup_gpu *rec, const rs_cosmetic *c, float amount, uint8_t detail)
{
    colour_tables t;
    build_tables(&t);
    prepared p = prepare(&t, c);
    compose(&t, rec, &p, amount, detail);
}

void rs_makeup_erase(rs_makeup_gpu *rec, float amount)
{
    float keep = 1.0f - clamp01(amount);
    rec->colour_i = (uint8_t)lrintf(rec->colour_i * keep);
    rec->spec_i = (uint8_t)lrintf(rec->spec_i * keep);
    // Keep records canonical: a part with no intensity carries no values, so a full erase is all zero.
    if (rec->colour_i == 0) rec->rgb[0] = rec->rgb[1] = rec->rgb[2] = rec->flags = rec->coverage = 0;
    if (rec->spec_i == 0) rec->m = rec->rho_s = rec->coat = rec->shimmer = 0;
}

void rs_makeup_apply_cpu(const rs_makeup_gpu *rec, const rs_makeup_uniforms *u, float albedo_lin[3], float *m,
                         float *rho_s)
{
    // Same operations in the same order as rs_makeup_apply in shaders_es/makeup.glsl.
    float ci = rec->colour_i / 255.0f;
    if (ci > 0.0f) {
        // Coverage: an opaque pigment keeps its own colour (not held in the face's range) and hides the
        // skin's texture; a sheer one is held and lets the texture through (docs/makeup.md).
        float cov = rec->coverage / 255.0f;
        float detail = (rec->flags / 128.0f) * (1.0f - cov) + cov;
        for (int ch = 0; ch < 3; ch++) {
            float cp = rs_srgb_to_linear(rec->rgb[ch] / 255.0f);
            float held = RS_CLAMP(cp, u->range_lo[ch], u->range_hi[ch]);
            float pig = RS_MIN((held * (1.0f - cov) + cp * cov) * detail, 1.0f);
            albedo_lin[ch] = albedo_lin[ch] * (1.0f - ci) + pig * ci;  // eq. (2)
        }
    }
    float si = rec->spec_i / 255.0f;
    if (si > 0.0f) {
        *m = *m * (1.0f - si) + (rec->m / 255.0f) * si;
        *rho_s = *rho_s * (1.0f - si) + (rec->rho_s / 255.0f) * si;
    }
}

void rs_makeup_layers_cpu(const rs_makeup_gpu *rec, float *coat, float *shimmer)
{
    float si = rec->spec_i / 255.0f;
    *coat = (rec->coat / 255.0f) * si;
    *shimmer = (rec->shimmer / 255.0f) * si;
}

// --- grid ------------------------------------------------------------------------------------------

static uint32_t cell_key(uint32_t x, uint32_t y, uint32_t z) { return x | y << 10 | z << 20; }

static uint32_t hash_slot(const rs_makeup *mk, uint32_t key)
{
    return (uint32_t)(key * 0x9E3779B1u) >> mk->hash_shift;
}

static const grid_cell *find_cell(const rs_makeup *mk, uint32_t key)
{
    for (uint32_t h = hash_slot(mk, key);; h = (h + 1) & mk->hash_mask) {
        uint32_t c = mk->hash[h];
        if (c == 0) return NULL;
        if (mk->cells[c - 1].key == key) return &mk->cells[c - 1];
    }
}

static void cell_coords(const grid_cell *gc, int xyz[3])
{
    xyz[0] = (int)(gc->key & 1023u), xyz[1] = (int)(gc->key >> 10 & 1023u), xyz[2] = (int)(gc->key >> 20 & 1023u);
}

// The occupied cells within `reach` (<= 4) cells of gc along each axis, gc included, into near[9 * 9 * 9].
static int cells_near_cell(const rs_makeup *mk, const grid_cell *gc, int reach, const grid_cell **near)
{
    int c[3], n = 0;
    cell_coords(gc, c);
    for (int dz = -reach; dz <= reach; dz++)
        for (int dy = -reach; dy <= reach; dy++)
            for (int dx = -reach; dx <= reach; dx++) {
                int x = c[0] + dx, y = c[1] + dy, z = c[2] + dz;
                if (x < 0 || y < 0 || z < 0 || (uint32_t)x >= mk->dim[0] || (uint32_t)y >= mk->dim[1] ||
                    (uint32_t)z >= mk->dim[2])
                    continue;
                const grid_cell *nc = find_cell(mk, cell_key((uint32_t)x, (uint32_t)y, (uint32_t)z));
                if (nc) near[n++] = nc;
            }
    return n;
}

static uint32_t axis_cell(const rs_makeup *mk, int a, float v)
{
    float f = (v - mk->origin[a]) * mk->inv_cell;
    if (!(f > 0.0f)) return 0;
    uint32_t i = f < (float)GRID_DIM_MAX ? (uint32_t)f : GRID_DIM_MAX;
    return i < mk->dim[a] ? i : mk->dim[a] - 1;
}

static rs_result build_grid(rs_makeup *mk, rs_error *err)
{
    const rs_splat_header *h = &mk->cloud->hdr;
    float ext = 0.0f;
    for (int a = 0; a < 3; a++) ext = RS_MAX(ext, h->bbox_max[a] - h->bbox_min[a]);
    float cell = isfinite(h->face_height) && h->face_height > 0.0f ? h->face_height / GRID_CELLS_PER_FACE
                                                                    : ext / GRID_CELLS_PER_FACE;
    cell = RS_MAX(cell, ext / (float)(GRID_DIM_MAX - 1));
    if (!(cell > 0.0f) || !isfinite(cell)) cell = 1.0f;
    mk->cell = cell;
    mk->inv_cell = 1.0f / cell;
    uint64_t dim_product = 1;
    for (int a = 0; a < 3; a++) {
        mk->origin[a] = h->bbox_min[a];
        float cells = floorf((h->bbox_max[a] - h->bbox_min[a]) * mk->inv_cell) + 1.0f;
        mk->dim[a] = cells < (float)GRID_DIM_MAX ? (uint32_t)cells : GRID_DIM_MAX;
        dim_product *= mk->dim[a];
    }
    uint32_t max_cells = (uint32_t)RS_MIN((uint64_t)mk->n, dim_product);
    uint32_t cap = 16;
    while (cap < 2u * max_cells) cap <<= 1;
    mk->hash_mask = cap - 1;
    mk->hash_shift = 32;
    for (uint32_t c = cap; c > 1; c >>= 1) mk->hash_shift--;
    mk->hash = calloc(cap, sizeof *mk->hash);
    mk->cells = rs_alloc_array(RS_MAX(max_cells, 1u), sizeof *mk->cells);
    mk->order = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *mk->order);
    uint32_t *cell_of = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *cell_of);
    if (!mk->hash || !mk->cells || !mk->order || !cell_of) {
        free(cell_of);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: grid for %u splats: out of memory", mk->n);
    }
    for (uint32_t i = 0; i < mk->n; i++) {
        const float *p = mk->cloud->pos[i];
        uint32_t key = cell_key(axis_cell(mk, 0, p[0]), axis_cell(mk, 1, p[1]), axis_cell(mk, 2, p[2]));
        uint32_t s = hash_slot(mk, key);
        while (mk->hash[s] != 0 && mk->cells[mk->hash[s] - 1].key != key) s = (s + 1) & mk->hash_mask;
        if (mk->hash[s] == 0) {
            mk->cells[mk->cell_count] = (grid_cell){key, 0, 0};
            mk->hash[s] = ++mk->cell_count;
        }
        cell_of[i] = mk->hash[s] - 1;
        mk->cells[cell_of[i]].count++;
    }
    uint32_t start = 0;
    for (uint32_t c = 0; c < mk->cell_count; c++) {
        mk->cells[c].start = start;
        start += mk->cells[c].count;
        mk->cells[c].count = 0;
    }
    // Filling in splat order keeps each cell's splats in index (LOD/Morton) order.
    for (uint32_t i = 0; i < mk->n; i++) {
        grid_cell *c = &mk->cells[cell_of[i]];
        mk->order[c->start + c->count++] = i;
    }
    free(cell_of);
    return RS_OK;
}

static float luminance_of(const float lut[256], const rs_splat_packed *p)
{
    uint32_t w = p->w[3];
    return 0.2126f * lut[w & 255u] + 0.7152f * lut[(w >> 8) & 255u] + 0.0722f * lut[(w >> 16) & 255u];
}

// Detail ratio L_base / L_local per splat, L_local = the cells' mean luminance interpolated
// trilinearly between cell centres (continuous in position: no grid pattern under a flat product).
static rs_result build_detail(rs_makeup *mk, const float lut[256], rs_error *err)
{
    float *cell_lum = rs_alloc_array(RS_MAX(mk->cell_count, 1u), sizeof *cell_lum);
    if (!cell_lum) return rs_fail(err, RS_ERR_NOMEM, "makeup: detail: out of memory");
    for (uint32_t c = 0; c < mk->cell_count; c++) {
        const grid_cell *gc = &mk->cells[c];
        double sum = 0.0;
        for (uint32_t k = gc->start; k < gc->start + gc->count; k++)
            sum += luminance_of(lut, &mk->cloud->packed[mk->order[k]]);
        cell_lum[c] = (float)(sum / gc->count);
    }
    for (uint32_t i = 0; i < mk->n; i++) {
        const float *p = mk->cloud->pos[i];
        int base[3];
        float f[3];
        for (int a = 0; a < 3; a++) {
            float u = (p[a] - mk->origin[a]) * mk->inv_cell - 0.5f;
            float b = floorf(u);
            base[a] = (int)RS_CLAMP(b, -1.0f, (float)GRID_DIM_MAX);
            f[a] = RS_CLAMP(u - b, 0.0f, 1.0f);
        }
        float acc = 0.0f, wsum = 0.0f;
        for (int corner = 0; corner < 8; corner++) {
            int ix = base[0] + (corner & 1), iy = base[1] + (corner >> 1 & 1), iz = base[2] + (corner >> 2 & 1);
            if (ix < 0 || iy < 0 || iz < 0 || (uint32_t)ix >= mk->dim[0] || (uint32_t)iy >= mk->dim[1] ||
                (uint32_t)iz >= mk->dim[2])
                continue;
            const grid_cell *gc = find_cell(mk, cell_key((uint32_t)ix, (uint32_t)iy, (uint32_t)iz));
            if (!gc) continue;
            float w = (corner & 1 ? f[0] : 1.0f - f[0]) * (corner & 2 ? f[1] : 1.0f - f[1]) *
                      (corner & 4 ? f[2] : 1.0f - f[2]);
            acc += w * cell_lum[gc - mk->cells];
            wsum += w;
        }
        float local = wsum > 0.0f ? acc / wsum : 0.0f;
        float ratio = local > 1e-5f ? luminance_of(lut, &mk->cloud->packed[i]) / local : 1.0f;
        mk->detail[i] = (uint8_t)lrintf(RS_MIN(ratio * 128.0f, 255.0f));
    }
    free(cell_lum);
    return RS_OK;
}

// The face's original colour range: per channel, the 0.01th and 99.99th percentile of the base colours
// (its extremes without stray outliers). 1st/99th was tried: on the bundled pale scan it lifted a
// black eyeliner to a light pinkish brown.
static void build_range(rs_makeup *mk, const float lut[256])
{
    uint32_t hist[3][256] = {{0}};
    for (uint32_t i = 0; i < mk->n; i++) {
        uint32_t w = mk->cloud->packed[i].w[3];
        for (int ch = 0; ch < 3; ch++) hist[ch][(w >> (8 * ch)) & 255u]++;
    }
    uint64_t lo_rank = (uint64_t)mk->n / 10000, hi_rank = (uint64_t)mk->n - 1 - (uint64_t)mk->n / 10000;
    for (int ch = 0; ch < 3; ch++) {
        uint64_t seen = 0;
        int lo = -1, hi = 255;
        for (int v = 0; v < 256; v++) {
            seen += hist[ch][v];
            if (lo < 0 && seen > lo_rank) lo = v;
            if (seen > hi_rank) {
                hi = v;
                break;
            }
        }
        mk->uni.range_lo[ch] = mk->n ? lut[RS_MAX(lo, 0)] : 0.0f;
        mk->uni.range_hi[ch] = mk->n ? lut[hi] : 1.0f;
    }
}

// --- region masks -----------------------------------------------------------------------------------

static uint32_t splat_region(const rs_makeup *mk, uint32_t i) { return mk->cloud->packed[i].w[1] >> 24; }

static float dist2(const float a[3], const float b[3])
{
    float x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

// A mask's field (see the top, "Region masks per pixel"): `src` (0..1 per splat) averaged with a Gaussian
// (sigma r / 3, the lips mask's) over the splats within r of each voxel's centre, so the field between the
// splats is the same smooth average the mask takes at them. Only voxels within r of a splat matter (a
// pixel samples the field at the surface it sees); the others hold 0.
static rs_result build_field(rs_makeup *mk, rs_cosmetic_region region, const float *src, float r,
                             float threshold, float band, rs_error *err)
{
    enum { DIM_MAX = 128, LUT = 256 };  // 128^3 R8 at most; render_fine.c stacks two fields in one texture
    const rs_splat_header *h = &mk->cloud->hdr;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < mk->n; i++)
        if (src[i] > 0.0f)
            for (int a = 0; a < 3; a++) lo[a] = fminf(lo[a], mk->cloud->pos[i][a]), hi[a] = fmaxf(hi[a], mk->cloud->pos[i][a]);
    if (!(lo[0] <= hi[0])) return RS_OK;
    float vox = RS_MAKEUP_FIELD_VOXEL_MM / (h->mm_per_unit > 0.0f ? h->mm_per_unit : 1.0f);
    for (int a = 0; a < 3; a++) {
        lo[a] -= r, hi[a] += r;
        vox = fmaxf(vox, (hi[a] - lo[a]) / (float)DIM_MAX);
    }
    rs_makeup_field f = {{lo[0], lo[1], lo[2]}, vox, {0, 0, 0}, NULL, threshold, band};
    size_t nv = 1;
    for (int a = 0; a < 3; a++) f.dim[a] = RS_CLAMP((int)ceilf((hi[a] - lo[a]) / vox), 1, DIM_MAX), nv *= (size_t)f.dim[a];
    float *sw = calloc(nv, sizeof *sw), *sp = calloc(nv, sizeof *sp);
    f.value = malloc(nv);
    if (!sw || !sp || !f.value) {
        free(sw), free(sp), free(f.value);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: region field: out of memory");
    }
    float g[LUT + 1], r2 = r * r, inv_vox = 1.0f / vox;
    for (int k = 0; k <= LUT; k++) g[k] = expf(-4.5f * (float)k / LUT);
    for (uint32_t i = 0; i < mk->n; i++) {
        const float *p = mk->cloud->pos[i];
        int v0[3], v1[3];
        bool out = false;
        for (int a = 0; a < 3 && !out; a++) {
            // voxel centres within r of p along this axis
            v0[a] = RS_MAX(0, (int)ceilf((p[a] - r - lo[a]) * inv_vox - 0.5f));
            v1[a] = RS_MIN(f.dim[a] - 1, (int)floorf((p[a] + r - lo[a]) * inv_vox - 0.5f));
            out = v0[a] > v1[a];
        }
        if (out) continue;
        for (int z = v0[2]; z <= v1[2]; z++) {
            float dz = lo[2] + (z + 0.5f) * vox - p[2];
            for (int y = v0[1]; y <= v1[1]; y++) {
                float dy = lo[1] + (y + 0.5f) * vox - p[1], dyz = dy * dy + dz * dz;
                if (dyz >= r2) continue;
                size_t row = ((size_t)z * f.dim[1] + y) * f.dim[0];
                for (int x = v0[0]; x <= v1[0]; x++) {
                    float dx = lo[0] + (x + 0.5f) * vox - p[0], d2 = dx * dx + dyz;
                    if (d2 >= r2) continue;
                    float gw = g[(int)(d2 / r2 * LUT)];
                    sw[row + x] += gw, sp[row + x] += gw * src[i];
                }
            }
        }
    }
    for (size_t v = 0; v < nv; v++) f.value[v] = sw[v] > 0.0f ? q255(sp[v] / sw[v]) : 0;
    free(sw), free(sp);
    mk->field[region] = f;
    return RS_OK;
}

// The lips field's source at a splat of CIELAB a* `a` (cut_a: Otsu's lip/skin cut): 0..1 over
// RS_MAKEUP_LIP_A_SPAN about the cut (lowered by RS_MAKEUP_LIP_CUT_SHIFT).
static float lip_source(float a, float cut_a)
{
    return RS_CLAMP((a - cut_a - RS_MAKEUP_LIP_CUT_SHIFT) / (2.0f * RS_MAKEUP_LIP_A_SPAN) + 0.5f, 0.0f, 1.0f);
}

// The lips' mask. The converter's lips region is a blob around the mouth (an ellipse in the face frame,
// ragged at splat scale: spikes of 1-2 mm): it reaches over the upper lip's border onto the skin, and a
// mask that fades in from its border keeps the spikes. Two things make the mask follow the lip line:
// - colour: the vermilion is redder than the skin around it (CIELAB a*), so within the region the splats
//   split into two colour classes (Otsu's threshold on a*) and each gets a lip likelihood; a face whose
//   region shows no clear colour step (painted lips, a colourless scan: class means < 4 a* apart) takes
//   the whole region as lips;
// - smoothing: the likelihood (0 outside the region) averaged with a Gaussian over
//   RS_MAKEUP_LIP_SMOOTH_MM, ramped from 0 at half to 1 at 95 %: the lip line is a smooth curve, a spike
//   thinner than the radius never reaches half, and splats outside the region stay at 0.
// `w` holds 255 / 0 by region on entry.
static rs_result lips_mask(rs_makeup *mk, uint8_t *w, rs_error *err)
{
    enum { BINS = 256 };
    const float lo = -32.0f, hi = 96.0f, per_bin = (float)BINS / (hi - lo);
    float *a = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *a);
    float *p = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *p);
    if (!a || !p) {
        free(a), free(p);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: lips mask: out of memory");
    }
    double hist[BINS] = {0}, total = 0;
    for (uint32_t i = 0; i < mk->n; i++) {
        p[i] = w[i] ? 1.0f : 0.0f;
        if (!w[i]) continue;
        uint32_t c = mk->cloud->packed[i].w[3];
        uint8_t rgb[3] = {(uint8_t)c, (uint8_t)(c >> 8), (uint8_t)(c >> 16)};
        double lab[3];
        rs_srgb8_to_lab(rgb, lab);
        a[i] = (float)lab[1];
        hist[RS_CLAMP((int)((a[i] - lo) * per_bin), 0, BINS - 1)] += 1, total += 1;
    }
    // Otsu: the threshold that maximises the between-class variance.
    double sum_all = 0, w0 = 0, sum0 = 0, best = -1, m0 = 0, m1 = 0;
    for (int b = 0; b < BINS; b++) sum_all += b * hist[b];
    int cut = -1;
    for (int b = 0; b < BINS - 1; b++) {
        w0 += hist[b], sum0 += b * hist[b];
        double w1 = total - w0;
        if (w0 < 1 || w1 < 1) continue;
        double u0 = sum0 / w0, u1 = (sum_all - sum0) / w1, v = w0 * w1 * (u1 - u0) * (u1 - u0);
        if (v > best) best = v, cut = b, m0 = u0, m1 = u1;
    }
    // The field's source (see build_field's caller below): the lip colour itself, a* about Otsu's cut
    // mapped to 0..1 (0 outside the region), or the region where the colour shows no step.
    float *fs = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *fs);
    if (!fs) {
        free(a), free(p);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: lips mask: out of memory");
    }
    memcpy(fs, p, (size_t)mk->n * sizeof *fs);
    float *p0 = malloc(RS_MAX(mk->n, 1u) * sizeof *p0);  // the region itself, 0 / 1
    if (!p0) {
        free(a), free(p), free(fs);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: lips mask: out of memory");
    }
    memcpy(p0, p, (size_t)mk->n * sizeof *p0);
    if (total >= 64 && cut >= 0 && (m1 - m0) / per_bin >= 4.0) {
        float t = lo + (float)((m0 + 0.3 * (m1 - m0)) / per_bin), band = (float)((m1 - m0) / per_bin) * 0.2f;
        float cut_a = lo + (float)(cut + 1) / per_bin;
        for (uint32_t i = 0; i < mk->n; i++) {
            if (!w[i]) continue;
            float x = RS_CLAMP((a[i] - (t - band)) / (2.0f * band), 0.0f, 1.0f);
            p[i] = x * x * (3.0f - 2.0f * x);
            fs[i] = lip_source(a[i], cut_a);
        }
        // The region's border is ragged at the splats' scale and may cut across the vermilion (the lower
        // lip's): splats outside it but within RS_MAKEUP_LIP_REACH_MM of it give the field their colour
        // too, so the colour, not the region, draws the line there. (Near: a field of the region itself
        // over that radius is above 0 at the splat.)
        const rs_splat_header *hn = &mk->cloud->hdr;
        float rn = RS_MAKEUP_LIP_REACH_MM / (hn->mm_per_unit > 0.0f ? hn->mm_per_unit : 1.0f);
        if (rn > 0.0f) {
            rs_result rr = build_field(mk, RS_COSMETIC_REGION_LIPS, p0, rn, 0.0f, 1.0f, err);
            if (rr != RS_OK) {
                free(a), free(p), free(fs), free(p0);
                return rr;
            }
            rs_makeup_field nf = mk->field[RS_COSMETIC_REGION_LIPS];
            mk->field[RS_COSMETIC_REGION_LIPS] = (rs_makeup_field){0};
            for (uint32_t i = 0; nf.value && i < mk->n; i++) {
                if (w[i] || rs_makeup_field_weight(&nf, mk->cloud->pos[i]) <= 0.5f) continue;
                uint32_t c = mk->cloud->packed[i].w[3];
                uint8_t rgb[3] = {(uint8_t)c, (uint8_t)(c >> 8), (uint8_t)(c >> 16)};
                double lab[3];
                rs_srgb8_to_lab(rgb, lab);
                fs[i] = lip_source((float)lab[1], cut_a);
            }
            free(nf.value);
        }
    }
    free(p0);
    const rs_splat_header *h = &mk->cloud->hdr;
    float r = RS_MAKEUP_LIP_SMOOTH_MM / (h->mm_per_unit > 0.0f ? h->mm_per_unit : 1.0f), r2 = r * r;
    int reach = RS_CLAMP((int)ceilf(r * mk->inv_cell), 1, 4);
    for (uint32_t c = 0; c < mk->cell_count; c++) {
        const grid_cell *gc = &mk->cells[c];
        bool any = false;
        for (uint32_t k = gc->start; k < gc->start + gc->count && !any; k++) any = w[mk->order[k]] != 0;
        if (!any) continue;
        const grid_cell *near[9 * 9 * 9];
        int nn = cells_near_cell(mk, gc, reach, near);
        for (uint32_t k = gc->start; k < gc->start + gc->count; k++) {
            uint32_t i = mk->order[k];
            if (!w[i]) continue;
            const float *pi = mk->cloud->pos[i];
            const float *ni = mk->cloud->normal[i];
            double sw = 0, sp = 0;
            for (int q = 0; q < nn; q++)
                for (uint32_t m = near[q]->start; m < near[q]->start + near[q]->count; m++) {
                    uint32_t j = mk->order[m];
                    float d2 = dist2(mk->cloud->pos[j], pi);
                    if (d2 >= r2) continue;
                    // The same sheet of surface only: not the other lip across the closed mouth.
                    const float *nj = mk->cloud->normal[j];
                    if (ni[0] * nj[0] + ni[1] * nj[1] + ni[2] * nj[2] < 0.0f) continue;
                    double g = exp(-4.5 * d2 / r2);  // sigma r / 3
                    sw += g, sp += g * p[j];
                }
            float lip = sw > 0 ? (float)(sp / sw) : p[i];
            float x = RS_CLAMP((lip - 0.5f) / 0.45f, 0.0f, 1.0f);
            a[i] = x * x * (3.0f - 2.0f * x);  // a[] (the colours) is free now; applied after the pass
        }
    }
    for (uint32_t i = 0; i < mk->n; i++)
        if (w[i]) w[i] = (uint8_t)lrintf(255.0f * a[i]);
    free(a);
    // The field: the lip colour (or the region) averaged over RS_MAKEUP_LIP_FIELD_MM (sigma 1 mm); its level
    // at the cut is the lip line. Measured at the lips' 3x close-up against the border the scan's albedo
    // shows (test_fine_makeup), covered / spill / wander: a* mapped over +-12 about Otsu's cut, the region's
    // border cutting the lower lip, 88.9 / 91.9 %, 0.4 %; the colour beyond that border (REACH) and a* over
    // +-4 (RS_MAKEUP_LIP_A_SPAN: nearer a step, so the blur's 0.5 level sits at the colour change, not
    // pulled into the lips' round outline) 94.6 / 94.9 %, 0.14 %; the cut 0.25 a* lower 96.2 / 96.1 %,
    // 0.36 %. Over 2 mm the line follows the colour's blotches (the lower lip's edge dents); over 4.5 or
    // 6 mm it is smoother still but the cut must drop 0.5-1 a* to fill the corners, and spills 0.9-1.5 %.
    float fr = RS_MAKEUP_LIP_FIELD_MM / (h->mm_per_unit > 0.0f ? h->mm_per_unit : 1.0f);
    rs_result res = build_field(mk, RS_COSMETIC_REGION_LIPS, fs, fr, 0.5f, RS_MAKEUP_LIP_LINE_BAND, err);
    free(p), free(fs);
    return res;
}

rs_result rs_makeup_region_weights(rs_makeup *mk, rs_cosmetic_region region, const uint8_t **out, rs_error *err)
{
    *out = NULL;
    if ((unsigned)region >= RS_COSMETIC_REGION_COUNT || region == RS_COSMETIC_REGION_ANY ||
        region == RS_COSMETIC_REGION_DEFAULT)
        return RS_OK;
    if (mk->mask_built[region]) {
        *out = mk->mask[region];
        return RS_OK;
    }
    const rs_splat_header *h = &mk->cloud->hdr;
    bool allowed[256] = {false};
    for (uint32_t k = 0; k < h->region_count && k < RS_SPLAT_MAX_REGIONS; k++) {
        char name[sizeof h->regions[k].name + 1] = {0};
        memcpy(name, h->regions[k].name, sizeof h->regions[k].name);
        allowed[k] = rs_cosmetic_region_allows(region, name);
    }
    uint8_t *w = malloc(RS_MAX(mk->n, 1u));
    uint8_t *cell_out = calloc(RS_MAX(mk->cell_count, 1u), 1);  // the cell holds a splat outside the mask
    if (!w || !cell_out) {
        free(w);
        free(cell_out);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: region mask: out of memory");
    }
    uint32_t inside = 0;
    for (uint32_t c = 0; c < mk->cell_count; c++) {
        const grid_cell *gc = &mk->cells[c];
        for (uint32_t k = gc->start; k < gc->start + gc->count; k++) {
            uint32_t i = mk->order[k];
            w[i] = allowed[splat_region(mk, i)] ? 255 : 0;
            inside += w[i] != 0;
            cell_out[c] |= w[i] == 0;
        }
    }
    mk->mask_built[region] = true;
    if (inside == 0) {  // nothing of this face is in the mask: ignore it rather than paint nothing
        free(w);
        free(cell_out);
        return RS_OK;
    }
    if (region == RS_COSMETIC_REGION_LIPS) {
        free(cell_out);
        rs_result r = lips_mask(mk, w, err);
        if (r) {
            free(w);
            mk->mask_built[region] = false;
            return r;
        }
        mk->mask[region] = w;
        *out = w;
        return RS_OK;
    }
    // Soft edge: each splat inside takes smoothstep(b / edge), b its distance to the region's border. The
    // border lies between the last splats inside and the first outside, so b = (distance to the nearest
    // splat outside) - (half the local spacing), an estimate that does not depend on the LOD, so a look
    // loads alike on a coarser one. The spacing comes from the nearest splat of any region: that distance
    // is ~2/3 of the mean spacing of a Poisson-disk set, hence 0.75 of it (on the bundled face this
    // balances the lips' mean weight between all splats and the 37k LOD: 208 and 206 of 255). Splats
    // farther than `reach_d` from any splat outside take 1; only cells near one holding such a splat
    // are looked at.
    float edge = RS_MAKEUP_MASK_EDGE_MM / (h->mm_per_unit > 0.0f ? h->mm_per_unit : 1.0f);
    float reach_d = 3.0f * edge, r2 = reach_d * reach_d;
    int reach = RS_CLAMP((int)ceilf(reach_d * mk->inv_cell), 1, 4);
    for (uint32_t c = 0; c < mk->cell_count; c++) {
        const grid_cell *gc = &mk->cells[c];
        // The neighbour cells holding splats outside, found once per cell (most cells have none), and the
        // adjacent ones (for the spacing).
        const grid_cell *all[9 * 9 * 9], *near[9 * 9 * 9], *adj[27];
        int na_all = cells_near_cell(mk, gc, reach, all), nn = 0, na = 0, c0[3];
        cell_coords(gc, c0);
        for (int q = 0; q < na_all; q++) {
            int c1[3];
            cell_coords(all[q], c1);
            if (cell_out[all[q] - mk->cells]) near[nn++] = all[q];
            if (abs(c1[0] - c0[0]) <= 1 && abs(c1[1] - c0[1]) <= 1 && abs(c1[2] - c0[2]) <= 1) adj[na++] = all[q];
        }
        for (uint32_t k = gc->start; nn && k < gc->start + gc->count; k++) {
            uint32_t i = mk->order[k];
            if (!w[i]) continue;
            const float *p = mk->cloud->pos[i];
            float out2 = r2, any2 = r2;
            for (int q = 0; q < nn; q++)
                for (uint32_t m = near[q]->start; m < near[q]->start + near[q]->count; m++) {
                    uint32_t j = mk->order[m];
                    if (allowed[splat_region(mk, j)]) continue;
                    out2 = RS_MIN(out2, dist2(mk->cloud->pos[j], p));
                }
            if (!(out2 < r2)) continue;
            for (int q = 0; q < na; q++)
                for (uint32_t m = adj[q]->start; m < adj[q]->start + adj[q]->count; m++)
                    if (mk->order[m] != i) any2 = RS_MIN(any2, dist2(mk->cloud->pos[mk->order[m]], p));
            float t = RS_CLAMP((sqrtf(out2) - 0.75f * sqrtf(any2)) / edge, 0.0f, 1.0f);
            w[i] = (uint8_t)RS_MAX(1, lrintf(255.0f * t * t * (3.0f - 2.0f * t)));
        }
    }
    free(cell_out);
    mk->mask[region] = w;
    *out = w;
    if (region != RS_COSMETIC_REGION_EYES) return RS_OK;
    // The eyes' field: the mask's weights between the splats (already soft: the field is the weight).
    float *src = rs_alloc_array(RS_MAX(mk->n, 1u), sizeof *src);
    if (!src) return rs_fail(err, RS_ERR_NOMEM, "makeup: region field: out of memory");
    for (uint32_t i = 0; i < mk->n; i++) src[i] = w[i] * (1.0f / 255.0f);
    rs_result res = build_field(mk, region, src, edge, 0.5f, 1.0f, err);
    free(src);
    return res;
}

rs_result rs_makeup_create(const rs_splat_cloud *cloud, const rs_makeup_desc *desc, rs_makeup **out,
                           rs_error *err)
{
    rs_makeup *mk = calloc(1, sizeof *mk);
    if (!mk) return rs_fail(err, RS_ERR_NOMEM, "makeup: out of memory");
    mk->cloud = cloud;
    mk->n = cloud->hdr.count;
    mk->undo_levels = desc && desc->undo_levels ? desc->undo_levels : DEFAULT_UNDO_LEVELS;
    mk->undo_bytes = desc && desc->undo_bytes ? desc->undo_bytes : DEFAULT_UNDO_BYTES;
    build_tables(&mk->tables);
    build_bands(mk);
    for (int k = 0; k < 256; k++) mk->touch_w[k] = rs_makeup_touch_weight((uint32_t)k);
    size_t n1 = RS_MAX(mk->n, 1u);
    mk->rec = calloc(n1, sizeof *mk->rec);
    mk->touch = calloc(n1, 1);
    mk->detail = calloc(n1, 1);
    mk->slot_of = rs_alloc_array(n1, sizeof *mk->slot_of);
    if (!mk->rec || !mk->touch || !mk->detail || !mk->slot_of) {
        rs_makeup_destroy(mk);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: layer for %u splats: out of memory", cloud->hdr.count);
    }
    memset(mk->slot_of, 0xff, n1 * sizeof *mk->slot_of);
    const float *lut = mk->tables.to_lin;
    rs_result r = build_grid(mk, err);
    if (r == RS_OK) r = build_detail(mk, lut, err);
    if (r != RS_OK) {
        rs_makeup_destroy(mk);
        return r;
    }
    build_range(mk, lut);
    *out = mk;
    return RS_OK;
}

static void free_history(rs_makeup *mk, uint32_t from)
{
    for (uint32_t k = from; k < mk->hist_count; k++) {
        mk->hist_bytes -= (size_t)mk->hist[k].n * sizeof(delta);
        free(mk->hist[k].d);
    }
    mk->hist_count = RS_MIN(mk->hist_count, from);
}

void rs_makeup_destroy(rs_makeup *mk)
{
    if (!mk) return;
    free_history(mk, 0);
    free(mk->hist);
    free(mk->rec);
    free(mk->touch);
    free(mk->detail);
    free(mk->cells);
    free(mk->hash);
    free(mk->order);
    free(mk->slot_of);
    free(mk->slots);
    free(mk->strokes);
    free(mk->stamps);
    free(mk->cosmetics);
    for (int k = 0; k < RS_COSMETIC_REGION_COUNT; k++) free(mk->mask[k]), free(mk->field[k].value);
    free(mk);
}

const rs_splat_cloud *rs_makeup_cloud(const rs_makeup *mk) { return mk->cloud; }
uint32_t rs_makeup_count(const rs_makeup *mk) { return mk->n; }
const rs_makeup_gpu *rs_makeup_records(const rs_makeup *mk) { return mk->rec; }
const uint8_t *rs_makeup_touches(const rs_makeup *mk) { return mk->touch; }
void rs_makeup_get_uniforms(const rs_makeup *mk, rs_makeup_uniforms *out) { *out = mk->uni; }

// --- gathering -------------------------------------------------------------------------------------

typedef struct cell_box {
    uint32_t lo[3], hi[3];  // inclusive
} cell_box;

static bool cells_around(const rs_makeup *mk, const float p[3], float r, cell_box *b)
{
    for (int a = 0; a < 3; a++) {
        if (p[a] + r < mk->origin[a] || p[a] - r > mk->origin[a] + mk->cell * (float)mk->dim[a]) return false;
        b->lo[a] = axis_cell(mk, a, p[a] - r);
        b->hi[a] = axis_cell(mk, a, p[a] + r);
    }
    return true;
}

// Squared distance from p to the cell's box: cells the sphere misses are skipped unread.
static float cell_dist2(const rs_makeup *mk, const float p[3], const uint32_t c[3])
{
    float d2 = 0.0f;
    for (int a = 0; a < 3; a++) {
        float lo = mk->origin[a] + mk->cell * (float)c[a], hi = lo + mk->cell;
        float d = p[a] < lo ? lo - p[a] : p[a] > hi ? p[a] - hi : 0.0f;
        d2 += d * d;
    }
    return d2;
}

// Calls fn for every grid cell that may hold splats within r of p; returns false if fn stopped.
typedef bool (*cell_fn)(void *user, const grid_cell *cell);
static void for_cells(const rs_makeup *mk, const float p[3], float r, cell_fn fn, void *user, uint32_t *visited)
{
    cell_box b;
    if (!cells_around(mk, p, r, &b)) return;
    float r2 = r * r;
    uint32_t c[3];
    for (c[2] = b.lo[2]; c[2] <= b.hi[2]; c[2]++)
        for (c[1] = b.lo[1]; c[1] <= b.hi[1]; c[1]++)
            for (c[0] = b.lo[0]; c[0] <= b.hi[0]; c[0]++) {
                if (cell_dist2(mk, p, c) > r2) continue;
                const grid_cell *gc = find_cell(mk, cell_key(c[0], c[1], c[2]));
                if (!gc) continue;
                if (visited) (*visited)++;
                if (!fn(user, gc)) return;
            }
}

typedef struct nearest_ctx {
    const rs_makeup *mk;
    const float *p;
    float best_d2;
    uint32_t best;
} nearest_ctx;

static bool nearest_cell(void *user, const grid_cell *gc)
{
    nearest_ctx *x = user;
    for (uint32_t k = gc->start; k < gc->start + gc->count; k++) {
        uint32_t i = x->mk->order[k];
        const float *q = x->mk->cloud->pos[i];
        float dx = q[0] - x->p[0], dy = q[1] - x->p[1], dz = q[2] - x->p[2];
        float d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < x->best_d2 || (d2 == x->best_d2 && i < x->best)) x->best_d2 = d2, x->best = i;
    }
    return true;
}

bool rs_makeup_nearest(const rs_makeup *mk, const float pos[3], float max_dist, uint32_t *idx)
{
    if (!(max_dist >= 0.0f) || !isfinite(pos[0]) || !isfinite(pos[1]) || !isfinite(pos[2])) return false;
    nearest_ctx x = {mk, pos, max_dist * max_dist, UINT32_MAX};
    // Ties at exactly max_dist count as inside.
    x.best_d2 = nextafterf(x.best_d2, INFINITY);
    for_cells(mk, pos, max_dist, nearest_cell, &x, NULL);
    if (x.best == UINT32_MAX) return false;
    *idx = x.best;
    return true;
}

typedef struct near_ctx {
    const rs_makeup *mk;
    const float *p;
    float r2;
    rs_makeup_near_fn fn;
    void *user;
} near_ctx;

static bool near_cell(void *user, const grid_cell *gc)
{
    near_ctx *x = user;
    for (uint32_t k = gc->start; k < gc->start + gc->count; k++) {
        uint32_t i = x->mk->order[k];
        float d2 = dist2(x->mk->cloud->pos[i], x->p);
        if (d2 < x->r2 && !x->fn(x->user, i, d2)) return false;
    }
    return true;
}

void rs_makeup_for_each_near(const rs_makeup *mk, const float pos[3], float radius, rs_makeup_near_fn fn, void *user)
{
    if (!(radius > 0.0f) || !isfinite(pos[0] + pos[1] + pos[2])) return;
    near_ctx x = {mk, pos, radius * radius, fn, user};
    for_cells(mk, pos, radius, near_cell, &x, NULL);
}

static uint32_t sum_cell_counts(const rs_makeup *mk, const float p[3], float r)
{
    cell_box b;
    if (!cells_around(mk, p, r, &b)) return 0;
    uint64_t sum = 0;
    uint32_t c[3];
    for (c[2] = b.lo[2]; c[2] <= b.hi[2]; c[2]++)
        for (c[1] = b.lo[1]; c[1] <= b.hi[1]; c[1]++)
            for (c[0] = b.lo[0]; c[0] <= b.hi[0]; c[0]++) {
                if (cell_dist2(mk, p, c) > r * r) continue;
                const grid_cell *gc = find_cell(mk, cell_key(c[0], c[1], c[2]));
                if (gc) sum += gc->count;
            }
    return (uint32_t)RS_MIN(sum, (uint64_t)mk->n);
}

// --- the fine layer --------------------------------------------------------------------------------

bool rs_makeup_is_fine(const rs_makeup *mk, float radius)
{
    float mm = mk->cloud->hdr.mm_per_unit > 0.0f ? mk->cloud->hdr.mm_per_unit : 1.0f;
    return radius * mm < RS_MAKEUP_FINE_RADIUS_MM;
}

uint32_t rs_makeup_fine_version(const rs_makeup *mk) { return mk->fine_version; }

const rs_makeup_field *rs_makeup_region_field(const rs_makeup *mk, rs_cosmetic_region region)
{
    if ((unsigned)region >= RS_COSMETIC_REGION_COUNT || !mk->field[region].value) return NULL;
    return &mk->field[region];
}

float rs_makeup_field_weight(const rs_makeup_field *f, const float p[3])
{
    if (!f || !f->value) return 1.0f;
    int i0[3];
    float fr[3];
    for (int a = 0; a < 3; a++) {
        // Voxel centres at (i + .5) * voxel, clamped within the box like the shader's texture coordinates.
        float t = RS_CLAMP((p[a] - f->origin[a]) / f->voxel - 0.5f, 0.0f, (float)(f->dim[a] - 1));
        i0[a] = RS_MIN((int)t, RS_MAX(f->dim[a] - 2, 0));
        fr[a] = f->dim[a] > 1 ? t - (float)i0[a] : 0.0f;
    }
    float v = 0.0f;
    for (int c = 0; c < 8; c++) {
        int x = i0[0] + (c & 1), y = i0[1] + (c >> 1 & 1), z = i0[2] + (c >> 2);
        float w = ((c & 1) ? fr[0] : 1.0f - fr[0]) * ((c >> 1 & 1) ? fr[1] : 1.0f - fr[1]) *
                  ((c >> 2) ? fr[2] : 1.0f - fr[2]);
        if (w > 0.0f) v += w * f->value[((size_t)z * f->dim[1] + y) * f->dim[0] + x];
    }
    return RS_CLAMP((v / 255.0f - f->threshold) / f->band + 0.5f, 0.0f, 1.0f);
}

// The region whose field masks a (non-eraser) stamp per pixel, or 0: a brush kept to a region with a
// field, wider than the fine radius (a pencil is its own mask: a lip or eye pencil traces the region's
// border and would be cut in half by it).
static rs_cosmetic_region field_region(const rs_makeup *mk, const rs_cosmetic *cos, bool masked, float radius)
{
    if (!masked || rs_makeup_is_fine(mk, radius)) return 0;
    rs_cosmetic_region r = rs_cosmetic_region_of(cos);
    return mk->field[r].value ? r : 0;
}

// The routing (see the top): per pixel or per splat. Decided from the log's stamp and the fields built
// so far; a field is built by the first stamp kept to its region, before that stamp is routed, so the log
// replays to the same routes.
static bool stamp_is_fine(const rs_makeup *mk, const rs_cosmetic *cos, bool eraser, bool masked, float radius)
{
    return !eraser && (rs_makeup_is_fine(mk, radius) || field_region(mk, cos, masked, radius) != 0);
}

typedef struct plane_ctx {
    const rs_makeup *mk;
    const float *p;
    float inv_2s2, r2;
    double w, c[3], n[3];
} plane_ctx;

static bool plane_cell(void *user, const grid_cell *gc)
{
    plane_ctx *x = user;
    for (uint32_t k = gc->start; k < gc->start + gc->count; k++) {
        uint32_t i = x->mk->order[k];
        float d2 = dist2(x->mk->cloud->pos[i], x->p);
        if (!(d2 < x->r2)) continue;
        double g = exp(-(double)d2 * x->inv_2s2);
        x->w += g;
        for (int a = 0; a < 3; a++) x->c[a] += g * x->mk->cloud->pos[i][a], x->n[a] += g * x->mk->cloud->normal[i][a];
    }
    return true;
}

// p moved onto the surface: the plane of the splats around it (Gaussian-weighted centre and normal over
// `reach`). A fine stamp's mirror image snapped to the nearest splat would jitter by half the splat
// spacing from stamp to stamp (a mirrored liner broke into dots); the plane moves smoothly with p.
static bool surface_point(const rs_makeup *mk, const float p[3], float reach, float out[3])
{
    plane_ctx x = {mk, p, 1.0f / (0.5f * reach * reach), reach * reach, 0, {0, 0, 0}, {0, 0, 0}};
    for_cells(mk, p, reach, plane_cell, &x, NULL);
    double len = sqrt(x.n[0] * x.n[0] + x.n[1] * x.n[1] + x.n[2] * x.n[2]);
    if (!(x.w > 0) || !(len > 0)) return false;
    double d = 0;
    for (int a = 0; a < 3; a++) d += (p[a] - x.c[a] / x.w) * x.n[a] / len;
    for (int a = 0; a < 3; a++) out[a] = (float)(p[a] - d * x.n[a] / len);
    return true;
}

rs_result rs_makeup_fine_stamps(const rs_makeup *mk, rs_makeup_fine_stamp **out, uint32_t *count, rs_error *err)
{
    *out = NULL;
    *count = 0;
    const rs_makeup_applied *s = rs_makeup_log_stamps(mk);
    uint32_t n = rs_makeup_log_count(mk), keep = 0, first = n;
    for (uint32_t k = 0; k < n; k++) {
        const rs_cosmetic *cos = s[k].eraser ? NULL : &mk->cosmetics[s[k].cosmetic];
        bool fine = stamp_is_fine(mk, cos, s[k].eraser, s[k].region_mask, s[k].radius);
        if (fine && first == n) first = k;
        if (fine || (s[k].eraser && first < n)) keep++;
    }
    if (keep == 0) return RS_OK;
    rs_makeup_fine_stamp *f = rs_alloc_array(keep, sizeof *f);
    if (!f) return rs_fail(err, RS_ERR_NOMEM, "makeup: fine layer of %u stamps: out of memory", keep);
    uint32_t j = 0, stroke = 0;
    for (uint32_t k = 0; k < n; k++) {
        stroke += k > 0 && s[k].stroke_start;
        const rs_cosmetic *cos = s[k].eraser ? NULL : &mk->cosmetics[s[k].cosmetic];
        bool fine = stamp_is_fine(mk, cos, s[k].eraser, s[k].region_mask, s[k].radius);
        if (!(fine || (s[k].eraser && k > first))) continue;
        f[j++] = (rs_makeup_fine_stamp){{s[k].pos[0], s[k].pos[1], s[k].pos[2]}, s[k].radius,
                                        {s[k].view_dir[0], s[k].view_dir[1], s[k].view_dir[2]}, s[k].amount,
                                        s[k].cosmetic, stroke, s[k].eraser,
                                        s[k].eraser ? 0u : (uint32_t)field_region(mk, cos, s[k].region_mask, s[k].radius)};
    }
    *out = f;
    *count = j;
    return RS_OK;
}

// Whether the applied log (rs_makeup_log_stamps) holds a fine stamp.
static bool log_has_fine(const rs_makeup *mk)
{
    const rs_makeup_applied *log = rs_makeup_log_stamps(mk);
    for (uint32_t k = 0, n = rs_makeup_log_count(mk); k < n; k++) {
        const rs_makeup_applied *s = &log[k];
        if (!s->eraser && stamp_is_fine(mk, &mk->cosmetics[s->cosmetic], false, s->region_mask, s->radius))
            return true;
    }
    return false;
}

// --- stamping --------------------------------------------------------------------------------------

typedef struct stamp_ctx {
    rs_makeup *mk;
    const float *p, *view;
    float view_len;  // 0: no facing test
    float r2, inv_r2, amount;
    const prepared *cos;  // NULL = eraser
    const uint8_t *mask;  // region mask weights (q/255), NULL = none
    rs_makeup_stamp_info *info;
} stamp_ctx;


static void stamp_splat(stamp_ctx *x, uint32_t i)
{
    rs_makeup *mk = x->mk;
    const float *q = mk->cloud->pos[i];
    float dx = q[0] - x->p[0], dy = q[1] - x->p[1], dz = q[2] - x->p[2];
    float d2 = dx * dx + dy * dy + dz * dz;
    if (!(d2 < x->r2)) return;
    float facing = rs_makeup_facing(mk->cloud->normal[i], x->view, x->view_len, !x->cos);
    if (!(facing > 0.0f)) return;
    float ig = falloff_t(d2 * x->inv_r2, x->cos ? x->cos->hard : 0.0f) * facing;
    if (x->mask) ig *= x->mask[i] * (1.0f / 255.0f);  // outside the product's region: 0, soft at its edge
    if (!(ig > 0.0f)) return;
    x->info->touched++;
    int32_t s = mk->slot_of[i];
    if (s < 0) {
        // Capacity was reserved before the gather (rs_makeup_stamp), so this cannot fail.
        s = (int32_t)mk->slot_count++;
        mk->slots[s] = (stroke_slot){i, mk->rec[i], mk->touch[i], 0.0f};
        mk->slot_of[i] = s;
        if (x->cos && mk->touch[i] < 255) mk->touch[i]++;
    }
    stroke_slot *sl = &mk->slots[s];
    float a;
    if (x->cos) {
        // Coverage v moves eq. (3) towards a hard-edged footprint: an opaque product (v = 1) deposits
        // fully over the inner part of the brush (I_G x 3, capped: a liner's solid line, its rim still
        // soft), a sheer one (v = 0) builds up by eq. (3).
        float v = x->cos->coverage;
        float i3 = rs_makeup_intensity(ig, x->cos->material_w, mk->touch_w[mk->touch[i]]);
        a = x->amount * (i3 + v * (RS_MIN(1.0f, ig * (1.0f + 2.0f * v)) - i3));
    } else {
        a = x->amount * RS_MIN(1.0f, 2.0f * ig);  // eraser: flat top, full erase in the inner half
    }
    if (!(a > sl->amount)) return;  // the stroke opacity cap: max over the stroke's stamps
    sl->amount = a;
    rs_makeup_gpu r = sl->before;
    if (x->cos) {
        compose(&mk->tables, &r, x->cos, a, mk->detail[i]);
    } else {
        rs_makeup_erase(&r, a);
        if (!(r.colour_i | r.spec_i)) mk->touch[i] = 0;  // fully erased: back to bare skin, I_F too
    }
    if (memcmp(&r, &mk->rec[i], sizeof r) != 0) {
        mk->rec[i] = r;
        extend(&x->info->dirty, i);
        mark(mk, i);
    }
}

static bool stamp_cell(void *user, const grid_cell *gc)
{
    stamp_ctx *x = user;
    x->info->examined += gc->count;
    for (uint32_t k = gc->start; k < gc->start + gc->count; k++) stamp_splat(x, x->mk->order[k]);
    return true;
}

static int log_cosmetic(rs_makeup *mk, const rs_cosmetic *c)
{
    for (uint32_t i = 0; i < mk->cosmetic_count; i++)
        if (rs_cosmetic_equal(&mk->cosmetics[i], c)) return (int)i;
    if (mk->cosmetic_count >= UINT16_MAX) return -1;
    if (!rs_array_grow((void **)&mk->cosmetics, &mk->cosmetic_cap, mk->cosmetic_count + 1, sizeof *mk->cosmetics))
        return -1;
    mk->cosmetics[mk->cosmetic_count] = *c;
    return (int)mk->cosmetic_count++;
}


static bool finite3(const float v[3]) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

static void apply_stamp(rs_makeup *mk, const rs_makeup_applied *s, const rs_cosmetic *cosmetic,
                        const uint8_t *mask, rs_makeup_stamp_info *info)
{
    prepared prep;
    const prepared *cos = NULL;
    if (cosmetic) {
        prep = prepare(&mk->tables, cosmetic);
        cos = &prep;
    }
    const float *v = s->view_dir;
    float vlen = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    stamp_ctx x = {mk, s->pos, v, vlen, s->radius * s->radius,
                   1.0f / (s->radius * s->radius), s->amount, cos, mask, info};
    for_cells(mk, s->pos, s->radius, stamp_cell, &x, &info->cells);
    mk->stamps[mk->stamp_count++] = *s;
}

void rs_makeup_begin_stroke(rs_makeup *mk)
{
    if (mk->in_stroke) rs_makeup_end_stroke(mk, NULL);
    mk->in_stroke = true;
    mk->stroke_fine = false;
    mk->stroke_reserved = false;
    mk->stroke_first_stamp = mk->stamp_count;
    mk->slot_count = 0;
}

bool rs_makeup_in_stroke(const rs_makeup *mk) { return mk->in_stroke; }

rs_result rs_makeup_stamp(rs_makeup *mk, const rs_makeup_stamp_desc *d, rs_makeup_stamp_info *info,
                          rs_error *err)
{
    rs_makeup_stamp_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    if (!finite3(d->pos) || !finite3(d->view_dir))
        return rs_fail(err, RS_ERR_ARG, "makeup stamp: position or view direction not finite");
    // A brush wider than the face is a mistake (and would make a stamp cost the whole grid).
    if (!isfinite(d->radius) || !(d->radius > 0.0f) || !(d->radius <= mk->cloud->hdr.face_height))
        return rs_fail(err, RS_ERR_ARG, "makeup stamp: radius %g, must be in (0, face height %g]", d->radius,
                       mk->cloud->hdr.face_height);
    if (!isfinite(d->opacity) || !isfinite(d->pressure) || (unsigned)d->pressure_map >= RS_MAKEUP_PRESSURE_COUNT)
        return rs_fail(err, RS_ERR_ARG, "makeup stamp: opacity, pressure or pressure map invalid");
    if (!d->eraser) {
        if (!d->cosmetic) return rs_fail(err, RS_ERR_ARG, "makeup stamp: no cosmetic");
        rs_error cerr = {0};
        if (rs_cosmetic_validate(d->cosmetic, &cerr) != RS_OK)
            return rs_fail(err, RS_ERR_ARG, "makeup stamp: %s", cerr.msg);
    }
    const uint8_t *mask = NULL;
    if (d->region_mask && !d->eraser) {
        rs_result r = rs_makeup_region_weights(mk, rs_cosmetic_region_of(d->cosmetic), &mask, err);
        if (r != RS_OK) return r;
    }
    bool implicit = !mk->in_stroke;
    if (implicit) rs_makeup_begin_stroke(mk);

    // Reserve everything first, so a failure leaves the layer untouched.
    uint32_t mirror_idx = UINT32_MAX;
    float mpos[3];
    // A fine stamp is evaluated per pixel by the renderer: logged, no record changes (see the top).
    bool fine = stamp_is_fine(mk, d->cosmetic, d->eraser, mask != NULL, d->radius);
    if (d->mirror) {
        rs_makeup_mirror_point(&mk->cloud->hdr, d->pos, mpos);
        // The mirror image of a surface point lies near the other side's surface; snap to the nearest
        // splat within one brush radius (none: the face is not symmetric there, skip the mirror). A fine
        // stamp's image is projected onto the surface instead, from up to two grid cells away (a face is
        // less symmetric than a 2 mm liner is wide).
        float reach = fine ? RS_MAX(d->radius, 2.0f * mk->cell) : d->radius;
        if (!rs_makeup_nearest(mk, mpos, reach, &mirror_idx)) mirror_idx = UINT32_MAX;
    }
    uint32_t need = sum_cell_counts(mk, d->pos, d->radius);
    if (mirror_idx != UINT32_MAX) need += sum_cell_counts(mk, mk->cloud->pos[mirror_idx], d->radius);
    int cos_index = d->eraser ? 0 : log_cosmetic(mk, d->cosmetic);
    bool ok = cos_index >= 0 && mk->stamp_count + 2 <= LOG_STAMPS_MAX &&
              rs_array_grow((void **)&mk->stamps, &mk->stamp_cap, mk->stamp_count + 2, sizeof *mk->stamps) &&
              rs_array_grow((void **)&mk->slots, &mk->slot_cap, (uint32_t)RS_MIN((uint64_t)mk->slot_count + need,
                                                                       (uint64_t)mk->n + 1), sizeof *mk->slots) &&
              (mk->stroke_reserved ||
               rs_array_grow((void **)&mk->strokes, &mk->stroke_cap, mk->stroke_count + 1, sizeof *mk->strokes));
    if (!ok) {
        if (implicit) mk->in_stroke = false;
        return rs_fail(err, mk->stamp_count + 2 > LOG_STAMPS_MAX ? RS_ERR_LIMIT : RS_ERR_NOMEM,
                       "makeup stamp: %s", mk->stamp_count + 2 > LOG_STAMPS_MAX
                                               ? "stamp log full (save the look and clear)"
                                               : "out of memory");
    }
    mk->stroke_reserved = true;

    const rs_cosmetic *cos = d->eraser ? NULL : &mk->cosmetics[cos_index];
    bool masked = d->region_mask && !d->eraser;
    rs_makeup_applied s = {{d->pos[0], d->pos[1], d->pos[2]},
                           {d->view_dir[0], d->view_dir[1], d->view_dir[2]},
                           d->radius,
                           clamp01(d->opacity) * rs_makeup_pressure_scale(d->pressure_map, d->pressure),
                           (uint16_t)cos_index,
                           d->eraser,
                           mk->stamp_count == mk->stroke_first_stamp,
                           masked};
    mk->fine_version++;
    // An eraser over fine stamps changes the picture even where it changes no record (a lipstick drawn per
    // pixel over bare skin): the stroke must stay in the log, which is where the renderer reads it.
    mk->stroke_fine |= fine || (d->eraser && !mk->stroke_fine && log_has_fine(mk));
    if (fine) mk->stamps[mk->stamp_count++] = s;
    else apply_stamp(mk, &s, cos, mask, info);
    if (mirror_idx != UINT32_MAX) {
        memcpy(s.pos, mk->cloud->pos[mirror_idx], sizeof s.pos);
        if (fine) surface_point(mk, mpos, 2.0f * mk->cell, s.pos);
        rs_makeup_mirror_dir(&mk->cloud->hdr, d->view_dir, s.view_dir);
        s.stroke_start = 0;
        if (fine) mk->stamps[mk->stamp_count++] = s;
        else apply_stamp(mk, &s, cos, mask, info);
        info->mirrored = true;
    }
    if (implicit) return rs_makeup_end_stroke(mk, err);
    return RS_OK;
}

// --- strokes, history, log ---------------------------------------------------------------------------

static uint32_t applied_stamp_end(const rs_makeup *mk)
{
    if (mk->applied == 0) return 0;
    const log_stroke *s = &mk->strokes[mk->applied - 1];
    return s->first + s->count;
}

// A new stroke after undo discards the undone strokes (their log stamps and history).
static void truncate_redo(rs_makeup *mk)
{
    free_history(mk, mk->applied - mk->hist_first);
    mk->stroke_count = mk->applied;
}

static void forget_all_history(rs_makeup *mk)
{
    free_history(mk, 0);
    mk->hist_first = mk->stroke_count;
}

// Pushes a finished stroke's deltas (taking ownership) and evicts the oldest beyond the budget.
static rs_result push_history(rs_makeup *mk, delta *d, uint32_t n, rs_error *err)
{
    if (!rs_array_grow((void **)&mk->hist, &mk->hist_cap, mk->hist_count + 1, sizeof *mk->hist)) {
        free(d);
        forget_all_history(mk);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: undo history: out of memory (history dropped)");
    }
    mk->hist[mk->hist_count++] = (hist_entry){d, n};
    mk->hist_bytes += (size_t)n * sizeof *d;
    uint32_t drop = 0;
    size_t bytes = mk->hist_bytes;
    while (mk->hist_count - drop > 1 && (mk->hist_count - drop > mk->undo_levels || bytes > mk->undo_bytes)) {
        bytes -= (size_t)mk->hist[drop].n * sizeof(delta);
        free(mk->hist[drop].d);
        drop++;
    }
    if (drop) {
        memmove(mk->hist, mk->hist + drop, (mk->hist_count - drop) * sizeof *mk->hist);
        mk->hist_count -= drop;
        mk->hist_first += drop;
        mk->hist_bytes = bytes;
    }
    return RS_OK;
}

// Appends a stroke to the log (capacity reserved by the caller) after discarding undone strokes.
static void log_push_stroke(rs_makeup *mk, uint32_t first, uint32_t count, bool clear)
{
    truncate_redo(mk);
    uint32_t dst = applied_stamp_end(mk);
    if (count && dst != first) memmove(mk->stamps + dst, mk->stamps + first, count * sizeof *mk->stamps);
    mk->stamp_count = dst + count;
    mk->strokes[mk->stroke_count++] = (log_stroke){dst, count, clear};
    mk->applied = mk->stroke_count;
}

rs_result rs_makeup_end_stroke(rs_makeup *mk, rs_error *err)
{
    if (!mk->in_stroke) return RS_OK;
    mk->in_stroke = false;
    uint32_t changed = 0;
    for (uint32_t k = 0; k < mk->slot_count; k++) {
        const stroke_slot *s = &mk->slots[k];
        mk->slot_of[s->idx] = -1;
        if (memcmp(&s->before, &mk->rec[s->idx], sizeof s->before) != 0 || s->touch_before != mk->touch[s->idx])
            changed++;
    }
    if (changed == 0 && !mk->stroke_fine) {
        // Nothing happened: the stroke leaves no trace in the log or the history.
        mk->stamp_count = mk->stroke_first_stamp;
        mk->slot_count = 0;
        return RS_OK;
    }
    log_push_stroke(mk, mk->stroke_first_stamp, mk->stamp_count - mk->stroke_first_stamp, false);
    // A stroke of fine stamps alone has no deltas: its history entry is empty, its log stroke is the change.
    delta *d = changed ? rs_alloc_array(changed, sizeof *d) : NULL;
    if (changed && !d) {
        mk->slot_count = 0;
        forget_all_history(mk);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: undo for a stroke of %u splats: out of memory", changed);
    }
    uint32_t j = 0;
    for (uint32_t k = 0; k < mk->slot_count; k++) {
        const stroke_slot *s = &mk->slots[k];
        if (memcmp(&s->before, &mk->rec[s->idx], sizeof s->before) == 0 && s->touch_before == mk->touch[s->idx])
            continue;
        d[j++] = (delta){s->idx, s->before, mk->rec[s->idx], s->touch_before, mk->touch[s->idx]};
    }
    mk->slot_count = 0;
    return push_history(mk, d, changed, err);
}

void rs_makeup_cancel_stroke(rs_makeup *mk, rs_makeup_range *dirty)
{
    rs_makeup_range r = {0, 0};
    if (mk->in_stroke) {
        for (uint32_t k = 0; k < mk->slot_count; k++) {
            const stroke_slot *s = &mk->slots[k];
            if (memcmp(&s->before, &mk->rec[s->idx], sizeof s->before) != 0) {
                extend(&r, s->idx);
                mark(mk, s->idx);
            }
            mk->rec[s->idx] = s->before;
            mk->touch[s->idx] = s->touch_before;
            mk->slot_of[s->idx] = -1;
        }
        mk->slot_count = 0;
        mk->stamp_count = mk->stroke_first_stamp;
        mk->in_stroke = false;
        mk->fine_version++;
    }
    if (dirty) *dirty = r;
}

static void apply_deltas(rs_makeup *mk, const hist_entry *h, bool forward, rs_makeup_range *dirty)
{
    rs_makeup_range r = {0, 0};
    for (uint32_t k = 0; k < h->n; k++) {
        const delta *d = &h->d[k];
        mk->rec[d->idx] = forward ? d->after : d->before;
        mk->touch[d->idx] = forward ? d->touch_after : d->touch_before;
        extend(&r, d->idx);
        mark(mk, d->idx);
    }
    if (dirty) *dirty = r;
}

bool rs_makeup_can_undo(const rs_makeup *mk) { return mk->applied > mk->hist_first || mk->in_stroke; }
bool rs_makeup_can_redo(const rs_makeup *mk) { return !mk->in_stroke && mk->applied < mk->stroke_count; }

bool rs_makeup_undo(rs_makeup *mk, rs_makeup_range *dirty)
{
    if (dirty) *dirty = (rs_makeup_range){0, 0};
    if (mk->in_stroke) rs_makeup_end_stroke(mk, NULL);
    if (mk->applied <= mk->hist_first) return false;
    apply_deltas(mk, &mk->hist[mk->applied - 1 - mk->hist_first], false, dirty);
    mk->applied--;
    mk->fine_version++;
    return true;
}

bool rs_makeup_redo(rs_makeup *mk, rs_makeup_range *dirty)
{
    if (dirty) *dirty = (rs_makeup_range){0, 0};
    if (mk->in_stroke) rs_makeup_end_stroke(mk, NULL);
    if (mk->applied >= mk->stroke_count) return false;
    apply_deltas(mk, &mk->hist[mk->applied - mk->hist_first], true, dirty);
    mk->applied++;
    mk->fine_version++;
    return true;
}

rs_result rs_makeup_clear(rs_makeup *mk, rs_makeup_range *dirty, rs_error *err)
{
    if (dirty) *dirty = (rs_makeup_range){0, 0};
    if (mk->in_stroke) rs_makeup_end_stroke(mk, NULL);
    static const rs_makeup_gpu zero;
    uint32_t changed = 0;
    for (uint32_t i = 0; i < mk->n; i++)
        if (mk->touch[i] || memcmp(&mk->rec[i], &zero, sizeof zero) != 0) changed++;
    if (changed == 0 && rs_makeup_log_count(mk) == 0) return RS_OK;
    delta *d = changed ? rs_alloc_array(changed, sizeof *d) : NULL;
    if ((changed && !d) || !rs_array_grow((void **)&mk->strokes, &mk->stroke_cap, mk->stroke_count + 1, sizeof *mk->strokes)) {
        free(d);
        return rs_fail(err, RS_ERR_NOMEM, "makeup: clear: out of memory");
    }
    rs_makeup_range r = {0, 0};
    uint32_t j = 0;
    for (uint32_t i = 0; i < mk->n; i++) {
        if (!mk->touch[i] && memcmp(&mk->rec[i], &zero, sizeof zero) == 0) continue;
        d[j++] = (delta){i, mk->rec[i], zero, mk->touch[i], 0};
        mk->rec[i] = zero;
        mk->touch[i] = 0;
        extend(&r, i);
        mark(mk, i);
    }
    if (dirty) *dirty = r;
    log_push_stroke(mk, mk->stamp_count, 0, true);
    mk->fine_version++;
    return push_history(mk, d, changed, err);
}

void rs_makeup_reset(rs_makeup *mk, rs_makeup_range *dirty)
{
    rs_makeup_cancel_stroke(mk, NULL);
    memset(mk->rec, 0, (size_t)mk->n * sizeof *mk->rec);
    memset(mk->touch, 0, mk->n);
    free_history(mk, 0);
    mk->hist_first = mk->stroke_count = mk->applied = mk->stamp_count = mk->cosmetic_count = 0;
    mk->fine_version++;
    mark_all(mk);
    if (dirty) *dirty = (rs_makeup_range){0, mk->n};
}

void rs_makeup_forget_history(rs_makeup *mk)
{
    if (mk->in_stroke) rs_makeup_end_stroke(mk, NULL);
    truncate_redo(mk);
    mk->stamp_count = applied_stamp_end(mk);
    forget_all_history(mk);
}

static uint32_t log_start(const rs_makeup *mk)
{
    for (uint32_t k = mk->applied; k > 0; k--)
        if (mk->strokes[k - 1].clear) return mk->strokes[k - 1].first;
    return 0;
}

uint32_t rs_makeup_log_count(const rs_makeup *mk) { return applied_stamp_end(mk) - log_start(mk); }
const rs_makeup_applied *rs_makeup_log_stamps(const rs_makeup *mk)
{
    return mk->stamps ? mk->stamps + log_start(mk) : NULL;
}
uint32_t rs_makeup_log_cosmetic_count(const rs_makeup *mk) { return mk->cosmetic_count; }

const rs_cosmetic *rs_makeup_log_cosmetic(const rs_makeup *mk, uint32_t i)
{
    return i < mk->cosmetic_count ? &mk->cosmetics[i] : NULL;
}

uint32_t rs_makeup_take_dirty(rs_makeup *mk, rs_makeup_range *out, uint32_t cap)
{
    uint32_t n = 0;
    for (uint32_t b = 0; b < mk->band_count; b++) {
        rs_makeup_range r = mk->band_dirty[b];
        mk->band_dirty[b] = (rs_makeup_range){0, 0};
        if (r.lo >= r.hi || cap == 0) continue;
        if (n < cap) {
            out[n++] = r;
        } else {
            // Too little room: widen the last range (still correct, uploads more).
            out[n - 1].lo = RS_MIN(out[n - 1].lo, r.lo);
            out[n - 1].hi = RS_MAX(out[n - 1].hi, r.hi);
        }
    }
    return n;
}
