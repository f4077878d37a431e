// test_strokes.c — stroke files (src/formats/strokes.c), cosmetic text (src/makeup/cosmetics.c) and the paint session
// that records and replays them (src/paint/paint.c) against a mock picker.
#include "support/harness.h"
#include "paint/paint.h"
#include "formats/strokes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define REQUIRE(cond) RS_REQUIRE(cond, "%s", #cond)

static const char *fixtures[] = {"tests/fixtures/strokes/lips.strokes", "tests/fixtures/strokes/cheek.strokes",
                                 "tests/fixtures/strokes/forehead.strokes"};

static rs_strokes *parse_text(const char *text, rs_error *err)
{
    rs_strokes *doc = NULL;
    if (rs_strokes_parse(text, strlen(text), &doc, err) != RS_OK) return NULL;
    return doc;
}

static bool docs_equal(const rs_strokes *a, const rs_strokes *b)
{
    if (a->count != b->count || a->sample_count != b->sample_count) return false;
    for (uint32_t i = 0; i < a->count; i++) {
        const rs_strokes_stroke *x = &a->strokes[i], *y = &b->strokes[i];
        if (memcmp(&x->view, &y->view, sizeof x->view) != 0 || x->brush.size_rel != y->brush.size_rel ||
            x->brush.opacity != y->brush.opacity || x->brush.pressure != y->brush.pressure ||
            x->brush.mirror != y->brush.mirror || x->brush.eraser != y->brush.eraser ||
            !rs_cosmetic_equal(&x->cosmetic, &y->cosmetic) || x->sample_count != y->sample_count ||
            x->first_sample != y->first_sample)
            return false;
    }
    return memcmp(a->samples, b->samples, a->sample_count * sizeof *a->samples) == 0;
}

// ---------------------------------------------------------------------------------------------------
// Files

static void test_committed_fixtures_parse(void)
{
    for (size_t f = 0; f < RS_COUNT_OF(fixtures); f++) {
        rs_strokes *doc = NULL;
        rs_error err = {0};
        if (!RS_CHECK(rs_strokes_load(fixtures[f], &doc, &err) == RS_OK, "%s", err.msg)) return;
        RS_CHECK(doc->count >= 1 && doc->sample_count > 20, "%s: %u strokes, %u samples", fixtures[f], doc->count,
                 doc->sample_count);
        RS_CHECK(doc->strokes[0].view.width_px == 256 && doc->strokes[0].view.height_px == 256, "%s: view size",
                 fixtures[f]);
        rs_strokes_destroy(doc);
    }
}

