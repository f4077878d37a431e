// rouge_web.c — the browser's host of rouge: a WebGL 2 context on a canvas and one rouge_face, behind
// plain functions that web/rouge.js calls (numbers, strings and pointers only: no struct layouts cross
// into JavaScript).
//
// Does: create the WebGL 2 context (Emscripten's html5 API) and keep it current; load a face from bytes or
// from a rouge_stream fed as the network delivers it (previews of the complete LOD levels, then the whole
// face); pass views, brushes, pointer events, looks and navigation to rouge.h; report the last error.
// Does not: read events, run a frame loop, fetch or store anything (rouge.js does), or know the page.
#include <emscripten/emscripten.h>
#include <emscripten/html5.h>
#include <rouge.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RW_API EMSCRIPTEN_KEEPALIVE

typedef struct rw_app {
    EMSCRIPTEN_WEBGL_CONTEXT_HANDLE gl;
    rouge_face *face;
    rouge_stream *stream;
    rouge_view view;          // the last view asked for (its env string is env_name)
    char env_name[64];
    rouge_brush brush;        // the last brush asked for (its cosmetic string is cosmetic)
    char cosmetic[64];
    bool have_brush, painting, preview;
    rouge_pointer_result last;
    rouge_error err;
} rw_app;

static int fail(rw_app *a, rouge_result code, const char *msg)
{
    a->err.code = code;
    snprintf(a->err.msg, sizeof a->err.msg, "%s", msg);
    return (int)code;
}

static int keep(rw_app *a, rouge_result r, const rouge_error *e)
{
    if (r != ROUGE_OK) a->err = *e;
    return (int)r;
}

static bool current(rw_app *a)
{
    return a && a->gl > 0 && emscripten_webgl_make_context_current(a->gl) == EMSCRIPTEN_RESULT_SUCCESS;
}

// Makes the WebGL 2 context on the canvas the CSS selector names. Always returns an app (NULL only
// without memory); rw_error_code tells whether the context exists.
RW_API rw_app *rw_create(const char *canvas)
{
    rw_app *a = calloc(1, sizeof *a);
    if (!a) return NULL;
    EmscriptenWebGLContextAttributes at;
    emscripten_webgl_init_context_attributes(&at);
    at.majorVersion = 2;
    at.minorVersion = 0;
    at.alpha = false;
    at.depth = false;     // rouge renders into its own targets and copies the picture
    at.stencil = false;
    at.antialias = false;
    at.premultipliedAlpha = false;
    at.preserveDrawingBuffer = false;
    at.enableExtensionsByDefault = true;  // EXT_color_buffer_float: rouge's float targets
    at.powerPreference = EM_WEBGL_POWER_PREFERENCE_HIGH_PERFORMANCE;
    a->gl = emscripten_webgl_create_context(canvas, &at);
    if (a->gl <= 0) {
        fail(a, ROUGE_ERR_GL, "this browser has no WebGL 2 (OpenGL ES 3.0): rouge cannot draw here");
        a->gl = 0;
        return a;
    }
    if (!current(a)) fail(a, ROUGE_ERR_GL, "the WebGL 2 context could not be made current");
    a->painting = true;
    return a;
}

RW_API void rw_destroy(rw_app *a)
{
    if (!a) return;
    if (current(a)) rouge_face_destroy(a->face);
    rouge_stream_destroy(a->stream);
    if (a->gl > 0) emscripten_webgl_destroy_context(a->gl);
    free(a);
}

RW_API int rw_error_code(const rw_app *a) { return a ? (int)a->err.code : (int)ROUGE_ERR_NOMEM; }
RW_API const char *rw_error_message(const rw_app *a) { return a ? a->err.msg : "out of memory"; }
RW_API void rw_error_clear(rw_app *a) { a->err = (rouge_error){0}; }
RW_API bool rw_has_face(const rw_app *a) { return a->face != NULL; }
RW_API bool rw_is_preview(const rw_app *a) { return a->face && a->preview; }

