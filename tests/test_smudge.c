// test_smudge.c — the smudge and blend tools (src/makeup/smudge.c) through the public face: a smudge
// across a lipstick edge carries the colour along the drag, fading; a blend widens a hard edge's ramp
// without changing how much product there is by much; a smudged liner (the per-pixel fine layer) moves
// too; recorded strokes and saved looks replay to the same picture; a bad tool is refused clearly.
// Pictures go to RS_TEST_OUT (or build/test-out) for people to look at.
#include "support/harness.h"
#include "gl/gl.h"
#include "rouge.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define FACE_PATH "assets/face.rsf"
#define W 512
#define H 512

static rouge_face *face;

static bool render(uint8_t *out)
{
    rouge_error e = {0};
    return rouge_face_render(face, &e) == ROUGE_OK && rouge_face_read_rgba(face, out, (size_t)W * H * 4, &e) == ROUGE_OK;
}

static void save(const char *name, const uint8_t *rgba)
{
    rs_image img = {.width = W, .height = H, .channels = 4, .pixels = (uint8_t *)rgba};
    rs_test_save(name, &img);
}

// A straight drag; returns the stamps it laid.
static uint32_t stroke(float x0, float y0, float x1, float y1, int steps)
{
    rouge_error e = {0};
    rouge_pointer_result res;
    uint32_t stamps = 0;
    for (int i = 0; i <= steps; i++) {
        float t = (float)i / (float)steps;
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : ROUGE_POINTER_MOVE, 0, x0 + (x1 - x0) * t,
                                  y0 + (y1 - y0) * t, 1.0f, i / 60.0};
        if (rouge_face_pointer(face, &ev, &res, &e) == ROUGE_OK) stamps += res.stamps;
    }
    rouge_pointer_event up = {ROUGE_POINTER_UP, 0, x1, y1, 1.0f, (steps + 1) / 60.0};
    if (rouge_face_pointer(face, &up, &res, &e) == ROUGE_OK) stamps += res.stamps;
    return stamps;
}


static uint8_t *bare;  // the bare face, albedo view

static const uint8_t *px(const uint8_t *img, int x, int y) { return img + ((size_t)y * W + x) * 4; }

// How far a pixel went from the bare skin towards `ink` (1 = the ink's colour), along the bare-ink line.
static double cover(const uint8_t *img, int x, int y, const double ink[3])
{
    const uint8_t *b = px(bare, x, y), *p = px(img, x, y);
    double num = 0, den = 0;
    for (int c = 0; c < 3; c++) num += (p[c] - b[c]) * (ink[c] - b[c]), den += (ink[c] - b[c]) * (ink[c] - b[c]);
    return den > 1.0 ? num / den : 0.0;
}

static void ink_at(const uint8_t *img, int x, int y, double ink[3])
{
    for (int c = 0; c < 3; c++) ink[c] = px(img, x, y)[c];
}

static bool set_brush(const rouge_brush *b)
{
    rouge_error e = {0};
    return RS_CHECK(rouge_face_set_brush(face, b, &e) == ROUGE_OK, "brush: %s", e.msg);
}

// A stripe of opaque lipstick across the forehead, y 113..147: its lower edge is the test's edge.
#define STRIPE_Y 130.0f
static const rouge_brush stripe_brush = {.cosmetic = "lipstick_matte", .opacity = 1.0f, .coverage = 1.0f,
                                         .size = 0.08f, .any_region = true};

static bool start(void)
{
    rouge_error e = {0};
    return RS_CHECK(rouge_face_clear(face, &e) == ROUGE_OK, "clear: %s", e.msg) && set_brush(&stripe_brush);
}

// The lower edge of column x: 10 % and 90 % crossings of the cover profile, from the stripe downwards.
static double edge_width(const uint8_t *img, int x, const double ink[3])
{
    double y10 = NAN, y90 = NAN, prev = cover(img, x, (int)STRIPE_Y, ink);
    for (int y = (int)STRIPE_Y + 1; y < 230; y++) {
        double c = cover(img, x, y, ink);
        if (isnan(y90) && c < 0.9 && prev >= 0.9) y90 = y - 1 + (prev - 0.9) / (prev - c);
        if (isnan(y10) && c < 0.1 && prev >= 0.1) y10 = y - 1 + (prev - 0.1) / (prev - c);
        prev = c;
    }
    return y10 - y90;
}

