// ui.h — a small immediate-mode UI drawn with GLES 3: the viewer's toolbar, HUD and help overlay.
//
// Does: batch anti-aliased shapes (rectangles, rounded rectangles, circles, rings, capsule lines, soft
// shadows) and textured quads into one vertex buffer, drawn with shaders_es/ui.*.glsl in submission order;
// text in a built-in 5x9 bitmap font (ASCII, drawn at integer scales so it stays crisp); vector icons;
// widgets (buttons, colour swatches, sliders, drag handles) with hot/active state and a hit-test of what
// the previous frame drew, so the app can route a pointer press to the UI or to the scene; the mobile
// makeup toolbar (layout as a pure function, drawing, actions); GPU texture copies and framebuffer
// read-back for the viewer's split view and screenshots.
// Does not: own a window, read devices or decide what an action does (the viewer maps actions to the
// makeup layer and the renderer). Coordinates are framebuffer pixels, origin top-left; `scale` is pixels
// per density-independent point (HiDPI), so a 44-point target is 44 * scale pixels.
//
//   rs_ui *ui;
//   if (rs_ui_create(&ui, &err) != RS_OK) return err.code;
//   rs_ui_begin(ui, fb_w, fb_h, scale, &(rs_ui_input){.x = mx, .y = my, .down = held, .pressed = edge});
//   if (rs_ui_button(ui, 1, (rs_ui_rect){16, 16, 48, 48}, RS_UI_ICON_UNDO, false)) undo();
//   rs_ui_end(ui);   // draws into the bound framebuffer
#ifndef RS_UI_H
#define RS_UI_H

#include "core/core.h"
#include "core/image.h"

#include <GLES3/gl3.h>

typedef struct rs_ui_rect {
    float x, y, w, h;  // framebuffer pixels, top-left origin
} rs_ui_rect;

typedef struct rs_ui_rgba {
    uint8_t r, g, b, a;  // sRGB, straight (not premultiplied) alpha
} rs_ui_rgba;

// The pointer as the UI sees it this frame (primary button only: the UI is touch-style).
typedef struct rs_ui_input {
    float x, y;      // framebuffer pixels
    bool down;       // held now
    bool pressed;    // went down since the last frame
    bool released;   // went up since the last frame (both may be set by a quick tap)
    bool inside;     // the pointer is over the window (hover feedback only)
} rs_ui_input;

typedef enum rs_ui_icon {
    RS_UI_ICON_NONE = 0,
    RS_UI_ICON_BRUSH,
    RS_UI_ICON_MOVE,      // navigate (view mode)
    RS_UI_ICON_ERASER,
    RS_UI_ICON_UNDO,
    RS_UI_ICON_REDO,
    RS_UI_ICON_MIRROR,
    RS_UI_ICON_TRASH,
    RS_UI_ICON_SPLIT,
    RS_UI_ICON_SAVE,
    RS_UI_ICON_LOAD,
    RS_UI_ICON_CAMERA,
    RS_UI_ICON_HELP,
    RS_UI_ICON_HUD,
    RS_UI_ICON_SUN,
    RS_UI_ICON_DOT,       // brush size
    RS_UI_ICON_DROP,      // opacity
    RS_UI_ICON_CLOSE,
    RS_UI_ICON_CHEVRONS,  // < > on the split divider
    RS_UI_ICON_REGION,    // the brush keeps to the product's region (a dot inside a dashed outline)
    RS_UI_ICON_SMUDGE,    // a fingertip and the smear it drags
    RS_UI_ICON_BLEND,     // a round brush over a hard line turned soft
    RS_UI_ICON_COUNT
} rs_ui_icon;

// Theme colours every widget uses.
#define RS_UI_WHITE ((rs_ui_rgba){245, 245, 247, 255})
#define RS_UI_DIM ((rs_ui_rgba){160, 160, 170, 255})
#define RS_UI_PANEL ((rs_ui_rgba){22, 22, 27, 210})
#define RS_UI_ACCENT ((rs_ui_rgba){236, 96, 128, 255})

