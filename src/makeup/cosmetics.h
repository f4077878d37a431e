// cosmetics.h — the products a person paints with: colour, material weight and finish per cosmetic.
//
// Does: a fixed table of presets (foundation shades 1/2/3, powder, blush, bronzer, contour, highlighter,
// lipsticks, lip gloss, eyeshadows, eyeliner, brow pencil, mascara, concealer), looked up by name or listed for a UI; custom products from
// an RGB or HSV colour and a custom finish; validation of a cosmetic's fields (for files that carry one).
// Does not: paint (src/makeup/makeup.c applies a cosmetic to the layer) or own any state: presets are static
// constants, customs are plain values the caller keeps.
//
//   const rs_cosmetic *gloss = rs_cosmetic_find("lip_gloss");
//   rs_cosmetic mine = *rs_cosmetic_find("lipstick_satin");
//   rs_cosmetic_hsv_to_rgb(340.0f, 0.6f, 0.8f, mine.rgb);   // custom pink, satin finish
//   snprintf(mine.name, sizeof mine.name, "custom");
//   for (uint32_t i = 0; i < rs_cosmetic_count(); i++) puts(rs_cosmetic_get(i)->name);
#ifndef RS_COSMETICS_H
#define RS_COSMETICS_H

#include "core/core.h"

#include <stddef.h>

#define RS_COSMETIC_NAME_MAX 32  // bytes including the NUL; names are [a-z0-9_]

typedef enum rs_cosmetic_kind {
    RS_COSMETIC_CUSTOM = 0,
    RS_COSMETIC_FOUNDATION,
    RS_COSMETIC_POWDER,
    RS_COSMETIC_BLUSH,
    RS_COSMETIC_BRONZER,      // bronzer and contour
    RS_COSMETIC_HIGHLIGHTER,
    RS_COSMETIC_LIPSTICK,
    RS_COSMETIC_LIP_GLOSS,
    RS_COSMETIC_EYESHADOW,
    RS_COSMETIC_EYELINER,
    RS_COSMETIC_BROW,         // brow pencil: fine hair-like strokes
    RS_COSMETIC_MASCARA,      // along the lash line: a crisp, very dark band
    RS_COSMETIC_CONCEALER,    // opaque, skin-toned, small brush: covers spots and under-eye shadow
    RS_COSMETIC_KIND_COUNT,
} rs_cosmetic_kind;

// Where a product goes by default when its brush keeps to regions (region-aware brushes, issue 15;
// regions are the .rsf region table's, found by name: see rs_cosmetic_region_allows).
typedef enum rs_cosmetic_region {
    RS_COSMETIC_REGION_DEFAULT = 0,  // the kind's: lipstick/gloss lips, liner/shadow eyes, custom any, else skin
    RS_COSMETIC_REGION_ANY,          // anywhere
    RS_COSMETIC_REGION_LIPS,         // "lips"
    RS_COSMETIC_REGION_EYES,         // "eyelid": the eye area from the lash lines to the brows
    RS_COSMETIC_REGION_SKIN,         // everything but "lips", "eyelid" and "brow"
    RS_COSMETIC_REGION_COUNT,
} rs_cosmetic_region;

// One product. Colour weights and intensities are 0..1. `m` and `rho_s` are absolute targets in the
// specular model's units (Beckmann roughness, Kelemen/Szirmay-Kalos scale; skin is about 0.23-0.30 and
// 0.18-0.31): where the product lies with finish intensity 1 they replace the skin's values.
typedef struct rs_cosmetic {
    char name[RS_COSMETIC_NAME_MAX];  // "lip_gloss"
    rs_cosmetic_kind kind;
    uint8_t rgb[3];          // product colour, sRGB (converted to linear light before any mixing)
    float material_weight;   // I_M of eq. (3): how strongly the product deposits
    float colour_weight;     // scales the colour intensity; 0 = colourless (lip gloss, clear powder)
    float finish_weight;     // scales the finish intensity (how much m/rho_s move towards the product's)
    float m;                 // finish: Beckmann roughness target, 0..1
    float rho_s;             // finish: specular scale target, 0..1
    float size_rel;          // default brush diameter as a fraction of the face height
    float opacity;           // default brush opacity (coverage per stroke)
    // Finish layers over the skin's own lobe (blended in with the finish intensity, like m and rho_s):
    float coat;              // clear-coat weight 0..1: a smooth, untinted second lobe (gloss; F0 0.04, m 0.1)
    float shimmer;           // flake sparkle 0..1: tiny pigment-tinted mirrors that glint (highlighter)
    float coverage;          // 0 sheer .. 1 opaque: an opaque pigment keeps its own colour (not held in the
                             // face's range), hides the skin texture and deposits fully in one stroke (eq. 3
                             // moves towards the brush footprint alone); docs/makeup.md
    rs_cosmetic_region region_mask;  // where its brush stays unless told otherwise (0 = the kind's default)
} rs_cosmetic;

