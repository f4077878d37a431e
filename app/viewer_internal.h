// viewer_internal.h — what the viewer's files share: the event queue every input source feeds (GLFW
// callbacks, the --events script, drag-and-drop), and the event script.
//
// viewer.c          the window, frame loop, input routing, actions, adaptive quality, face loading
// viewer_draw.c     the picture, toolbar, split divider, brush ring, HUD, toasts, help, screenshots
// viewer_events.c   the event queue and the event script (parser + player)
// viewer_editor.c   the product editor (custom colour, finish, coverage)
// viewer_looks.c    the look library sheet, the save dialog and the split's compared look
#ifndef RS_APP_VIEWER_INTERNAL_H
#define RS_APP_VIEWER_INTERNAL_H

#include "cli.h"
#include "core/core.h"
#include "formats/looklib.h"
#include "makeup/cosmetics.h"
#include "rouge.h"
#include "ui.h"
#include "window.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>

typedef struct GLFWwindow GLFWwindow;

// --- events: one queue, whatever produced them ------------------------------------------------------

typedef enum vw_event_type {
    VW_MOVE = 0,   // pointer (mouse) moved to x, y
    VW_BUTTON,     // mouse button `button` (0 left, 1 right, 2 middle) down/up at x, y
    VW_SCROLL,     // wheel by dy (+ = away from the user = zoom in)
    VW_KEY,        // key press (down) or release: GLFW key code + GLFW modifier bits
    VW_TOUCH,      // touch pointer `id` down/move/up at x, y
    VW_DROP,       // a file dropped on the window
    VW_CHAR,       // a character typed (Unicode code point in `key`): text fields
} vw_event_type;

typedef struct vw_event {
    vw_event_type type;
    double time_s;         // input clock (GLFW time, or the script clock)
    float x, y;            // window coordinates (screen coordinates, not framebuffer pixels)
    int button;
    bool down;
    float dy;
    int key, mods;
    int id;                // touch pointer id
    rouge_pointer_type touch;  // ROUGE_POINTER_DOWN / MOVE / UP
    char path[512];        // VW_DROP
} vw_event;

// The UI's design size in points: the toolbar fits it at scale 1; smaller windows scale the whole UI down.
#define VW_UI_DESIGN_W 800.0f
#define VW_UI_DESIGN_H 600.0f
#define VW_QUEUE_CAP 4096

typedef struct vw_queue {
    vw_event ev[VW_QUEUE_CAP];
    int head, count;
    int dropped;           // events lost to a full queue (reported on the HUD)
} vw_queue;

void vw_queue_push(vw_queue *q, const vw_event *ev);
bool vw_queue_pop(vw_queue *q, vw_event *ev);
bool vw_queue_peek(const vw_queue *q, vw_event *ev);

// --- the event script (--events FILE) ---------------------------------------------------------------
// Format (also printed by `rouge --help`): one command per line, '#' starts a comment, coordinates are
// window coordinates (as GLFW and xdotool see them), origin top-left.
//   move X Y                    pointer to (X, Y)
//   down [left|right|middle]    button press at the pointer (default left)
//   up [left|right|middle]      button release
//   click X Y                   move, down, up (left)
//   drag X0 Y0 X1 Y1 [STEPS] [left|right|middle]   press, STEPS moves (default 20), release
//   scroll DY                   mouse wheel (+ zooms in)
//   key NAME                    a key pressed and released: a character (p, [, ?, ...) or f1..f12, esc,
//                               tab, space, enter, left, right, up, down, delete, backspace, home;
//                               prefixes ctrl+, shift+, alt+ (ctrl+z, shift+[)
//   keydown NAME, keyup NAME    a key held / let go (L held while dragging moves the light)
//   touch ID down|move|up X Y   touch pointer ID (1..9): two of them pinch and pan
//   type TEXT                   characters typed (a text field: the look library's save dialog)
//   drop FILE                   as if FILE was dropped on the window
//   step S                      script clock advance per pointer event (default 1/60 s)
//   frames N                    let N frames run
//   wait S                      keep running for S seconds
//   idle                        run until the picture has refined to full quality
//   screenshot FILE [X Y W H]   wait until idle, then write the window (UI included), or the region
//                               of it, as a PNG
//   wait-for FILE               keep running until FILE exists (sync with a test driving the window
//                               from outside, e.g. xdotool)
//   loaded                      keep running until the face file has loaded completely (a preview of
//                               its first LOD levels may be on screen before)
//   slow S                      from here every frame takes at least S seconds (a slow device) and
//                               events arrive by the script clock in real time, as a hand's do: one
//                               frame gets every event that happened during it; 0 = back to normal
//   state FILE                  write what the input did so far (camera, light, editor colour, events
//                               queued and applied, render scales) as "name value" lines
//   quit                        close the viewer (exit status 0)

