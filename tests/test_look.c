// test_look.c — look files (src/formats/look.c): save/load round trip, loading on another LOD, hostile input.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "formats/look.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REQUIRE(cond) RS_REQUIRE(cond, "%s", #cond)

// A plane of k x k splats over [-0.5, 0.5]^2 facing +z, face height 1, a smooth colour gradient. With
// `lod` the splats are ordered coarse first (every other row and column), so the first quarter is a
// spatially uniform LOD prefix, as the converter orders real faces.
static rs_splat *plane_splats(uint32_t k, bool lod, uint32_t *coarse)
{
    rs_splat *s = calloc((size_t)k * k, sizeof *s);
    uint32_t n = 0;
    for (int pass = 0; pass < (lod ? 2 : 1); pass++)
        for (uint32_t y = 0; y < k; y++)
            for (uint32_t x = 0; x < k; x++) {
                bool is_coarse = (x % 2 == 0) && (y % 2 == 0);
                if (lod && (pass == 0) != is_coarse) continue;
                float px = -0.5f + (float)x / (k - 1), py = -0.5f + (float)y / (k - 1);
                // Lips below y = -0.2 (a region mask has a border to keep to), cheek elsewhere.
                s[n++] = (rs_splat){{px, py, 0.0f}, {0, 0, 1}, 1.0f / (k - 1),
                                    {(uint8_t)(190 + 30 * px), (uint8_t)(145 + 20 * py), 125},
                                    py < -0.2f ? RS_REGION_LIPS : RS_REGION_CHEEK};
            }
    if (coarse) *coarse = ((k + 1) / 2) * ((k + 1) / 2);
    return s;
}

static rs_splat_cloud *cloud_of(const rs_splat *s, uint32_t n, uint32_t lod1)
{
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.mm_per_unit = 190.0f;
    h.face_height = 1.0f;
    h.forward[2] = 1.0f;
    h.up[1] = 1.0f;
    h.lod_count = lod1 ? 2 : 1;
    h.lods[0] = n;
    h.lods[1] = lod1;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, n, &h, &c, &err) == RS_OK, "%s", err.msg);
    return c;
}

static rs_makeup *layer(const rs_splat_cloud *c)
{
    rs_makeup *mk = NULL;
    rs_error err = {0};
    if (!c || rs_makeup_create(c, NULL, &mk, &err) != RS_OK) RS_CHECK(false, "%s", err.msg);
    return mk;
}

static void line(rs_makeup *mk, float x0, float y0, float x1, float y1, rs_makeup_stamp_desc d)
{
    rs_error err = {0};
    rs_makeup_begin_stroke(mk);
    for (int i = 0; i <= 20; i++) {
        d.pos[0] = x0 + (x1 - x0) * i / 20.0f, d.pos[1] = y0 + (y1 - y0) * i / 20.0f;
        d.pressure = 0.5f + 0.025f * i;
        RS_CHECK(rs_makeup_stamp(mk, &d, NULL, &err) == RS_OK, "%s", err.msg);
    }
    RS_CHECK(rs_makeup_end_stroke(mk, &err) == RS_OK, "%s", err.msg);
}

