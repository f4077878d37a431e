// test_makeup.c — the makeup layer (src/makeup/makeup.c): eq. 2/3 arithmetic, composition, strokes, eraser,
// undo/redo, mirror, brush sizes, spacing invariance, finishes, grid gathering. Synthetic clouds only.
#include "support/harness.h"
#include "makeup/makeup.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REQUIRE(cond) RS_REQUIRE(cond, "%s", #cond)

// ---------------------------------------------------------------------------------------------------
// Synthetic clouds

static rs_splat_header frame(float face_height)
{
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.mm_per_unit = 190.0f / face_height;
    h.face_height = face_height;
    h.forward[2] = 1.0f;
    h.up[1] = 1.0f;
    h.lod_count = 1;
    return h;
}

static rs_splat_cloud *make_cloud(rs_splat *s, uint32_t n, rs_splat_header h)
{
    h.lods[0] = n;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    if (rs_splat_create(s, n, &h, &c, &err) != RS_OK) {
        RS_CHECK(false, "rs_splat_create: %s", err.msg);
        return NULL;
    }
    return c;
}

// A square plane of side `side` at z = 0 facing +z, `k` x `k` splats, row-major. Skin colour with a
// fine two-tone texture (alternate splats differ) so the detail ratio has something to keep.
static rs_splat_cloud *plane(uint32_t k, float side)
{
    rs_splat *s = rs_alloc_array((size_t)k * k, sizeof *s);
    float step = side / (float)(k - 1);
    for (uint32_t y = 0; y < k; y++)
        for (uint32_t x = 0; x < k; x++) {
            rs_splat *p = &s[y * k + x];
            *p = (rs_splat){{-0.5f * side + step * x, -0.5f * side + step * y, 0.0f}, {0, 0, 1}, step, {0, 0, 0}, 1};
            uint8_t v = ((x + y) & 1) ? 10 : 0;
            p->rgb[0] = (uint8_t)(196 + v), p->rgb[1] = (uint8_t)(150 + v), p->rgb[2] = (uint8_t)(128 + v);
        }
    rs_splat_cloud *c = make_cloud(s, k * k, frame(1.0f));
    free(s);
    return c;
}

static rs_makeup *layer(const rs_splat_cloud *c, const rs_makeup_desc *d)
{
    rs_makeup *mk = NULL;
    rs_error err = {0};
    if (!c || rs_makeup_create(c, d, &mk, &err) != RS_OK) {
        RS_CHECK(false, "rs_makeup_create: %s", err.msg);
        return NULL;
    }
    return mk;
}

static rs_makeup_stamp_desc stamp_at(float x, float y, float size_rel, const char *cosmetic)
{
    rs_makeup_stamp_desc d = {
        .pos = {x, y, 0.0f}, .view_dir = {0, 0, 1}, .radius = 0.5f * size_rel, .opacity = 0.8f,
        .pressure = 1.0f, .cosmetic = cosmetic ? rs_cosmetic_find(cosmetic) : NULL, .eraser = cosmetic == NULL,
    };
    return d;
}

static bool stamp(rs_makeup *mk, const rs_makeup_stamp_desc *d, rs_makeup_stamp_info *info)
{
    rs_error err = {0};
    return RS_CHECK(rs_makeup_stamp(mk, d, info, &err) == RS_OK, "stamp: %s", err.msg);
}

// A stroke of stamps from (x0, y0) to (x1, y1), `step` apart (model units).
static void stroke_line(rs_makeup *mk, float x0, float y0, float x1, float y1, float step, rs_makeup_stamp_desc d)
{
    rs_error err = {0};
    float len = hypotf(x1 - x0, y1 - y0);
    uint32_t n = (uint32_t)ceilf(len / step);
    rs_makeup_begin_stroke(mk);
    for (uint32_t i = 0; i <= n; i++) {
        float u = n ? (float)i / (float)n : 0.0f;
        d.pos[0] = x0 + (x1 - x0) * u, d.pos[1] = y0 + (y1 - y0) * u;
        if (!stamp(mk, &d, NULL)) break;
    }
    RS_CHECK(rs_makeup_end_stroke(mk, &err) == RS_OK, "end_stroke: %s", err.msg);
}

static rs_makeup_gpu *snapshot(const rs_makeup *mk)
{
    size_t n = rs_makeup_count(mk);
    rs_makeup_gpu *s = rs_alloc_array(n, sizeof *s);
    memcpy(s, rs_makeup_records(mk), n * sizeof *s);
    return s;
}

static bool same_records(const rs_makeup *mk, const rs_makeup_gpu *snap)
{
    return memcmp(rs_makeup_records(mk), snap, rs_makeup_count(mk) * sizeof *snap) == 0;
}

static uint32_t painted(const rs_makeup *mk)
{
    uint32_t n = 0;
    for (uint32_t i = 0; i < rs_makeup_count(mk); i++) n += rs_makeup_records(mk)[i].colour_i > 0;
    return n;
}

static uint32_t index_near(const rs_makeup *mk, float x, float y)
{
    uint32_t idx = 0;
    RS_CHECK(rs_makeup_nearest(mk, (float[3]){x, y, 0}, 0.1f, &idx), "no splat near (%g, %g)", x, y);
    return idx;
}

static float lum(const float c[3]) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

static void base_albedo(const rs_splat_cloud *c, uint32_t i, float out[3])
{
    uint32_t w = c->packed[i].w[3];
    for (int ch = 0; ch < 3; ch++) out[ch] = rs_srgb_to_linear(((w >> (8 * ch)) & 255u) / 255.0f);
}

// ---------------------------------------------------------------------------------------------------
// Arithmetic

static void test_eq3_intensity_is_weighted_sum_at_brush_centre(void)
{
    RS_CHECK(fabsf(rs_makeup_intensity(1.0f, 0.5f, 0.25f) - (0.3f + 0.15f + 0.075f)) < 1e-6f, "centre: eq. 3");
    RS_CHECK(fabsf(rs_makeup_intensity(0.5f, 1.0f, 1.0f) - 0.45f) < 1e-6f, "footprint scales every term");
    RS_CHECK(rs_makeup_intensity(0.0f, 1.0f, 1.0f) == 0.0f, "outside the brush: no contribution");
    RS_CHECK(fabsf(rs_makeup_falloff(0.0f, 2.0f) - 1.0f) < 1e-6f, "I_G(0) = 1");
    RS_CHECK(rs_makeup_falloff(2.0f, 2.0f) == 0.0f && rs_makeup_falloff(3.0f, 2.0f) == 0.0f, "I_G = 0 from the rim");
    // sigma = radius / 2, shifted: I_G(r/2) = (e^-0.5 - e^-2) / (1 - e^-2).
    float want = (expf(-0.5f) - expf(-2.0f)) / (1.0f - expf(-2.0f));
    RS_CHECK(fabsf(rs_makeup_falloff(1.0f, 2.0f) - want) < 1e-5f, "I_G(r/2) = %g, want %g",
             rs_makeup_falloff(1.0f, 2.0f), want);
    float prev = 2.0f;
    for (int i = 0; i <= 20; i++) {
        float g = rs_makeup_falloff(0.1f * i, 2.0f);
        RS_CHECK(g <= prev, "I_G not decreasing at %d", i);
        prev = g;
    }
    RS_CHECK(rs_makeup_touch_weight(0) == 0.0f, "I_F(0) = 0");
    RS_CHECK(fabsf(rs_makeup_touch_weight(2) - (1.0f - expf(-2.0f / RS_MAKEUP_TOUCH_K))) < 1e-6f,
             "I_F(2) = 1 - e^(-2/K)");
    RS_CHECK(fabsf(rs_makeup_touch_weight(1) - (1.0f - expf(-1.0f))) < 1e-6f, "I_F(1) = 1 - e^-1 (K = 1)");
    RS_CHECK(rs_makeup_touch_weight(3) > rs_makeup_touch_weight(2), "I_F grows with touches");
}