// Finish families (docs/makeup.md): what a product editor offers. Each sets m, rho_s, coat, shimmer.
typedef enum rs_finish {
    RS_FINISH_MATTE = 0,     // rough, about half the skin's rho_s, no coat: dulls shine (powder)
    RS_FINISH_SATIN,         // about the skin's own lobe plus a faint coat
    RS_FINISH_GLOSS,         // smooth lobe and a full clear coat: sharp reflections of the surroundings
    RS_FINISH_SHIMMER,       // smooth lobe and flakes
    RS_FINISH_COUNT,
} rs_finish;

const char *rs_finish_name(rs_finish f);                    // "matte", "satin", "gloss", "shimmer"
bool rs_finish_parse(const char *name, rs_finish *out);
void rs_cosmetic_set_finish(rs_cosmetic *c, rs_finish f);  // keeps colour, weights, brush
rs_finish rs_cosmetic_finish(const rs_cosmetic *c);         // the family nearest to c's finish
// A new colour; a colourless product (gloss, clear powder: colour weight < 0.5) gains one (0.8).
void rs_cosmetic_set_rgb(rs_cosmetic *c, const uint8_t rgb[3]);

uint32_t rs_cosmetic_count(void);
// Preset i (0 <= i < rs_cosmetic_count()), in UI order; NULL when out of range.
const rs_cosmetic *rs_cosmetic_get(uint32_t i);
// Preset by exact name ("foundation_2"); NULL when unknown.
const rs_cosmetic *rs_cosmetic_find(const char *name);
const char *rs_cosmetic_kind_name(rs_cosmetic_kind kind);

// The region a product keeps to, DEFAULT resolved by kind (never DEFAULT); its name ("lips", "eyes",
// "skin", "any") for files and the UI; and whether a region of the face table named `region` is in it.
rs_cosmetic_region rs_cosmetic_region_of(const rs_cosmetic *c);
const char *rs_cosmetic_region_name(rs_cosmetic_region r);
bool rs_cosmetic_region_allows(rs_cosmetic_region r, const char *region);

// A custom product: colour from sRGB, finish (m, rho_s) and weights given; named "custom", default
// brush of a medium blending brush. Values are clamped to their ranges.
rs_cosmetic rs_cosmetic_custom(const uint8_t rgb[3], float material_weight, float m, float rho_s);
// HSV (h in degrees, any value, wrapped; s, v in 0..1) to sRGB 8-bit: colour pickers work in HSV.
void rs_cosmetic_hsv_to_rgb(float h_deg, float s, float v, uint8_t rgb[3]);
// The inverse: h in [0, 360) (0 for greys), s and v in 0..1.
void rs_cosmetic_rgb_to_hsv(const uint8_t rgb[3], float *h_deg, float *s, float *v);

// Checks every field is finite and in range and the name is [a-z0-9_]+ (for cosmetics read from files).
rs_result rs_cosmetic_validate(const rs_cosmetic *c, rs_error *err);
// Field-by-field equality (no memcmp over padding).
bool rs_cosmetic_equal(const rs_cosmetic *a, const rs_cosmetic *b);

// Text form used by stroke and look files (docs/makeup.md): a preset's name when c equals that preset,
// else "custom name=N kind=K rgb=R,G,B weight=W colour=C finish=F m=M rho_s=S size=Z opacity=O
// coat=G shimmer=H coverage=V region=R" (the finish layers only when non-zero, the region only when not the
// kind's default)
// (floats printed to round-trip exactly). Returns what snprintf returns.
int rs_cosmetic_format(const rs_cosmetic *c, char *buf, size_t cap);
// Parses that form (NUL-terminated, one line). "custom" needs rgb= or hsv=H,S,V plus m= and rho_s=;
// other keys default to rs_cosmetic_custom's values. The result is validated.
rs_result rs_cosmetic_parse(const char *text, rs_cosmetic *out, rs_error *err);

#endif