// A session with everything a look must carry: presets, a custom product, pressure, mirror, eraser,
// an undone stroke, a clear before the final strokes, and (with `masked`) a stroke kept to the lips
// across their border. (Region masks are rebuilt per cloud, so a masked stroke's fade differs per splat
// on a coarser LOD; test_paint_render bounds that on the rendered face.)
static void paint_session(rs_makeup *mk, bool masked)
{
    rs_error err = {0};
    rs_makeup_stamp_desc d = {.view_dir = {0, 0, 1}, .radius = 0.06f, .opacity = 0.7f,
                              .cosmetic = rs_cosmetic_find("bronzer")};
    line(mk, -0.3f, 0.3f, 0.3f, 0.3f, d);
    RS_CHECK(rs_makeup_clear(mk, NULL, &err) == RS_OK, "%s", err.msg);
    d.cosmetic = rs_cosmetic_find("foundation_2");
    d.radius = 0.15f;
    line(mk, -0.3f, 0.0f, 0.3f, 0.1f, d);
    d.cosmetic = rs_cosmetic_find("lip_gloss");
    d.radius = 0.04f;
    line(mk, -0.1f, -0.3f, 0.1f, -0.3f, d);
    if (masked) {
        d.cosmetic = rs_cosmetic_find("lipstick_matte");
        d.region_mask = true;
        line(mk, 0.0f, -0.1f, 0.0f, -0.35f, d);
        d.region_mask = false;
    }
    static rs_cosmetic custom;
    custom = rs_cosmetic_custom((const uint8_t[3]){150, 40, 140}, 0.55f, 0.31f, 0.17f);
    d.cosmetic = &custom;
    d.mirror = true;
    d.radius = 0.05f;
    line(mk, 0.15f, -0.1f, 0.3f, -0.2f, d);
    d.mirror = false;
    d.cosmetic = NULL;
    d.eraser = true;
    d.opacity = 0.8f;
    line(mk, -0.2f, 0.05f, 0.2f, 0.05f, d);
    d.eraser = false;
    d.cosmetic = rs_cosmetic_find("eyeliner");
    line(mk, -0.4f, 0.4f, 0.4f, 0.4f, d);
    rs_makeup_undo(mk, NULL);  // the eyeliner is undone: not part of the look
}

static bool same_layers(const rs_makeup *a, const rs_makeup *b)
{
    return rs_makeup_count(a) == rs_makeup_count(b) &&
           memcmp(rs_makeup_records(a), rs_makeup_records(b), rs_makeup_count(a) * sizeof(rs_makeup_gpu)) == 0 &&
           memcmp(rs_makeup_touches(a), rs_makeup_touches(b), rs_makeup_count(a)) == 0;
}

