// test_ui.c — the viewer's UI toolkit: the bitmap font, toolbar layout (touch-target sizes, no overlaps,
// fits the window, hit-testing), widget input (taps, slider drags, routing presses between UI and scene)
// and a headless render of the toolbar compared with a golden image.
#include "support/harness.h"
#include "gl/gl.h"
#include "ui.h"
#include "viewer_internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rs_gl_context *gl;

// --- font -------------------------------------------------------------------------------------------

static void test_font_has_ink_for_every_printable_ascii_glyph(void)
{
    for (int ch = 33; ch < 127; ch++) {
        uint8_t rows[9];
        RS_REQUIRE(rs_ui_font_glyph(ch, rows), "glyph %d missing", ch);
        int ink = 0;
        for (int r = 0; r < 9; r++) ink += rows[r] != 0;
        RS_CHECK(ink > 0, "glyph '%c' is blank", ch);
    }
    uint8_t rows[9];
    RS_CHECK(rs_ui_font_glyph(' ', rows) && !rows[0] && !rows[3], "space is not blank");
    RS_CHECK(!rs_ui_font_glyph(200, rows), "non-ASCII reported as a glyph");
}

static void test_font_glyphs_are_distinct(void)
{
    // Two identical glyphs would make a label ambiguous (l vs 1, O vs 0 ...).
    uint8_t g[127][9];
    for (int ch = 33; ch < 127; ch++) rs_ui_font_glyph(ch, g[ch]);
    for (int a = 33; a < 127; a++)
        for (int b = a + 1; b < 127; b++) RS_CHECK(memcmp(g[a], g[b], 9) != 0, "'%c' and '%c' look the same", a, b);
}

static void test_font_descenders_only_below_baseline_for_gjpqy(void)
{
    for (int ch = 33; ch < 127; ch++) {
        uint8_t rows[9];
        rs_ui_font_glyph(ch, rows);
        bool desc = rows[7] || rows[8];
        bool want = strchr("gjpqy,_|", ch) != NULL;
        RS_CHECK(desc == want, "'%c': descender %d, expected %d", ch, desc, want);
    }
}

static void test_text_width_is_cells_minus_last_gap(void)
{
    RS_CHECK(rs_ui_text_width("", 2) == 0, "empty");
    RS_CHECK(rs_ui_text_width("A", 1) == 5, "A at 1: %g", rs_ui_text_width("A", 1));
    RS_CHECK(rs_ui_text_width("Full", 2) == (4 * 6 - 1) * 2, "Full at 2: %g", rs_ui_text_width("Full", 2));
}

// --- layout -----------------------------------------------------------------------------------------

static bool overlap(rs_ui_rect a, rs_ui_rect b)
{
    return a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h;
}

static bool inside(rs_ui_rect in, rs_ui_rect out)
{
    const float e = 0.01f;
    return in.x >= out.x - e && in.y >= out.y - e && in.x + in.w <= out.x + out.w + e &&
           in.y + in.h <= out.y + out.h + e;
}

typedef struct size_case {
    int w, h;
    float scale;
    float min_target;  // points: 44 is Apple's minimum touch target
} size_case;

static const size_case sizes[] = {
    {800, 600, 1, 44}, {1024, 768, 1, 44}, {1920, 1080, 1, 44}, {1600, 1200, 2, 44 * 2}, {2560, 1440, 2, 44 * 2},
};

static void test_toolbar_targets_are_at_least_44pt(void)
{
    for (size_t k = 0; k < RS_COUNT_OF(sizes); k++) {
        rs_ui_toolbar_layout l;
        rs_ui_toolbar_layout_compute(sizes[k].w, sizes[k].h, sizes[k].scale, 15, &l);
        for (int t = RS_UI_TOOL_PAINT; t < RS_UI_TOOL_SWATCH; t++)
            RS_CHECK(l.tool[t].w >= sizes[k].min_target && l.tool[t].h >= sizes[k].min_target,
                     "%dx%d: tool %d is %gx%g", sizes[k].w, sizes[k].h, t, l.tool[t].w, l.tool[t].h);
        for (int i = 0; i < 15; i++)
            RS_CHECK(l.swatch[i].w >= sizes[k].min_target, "%dx%d: swatch %d is %g wide", sizes[k].w, sizes[k].h, i,
                     l.swatch[i].w);
    }
}

