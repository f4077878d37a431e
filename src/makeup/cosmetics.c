// cosmetics.c — preset products and custom ones. The numbers are starting points chosen from the
// sources below and tuned by eye on the bundled head; docs/makeup.md gives the table with the reasons.
//
// Anchors for the finish values (m = Beckmann roughness, rho_s = specular scale, paper Table 1 units):
// bare skin measures m 0.23-0.30, rho_s 0.18-0.31 (Weyrich et al. 2006, paper Table 1). The paper's
// reflectance editing lowers specular for foundation/powder ("less oily shine") and raises it for a
// colourless gloss. Vendors model finish as matte / satin / gloss / shimmer; our mapping
// (research/product_anchors.md §1.2): matte = rougher and about half the skin's rho_s, satin = about the
// skin's values, gloss = smoother and about twice rho_s, shimmer = slightly smoother and ~1.5x rho_s.
// Coverage (opacity) defaults follow Banuba's "mid" presets (foundation 0.6, lipstick 0.8, highlighter
// 0.5, eyeshadow/eyeliner 0.9); material weights I_M say how much pigment a product lays down in one
// pass: sheer products (blush, bronzer) low, creamy opaque ones (lipstick, liner) high.
#define _POSIX_C_SOURCE 200809L  // strtok_r
#include "makeup/cosmetics.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>

