// viewer.c — `rouge view`: the face in a GLFW window with a mobile-style makeup toolbar.
//
// One frame: poll GLFW (callbacks only queue events), let the --events script queue its events, route
// each event to the UI or the scene (orbit / paint / pan / zoom / light), re-render the face only when
// something changed (coarser LOD while the user interacts, full quality once idle), draw the picture, the
// toolbar and overlays with app/ui.h, swap. The face (rendering, painting, picking, looks, stroke
// recording) is a rouge_face of the public API (rouge.h), as in any host: `rouge render` and the viewer
// cannot disagree. This file maps what a person does onto it.
#define _POSIX_C_SOURCE 200809L
#include "app.h"
#include "viewer_internal.h"
#include "formats/env_lookup.h"
#include "ui.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <time.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// Adaptive quality: while the user interacts, pick the LOD whose frame time fits this budget; once no
// input arrived for SETTLE_S (and SETTLE_FRAMES frames), render one frame at full quality.
#define BUDGET_MS 40.0
#define SETTLE_S 0.25
#define SETTLE_FRAMES 3
#define ORBIT_DEG_PER_PT 0.35f
#define ZOOM_STEP 1.12f
#define SIZE_MIN_REL 0.02f    // brush diameter / face height at the size slider's ends (log scale)
#define SIZE_MAX_REL 0.40f
#define LIGHT_DIAL_DEG 85.0f  // the light dial's rim is this far from the view axis
#define TOAST_S 3.5
#define DENSE_SPLATS 60000u   // below this many splats a face looks sparse: lower the resolution first

// --- shortcuts: one table for --help and the help overlay (viewer_internal.h) ----------------------------

// Short enough for the overlay at 800 px wide; --help adds the details below the table.
const vw_shortcut vw_shortcuts[] = {
    {"Left drag", "orbit; in paint mode: paint"},
    {"Right drag, scroll", "pan, zoom (touch: two fingers)"},
    {"L+drag, sun dial", "move the light (environments: turn them)"},
    {"G, Shift+G, top chips", "next / previous lighting environment"},
    {"Arrows, +/-, 0", "orbit, zoom, reset camera and light"},
    {"Shift+1, 2, 3", "zoom to the eyes, the lips, a cheek"},
    {"P", "paint / view mode"},
    {"1-9, Tab", "pick a cosmetic; Tab: next"},
    {"[ ], Shift+[ ]", "brush size, opacity"},
    {"E, M", "eraser, mirror painting"},
    {"J, Shift+J", "smudge, blend the makeup on the face"},
    {"K", "keep the brush to its region"},
    {"C", "product editor: colour, finish, coverage"},
    {"V (in the editor)", "eyedropper: the face's colour under the pointer"},
    {"Ctrl+Z, Ctrl+Y", "undo, redo"},
    {"Delete", "clear all makeup"},
    {"A, D, F", "albedo / diffuse / full"},
    {"R", "mobile / reference pipeline"},
    {"B", "split: bare face vs current look"},
    {"I", "HUD: frame time, LOD"},
    {"S", "export the picture and its look (asks where)"},
    {"Ctrl+S, Ctrl+O", "save a look / the look library"},
    {"F11, Ctrl+Q", "full screen, quit"},
    {"H or ?, Esc", "help; Esc closes help/split"},
    {"Drop a .rsf file", "open another face"},
};
const size_t vw_shortcut_count = RS_COUNT_OF(vw_shortcuts);

void rs_app_print_viewer_help(FILE *f)
{
    fprintf(f, "viewer controls (rouge view):\n");
    for (size_t i = 0; i < vw_shortcut_count; i++) fprintf(f, "  %-26s %s\n", vw_shortcuts[i].keys, vw_shortcuts[i].what);
    fprintf(f, "  Middle drag pans too; Shift+Tab picks the previous cosmetic; Ctrl+Shift+Z redoes; Esc closes\n"
               "  the help, then the split. The toolbar does all of it by touch: swatches pick a cosmetic (and\n"
               "  paint mode), the right rail holds the light dial (drag the sun: the light follows geared down,\n"
               "  120 points of drag from the centre to the rim), brush size (mm) and opacity (%%); drag the split's\n"
               "  divider to compare. Ctrl+S saves the look under a name in the look library (--looks DIR;\n"
               "  see 'look library' below), Ctrl+O opens the library: tap a look to load it, its split icon to\n"
               "  compare it with the current one side by side, its bin twice to delete it. --look FILE loads a\n"
               "  look file at start.\n"
               "  While orbiting or painting a coarser LOD (then a lower resolution) keeps frames near %.0f ms;\n"
               "  the picture refines to full quality when idle.\n",
            BUDGET_MS);
    fprintf(f,
            "\nevent scripts (rouge view --events FILE): one command per line, '#' comments, window coordinates\n"
            "  move X Y | down [left|right|middle] | up [BUTTON] | click X Y | drag X0 Y0 X1 Y1 [STEPS] [BUTTON]\n"
            "  scroll DY | key NAME (p, [, ?, ctrl+z, shift+tab, f11, esc, ...) | type TEXT | touch ID down|move|up X Y\n"
            "  drop FILE | step S (script clock per pointer event, default 1/60 s) | frames N | wait S\n"
            "  idle (until full quality) | screenshot FILE [X Y W H] (PNG of the window or a region, after\n"
            "  idle) | wait-for FILE (until FILE exists) | loaded (until the face file has loaded) | quit\n"
            "  keydown NAME, keyup NAME (a key held: L+drag) | slow S (every frame takes S seconds, events arrive\n"
            "  in real time: a slow device) | state FILE (camera, light, editor colour, events applied)\n");
}

// The viewer's own options: --events, --bench-orbit, and whether --size / --pipeline were given.
typedef struct vw_options {
    const char *events;
    int bench_orbit;
    bool size_set, pipeline_set;
} vw_options;

static vw_options viewer_options(const rs_cli *c)
{
    return (vw_options){c->events, c->bench_orbit, c->size_set, c->pipeline_set};
}

// --- small shared helpers --------------------------------------------------------------------------------

// A message over the swatch sheet for a few seconds (errors longer, in red): how file results reach a
// person without a terminal.
void vw_toast(vw_viewer *v, bool error, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(v->toast, sizeof v->toast, fmt, ap);
    va_end(ap);
    v->toast_error = error;
    v->toast_until = glfwGetTime() + (error ? 3 * TOAST_S : TOAST_S);
}

float vw_size_to_slider(float size_rel)
{
    float v = logf(size_rel / SIZE_MIN_REL) / logf(SIZE_MAX_REL / SIZE_MIN_REL);
    return RS_CLAMP(v, 0.0f, 1.0f);
}

static float slider_to_size(float v) { return SIZE_MIN_REL * powf(SIZE_MAX_REL / SIZE_MIN_REL, v); }

// --- the face's view ---------------------------------------------------------------------------------------

// Hands the view as the viewer holds it to the face: picks and strokes then see the camera on screen.
static void push_view(vw_viewer *v)
{
    if (!v->face) return;
    rouge_error e = {0};
    v->view.env = v->env_name;
    if (rouge_face_set_view(v->face, &v->view, &e) != ROUGE_OK) vw_toast(v, true, "%s", e.msg);
}

// Pointer positions are framebuffer pixels; the picture may be rendered at a lower resolution
// (render_scale) while the user interacts, and the face works in the pixels of its last frame.
bool vw_pick(vw_viewer *v, float x, float y, rouge_pick *out)
{
    if (!v->face || !rouge_face_pick(v->face, x * v->render_scale, y * v->render_scale, out)) return false;
    out->brush_radius_px /= v->render_scale;
    return true;
}

// --- brush and view state -----------------------------------------------------------------------------