static void test_toolbar_items_fit_their_panels_and_never_overlap(void)
{
    for (size_t k = 0; k < RS_COUNT_OF(sizes) + 2; k++) {
        // Two extra cases: a small window and many swatches squeeze the layout.
        int w = k < RS_COUNT_OF(sizes) ? sizes[k].w : 480, h = k < RS_COUNT_OF(sizes) ? sizes[k].h : 360;
        float sc = k < RS_COUNT_OF(sizes) ? sizes[k].scale : 1;
        int n = k == RS_COUNT_OF(sizes) + 1 ? RS_UI_TOOLBAR_MAX_SWATCHES : 15;
        rs_ui_toolbar_layout l;
        rs_ui_toolbar_layout_compute(w, h, sc, n, &l);
        rs_ui_rect win = {0, 0, (float)w, (float)h};
        rs_ui_rect panels[4] = {l.top, l.left, l.right, l.bottom};
        for (int i = 0; i < 4; i++) {
            RS_CHECK(inside(panels[i], win), "%dx%d: panel %d outside the window", w, h, i);
            for (int j = i + 1; j < 4; j++) RS_CHECK(!overlap(panels[i], panels[j]), "%dx%d: panels %d, %d overlap", w, h, i, j);
        }
        // Every item: inside one panel, overlapping no other item.
        rs_ui_rect items[RS_UI_TOOL_COUNT + RS_UI_TOOLBAR_MAX_SWATCHES];
        int ni = 0;
        for (int t = RS_UI_TOOL_PAINT; t < RS_UI_TOOL_SWATCH; t++) items[ni++] = l.tool[t];
        for (int i = 0; i < n; i++) items[ni++] = l.swatch[i];
        for (int i = 0; i < ni; i++) {
            bool in_panel = false;
            for (int p = 0; p < 4; p++) in_panel |= inside(items[i], panels[p]);
            RS_CHECK(in_panel, "%dx%d: item %d (%g,%g %gx%g) outside every panel", w, h, i, items[i].x, items[i].y,
                     items[i].w, items[i].h);
            for (int j = i + 1; j < ni; j++) RS_CHECK(!overlap(items[i], items[j]), "%dx%d: items %d and %d overlap", w, h, i, j);
        }
    }
}

static void test_toolbar_leaves_the_middle_for_the_face(void)
{
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(800, 600, 1, 15, &l);
    // The face is drawn in the middle: at least 60% of the width and the height must stay free there.
    float free_w = l.right.x - (l.left.x + l.left.w), free_h = l.bottom.y - (l.top.y + l.top.h);
    RS_CHECK(free_w >= 0.6f * 800 && free_h >= 0.6f * 600, "free area %gx%g", free_w, free_h);
    RS_CHECK(rs_ui_toolbar_hit(&l, 400, 300, NULL) == RS_UI_TOOL_NONE, "the window centre is a tool");
}

static void test_toolbar_hit_finds_each_item_at_its_centre(void)
{
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(1024, 768, 1, 15, &l);
    for (int t = RS_UI_TOOL_PAINT; t < RS_UI_TOOL_SWATCH; t++) {
        rs_ui_rect r = l.tool[t];
        RS_CHECK(rs_ui_toolbar_hit(&l, r.x + r.w / 2, r.y + r.h / 2, NULL) == (rs_ui_tool)t, "tool %d", t);
    }
    for (int i = 0; i < 15; i++) {
        int sw = -1;
        rs_ui_rect r = l.swatch[i];
        RS_CHECK(rs_ui_toolbar_hit(&l, r.x + r.w / 2, r.y + r.h / 2, &sw) == RS_UI_TOOL_SWATCH && sw == i,
                 "swatch %d hit as %d", i, sw);
    }
}