static void test_round_trip_is_identical(void)
{
    rs_strokes *doc = NULL;
    rs_error err = {0};
    REQUIRE(rs_strokes_create(&doc, &err) == RS_OK);
    rs_strokes_view v = {12.5f, -7.25f, 1.3f, 30.0f, 640, 480, {0.125f, -0.0625f}};  // pan round-trips too
    rs_strokes_brush b = {0.2f, 0.6f, RS_MAKEUP_PRESSURE_LINEAR, true, false, true, RS_TOOL_PAINT};
    rs_cosmetic custom = *rs_cosmetic_find("lipstick_satin");
    rs_cosmetic_hsv_to_rgb(330.0f, 0.55f, 0.8f, custom.rgb);
    snprintf(custom.name, sizeof custom.name, "my_pink");
    custom.kind = RS_COSMETIC_CUSTOM;
    custom.rho_s = 0.3141593f;
    const rs_cosmetic *cos[3] = {rs_cosmetic_find("blush"), &custom, rs_cosmetic_find("blush")};
    for (int s = 0; s < 3; s++) {
        if (s == 2) b.eraser = true, v.yaw_deg = -30.0f;
        REQUIRE(rs_strokes_begin(doc, &v, &b, cos[s], &err) == RS_OK);
        for (int k = 0; k < 10 + s; k++) {
            rs_strokes_sample sm = {0.0123457f * k, 100.1f + 3.3f * k, 50.7f - 1.1f * k, 1.0f / (k + 1)};
            REQUIRE(rs_strokes_add_sample(doc, &sm, &err) == RS_OK);
        }
        rs_strokes_end(doc);
    }
    char *text = NULL, *text2 = NULL;
    size_t len = 0, len2 = 0;
    REQUIRE(rs_strokes_write_memory(doc, &text, &len, &err) == RS_OK);
    rs_strokes *back = NULL;
    RS_CHECK(rs_strokes_parse(text, len, &back, &err) == RS_OK, "re-parse: %s", err.msg);
    if (back) {
        RS_CHECK(docs_equal(doc, back), "parsed document differs from the written one");
        REQUIRE(rs_strokes_write_memory(back, &text2, &len2, &err) == RS_OK);
        RS_CHECK(len == len2 && memcmp(text, text2, len) == 0, "second write differs");
    }
    // Through a file (atomic save).
    char path[600];
    snprintf(path, sizeof path, "%s/strokes_round_trip.strokes", rs_test_out_dir());
    REQUIRE(rs_strokes_save(doc, path, &err) == RS_OK);
    rs_strokes *loaded = NULL;
    RS_CHECK(rs_strokes_load(path, &loaded, &err) == RS_OK && docs_equal(doc, loaded), "file round trip: %s", err.msg);
    free(text);
    free(text2);
    rs_strokes_destroy(doc);
    rs_strokes_destroy(back);
    rs_strokes_destroy(loaded);
}