// Smudging down from inside the stripe across its lower edge drags the lipstick onto the bare skin
// below: the pixels past the edge gain its colour, less the further along the drag; a column beside the
// smudge keeps its own.
static void test_smudge_drags_lipstick_across_its_edge(void)
{
    if (!start()) return;
    stroke(185, STRIPE_Y, 325, STRIPE_Y, 40);
    uint8_t *before = malloc((size_t)W * H * 4), *after = malloc((size_t)W * H * 4);
    RS_REQUIRE(render(before), "render");
    double ink[3];
    ink_at(before, 255, (int)STRIPE_Y, ink);
    rouge_stats st = rouge_face_stats(face);
    uint32_t stamps = st.look_stamps;
    RS_REQUIRE(set_brush(&(rouge_brush){.tool = ROUGE_TOOL_SMUDGE, .size = 0.05f}), "smudge brush");
    double t0 = rs_time_now();
    uint32_t n = stroke(255, STRIPE_Y, 255, 200, 30);
    double ms = (rs_time_now() - t0) * 1000.0;
    printf("# smudge stroke: %u stamps in %.0f ms (%.2f ms a stamp, wall clock on a shared machine)\n", n, ms,
           n ? ms / n : 0.0);
    RS_REQUIRE(render(after), "render");
    save("smudge_lipstick_before", before);
    save("smudge_lipstick_after", after);
    st = rouge_face_stats(face);
    RS_CHECK(st.look_stamps > stamps, "the smudge laid no stamp (%u, was %u)", st.look_stamps, stamps);
    // The edge: where the stripe's own cover falls under 10 % in the smudged column, before smudging.
    int edge = (int)STRIPE_Y;
    while (edge < 230 && cover(before, 255, edge, ink) >= 0.1) edge++;
    double gain[4];
    printf("# smudge: edge at y %d; cover past it, before -> after:", edge);
    for (int k = 0; k < 4; k++) {
        int y = edge + 4 + 10 * k;
        double c0 = 0, c1 = 0;
        for (int x = 250; x <= 260; x++) c0 += cover(before, x, y, ink) / 11, c1 += cover(after, x, y, ink) / 11;
        gain[k] = c1 - c0;
        printf(" y+%d %.3f -> %.3f", 4 + 10 * k, c0, c1);
    }
    printf("\n");
    RS_CHECK(gain[0] >= 0.2, "just past the edge the smudge added %.3f of the lipstick's colour (want >= 0.2)", gain[0]);
    RS_CHECK(gain[0] > gain[1] && gain[1] > gain[2], "the colour does not fade along the drag: %.3f %.3f %.3f",
             gain[0], gain[1], gain[2]);
    RS_CHECK(gain[2] >= 0.03, "the drag carried nothing 24 px past the edge (%.3f)", gain[2]);
    // Beside the smudge (40 px to the left) nothing changed.
    double side = 0;
    for (int y = edge; y < edge + 40; y++) side = fmax(side, fabs(cover(after, 205, y, ink) - cover(before, 205, y, ink)));
    RS_CHECK(side < 0.02, "a column 50 px beside the smudge changed by %.3f", side);
    // One undo takes the whole smudge back.
    uint8_t *undone = malloc((size_t)W * H * 4);
    RS_CHECK(rouge_face_undo(face), "nothing to undo");
    if (render(undone)) {
        int d = 0;
        for (size_t i = 0; i < (size_t)W * H * 4; i++) d = RS_MAX(d, abs(undone[i] - before[i]));
        RS_CHECK(d == 0, "undoing the smudge left a difference of %d/255", d);
    }
    free(undone);
    // Its colour is the lipstick's: the hue of the gain points from the skin to the ink.
    const uint8_t *b = px(bare, 255, edge + 4), *a = px(after, 255, edge + 4);
    double dot = 0, n1 = 0, n2 = 0;
    for (int c = 0; c < 3; c++) {
        double d1 = a[c] - b[c], d2 = ink[c] - b[c];
        dot += d1 * d2, n1 += d1 * d1, n2 += d2 * d2;
    }
    RS_CHECK(n1 > 0 && dot / sqrt(n1 * n2) > 0.95, "the smudged colour is not the lipstick's (cosine %.3f)",
             n1 > 0 ? dot / sqrt(n1 * n2) : 0.0);
    free(before), free(after);
}