// --- GL: widgets and rendering ----------------------------------------------------------------------

typedef struct target {
    GLuint tex, fbo;
    int w, h;
} target;

static void target_begin(target *t, int w, int h)
{
    t->w = w, t->h = h;
    glGenTextures(1, &t->tex);
    glBindTexture(GL_TEXTURE_2D, t->tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, w, h);
    glGenFramebuffers(1, &t->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, t->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, t->tex, 0);
    glViewport(0, 0, w, h);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
}

static void target_end(target *t)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &t->fbo);
    glDeleteTextures(1, &t->tex);
}

static void test_text_renders_the_glyph_bits_exactly(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    target t;
    target_begin(&t, 32, 32);
    rs_ui_begin(ui, 32, 32, 1, &(rs_ui_input){0});
    rs_ui_text(ui, 3, 4, 2, (rs_ui_rgba){255, 255, 255, 255}, "g");
    rs_ui_end(ui);
    rs_image img = {0};
    RS_REQUIRE(rs_ui_read_pixels(32, 32, &img, &err) == RS_OK, "%s", err.msg);
    uint8_t rows[9];
    rs_ui_font_glyph('g', rows);
    int wrong = 0;
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            int gx = (x - 3) / 2, gy = (y - 4) / 2;
            bool ink = x >= 3 && y >= 4 && gx < 5 && gy < 9 && (rows[gy] & (0x10 >> gx));
            uint8_t v = img.pixels[((size_t)y * 32 + (size_t)x) * 4];
            if ((ink && v != 255) || (!ink && v != 0)) wrong++;
        }
    RS_CHECK(wrong == 0, "%d pixels differ from the glyph at scale 2", wrong);
    if (wrong) rs_test_save("ui_text_g", &img);
    rs_image_free(&img);
    target_end(&t);
    rs_ui_destroy(ui);
}

// One UI frame with the pointer state `in`; returns what the button reported.
static bool frame_button(rs_ui *ui, rs_ui_input in)
{
    rs_ui_begin(ui, 200, 200, 1, &in);
    bool tap = rs_ui_button(ui, 7, (rs_ui_rect){50, 50, 48, 48}, RS_UI_ICON_UNDO, false);
    rs_ui_end(ui);
    return tap;
}

static void test_button_taps_only_when_pressed_and_released_on_it(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    target t;
    target_begin(&t, 200, 200);
    // A tap inside: press frame, release frame.
    RS_CHECK(!frame_button(ui, (rs_ui_input){.x = 70, .y = 70, .down = true, .pressed = true}), "tapped on press");
    RS_CHECK(frame_button(ui, (rs_ui_input){.x = 72, .y = 71, .released = true}), "no tap on release");
    // Press and release within one frame (a script or a fast tap) still taps.
    RS_CHECK(frame_button(ui, (rs_ui_input){.x = 70, .y = 70, .pressed = true, .released = true}), "quick tap lost");
    // Press inside, slide off, release: cancelled.
    frame_button(ui, (rs_ui_input){.x = 70, .y = 70, .down = true, .pressed = true});
    frame_button(ui, (rs_ui_input){.x = 150, .y = 150, .down = true});
    RS_CHECK(!frame_button(ui, (rs_ui_input){.x = 150, .y = 150, .released = true}), "slide-off tapped");
    // Press outside (on the scene), release inside: not a tap.
    frame_button(ui, (rs_ui_input){.x = 10, .y = 10, .down = true, .pressed = true});
    RS_CHECK(!frame_button(ui, (rs_ui_input){.x = 70, .y = 70, .released = true}), "drag-in tapped");
    target_end(&t);
    rs_ui_destroy(ui);
}