typedef struct rs_ui rs_ui;

// Needs a current GLES 3 context (compiles the UI program, creates the font texture and buffers).
rs_result rs_ui_create(rs_ui **out, rs_error *err);
void rs_ui_destroy(rs_ui *ui);

// Starts a frame: clears the draw list; widgets compare `in` with last frame's state.
void rs_ui_begin(rs_ui *ui, int fb_w, int fb_h, float scale, const rs_ui_input *in);
// Draws the frame's list into the bound framebuffer (viewport = fb size) with premultiplied blending.
void rs_ui_end(rs_ui *ui);
// Ends a frame without drawing it: an input-only pass, so widgets see every press, move and release in
// order however many arrive between two drawn frames (one state per frame would lose a quick tap or flick).
void rs_ui_end_input(rs_ui *ui);
float rs_ui_scale(const rs_ui *ui);

// True when (x, y) lies on something interactive or on a panel drawn in the last finished frame, or a
// widget holds the pointer (a slider being dragged): the press belongs to the UI, not to the scene.
bool rs_ui_captures(const rs_ui *ui, float x, float y);
// The pointer position of this frame, framebuffer pixels.
void rs_ui_pointer(const rs_ui *ui, float *x, float *y);

// --- primitives (appended to the frame's list; later ones draw on top) -----------------------------
void rs_ui_fill(rs_ui *ui, rs_ui_rect r, float radius, rs_ui_rgba c);
void rs_ui_stroke(rs_ui *ui, rs_ui_rect r, float radius, float width, rs_ui_rgba c);
// A soft shadow/glow: the rounded rect blurred over `blur` pixels.
void rs_ui_shadow(rs_ui *ui, rs_ui_rect r, float radius, float blur, rs_ui_rgba c);
void rs_ui_circle(rs_ui *ui, float cx, float cy, float r, rs_ui_rgba c);
void rs_ui_ring(rs_ui *ui, float cx, float cy, float r, float width, rs_ui_rgba c);
// A line with round caps (a capsule) `width` pixels wide.
void rs_ui_line(rs_ui *ui, float x0, float y0, float x1, float y1, float width, rs_ui_rgba c);
// An arc of radius r from angle a0 to a1 (radians, 0 = +x, counter-clockwise on screen = negative y).
void rs_ui_arc(rs_ui *ui, float cx, float cy, float r, float a0, float a1, float width, rs_ui_rgba c);
void rs_ui_icon_draw(rs_ui *ui, rs_ui_icon icon, rs_ui_rect r, rs_ui_rgba c);
// A texture (RGBA8, rows bottom-first as GL renders them) into r; uv = {u0, v0, u1, v1} with v0 at the
// rect's top. Alpha is taken as 1 (rendered frames).
void rs_ui_image(rs_ui *ui, GLuint texture, rs_ui_rect r, const float uv[4]);
// A panel: shadow + translucent rounded rect; also marks the area as the UI's for rs_ui_captures.
void rs_ui_panel(rs_ui *ui, rs_ui_rect r, float radius);

// --- text: the built-in font, 5x9 glyph in a 6x11 cell, integer scale ------------------------------
#define RS_UI_FONT_CELL_W 6
#define RS_UI_FONT_CELL_H 11
// Width in pixels of one line of `s` at integer `scale` (newlines not handled: one line).
float rs_ui_text_width(const char *s, int scale);
// Draws one line with its top-left at (x, y); returns the width drawn. Unknown characters draw '?'.
float rs_ui_text(rs_ui *ui, float x, float y, int scale, rs_ui_rgba c, const char *s);
// The glyph of a character as 9 rows of 5 bits (bit 4 = leftmost column); false (rows zeroed) when
// the character is not printable ASCII.
bool rs_ui_font_glyph(int ch, uint8_t rows[9]);