typedef enum vw_cmd_type {
    VW_CMD_EVENT = 0,   // push `ev` (pointer/key/touch/drop commands expand to these)
    VW_CMD_STEP,
    VW_CMD_FRAMES,
    VW_CMD_WAIT,
    VW_CMD_IDLE,
    VW_CMD_SCREENSHOT,
    VW_CMD_WAIT_FOR,
    VW_CMD_LOADED,
    VW_CMD_SLOW,
    VW_CMD_STATE,
    VW_CMD_QUIT,
} vw_cmd_type;

typedef struct vw_cmd {
    vw_cmd_type type;
    vw_event ev;        // time_s: unset; the player stamps the script clock
    bool advance;       // pointer events advance the script clock by one step
    double value;       // step/wait seconds, frame count
    int line;
    char path[512];     // screenshot, wait-for, state
    float rect[4];      // screenshot region X Y W H (window coordinates); W = 0: the whole window
} vw_cmd;

typedef struct vw_script {
    char name[256];
    vw_cmd *cmd;
    int count, next;
    double clock_s, step_s;
    // Blocking state of the player.
    int frames_left;
    double wait_until;
    bool want_idle;
    bool want_shot;
    bool done;
    // `slow`: the frame's minimum duration, and where the script clock met the wall clock.
    double slow_s, live_wall_s, live_clock_s;
    long long pushed;   // events queued by the script so far
} vw_script;

#define VW_SCRIPT_MAX_BYTES (4u << 20)
#define VW_SCRIPT_MAX_CMDS 200000

// Parses a script file; errors name the file and line ("demo.events:7: unknown command 'jump'").
rs_result vw_script_load(const char *path, vw_script *out, rs_error *err);
void vw_script_free(vw_script *s);

// What the player wants from the frame loop this frame.
typedef struct vw_script_step {
    bool quit;
    const char *screenshot;  // write the window to this path at the end of this frame
    const float *rect;       // ... this region of it (window coordinates), or all of it when rect[2] == 0
    const char *state;       // write the viewer's state to this path at the end of this frame
} vw_script_step;

// Runs commands until one blocks: pushes events into q. `settled` says the picture is at full quality
// with nothing pending, `loading` that a face file is still loading; now_s is the wall clock.
void vw_script_run(vw_script *s, vw_queue *q, bool settled, bool loading, double now_s, vw_script_step *out);

// Key name ("ctrl+z", "f11", "?") to GLFW key code + modifiers; false when unknown.
bool vw_key_from_name(const char *name, int *key, int *mods);

// --- the viewer's state (viewer.c owns it; viewer_draw.c reads it and draws) -------------------------

// The face loading on a thread: the file (or standard input for "-") fed piece by piece to a
// rouge_stream. The frame loop shows a preview face of the LOD levels that have arrived (the first at
// once, then at most one every VW_PREVIEW_EVERY_S) while the rest arrives, then the whole face once `done`.
typedef struct vw_loader {
    pthread_t thread;
    bool running;
    bool initial;                 // the face named on the command line: failing to load it is fatal
    atomic_bool done, cancel;
    char path[512];
    int fd;                       // the open file (0: standard input), closed by the reading thread
    rouge_stream *stream;
    rouge_result result;          // the reading thread's, once done
    rouge_error err;
    double t0, last_preview;
    uint32_t shown;               // splats of the face on screen made from the stream (0: none)
    bool building;                // read and decoded: the face is made of it next frame (the screen says so)
    double decoded_s;             // ... how long reading and decoding took
    rouge_progress made;          // while the face is made (rouge_face_create, its first frame included):
                                  // the stage it reports (stage NULL otherwise)
    int screens;                  // loading screens drawn between those stages (the script's `state`) ...
    char screens_log[480];        // ... as "stage@fraction;" (the last face's)
} vw_loader;