static void test_captures_routes_presses_on_panels_to_the_ui(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    target t;
    target_begin(&t, 800, 600);
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(800, 600, 1, 15, &l);
    uint8_t rgb[15][3] = {{0}};
    rs_ui_toolbar_state st = {.swatch_count = 15, .swatch_rgb = (const uint8_t(*)[3])rgb, .size = 0.5f, .opacity = 0.5f};
    rs_ui_begin(ui, 800, 600, 1, &(rs_ui_input){.x = 400, .y = 300});
    rs_ui_toolbar(ui, &l, &st, NULL);
    rs_ui_end(ui);
    RS_CHECK(!rs_ui_captures(ui, 400, 300), "the face area is captured");
    RS_CHECK(rs_ui_captures(ui, l.bottom.x + 2, l.bottom.y + 2), "a panel corner is not captured");
    rs_ui_rect u = l.tool[RS_UI_TOOL_UNDO];
    RS_CHECK(rs_ui_captures(ui, u.x + 5, u.y + 5), "the undo button is not captured");
    // While a slider is dragged, presses anywhere belong to the UI.
    rs_ui_rect sz = l.tool[RS_UI_TOOL_SIZE];
    float kx = sz.x + sz.w / 2, ky = sz.y + sz.h / 2;
    rs_ui_begin(ui, 800, 600, 1, &(rs_ui_input){.x = kx, .y = ky, .down = true, .pressed = true});
    rs_ui_toolbar(ui, &l, &st, NULL);
    rs_ui_end(ui);
    RS_CHECK(rs_ui_captures(ui, 400, 300), "a dragged slider lost the pointer");
    target_end(&t);
    rs_ui_destroy(ui);
}

// A drag moves by what the pointer moved since the press: the pointer hovering 300 px away the frame
// before (or a new touch landing there) must not add that jump (the split divider once went 200+ px left
// for an 88 px drag to the right).
static void test_drag_counts_from_the_press_not_the_hover(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    rs_ui_rect handle = {380, 280, 40, 40};
    const rs_ui_input seq[] = {
        {.x = 100, .y = 500, .inside = true},                       // hovering far away
        {.x = 400, .y = 300, .down = true, .pressed = true},        // a touch lands on the handle
        {.x = 444, .y = 300, .down = true},
        {.x = 488, .y = 302, .down = true},
        {.x = 488, .y = 302, .released = true},
    };
    float total = 0;
    for (size_t i = 0; i < RS_COUNT_OF(seq); i++) {
        float dx = 0, dy = 0;
        rs_ui_begin(ui, 800, 600, 1, &seq[i]);
        if (rs_ui_drag(ui, 3001, handle, &dx, &dy)) total += dx;
        rs_ui_end(ui);
        handle.x += dx;  // the widget follows, as the divider does
    }
    RS_CHECK(fabsf(total - 88.0f) < 0.5f, "dragged 88 px right, moved %g px", total);
    rs_ui_destroy(ui);
}