static void test_eq2_blend_is_linear_and_zero_record_is_base(void)
{
    rs_makeup_uniforms u = {{0, 0, 0}, {1, 1, 1}};
    float base[3] = {0.5f, 0.3f, 0.2f}, c[3];
    float m = 0.27f, rho = 0.23f;
    rs_makeup_gpu zero = {0};
    memcpy(c, base, sizeof c);
    rs_makeup_apply_cpu(&zero, &u, c, &m, &rho);
    RS_CHECK(memcmp(c, base, sizeof c) == 0 && m == 0.27f && rho == 0.23f, "zero record must leave the base exactly");

    // Full intensity, detail ratio 1 (flags 128): the pigment's linear colour.
    rs_makeup_gpu full = {.rgb = {255, 0, 128}, .colour_i = 255, .flags = 128};
    memcpy(c, base, sizeof c);
    rs_makeup_apply_cpu(&full, &u, c, &m, &rho);
    RS_CHECK(fabsf(c[0] - 1.0f) < 1e-6f && c[1] == 0.0f && fabsf(c[2] - rs_srgb_to_linear(128 / 255.0f)) < 1e-6f,
             "I = 1 gives Cp: %g %g %g", c[0], c[1], c[2]);
    // Half intensity: the midpoint in linear light (eq. 2), not in sRGB.
    rs_makeup_gpu half = full;
    half.colour_i = 51;  // 0.2
    memcpy(c, base, sizeof c);
    rs_makeup_apply_cpu(&half, &u, c, &m, &rho);
    RS_CHECK(fabsf(c[0] - (0.5f * 0.8f + 1.0f * 0.2f)) < 1e-6f && fabsf(c[1] - 0.3f * 0.8f) < 1e-6f,
             "eq. 2 at I = 0.2: %g %g", c[0], c[1]);
    // The face range clamps the pigment, not the base.
    rs_makeup_uniforms narrow = {{0.1f, 0.1f, 0.1f}, {0.6f, 0.6f, 0.6f}};
    memcpy(c, base, sizeof c);
    rs_makeup_apply_cpu(&full, &narrow, c, &m, &rho);
    RS_CHECK(fabsf(c[0] - 0.6f) < 1e-6f && fabsf(c[1] - 0.1f) < 1e-6f, "pigment clamped into the range: %g %g", c[0],
             c[1]);
    // Detail ratio 0.5 halves the pigment (skin texture shows through).
    rs_makeup_gpu dark = full;
    dark.flags = 64;
    dark.rgb[0] = 128;
    memcpy(c, base, sizeof c);
    rs_makeup_apply_cpu(&dark, &u, c, &m, &rho);
    RS_CHECK(fabsf(c[0] - 0.5f * rs_srgb_to_linear(128 / 255.0f)) < 1e-6f, "detail modulates: %g", c[0]);
}

static void test_composition_of_two_products_equals_sequential_blends(void)
{
    rs_makeup_uniforms u = {{0, 0, 0}, {1, 1, 1}};
    const rs_cosmetic *a = rs_cosmetic_find("blush"), *b = rs_cosmetic_find("foundation_2");
    float amounts[][2] = {{0.3f, 0.5f}, {0.9f, 0.1f}, {0.05f, 0.7f}, {0.6f, 0.6f}};
    for (size_t t = 0; t < RS_COUNT_OF(amounts); t++) {
        rs_makeup_gpu ra = {0}, rb = ra, rab = ra;
        rs_makeup_compose(&ra, a, amounts[t][0], 128);
        rs_makeup_compose(&rb, b, amounts[t][1], 128);
        rs_makeup_compose(&rab, a, amounts[t][0], 128);
        rs_makeup_compose(&rab, b, amounts[t][1], 128);
        float seq[3] = {0.4f, 0.25f, 0.2f}, one[3] = {0.4f, 0.25f, 0.2f};
        float m1 = 0.27f, r1 = 0.23f, m2 = 0.27f, r2 = 0.23f;
        rs_makeup_apply_cpu(&ra, &u, seq, &m1, &r1);
        rs_makeup_apply_cpu(&rb, &u, seq, &m1, &r1);
        rs_makeup_apply_cpu(&rab, &u, one, &m2, &r2);
        for (int ch = 0; ch < 3; ch++)
            RS_CHECK(fabsf(seq[ch] - one[ch]) < 4e-3f, "case %zu ch %d: stacked %g vs sequential %g", t, ch, one[ch],
                     seq[ch]);
        RS_CHECK(fabsf(m1 - m2) < 4e-3f && fabsf(r1 - r2) < 4e-3f, "case %zu: finish %g/%g vs %g/%g", t, m2, r2, m1,
                 r1);
        float want_i = 1.0f - (1.0f - amounts[t][0]) * (1.0f - amounts[t][1]);
        RS_CHECK(fabsf(rab.colour_i / 255.0f - want_i) < 2.5f / 255.0f, "I' = %g, want %g", rab.colour_i / 255.0f,
                 want_i);
    }
}

static void test_foundation_shades_darken_in_order(void)
{
    rs_makeup_uniforms u = {{0, 0, 0}, {1, 1, 1}};
    float prev = 2.0f;
    for (int s = 1; s <= 3; s++) {
        char name[32];
        snprintf(name, sizeof name, "foundation_%d", s);
        rs_makeup_gpu r = {0};
        rs_makeup_compose(&r, rs_cosmetic_find(name), 0.8f, 128);
        float c[3] = {0.45f, 0.3f, 0.25f}, m = 0.27f, rho = 0.23f;
        rs_makeup_apply_cpu(&r, &u, c, &m, &rho);
        RS_CHECK(lum(c) < prev, "%s: luminance %g not darker than the previous shade %g", name, lum(c), prev);
        prev = lum(c);
    }
}

static void test_lip_gloss_raises_rho_s_lowers_m_and_keeps_colour(void)
{
    rs_makeup_uniforms u = {{0, 0, 0}, {1, 1, 1}};
    rs_makeup_gpu r = {0};
    rs_makeup_compose(&r, rs_cosmetic_find("lip_gloss"), 0.8f, 128);
    RS_CHECK(r.colour_i == 0, "lip gloss is colourless: colour_i %d", r.colour_i);
    float c[3] = {0.4f, 0.12f, 0.12f}, m = 0.28f, rho = 0.28f;
    rs_makeup_apply_cpu(&r, &u, c, &m, &rho);
    RS_CHECK(c[0] == 0.4f && c[1] == 0.12f && c[2] == 0.12f, "colour changed by a colourless gloss");
    RS_CHECK(rho > 0.28f + 0.1f && m < 0.28f - 0.05f, "gloss: rho_s %g (want up), m %g (want down)", rho, m);
}

static void test_powder_lowers_rho_s_raises_m(void)
{
    rs_makeup_uniforms u = {{0, 0, 0}, {1, 1, 1}};
    rs_makeup_gpu r = {0};
    rs_makeup_compose(&r, rs_cosmetic_find("powder"), 0.8f, 128);
    float c[3] = {0.4f, 0.3f, 0.25f}, m = 0.265f, rho = 0.265f;  // forehead, paper Table 1
    rs_makeup_apply_cpu(&r, &u, c, &m, &rho);
    RS_CHECK(rho < 0.265f - 0.1f && m > 0.265f + 0.05f, "powder: rho_s %g (want down), m %g (want up)", rho, m);
    // Highlighter does the opposite to rho_s.
    rs_makeup_gpu h = {0};
    rs_makeup_compose(&h, rs_cosmetic_find("highlighter"), 0.8f, 128);
    float m2 = 0.265f, rho2 = 0.265f;
    rs_makeup_apply_cpu(&h, &u, c, &m2, &rho2);
    RS_CHECK(rho2 > 0.265f, "highlighter: rho_s %g should rise", rho2);
}

// ---------------------------------------------------------------------------------------------------
// The layer