void vw_apply_brush(vw_viewer *v)
{
    if (!v->face) return;
    // The product as the public brush: the preset, and what the editor changed about it.
    const rs_cosmetic *c = vw_current_cosmetic(v), *preset = rs_cosmetic_get((uint32_t)v->cosmetic);
    rouge_brush b = {.cosmetic = preset->name, .size = v->size_rel, .opacity = v->opacity,
                     .eraser = v->eraser && v->tool == ROUGE_TOOL_PAINT, .mirror = v->mirror,
                     .any_region = v->any_region, .tool = v->tool};
    if (v->editor.custom) {
        if (memcmp(c->rgb, preset->rgb, 3) != 0)
            for (int i = 0; i < 3; i++) b.color[i] = c->rgb[i] / 255.0f, b.color[3] = 1;
        if (c->m != preset->m || c->rho_s != preset->rho_s || c->coat != preset->coat || c->shimmer != preset->shimmer)
            b.finish = (rouge_finish)(rs_cosmetic_finish(c) + 1);
        if (c->coverage != preset->coverage) b.coverage = c->coverage > 0 ? c->coverage : -1.0f;
    }
    rouge_error e = {0};
    if (rouge_face_set_brush(v->face, &b, &e) != ROUGE_OK) vw_toast(v, true, "%s", e.msg);
    // A preview's makeup would be lost when the whole face replaces it: painting waits for the rest.
    rouge_face_set_painting(v->face, v->paint_mode && !v->partial);
}

// Where the current product's brush stays ("lips"), NULL when it paints anywhere.
const char *vw_brush_region(const vw_viewer *v)
{
    rs_cosmetic_region r = rs_cosmetic_region_of(vw_current_cosmetic(v));
    if (v->any_region || r == RS_COSMETIC_REGION_ANY) return NULL;
    return rs_cosmetic_region_name(r);
}

static void toggle_region(vw_viewer *v)
{
    v->any_region = !v->any_region;
    vw_apply_brush(v);
    const char *r = vw_brush_region(v);
    if (r) vw_toast(v, false, "Brush keeps to the %s (K: anywhere)", r);
    else vw_toast(v, false, "Brush paints anywhere (K: keep to the product's region)");
}

// J / Shift+J and the rail's button: the smudge or blend tool on, or (the same again) back to the product.
static void toggle_tool(vw_viewer *v, rouge_tool t)
{
    v->tool = v->tool == t ? ROUGE_TOOL_PAINT : t;
    v->eraser = false;
    v->paint_mode = true;
    vw_apply_brush(v);
    if (v->tool == ROUGE_TOOL_SMUDGE)
        vw_toast(v, false, "Smudge: drag from the makeup to carry it along");
    else if (v->tool == ROUGE_TOOL_BLEND)
        vw_toast(v, false, "Blend: brush over an edge to soften it");
}

static void select_cosmetic(vw_viewer *v, int i)
{
    int n = (int)rs_cosmetic_count();
    v->cosmetic = ((i % n) + n) % n;
    v->editor.custom = false;  // a preset picked: the editor shows it until edited
    vw_editor_sync(v);
    const rs_cosmetic *c = rs_cosmetic_get((uint32_t)v->cosmetic);
    // A product comes with its own brush (a liner is fine, a foundation broad), as in mobile makeup apps.
    v->size_rel = RS_CLAMP(c->size_rel, SIZE_MIN_REL, SIZE_MAX_REL);
    v->opacity = c->opacity;
    v->eraser = false;
    v->tool = ROUGE_TOOL_PAINT;
    v->paint_mode = true;
    vw_apply_brush(v);
}

static bool env_lit(const vw_viewer *v) { return !rs_env_is_paper(v->env_name); }

// Under an environment the dial turns the world around the face (its sideways position is the
// rotation, a half turn at the rim); under `paper` it points the key light.
static void light_from_dial(vw_viewer *v)
{
    if (env_lit(v)) {
        v->view.env_rotation_deg = v->light_dial[0] * 180.0f;
    } else {
        v->view.key.yaw_deg = v->light_dial[0] * LIGHT_DIAL_DEG;
        v->view.key.pitch_deg = v->light_dial[1] * LIGHT_DIAL_DEG;
    }
    v->dirty_view = true;
}

static void dial_from_light(vw_viewer *v)
{
    if (env_lit(v)) {
        v->light_dial[0] = RS_CLAMP(v->view.env_rotation_deg / 180.0f, -1.0f, 1.0f), v->light_dial[1] = 0;
        return;
    }
    float x = v->view.key.yaw_deg / LIGHT_DIAL_DEG, y = v->view.key.pitch_deg / LIGHT_DIAL_DEG;
    float d = sqrtf(x * x + y * y);
    if (d > 1) x /= d, y /= d;
    v->light_dial[0] = x, v->light_dial[1] = y;
}

// Switches the lighting to environment `name` (a bundled name, "paper" or a .rse file); on failure the
// current one stays and a toast says why.
bool vw_set_env(vw_viewer *v, const char *name)
{
    if (strlen(name) >= sizeof v->env_name) {
        vw_toast(v, true, "environment name too long: %.60s...", name);
        return false;
    }
    rouge_error err = {0};
    if (v->face) {
        // The face loads (and checks) it; on failure its previous environment stays.
        rouge_view t = v->view;
        t.env = name;
        if (rouge_face_set_view(v->face, &t, &err) != ROUGE_OK) {
            vw_toast(v, true, "%s", err.msg);
            return false;
        }
    } else if (!rs_env_is_paper(name)) {
        // No face yet (start-up): check that it loads, so a bad --env fails at once.
        rs_env *e = NULL;
        rs_error e2 = {0};
        rs_result r = rs_env_open(name, v->env_dir, &e, &e2);
        rs_env_destroy(e);
        if (r) {
            vw_toast(v, true, "%s", e2.msg);
            return false;
        }
    }
    snprintf(v->env_name, sizeof v->env_name, "%s", name);
    v->view.env = v->env_name;
    dial_from_light(v);
    v->dirty_view = true;
    return true;
}

static void next_env(vw_viewer *v, int step)
{
    int n = rouge_environment_count(), cur = 0;
    for (int i = 0; i < n; i++)
        if (strcmp(rouge_environment_name(i), v->env_name) == 0) cur = i;
    for (int k = 1; k < n; k++)  // skips one that fails to load
        if (vw_set_env(v, rouge_environment_name(((cur + step * k) % n + n) % n))) break;
}

static void reset_camera(vw_viewer *v)
{
    const rs_cli *c = v->cli;
    v->view.yaw_deg = c->view_set[0] ? c->view.yaw_deg : 0;
    v->view.pitch_deg = c->view_set[1] ? c->view.pitch_deg : 0;
    // Slightly smaller than `render`'s default so the chin clears the swatch sheet.
    v->view.zoom = c->view_set[2] ? c->view.zoom : 0.85f;
    v->view.pan[0] = v->view.pan[1] = 0;
    v->dirty_view = true;
}

// Drags in window coordinates (points): the same drag turns the face as far at any render scale, LOD
// or pixel density. Drag right turns the face to the right (the camera goes left); drag down shows it
// from above.
static void orbit(vw_viewer *v, float dx_pt, float dy_pt)
{
    v->view.yaw_deg = fmodf(v->view.yaw_deg - dx_pt * ORBIT_DEG_PER_PT, 360.0f);
    v->view.pitch_deg = RS_CLAMP(v->view.pitch_deg + dy_pt * ORBIT_DEG_PER_PT, -80.0f, 80.0f);
    v->dirty_view = true;
}

static void pan(vw_viewer *v, float dx_pt, float dy_pt)
{
    v->view.pan[0] += dx_pt / (float)v->win_h;
    v->view.pan[1] += dy_pt / (float)v->win_h;
    v->dirty_view = true;
}

// Zoom by `factor` keeping the point under (cx, cy) fixed on screen (pinch / wheel at the cursor).
static void zoom_at(vw_viewer *v, float factor, float cx, float cy)
{
    float z0 = v->view.zoom, z1 = RS_CLAMP(z0 * factor, 0.3f, 12.0f);
    if (z1 == z0) return;
    // The picture scales about the pan-shifted centre; move the pan so the cursor's point stays put.
    float ox = (cx - (float)v->fb_w * 0.5f) / (float)v->fb_h, oy = (cy - (float)v->fb_h * 0.5f) / (float)v->fb_h;
    float s = z1 / z0;
    v->view.pan[0] = ox - (ox - v->view.pan[0]) * s;
    v->view.pan[1] = oy - (oy - v->view.pan[1]) * s;
    v->view.zoom = z1;
    v->dirty_view = true;
}

static void mark_input(vw_viewer *v)
{
    v->last_input_s = glfwGetTime();
    v->last_input_frame = v->frame_no;
}