static void test_slider_follows_the_pointer_and_clamps(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    target t;
    target_begin(&t, 800, 600);
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(800, 600, 1, 15, &l);
    uint8_t rgb[15][3] = {{0}};
    rs_ui_toolbar_state st = {.swatch_count = 15, .swatch_rgb = (const uint8_t(*)[3])rgb, .size = 0.5f, .opacity = 0.5f};
    rs_ui_rect sz = l.tool[RS_UI_TOOL_SIZE];
    float x = sz.x + sz.w / 2;
    float ys[4] = {sz.y + sz.h / 2, sz.y - 500, sz.y + sz.h + 500, sz.y + sz.h / 2};
    float vs[4];
    rs_ui_tool tool = RS_UI_TOOL_NONE;
    for (int i = 0; i < 4; i++) {
        rs_ui_input in = {.x = x, .y = ys[i], .down = i < 3, .pressed = i == 0, .released = i == 3};
        rs_ui_begin(ui, 800, 600, 1, &in);
        rs_ui_tool r = rs_ui_toolbar(ui, &l, &st, NULL);
        if (r != RS_UI_TOOL_NONE) tool = r;
        rs_ui_end(ui);
        vs[i] = st.size;
    }
    RS_CHECK(tool == RS_UI_TOOL_SIZE, "slider change reported as %d", tool);
    RS_CHECK(vs[0] > 0.2f && vs[0] < 0.8f, "middle press gave %g", vs[0]);
    RS_CHECK(vs[1] == 1.0f, "dragged far up gave %g (vertical sliders grow upwards)", vs[1]);
    RS_CHECK(vs[2] == 0.0f, "dragged far down gave %g", vs[2]);
    RS_CHECK(st.opacity == 0.5f, "the opacity slider moved too");
    target_end(&t);
    rs_ui_destroy(ui);
}

// The sun dial (issue 15): large enough to aim with a finger, and geared: pressing anywhere on it does not
// make the light jump, a 22-pixel drag turns the light by less than a fifth of the dial's range (~17
// degrees; it once swung the light under the chin), and a long drag still reaches the rim.
static void test_light_dial_is_large_and_geared(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    target t;
    target_begin(&t, 800, 600);
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(800, 600, 1, 15, &l);
    rs_ui_rect d = l.tool[RS_UI_TOOL_LIGHT];
    RS_CHECK(d.w >= 80 && d.h >= 80, "the dial is %gx%g pt", d.w, d.h);
    uint8_t rgb[15][3] = {{0}};
    rs_ui_toolbar_state st = {.swatch_count = 15, .swatch_rgb = (const uint8_t(*)[3])rgb, .light = {0.0f, 0.4f}};
    float cx = d.x + d.w / 2, cy = d.y + d.h / 2;
    // Press on the dial's centre (away from the sun), drag 22 px down over a few frames, release.
    const float ys[6] = {cy, cy, cy + 8, cy + 15, cy + 22, cy + 22};
    float after_press = 0;
    for (int i = 0; i < 6; i++) {
        rs_ui_input in = {.x = cx, .y = ys[i], .down = i < 5, .pressed = i == 0, .released = i == 5, .inside = true};
        rs_ui_begin(ui, 800, 600, 1, &in);
        rs_ui_toolbar(ui, &l, &st, NULL);
        rs_ui_end(ui);
        if (i == 1) after_press = st.light[1];
    }
    RS_CHECK(fabsf(after_press - 0.4f) < 1e-6f && st.light[0] == 0.0f, "a press moved the light to (%g, %g)",
             st.light[0], after_press);
    float moved = 0.4f - st.light[1];
    RS_CHECK(moved > 0.1f && moved < 0.2f, "a 22 px drag down moved the light by %.3f of the dial's radius", moved);
    // A long drag to the right ends on the rim, not beyond it.
    for (int i = 0; i < 12; i++) {
        rs_ui_input in = {.x = cx + 30.0f * (float)i, .y = cy, .down = i < 11, .pressed = i == 0, .released = i == 11,
                          .inside = true};
        rs_ui_begin(ui, 800, 600, 1, &in);
        rs_ui_toolbar(ui, &l, &st, NULL);
        rs_ui_end(ui);
    }
    float r = hypotf(st.light[0], st.light[1]);
    RS_CHECK(r > 0.99f && r < 1.001f && st.light[0] > 0.9f, "after a long drag the light is at (%g, %g)", st.light[0],
             st.light[1]);
    target_end(&t);
    rs_ui_destroy(ui);
}