// --- widgets: `id` is any nonzero value stable across frames ----------------------------------------
// A round icon button; `on` draws it in the accent colour. True when tapped (pressed and released on it).
bool rs_ui_button(rs_ui *ui, int id, rs_ui_rect r, rs_ui_icon icon, bool on);
// A text button (segmented controls); true when tapped.
bool rs_ui_text_button(rs_ui *ui, int id, rs_ui_rect r, const char *label, bool on);
// A round colour swatch (rgb sRGB) in r; selected draws a ring around it. True when tapped.
bool rs_ui_swatch(rs_ui *ui, int id, rs_ui_rect r, const uint8_t rgb[3], bool selected);
// A slider along the long side of r (vertical sliders grow upwards); *value in 0..1. True when changed.
// `label` ("Size") and `value_text` ("18 mm") are drawn at the track's far end (vertical: above it);
// either may be NULL.
bool rs_ui_slider(rs_ui *ui, int id, rs_ui_rect r, rs_ui_icon icon, const char *label, const char *value_text,
                  float *value);
// An invisible tap target (a thumbnail, a modal sheet's background): true when tapped.
bool rs_ui_area(rs_ui *ui, int id, rs_ui_rect r);
// Whether the pointer is over r and no other widget holds it (hover feedback for rs_ui_area).
bool rs_ui_hot(const rs_ui *ui, int id, rs_ui_rect r);
// A draggable area: true while held; *dx, *dy = pointer motion since the last frame (pixels).
bool rs_ui_drag(rs_ui *ui, int id, rs_ui_rect r, float *dx, float *dy);

// --- helpers --------------------------------------------------------------------------------------
bool rs_ui_rect_contains(rs_ui_rect r, float x, float y);
// Shrinks r by d on every side.
rs_ui_rect rs_ui_rect_inset(rs_ui_rect r, float d);

// --- the makeup toolbar ---------------------------------------------------------------------------
// Everything a person taps. Panels: top bar (render mode, pipeline, split, HUD, save/load, screenshot,
// help), left rail (paint/view, eraser, smudge/blend, mirror, region, undo, redo, clear), right rail (light dial, brush size,
// opacity) and bottom sheet (cosmetic swatches with the selected product's name).
typedef enum rs_ui_tool {
    RS_UI_TOOL_NONE = 0,
    RS_UI_TOOL_PAINT,         // toggles paint / view mode
    RS_UI_TOOL_ERASER,
    RS_UI_TOOL_SMUDGE,        // the makeup tools: off -> smudge (drag the makeup along) -> blend (soften) -> off
    RS_UI_TOOL_MIRROR,
    RS_UI_TOOL_REGION,        // region-aware brush on/off
    RS_UI_TOOL_UNDO,
    RS_UI_TOOL_REDO,
    RS_UI_TOOL_CLEAR,
    RS_UI_TOOL_ALBEDO,        // render modes (a segmented control)
    RS_UI_TOOL_DIFFUSE,
    RS_UI_TOOL_FULL,
    RS_UI_TOOL_PIPELINE,      // mobile <-> reference
    RS_UI_TOOL_SPLIT,         // before/after
    RS_UI_TOOL_HUD,
    RS_UI_TOOL_SAVE,
    RS_UI_TOOL_LOAD,
    RS_UI_TOOL_SCREENSHOT,
    RS_UI_TOOL_HELP,
    RS_UI_TOOL_LIGHT,         // the light dial (value changed)
    RS_UI_TOOL_SIZE,          // brush size slider (value changed)
    RS_UI_TOOL_OPACITY,       // opacity slider (value changed)
    RS_UI_TOOL_SWATCH,        // a cosmetic swatch (index returned separately)
    RS_UI_TOOL_COUNT
} rs_ui_tool;