// The look library (viewer_looks.c).
#define VW_LOOKS_PAGE_MAX 32  // cards on one page of the sheet

// Where the sheet and the save dialog put things (pure: vw_looks_layout), framebuffer pixels.
typedef struct vw_looks_sheet_layout {
    rs_ui_rect sheet, title, save, bare, close, prev, next, folder;
    int cols, rows, per_page;
    rs_ui_rect card[VW_LOOKS_PAGE_MAX];  // thumbnails (the name below, compare and delete on the top right)
    rs_ui_rect dialog, field, ok, cancel;
} vw_looks_sheet_layout;

typedef struct vw_looks {
    char dir[1024];             // the library: --looks or the XDG default ("" when neither could be set)
    bool open;                  // the sheet is shown
    bool saving;                // the save dialog is shown
    bool clash;                 // the dialog's name is taken: it asks before overwriting
    bool back_to_sheet;         // the dialog was opened from the sheet (and returns there)
    char name[RS_LOOKLIB_NAME_MAX + 1];  // the name being typed
    bool exporting;             // the dialog asks where to export the picture (S) instead
    char export_path[1024];     // ... the path being typed (prefilled with a free name)
    bool export_pending;        // export_path is written once the picture is at full quality
    rs_looklib_entry *entries;  // newest first
    uint32_t count;
    int page, selected, per_page, cols;
    int confirm_delete;         // the entry whose delete waits for a second tap, -1 none
    rs_ui_texture thumb[VW_LOOKS_PAGE_MAX];
    int thumb_page;             // the page those textures show, -1 none
    char compare[RS_LOOKLIB_NAME_MAX + 1];  // the look in the split's left half (the face holds it as its
                                            // compare look); "" = the bare face
    bool compare_dirty;         // the left half must be rendered again
} vw_looks;

// One step of the adaptive quality ladder: the LOD prefix drawn and the render resolution.
typedef struct vw_rung {
    uint32_t max_splats;
    float scale;  // render pixels per framebuffer pixel (dynamic resolution)
} vw_rung;

// The product editor (viewer_editor.c): a custom product derived from the selected preset.
#define VW_SHADES_MAX 8
#define VW_SHADES_FILE "shades.txt"  // one product a line, as rs_cosmetic_format writes it

typedef struct vw_editor {
    bool open;
    bool custom;            // the brush paints `product` instead of the selected preset
    rs_cosmetic product;    // what the editor shows and edits
    float hsv[3];           // hue (degrees), saturation, value of product.rgb (kept: greys have no hue)
    bool hex_entry;         // typing a colour as six hex digits (X, or a tap on the hex field)
    char hex[8];
    int hex_len;
    rs_cosmetic shades[VW_SHADES_MAX];  // "my shades": kept in VW_SHADES_FILE in the look library's folder
    int shade_count;
} vw_editor;

// Where the editor puts things (pure, for tests), framebuffer pixels.
typedef struct vw_editor_layout {
    rs_ui_rect panel, close, sv, hue, swatch, hex, finish[RS_FINISH_COUNT], coverage;
    rs_ui_rect shades[VW_SHADES_MAX], shade_add;  // the "my shades" row
} vw_editor_layout;