// Labelled sliders: each shows its name and value above its track (ink there with texts, none without).
static void test_sliders_show_their_names_and_values(void)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg);
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(800, 600, 1, 15, &l);
    uint8_t rgb[15][3] = {{0}};
    int ink[2][2] = {{0}};
    for (int with = 0; with < 2; with++) {
        target t;
        target_begin(&t, 800, 600);
        rs_ui_toolbar_state st = {.swatch_count = 15, .swatch_rgb = (const uint8_t(*)[3])rgb, .size = 0.0f,
                                  .opacity = 0.0f, .size_text = with ? "18 mm" : NULL,
                                  .opacity_text = with ? "80%" : NULL};
        rs_ui_begin(ui, 800, 600, 1, &(rs_ui_input){.x = -1, .y = -1});
        rs_ui_toolbar(ui, &l, &st, NULL);
        rs_ui_end(ui);
        rs_image img = {0};
        RS_REQUIRE(rs_ui_read_pixels(800, 600, &img, &err) == RS_OK, "%s", err.msg);
        // The top 30 px of each slider (with value 0 the knob sits at the bottom).
        const rs_ui_tool sl[2] = {RS_UI_TOOL_SIZE, RS_UI_TOOL_OPACITY};
        for (int k = 0; k < 2; k++) {
            rs_ui_rect r = l.tool[sl[k]];
            for (int y = (int)r.y; y < (int)r.y + 30; y++)
                for (int x = (int)r.x; x < (int)(r.x + r.w); x++)
                    ink[with][k] += img.pixels[((size_t)y * 800 + (size_t)x) * 4 + 1] > 200;
        }
        rs_image_free(&img);
        target_end(&t);
    }
    RS_CHECK(ink[1][0] > 40 && ink[1][1] > 40, "size / opacity labels drew %d / %d bright pixels", ink[1][0], ink[1][1]);
    // Without value texts the names still show (dimmer than white): the value is what adds white ink.
    RS_CHECK(ink[0][0] < ink[1][0] && ink[0][1] < ink[1][1], "the values add no ink (%d/%d vs %d/%d)", ink[0][0],
             ink[0][1], ink[1][0], ink[1][1]);
    rs_ui_destroy(ui);
}

// A fixed palette so the golden image does not change when the cosmetics presets are tuned.
static const uint8_t golden_rgb[15][3] = {
    {242, 208, 182}, {222, 178, 146}, {178, 128, 96}, {236, 218, 204}, {220, 112, 122},
    {168, 110, 76},  {132, 100, 84},  {250, 236, 214}, {168, 36, 54},  {204, 78, 118},
    {255, 255, 255}, {122, 82, 62},   {112, 62, 92},   {222, 192, 152}, {28, 22, 22},
};
static const char *const golden_names[15] = {"Foundation 1", "Foundation 2", "Foundation 3", "Powder", "Blush",
                                             "Bronzer", "Contour", "Highlighter", "Lipstick matte",
                                             "Lipstick satin", "Lip gloss", "Eyeshadow brown", "Eyeshadow plum",
                                             "Eyeshadow champagne", "Eyeliner"};

static void render_toolbar(int w, int h, float scale, rs_image *out)
{
    rs_ui *ui = NULL;
    rs_error err = {0};
    if (!RS_CHECK(rs_ui_create(&ui, &err) == RS_OK, "%s", err.msg)) return;
    target t;
    target_begin(&t, w, h);
    rs_ui_toolbar_layout l;
    rs_ui_toolbar_layout_compute(w, h, scale, 15, &l);
    rs_ui_toolbar_state st = {.swatch_count = 15, .swatch_rgb = golden_rgb, .swatch_name = golden_names,
                              .selected = 9, .size = 0.35f, .opacity = 0.7f, .light = {-0.45f, 0.4f},
                              .size_text = "18 mm", .opacity_text = "70%",
                              .paint = true, .mirror = true, .keep_region = true, .region_name = "lips",
                              .can_undo = true, .mode = 2, .mobile = true};
    rs_ui_begin(ui, w, h, scale, &(rs_ui_input){.x = -1, .y = -1});
    // A backdrop like the viewer's: a vertical grey gradient and a soft disc where the face would be.
    for (int i = 0; i < 16; i++) {
        uint8_t g = (uint8_t)(58 - i * 2);
        rs_ui_fill(ui, (rs_ui_rect){0, (float)h * (float)i / 16, (float)w, (float)h / 16 + 1}, 0, (rs_ui_rgba){g, g, (uint8_t)(g + 3), 255});
    }
    rs_ui_shadow(ui, (rs_ui_rect){(float)w * 0.35f, (float)h * 0.2f, (float)w * 0.3f, (float)h * 0.55f},
                 (float)w * 0.15f, 40, (rs_ui_rgba){205, 160, 135, 255});
    rs_ui_toolbar(ui, &l, &st, NULL);
    rs_ui_end(ui);
    RS_CHECK(rs_ui_read_pixels(w, h, out, &err) == RS_OK, "%s", err.msg);
    target_end(&t);
    rs_ui_destroy(ui);
}