static void test_malformed_files_fail_with_line_and_field(void)
{
    static const char *head = "rouge-strokes 1\nview yaw=0 pitch=0 zoom=1 fov=30 size=256x256\n"
                              "brush size=0.1 opacity=0.5\ncosmetic blush\n";
    static const struct { const char *body; bool with_head; const char *want; } cases[] = {
        {"", false, "empty file"},
        {"# only a comment\n", false, "empty file"},
        {"rouge-look 1\n", false, "not a stroke file"},
        {"rouge-strokes 2\n", false, "version '2' not supported"},
        {"rouge-strokes 1 extra\n", false, "not a stroke file"},
        {"rouge-strokes -1\n", false, "version"},
        {"rouge-strokes 99999999999999999999\n", false, "version"},
        {"stroke\ns 0 1 2 1\n", true, "missing 'end'"},
        {"stroke\ns 0 1 2 1\nend\nend\n", true, "line 8: 'end' without 'stroke'"},
        {"s 0 1 2 1\n", true, "line 5: sample outside a stroke"},
        {"stroke\nend\n", true, "stroke has no samples"},
        {"stroke\nview yaw=0 pitch=0 zoom=1 fov=30 size=256x256\n", true, "inside a stroke"},
        {"stroke\ns 0 1 2\nend\n", true, "needs 4 numbers"},
        {"stroke\ns 0 1 2 1 5\nend\n", true, "more than 4 numbers"},
        {"stroke\ns 0 nan 2 1\nend\n", true, "not a finite number"},
        {"stroke\ns 0 1 inf 1\nend\n", true, "not a finite number"},
        {"stroke\ns 0 1e999 2 1\nend\n", true, "not a finite number"},
        {"stroke\ns 0 1x 2 1\nend\n", true, "not a finite number"},
        {"stroke\ns 0 1 2 1.5\nend\n", true, "pressure: 1.5"},
        {"stroke\ns 0 1 2e6 1\nend\n", true, "beyond"},
        {"stroke\ns 1 1 2 1\ns 0.5 1 2 1\nend\n", true, "line 7: sample: time: 0.5 goes back"},
        {"stroke\ns -1 1 2 1\nend\n", true, "time"},
        {"frobnicate\n", true, "unknown keyword 'frobnicate'"},
        {"brush size=0.1\n", true, "needs size= and opacity="},
        {"brush size=0 opacity=0.5\n", true, "brush: size: 0"},
        {"brush size=0.1 opacity=2\n", true, "opacity: 2"},
        {"brush size=0.1 opacity=0.5 pressure=hard\n", true, "pressure: bad value"},
        {"brush size=0.1 opacity=0.5 mirror=2\n", true, "mirror: bad value"},
        {"brush size=0.1 size=0.2 opacity=0.5\n", true, "size given twice"},
        {"brush size=0.1 opacity=0.5 colour=red\n", true, "unknown key"},
        {"brush size 0.1\n", true, "not key=value"},
        {"view yaw=0 pitch=0 zoom=1 fov=30\n", true, "missing size="},
        {"view yaw=0 pitch=100 zoom=1 fov=30 size=256x256\n", true, "pitch: 100"},
        {"view yaw=0 pitch=0 zoom=0 fov=30 size=256x256\n", true, "zoom: 0"},
        {"view yaw=0 pitch=0 zoom=1 fov=0 size=256x256\n", true, "fov: 0"},
        {"view yaw=0 pitch=0 zoom=1 fov=30 size=0x256\n", true, "size"},
        {"view yaw=0 pitch=0 zoom=1 fov=30 size=256x99999\n", true, "size"},
        {"view yaw=0 pitch=0 zoom=1 fov=30 size=256\n", true, "size"},
        {"cosmetic\n", true, "missing name"},
        {"cosmetic nail_polish\n", true, "unknown preset 'nail_polish'"},
        {"cosmetic blush extra\n", true, "unexpected text"},
        {"cosmetic custom m=0.3 rho_s=0.2\n", true, "needs rgb= or hsv="},
        {"cosmetic custom rgb=1,2,3\n", true, "needs m= and rho_s="},
        {"cosmetic custom rgb=1,2,300 m=0.3 rho_s=0.2\n", true, "rgb: bad value"},
        {"cosmetic custom rgb=1,2 m=0.3 rho_s=0.2\n", true, "rgb: bad value"},
        {"cosmetic custom rgb=1,2,3,4 m=0.3 rho_s=0.2\n", true, "rgb: bad value"},
        {"cosmetic custom rgb=1,2,3 m=3 rho_s=0.2\n", true, "m: 3"},
        {"cosmetic custom rgb=1,2,3 m=0.3 rho_s=0.2 name=Bad!\n", true, "name"},
        {"cosmetic custom hsv=10,2,1 m=0.3 rho_s=0.2\n", true, "hsv: bad value"},
        {"cosmetic custom rgb=1,2,3 m=0.3 rho_s=0.2 kind=paint\n", true, "kind: bad value"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(cases); i++) {
        char text[512];
        snprintf(text, sizeof text, "%s%s", cases[i].with_head ? head : "", cases[i].body);
        rs_error err = {0};
        rs_strokes *doc = parse_text(text, &err);
        RS_CHECK(!doc, "case %zu accepted: %s", i, cases[i].body);
        rs_strokes_destroy(doc);
        RS_CHECK(err.code == RS_ERR_FORMAT || err.code == RS_ERR_LIMIT, "case %zu: code %d", i, err.code);
        RS_CHECK(strstr(err.msg, cases[i].want) != NULL, "case %zu: message '%s' lacks '%s'", i, err.msg,
                 cases[i].want);
    }
}

static void test_hostile_sizes_are_refused(void)
{
    rs_error err = {0};
    rs_strokes *doc = NULL;
    // A line over the cap.
    char *big = malloc(4096);
    memset(big, 'x', 4095);
    big[4095] = '\0';
    memcpy(big, "rouge-strokes 1\n# ", 18);
    RS_CHECK(rs_strokes_parse(big, 4095, &doc, &err) != RS_OK && strstr(err.msg, "line 2: longer than"), "%s", err.msg);
    // A NUL byte inside a line.
    static const char nul[] = "rouge-strokes 1\nview\0 yaw=0\n";
    RS_CHECK(rs_strokes_parse(nul, sizeof nul - 1, &doc, &err) != RS_OK && strstr(err.msg, "NUL"), "%s", err.msg);
    // More strokes than the cap (4096 one-sample strokes).
    size_t cap = 200 + (RS_STROKES_MAX_STROKES + 1) * 24;
    char *many = malloc(cap);
    size_t n = (size_t)snprintf(many, cap, "rouge-strokes 1\nview yaw=0 pitch=0 zoom=1 fov=30 size=8x8\n"
                                           "brush size=0.1 opacity=1\ncosmetic blush\n");
    for (int i = 0; i <= RS_STROKES_MAX_STROKES; i++)
        n += (size_t)snprintf(many + n, cap - n, "stroke\ns 0 1 1 1\nend\n");
    RS_CHECK(rs_strokes_parse(many, n, &doc, &err) == RS_ERR_LIMIT && strstr(err.msg, "more than 4096 strokes"), "%s",
             err.msg);
    RS_CHECK(rs_strokes_parse(many, (size_t)RS_STROKES_MAX_BYTES + 1, &doc, &err) == RS_ERR_LIMIT, "size cap");
    // Windows line endings and no final newline are fine.
    static const char crlf[] =
        "rouge-strokes 1\r\nview yaw=0 pitch=0 zoom=1 fov=30 size=8x8\r\nbrush size=0.1 opacity=1\r\n"
        "cosmetic lip_gloss\r\nstroke\r\ns 0 1 1 1\r\nend";
    RS_CHECK(rs_strokes_parse(crlf, sizeof crlf - 1, &doc, &err) == RS_OK, "CRLF: %s", err.msg);
    rs_strokes_destroy(doc);
    free(big);
    free(many);
}

static void test_cosmetic_text_round_trips(void)
{
    char buf[512];
    rs_error err = {0};
    for (uint32_t i = 0; i < rs_cosmetic_count(); i++) {
        const rs_cosmetic *c = rs_cosmetic_get(i);
        RS_CHECK(rs_cosmetic_validate(c, &err) == RS_OK, "preset %s invalid: %s", c->name, err.msg);
        rs_cosmetic_format(c, buf, sizeof buf);
        RS_CHECK(strcmp(buf, c->name) == 0, "preset writes as its name, got '%s'", buf);
        rs_cosmetic back;
        RS_CHECK(rs_cosmetic_parse(buf, &back, &err) == RS_OK && rs_cosmetic_equal(&back, c), "preset %s", c->name);
    }
    rs_cosmetic c = rs_cosmetic_custom((const uint8_t[3]){10, 200, 33}, 0.45f, 0.123456789f, 0.4f);
    c.size_rel = 0.0777f;
    rs_cosmetic_format(&c, buf, sizeof buf);
    rs_cosmetic back;
    RS_CHECK(rs_cosmetic_parse(buf, &back, &err) == RS_OK && rs_cosmetic_equal(&back, &c), "custom '%s': %s", buf,
             err.msg);
    // A preset with one field changed is written in full, not by name.
    c = *rs_cosmetic_find("powder");
    c.opacity = 0.42f;
    rs_cosmetic_format(&c, buf, sizeof buf);
    RS_CHECK(strncmp(buf, "custom ", 7) == 0 && rs_cosmetic_parse(buf, &back, &err) == RS_OK &&
                 rs_cosmetic_equal(&back, &c),
             "modified preset '%s'", buf);
    RS_CHECK(rs_cosmetic_parse("custom hsv=0,1,1 m=0.3 rho_s=0.2", &back, &err) == RS_OK && back.rgb[0] == 255 &&
                 back.rgb[1] == 0 && back.rgb[2] == 0, "hsv red");
    uint8_t rgb[3];
    rs_cosmetic_hsv_to_rgb(-240.0f, 1.0f, 1.0f, rgb);
    RS_CHECK(rgb[0] == 0 && rgb[1] == 255 && rgb[2] == 0, "hsv -240 deg = green: %u %u %u", rgb[0], rgb[1], rgb[2]);
    RS_CHECK(rs_cosmetic_find("lip_gloss") && !rs_cosmetic_find("lip") && !rs_cosmetic_find(NULL),
             "find by exact name");
    RS_CHECK(rs_cosmetic_count() >= 15, "only %u presets", rs_cosmetic_count());
}

// ---------------------------------------------------------------------------------------------------
// Paint session with a mock picker: an orthographic frontal view of a plane, 256 x 256 px over
// [-0.5, 0.5]^2 (model units), face height 1.

typedef struct mock {
    const rs_splat_cloud *cloud;
    rs_makeup *mk;
    float half;  // plane half-size; outside is background
} mock;

static bool mock_pick(void *user, float x, float y, uint32_t *idx, float hit[3])
{
    mock *m = user;
    float p[3] = {x / 256.0f - 0.5f, 0.5f - y / 256.0f, 0.0f};
    if (fabsf(p[0]) > m->half || fabsf(p[1]) > m->half) return false;
    hit[0] = p[0], hit[1] = p[1], hit[2] = p[2];
    return rs_makeup_nearest(m->mk, p, 0.02f, idx);
}

static float mock_ppu(void *user, const float pos[3])
{
    (void)user, (void)pos;
    return 256.0f;
}

static void mock_dir(void *user, const float pos[3], float dir[3])
{
    (void)user, (void)pos;
    dir[0] = 0, dir[1] = 0, dir[2] = 1;
}

static rs_splat_cloud *plane(uint32_t k, float side)
{
    rs_splat *s = calloc((size_t)k * k, sizeof *s);
    float step = side / (float)(k - 1);
    for (uint32_t y = 0; y < k; y++)
        for (uint32_t x = 0; x < k; x++)
            s[y * k + x] = (rs_splat){{-0.5f * side + step * x, -0.5f * side + step * y, 0.0f}, {0, 0, 1}, step,
                                      {200, 150, 130}, 1};
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.mm_per_unit = 190.0f;
    h.face_height = 1.0f;
    h.forward[2] = 1.0f;
    h.up[1] = 1.0f;
    h.lod_count = 1;
    h.lods[0] = k * k;
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, k * k, &h, &c, &err) == RS_OK, "%s", err.msg);
    free(s);
    return c;
}