// --- the face: load (in a thread, with a loading screen), open, swap -------------------------------------

#define VW_READ_BYTES (256u << 10)
#define VW_PREVIEW_EVERY_S 0.5  // a slow stream refines at most this often (each face opened costs a renderer)
#define VW_PREVIEW_AFTER_S 0.1  // a local 600k face loads in ~40 ms: no preview for it

// Reads the open file (or standard input) into the stream; the frame loop makes preview faces from it
// as LOD levels complete. Standard input is polled so that quitting cancels a stalled stream.
static void *load_main(void *arg)
{
    vw_loader *l = arg;
    uint8_t *buf = malloc(VW_READ_BYTES);
    rouge_result r = ROUGE_OK;
    if (!buf) {
        l->err.code = r = ROUGE_ERR_NOMEM;
        snprintf(l->err.msg, sizeof l->err.msg, "%s: out of memory", l->path);
    }
    while (!r && !atomic_load(&l->cancel) && !rouge_stream_get_progress(l->stream).complete) {
        if (l->fd == 0) {
            struct pollfd pfd = {.fd = 0, .events = POLLIN};
            if (poll(&pfd, 1, 100) == 0) continue;
        }
        ssize_t n = read(l->fd, buf, VW_READ_BYTES);
        if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (n < 0) {
            l->err.code = r = ROUGE_ERR_IO;
            snprintf(l->err.msg, sizeof l->err.msg, "%s: read failed: %s", l->path, strerror(errno));
        }
        if (n <= 0) break;
        r = rouge_stream_feed(l->stream, buf, (size_t)n, &l->err);
    }
    if (!r && !rouge_stream_get_progress(l->stream).complete) {
        l->err.code = r = ROUGE_ERR_IO;
        snprintf(l->err.msg, sizeof l->err.msg, "%s: %s", l->path,
                 atomic_load(&l->cancel) ? "loading cancelled" : "the file ends early (truncated)");
    }
    free(buf);
    if (l->fd > 0) close(l->fd);
    l->result = r;
    atomic_store(&l->done, true);
    return NULL;
}