// Applies what the host asked for so far to a new face: view (camera kept from the old face when there
// was one), brush, paint mode.
static int adopt(rw_app *a, rouge_face *face, bool preview)
{
    rouge_error e = {0};
    if (a->face) {
        rouge_view old = rouge_face_get_view(a->face);
        a->view.yaw_deg = old.yaw_deg, a->view.pitch_deg = old.pitch_deg, a->view.zoom = old.zoom;
        a->view.pan[0] = old.pan[0], a->view.pan[1] = old.pan[1];
        rouge_face_destroy(a->face);
    }
    a->face = face;
    a->preview = preview;
    a->view.env = a->env_name[0] ? a->env_name : NULL;
    if (rouge_face_set_view(face, &a->view, &e) != ROUGE_OK) return keep(a, ROUGE_ERR_ARG, &e);
    if (a->have_brush) {
        a->brush.cosmetic = a->cosmetic[0] ? a->cosmetic : NULL;
        if (rouge_face_set_brush(face, &a->brush, &e) != ROUGE_OK) return keep(a, ROUGE_ERR_ARG, &e);
    }
    // A preview cannot be painted: the strokes would be lost with it.
    rouge_face_set_painting(face, a->painting && !preview);
    return ROUGE_OK;
}

static int create_face(rw_app *a, const rouge_face_desc *desc, bool preview)
{
    if (!current(a)) return fail(a, ROUGE_ERR_GL, "no WebGL 2 context");
    rouge_face *face;
    rouge_error e = {0};
    // Created with the view asked for, so only the environments it names need to be there.
    rouge_face_desc d = *desc;
    rouge_view v = a->view;
    v.env = a->env_name[0] ? a->env_name : NULL;
    d.view = &v;
    rouge_result r = rouge_face_create(&d, &face, &e);
    if (r != ROUGE_OK) return keep(a, r, &e);
    return adopt(a, face, preview);
}

// A whole .rsf in memory (the page's "bytes" source). env_dir: where named environments' .rse files are.
RW_API int rw_face_from_bytes(rw_app *a, const void *data, size_t size, const char *env_dir)
{
    return create_face(a, &(rouge_face_desc){.data = data, .size = size, .env_dir = env_dir}, false);
}

// --- streaming ---------------------------------------------------------------------------------------------

RW_API int rw_stream_begin(rw_app *a, const char *name, double total_bytes)
{
    rouge_stream_destroy(a->stream);
    a->stream = NULL;
    rouge_error e = {0};
    uint64_t total = total_bytes > 0 && total_bytes < 1e15 ? (uint64_t)total_bytes : 0;
    return keep(a, rouge_stream_create(name, total, &a->stream, &e), &e);
}

RW_API int rw_stream_feed(rw_app *a, const void *data, size_t size)
{
    if (!a->stream) return fail(a, ROUGE_ERR_ARG, "no stream begun");
    rouge_error e = {0};
    return keep(a, rouge_stream_feed(a->stream, data, size, &e), &e);
}

// out[0..4]: bytes, splats, decoded, ready, complete.
RW_API void rw_stream_progress(const rw_app *a, double *out)
{
    rouge_stream_progress p = a->stream ? rouge_stream_get_progress(a->stream) : (rouge_stream_progress){0};
    out[0] = (double)p.bytes, out[1] = p.splats, out[2] = p.decoded, out[3] = p.ready, out[4] = p.complete;
}

// The face as far as the stream has arrived: a preview of its complete LOD levels, or the whole face once
// every byte is in (then the stream is released).
RW_API int rw_face_from_stream(rw_app *a, const char *env_dir)
{
    if (!a->stream) return fail(a, ROUGE_ERR_ARG, "no stream begun");
    bool complete = rouge_stream_get_progress(a->stream).complete;
    int r = create_face(a, &(rouge_face_desc){.stream = a->stream, .env_dir = env_dir}, !complete);
    if (r == ROUGE_OK && complete) {
        rouge_stream_destroy(a->stream);
        a->stream = NULL;
    }
    return r;
}

// --- view, brush, navigation -------------------------------------------------------------------------------

// The view as numbers (0 = rouge's default for each): size in drawing-buffer pixels, camera, lighting.
RW_API int rw_set_view(rw_app *a, int width, int height, float yaw, float pitch, float zoom, float pan_x,
                       float pan_y, const char *env, float env_rotation, int mode, int pipeline, float exposure,
                       bool hide_makeup, bool compare_look, int kernel_count, float lod_density)
{
    rouge_view v = a->view;
    v.width = width, v.height = height;
    v.yaw_deg = yaw, v.pitch_deg = pitch, v.zoom = zoom, v.pan[0] = pan_x, v.pan[1] = pan_y;
    v.env_rotation_deg = env_rotation;
    v.mode = (rouge_mode)mode, v.pipeline = (rouge_pipeline)pipeline;
    v.exposure = exposure;
    v.hide_makeup = hide_makeup, v.compare_look = compare_look;
    v.kernel_count = kernel_count, v.lod_density = lod_density;
    char name[sizeof a->env_name];
    snprintf(name, sizeof name, "%s", env ? env : "");
    v.env = name[0] ? name : NULL;
    if (a->face) {
        rouge_error e = {0};
        if (!current(a)) return fail(a, ROUGE_ERR_GL, "no WebGL 2 context");
        if (rouge_face_set_view(a->face, &v, &e) != ROUGE_OK) return keep(a, e.code, &e);
    }
    memcpy(a->env_name, name, sizeof name);
    a->view = v;
    a->view.env = NULL;  // points into env_name when used (adopt)
    return ROUGE_OK;
}