typedef struct session {
    rs_splat_cloud *cloud;
    mock m;
    rs_paint *paint;
} session;

static bool open_session_k(session *s, float half, uint32_t k)
{
    memset(s, 0, sizeof *s);
    s->cloud = plane(k, 1.0f);
    rs_error err = {0};
    if (!s->cloud || rs_makeup_create(s->cloud, NULL, &s->m.mk, &err) != RS_OK) return RS_CHECK(false, "%s", err.msg);
    s->m.cloud = s->cloud;
    s->m.half = half;
    rs_paint_picker pk = {&s->m, mock_pick, mock_ppu, mock_dir};
    return RS_CHECK(rs_paint_create(s->m.mk, &pk, &(rs_paint_desc){.input.mode = RS_INPUT_PAINT}, &s->paint, &err) ==
                        RS_OK,
                    "%s", err.msg);
}

static bool open_session(session *s, float half) { return open_session_k(s, half, 129); }

static void close_session(session *s)
{
    rs_paint_destroy(s->paint);
    rs_makeup_destroy(s->m.mk);
    rs_splat_destroy(s->cloud);
}

static void test_replayed_fixture_paints_along_its_path(void)
{
    for (size_t f = 0; f < RS_COUNT_OF(fixtures); f++) {
        session s;
        if (!open_session(&s, 0.6f)) return;
        rs_strokes *doc = NULL;
        rs_error err = {0};
        REQUIRE(rs_strokes_load(fixtures[f], &doc, &err) == RS_OK);
        double sx = 0, sy = 0;
        uint32_t ns = 0;
        for (uint32_t k = 0; k < doc->count; k++) {
            rs_paint_result res;
            REQUIRE(rs_paint_replay(s.paint, doc, k, 256, 256, &res, &err) == RS_OK);
            RS_CHECK(res.stamps > 5 && res.misses == 0 && res.dirty.lo < res.dirty.hi, "%s stroke %u: %u stamps",
                     fixtures[f], k, res.stamps);
            const rs_strokes_sample *sm = doc->samples + doc->strokes[k].first_sample;
            for (uint32_t j = 0; j < doc->strokes[k].sample_count; j++) sx += sm[j].x_px, sy += sm[j].y_px, ns++;
        }
        // The painted area's centroid (weighted by intensity, in pixels) is the stroke's.
        double px = 0, py = 0, w = 0;
        const rs_makeup_gpu *r = rs_makeup_records(s.m.mk);
        bool mirror = doc->strokes[0].brush.mirror;
        for (uint32_t i = 0; i < rs_makeup_count(s.m.mk); i++) {
            float x = (s.cloud->pos[i][0] + 0.5f) * 256.0f, y = (0.5f - s.cloud->pos[i][1]) * 256.0f;
            if (mirror && x > 128.0f) continue;  // the mirrored half, checked below
            double wi = r[i].colour_i + r[i].spec_i;
            px += wi * x, py += wi * y, w += wi;
        }
        RS_REQUIRE(w > 0, "%s painted nothing", fixtures[f]);
        px /= w, py /= w, sx /= ns, sy /= ns;
        RS_CHECK(hypot(px - sx, py - sy) < 4.0, "%s: painted centroid (%.1f, %.1f), stroke centroid (%.1f, %.1f)",
                 fixtures[f], px, py, sx, sy);
        if (mirror) {
            double mw = 0;
            for (uint32_t i = 0; i < rs_makeup_count(s.m.mk); i++)
                if ((s.cloud->pos[i][0] + 0.5f) * 256.0f > 128.0f) mw += r[i].colour_i + r[i].spec_i;
            RS_CHECK(fabs(mw - w) < 0.05 * w, "%s: mirrored side weight %.0f vs %.0f", fixtures[f], mw, w);
        }
        rs_strokes_destroy(doc);
        close_session(&s);
    }
}