#define RS_UI_TOOLBAR_MAX_SWATCHES 32
// The light dial is RS_UI_DIAL_PT points across; a drag moves the sun by (drag / RS_UI_DIAL_DRAG_PT) of the
// dial's radius whatever the dial's size, so a 22-point flick turns the light ~15 deg, not under the chin.
#define RS_UI_DIAL_PT 84.0f
#define RS_UI_DIAL_DRAG_PT 120.0f

typedef struct rs_ui_toolbar_layout {
    rs_ui_rect top, left, right, bottom;   // panels
    rs_ui_rect tool[RS_UI_TOOL_COUNT];     // one rect per tool (NONE and SWATCH unused)
    int swatch_count;
    rs_ui_rect swatch[RS_UI_TOOLBAR_MAX_SWATCHES];
    rs_ui_rect label;                      // the selected product's name, above the swatches
    float target;                          // touch target size used, pixels
} rs_ui_toolbar_layout;

typedef struct rs_ui_toolbar_state {
    int swatch_count;                      // <= RS_UI_TOOLBAR_MAX_SWATCHES
    const uint8_t (*swatch_rgb)[3];        // sRGB per swatch
    const char *const *swatch_name;        // display names (may be NULL)
    const char *region_name;               // where the brush stays ("lips"), shown by the name; NULL: anywhere
    int selected;                          // swatch index, -1 none
    float size, opacity;                   // slider values 0..1 (the viewer maps them to brush units)
    const char *size_text, *opacity_text;  // what they mean, shown on the sliders ("18 mm", "80%"); may be NULL
    float light[2];                        // light dial position in the unit disc (x right, y up); dragging
                                           // the sun moves it by the drag / RS_UI_DIAL_DRAG_PT points
    bool paint, eraser, mirror, keep_region, split, hud, help;
    bool smudge, blend;                    // the smudge or blend tool is on (the sheet names it)
    bool can_undo, can_redo;
    int mode;                              // 0 albedo, 1 diffuse, 2 full
    bool mobile;                           // pipeline: mobile (true) or reference
} rs_ui_toolbar_state;

// Pure layout for a framebuffer of fb_w x fb_h at `scale`; adapts to narrow windows (smaller targets,
// swatches that still fit). Used by rs_ui_toolbar and by tests.
void rs_ui_toolbar_layout_compute(int fb_w, int fb_h, float scale, int swatch_count, rs_ui_toolbar_layout *out);
// What is under (x, y): a tool, or RS_UI_TOOL_SWATCH with *swatch set; RS_UI_TOOL_NONE elsewhere.
rs_ui_tool rs_ui_toolbar_hit(const rs_ui_toolbar_layout *l, float x, float y, int *swatch);
// Draws the toolbar and handles its input. Sliders and the light dial update `st` in place. Returns the
// tool tapped or changed this frame (RS_UI_TOOL_NONE if none); *swatch gets the index for SWATCH.
rs_ui_tool rs_ui_toolbar(rs_ui *ui, const rs_ui_toolbar_layout *l, rs_ui_toolbar_state *st, int *swatch);

// --- GPU helpers for the viewer (GL stays in the render/UI modules) --------------------------------
// A viewer-owned RGBA8 texture.
typedef struct rs_ui_texture {
    GLuint tex, fbo;
    int width, height;
} rs_ui_texture;
// Copies `src` (RGBA8, w x h) into dst, (re)allocating it to that size.
rs_result rs_ui_texture_copy(rs_ui_texture *dst, GLuint src, int w, int h, rs_error *err);
void rs_ui_texture_free(rs_ui_texture *t);
// Uploads an RGB or RGBA image (rows top-first: draw it with uv {0, 0, 1, 1}) into dst, (re)allocating it.
rs_result rs_ui_texture_upload(rs_ui_texture *dst, const rs_image *img, rs_error *err);
// Reads the bound framebuffer's w x h pixels into a new RGBA image, rows top-first.
rs_result rs_ui_read_pixels(int w, int h, rs_image *out, rs_error *err);

#endif