// out[0..7]: yaw, pitch, zoom, pan x, pan y, width, height, env rotation — the camera as navigation left it.
RW_API void rw_get_view(const rw_app *a, float *out)
{
    rouge_view v = a->face ? rouge_face_get_view(a->face) : a->view;
    out[0] = v.yaw_deg, out[1] = v.pitch_deg, out[2] = v.zoom, out[3] = v.pan[0], out[4] = v.pan[1];
    out[5] = (float)v.width, out[6] = (float)v.height, out[7] = v.env_rotation_deg;
}

RW_API int rw_set_brush(rw_app *a, const char *cosmetic, float r, float g, float b, float alpha, int finish,
                        float coverage, float size, float opacity, int pressure, bool eraser, bool mirror,
                        bool any_region, int tool)
{
    rouge_brush br = {
        .color = {r, g, b, alpha}, .finish = (rouge_finish)finish, .coverage = coverage, .size = size,
        .opacity = opacity, .pressure = (rouge_pressure)pressure, .eraser = eraser, .mirror = mirror,
        .any_region = any_region, .tool = (rouge_tool)tool,
    };
    char name[sizeof a->cosmetic];
    snprintf(name, sizeof name, "%s", cosmetic ? cosmetic : "");
    br.cosmetic = name[0] ? name : NULL;
    if (a->face) {
        rouge_error e = {0};
        if (rouge_face_set_brush(a->face, &br, &e) != ROUGE_OK) return keep(a, e.code, &e);
    }
    memcpy(a->cosmetic, name, sizeof name);
    a->brush = br;
    a->brush.cosmetic = NULL;
    a->have_brush = true;
    return ROUGE_OK;
}

RW_API void rw_set_painting(rw_app *a, bool painting)
{
    a->painting = painting;
    if (a->face) rouge_face_set_painting(a->face, painting && !a->preview);
}

RW_API void rw_orbit(rw_app *a, float yaw_deg, float pitch_deg)
{
    if (a->face) rouge_face_orbit(a->face, yaw_deg, pitch_deg);
}
RW_API void rw_pan(rw_app *a, float dx, float dy)
{
    if (a->face) rouge_face_pan(a->face, dx, dy);
}
RW_API void rw_zoom_at(rw_app *a, float factor, float x, float y)
{
    if (a->face) rouge_face_zoom_at(a->face, factor, x, y);
}
RW_API int rw_target(rw_app *a, const char *region, float fill)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet");
    rouge_error e = {0};
    return keep(a, rouge_face_target(a->face, region, fill, &e), &e);
}

// One pointer event, x / y in pixels of the last frame. The result: rw_pointer_result.
RW_API int rw_pointer(rw_app *a, int type, int id, float x, float y, float pressure, double time_s)
{
    a->last = (rouge_pointer_result){0};
    if (!a->face) return ROUGE_OK;  // nothing to touch yet: the event has no effect, by design
    if (!current(a)) return fail(a, ROUGE_ERR_GL, "no WebGL 2 context");
    rouge_error e = {0};
    rouge_pointer_event ev = {(rouge_pointer_type)type, id, x, y, pressure, time_s};
    return keep(a, rouge_face_pointer(a->face, &ev, &a->last, &e), &e);
}

// out[0..9]: stamps, misses, begin, end, cancel, orbit dx, dy, pan dx, dy, zoom.
RW_API void rw_pointer_result(const rw_app *a, float *out)
{
    const rouge_pointer_result *p = &a->last;
    out[0] = (float)p->stamps, out[1] = (float)p->misses, out[2] = p->stroke_begin, out[3] = p->stroke_end;
    out[4] = p->stroke_cancel, out[5] = p->orbit_dx, out[6] = p->orbit_dy, out[7] = p->pan_dx, out[8] = p->pan_dy;
    out[9] = p->zoom;
}