static void feed(session *s, rs_input_type t, int id, float x, float y, double time, rs_paint_result *acc)
{
    rs_paint_result res;
    rs_error err = {0};
    RS_CHECK(rs_paint_feed(s->paint, &(rs_input_event){t, id, x, y, 0.8f, time}, &res, &err) == RS_OK, "%s", err.msg);
    if (acc) {
        acc->stamps += res.stamps;
        acc->misses += res.misses;
        acc->stroke_cancel |= res.stroke_cancel;
    }
}

static void test_live_strokes_replay_identically_from_their_recording(void)
{
    session live, again;
    if (!open_session(&live, 0.6f) || !open_session(&again, 0.6f)) return;
    rs_strokes *doc = NULL;
    rs_error err = {0};
    REQUIRE(rs_strokes_create(&doc, &err) == RS_OK);
    rs_strokes_view v = {0, 0, 1, 30, 256, 256, {0, 0}};
    rs_paint_set_recorder(live.paint, doc, &v);
    rs_paint_brush b = {.cosmetic = *rs_cosmetic_find("blush"), .size_rel = 0.1f, .mirror = true};
    rs_paint_set_brush(live.paint, &b);
    feed(&live, RS_INPUT_DOWN, 5, 60, 100, 0.0, NULL);
    for (int i = 1; i < 30; i++) {
        feed(&live, RS_INPUT_MOVE, 5, 60 + 2.0f * i, 100 + 20 * sinf(0.2f * i), i / 60.0, NULL);
        if (i == 10) rs_paint_set_recorder(live.paint, doc, &v);  // a view update must not drop the stroke
    }
    feed(&live, RS_INPUT_UP, 5, 120, 100, 0.5, NULL);
    b.cosmetic = *rs_cosmetic_find("lip_gloss");
    b.mirror = false;
    rs_paint_set_brush(live.paint, &b);
    feed(&live, RS_INPUT_DOWN, 6, 100, 200, 1.0, NULL);
    feed(&live, RS_INPUT_MOVE, 6, 150, 190, 1.1, NULL);
    feed(&live, RS_INPUT_UP, 6, 160, 190, 1.2, NULL);
    // A stroke cancelled by a second finger is neither painted nor recorded.
    feed(&live, RS_INPUT_DOWN, 7, 30, 30, 2.0, NULL);
    feed(&live, RS_INPUT_MOVE, 7, 40, 30, 2.1, NULL);
    feed(&live, RS_INPUT_DOWN, 8, 90, 30, 2.2, NULL);
    feed(&live, RS_INPUT_UP, 8, 90, 30, 2.3, NULL);
    feed(&live, RS_INPUT_UP, 7, 40, 30, 2.3, NULL);
    rs_paint_set_recorder(live.paint, NULL, NULL);
    RS_CHECK(doc->count == 2, "recorded %u strokes, want 2", doc->count);
    for (uint32_t k = 0; k < doc->count; k++) {
        rs_paint_result res;
        REQUIRE(rs_paint_replay(again.paint, doc, k, 256, 256, &res, &err) == RS_OK);
    }
    RS_CHECK(memcmp(rs_makeup_records(live.m.mk), rs_makeup_records(again.m.mk),
                    rs_makeup_count(live.m.mk) * sizeof(rs_makeup_gpu)) == 0, "replay differs from the live strokes");
    RS_CHECK(rs_makeup_records(live.m.mk)[0].colour_i == 0, "cancelled stroke left paint at the corner");
    // Undo in the live layer goes stroke by stroke.
    int undos = 0;
    while (rs_makeup_undo(live.m.mk, NULL)) undos++;
    RS_CHECK(undos == 2, "%d undo levels after two strokes", undos);
    rs_strokes_destroy(doc);
    close_session(&live);
    close_session(&again);
}