static void test_toolbar_render_matches_golden(void)
{
    rs_image img = {0};
    render_toolbar(800, 600, 1, &img);
    if (img.pixels) rs_test_golden("ui_toolbar_800x600", &img, 8, 0.002, 35.0);
    rs_image_free(&img);
}

static void test_toolbar_render_at_2x_is_the_1x_layout_doubled(void)
{
    // HiDPI: at scale 2 in a 2x framebuffer every item sits at twice the 1x position; compare the 2x
    // render downsampled with the 1x render.
    rs_image a = {0}, b = {0}, half = {0};
    render_toolbar(800, 600, 1, &a);
    render_toolbar(1600, 1200, 2, &b);
    rs_error err = {0};
    if (a.pixels && b.pixels && rs_image_create(800, 600, 4, &half, &err) == RS_OK) {
        for (int y = 0; y < 600; y++)
            for (int x = 0; x < 800; x++)
                for (int c = 0; c < 4; c++) {
                    int s = 0;
                    for (int k = 0; k < 4; k++)
                        s += b.pixels[(((size_t)(2 * y + k / 2)) * 1600 + (size_t)(2 * x + k % 2)) * 4 + (size_t)c];
                    half.pixels[((size_t)y * 800 + (size_t)x) * 4 + (size_t)c] = (uint8_t)((s + 2) / 4);
                }
        rs_image_metrics m;
        rs_image_compare(&a, &half, 48, &m, &err);
        // Text is pixel art (scale 2 vs 4 glyph pixels) and edges anti-alias differently: loose bounds.
        RS_CHECK(m.psnr > 24 && m.frac_over < 0.01, "PSNR %.1f, %.4f of pixels off by > 48", m.psnr, m.frac_over);
        if (m.psnr <= 24 || m.frac_over >= 0.01) rs_test_save("ui_toolbar_2x_half", &half), rs_test_save("ui_toolbar_1x", &a);
    }
    rs_image_free(&a);
    rs_image_free(&b);
    rs_image_free(&half);
}

// The product editor's colour maths: every preset's colour and a sweep of others survive sRGB -> HSV ->
// sRGB exactly (the picker starts from the product's colour, so opening it must not change the colour).
static void test_editor_hsv_round_trip(void)
{
    int bad = 0;
    for (uint32_t i = 0; i < rs_cosmetic_count(); i++) {
        const rs_cosmetic *c = rs_cosmetic_get(i);
        float h, s, v;
        uint8_t back[3];
        rs_cosmetic_rgb_to_hsv(c->rgb, &h, &s, &v);
        rs_cosmetic_hsv_to_rgb(h, s, v, back);
        bad += memcmp(back, c->rgb, 3) != 0;
    }
    for (int r = 0; r < 256; r += 15)
        for (int g = 0; g < 256; g += 17)
            for (int b = 0; b < 256; b += 13) {
                uint8_t rgb[3] = {(uint8_t)r, (uint8_t)g, (uint8_t)b}, back[3];
                float h, s, v;
                rs_cosmetic_rgb_to_hsv(rgb, &h, &s, &v);
                RS_CHECK(h >= 0 && h < 360 && s >= 0 && s <= 1 && v >= 0 && v <= 1, "hsv range %g %g %g", h, s, v);
                rs_cosmetic_hsv_to_rgb(h, s, v, back);
                bad += memcmp(back, rgb, 3) != 0;
            }
    RS_CHECK(bad == 0, "%d colours changed through HSV", bad);
}