// Blending along the stripe's lower edge widens its 10-90 % ramp, and the product's total stays about as
// it was (a stamp only adds: the edge is feathered outwards, so it grows a little).
static void test_blend_softens_a_hard_edge(void)
{
    if (!start()) return;
    stroke(185, STRIPE_Y, 325, STRIPE_Y, 40);
    uint8_t *before = malloc((size_t)W * H * 4), *after = malloc((size_t)W * H * 4);
    RS_REQUIRE(render(before), "render");
    double ink[3];
    ink_at(before, 255, (int)STRIPE_Y, ink);
    int edge = (int)STRIPE_Y;
    while (edge < 230 && cover(before, 255, edge, ink) >= 0.5) edge++;
    RS_REQUIRE(set_brush(&(rouge_brush){.tool = ROUGE_TOOL_BLEND, .size = 0.05f}), "blend brush");
    stroke(215, (float)edge, 295, (float)edge, 30);
    RS_REQUIRE(render(after), "render");
    save("blend_edge_before", before);
    save("blend_edge_after", after);
    double w0 = 0, w1 = 0, t0 = 0, t1 = 0;
    int n = 0;
    for (int x = 240; x <= 270; x += 2) {
        double a = edge_width(before, x, ink), b = edge_width(after, x, ink);
        if (isnan(a) || isnan(b)) continue;
        w0 += a, w1 += b, n++;
    }
    for (int x = 240; x <= 270; x++)
        for (int y = 100; y < 230; y++) t0 += cover(before, x, y, ink), t1 += cover(after, x, y, ink);
    RS_REQUIRE(n >= 10, "the edge was found in %d columns only", n);
    w0 /= n, w1 /= n;
    printf("# blend: edge 10-90 %% %.1f -> %.1f px (%d columns); total cover %.0f -> %.0f (%+.1f %%)\n", w0, w1, n,
           t0, t1, 100.0 * (t1 - t0) / t0);
    RS_CHECK(w1 >= 1.5 * w0, "the edge's ramp grew from %.1f to %.1f px only (want x1.5)", w0, w1);
    RS_CHECK(fabs(t1 - t0) <= 0.2 * t0, "the total changed by %+.1f %% (want within 20 %%)", 100.0 * (t1 - t0) / t0);
    free(before), free(after);
}

static bool same(const uint8_t *a, const uint8_t *b, int *maxd)
{
    *maxd = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) *maxd = RS_MAX(*maxd, abs(a[i] - b[i]));
    return *maxd == 0;
}

// Paint, smudge and blend recorded to a stroke file: replaying the file, and loading the look saved
// from it, give the same picture; the file names the tools; the look needs no new field.
static void test_recorded_smudge_replays_to_the_same_picture(void)
{
    if (!start()) return;
    char path[512];
    snprintf(path, sizeof path, "%s/smudge_%d.strokes", rs_test_out_dir(), (int)getpid());
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_record_strokes(face, path, &e) == ROUGE_OK, "record: %s", e.msg);
    stroke(185, STRIPE_Y, 325, STRIPE_Y, 40);
    RS_REQUIRE(set_brush(&(rouge_brush){.tool = ROUGE_TOOL_SMUDGE, .size = 0.05f, .mirror = true}), "smudge");
    stroke(230, STRIPE_Y, 200, 190, 25);
    RS_REQUIRE(set_brush(&(rouge_brush){.tool = ROUGE_TOOL_BLEND, .size = 0.04f, .opacity = 0.6f}), "blend");
    stroke(260, 148, 320, 148, 20);
    RS_REQUIRE(rouge_face_record_strokes(face, NULL, &e) == ROUGE_OK, "stop: %s", e.msg);
    rouge_view view = rouge_face_get_view(face);
    uint8_t *live = malloc((size_t)W * H * 4), *replay = malloc((size_t)W * H * 4), *look = malloc((size_t)W * H * 4);
    RS_REQUIRE(render(live), "render");
    char *text = NULL;
    size_t len = 0;
    RS_REQUIRE(rouge_face_save_look_memory(face, &text, &len, &e) == ROUGE_OK, "save look: %s", e.msg);
    RS_CHECK(strstr(text, "tool") == NULL, "the look has a tool field: looks keep plain stamps");

    FILE *f = fopen(path, "rb");
    char buf[1 << 16];
    size_t got = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f) fclose(f);
    buf[got] = '\0';
    RS_CHECK(strstr(buf, "tool=smudge") && strstr(buf, "tool=blend"), "the stroke file does not name the tools");
    RS_CHECK(strstr(buf, "tool=paint") == NULL, "a paint brush line names its tool (old readers would refuse it)");

    RS_REQUIRE(rouge_face_clear(face, &e) == ROUGE_OK, "clear: %s", e.msg);
    RS_REQUIRE(rouge_face_play_strokes(face, path, &e) == ROUGE_OK, "play: %s", e.msg);
    rouge_face_set_view(face, &view, &e);
    RS_REQUIRE(render(replay), "render");
    int d1 = 0, d2 = 0;
    RS_CHECK(same(live, replay, &d1), "the replayed strokes differ from the live ones by up to %d/255", d1);

    RS_REQUIRE(rouge_face_clear(face, &e) == ROUGE_OK, "clear: %s", e.msg);
    RS_REQUIRE(rouge_face_load_look_memory(face, text, len, &e) == ROUGE_OK, "load look: %s", e.msg);
    RS_REQUIRE(render(look), "render");
    RS_CHECK(same(live, look, &d2), "the loaded look differs from the painted one by up to %d/255", d2);
    save("smudge_replay_live", live);
    save("smudge_replay_played", replay);
    rouge_free(text);
    free(live), free(replay), free(look);
    remove(path);
}