static rs_result load_start(vw_viewer *v, const char *path, rs_error *err)
{
    vw_loader *l = &v->load;
    if (l->running) return rs_fail(err, RS_ERR_ARG, "already loading %s", l->path);
    memset(l, 0, sizeof *l);
    snprintf(l->path, sizeof l->path, "%s", path);
    l->t0 = glfwGetTime();
    atomic_store(&l->done, false);
    atomic_store(&l->cancel, false);
    bool in = !strcmp(path, "-");
    struct stat st;
    l->fd = in ? 0 : open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (l->fd < 0) return rs_fail(err, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    rs_result r = RS_OK;
    if (!in && fstat(l->fd, &st) != 0) r = rs_fail(err, RS_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    // Regular files only (or an explicit "-"): a directory, /dev/zero or a FIFO would hang or never end.
    else if (!in && !S_ISREG(st.st_mode)) r = rs_fail(err, RS_ERR_IO, "%s: not a regular file", path);
    rouge_error e = {0};
    if (!r && rouge_stream_create(in ? "(standard input)" : path, in ? 0 : (uint64_t)st.st_size, &l->stream, &e))
        r = rs_app_error((rouge_result)e.code, &e, err);
    if (!r && pthread_create(&l->thread, NULL, load_main, l) != 0)
        r = rs_fail(err, RS_ERR_NOMEM, "cannot start a loader thread");
    if (r) {
        rouge_stream_destroy(l->stream);
        l->stream = NULL;
        if (l->fd > 0) close(l->fd);
        return r;
    }
    l->running = true;
    return RS_OK;
}

// Joins a finished loader; false while it still runs. The stream stays for the face to take.
static bool load_finished(vw_viewer *v)
{
    vw_loader *l = &v->load;
    if (!l->running || !atomic_load(&l->done)) return false;
    pthread_join(l->thread, NULL);
    l->running = false;
    return true;
}

// Stops a load that is still running (the window closes) and drops what it read.
static void load_abort(vw_viewer *v)
{
    vw_loader *l = &v->load;
    if (l->running) {
        atomic_store(&l->cancel, true);
        while (!load_finished(v)) nanosleep(&(struct timespec){0, 10 * 1000 * 1000}, NULL);
    }
    rouge_stream_destroy(l->stream);
    l->stream = NULL;
}

// The interactive quality ladder: coarser LOD prefixes first (while the face keeps a dense enough look),
// then lower render resolutions (per-pixel passes dominate on software rasterisers), then both.
static void build_rungs(vw_viewer *v)
{
    const rouge_stats *h = &v->info;
    // No rung draws more splats than the picture at rest (--max-splats): moving, the face once drew
    // half again as many as at rest.
    uint32_t full = v->cli->view.max_splats ? RS_MIN(v->cli->view.max_splats, h->splats) : h->splats;
    uint32_t nl = 0;
    uint32_t lods[ROUGE_MAX_LODS];
    lods[nl++] = full;
    for (uint32_t i = 0; i < h->lod_count && nl < ROUGE_MAX_LODS; i++)
        if (h->lods[i] < full) lods[nl++] = h->lods[i];
    uint32_t floor_n = RS_MIN(full, RS_MAX(DENSE_SPLATS, 1u));
    uint32_t fi = 0;
    while (fi + 1 < nl && lods[fi + 1] >= floor_n) fi++;
    int n = 0;
    for (uint32_t i = 0; i <= fi; i++) v->rungs[n++] = (vw_rung){lods[i], 1.0f};
    v->rungs[n++] = (vw_rung){lods[fi], 0.75f};
    v->rungs[n++] = (vw_rung){lods[fi], 0.5f};
    for (uint32_t i = fi + 1; i < nl; i++) v->rungs[n++] = (vw_rung){lods[i], 0.5f};
    v->rungs[n++] = (vw_rung){lods[nl - 1], 0.35f};
    v->rung_count = n;
    // First guess: about a quarter of the splats at full resolution; the controller adapts from there.
    v->rung = 0;
    while (v->rung + 1 <= (int)fi && v->rungs[v->rung].max_splats > full / 4) v->rung++;
}

static void face_close(vw_viewer *v)
{
    rouge_face_destroy(v->face);
    v->face = NULL;
}

// Makes a face from the loader's stream the face on screen: a preview of the LOD levels so far, or the
// whole face. On failure the previous face stays.
static void update_window_size(vw_viewer *v);
static void apply_rung(vw_viewer *v, vw_rung q);

// rouge_face_create's progress while a face is made (seconds: shaders, shadow map, the first frame): the
// loading screen, drawn and shown at each stage. Closing the window cancels.
static bool make_progress(void *user, const rouge_progress *p)
{
    vw_viewer *v = user;
    vw_loader *l = &v->load;
    l->made = *p;
    if (p->step == 1) l->screens = 0, l->screens_log[0] = '\0';
    size_t n = strlen(l->screens_log);
    snprintf(l->screens_log + n, sizeof l->screens_log - n, "%s@%.3f;", p->stage, p->fraction);
    l->screens++;
    glfwPollEvents();  // input goes to the queue; the window stays responsive
    update_window_size(v);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, v->fb_w, v->fb_h);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    if (v->face) {  // a preview stays on screen while the whole face is made
        rs_ui_begin(v->scene_ui, v->fb_w, v->fb_h, v->ui_scale, &(rs_ui_input){.x = -1, .y = -1});
        vw_draw_picture(v, v->scene_ui);
        rs_ui_end(v->scene_ui);
    }
    vw_draw_loading_frame(v);
    glfwSwapBuffers(v->win);
    return !glfwWindowShouldClose(v->win);
}

// Makes the face of the stream, with its first frame (at the full-quality view the next frame asks for,
// so that frame only copies it out) shown stage by stage on the loading screen.
static rs_result face_open(vw_viewer *v, rs_error *err)
{
    rouge_face *f = NULL;
    rouge_error e = {0};
    apply_rung(v, (vw_rung){v->cli->view.max_splats, 1.0f});
    v->view.env = v->env_name;
    rouge_result r = rouge_face_create(&(rouge_face_desc){.stream = v->load.stream, .view = &v->view,
                                                          .env_dir = v->env_dir[0] ? v->env_dir : NULL,
                                                          .manual_navigation = true, .first_frame = true,
                                                          .progress_stage = make_progress, .progress_user = v},
                                       &f, &e);
    v->load.made.stage = NULL;
    if (!r && v->cli->record) r = rouge_face_record_strokes(f, v->cli->record, &e);
    if (r) {
        rouge_face_destroy(f);
        return rs_app_error(r, &e, err);
    }
    face_close(v);
    vw_looks_forget_face(v);
    v->face = f;
    v->info = rouge_face_stats(f);
    snprintf(v->face_path, sizeof v->face_path, "%s", v->load.path);
    vw_apply_brush(v);
    build_rungs(v);
    v->rendered_full = false;
    v->dirty_view = v->dirty_makeup = true;
    return RS_OK;
}

rs_result vw_load_look_file(vw_viewer *v, const char *path, rs_error *err)
{
    rouge_error e = {0};
    rouge_result r = rouge_face_load_look(v->face, path, &e);
    if (r != ROUGE_OK) {
        vw_toast(v, true, "%s", e.msg);
        return rs_app_error(r, &e, err);
    }
    v->dirty_makeup = true;
    return RS_OK;
}

// --- actions (toolbar and keys share them) --------------------------------------------------------------

static void do_undo(vw_viewer *v, bool redo)
{
    if (redo ? rouge_face_redo(v->face) : rouge_face_undo(v->face)) v->dirty_makeup = true;
}

static void do_clear(vw_viewer *v)
{
    rouge_error e = {0};
    if (rouge_face_clear(v->face, &e) != ROUGE_OK) vw_toast(v, true, "%s", e.msg);
    v->dirty_makeup = true;
}

static void set_mode(vw_viewer *v, rouge_mode m)
{
    v->view.mode = m;
    v->dirty_view = true;
}

static void toggle_fullscreen(vw_viewer *v)
{
    GLFWmonitor *mon = glfwGetPrimaryMonitor();
    if (!v->fullscreen && mon) {
        const GLFWvidmode *mode = glfwGetVideoMode(mon);
        glfwGetWindowPos(v->win, &v->saved_pos[0], &v->saved_pos[1]);
        glfwGetWindowSize(v->win, &v->saved_size[0], &v->saved_size[1]);
        if (mode) glfwSetWindowMonitor(v->win, mon, 0, 0, mode->width, mode->height, mode->refreshRate);
        v->fullscreen = true;
    } else if (v->fullscreen) {
        glfwSetWindowMonitor(v->win, NULL, v->saved_pos[0], v->saved_pos[1], v->saved_size[0], v->saved_size[1], 0);
        v->fullscreen = false;
    }
}

static bool at_full_quality(const vw_viewer *v);

// B and the split button: always the bare face against the current look (a look from the library is
// compared from its card on the sheet).
static void toggle_split(vw_viewer *v)
{
    v->split = !v->split;
    if (v->split) vw_looks_compare_bare(v);
    v->dirty_view = true;
}

// Shift+1-3: the eyes, the lips or a cheek fill the view (rouge_face_target on the face's regions); the
// camera keeps its angle, so a three-quarter view zooms to the cheek that faces it.
static void zoom_to_region(vw_viewer *v, int which)
{
    static const char *const regions[] = {"eyelid", "lips", "cheek"};
    // Both eyes together are wide: they take more of the view than one lip or cheek would.
    static const float fill[] = {0.7f, 0.0f, 0.0f};
    rouge_error e = {0};
    if (rouge_face_set_view(v->face, &v->view, &e) != ROUGE_OK ||
        rouge_face_target(v->face, regions[which], fill[which], &e) != ROUGE_OK) {
        vw_toast(v, true, "%s", e.msg);
        return;
    }
    rouge_view t = rouge_face_get_view(v->face);
    v->view.zoom = t.zoom;
    v->view.pan[0] = t.pan[0], v->view.pan[1] = t.pan[1];
    v->dirty_view = true;
}

static void key_action(vw_viewer *v, int key, int mods)
{
    if (vw_looks_key(v, key, mods)) return;  // the look library's sheet or dialog has the keyboard
    if (vw_editor_key(v, key, mods)) return;  // the product editor's keys (X, N, comma, period, V, Esc)
    bool ctrl = mods & GLFW_MOD_CONTROL, shift = mods & GLFW_MOD_SHIFT;
    int n = rouge_cosmetic_count();
    switch (key) {
    case GLFW_KEY_C: vw_editor_toggle(v); break;
    case GLFW_KEY_P: v->paint_mode = !v->paint_mode, vw_apply_brush(v); break;
    case GLFW_KEY_E: v->eraser = !v->eraser, v->tool = ROUGE_TOOL_PAINT, v->paint_mode = true, vw_apply_brush(v); break;
    case GLFW_KEY_J: toggle_tool(v, shift ? ROUGE_TOOL_BLEND : ROUGE_TOOL_SMUDGE); break;
    case GLFW_KEY_M: v->mirror = !v->mirror, vw_apply_brush(v); break;
    case GLFW_KEY_K: toggle_region(v); break;
    case GLFW_KEY_Z: if (ctrl) do_undo(v, shift); break;
    case GLFW_KEY_Y: if (ctrl) do_undo(v, true); break;
    case GLFW_KEY_DELETE: do_clear(v); break;
    case GLFW_KEY_A: set_mode(v, ROUGE_MODE_ALBEDO); break;
    case GLFW_KEY_D: set_mode(v, ROUGE_MODE_DIFFUSE); break;
    case GLFW_KEY_F: set_mode(v, ROUGE_MODE_FULL); break;
    case GLFW_KEY_R:
        v->view.pipeline = v->view.pipeline == ROUGE_PIPELINE_REFERENCE ? ROUGE_PIPELINE_MOBILE : ROUGE_PIPELINE_REFERENCE;
        v->dirty_view = true;
        break;
    case GLFW_KEY_B: toggle_split(v); break;
    case GLFW_KEY_I: v->hud = !v->hud; break;
    case GLFW_KEY_H: v->help = !v->help; break;
    case GLFW_KEY_SLASH: if (shift) v->help = !v->help; break;
    case GLFW_KEY_ESCAPE:
        if (v->help) v->help = false;
        else if (v->split) v->split = false, v->dirty_view = true;
        break;
    case GLFW_KEY_S:
        if (ctrl) vw_looks_begin_save(v);
        else vw_looks_begin_export(v);
        break;
    case GLFW_KEY_O:
        if (ctrl) vw_looks_open(v);
        break;
    case GLFW_KEY_Q: if (ctrl) v->quit = true; break;
    case GLFW_KEY_F11: toggle_fullscreen(v); break;
    case GLFW_KEY_TAB: select_cosmetic(v, v->cosmetic + (shift ? -1 : 1)); break;
    case GLFW_KEY_LEFT_BRACKET:
    case GLFW_KEY_RIGHT_BRACKET: {
        float d = key == GLFW_KEY_LEFT_BRACKET ? -0.08f : 0.08f;
        if (shift) v->opacity = RS_CLAMP(v->opacity + d, 0.05f, 1.0f);
        else v->size_rel = slider_to_size(RS_CLAMP(vw_size_to_slider(v->size_rel) + d, 0.0f, 1.0f));
        vw_apply_brush(v);
        break;
    }
    case GLFW_KEY_LEFT: orbit(v, -40, 0), mark_input(v); break;
    case GLFW_KEY_RIGHT: orbit(v, 40, 0), mark_input(v); break;
    case GLFW_KEY_UP: orbit(v, 0, -40), mark_input(v); break;
    case GLFW_KEY_DOWN: orbit(v, 0, 40), mark_input(v); break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD: zoom_at(v, ZOOM_STEP, (float)v->fb_w * 0.5f, (float)v->fb_h * 0.5f), mark_input(v); break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT: zoom_at(v, 1 / ZOOM_STEP, (float)v->fb_w * 0.5f, (float)v->fb_h * 0.5f), mark_input(v); break;
    case GLFW_KEY_0:
    case GLFW_KEY_HOME:
        // The whole view as the viewer started: camera and the light (the dial follows).
        reset_camera(v);
        rouge_view start = rs_app_public_view(&v->cli->view, v->env_name);
        v->view.key = start.key;
        v->view.env_rotation_deg = start.env_rotation_deg;
        dial_from_light(v);
        break;
    case GLFW_KEY_G: next_env(v, shift ? -1 : 1); break;
    default:
        if (shift && key >= GLFW_KEY_1 && key <= GLFW_KEY_3) zoom_to_region(v, key - GLFW_KEY_1);
        else if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9 && key - GLFW_KEY_1 < n) select_cosmetic(v, key - GLFW_KEY_1);
        break;
    }
}