RW_API bool rw_undo(rw_app *a) { return a->face && current(a) && rouge_face_undo(a->face); }
RW_API bool rw_redo(rw_app *a) { return a->face && current(a) && rouge_face_redo(a->face); }
RW_API int rw_clear(rw_app *a)
{
    if (!a->face) return ROUGE_OK;
    rouge_error e = {0};
    return keep(a, rouge_face_clear(a->face, &e), &e);
}

// --- frames and pixels ----------------------------------------------------------------------------------------

RW_API bool rw_changed(const rw_app *a) { return a->face && rouge_face_changed(a->face); }

// Draws the face into the canvas's drawing buffer (w x h pixels).
RW_API int rw_draw(rw_app *a, int w, int h)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet");
    if (!current(a)) return fail(a, ROUGE_ERR_GL, "no WebGL 2 context");
    rouge_error e = {0};
    return keep(a, rouge_face_draw(a->face, 0, 0, w, h, &e), &e);
}

RW_API int rw_read_rgba(rw_app *a, uint8_t *rgba, size_t capacity)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet");
    if (!current(a)) return fail(a, ROUGE_ERR_GL, "no WebGL 2 context");
    rouge_error e = {0};
    return keep(a, rouge_face_read_rgba(a->face, rgba, capacity, &e), &e);
}

// out[0..13]: splats, splats drawn, width, height, frame ms, can undo, can redo, in stroke, look stamps,
// face height mm, LOD level count, float targets, kernel count, auto splats.
RW_API void rw_stats(const rw_app *a, double *out)
{
    rouge_stats s = a->face ? rouge_face_stats(a->face) : (rouge_stats){0};
    double v[] = {s.splats, s.splats_drawn, s.width, s.height, s.frame_ms, s.can_undo, s.can_redo, s.in_stroke,
                  s.look_stamps, s.face_height_mm, s.lod_count, s.float_targets, s.kernel_count, s.auto_splats};
    memcpy(out, v, sizeof v);
}

// The surface under a pixel of the last frame: out[0..4] = splat, x, y, z, region; false on background.
RW_API bool rw_pick(rw_app *a, float x, float y, float *out)
{
    rouge_pick p;
    if (!a->face || !current(a) || !rouge_face_pick(a->face, x, y, &p)) return false;
    out[0] = (float)p.splat, out[1] = p.position[0], out[2] = p.position[1], out[3] = p.position[2];
    out[4] = (float)p.region;
    return true;
}

// --- looks -------------------------------------------------------------------------------------------------

RW_API int rw_load_look(rw_app *a, const void *data, size_t size)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet");
    rouge_error e = {0};
    return keep(a, rouge_face_load_look_memory(a->face, data, size, &e), &e);
}

// The look as text (free it with rouge_free); NULL on failure. *size receives its length.
RW_API char *rw_save_look(rw_app *a, size_t *size)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet"), NULL;
    char *data = NULL;
    rouge_error e = {0};
    if (keep(a, rouge_face_save_look_memory(a->face, &data, size, &e), &e) != ROUGE_OK) return NULL;
    return data;
}

// A look file in the module's file system (or NULL: the bare face) as the comparison look.
RW_API int rw_set_compare_look(rw_app *a, const char *path)
{
    if (!a->face) return fail(a, ROUGE_ERR_ARG, "no face yet");
    rouge_error e = {0};
    return keep(a, rouge_face_set_compare_look(a->face, path && path[0] ? path : NULL, &e), &e);
}

// --- the product table (pure data) -------------------------------------------------------------------------

// out[0..8]: r, g, b (0..255), size, opacity, finish, coverage; strings through the name / kind / region
// functions. false when i is out of range.
RW_API bool rw_cosmetic(int i, float *out)
{
    rouge_cosmetic c;
    if (!rouge_cosmetic_get(i, &c)) return false;
    out[0] = c.rgb[0], out[1] = c.rgb[1], out[2] = c.rgb[2], out[3] = c.size, out[4] = c.opacity;
    out[5] = (float)c.finish, out[6] = c.coverage;
    return true;
}
RW_API const char *rw_cosmetic_name(int i)
{
    rouge_cosmetic c;
    return rouge_cosmetic_get(i, &c) ? c.name : NULL;
}
RW_API const char *rw_cosmetic_kind(int i)
{
    rouge_cosmetic c;
    return rouge_cosmetic_get(i, &c) ? c.kind : NULL;
}
RW_API const char *rw_cosmetic_region(int i)
{
    rouge_cosmetic c;
    return rouge_cosmetic_get(i, &c) && c.region ? c.region : "";
}