// A liner is the per-pixel fine layer: a smudge across it picks it up there and carries it as well.
static void test_smudge_moves_the_fine_layer(void)
{
    if (!start()) return;
    RS_REQUIRE(set_brush(&(rouge_brush){.cosmetic = "eyeliner", .opacity = 1.0f, .any_region = true}), "liner");
    stroke(200, STRIPE_Y, 310, STRIPE_Y, 60);
    uint8_t *before = malloc((size_t)W * H * 4), *after = malloc((size_t)W * H * 4);
    RS_REQUIRE(render(before), "render");
    double ink[3];
    int yl = (int)STRIPE_Y;
    for (int y = (int)STRIPE_Y - 6; y <= (int)STRIPE_Y + 6; y++)
        if (px(before, 255, y)[1] < px(before, 255, yl)[1]) yl = y;
    ink_at(before, 255, yl, ink);
    RS_REQUIRE(set_brush(&(rouge_brush){.tool = ROUGE_TOOL_SMUDGE, .size = 0.04f}), "smudge");
    stroke(255, (float)yl, 255, (float)yl + 40, 25);
    RS_REQUIRE(render(after), "render");
    save("smudge_liner_after", after);
    double c0 = 0, c1 = 0;
    for (int y = yl + 8; y < yl + 20; y++)
        for (int x = 250; x <= 260; x++) c0 += cover(before, x, y, ink), c1 += cover(after, x, y, ink);
    c0 /= 12 * 11, c1 /= 12 * 11;
    printf("# smudged liner: cover 8-20 px below the line %.3f -> %.3f\n", c0, c1);
    RS_CHECK(c1 - c0 >= 0.1, "the smudge carried %.3f of the liner below it (want >= 0.1)", c1 - c0);
    free(before), free(after);
}

// A tool the API does not have, or the eraser with a tool, is refused with a message that says so; the
// brush stays as it was. A stroke file naming an unknown tool is refused with its line.
static void test_invalid_tool_is_refused(void)
{
    rouge_error e = {0};
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.tool = (rouge_tool)7}, &e) == ROUGE_ERR_ARG &&
                 strstr(e.msg, "tool 7"),
             "tool 7: %s", e.msg);
    printf("# %s\n", e.msg);
    e = (rouge_error){0};
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.tool = (rouge_tool)-1}, &e) == ROUGE_ERR_ARG, "tool -1");
    e = (rouge_error){0};
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.tool = ROUGE_TOOL_SMUDGE, .eraser = true}, &e) ==
                 ROUGE_ERR_ARG && strstr(e.msg, "eraser"),
             "eraser with smudge: %s", e.msg);
    char path[512];
    snprintf(path, sizeof path, "%s/badtool_%d.strokes", rs_test_out_dir(), (int)getpid());
    FILE *f = fopen(path, "w");
    RS_REQUIRE(f, "write %s", path);
    fputs("rouge-strokes 1\nview yaw=0 pitch=0 zoom=1 fov=30 size=512x512\n"
          "brush size=0.05 opacity=0.8 pressure=floor mirror=0 eraser=0 mask=1 tool=rub\n"
          "cosmetic blush\nstroke\ns 0 250 250 1\nend\n", f);
    fclose(f);
    e = (rouge_error){0};
    RS_CHECK(rouge_face_play_strokes(face, path, &e) == ROUGE_ERR_FORMAT && strstr(e.msg, "line 3") &&
                 strstr(e.msg, "tool"),
             "stroke file with tool=rub: %s", e.msg);
    printf("# %s\n", e.msg);
    remove(path);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_gl_context *gl = NULL;
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - smudge: no GL context: %s\n", err.msg);
        return rs_test_finish();
    }
    rouge_error e = {0};
    if (rouge_face_create(&(rouge_face_desc){.path = FACE_PATH}, &face, &e) != ROUGE_OK) {
        printf("FAIL - smudge: %s\n", e.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    rouge_face_set_view(face, &(rouge_view){.width = W, .height = H, .mode = ROUGE_MODE_ALBEDO}, &e);
    bare = malloc((size_t)W * H * 4);
    if (!bare || !render(bare)) {
        printf("FAIL - smudge: the bare face does not render\n");
        return 1;
    }
    save("smudge_bare", bare);
    RS_RUN(test_smudge_drags_lipstick_across_its_edge);
    RS_RUN(test_blend_softens_a_hard_edge);
    RS_RUN(test_smudge_moves_the_fine_layer);
    RS_RUN(test_recorded_smudge_replays_to_the_same_picture);
    RS_RUN(test_invalid_tool_is_refused);
    free(bare);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