typedef struct vw_viewer {
    const rs_cli *cli;
    rouge_error record_err;  // the first failed write of the --record file (the exit reports it)
    rs_window *window;
    GLFWwindow *win;
    rs_ui *ui, *scene_ui;  // the interactive UI, and a second list for the picture (screenshots without UI)
    vw_queue queue;
    vw_script script;
    bool have_script;

    // The face: everything rendered and painted goes through the public API, as in any host.
    rouge_face *face;
    rouge_stats info;           // its splat counts, LOD levels and size (refreshed each frame)
    char face_path[512];
    vw_loader load;
    bool partial;  // the face shown is a preview of a file still loading: painting waits for the rest

    // Window (screen coordinates) and framebuffer (pixels).
    int win_w, win_h, fb_w, fb_h;
    float px_per_pt;  // framebuffer pixels per window coordinate
    float ui_scale;
    bool fullscreen;
    int saved_pos[2], saved_size[2];

    // Camera, light and what is shown.
    rouge_view view;            // view.env points at env_name
    char env_name[600];         // the lighting as chosen (a bundled name, "paper" or a .rse path)
    char env_dir[600];          // <bin>/../share/rouge/env
    float light_dial[2];
    bool split, hud, help, paint_mode;
    float split_frac;

    // Brush.
    int cosmetic;  // preset index
    float size_rel, opacity;
    bool eraser, mirror;
    rouge_tool tool;  // J: smudge, Shift+J: blend (ROUGE_TOOL_PAINT: the product or the eraser)
    bool any_region;  // K: paint anywhere instead of keeping to the product's region

    // Pointer. Gestures are measured in window coordinates (wx, wy: the events' own), so a render scale
    // that changes mid-drag cannot change what the drag means; mx, my are the same point for the UI.
    float wx, wy;               // window coordinates
    float mx, my;               // framebuffer pixels
    bool l_held;                // L is down (from the queued key events, never sampled)
    int face_pointers;          // pointers the face holds down (painting, touch gestures)
    float face_scale;           // render pixels per framebuffer pixel the face's gesture is measured in
    bool ui_input_only;         // an input-only UI pass (rs_ui_end_input): draw nothing costly
    long long events_applied;   // events taken from the queue and routed (the `state` script command)
    float scale_lo, scale_hi;   // render scales drawn since the last `state`
    bool ui_owns[3];            // a press of button b went to the UI
    bool scene_owns[3];         // ... or to the scene
    bool light_drag;            // L held at press: the left drag moves the light
    bool face_drag;             // ... else in paint mode it went to the face; else it orbits
    bool ui_pressed, ui_released;
    bool ring_valid;
    float ring_px;              // brush ring radius on screen
    bool ring_moved;
    bool pointer_outside;       // the mouse left the window (no brush ring)

    // Rendering state.
    bool dirty_view;            // camera/light/mode changed: both halves of the split are stale
    bool dirty_makeup;          // the made-up half is stale
    vw_rung rungs[ROUGE_MAX_LODS + 4];  // interactive quality ladder, best first
    int rung_count, rung;       // the rung interactive frames use (adapted to the frame-time budget)
    vw_rung rendered;              // quality of the picture on screen (max_splats 0 = full)
    bool rendered_full;
    float render_scale;         // render pixels per framebuffer pixel of the picture on screen
    rs_ui_texture before;       // bare face for the split view
    double last_input_s;
    long long frame_no, last_input_frame;
    double frame_ms_avg;        // frame time of rendered frames, smoothed (HUD)
    bool rendered_this_frame;

    // Files.
    vw_looks looks;
    vw_editor editor;
    char toast[256];
    bool toast_error;
    double toast_until;
    uint8_t swatch_rgb[RS_UI_TOOLBAR_MAX_SWATCHES][3];  // the toolbar's swatches, rebuilt each frame
    char swatch_names[RS_UI_TOOLBAR_MAX_SWATCHES][RS_COSMETIC_NAME_MAX];
    const char *swatch_name_ptr[RS_UI_TOOLBAR_MAX_SWATCHES];
    char size_text[24], opacity_text[24];  // the sliders' values as shown ("18 mm", "80%")
    bool quit;
} vw_viewer;

// Shortcuts: one table for --help and the help overlay.
typedef struct vw_shortcut {
    const char *keys, *what;
} vw_shortcut;
extern const vw_shortcut vw_shortcuts[];
extern const size_t vw_shortcut_count;