//  name, kind, sRGB, I_M, colour w, finish w, m, rho_s, size (diameter / face height), opacity, coat, shimmer,
//  coverage, region (where the brush stays unless told otherwise: lips, the eye area, or skin off the lips,
//  eyes and brows)
static const rs_cosmetic presets[] = {
    // Foundation shades 1 (light) to 3 (deep), a warm-neutral undertone like most skin. Satin-matte:
    // a little rougher and less specular than skin (the paper: base makeup reduces oily shine).
    // Large blending brush (0.3 = the paper's largest tool), medium coverage.
    {"foundation_1", RS_COSMETIC_FOUNDATION, {236, 203, 178}, 0.60f, 1.00f, 0.70f, 0.34f, 0.15f, 0.30f, 0.50f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    {"foundation_2", RS_COSMETIC_FOUNDATION, {208, 164, 132}, 0.60f, 1.00f, 0.70f, 0.34f, 0.15f, 0.30f, 0.50f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    {"foundation_3", RS_COSMETIC_FOUNDATION, {168, 122, 92}, 0.60f, 1.00f, 0.70f, 0.34f, 0.15f, 0.30f, 0.50f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    // Translucent setting powder: barely tints (colour weight 0.15, a slight brightening), fully matte:
    // roughness up, rho_s to about a third of skin. This is the "reduced shine" of the paper's Fig. 12.
    {"powder", RS_COSMETIC_POWDER, {236, 218, 204}, 0.50f, 0.15f, 1.00f, 0.45f, 0.07f, 0.30f, 0.60f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    // Powder blush, rose: sheer (low I_M, opacity 0.35) so it builds up over strokes; matte-ish finish
    // at half weight (a powder over skin, not a full film).
    {"blush", RS_COSMETIC_BLUSH, {220, 112, 122}, 0.35f, 1.00f, 0.50f, 0.35f, 0.14f, 0.20f, 0.35f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    // Bronzer: warm brown, sheer, matte; contour: cooler, greyer brown that reads as shadow.
    {"bronzer", RS_COSMETIC_BRONZER, {168, 110, 76}, 0.35f, 1.00f, 0.50f, 0.36f, 0.13f, 0.20f, 0.30f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    {"contour", RS_COSMETIC_BRONZER, {132, 100, 84}, 0.35f, 1.00f, 0.50f, 0.36f, 0.13f, 0.15f, 0.30f,
     0.0f, 0.0f, 0.0f, RS_COSMETIC_REGION_SKIN},
    // Highlighter, shimmer: pale champagne at half colour weight (a sheen, not white paint); smoother
    // and brighter specular (rho_s 0.45, ~1.5-2x skin) is what makes it catch the light.
    {"highlighter", RS_COSMETIC_HIGHLIGHTER, {250, 236, 214}, 0.40f, 0.50f, 1.00f, 0.21f, 0.45f, 0.12f, 0.50f,
     0.0f, 0.80f, 0.0f, RS_COSMETIC_REGION_SKIN},
    // Lipsticks: opaque, small brush. Matte red: rough, low specular. Satin pink: about the lips' own
    // measured finish (m 0.27-0.30, rho_s 0.26-0.31), so colour changes but the sheen stays.
    // Lipsticks are the most opaque products: full coverage and high pigment load, so two passes cover
    // the lips (I ~ 0.94 at the brush centre) while the lips' texture still shows through.
    {"lipstick_matte", RS_COSMETIC_LIPSTICK, {168, 36, 54}, 0.95f, 1.00f, 1.00f, 0.42f, 0.09f, 0.08f, 1.00f,
     0.0f, 0.0f, 0.60f, RS_COSMETIC_REGION_LIPS},
    {"lipstick_satin", RS_COSMETIC_LIPSTICK, {204, 78, 118}, 0.90f, 1.00f, 1.00f, 0.27f, 0.28f, 0.08f, 1.00f,
     0.25f, 0.0f, 0.40f, RS_COSMETIC_REGION_LIPS},
    // Lip gloss: colourless (colour weight 0: the record's colour intensity stays 0), a clear wet coat:
    // a full clear-coat lobe (the sharp window/softbox reflections) over a smoother lip lobe.
    {"lip_gloss", RS_COSMETIC_LIP_GLOSS, {255, 255, 255}, 0.60f, 0.00f, 1.00f, 0.12f, 0.65f, 0.08f, 0.80f,
     1.00f, 0.0f, 0.0f, RS_COSMETIC_REGION_LIPS},
    // Eyeshadows: brown matte (the paper's Fig. 12), plum satin, champagne shimmer. Lid-sized brush.
    {"eyeshadow_brown", RS_COSMETIC_EYESHADOW, {122, 82, 62}, 0.55f, 1.00f, 0.80f, 0.38f, 0.12f, 0.07f, 0.60f,
     0.0f, 0.0f, 0.30f, RS_COSMETIC_REGION_EYES},
    {"eyeshadow_plum", RS_COSMETIC_EYESHADOW, {112, 62, 92}, 0.55f, 1.00f, 0.80f, 0.30f, 0.20f, 0.07f, 0.60f,
     0.0f, 0.0f, 0.50f, RS_COSMETIC_REGION_EYES},
    {"eyeshadow_champagne", RS_COSMETIC_EYESHADOW, {222, 192, 152}, 0.55f, 0.80f, 1.00f, 0.22f, 0.40f, 0.07f, 0.60f,
     0.0f, 0.60f, 0.0f, RS_COSMETIC_REGION_EYES},
    // Eyeliner: near-black, opaque (coverage 1: its black is not lifted to the face's darkest colour),
    // fine hard line; a matte gel liner, rho_s a sixth of skin's (a glossier one mirrors the softboxes
    // as a grey streak along it).
    {"eyeliner", RS_COSMETIC_EYELINER, {28, 22, 22}, 0.90f, 1.00f, 1.00f, 0.38f, 0.045f, 0.02f, 1.00f,
     0.0f, 0.0f, 1.00f, RS_COSMETIC_REGION_EYES},
    // Brow pencil: taupe brown, fine (a 2 mm tip: hair-like strokes along the brow), semi-opaque, matte.
    // Any region: the brows are their own region in a scan, or none.
    {"brow_pencil", RS_COSMETIC_BROW, {92, 70, 56}, 0.80f, 1.00f, 0.80f, 0.40f, 0.10f, 0.018f, 0.80f,
     0.0f, 0.0f, 0.70f, RS_COSMETIC_REGION_ANY},
    // Mascara: black, opaque, a short crisp band on the upper lash line with a faint wet sheen.
    {"mascara", RS_COSMETIC_MASCARA, {16, 14, 14}, 0.95f, 1.00f, 1.00f, 0.30f, 0.20f, 0.015f, 1.00f,
     0.0f, 0.0f, 1.00f, RS_COSMETIC_REGION_EYES},
    // Concealer: light, neutral-warm, high coverage on a small brush; matte like foundation.
    {"concealer", RS_COSMETIC_CONCEALER, {226, 190, 164}, 0.75f, 1.00f, 0.70f, 0.36f, 0.13f, 0.05f, 0.70f,
     0.0f, 0.0f, 0.75f, RS_COSMETIC_REGION_SKIN},
};

uint32_t rs_cosmetic_count(void) { return (uint32_t)RS_COUNT_OF(presets); }

const rs_cosmetic *rs_cosmetic_get(uint32_t i) { return i < RS_COUNT_OF(presets) ? &presets[i] : NULL; }

const rs_cosmetic *rs_cosmetic_find(const char *name)
{
    if (!name) return NULL;
    for (size_t i = 0; i < RS_COUNT_OF(presets); i++)
        if (strcmp(presets[i].name, name) == 0) return &presets[i];
    return NULL;
}

const char *rs_cosmetic_kind_name(rs_cosmetic_kind kind)
{
    static const char *names[RS_COSMETIC_KIND_COUNT] = {
        "custom", "foundation", "powder", "blush", "bronzer", "highlighter", "lipstick", "lip_gloss",
        "eyeshadow", "eyeliner", "brow", "mascara", "concealer",
    };
    return (unsigned)kind < RS_COSMETIC_KIND_COUNT ? names[kind] : "unknown";
}

static float clamp01(float x) { return isfinite(x) ? RS_CLAMP(x, 0.0f, 1.0f) : 0.0f; }

rs_cosmetic_region rs_cosmetic_region_of(const rs_cosmetic *c)
{
    if (c->region_mask != RS_COSMETIC_REGION_DEFAULT && (unsigned)c->region_mask < RS_COSMETIC_REGION_COUNT)
        return c->region_mask;
    switch (c->kind) {
    case RS_COSMETIC_LIPSTICK:
    case RS_COSMETIC_LIP_GLOSS: return RS_COSMETIC_REGION_LIPS;
    case RS_COSMETIC_EYESHADOW:
    case RS_COSMETIC_MASCARA:
    case RS_COSMETIC_EYELINER: return RS_COSMETIC_REGION_EYES;
    case RS_COSMETIC_CUSTOM: return RS_COSMETIC_REGION_ANY;
    default: return RS_COSMETIC_REGION_SKIN;  // base, powder, blush, bronzer, highlighter
    }
}

const char *rs_cosmetic_region_name(rs_cosmetic_region r)
{
    static const char *names[RS_COSMETIC_REGION_COUNT] = {"default", "any", "lips", "eyes", "skin"};
    return (unsigned)r < RS_COSMETIC_REGION_COUNT ? names[r] : "unknown";
}

bool rs_cosmetic_region_allows(rs_cosmetic_region r, const char *region)
{
    switch (r) {
    case RS_COSMETIC_REGION_LIPS: return strcmp(region, "lips") == 0;
    case RS_COSMETIC_REGION_EYES: return strcmp(region, "eyelid") == 0;
    case RS_COSMETIC_REGION_SKIN:
        return strcmp(region, "lips") != 0 && strcmp(region, "eyelid") != 0 && strcmp(region, "brow") != 0;
    default: return true;
    }
}

// The finish families as (m, rho_s, coat, shimmer): matte and satin from the anchors above; gloss adds a
// full clear coat to a smooth lobe; shimmer a smooth, bright lobe with flakes.
static const float finishes[RS_FINISH_COUNT][4] = {
    [RS_FINISH_MATTE] = {0.45f, 0.07f, 0.0f, 0.0f},
    [RS_FINISH_SATIN] = {0.27f, 0.28f, 0.25f, 0.0f},
    [RS_FINISH_GLOSS] = {0.12f, 0.65f, 1.0f, 0.0f},
    [RS_FINISH_SHIMMER] = {0.21f, 0.45f, 0.0f, 0.8f},
};
static const char *const finish_names[RS_FINISH_COUNT] = {"matte", "satin", "gloss", "shimmer"};

const char *rs_finish_name(rs_finish f) { return (unsigned)f < RS_FINISH_COUNT ? finish_names[f] : "unknown"; }

bool rs_finish_parse(const char *name, rs_finish *out)
{
    for (int f = 0; f < RS_FINISH_COUNT; f++)
        if (name && strcmp(name, finish_names[f]) == 0) {
            *out = (rs_finish)f;
            return true;
        }
    return false;
}

void rs_cosmetic_set_rgb(rs_cosmetic *c, const uint8_t rgb[3])
{
    memcpy(c->rgb, rgb, 3);
    if (c->colour_weight < 0.5f) c->colour_weight = 0.8f;
}

void rs_cosmetic_set_finish(rs_cosmetic *c, rs_finish f)
{
    if ((unsigned)f >= RS_FINISH_COUNT) return;
    c->m = finishes[f][0];
    c->rho_s = finishes[f][1];
    c->coat = finishes[f][2];
    c->shimmer = finishes[f][3];
    c->finish_weight = 1.0f;
}

rs_finish rs_cosmetic_finish(const rs_cosmetic *c)
{
    rs_finish best = RS_FINISH_SATIN;
    float best_d = INFINITY;
    for (int f = 0; f < RS_FINISH_COUNT; f++) {
        // rho_s and m span ~0.5 where coat and shimmer span 1: weigh them up so each axis counts alike.
        float d[4] = {2.0f * (c->m - finishes[f][0]), 2.0f * (c->rho_s - finishes[f][1]), c->coat - finishes[f][2],
                      c->shimmer - finishes[f][3]};
        float dd = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[3] * d[3];
        if (dd < best_d) best_d = dd, best = (rs_finish)f;
    }
    return best;
}

rs_cosmetic rs_cosmetic_custom(const uint8_t rgb[3], float material_weight, float m, float rho_s)
{
    // Defaults of a medium blending brush; colour and finish at full weight.
    rs_cosmetic c = {"custom", RS_COSMETIC_CUSTOM, {rgb[0], rgb[1], rgb[2]}, clamp01(material_weight),
                     1.0f, 1.0f, clamp01(m), clamp01(rho_s), 0.15f, 0.6f, 0.0f, 0.0f, 0.0f,
                     RS_COSMETIC_REGION_DEFAULT};
    return c;
}

void rs_cosmetic_hsv_to_rgb(float h_deg, float s, float v, uint8_t rgb[3])
{
    float h = isfinite(h_deg) ? fmodf(h_deg, 360.0f) : 0.0f;
    if (h < 0.0f) h += 360.0f;
    s = clamp01(s);
    v = clamp01(v);
    float c = v * s, hp = h / 60.0f;
    float x = c * (1.0f - fabsf(fmodf(hp, 2.0f) - 1.0f));
    float r = 0, g = 0, b = 0;
    switch ((int)hp) {
    case 0: r = c, g = x; break;
    case 1: r = x, g = c; break;
    case 2: g = c, b = x; break;
    case 3: g = x, b = c; break;
    case 4: r = x, b = c; break;
    default: r = c, b = x; break;
    }
    float mm = v - c;
    rgb[0] = (uint8_t)lrintf(RS_CLAMP(r + mm, 0.0f, 1.0f) * 255.0f);
    rgb[1] = (uint8_t)lrintf(RS_CLAMP(g + mm, 0.0f, 1.0f) * 255.0f);
    rgb[2] = (uint8_t)lrintf(RS_CLAMP(b + mm, 0.0f, 1.0f) * 255.0f);
}

void rs_cosmetic_rgb_to_hsv(const uint8_t rgb[3], float *h_deg, float *s, float *v)
{
    float r = rgb[0] / 255.0f, g = rgb[1] / 255.0f, b = rgb[2] / 255.0f;
    float mx = fmaxf(r, fmaxf(g, b)), mn = fminf(r, fminf(g, b)), c = mx - mn, h = 0.0f;
    if (c > 0.0f) {
        if (mx == r) h = fmodf((g - b) / c + 6.0f, 6.0f);
        else if (mx == g) h = (b - r) / c + 2.0f;
        else h = (r - g) / c + 4.0f;
    }
    *h_deg = h * 60.0f;
    *s = mx > 0.0f ? c / mx : 0.0f;
    *v = mx;
}

static bool in01(float x) { return isfinite(x) && x >= 0.0f && x <= 1.0f; }

rs_result rs_cosmetic_validate(const rs_cosmetic *c, rs_error *err)
{
    const char *end = memchr(c->name, 0, sizeof c->name);
    if (!end || end == c->name) return rs_fail(err, RS_ERR_FORMAT, "cosmetic: name empty or too long");
    for (const char *p = c->name; p < end; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_'))
            return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: name: only a-z, 0-9 and _ allowed", c->name);
    if ((unsigned)c->kind >= RS_COSMETIC_KIND_COUNT)
        return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: kind %d unknown", c->name, (int)c->kind);
    const struct { const char *field; float v; } f[] = {
        {"material_weight", c->material_weight}, {"colour_weight", c->colour_weight},
        {"finish_weight", c->finish_weight}, {"m", c->m}, {"rho_s", c->rho_s}, {"opacity", c->opacity},
        {"coat", c->coat}, {"shimmer", c->shimmer}, {"coverage", c->coverage},
    };
    for (size_t i = 0; i < RS_COUNT_OF(f); i++)
        if (!in01(f[i].v))
            return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: %s: %g, must be in [0, 1]", c->name, f[i].field,
                           f[i].v);
    if (!isfinite(c->size_rel) || !(c->size_rel > 0.0f) || c->size_rel > 1.0f)
        return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: size: %g, must be in (0, 1]", c->name, c->size_rel);
    if ((unsigned)c->region_mask >= RS_COSMETIC_REGION_COUNT)
        return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: region %d unknown", c->name, (int)c->region_mask);
    return RS_OK;
}

bool rs_cosmetic_equal(const rs_cosmetic *a, const rs_cosmetic *b)
{
    return strncmp(a->name, b->name, sizeof a->name) == 0 && a->kind == b->kind && a->rgb[0] == b->rgb[0] &&
           a->rgb[1] == b->rgb[1] && a->rgb[2] == b->rgb[2] && a->material_weight == b->material_weight &&
           a->colour_weight == b->colour_weight && a->finish_weight == b->finish_weight && a->m == b->m &&
           a->rho_s == b->rho_s && a->size_rel == b->size_rel && a->opacity == b->opacity && a->coat == b->coat &&
           a->shimmer == b->shimmer && a->coverage == b->coverage &&
           rs_cosmetic_region_of(a) == rs_cosmetic_region_of(b);
}

// --- text form ---------------------------------------------------------------------------------------

int rs_cosmetic_format(const rs_cosmetic *c, char *buf, size_t cap)
{
    const rs_cosmetic *preset = rs_cosmetic_find(c->name);
    if (preset && rs_cosmetic_equal(preset, c)) return snprintf(buf, cap, "%s", c->name);
    char finish[128] = "";
    if (c->coat != 0.0f || c->shimmer != 0.0f || c->coverage != 0.0f)
        snprintf(finish, sizeof finish, " coat=%.9g shimmer=%.9g coverage=%.9g", c->coat, c->shimmer, c->coverage);
    rs_cosmetic kind_default = *c;
    kind_default.region_mask = RS_COSMETIC_REGION_DEFAULT;
    rs_cosmetic_region region = rs_cosmetic_region_of(c);
    if (region != rs_cosmetic_region_of(&kind_default)) {
        size_t n = strlen(finish);
        snprintf(finish + n, sizeof finish - n, " region=%s", rs_cosmetic_region_name(region));
    }
    return snprintf(buf, cap,
                    "custom name=%.*s kind=%s rgb=%u,%u,%u weight=%.9g colour=%.9g finish=%.9g m=%.9g rho_s=%.9g "
                    "size=%.9g opacity=%.9g%s",
                    (int)strnlen(c->name, sizeof c->name), c->name, rs_cosmetic_kind_name(c->kind), c->rgb[0],
                    c->rgb[1], c->rgb[2], c->material_weight, c->colour_weight, c->finish_weight, c->m, c->rho_s,
                    c->size_rel, c->opacity, finish);
}

// "a,b,c" into three floats.
static bool parse_f3(const char *s, float out[3])
{
    double v[3];
    if (!rs_parse_list(s, ',', 3, -FLT_MAX, FLT_MAX, v)) return false;
    for (int k = 0; k < 3; k++) out[k] = (float)v[k];
    return true;
}

rs_result rs_cosmetic_parse(const char *text, rs_cosmetic *out, rs_error *err)
{
    char buf[512];
    size_t len = strnlen(text, sizeof buf);
    if (len == sizeof buf) return rs_fail(err, RS_ERR_FORMAT, "cosmetic: longer than %zu bytes", sizeof buf - 1);
    memcpy(buf, text, len + 1);
    char *save = NULL;
    char *tok = strtok_r(buf, " \t", &save);
    if (!tok) return rs_fail(err, RS_ERR_FORMAT, "cosmetic: missing name");
    if (strcmp(tok, "custom") != 0) {
        const rs_cosmetic *p = rs_cosmetic_find(tok);
        if (!p) return rs_fail(err, RS_ERR_FORMAT, "cosmetic: unknown preset '%.64s'", tok);
        if (strtok_r(NULL, " \t", &save))
            return rs_fail(err, RS_ERR_FORMAT, "cosmetic %s: unexpected text after a preset name", p->name);
        *out = *p;
        return RS_OK;
    }
    static const uint8_t white[3] = {255, 255, 255};
    rs_cosmetic c = rs_cosmetic_custom(white, 0.6f, 0.0f, 0.0f);
    bool have_colour = false, have_m = false, have_rho = false;
    while ((tok = strtok_r(NULL, " \t", &save)) != NULL) {
        char *eq = strchr(tok, '=');
        if (!eq) return rs_fail(err, RS_ERR_FORMAT, "cosmetic custom: '%.64s' is not key=value", tok);
        *eq = '\0';
        const char *key = tok;
        char *val = eq + 1;
        float f3[3], f = 0.0f;
        bool ok = true;
        if (strcmp(key, "name") == 0) {
            size_t n = strlen(val);
            ok = n > 0 && n < sizeof c.name;
            if (ok) {
                memset(c.name, 0, sizeof c.name);
                memcpy(c.name, val, n);
            }
        } else if (strcmp(key, "kind") == 0) {
            ok = false;
            for (int k = 0; k < RS_COSMETIC_KIND_COUNT; k++)
                if (strcmp(val, rs_cosmetic_kind_name((rs_cosmetic_kind)k)) == 0)
                    c.kind = (rs_cosmetic_kind)k, ok = true;
        } else if (strcmp(key, "region") == 0) {
            ok = false;
            for (int k = RS_COSMETIC_REGION_ANY; k < RS_COSMETIC_REGION_COUNT; k++)
                if (strcmp(val, rs_cosmetic_region_name((rs_cosmetic_region)k)) == 0)
                    c.region_mask = (rs_cosmetic_region)k, ok = true;
        } else if (strcmp(key, "rgb") == 0) {
            ok = parse_f3(val, f3);
            for (int k = 0; ok && k < 3; k++) {
                ok = f3[k] >= 0.0f && f3[k] <= 255.0f && f3[k] == floorf(f3[k]);
                if (ok) c.rgb[k] = (uint8_t)f3[k];
            }
            have_colour = true;
        } else if (strcmp(key, "hsv") == 0) {
            ok = parse_f3(val, f3) && f3[1] >= 0.0f && f3[1] <= 1.0f && f3[2] >= 0.0f && f3[2] <= 1.0f;
            if (ok) rs_cosmetic_hsv_to_rgb(f3[0], f3[1], f3[2], c.rgb);
            have_colour = true;
        } else {
            struct { const char *key; float *field; bool *seen; } fields[] = {
                {"weight", &c.material_weight, NULL}, {"colour", &c.colour_weight, NULL},
                {"finish", &c.finish_weight, NULL}, {"m", &c.m, &have_m}, {"rho_s", &c.rho_s, &have_rho},
                {"size", &c.size_rel, NULL}, {"opacity", &c.opacity, NULL}, {"coat", &c.coat, NULL},
                {"shimmer", &c.shimmer, NULL}, {"coverage", &c.coverage, NULL},
            };
            size_t k = 0;
            while (k < RS_COUNT_OF(fields) && strcmp(key, fields[k].key) != 0) k++;
            if (k == RS_COUNT_OF(fields))
                return rs_fail(err, RS_ERR_FORMAT, "cosmetic custom: unknown key '%.32s'", key);
            ok = rs_parse_float(val, &f);
            if (ok) *fields[k].field = f;
            if (ok && fields[k].seen) *fields[k].seen = true;
        }
        if (!ok) return rs_fail(err, RS_ERR_FORMAT, "cosmetic custom: %.32s: bad value '%.64s'", key, val);
    }
    if (!have_colour) return rs_fail(err, RS_ERR_FORMAT, "cosmetic custom: needs rgb= or hsv=");
    if (!have_m || !have_rho) return rs_fail(err, RS_ERR_FORMAT, "cosmetic custom: needs m= and rho_s=");
    rs_result r = rs_cosmetic_validate(&c, err);
    if (r != RS_OK) return r;
    *out = c;
    return RS_OK;
}