// The editor panel fits the window between the top bar, the right rail and the swatch sheet, its controls
// inside it, touch-sized, at the sizes people use.
static void test_editor_layout_fits_beside_the_toolbar(void)
{
    const int sizes[][2] = {{800, 600}, {1280, 720}, {1920, 1080}, {1024, 768}};
    for (size_t k = 0; k < sizeof sizes / sizeof *sizes; k++) {
        int w = sizes[k][0], h = sizes[k][1];
        float scale = h >= 1000 ? 1.5f : 1.0f;
        rs_ui_toolbar_layout tb;
        rs_ui_toolbar_layout_compute(w, h, scale, (int)rs_cosmetic_count(), &tb);
        vw_editor_layout l;
        vw_editor_layout_compute(&tb, scale, &l);
        rs_ui_rect p = l.panel;
        RS_CHECK(p.x >= 0 && p.y >= tb.top.y + tb.top.h && p.x + p.w <= tb.right.x && p.y + p.h <= tb.bottom.y,
                 "%dx%d: panel (%.0f %.0f %.0f %.0f) overlaps the toolbar or leaves the window", w, h, p.x, p.y, p.w,
                 p.h);
        rs_ui_rect parts[] = {l.close, l.sv, l.hue, l.swatch, l.hex, l.finish[0], l.finish[RS_FINISH_COUNT - 1],
                              l.coverage};
        for (size_t i = 0; i < sizeof parts / sizeof *parts; i++) {
            rs_ui_rect r = parts[i];
            RS_CHECK(r.x >= p.x && r.y >= p.y && r.x + r.w <= p.x + p.w + 0.5f && r.y + r.h <= p.y + p.h + 0.5f,
                     "%dx%d: control %zu outside the panel", w, h, i);
            RS_CHECK(r.h >= 16 * scale - 0.01f, "%dx%d: control %zu only %.0f px tall", w, h, i, r.h);
        }
    }
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_editor_hsv_round_trip);
    RS_RUN(test_editor_layout_fits_beside_the_toolbar);
    RS_RUN(test_font_has_ink_for_every_printable_ascii_glyph);
    RS_RUN(test_font_glyphs_are_distinct);
    RS_RUN(test_font_descenders_only_below_baseline_for_gjpqy);
    RS_RUN(test_text_width_is_cells_minus_last_gap);
    RS_RUN(test_toolbar_targets_are_at_least_44pt);
    RS_RUN(test_toolbar_items_fit_their_panels_and_never_overlap);
    RS_RUN(test_toolbar_leaves_the_middle_for_the_face);
    RS_RUN(test_toolbar_hit_finds_each_item_at_its_centre);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - ui_gl_tests: %s\n", err.msg);
        return rs_test_finish();
    }
    RS_RUN(test_text_renders_the_glyph_bits_exactly);
    RS_RUN(test_button_taps_only_when_pressed_and_released_on_it);
    RS_RUN(test_captures_routes_presses_on_panels_to_the_ui);
    RS_RUN(test_drag_counts_from_the_press_not_the_hover);
    RS_RUN(test_slider_follows_the_pointer_and_clamps);
    RS_RUN(test_light_dial_is_large_and_geared);
    RS_RUN(test_sliders_show_their_names_and_values);
    RS_RUN(test_toolbar_render_matches_golden);
    RS_RUN(test_toolbar_render_at_2x_is_the_1x_layout_doubled);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