// --- input routing -------------------------------------------------------------------------------------

static void apply_tool(vw_viewer *v, rs_ui_tool t, const rs_ui_toolbar_state *st, int sw);

// One UI pass for the pointer as it is now, drawn nowhere: each press, move and release of a batch gets
// its own, so a tap or a flick that starts and ends between two drawn frames still acts (the widgets
// see every state in order, not only the batch's last).
static void ui_pass(vw_viewer *v)
{
    rs_ui_toolbar_state st;
    int sw = -1;
    v->ui_input_only = true;
    rs_ui_tool t = vw_draw_ui(v, &st, &sw);
    v->ui_input_only = false;
    rs_ui_end_input(v->ui);
    apply_tool(v, t, &st, sw);
}

// A pointer for the face (painting, touch gestures), in window coordinates. A gesture is measured in one
// pixel scale from its first touch to its last (the face_scale of its first DOWN); render_scene keeps the
// picture at that scale while a stroke picks in it.
static void feed_face(vw_viewer *v, rouge_pointer_type type, int id, float wx, float wy, double t)
{
    if (!v->face) return;
    if (type == ROUGE_POINTER_DOWN) {
        if (v->face_pointers++ == 0) v->face_scale = v->render_scale;
        // The face picks through the camera on screen.
        push_view(v);
    }
    float k = v->face_scale * v->px_per_pt;  // face pixels per window coordinate
    rouge_pointer_event ev = {type, id, wx * k, wy * k, 1.0f, t};
    rouge_pointer_result res;
    rouge_error e = {0};
    if (rouge_face_pointer(v->face, &ev, &res, &e) != ROUGE_OK) {
        vw_toast(v, true, "%s", e.msg);
        // A recording's failed write can surface here instead of at the final flush: keep it for the exit.
        if (v->cli->record && e.code == ROUGE_ERR_IO && !v->record_err.code) v->record_err = e;
    }
    if (type == ROUGE_POINTER_UP || type == ROUGE_POINTER_CANCEL) v->face_pointers = RS_MAX(v->face_pointers - 1, 0);
    // Gestures come back in the face's pixels: back to window coordinates with the same scale.
    if (res.orbit_dx != 0 || res.orbit_dy != 0) orbit(v, res.orbit_dx / k, res.orbit_dy / k);
    if (res.pan_dx != 0 || res.pan_dy != 0) pan(v, res.pan_dx / k, res.pan_dy / k);
    bool zoomed = res.zoom != 1.0f && res.zoom > 0;
    if (zoomed) zoom_at(v, res.zoom, res.zoom_x / v->face_scale, res.zoom_y / v->face_scale);
    if (res.stamps || res.stroke_end || res.stroke_cancel) v->dirty_makeup = true;
    // Navigation coarsens the picture while it moves; painting does not: the view stays, so the face
    // redraws only what the stamps touched (incremental frames) at full quality.
    bool navigated = res.orbit_dx != 0 || res.orbit_dy != 0 || res.pan_dx != 0 || res.pan_dy != 0 || zoomed;
    if (navigated || !v->paint_mode) mark_input(v);
}

static void pointer_button(vw_viewer *v, int b, bool down, double t)
{
    if (down) {
        // The UI as it is now decides who owns the press (a tap earlier in this batch may have opened a
        // panel that this press hits).
        ui_pass(v);
        if (rs_ui_captures(v->ui, v->mx, v->my)) {
            v->ui_owns[b] = true;
            if (b == 0) v->ui_pressed = true, ui_pass(v);
            return;
        }
        v->scene_owns[b] = true;
        if (b == 0) {
            v->light_drag = v->l_held;
            // Paint mode hands the pointer to the face; view mode orbits here, in window coordinates.
            v->face_drag = !v->light_drag && v->paint_mode;
            if (v->face_drag) feed_face(v, ROUGE_POINTER_DOWN, 0, v->wx, v->wy, t);
        }
        return;
    }
    if (v->ui_owns[b]) {
        v->ui_owns[b] = false;
        if (b == 0) v->ui_released = true, ui_pass(v);
        return;
    }
    if (!v->scene_owns[b]) return;
    v->scene_owns[b] = false;
    if (b == 0 && v->face_drag) feed_face(v, ROUGE_POINTER_UP, 0, v->wx, v->wy, t);
    if (b == 0) v->light_drag = v->face_drag = false;
}

static void pointer_move(vw_viewer *v, float wx, float wy, double t)
{
    float dx = wx - v->wx, dy = wy - v->wy;
    v->wx = wx, v->wy = wy;
    v->mx = wx * v->px_per_pt, v->my = wy * v->px_per_pt;
    v->ring_moved = true;
    if (v->ui_owns[0]) ui_pass(v);
    if (v->scene_owns[0]) {
        if (v->light_drag) {
            const float k = 0.4f;  // degrees per point
            v->view.key.yaw_deg = RS_CLAMP(v->view.key.yaw_deg + dx * k, -LIGHT_DIAL_DEG, LIGHT_DIAL_DEG);
            v->view.key.pitch_deg = RS_CLAMP(v->view.key.pitch_deg - dy * k, -LIGHT_DIAL_DEG, LIGHT_DIAL_DEG);
            dial_from_light(v);
            v->dirty_view = true;
            mark_input(v);
        } else if (v->face_drag) {
            feed_face(v, ROUGE_POINTER_MOVE, 0, wx, wy, t);
        } else {
            orbit(v, dx, dy);
            mark_input(v);
        }
    }
    if (v->scene_owns[1] || v->scene_owns[2]) {
        pan(v, dx, dy);
        mark_input(v);
    }
}

// Routes every queued event in order, UI taps included (each has its own input-only UI pass).
static void dispatch(vw_viewer *v)
{
    vw_event ev;
    while (vw_queue_pop(&v->queue, &ev)) {
        v->events_applied++;
        switch (ev.type) {
        case VW_MOVE: pointer_move(v, ev.x, ev.y, ev.time_s); break;
        case VW_BUTTON:
            if (!isnan(ev.x) && (ev.x != v->wx || ev.y != v->wy)) pointer_move(v, ev.x, ev.y, ev.time_s);
            pointer_button(v, RS_CLAMP(ev.button, 0, 2), ev.down, ev.time_s);
            break;
        case VW_SCROLL:
            zoom_at(v, powf(ZOOM_STEP, ev.dy), v->mx, v->my);
            mark_input(v);
            break;
        case VW_KEY:
            if (ev.key == GLFW_KEY_L) v->l_held = ev.down;
            if (ev.down) key_action(v, ev.key, ev.mods);
            break;
        case VW_TOUCH: feed_face(v, ev.touch, 100 + ev.id, ev.x, ev.y, ev.time_s); break;
        case VW_CHAR:
            if (!vw_editor_char(v, (unsigned)ev.key)) vw_looks_char(v, (unsigned)ev.key);
            break;
        case VW_DROP: {
            rs_error err = {0};
            if (load_start(v, ev.path, &err) != RS_OK) vw_toast(v, true, "%s", err.msg);
            break;
        }
        }
    }
}

// --- GLFW callbacks: queue only ---------------------------------------------------------------------------