static void test_background_stamps_nothing_and_view_mode_paints_nothing(void)
{
    session s;
    if (!open_session(&s, 0.2f)) return;
    rs_paint_result acc = {0};
    // From the background across the plane's edge: the background part misses.
    feed(&s, RS_INPUT_DOWN, 1, 10, 128, 0.0, &acc);
    for (int i = 1; i <= 20; i++) feed(&s, RS_INPUT_MOVE, 1, 10 + 6.0f * i, 128, i / 60.0, &acc);
    feed(&s, RS_INPUT_UP, 1, 130, 128, 0.4, &acc);
    RS_CHECK(acc.misses > 0 && acc.stamps > 0, "misses %u, stamps %u", acc.misses, acc.stamps);
    uint32_t painted = 0;
    for (uint32_t i = 0; i < rs_makeup_count(s.m.mk); i++) painted += rs_makeup_records(s.m.mk)[i].colour_i > 0;
    rs_paint_set_mode(s.paint, RS_INPUT_VIEW);
    rs_paint_result res;
    rs_error err = {0};
    REQUIRE(rs_paint_feed(s.paint, &(rs_input_event){RS_INPUT_DOWN, 2, 128, 128, 1, 1.0}, &res, &err) == RS_OK);
    REQUIRE(rs_paint_feed(s.paint, &(rs_input_event){RS_INPUT_MOVE, 2, 140, 120, 1, 1.1}, &res, &err) == RS_OK);
    RS_CHECK(res.stamps == 0 && res.orbit_dx_px == 12.0f && res.orbit_dy_px == -8.0f,
             "view mode: %u stamps, orbit %g %g", res.stamps, res.orbit_dx_px, res.orbit_dy_px);
    REQUIRE(rs_paint_feed(s.paint, &(rs_input_event){RS_INPUT_UP, 2, 140, 120, 1, 1.2}, &res, &err) == RS_OK);
    uint32_t after = 0;
    for (uint32_t i = 0; i < rs_makeup_count(s.m.mk); i++) after += rs_makeup_records(s.m.mk)[i].colour_i > 0;
    RS_CHECK(painted > 0 && after == painted, "view mode changed the layer (%u -> %u)", painted, after);
    close_session(&s);
}