static void test_stamp_paints_only_within_radius_and_reports_dirty_range(void)
{
    rs_splat_cloud *c = plane(101, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(0.1f, -0.05f, 0.2f, "blush");
    rs_makeup_stamp_info info;
    REQUIRE(stamp(mk, &d, &info));
    RS_CHECK(info.touched > 0 && info.dirty.lo < info.dirty.hi, "nothing painted");
    const rs_makeup_gpu *r = rs_makeup_records(mk);
    for (uint32_t i = 0; i < rs_makeup_count(mk); i++) {
        float dx = c->pos[i][0] - 0.1f, dy = c->pos[i][1] + 0.05f;
        bool inside = dx * dx + dy * dy < d.radius * d.radius;
        bool is_painted = r[i].colour_i || r[i].spec_i;
        if (is_painted && !inside) RS_CHECK(false, "splat %u painted outside the radius", i);
        if (is_painted && (i < info.dirty.lo || i >= info.dirty.hi)) RS_CHECK(false, "splat %u outside dirty range", i);
        if (!is_painted && dx * dx + dy * dy < 0.25f * d.radius * d.radius)
            RS_CHECK(false, "splat %u near centre unpainted", i);
    }
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_brush_sizes_grow_painted_area_quadratically(void)
{
    rs_splat_cloud *c = plane(201, 1.0f);
    uint32_t area[3];
    for (int s = 0; s < 3; s++) {
        rs_makeup *mk = layer(c, NULL);
        REQUIRE(mk);
        rs_makeup_stamp_desc d = stamp_at(0.0f, 0.0f, 0.1f * (s + 1), "foundation_1");
        d.radius = rs_makeup_brush_radius(&c->hdr, 0.1f * (s + 1));
        REQUIRE(stamp(mk, &d, NULL));
        area[s] = painted(mk);
        rs_makeup_destroy(mk);
    }
    double r2 = (double)area[1] / area[0], r3 = (double)area[2] / area[0];
    RS_CHECK(area[0] < area[1] && area[1] < area[2], "areas %u %u %u not growing", area[0], area[1], area[2]);
    RS_CHECK(fabs(r2 - 4.0) < 0.4 && fabs(r3 - 9.0) < 0.9, "area ratios %.2f %.2f, want ~4 and ~9", r2, r3);
    rs_splat_destroy(c);
}

static void test_pressure_scales_opacity(void)
{
    rs_splat_cloud *c = plane(101, 1.0f);
    int got[3][2];
    rs_makeup_pressure maps[3] = {RS_MAKEUP_PRESSURE_FLOOR, RS_MAKEUP_PRESSURE_LINEAR, RS_MAKEUP_PRESSURE_NONE};
    for (int m = 0; m < 3; m++)
        for (int p = 0; p < 2; p++) {
            rs_makeup *mk = layer(c, NULL);
            REQUIRE(mk);
            rs_makeup_stamp_desc d = stamp_at(0.0f, 0.0f, 0.2f, "lipstick_matte");
            d.pressure = p ? 1.0f : 0.5f;
            d.pressure_map = maps[m];
            REQUIRE(stamp(mk, &d, NULL));
            got[m][p] = rs_makeup_records(mk)[index_near(mk, 0, 0)].colour_i;
            rs_makeup_destroy(mk);
        }
    RS_CHECK(got[0][0] < got[0][1], "floor map: half pressure %d not below full %d", got[0][0], got[0][1]);
    RS_CHECK(abs(got[0][0] - (int)lrintf(got[0][1] * 0.65f)) <= 2, "floor map at p = 0.5: %d, want 0.65 x %d",
             got[0][0], got[0][1]);
    RS_CHECK(abs(got[1][0] - (int)lrintf(got[1][1] * 0.5f)) <= 2, "linear map: %d vs %d", got[1][0], got[1][1]);
    RS_CHECK(got[2][0] == got[2][1], "no map: pressure must not matter (%d vs %d)", got[2][0], got[2][1]);
    rs_splat_destroy(c);
}

static void test_stroke_caps_gain_at_opacity_and_strokes_build_up(void)
{
    rs_splat_cloud *c = plane(101, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    uint32_t centre = index_near(mk, 0, 0);
    rs_makeup_stamp_desc d = stamp_at(0.0f, 0.0f, 0.2f, "blush");
    REQUIRE(stamp(mk, &d, NULL));
    int once = rs_makeup_records(mk)[centre].colour_i;
    rs_makeup_range r;
    REQUIRE(rs_makeup_undo(mk, &r));
    // Twenty dabs on the same spot in one stroke: no more than one.
    rs_makeup_begin_stroke(mk);
    for (int i = 0; i < 20; i++) REQUIRE(stamp(mk, &d, NULL));
    rs_error err = {0};
    REQUIRE(rs_makeup_end_stroke(mk, &err) == RS_OK);
    int capped = rs_makeup_records(mk)[centre].colour_i;
    RS_CHECK(capped == once, "20 stamps in one stroke gave I %d, one stamp %d", capped, once);
    float cap = d.opacity * 0.9f * 255.0f;
    RS_CHECK(capped <= cap + 1.0f, "stroke gain %d above opacity cap %.1f", capped, cap);
    // A second stroke adds (eq. 2 stacking) and the touch count grows.
    REQUIRE(stamp(mk, &d, NULL));
    RS_CHECK(rs_makeup_records(mk)[centre].colour_i > capped, "second stroke did not build up");
    RS_CHECK(rs_makeup_touches(mk)[centre] == 2, "touches %d, want 2 (one per stroke)", rs_makeup_touches(mk)[centre]);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_stamp_spacing_does_not_change_the_result(void)
{
    rs_splat_cloud *c = plane(151, 1.0f);
    rs_makeup *fine = layer(c, NULL), *coarse = layer(c, NULL);
    REQUIRE(fine && coarse);
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.2f, "foundation_3");
    // A slow hand (stamps 2 % of the radius apart) and a fast one (15 %).
    stroke_line(fine, -0.3f, -0.1f, 0.25f, 0.2f, 0.02f * d.radius, d);
    stroke_line(coarse, -0.3f, -0.1f, 0.25f, 0.2f, 0.15f * d.radius, d);
    const rs_makeup_gpu *a = rs_makeup_records(fine), *b = rs_makeup_records(coarse);
    int worst = 0;
    uint32_t differ = 0;
    for (uint32_t i = 0; i < rs_makeup_count(fine); i++) {
        int di = abs(a[i].colour_i - b[i].colour_i);
        worst = RS_MAX(worst, di);
        differ += di > 1;
    }
    RS_CHECK(painted(fine) > 1000, "stroke painted only %u splats", painted(fine));
    RS_CHECK(worst <= 3, "intensity differs by %d/255 between stamp spacings", worst);
    RS_CHECK(differ < painted(fine) / 10, "%u of %u splats differ by more than 1/255", differ, painted(fine));
    rs_makeup_destroy(fine);
    rs_makeup_destroy(coarse);
    rs_splat_destroy(c);
}

static void test_eraser_restores_base_exactly(void)
{
    rs_splat_cloud *c = plane(101, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.2f, "lipstick_satin");
    stroke_line(mk, -0.2f, 0.0f, 0.2f, 0.0f, 0.01f, d);
    d.cosmetic = rs_cosmetic_find("lip_gloss");
    stroke_line(mk, -0.2f, 0.05f, 0.2f, 0.05f, 0.01f, d);
    REQUIRE(painted(mk) > 0);
    // A partial erase lowers the intensity without changing the colour.
    uint32_t centre = index_near(mk, 0, 0);
    rs_makeup_gpu before = rs_makeup_records(mk)[centre];
    rs_makeup_stamp_desc e = stamp_at(0, 0, 0.2f, NULL);
    e.opacity = 0.5f;
    REQUIRE(stamp(mk, &e, NULL));
    rs_makeup_gpu after = rs_makeup_records(mk)[centre];
    RS_CHECK(after.colour_i < before.colour_i && after.colour_i > 0, "partial erase: I %d -> %d", before.colour_i,
             after.colour_i);
    RS_CHECK(memcmp(after.rgb, before.rgb, 3) == 0, "partial erase changed the colour");
    // Full erase over everything: every record zero, every touch count zero.
    e.opacity = 1.0f;
    e.radius = 0.25f;
    stroke_line(mk, -0.5f, -0.5f, 0.5f, -0.5f, 0.02f, e);
    for (float y = -0.5f; y <= 0.5f; y += 0.1f) stroke_line(mk, -0.5f, y, 0.5f, y, 0.02f, e);
    static const rs_makeup_gpu zero;
    bool all_zero = true;
    for (uint32_t i = 0; i < rs_makeup_count(mk); i++)
        all_zero &= memcmp(&rs_makeup_records(mk)[i], &zero, sizeof zero) == 0 && rs_makeup_touches(mk)[i] == 0;
    RS_CHECK(all_zero, "a full erase left makeup behind");
    // And a zero record composes to the base exactly.
    rs_makeup_uniforms u;
    rs_makeup_get_uniforms(mk, &u);
    float base[3], col[3], m = 0.3f, rho = 0.2f;
    base_albedo(c, centre, base);
    memcpy(col, base, sizeof col);
    rs_makeup_apply_cpu(&rs_makeup_records(mk)[centre], &u, col, &m, &rho);
    RS_CHECK(memcmp(col, base, sizeof col) == 0 && m == 0.3f && rho == 0.2f, "erased splat is not the base");
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_undo_redo_restore_each_level_exactly(void)
{
    rs_splat_cloud *c = plane(81, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    enum { N = 24 };
    rs_makeup_gpu *snap[N + 1];
    snap[0] = snapshot(mk);
    const char *names[] = {"foundation_2", "blush", "lip_gloss", "powder", NULL};
    for (int s = 0; s < N; s++) {
        rs_makeup_stamp_desc d = stamp_at(0, 0, 0.15f, names[s % 5]);
        if (!d.cosmetic) d.opacity = 0.6f;
        float y = -0.4f + 0.035f * s;
        stroke_line(mk, -0.3f, y, 0.3f, y + 0.1f, 0.01f, d);
        snap[s + 1] = snapshot(mk);
    }
    for (int s = N; s > 0; s--) {
        rs_makeup_range r;
        if (!RS_CHECK(rs_makeup_undo(mk, &r), "undo %d refused", s)) return;
        RS_CHECK(same_records(mk, snap[s - 1]), "undo to level %d not exact", s - 1);
    }
    RS_CHECK(!rs_makeup_undo(mk, NULL), "undo past the first stroke");
    for (int s = 1; s <= N; s++) {
        if (!RS_CHECK(rs_makeup_redo(mk, NULL), "redo %d refused", s)) return;
        RS_CHECK(same_records(mk, snap[s]), "redo to level %d not exact", s);
    }
    RS_CHECK(!rs_makeup_redo(mk, NULL), "redo past the last stroke");
    // Undo twice, paint: redo is gone, the new stroke undoes to level N-2.
    rs_makeup_undo(mk, NULL);
    rs_makeup_undo(mk, NULL);
    rs_makeup_stamp_desc d = stamp_at(0.2f, 0.2f, 0.1f, "eyeliner");
    REQUIRE(stamp(mk, &d, NULL));
    RS_CHECK(!rs_makeup_can_redo(mk), "redo survived a new stroke");
    rs_makeup_undo(mk, NULL);
    RS_CHECK(same_records(mk, snap[N - 2]), "undo after a new stroke");
    for (int s = 0; s <= N; s++) free(snap[s]);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_undo_keeps_64_levels_and_respects_the_byte_budget(void)
{
    rs_splat_cloud *c = plane(41, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    for (int s = 0; s < 70; s++) {
        rs_makeup_stamp_desc d = stamp_at(-0.4f + 0.0114f * s, 0.0f, 0.05f, "blush");
        REQUIRE(stamp(mk, &d, NULL));
    }
    int undone = 0;
    while (rs_makeup_undo(mk, NULL)) undone++;
    RS_CHECK(undone == 64, "%d undo levels, want the default 64", undone);
    rs_makeup_destroy(mk);

    // A 2 KiB budget holds only a few small strokes (but always the newest).
    mk = layer(c, &(rs_makeup_desc){.undo_bytes = 2048});
    REQUIRE(mk);
    for (int s = 0; s < 10; s++) {
        rs_makeup_stamp_desc d = stamp_at(-0.4f + 0.08f * s, 0.0f, 0.1f, "blush");
        REQUIRE(stamp(mk, &d, NULL));
    }
    undone = 0;
    while (rs_makeup_undo(mk, NULL)) undone++;
    RS_CHECK(undone >= 1 && undone < 10, "%d levels under a 2 KiB budget", undone);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_cancel_and_clear_restore_and_undo(void)
{
    rs_splat_cloud *c = plane(81, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.3f, "bronzer");
    REQUIRE(stamp(mk, &d, NULL));
    rs_makeup_gpu *one = snapshot(mk);
    rs_makeup_begin_stroke(mk);
    d.pos[0] = 0.2f;
    REQUIRE(stamp(mk, &d, NULL));
    rs_makeup_range r;
    rs_makeup_cancel_stroke(mk, &r);
    RS_CHECK(same_records(mk, one) && r.lo < r.hi, "cancel did not restore");
    RS_CHECK(!rs_makeup_can_redo(mk), "cancelled stroke became redoable");
    rs_error err = {0};
    REQUIRE(rs_makeup_clear(mk, &r, &err) == RS_OK);
    RS_CHECK(painted(mk) == 0 && r.lo < r.hi, "clear left makeup");
    RS_CHECK(rs_makeup_log_count(mk) == 0, "log after clear has %u stamps", rs_makeup_log_count(mk));
    REQUIRE(rs_makeup_undo(mk, NULL));
    RS_CHECK(same_records(mk, one), "undo of clear not exact");
    RS_CHECK(rs_makeup_log_count(mk) == 1, "log after undoing the clear: %u stamps", rs_makeup_log_count(mk));
    free(one);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// A sphere symmetric about x = 0: splat i + half is splat i mirrored.
static void test_mirror_stamp_paints_symmetrically(void)
{
    enum { HALF = 6000 };
    rs_splat *s = calloc(2 * HALF, sizeof *s);
    for (uint32_t i = 0; i < HALF; i++) {
        // Fibonacci points on the x > 0 hemisphere.
        float y = 1.0f - 2.0f * (i + 0.5f) / HALF, r = sqrtf(1.0f - y * y), phi = 2.39996323f * i;
        float x = fabsf(r * cosf(phi)) + 1e-3f, z = r * sinf(phi);
        float len = sqrtf(x * x + y * y + z * z);
        float p[3] = {0.4f * x / len, 0.4f * y / len, 0.4f * z / len};
        s[i] = (rs_splat){{p[0], p[1], p[2]}, {x / len, y / len, z / len}, 0.01f, {200, 150, 130}, 0};
        s[i + HALF] = (rs_splat){{-p[0], p[1], p[2]}, {-x / len, y / len, z / len}, 0.01f, {200, 150, 130}, 0};
    }
    rs_splat_header h = frame(1.0f);
    rs_splat_cloud *c = make_cloud(s, 2 * HALF, h);
    free(s);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    float px = 0.0f, py = 0.1f, pz = 0.0f;
    uint32_t at;
    REQUIRE(rs_makeup_nearest(mk, (float[3]){0.25f, 0.1f, 0.3f}, 0.2f, &at));
    px = c->pos[at][0], py = c->pos[at][1], pz = c->pos[at][2];
    rs_makeup_stamp_desc d = {.pos = {px, py, pz}, .view_dir = {0, 0, 1}, .radius = 0.08f, .opacity = 0.9f,
                              .pressure = 1.0f, .cosmetic = rs_cosmetic_find("blush"), .mirror = true};
    rs_makeup_stamp_info info;
    REQUIRE(stamp(mk, &d, &info));
    RS_CHECK(info.mirrored, "mirror stamp found no surface");
    const rs_makeup_gpu *r = rs_makeup_records(mk);
    uint32_t count = 0, bad = 0;
    for (uint32_t i = 0; i < HALF; i++) {
        count += r[i].colour_i > 0;
        bad += abs(r[i].colour_i - r[i + HALF].colour_i) > 1 || abs(r[i].rgb[0] - r[i + HALF].rgb[0]) > 1;
    }
    RS_CHECK(count > 20, "only %u splats painted", count);
    RS_CHECK(bad == 0, "%u mirrored pairs differ", bad);
    float q[3];
    rs_makeup_mirror_point(&c->hdr, (float[3]){0.3f, 0.2f, 0.1f}, q);
    RS_CHECK(q[0] == -0.3f && q[1] == 0.2f && q[2] == 0.1f, "mirror point (%g %g %g)", q[0], q[1], q[2]);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_facing_test_keeps_stamp_off_the_far_side(void)
{
    // Two sheets 2 mm apart (upper lip over lower lip seen edge-on): front faces +z, back faces -z.
    enum { K = 41 };
    rs_splat *s = calloc(2 * K * K, sizeof *s);
    for (uint32_t y = 0; y < K; y++)
        for (uint32_t x = 0; x < K; x++) {
            float px = -0.2f + 0.01f * x, py = -0.2f + 0.01f * y;
            s[y * K + x] = (rs_splat){{px, py, 0.0f}, {0, 0, 1}, 0.01f, {200, 120, 120}, 4};
            s[K * K + y * K + x] = (rs_splat){{px, py, -0.01f}, {0, 0, -1}, 0.01f, {200, 120, 120}, 4};
        }
    rs_splat_cloud *c = make_cloud(s, 2 * K * K, frame(1.0f));
    free(s);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.2f, "lipstick_matte");
    REQUIRE(stamp(mk, &d, NULL));
    uint32_t front = 0, back = 0;
    for (uint32_t i = 0; i < K * K; i++) front += rs_makeup_records(mk)[i].colour_i > 0;
    for (uint32_t i = K * K; i < 2 * K * K; i++) back += rs_makeup_records(mk)[i].colour_i > 0;
    RS_CHECK(front > 50 && back == 0, "front %u painted, back %u (want 0)", front, back);
    // Without a view direction both sheets take it.
    d.view_dir[2] = 0.0f;
    d.pos[0] = 0.05f;
    REQUIRE(stamp(mk, &d, NULL));
    back = 0;
    for (uint32_t i = K * K; i < 2 * K * K; i++) back += rs_makeup_records(mk)[i].colour_i > 0;
    RS_CHECK(back > 0, "facing test off, yet the back sheet is unpainted");
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// A brush pressed from the front glances off a surface turning away: a blush stroke towards a cheek's
// side must fade out there, not stop at a line (the former facing test cut it off at N.V 0.2, a hard
// edge seen from the side), and the surface facing away stays bare. A half cylinder about y (19 mm
// radius, a splat per degree), the stamp at 75 deg from the view, its reach +-60 deg.
static void test_a_stroke_fades_out_where_the_surface_turns_away(void)
{
    enum { ARC = 201, ROWS = 21 };  // -100..100 deg, y -0.05..0.05
    const float R = 0.1f, deg = 3.14159265f / 180.0f;
    rs_splat *s = calloc(ARC * ROWS, sizeof *s);
    REQUIRE(s);
    for (uint32_t y = 0; y < ROWS; y++)
        for (uint32_t a = 0; a < ARC; a++) {
            float phi = ((float)a - 100.0f) * deg, n[3] = {sinf(phi), 0.0f, cosf(phi)};
            s[y * ARC + a] = (rs_splat){{R * n[0], -0.05f + 0.005f * (float)y, R * n[2]}, {n[0], n[1], n[2]}, 0.005f,
                                        {196, 150, 128}, 1};
        }
    rs_splat_cloud *c = make_cloud(s, ARC * ROWS, frame(1.0f));
    free(s);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(R * sinf(75.0f * deg), 0.0f, 0.2f, "blush");
    d.pos[2] = R * cosf(75.0f * deg);
    d.opacity = 1.0f;
    REQUIRE(stamp(mk, &d, NULL));
    const rs_makeup_gpu *rec = rs_makeup_records(mk) + (ROWS / 2) * ARC;  // the row through the stamp
    int peak = 0, jump = 0, jump_at = 0, beyond = 0;
    for (int a = 0; a < ARC; a++) peak = RS_MAX(peak, rec[a].colour_i);
    for (int a = 1; a < ARC; a++) {
        int step = abs((int)rec[a].colour_i - (int)rec[a - 1].colour_i);
        if (step > jump) jump = step, jump_at = a - 100;
    }
    for (int a = 190; a < ARC; a++) beyond += rec[a].colour_i > 0;  // 90 deg and on: facing away
    int grazing = rec[100 + 84].colour_i;                            // N.V 0.10
    printf("# stroke towards the side: peak %d/255, largest step between splats a degree apart %d (at %d deg), "
           "%d/255 at N.V 0.10, %d splats painted facing away\n", peak, jump, jump_at, grazing, beyond);
    RS_CHECK(peak > 100, "the stamp painted %d/255 at most", peak);
    RS_CHECK(jump <= peak / 8, "the blush steps by %d/255 between neighbouring splats at %d deg (peak %d): an edge",
             jump, jump_at, peak);
    RS_CHECK(grazing > 0 && grazing < peak / 2, "at N.V 0.10 the blush is %d/255 (want a fading share of %d)",
             grazing, peak);
    RS_CHECK(beyond == 0, "%d splats facing away from the brush were painted", beyond);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_detail_keeps_skin_texture_and_range_under_foundation(void)
{
    rs_splat_cloud *c = plane(101, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.4f, "foundation_1");
    d.opacity = 1.0f;
    for (int k = 0; k < 4; k++) REQUIRE(stamp(mk, &d, NULL));  // four strokes: near full coverage
    rs_makeup_uniforms u;
    rs_makeup_get_uniforms(mk, &u);
    uint32_t a = index_near(mk, 0, 0), b = index_near(mk, 0.01f, 0);  // neighbours of the two tones
    REQUIRE(a != b);
    float ca[3], cb[3], m = 0.3f, rho = 0.2f;
    base_albedo(c, a, ca);
    base_albedo(c, b, cb);
    float base_ratio = lum(ca) / lum(cb);
    rs_makeup_apply_cpu(&rs_makeup_records(mk)[a], &u, ca, &m, &rho);
    rs_makeup_apply_cpu(&rs_makeup_records(mk)[b], &u, cb, &m, &rho);
    float made_ratio = lum(ca) / lum(cb);
    RS_CHECK(rs_makeup_records(mk)[a].colour_i > 200, "coverage only %d", rs_makeup_records(mk)[a].colour_i);
    RS_CHECK(fabsf(logf(made_ratio)) > 0.5f * fabsf(logf(base_ratio)),
             "texture flattened: tone ratio %g under foundation, %g bare", made_ratio, base_ratio);
    for (int ch = 0; ch < 3; ch++) RS_CHECK(ca[ch] <= 1.0f && cb[ch] <= 1.0f, "channel %d above 1", ch);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_gather_on_600k_splats_touches_only_nearby_cells(void)
{
    rs_splat_cloud *c = plane(775, 2.0f);  // 600,625 splats
    REQUIRE(c);
    double t0 = rs_time_now();
    rs_makeup *mk = layer(c, NULL);
    double t_create = rs_time_now() - t0;
    REQUIRE(mk);
    float sizes[3] = {0.1f, 0.2f, 0.3f};
    for (int s = 0; s < 3; s++) {
        rs_makeup_stamp_desc d = stamp_at(0.3f, -0.2f, sizes[s], "blush");
        d.radius = rs_makeup_brush_radius(&c->hdr, sizes[s]);
        rs_makeup_stamp_info info;
        enum { REPS = 20 };
        double t1 = rs_time_now();
        rs_makeup_begin_stroke(mk);
        for (int k = 0; k < REPS; k++) {
            d.pos[0] = 0.3f + 0.002f * k;
            REQUIRE(stamp(mk, &d, &info));
        }
        double us = (rs_time_now() - t1) / REPS * 1e6;
        rs_error err = {0};
        REQUIRE(rs_makeup_end_stroke(mk, &err) == RS_OK);
        printf("# stamp size %.1f on %u splats: %u touched, %u examined in %u cells, %.0f us/stamp\n", sizes[s],
               c->hdr.count, info.touched, info.examined, info.cells, us);
        RS_CHECK(info.touched > 100, "size %.1f touched %u", sizes[s], info.touched);
        RS_CHECK(info.examined < 2 * info.touched + 2000, "size %.1f examined %u for %u touched: the grid is not local",
                 sizes[s], info.examined, info.touched);
        RS_CHECK(info.examined < c->hdr.count / 20, "examined %u of %u", info.examined, c->hdr.count);
        RS_CHECK(info.dirty.hi - info.dirty.lo < c->hdr.count / 2, "dirty range spans %u",
                 info.dirty.hi - info.dirty.lo);
    }
    printf("# layer create on %u splats: %.0f ms\n", c->hdr.count, t_create * 1e3);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_nearest_respects_tolerance(void)
{
    rs_splat_cloud *c = plane(11, 1.0f);  // 0.1 apart
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    uint32_t idx = 99999;
    RS_CHECK(rs_makeup_nearest(mk, (float[3]){0.21f, -0.29f, 0.0f}, 0.05f, &idx), "no splat within 0.05");
    RS_CHECK(fabsf(c->pos[idx][0] - 0.2f) < 1e-3f && fabsf(c->pos[idx][1] + 0.3f) < 1e-3f, "wrong nearest splat");
    RS_CHECK(!rs_makeup_nearest(mk, (float[3]){0.25f, 0.25f, 0.2f}, 0.1f, &idx), "found a splat beyond tolerance");
    RS_CHECK(!rs_makeup_nearest(mk, (float[3]){9.0f, 9.0f, 9.0f}, 0.5f, &idx), "found a splat far outside the grid");
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_bad_stamps_are_refused_without_change(void)
{
    rs_splat_cloud *c = plane(21, 1.0f);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_error err = {0};
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.2f, "blush");
    d.pos[0] = NAN;
    RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_ERR_ARG, "NaN position accepted");
    d = stamp_at(0, 0, 0.2f, "blush");
    d.radius = 5.0f;
    RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_ERR_ARG, "radius beyond face height accepted");
    d = stamp_at(0, 0, 0.2f, "blush");
    d.cosmetic = NULL;
    RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_ERR_ARG, "missing cosmetic accepted");
    rs_cosmetic bad = *rs_cosmetic_find("blush");
    bad.m = NAN;
    d.cosmetic = &bad;
    RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_ERR_ARG, "NaN finish accepted");
    RS_CHECK(painted(mk) == 0 && !rs_makeup_in_stroke(mk) && !rs_makeup_can_undo(mk), "a refused stamp left traces");
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_take_dirty_gives_compact_ranges_per_lod_band(void)
{
    // A plane ordered coarse level first (every other row and column), then the rest.
    enum { K = 101 };
    rs_splat *s = calloc(K * K, sizeof *s);
    uint32_t n = 0, coarse = 0;
    for (int pass = 0; pass < 2; pass++)
        for (uint32_t y = 0; y < K; y++)
            for (uint32_t x = 0; x < K; x++) {
                bool c = x % 2 == 0 && y % 2 == 0;
                if ((pass == 0) != c) continue;
                s[n++] = (rs_splat){
                    {-0.5f + x / (K - 1.0f), -0.5f + y / (K - 1.0f), 0}, {0, 0, 1}, 0.01f, {200, 150, 130}, 1};
                coarse += c;
            }
    rs_splat_header h = frame(1.0f);
    h.lod_count = 2;
    h.lods[1] = coarse;
    h.lods[0] = n;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    REQUIRE(rs_splat_create(s, n, &h, &c, &err) == RS_OK);
    free(s);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    rs_makeup_range r[RS_MAKEUP_MAX_RANGES];
    RS_CHECK(rs_makeup_take_dirty(mk, r, RS_MAKEUP_MAX_RANGES) == 0, "fresh layer reports changes");
    rs_makeup_stamp_desc d = stamp_at(0.1f, 0.1f, 0.1f, "blush");
    rs_makeup_stamp_info info;
    REQUIRE(stamp(mk, &d, &info));
    uint32_t nr = rs_makeup_take_dirty(mk, r, RS_MAKEUP_MAX_RANGES);
    RS_REQUIRE(nr == 2, "%u ranges, want one per LOD band", nr);
    RS_CHECK(r[0].hi <= coarse && r[1].lo >= coarse, "ranges cross the band boundary");
    uint32_t spans = (r[0].hi - r[0].lo) + (r[1].hi - r[1].lo);
    RS_CHECK(spans < (info.dirty.hi - info.dirty.lo) / 2, "bands span %u, single span %u", spans,
             info.dirty.hi - info.dirty.lo);
    for (uint32_t i = 0; i < n; i++)
        if (rs_makeup_records(mk)[i].colour_i && !((i >= r[0].lo && i < r[0].hi) || (i >= r[1].lo && i < r[1].hi)))
            RS_CHECK(false, "changed record %u outside the ranges", i);
    RS_CHECK(rs_makeup_take_dirty(mk, r, RS_MAKEUP_MAX_RANGES) == 0, "ranges not forgotten after taking");
    REQUIRE(rs_makeup_undo(mk, NULL));
    nr = rs_makeup_take_dirty(mk, r, 1);
    RS_CHECK(nr == 1 && r[0].lo <= info.dirty.lo && r[0].hi >= info.dirty.hi, "undo with cap 1: one merged range");
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// Issue 15: overlapping passes build up smoothly. Two parallel foundation_3 strokes on a uniform plane,
// the second half a brush width below the first; along a path crossing both (the CPU mirror of the shader,
// sRGB luminance as displayed), the colour darkens without a step: on each side of its darkest point the
// luminance is monotone within 1/255 (a band would show as a rise inside the overlap).
static void test_overlapping_passes_build_up_without_banding(void)
{
    enum { K = 161 };
    rs_splat *pl = rs_alloc_array((size_t)K * K, sizeof *pl);
    RS_REQUIRE(pl, "out of memory");
    float side = 1.0f, step = side / (K - 1);
    for (int y = 0; y < K; y++)
        for (int x = 0; x < K; x++)
            pl[y * K + x] = (rs_splat){{-0.5f + step * x, -0.5f + step * y, 0.0f}, {0, 0, 1}, step, {214, 170, 150}, 1};
    // The face's colour range (the pigment is held in it): a dark and a light row far from the strokes.
    for (int x = 0; x < K; x++) {
        pl[x].rgb[0] = 40, pl[x].rgb[1] = 28, pl[x].rgb[2] = 24;
        pl[(K - 1) * K + x].rgb[0] = 250, pl[(K - 1) * K + x].rgb[1] = 240, pl[(K - 1) * K + x].rgb[2] = 235;
    }
    rs_splat_cloud *c = make_cloud(pl, K * K, frame(1.0f));
    free(pl);
    rs_makeup *mk = layer(c, NULL);
    if (!mk) {
        rs_splat_destroy(c);
        return;
    }
    rs_makeup_stamp_desc d = stamp_at(0, 0, 0.2f, "foundation_3");
    stroke_line(mk, -0.35f, 0.0f, 0.35f, 0.0f, 0.01f, d);
    stroke_line(mk, -0.35f, -0.05f, 0.35f, -0.05f, 0.01f, d);
    rs_makeup_uniforms u;
    rs_makeup_get_uniforms(mk, &u);
    // The column x = 0, from y = -0.3 to 0.25 (beyond both strokes' rims).
    double lum[K];
    int n = 0, darkest = 0;
    for (int y = 0; y < K; y++) {
        float yy = -0.5f + step * y;
        if (yy < -0.3f || yy > 0.25f) continue;
        uint32_t i = (uint32_t)(y * K + K / 2);
        float a[3] = {rs_srgb_to_linear(214 / 255.0f), rs_srgb_to_linear(170 / 255.0f), rs_srgb_to_linear(150 / 255.0f)};
        float m = 0.3f, r = 0.3f;
        rs_makeup_apply_cpu(&rs_makeup_records(mk)[i], &u, a, &m, &r);
        lum[n] = 255.0 * (0.2126 * rs_linear_to_srgb(a[0]) + 0.7152 * rs_linear_to_srgb(a[1]) + 0.0722 * rs_linear_to_srgb(a[2]));
        if (lum[n] < lum[darkest]) darkest = n;
        n++;
    }
    double worst = 0;
    for (int k = 1; k < n; k++) {
        double rise = k <= darkest ? lum[k] - lum[k - 1] : lum[k - 1] - lum[k];  // against the expected way
        worst = fmax(worst, rise);
    }
    printf("# two overlapping foundation passes: %.1f -> %.1f -> %.1f (sRGB luminance), worst step against "
           "the build-up %.2f/255\n", lum[0], lum[darkest], lum[n - 1], worst);
    RS_CHECK(lum[0] - lum[darkest] > 20, "the passes barely show (%.1f)", lum[0] - lum[darkest]);
    RS_CHECK(worst <= 1.0, "luminance steps %.2f/255 the wrong way: banding", worst);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// ---------------------------------------------------------------------------------------------------
// Region masks (region-aware brushes)

// A plane split down x = 0: lips on the left (x < 0), `other` on the right; 0.38 mm spacing.
static rs_splat_cloud *split_plane(void)
{
    enum { K = 201 };
    rs_splat *s = rs_alloc_array((size_t)K * K, sizeof *s);
    if (!s) return NULL;
    float side = 0.4f, step = side / (K - 1);
    for (uint32_t y = 0; y < K; y++)
        for (uint32_t x = 0; x < K; x++) {
            float px = -0.5f * side + step * x;
            s[y * K + x] = (rs_splat){{px, -0.5f * side + step * y, 0}, {0, 0, 1}, step, {196, 150, 128},
                                      px < -1e-6f ? RS_REGION_LIPS : RS_REGION_OTHER};
        }
    rs_splat_cloud *c = make_cloud(s, K * K, frame(1.0f));
    free(s);
    return c;
}

static void test_region_mask_is_zero_outside_and_rises_softly_inside(void)
{
    rs_splat_cloud *c = split_plane();
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    const uint8_t *w = NULL;
    rs_error err = {0};
    REQUIRE(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_LIPS, &w, &err) == RS_OK && w);
    float edge = RS_MAKEUP_MASK_EDGE_MM / c->hdr.mm_per_unit;
    // Along a row: 0 on the right half, rising with the distance to it on the left, 255 beyond the edge.
    int bad = 0, last = 256;
    float half_at = NAN;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        float x = c->pos[i][0];
        bool lips = x < -1e-6f;
        if (!lips) bad += w[i] != 0;
        else if (x < -edge - 0.002f) bad += w[i] != 255;  // the border is within a spacing left of x = 0
        else bad += w[i] == 0;  // inside and near the border: faded, never cut to nothing
    }
    RS_CHECK(bad == 0, "%d splats with the wrong weight", bad);
    uint32_t row = 100 * 201;  // y = 0
    for (uint32_t x = 0; x < 100; x++) {  // from the far left towards the border: non-increasing
        int v = w[row + x];
        RS_CHECK(v <= last, "weight rises again towards the border at column %u (%d after %d)", x, v, last);
        if (v >= 128) half_at = -c->pos[row + x][0] * c->hdr.mm_per_unit;  // the last one still above half
        last = v;
    }
    // smoothstep(b / edge) = 1/2 at b = edge / 2, b the distance to the first splat outside (x = 0) less
    // 0.75 of the nearest-neighbour distance (here the grid spacing).
    float spacing_mm = 0.002f * c->hdr.mm_per_unit, half_b = half_at - 0.75f * spacing_mm;
    RS_CHECK(half_b >= 0.5f * RS_MAKEUP_MASK_EDGE_MM - 1e-3f && half_b <= 0.5f * RS_MAKEUP_MASK_EDGE_MM + spacing_mm,
             "weight halves %.2f mm inside the border", half_b);
    // The same table on demand; a table without an eyelid region has no eye mask (ignored), ANY none.
    const uint8_t *again = NULL, *eyes = (const uint8_t *)1, *any = (const uint8_t *)1;
    RS_CHECK(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_LIPS, &again, &err) == RS_OK && again == w, "rebuilt");
    RS_CHECK(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_EYES, &eyes, &err) == RS_OK && eyes == NULL,
             "eye mask on a face without eyelids");
    RS_CHECK(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_ANY, &any, &err) == RS_OK && any == NULL, "any");
    // Skin is everything but lips, eyelids and brows: here the right half.
    const uint8_t *skin = NULL;
    REQUIRE(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_SKIN, &skin, &err) == RS_OK && skin);
    RS_CHECK(skin[row + 10] == 0 && skin[row + 190] == 255, "skin mask: %d left, %d right", skin[row + 10],
             skin[row + 190]);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// The lips' mask follows the lip colour and a smooth line, never leaving the region: on a plane whose
// left half is the lips region, with skin-coloured splats along its border (the region reaching onto the
// skin above a lip) and a thin red spike of lips label poking into the right half (the region's ragged
// edge), only the red part deep inside gets the brush; the skin-coloured band, the spike and everything
// outside get nothing, and the weight never rises towards the border.
static void test_lips_mask_follows_the_lip_colour_not_the_ragged_region(void)
{
    enum { K = 201 };
    rs_splat *s = rs_alloc_array((size_t)K * K, sizeof *s);
    REQUIRE(s);
    float side = 0.4f, step = side / (K - 1), band = 0.03f;  // 5.7 mm of skin colour inside the border
    for (uint32_t y = 0; y < K; y++)
        for (uint32_t x = 0; x < K; x++) {
            float px = -0.5f * side + step * x, py = -0.5f * side + step * y;
            bool spike = px > -1e-6f && px < 0.012f && fabsf(py) < 0.003f;  // 4.6 mm long, 1.1 mm wide
            bool lips = px < -1e-6f || spike;
            bool red = px < -band - 1e-6f || spike;
            s[y * K + x] = (rs_splat){{px, py, 0}, {0, 0, 1}, step, {0, 0, 0}, lips ? RS_REGION_LIPS : RS_REGION_OTHER};
            const uint8_t *rgb = red ? (const uint8_t[3]){178, 84, 92} : (const uint8_t[3]){196, 150, 128};
            memcpy(s[y * K + x].rgb, rgb, 3);
        }
    rs_splat_cloud *c = make_cloud(s, K * K, frame(1.0f));
    free(s);
    REQUIRE(c);
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    const uint8_t *w = NULL;
    rs_error err = {0};
    REQUIRE(rs_makeup_region_weights(mk, RS_COSMETIC_REGION_LIPS, &w, &err) == RS_OK && w);
    float r = RS_MAKEUP_LIP_SMOOTH_MM / c->hdr.mm_per_unit;
    int outside = 0, spike = 0, skin = 0, deep = 0;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        float x = c->pos[i][0], y = c->pos[i][1];
        bool in_spike = x > -1e-6f && x < 0.012f && fabsf(y) < 0.003f;
        if (in_spike) spike = RS_MAX(spike, (int)w[i]);
        else if (x > -1e-6f) outside += w[i] != 0;
        else if (x > -band + r) skin = RS_MAX(skin, (int)w[i]);  // skin colour farther than r from the red
        else if (x < -band - r && x > -0.5f * side + r) deep += w[i] != 255;
    }
    RS_CHECK(outside == 0, "%d splats outside the lips region carry weight", outside);
    RS_CHECK(spike <= 8, "the thin spike of the region gets weight %d", spike);
    RS_CHECK(skin == 0, "skin-coloured splats of the region get weight %d", skin);
    RS_CHECK(deep == 0, "%d splats deep in the red lips are not fully in", deep);
    uint32_t row = 50 * K;  // y = -0.1: far from the spike
    int last = 256;
    for (uint32_t x = 10; x < 100; x++) {
        RS_CHECK(w[row + x] <= last, "weight rises again towards the border at column %u", x);
        last = w[row + x];
    }
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

// A region field's weight at (x, y, z): the nearest voxel's value through the ramp (makeup_fine.glsl
// interpolates; away from the border the two agree).
static float field_weight(const rs_makeup_field *f, float x, float y, float z)
{
    float p[3] = {x, y, z};
    int v[3];
    for (int a = 0; a < 3; a++) v[a] = RS_CLAMP((int)floorf((p[a] - f->origin[a]) / f->voxel), 0, f->dim[a] - 1);
    float q = f->value[((size_t)v[2] * f->dim[1] + v[1]) * f->dim[0] + v[0]] / 255.0f;
    return RS_CLAMP((q - f->threshold) / f->band + 0.5f, 0.0f, 1.0f);
}

// rs_makeup_field_weight (the smudge's CPU copy of the shader's mask) on a 2x1x1 field, 0 | 255, cut 0.5
// band 0.2: voxel centres give 0 and 1, the midpoint the cut (0.5), outside the box the edge voxel's value,
// 60 % of the way 0.6 -> ramped (0.6 - 0.5) / 0.2 + 0.5 = 1; no field: 1 everywhere.
static void test_field_weight_interpolates_and_ramps_like_the_shader(void)
{
    uint8_t v[2] = {0, 255};
    rs_makeup_field f = {.origin = {0, 0, 0}, .voxel = 1.0f, .dim = {2, 1, 1}, .value = v, .threshold = 0.5f, .band = 0.2f};
    const float at[5][3] = {{0.5f, 0.5f, 0.5f}, {1.5f, 0.5f, 0.5f}, {1.0f, 0.5f, 0.5f}, {-3.0f, 0.5f, 0.5f}, {1.1f, 0.5f, 0.5f}};
    const float want[5] = {0.0f, 1.0f, 0.5f, 0.0f, 1.0f};
    for (int k = 0; k < 5; k++) {
        float w = rs_makeup_field_weight(&f, at[k]);
        RS_CHECK(fabsf(w - want[k]) < 1e-4f, "point %d: weight %.4f, want %.4f", k, w, want[k]);
    }
    const float p[3] = {0.7f, 0.5f, 0.5f};  // 0.2 of the way: f 0.2, ramp (0.2 - 0.5) / 0.2 + 0.5 < 0 -> 0
    RS_CHECK(rs_makeup_field_weight(&f, p) == 0.0f, "below the band: %.4f", rs_makeup_field_weight(&f, p));
    RS_CHECK(rs_makeup_field_weight(NULL, p) == 1.0f, "no field: not 1");
}

static void test_masked_stamp_paints_only_its_region_and_the_eraser_is_never_masked(void)
{
    rs_splat_cloud *c = split_plane();
    rs_makeup *mk = layer(c, NULL);
    REQUIRE(mk);
    // A lipstick dab centred on the border, kept to the lips and not. Kept to the lips it is drawn per
    // pixel (makeup.c, "Region masks per pixel"): no record changes, one fine stamp masked by the lips'
    // field, which is 1 on the lips and 0 off them.
    for (int masked = 1; masked >= 0; masked--) {
        rs_makeup_stamp_desc d = stamp_at(0.0f, 0.0f, 0.1f, "lipstick_matte");
        d.region_mask = masked;
        REQUIRE(stamp(mk, &d, NULL));
        uint32_t left = 0, right = 0;
        for (uint32_t i = 0; i < c->hdr.count; i++)
            if (rs_makeup_records(mk)[i].colour_i || rs_makeup_records(mk)[i].spec_i)
                *(c->pos[i][0] < 0 ? &left : &right) += 1;
        rs_makeup_fine_stamp *fs = NULL;
        uint32_t nf = 0;
        rs_error err = {0};
        REQUIRE(rs_makeup_fine_stamps(mk, &fs, &nf, &err) == RS_OK);
        if (masked) {
            const rs_makeup_field *f = rs_makeup_region_field(mk, RS_COSMETIC_REGION_LIPS);
            RS_CHECK(left == 0 && right == 0, "masked: %u / %u records painted (drawn per pixel)", left, right);
            RS_CHECK(nf == 1 && fs[0].region == RS_COSMETIC_REGION_LIPS, "masked: %u fine stamps, region %u", nf,
                     nf ? fs[0].region : 0);
            REQUIRE(f);
            float in = field_weight(f, -0.05f, 0.0f, 0.0f), out = field_weight(f, 0.05f, 0.0f, 0.0f);
            RS_CHECK(in == 1.0f && out == 0.0f, "the lips' field: %.2f on the lips, %.2f off them", in, out);
        } else {
            RS_CHECK(right > 100 && nf == 0, "unmasked: only %u painted off the lips, %u fine stamps", right, nf);
        }
        free(fs);
        RS_CHECK(rs_makeup_log_stamps(mk)[rs_makeup_log_count(mk) - 1].region_mask == masked, "log flag");
        if (masked) REQUIRE(rs_makeup_undo(mk, NULL));
    }
    // The eraser is never kept to a region: it cleans up wherever it goes (bleed included).
    rs_makeup_gpu *snap[2];
    for (int masked = 1; masked >= 0; masked--) {
        rs_makeup_stamp_desc e = stamp_at(0.0f, 0.0f, 0.1f, NULL);
        e.region_mask = masked;
        REQUIRE(stamp(mk, &e, NULL));
        snap[masked] = snapshot(mk);
        REQUIRE(rs_makeup_undo(mk, NULL));
    }
    RS_CHECK(memcmp(snap[0], snap[1], rs_makeup_count(mk) * sizeof *snap[0]) == 0, "a masked eraser erased less");
    free(snap[0]);
    free(snap[1]);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_eq3_intensity_is_weighted_sum_at_brush_centre);
    RS_RUN(test_field_weight_interpolates_and_ramps_like_the_shader);
    RS_RUN(test_eq2_blend_is_linear_and_zero_record_is_base);
    RS_RUN(test_composition_of_two_products_equals_sequential_blends);
    RS_RUN(test_foundation_shades_darken_in_order);
    RS_RUN(test_lip_gloss_raises_rho_s_lowers_m_and_keeps_colour);
    RS_RUN(test_powder_lowers_rho_s_raises_m);
    RS_RUN(test_stamp_paints_only_within_radius_and_reports_dirty_range);
    RS_RUN(test_brush_sizes_grow_painted_area_quadratically);
    RS_RUN(test_pressure_scales_opacity);
    RS_RUN(test_stroke_caps_gain_at_opacity_and_strokes_build_up);
    RS_RUN(test_stamp_spacing_does_not_change_the_result);
    RS_RUN(test_eraser_restores_base_exactly);
    RS_RUN(test_undo_redo_restore_each_level_exactly);
    RS_RUN(test_undo_keeps_64_levels_and_respects_the_byte_budget);
    RS_RUN(test_cancel_and_clear_restore_and_undo);
    RS_RUN(test_mirror_stamp_paints_symmetrically);
    RS_RUN(test_facing_test_keeps_stamp_off_the_far_side);
    RS_RUN(test_a_stroke_fades_out_where_the_surface_turns_away);
    RS_RUN(test_detail_keeps_skin_texture_and_range_under_foundation);
    RS_RUN(test_gather_on_600k_splats_touches_only_nearby_cells);
    RS_RUN(test_nearest_respects_tolerance);
    RS_RUN(test_bad_stamps_are_refused_without_change);
    RS_RUN(test_take_dirty_gives_compact_ranges_per_lod_band);
    RS_RUN(test_overlapping_passes_build_up_without_banding);
    RS_RUN(test_region_mask_is_zero_outside_and_rises_softly_inside);
    RS_RUN(test_lips_mask_follows_the_lip_colour_not_the_ragged_region);
    RS_RUN(test_masked_stamp_paints_only_its_region_and_the_eraser_is_never_masked);
    return rs_test_finish();
}