static void on_cursor(GLFWwindow *w, double x, double y)
{
    vw_viewer *v = glfwGetWindowUserPointer(w);
    vw_queue_push(&v->queue, &(vw_event){.type = VW_MOVE, .time_s = glfwGetTime(), .x = (float)x, .y = (float)y});
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    (void)mods;
    vw_viewer *v = glfwGetWindowUserPointer(w);
    int b = button == GLFW_MOUSE_BUTTON_LEFT ? 0 : button == GLFW_MOUSE_BUTTON_RIGHT ? 1 : button == GLFW_MOUSE_BUTTON_MIDDLE ? 2 : -1;
    if (b < 0) return;
    // At the pointer's last queued position: glfwGetCursorPos would answer where the pointer is now, after
    // motion events still waiting in this batch.
    vw_queue_push(&v->queue, &(vw_event){.type = VW_BUTTON, .time_s = glfwGetTime(), .x = NAN, .y = NAN,
                                         .button = b, .down = action == GLFW_PRESS});
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    vw_viewer *v = glfwGetWindowUserPointer(w);
    vw_queue_push(&v->queue, &(vw_event){.type = VW_SCROLL, .time_s = glfwGetTime(), .dy = (float)dy});
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    (void)scancode;
    vw_viewer *v = glfwGetWindowUserPointer(w);
    if (key == GLFW_KEY_UNKNOWN) return;
    // Releases too: a key held during a drag (L) is known from the queue, never sampled.
    vw_queue_push(&v->queue, &(vw_event){.type = VW_KEY, .time_s = glfwGetTime(), .key = key, .mods = mods,
                                         .down = action != GLFW_RELEASE});
}

static void on_char(GLFWwindow *w, unsigned int codepoint)
{
    vw_viewer *v = glfwGetWindowUserPointer(w);
    vw_queue_push(&v->queue, &(vw_event){.type = VW_CHAR, .time_s = glfwGetTime(), .key = (int)codepoint});
}

static void on_drop(GLFWwindow *w, int count, const char **paths)
{
    vw_viewer *v = glfwGetWindowUserPointer(w);
    if (count < 1) return;
    vw_event ev = {.type = VW_DROP, .time_s = glfwGetTime()};
    snprintf(ev.path, sizeof ev.path, "%s", paths[0]);
    vw_queue_push(&v->queue, &ev);
}

static void on_enter(GLFWwindow *w, int entered)
{
    vw_viewer *v = glfwGetWindowUserPointer(w);
    v->pointer_outside = !entered;
}

static void on_refresh(GLFWwindow *w)
{
    vw_viewer *v = glfwGetWindowUserPointer(w);
    v->dirty_view = true;
}

// --- frames: window size, adaptive quality, rendering ----------------------------------------------------

static void update_window_size(vw_viewer *v)
{
    int ww, wh, fw, fh;
    glfwGetWindowSize(v->win, &ww, &wh);
    glfwGetFramebufferSize(v->win, &fw, &fh);
    if (fw < 1 || fh < 1 || ww < 1 || wh < 1) return;  // minimised
    // A resize is input (the picture coarsens while it lasts); the window's first size is not: marking it
    // once cost every start a few coarse renders of the face and one more full one.
    if (fw != v->fb_w || fh != v->fb_h) {
        v->dirty_view = true;
        if (v->fb_w > 0) mark_input(v);
    }
    v->win_w = ww, v->win_h = wh, v->fb_w = fw, v->fb_h = fh;
    v->px_per_pt = (float)fw / (float)ww;
    float cx = 1, cy = 1;
    glfwGetWindowContentScale(v->win, &cx, &cy);
    // Content scale is pixels per point on every platform GLFW supports (macOS: the Retina factor,
    // X11/Wayland/Windows: the DPI setting); fall back to the framebuffer ratio.
    // A window smaller than the UI's design size scales all of it down together (toolbar, editor, sheets,
    // text): the toolbar alone once shrank and the rest overlapped it.
    float fit = RS_MIN((float)ww / VW_UI_DESIGN_W, (float)wh / VW_UI_DESIGN_H);
    v->ui_scale = RS_CLAMP(RS_MAX(cx, v->px_per_pt), 1.0f, 4.0f) * RS_CLAMP(fit, 0.25f, 1.0f);
}

double vw_now(void) { return glfwGetTime(); }

static bool interacting(const vw_viewer *v)
{
    // A left button held in paint mode paints (full quality, incremental frames); otherwise it orbits.
    bool painting = v->scene_owns[0] && v->face_drag;
    // A widget held (the editor's colour square, a slider) changes no view: the picture stays at full
    // quality; the light dial marks its own input.
    bool held = (v->scene_owns[0] && !painting) || v->scene_owns[1] || v->scene_owns[2];
    return held || vw_now() - v->last_input_s < SETTLE_S || v->frame_no - v->last_input_frame < SETTLE_FRAMES;
}

// Moves along the quality ladder after an interactive frame: coarser when over budget, finer when well
// under it (the dead band between keeps it from flickering between two neighbours).
static void adapt_quality(vw_viewer *v, double frame_ms)
{
    if (frame_ms > BUDGET_MS * 1.3 && v->rung + 1 < v->rung_count) v->rung += frame_ms > BUDGET_MS * 2.5 ? 2 : 1;
    else if (frame_ms < BUDGET_MS * 0.6 && v->rung > 0) v->rung--;
    v->rung = RS_MIN(v->rung, v->rung_count - 1);
}

// The view as rendered: the picture's resolution and LOD.
static void apply_rung(vw_viewer *v, vw_rung q)
{
    v->render_scale = q.scale;
    v->view.width = RS_MAX(16, (int)lroundf((float)v->fb_w * q.scale));
    v->view.height = RS_MAX(16, (int)lroundf((float)v->fb_h * q.scale));
    v->view.max_splats = q.max_splats;
}

// Renders the picture if stale; both halves in split view (the left one only when the view changed).
static rs_result render_scene(vw_viewer *v, rs_error *err)
{
    bool inter = interacting(v);
    vw_rung want = inter ? v->rungs[v->rung] : (vw_rung){v->cli->view.max_splats, 1.0f};
    // A stroke picks in the pixels of the picture on screen: its resolution holds until the face lets go.
    if (v->face_pointers > 0 && v->paint_mode && !v->partial) want.scale = v->face_scale;
    bool quality_change = want.max_splats != v->rendered.max_splats || want.scale != v->rendered.scale ||
                          (!inter && !v->rendered_full);
    if (!v->dirty_view && !v->dirty_makeup && !quality_change) return RS_OK;
    apply_rung(v, want);
    rouge_error e = {0};
    rs_result r = RS_OK;
    if (v->split && (v->dirty_view || quality_change || !v->before.tex || v->looks.compare_dirty)) {
        // The left half: the bare face, or a look from the library to compare with.
        v->view.compare_look = true;
        push_view(v);
        r = rs_app_error(rouge_face_render(v->face, &e), &e, err);
        v->view.compare_look = false;
        v->looks.compare_dirty = false;
        int tw, th;
        GLuint tex = rouge_face_texture(v->face, &tw, &th);
        if (!r) r = rs_ui_texture_copy(&v->before, tex, tw, th, err);
    }
    push_view(v);
    if (!r) r = rs_app_error(rouge_face_render(v->face, &e), &e, err);
    v->info = rouge_face_stats(v->face);
    v->dirty_view = v->dirty_makeup = false;
    v->rendered = want;
    v->rendered_full = !inter && want.scale == 1.0f;
    v->rendered_this_frame = true;
    v->scale_lo = RS_MIN(v->scale_lo, want.scale), v->scale_hi = RS_MAX(v->scale_hi, want.scale);
    return r;
}