// viewer.c
double vw_now(void);
void vw_toast(vw_viewer *v, bool error, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
// Lighting environment by name (bundled, "paper" or a .rse file); false (and a toast) when it cannot load.
bool vw_set_env(vw_viewer *v, const char *name);
float vw_size_to_slider(float size_rel);
// Where the current product's brush stays ("lips", "eyes", "skin"), NULL when it paints anywhere.
const char *vw_brush_region(const vw_viewer *v);
// The face under framebuffer pixel (x, y) of the picture as shown, whatever resolution it was rendered
// at; the brush radius in framebuffer pixels.
bool vw_pick(vw_viewer *v, float x_px, float y_px, rouge_pick *out);

// Loads a look file into the face (undo history restarts); toasts and returns failures.
rs_result vw_load_look_file(vw_viewer *v, const char *path, rs_error *err);

// viewer_looks.c
void vw_looks_layout(int fb_w, int fb_h, float scale, vw_looks_sheet_layout *out);
void vw_looks_init(vw_viewer *v);
void vw_looks_free(vw_viewer *v);
void vw_looks_open(vw_viewer *v);           // Ctrl+O, the top bar's folder
void vw_looks_begin_save(vw_viewer *v);     // Ctrl+S, the top bar's save
void vw_looks_begin_export(vw_viewer *v);   // S, the top bar's camera: asks where, prefilled
// Writes the face's last frame (the current look, full quality, no UI or split) to export_path and the
// look beside it (.look); says where in a toast.
void vw_looks_export(vw_viewer *v);
void vw_looks_compare_bare(vw_viewer *v);   // the split's left half shows the bare face
bool vw_looks_modal(const vw_viewer *v);    // the sheet or the dialog is up: the toolbar steps aside
bool vw_looks_key(vw_viewer *v, int key, int mods);  // true when the sheet/dialog took the key
void vw_looks_char(vw_viewer *v, unsigned codepoint);
void vw_looks_draw(vw_viewer *v);           // into v->ui, after the rest; handles its taps
void vw_looks_forget_face(vw_viewer *v);    // another face was opened
bool vw_looks_comparing(const vw_viewer *v);

// viewer.c: the brush from the current product, size, opacity, eraser, mirror, region toggle.
void vw_apply_brush(vw_viewer *v);

// viewer_editor.c
void vw_editor_layout_compute(const rs_ui_toolbar_layout *toolbar, float scale, vw_editor_layout *out);
const rs_cosmetic *vw_current_cosmetic(const vw_viewer *v);  // the custom product or the selected preset
void vw_editor_sync(vw_viewer *v);     // show the selected preset (when no custom product is in use)
void vw_editor_toggle(vw_viewer *v);   // C, the swatch row's Edit chip
void vw_editor_load_shades(vw_viewer *v);  // "my shades" from the look library's folder (after vw_looks_init)
bool vw_editor_key(vw_viewer *v, int key, int mods);  // true when the editor took the key
bool vw_editor_char(vw_viewer *v, unsigned codepoint);
void vw_editor_draw(vw_viewer *v, const rs_ui_toolbar_layout *toolbar);  // into v->ui; handles its input

// viewer_draw.c
// The rendered picture (and the split's bare half) filling the window, into `ui`'s list.
void vw_draw_picture(vw_viewer *v, rs_ui *ui);
// Begins v->ui's frame and draws the toolbar and overlays; returns the tool tapped (RS_UI_TOOL_NONE if
// none) with the toolbar state after the frame's input in *st and the swatch in *swatch.
rs_ui_tool vw_draw_ui(vw_viewer *v, rs_ui_toolbar_state *st, int *swatch);
// One frame of the loading screen alone into the bound framebuffer (v->ui's list; the caller swaps): what a
// face being made reports (v->load.made) between its stages.
void vw_draw_loading_frame(vw_viewer *v);
// Writes the bound framebuffer (or a region, window coordinates, when rect[2] > 0) as an RGB PNG.
void vw_write_png(vw_viewer *v, const char *path, const float *rect);

#endif