static void test_hand_speed_and_event_rate_do_not_change_the_layer(void)
{
    // The same curve drawn slowly with a 240 Hz pen and quickly with a 60 Hz mouse.
    // A plane dense enough (0.67 px apart) that snapping stamps to picked splats does not dominate.
    session a, b;
    if (!open_session_k(&a, 0.6f, 385) || !open_session_k(&b, 0.6f, 385)) return;
    rs_paint_brush br = {.cosmetic = *rs_cosmetic_find("foundation_3"), .size_rel = 0.12f, .opacity = 0.7f,
                         .pressure = RS_MAKEUP_PRESSURE_NONE};
    rs_paint_set_brush(a.paint, &br);
    rs_paint_set_brush(b.paint, &br);
    session *s[2] = {&a, &b};
    double rate[2] = {240.0, 60.0}, duration[2] = {2.0, 0.25};
    for (int k = 0; k < 2; k++) {
        int n = (int)(rate[k] * duration[k]);
        for (int i = 0; i <= n; i++) {
            float u = (float)i / n, x = 60 + 140 * u, y = 128 + 40 * sinf(5 * u);
            rs_input_type t = i == 0 ? RS_INPUT_DOWN : i == n ? RS_INPUT_UP : RS_INPUT_MOVE;
            feed(s[k], t, 1, x, y, i / rate[k], NULL);
        }
    }
    // Both strokes follow the curve to within about a pixel (the 60 Hz polyline alone is off by ~1 px at
    // the crests), and a pixel is 7 % of this brush's radius: compare what the stroke deposits (amount,
    // area, place), not splat by splat.
    const rs_makeup_gpu *r[2] = {rs_makeup_records(a.m.mk), rs_makeup_records(b.m.mk)};
    double sum[2] = {0, 0}, cx[2] = {0, 0}, cy[2] = {0, 0};
    uint32_t area[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        for (uint32_t i = 0; i < rs_makeup_count(a.m.mk); i++) {
            double w = r[k][i].colour_i;
            sum[k] += w;
            area[k] += w > 0;
            cx[k] += w * (a.cloud->pos[i][0] + 0.5) * 256.0;
            cy[k] += w * (0.5 - a.cloud->pos[i][1]) * 256.0;
        }
        cx[k] /= sum[k], cy[k] /= sum[k];
    }
    RS_CHECK(area[0] > 5000, "painted %u", area[0]);
    RS_CHECK(fabs(sum[1] / sum[0] - 1.0) < 0.03, "deposit differs: %.0f vs %.0f", sum[1], sum[0]);
    RS_CHECK(fabs((double)area[1] / area[0] - 1.0) < 0.03, "area differs: %u vs %u", area[1], area[0]);
    RS_CHECK(hypot(cx[1] - cx[0], cy[1] - cy[0]) < 1.0, "centroids (%.1f %.1f) vs (%.1f %.1f)", cx[1], cy[1], cx[0],
             cy[0]);
    close_session(&a);
    close_session(&b);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_committed_fixtures_parse);
    RS_RUN(test_round_trip_is_identical);
    RS_RUN(test_malformed_files_fail_with_line_and_field);
    RS_RUN(test_hostile_sizes_are_refused);
    RS_RUN(test_cosmetic_text_round_trips);
    RS_RUN(test_replayed_fixture_paints_along_its_path);
    RS_RUN(test_live_strokes_replay_identically_from_their_recording);
    RS_RUN(test_background_stamps_nothing_and_view_mode_paints_nothing);
    RS_RUN(test_hand_speed_and_event_rate_do_not_change_the_layer);
    return rs_test_finish();
}