// What a toolbar tap or drag does (the same actions as the keys).
static void apply_tool(vw_viewer *v, rs_ui_tool t, const rs_ui_toolbar_state *st, int sw)
{
    switch (t) {
    case RS_UI_TOOL_PAINT: v->paint_mode = !v->paint_mode, vw_apply_brush(v); break;
    case RS_UI_TOOL_ERASER: v->eraser = !v->eraser, v->tool = ROUGE_TOOL_PAINT, v->paint_mode = true, vw_apply_brush(v); break;
    case RS_UI_TOOL_SMUDGE:  // cycles: off, smudge, blend, off
        toggle_tool(v, v->tool == ROUGE_TOOL_SMUDGE ? ROUGE_TOOL_BLEND
                       : v->tool == ROUGE_TOOL_BLEND ? ROUGE_TOOL_BLEND
                                                     : ROUGE_TOOL_SMUDGE);
        break;
    case RS_UI_TOOL_MIRROR: v->mirror = !v->mirror, vw_apply_brush(v); break;
    case RS_UI_TOOL_REGION: toggle_region(v); break;
    case RS_UI_TOOL_UNDO: do_undo(v, false); break;
    case RS_UI_TOOL_REDO: do_undo(v, true); break;
    case RS_UI_TOOL_CLEAR: do_clear(v); break;
    case RS_UI_TOOL_ALBEDO: set_mode(v, ROUGE_MODE_ALBEDO); break;
    case RS_UI_TOOL_DIFFUSE: set_mode(v, ROUGE_MODE_DIFFUSE); break;
    case RS_UI_TOOL_FULL: set_mode(v, ROUGE_MODE_FULL); break;
    case RS_UI_TOOL_PIPELINE: key_action(v, GLFW_KEY_R, 0); break;
    case RS_UI_TOOL_SPLIT: toggle_split(v); break;
    case RS_UI_TOOL_HUD: v->hud = !v->hud; break;
    case RS_UI_TOOL_SAVE: vw_looks_begin_save(v); break;
    case RS_UI_TOOL_LOAD: vw_looks_open(v); break;
    case RS_UI_TOOL_SCREENSHOT: vw_looks_begin_export(v); break;
    case RS_UI_TOOL_HELP: v->help = !v->help; break;
    case RS_UI_TOOL_LIGHT:
        v->light_dial[0] = st->light[0], v->light_dial[1] = st->light[1];
        light_from_dial(v);
        mark_input(v);
        break;
    case RS_UI_TOOL_SIZE: v->size_rel = slider_to_size(st->size), vw_apply_brush(v); break;
    case RS_UI_TOOL_OPACITY: v->opacity = RS_CLAMP(st->opacity, 0.02f, 1.0f), vw_apply_brush(v); break;
    case RS_UI_TOOL_SWATCH: if (sw >= 0) select_cosmetic(v, sw); break;
    case RS_UI_TOOL_NONE:
    case RS_UI_TOOL_COUNT: break;
    }
}

// What the input did so far, for the event script's `state` (tests read it).
static void write_state(vw_viewer *v, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        vw_toast(v, true, "%s: %s", path, strerror(errno));
        return;
    }
    const vw_editor *e = &v->editor;
    fprintf(f, "frame %lld\nscript_events %lld\nevents_applied %lld\nevents_dropped %d\n", v->frame_no,
            v->script.pushed, v->events_applied, v->queue.dropped);
    fprintf(f, "yaw_deg %.4f\npitch_deg %.4f\nzoom %.4f\npan %.4f %.4f\nlight_dial %.4f %.4f\n", v->view.yaw_deg,
            v->view.pitch_deg, v->view.zoom, v->view.pan[0], v->view.pan[1], v->light_dial[0], v->light_dial[1]);
    fprintf(f, "editor_open %d\neditor_hsv %.3f %.4f %.4f\neditor_rgb %d %d %d\nshades %d\n", e->open, e->hsv[0],
            e->hsv[1], e->hsv[2], e->product.rgb[0], e->product.rgb[1], e->product.rgb[2], e->shade_count);
    fprintf(f, "loading_screens %d\nloading_stages %s\n", v->load.screens, v->load.screens_log);
    fprintf(f, "render_scale %.3f\nrender_scale_range %.3f %.3f\n", v->render_scale, v->scale_lo, v->scale_hi);
    fprintf(f, "looks_sheet %d\nsave_dialog %d\nsave_name %s\nsplit %d\nsplit_left %s\ntoast %s\n", v->looks.open,
            v->looks.saving, v->looks.name, v->split, v->looks.compare[0] ? v->looks.compare : "(bare)", v->toast);
    fclose(f);
    v->scale_lo = v->scale_hi = v->render_scale;
}