static void test_look_round_trip_is_identical(void)
{
    uint32_t k = 121;
    rs_splat *s = plane_splats(k, false, NULL);
    rs_splat_cloud *c = cloud_of(s, k * k, 0);
    free(s);
    rs_makeup *mk = layer(c), *other = layer(c);
    REQUIRE(mk && other);
    paint_session(mk, true);
    rs_error err = {0};
    char *text = NULL;
    size_t len = 0;
    REQUIRE(rs_look_write_memory(mk, &text, &len, &err) == RS_OK);
    rs_look *look = NULL;
    if (!RS_CHECK(rs_look_parse(text, len, &look, &err) == RS_OK, "%s", err.msg)) return;
    RS_CHECK(look->cosmetic_count >= 3 && look->stamp_count > 60, "%u cosmetics, %u stamps", look->cosmetic_count,
             look->stamp_count);
    RS_CHECK(strstr(text, " mask\n") != NULL, "the masked stroke's stamps are not marked in the text");
    rs_makeup_range dirty;
    REQUIRE(rs_look_apply(look, other, &dirty, &err) == RS_OK);
    RS_CHECK(same_layers(mk, other), "replayed look differs from the painted layer");
    RS_CHECK(dirty.lo == 0 && dirty.hi == rs_makeup_count(other), "dirty range of a load must cover the layer");
    RS_CHECK(!rs_makeup_can_undo(other), "a loaded look must start a fresh undo history");
    // Through a file, and saving the loaded look again gives the same text.
    char path[600];
    snprintf(path, sizeof path, "%s/look_round_trip.look", rs_test_out_dir());
    REQUIRE(rs_look_save(other, path, &err) == RS_OK);
    rs_makeup *third = layer(c);
    RS_CHECK(rs_look_load(third, path, &dirty, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(same_layers(mk, third), "look loaded from a file differs");
    char *text2 = NULL;
    size_t len2 = 0;
    REQUIRE(rs_look_write_memory(third, &text2, &len2, &err) == RS_OK);
    RS_CHECK(len == len2 && memcmp(text, text2, len) == 0, "re-saved look text differs");
    // The atomic write leaves no temporary behind.
    DIR *dir = opendir(rs_test_out_dir());
    struct dirent *e;
    bool tmp = false;
    while (dir && (e = readdir(dir)) != NULL) tmp |= strstr(e->d_name, "look_round_trip.look.tmp") != NULL;
    if (dir) closedir(dir);
    RS_CHECK(!tmp, "temporary file left next to the look");
    free(text);
    free(text2);
    rs_look_destroy(look);
    rs_makeup_destroy(mk);
    rs_makeup_destroy(other);
    rs_makeup_destroy(third);
    rs_splat_destroy(c);
}

static void test_look_made_on_full_cloud_loads_on_lod_prefix(void)
{
    uint32_t k = 161, coarse = 0;
    rs_splat *s = plane_splats(k, true, &coarse);
    rs_splat_cloud *full = cloud_of(s, k * k, coarse), *prefix = cloud_of(s, coarse, 0);
    free(s);
    rs_makeup *mk = layer(full), *small = layer(prefix);
    REQUIRE(mk && small);
    paint_session(mk, false);
    rs_error err = {0};
    char path[600];
    snprintf(path, sizeof path, "%s/look_lod.look", rs_test_out_dir());
    REQUIRE(rs_look_save(mk, path, &err) == RS_OK);
    RS_CHECK(rs_look_load(small, path, NULL, &err) == RS_OK, "%s", err.msg);
    rs_makeup_uniforms ua, ub;
    rs_makeup_get_uniforms(mk, &ua);
    rs_makeup_get_uniforms(small, &ub);
    float worst = 0.0f, worst_spec = 0.0f;
    uint32_t painted = 0;
    for (uint32_t i = 0; i < coarse; i++) {
        // Same splat (same position) in both clouds: compose the makeup over the same base.
        float a[3], b[3], ma = 0.27f, mb = 0.27f, ra = 0.23f, rb = 0.23f;
        uint32_t w = full->packed[i].w[3];
        for (int ch = 0; ch < 3; ch++) a[ch] = b[ch] = rs_srgb_to_linear(((w >> (8 * ch)) & 255u) / 255.0f);
        rs_makeup_apply_cpu(&rs_makeup_records(mk)[i], &ua, a, &ma, &ra);
        rs_makeup_apply_cpu(&rs_makeup_records(small)[i], &ub, b, &mb, &rb);
        for (int ch = 0; ch < 3; ch++) worst = fmaxf(worst, fabsf(a[ch] - b[ch]));
        worst_spec = fmaxf(worst_spec, fmaxf(fabsf(ma - mb), fabsf(ra - rb)));
        painted += rs_makeup_records(mk)[i].colour_i > 0;
    }
    RS_CHECK(painted > 100, "only %u prefix splats painted", painted);
    RS_CHECK(worst < 0.01f, "colour differs by %g (linear) between LODs", worst);
    RS_CHECK(worst_spec < 0.01f, "finish differs by %g between LODs", worst_spec);
    rs_makeup_destroy(mk);
    rs_makeup_destroy(small);
    rs_splat_destroy(full);
    rs_splat_destroy(prefix);
}

static void test_look_for_another_face_is_refused(void)
{
    uint32_t k = 41;
    rs_splat *s = plane_splats(k, false, NULL);
    rs_splat_cloud *c = cloud_of(s, k * k, 0);
    free(s);
    rs_makeup *mk = layer(c);
    REQUIRE(mk);
    static const char text[] =
        "rouge-look 1\nface height=1.5\ncosmetic 0 blush\nstroke\np 0 0 0 0 0 1 0.1 0.5 0\nend\n";
    rs_look *look = NULL;
    rs_error err = {0};
    REQUIRE(rs_look_parse(text, sizeof text - 1, &look, &err) == RS_OK);
    RS_CHECK(rs_look_apply(look, mk, NULL, &err) == RS_ERR_ARG && strstr(err.msg, "another face"), "%s", err.msg);
    rs_look_destroy(look);
    rs_makeup_destroy(mk);
    rs_splat_destroy(c);
}

static void test_malformed_looks_fail_with_line_and_field(void)
{
    static const char *head = "rouge-look 1\nface height=1\ncosmetic 0 blush\n";
    static const struct { const char *body; bool with_head; const char *want; } cases[] = {
        {"", false, "empty file"},
        {"rouge-strokes 1\n", false, "not a look file"},
        {"rouge-look 7\n", false, "version '7' not supported"},
        {"rouge-look 1\n", false, "missing the 'face' line"},
        {"rouge-look 1\nstroke\n", false, "stroke before the 'face' line"},
        {"rouge-look 1\nface height=0\n", false, "face: expected height"},
        {"rouge-look 1\nface height=nan\n", false, "face: expected height"},
        {"rouge-look 1\nface height=1\nface height=1\n", false, "given twice"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5 0\n", true, "file ends inside a stroke"},
        {"p 0 0 0 0 0 1 0.1 0.5 0\n", true, "line 4: stamp outside a stroke"},
        {"stroke\nend\n", true, "stroke has no stamps"},
        {"end\n", true, "'end' without 'stroke'"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5\nend\n", true, "missing cosmetic index"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5 1\nend\n", true, "not a defined cosmetic index"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5 -1\nend\n", true, "not a defined cosmetic index"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5 0 9\nend\n", true, "unexpected text"},
        {"stroke\np 0 0 0 0 0 1 0.1 0.5 0 mask 9\nend\n", true, "unexpected text"},
        {"stroke\ne 0 0 0 0 0 1 0.1 0.5 mask\nend\n", true, "unexpected text"},
        {"stroke\np 0 0 0 0 0 1 0 0.5 0\nend\n", true, "radius: 0"},
        {"stroke\np 0 0 0 0 0 1 0.1 1.5 0\nend\n", true, "amount: 1.5"},
        {"stroke\np 0 nan 0 0 0 1 0.1 0.5 0\nend\n", true, "y: 'nan'"},
        {"stroke\np 0 0 1e30 0 0 1 0.1 0.5 0\nend\n", true, "z: '1e30'"},
        {"stroke\ne 0 0 0 0 0 1 0.1\nend\n", true, "missing amount"},
        {"stroke\nq 0 0 0\nend\n", true, "inside a stroke"},
        {"cosmetic 0 blush\n", true, "index must be 1"},
        {"cosmetic 1\n", true, "missing definition"},
        {"cosmetic 1 custom rgb=1,2,3\n", true, "needs m= and rho_s="},
        {"cosmetic 99999999999 blush\n", true, "index must be 1"},
        {"glitter\n", true, "unknown keyword 'glitter'"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        char text[512];
        snprintf(text, sizeof text, "%s%s", cases[i].with_head ? head : "", cases[i].body);
        rs_error err = {0};
        rs_look *look = NULL;
        RS_CHECK(rs_look_parse(text, strlen(text), &look, &err) != RS_OK, "case %zu accepted", i);
        rs_look_destroy(look);
        RS_CHECK(strstr(err.msg, cases[i].want) != NULL, "case %zu: message '%s' lacks '%s'", i, err.msg,
                 cases[i].want);
    }
    rs_look *look = NULL;
    rs_error err = {0};
    RS_CHECK(rs_look_parse("x", (size_t)RS_LOOK_MAX_BYTES + 1, &look, &err) == RS_ERR_LIMIT, "size cap");
    static const char nul[] = "rouge-look 1\nface\0 height=1\n";
    RS_CHECK(rs_look_parse(nul, sizeof nul - 1, &look, &err) != RS_OK && strstr(err.msg, "line 2: NUL"), "%s", err.msg);
    RS_CHECK(rs_look_load(NULL, "tests/fixtures/strokes/does-not-exist.look", NULL, &err) == RS_ERR_IO,
             "missing file: %s", err.msg);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_look_round_trip_is_identical);
    RS_RUN(test_look_made_on_full_cloud_loads_on_lod_prefix);
    RS_RUN(test_look_for_another_face_is_refused);
    RS_RUN(test_malformed_looks_fail_with_line_and_field);
    return rs_test_finish();
}