// One frame: events, rendering, UI, swap. Returns the frame's wall time in ms.
static double frame(vw_viewer *v, const vw_script_step *step, rs_error *err)
{
    double t0 = vw_now();
    v->rendered_this_frame = false;
    update_window_size(v);
    // A face's first picture is made with the face (face_open: seconds on a slow GPU, shown stage by stage
    // on the loading screen); until the face is there, input waits in the queue (nothing is lost).
    if (v->face) {
        dispatch(v);
        rs_result r = render_scene(v, err);
        if (r) {
            vw_toast(v, true, "%s", err->msg);
            v->dirty_view = v->dirty_makeup = false;
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, v->fb_w, v->fb_h);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    rs_ui_begin(v->scene_ui, v->fb_w, v->fb_h, v->ui_scale, &(rs_ui_input){.x = -1, .y = -1});
    vw_draw_picture(v, v->scene_ui);
    rs_ui_end(v->scene_ui);
    // S exports the current look at full quality: while the picture is still refining (or being moved),
    // the export waits.
    if (v->looks.export_pending && at_full_quality(v)) vw_looks_export(v);
    rs_ui_toolbar_state st;
    int sw = -1;
    rs_ui_tool t = vw_draw_ui(v, &st, &sw);
    rs_ui_end(v->ui);
    apply_tool(v, t, &st, sw);
    if (step && step->screenshot) vw_write_png(v, step->screenshot, step->rect);
    if (step && step->state) write_state(v, step->state);
    glfwSwapBuffers(v->win);
    v->frame_no++;
    // The script's `slow`: a slow device, to prove that input keeps arriving whole meanwhile.
    double slow_s = v->have_script ? v->script.slow_s : 0, left_s = t0 + slow_s - vw_now();
    if (left_s > 0) nanosleep(&(struct timespec){(time_t)left_s, (long)(fmod(left_s, 1.0) * 1e9)}, NULL);
    double ms = (vw_now() - t0) * 1000.0;
    if (v->rendered_this_frame) {
        v->frame_ms_avg = v->frame_ms_avg > 0 ? v->frame_ms_avg * 0.8 + ms * 0.2 : ms;
        if (!v->rendered_full) adapt_quality(v, ms);
    }
    return ms;
}

// Shows a background load's progress: a preview of the LOD levels that have arrived (when the load is
// slow enough for one to help), then the whole face; or keeps what is shown and says why it failed.
static rs_result poll_loader(vw_viewer *v, rs_error *err)
{
    vw_loader *l = &v->load;
    if (!l->stream) return RS_OK;
    double now = glfwGetTime();
    if (l->running && !atomic_load(&l->done) && now - l->t0 >= VW_PREVIEW_AFTER_S &&
        (!l->shown || now - l->last_preview >= VW_PREVIEW_EVERY_S)) {
        rouge_stream_progress p = rouge_stream_get_progress(l->stream);
        rs_error e = {0};
        if (p.ready > l->shown && !p.complete) {
            if (!v->partial) reset_camera(v);  // first: the face's first frame is made with the camera
            if (face_open(v, &e) == RS_OK) {
                // The last bytes may have arrived meanwhile: then this face is the whole one.
                l->shown = v->info.splats, l->last_preview = now;
                v->partial = l->shown < p.splats;
                vw_apply_brush(v);
            }
        }
    }
    if (!l->building) {
        if (!load_finished(v)) return RS_OK;
        // Every splat is decoded; making the face of them blocks this thread for a while. One frame first
        // says so (the loading line once sat at "N of N splats" all that time).
        if (!l->result && (!l->shown || v->partial)) {
            l->building = true;
            l->decoded_s = now - l->t0;
            return RS_OK;
        }
    }
    l->building = false;
    bool was_partial = v->partial;
    rs_error e = {0};
    rs_result r = (rs_result)l->result;
    if (r) rs_fail(&e, r, "%s", l->err.msg);
    // The camera first, so the face's first frame (made with it) is the one shown.
    if (!r && !l->shown) reset_camera(v);
    if (!r && (!l->shown || was_partial)) r = face_open(v, &e);
    rouge_stream_destroy(l->stream);
    l->stream = NULL;
    v->partial = false;  // on failure a preview stays: all there is of that file
    if (v->face) vw_apply_brush(v);
    if (r) {
        if (l->initial) return rs_fail(err, r, "%s", e.msg);
        vw_toast(v, true, "%s", e.msg);
        return RS_OK;
    }
    if (l->initial && v->cli->look) {
        if ((r = vw_load_look_file(v, v->cli->look, err))) return r;
        vw_toast(v, false, "Loaded look %s", v->cli->look);
    }
    if (!l->initial) vw_toast(v, false, "Opened %s", l->path);
    return RS_OK;
}

// A load ends when its face is swapped in (the stream is dropped then), not when its thread ends: making the
// face of the decoded splats takes a frame more, and a script's `loaded` once shot the preview meanwhile.
static bool loading(const vw_viewer *v) { return v->load.stream != NULL; }

// The picture on screen is the full-quality one and nothing is about to change it.
static bool at_full_quality(const vw_viewer *v)
{
    // A preview at full quality is all there is to show until more of the file arrives.
    return v->face && (!v->load.running || v->partial) && !interacting(v) && v->rendered_full && !v->dirty_view &&
           !v->dirty_makeup && v->queue.count == 0;
}

// ... and no export is waiting for it (scripts' `idle` and `quit` wait for S too).
static bool settled(const vw_viewer *v) { return at_full_quality(v) && !v->looks.export_pending; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// --bench-orbit N: N orbiting frames with adaptive quality; prints the median frame time and the LOD.
static rs_result bench_orbit(vw_viewer *v, int n, rs_error *err)
{
    double *ms = rs_alloc_array((size_t)n, sizeof *ms);
    uint32_t *splats = rs_alloc_array((size_t)n, sizeof *splats);
    if (!ms || !splats) {
        free(ms), free(splats);
        return rs_fail(err, RS_ERR_NOMEM, "bench: out of memory");
    }
    // No vsync: we measure rendering, not the display's refresh.
    glfwSwapInterval(0);
    // Warm up: one full frame, and let the controller settle on its LOD over a few frames.
    for (int i = 0; i < n + 10 && !glfwWindowShouldClose(v->win); i++) {
        orbit(v, 6.0f, 0);
        mark_input(v);
        double t = frame(v, NULL, err);
        if (i >= 10) ms[i - 10] = t, splats[i - 10] = rouge_face_stats(v->face).splats_drawn;
    }
    qsort(ms, (size_t)n, sizeof *ms, cmp_double);
    uint32_t lo = splats[0], hi = splats[0];
    for (int i = 0; i < n; i++) lo = RS_MIN(lo, splats[i]), hi = RS_MAX(hi, splats[i]);
    printf("bench-orbit: %dx%d window (%dx%d px), %s pipeline, %d frames: median %.1f ms (p90 %.1f ms), "
           "LOD %u..%u of %u splats (budget %.0f ms), %s\n",
           v->win_w, v->win_h, v->fb_w, v->fb_h, v->view.pipeline == ROUGE_PIPELINE_REFERENCE ? "reference" : "mobile",
           n, ms[n / 2], ms[(n * 9) / 10], lo, hi, v->info.splats, BUDGET_MS, rs_window_caps(v->window)->renderer);
    free(ms);
    free(splats);
    return RS_OK;
}

static rs_result run(vw_viewer *v, rs_error *err)
{
    const rs_cli *c = v->cli;
    char def[600];
    if (!rs_app_env_dir(v->env_dir, sizeof v->env_dir)) v->env_dir[0] = 0;
    if (!vw_set_env(v, c->env ? c->env : RS_ENV_DEFAULT))
        return rs_fail(err, RS_ERR_ARG, "%s", v->toast);
    rs_result r = load_start(v, c->face ? c->face : rs_app_default_face(def, sizeof def), err);
    if (r) return r;
    v->load.initial = true;
    vw_options o = viewer_options(c);
    // Loading screen until the face (or a preview of it) is there; the bench waits for all of it.
    while (!v->face || (o.bench_orbit > 0 && loading(v))) {
        if (glfwWindowShouldClose(v->win)) {
            load_abort(v);
            return RS_OK;
        }
        glfwPollEvents();
        if ((r = poll_loader(v, err))) return r;
        if (!v->face || v->load.running) {
            frame(v, NULL, err);
            glfwWaitEventsTimeout(0.03);
        }
    }
    // One frame with the toolbar before any input: presses are routed by what the last frame drew.
    frame(v, NULL, err);
    if (o.bench_orbit > 0) return bench_orbit(v, o.bench_orbit, err);

    while (!v->quit && !glfwWindowShouldClose(v->win)) {
        // Sleep while nothing changes: a viewer at rest costs no CPU.
        // A toast is still: it needs a frame when it goes, not a busy loop while it shows (an error's
        // 10 s of spinning once cost a scripted session most of its CPU).
        bool busy = v->load.running || v->load.building || interacting(v) || v->dirty_view || v->dirty_makeup || !v->rendered_full;
        double toast_left = v->toast[0] ? v->toast_until + 0.1 - vw_now() : 0;
        if (busy) glfwPollEvents();
        else glfwWaitEventsTimeout(v->have_script ? 0.01 : toast_left > 0 ? RS_MIN(toast_left, 0.5) : 0.5);
        if ((r = poll_loader(v, err))) return r;
        vw_script_step step = {0};
        if (v->have_script) {
            int next0 = v->script.next, frames0 = v->script.frames_left;
            vw_script_run(&v->script, &v->queue, settled(v), loading(v), vw_now(), &step);
            if (step.quit) v->quit = true;
            if (v->script.done && !step.quit && !step.screenshot) v->have_script = false;
            // A script waiting (on its clock, a file, a load) with nothing to show draws no frame: the
            // same picture again and again cost a core while it waited.
            if (!busy && v->script.next == next0 && !frames0 && !step.screenshot && !step.state && !v->queue.count &&
                !v->looks.export_pending)
                continue;
        }
        frame(v, &step, err);
    }
    return RS_OK;
}

rs_result rs_app_view(const rs_cli *cli, rs_error *err)
{
    vw_viewer *v = calloc(1, sizeof *v);
    if (!v) return rs_fail(err, RS_ERR_NOMEM, "viewer: out of memory");
    v->cli = cli;
    rs_result r = RS_OK;
    vw_options o = viewer_options(cli);
    if (o.events) {
        r = vw_script_load(o.events, &v->script, err);
        v->have_script = r == RS_OK;
    }
    int w = o.size_set ? cli->view.width : 1024, h = o.size_set ? cli->view.height : 768;
    if (!r)
        r = rs_window_create(&(rs_window_desc){.width = w, .height = h, .title = "rouge",
                                               .fullscreen = cli->fullscreen},
                             &v->window, err);
    if (!r) r = rs_ui_create(&v->ui, err);
    if (!r) r = rs_ui_create(&v->scene_ui, err);
    if (!r) {
        v->win = rs_window_glfw(v->window);
        v->fullscreen = cli->fullscreen;
        glfwSetWindowUserPointer(v->win, v);
        glfwSetCursorPosCallback(v->win, on_cursor);
        glfwSetMouseButtonCallback(v->win, on_button);
        glfwSetScrollCallback(v->win, on_scroll);
        glfwSetKeyCallback(v->win, on_key);
        glfwSetDropCallback(v->win, on_drop);
        glfwSetCharCallback(v->win, on_char);
        glfwSetWindowRefreshCallback(v->win, on_refresh);
        glfwSetCursorEnterCallback(v->win, on_enter);
        v->view = rs_app_public_view(&cli->view, NULL);
        if (!o.pipeline_set) v->view.pipeline = ROUGE_PIPELINE_MOBILE;
        v->split_frac = 0.5f;
        v->render_scale = 1;
        v->hud = true;
        v->last_input_s = -1e9;
        v->last_input_frame = -1000;
        vw_looks_init(v);
        vw_editor_load_shades(v);
        dial_from_light(v);
        select_cosmetic(v, 0);
        v->paint_mode = false;
        double mx, my;
        glfwGetCursorPos(v->win, &mx, &my);
        update_window_size(v);
        v->wx = (float)mx, v->wy = (float)my;
        v->mx = v->wx * v->px_per_pt, v->my = v->wy * v->px_per_pt;
        v->scale_lo = v->scale_hi = 1;
        r = run(v, err);
    }
    if (v->face && cli->record) {
        // Every stroke in the recording's file before the viewer says it is done.
        rouge_error e2 = {0};
        rouge_result fr = rouge_face_flush_strokes(v->face, &e2);
        if (!fr && v->record_err.code) fr = v->record_err.code, e2 = v->record_err;
        if (!r) r = rs_app_error(fr, &e2, err);
    }
    load_abort(v);
    vw_looks_free(v);
    face_close(v);
    rs_ui_texture_free(&v->before);
    rs_ui_destroy(v->ui);
    rs_ui_destroy(v->scene_ui);
    rs_window_destroy(v->window);
    vw_script_free(&v->script);
    free(v);
    return r;
}
