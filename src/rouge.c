// rouge.c — the public face object (include/rouge.h): one cloud, its renderer, makeup layer and painting
// session wired together the one way every host needs them (the viewer, `rouge render`, examples), plus
// saving and restoring the host's GL state around every call that touches GL.
#include "rouge.h"

#include "core/core.h"
#include "core/image.h"
#include "formats/env_lookup.h"
#include "formats/look.h"
#include "formats/strokes.h"
#include "gl/gl.h"
#include "makeup/cosmetics.h"
#include "makeup/makeup.h"
#include "paint/paint.h"
#include "render/render.h"
#include "splat/splat.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#ifdef __EMSCRIPTEN__
#include <emscripten/html5.h>
#else
#include <EGL/egl.h>
#endif

// The public result codes are the library's, name for name.
_Static_assert((int)ROUGE_ERR_ARG == (int)RS_ERR_ARG && (int)ROUGE_ERR_GL == (int)RS_ERR_GL, "rouge_result");
_Static_assert((int)ROUGE_MODE_COUNT == (int)RS_MODE_COUNT, "rouge_mode");
_Static_assert(ROUGE_MAX_LODS == RS_SPLAT_MAX_LODS, "ROUGE_MAX_LODS");
_Static_assert((int)ROUGE_COMPOSITE_PHYSICAL == (int)RS_COMPOSITE_PHYSICAL, "rouge_composite");
_Static_assert(sizeof(((rouge_error *)0)->msg) == sizeof(((rs_error *)0)->msg), "rouge_error");
_Static_assert(ROUGE_VIEW_MAX_SIZE == RS_VIEW_MAX_SIZE_PX, "ROUGE_VIEW_MAX_SIZE");
_Static_assert(sizeof(((rouge_look_item *)0)->name) == RS_COSMETIC_NAME_MAX, "rouge_look_item");
// The library's own codes stop before the one only the public API has.
_Static_assert((int)ROUGE_ERR_CANCELLED == (int)RS_ERR_ARG + 1, "ROUGE_ERR_CANCELLED");

#define ROUGE_ENV_MAX 64
#define ROUGE_DEFAULT_SIZE 512
#define ORBIT_DEG_PER_PX 0.35f
#define PITCH_LIMIT_DEG 80.0f
#define ZOOM_MIN 0.3f
#define ZOOM_MAX 12.0f
#define PIXEL_RATIO_MIN 0.1f
#define PIXEL_RATIO_MAX 16.0f

// A stroke recording is rewritten whole after each stroke (temp file, fsync, rename: the file on disk is
// always a complete recording). The writing happens on this thread, so ending a stroke costs only turning
// the document into text; a newer text supersedes one not yet written. Failures are reported by the next
// rouge_face_pointer / rouge_face_flush_strokes / rouge_face_record_strokes call.
typedef struct rec_writer {
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t cv;   // signalled on new text, on quit and when a write finishes
    char *path;
    char *pending;       // the newest text not yet taken by the thread (NULL: none)
    size_t pending_len;
    bool busy, quit;
    rs_result result;    // the last failed write, until reported
    rs_error error;
} rec_writer;

static void *rec_thread(void *arg)
{
    rec_writer *w = arg;
    pthread_mutex_lock(&w->mu);
    for (;;) {
        while (!w->pending && !w->quit) pthread_cond_wait(&w->cv, &w->mu);
        if (!w->pending) break;  // quit, and everything is written
        char *text = w->pending;
        size_t len = w->pending_len;
        w->pending = NULL;
        w->busy = true;
        pthread_mutex_unlock(&w->mu);
        rs_error e = {0};
        rs_result r = rs_file_write_atomic(w->path, text, len, &e);
        free(text);
        pthread_mutex_lock(&w->mu);
        w->busy = false;
        if (r && !w->result) w->result = r, w->error = e;
        pthread_cond_broadcast(&w->cv);
    }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

static rs_result rec_writer_start(const char *path, rec_writer **out, rs_error *e)
{
    rec_writer *w = calloc(1, sizeof *w);
    size_t n = strlen(path) + 1;
    if (!w || !(w->path = malloc(n))) {
        free(w);
        return rs_fail(e, RS_ERR_NOMEM, "strokes: out of memory");
    }
    memcpy(w->path, path, n);
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv, NULL);
    if (pthread_create(&w->thread, NULL, rec_thread, w) != 0) {
        pthread_cond_destroy(&w->cv);
        pthread_mutex_destroy(&w->mu);
        free(w->path);
        free(w);
        return rs_fail(e, RS_ERR_NOMEM, "strokes: cannot start the writer thread");
    }
    *out = w;
    return RS_OK;
}

// Hands the newest text to the thread (taking ownership of it).
static void rec_writer_submit(rec_writer *w, char *text, size_t len)
{
    pthread_mutex_lock(&w->mu);
    free(w->pending);
    w->pending = text, w->pending_len = len;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
}

// The last failure since the previous call (and clears it); with `wait`, first waits until every
// submitted text is on disk.
static rs_result rec_writer_status(rec_writer *w, bool wait, rs_error *e)
{
    pthread_mutex_lock(&w->mu);
    while (wait && (w->pending || w->busy)) pthread_cond_wait(&w->cv, &w->mu);
    rs_result r = w->result;
    if (r) *e = w->error;
    w->result = RS_OK;
    pthread_mutex_unlock(&w->mu);
    return r;
}

// Writes what is pending, stops the thread and frees the writer; returns the last failure.
static rs_result rec_writer_stop(rec_writer *w, rs_error *e)
{
    if (!w) return RS_OK;
    pthread_mutex_lock(&w->mu);
    w->quit = true;
    pthread_cond_broadcast(&w->cv);
    pthread_mutex_unlock(&w->mu);
    pthread_join(w->thread, NULL);
    rs_result r = w->result;
    if (r) *e = w->error;
    pthread_cond_destroy(&w->cv);
    pthread_mutex_destroy(&w->mu);
    free(w->pending);
    free(w->path);
    free(w);
    return r;
}

struct rouge_face {
    rs_splat_cloud *cloud;
    rs_renderer *ren;
    rs_makeup *mk;
    rs_paint *paint;
    rouge_view view;              // as set (env points at env_name)
    char env_name[ROUGE_ENV_MAX]; // the environment uploaded to the renderer ("" = none yet)
    char view_env[ROUGE_ENV_MAX]; // view.env points here
    char *env_dir;                // rouge_face_desc.env_dir
    rs_view frame_view;           // the view of the last frame: pointer coordinates and picks refer to it
    float frame_ratio;            // its pixel_ratio: pointer coordinates * frame_ratio = its pixels
    bool have_frame;
    bool changed;                 // view or makeup changed since the last frame
    bool manual_navigation, painting;
    rs_strokes *rec;              // stroke recording (rouge_face_record_strokes)
    rec_writer *writer;           // writes it to its file off the pointer path
    uint32_t uploaded;            // records uploaded for the last frame
    rs_makeup *cmp;               // the compared look (rouge_face_set_compare_look), NULL = bare
    uint32_t fine_version;        // the painted layer's fine stamps the renderer holds (rs_makeup_fine_version)
    bool fine_other;              // the renderer holds another layer's fine stamps (the compared look's)
    uintptr_t context;            // the GL context the face was created in (its objects live there)
    uint32_t host_gl_error;       // the first GL error a host left pending (rouge_face_take_host_gl_error)
    bool have_source;             // loaded from a file: never overwrite it
    rs_file_id source;
    GLuint srgb_tex, srgb_pbo;    // draw into an sRGB framebuffer: the frame's bytes as sRGB texels
    int srgb_w, srgb_h;
    struct {                      // environments from memory (rouge_face_add_environment)
        char name[ROUGE_ENV_MAX];
        rs_env *env;
    } envs[ROUGE_MAX_ENVIRONMENTS];
    int env_count;
};

// A file arriving piece by piece: the splat loader behind a lock (one thread feeds, the GL thread makes
// faces from it).
struct rouge_stream {
    pthread_mutex_t mu;
    rs_splat_loader *ld;
    uint64_t bytes;
    bool taken;                   // a complete stream's splats went to a face
    rouge_stream_progress final;  // its progress then: the loader forgets it, the reading thread must not
};

static rouge_result fail_out(rouge_error *out, const rs_error *e)
{
    if (out) {
        out->code = (rouge_result)e->code;
        memcpy(out->msg, e->msg, sizeof out->msg);
    }
    return (rouge_result)e->code;
}

static rouge_result fail_arg(rouge_error *out, const char *what)
{
    rs_error e = {0};
    rs_fail(&e, RS_ERR_ARG, "%s", what);
    return fail_out(out, &e);
}

// An output path must not name the .rsf the face was loaded from (the CLI refuses the same).
static rs_result refuse_source(const rouge_face *f, const char *path, rs_error *e)
{
    if (f->have_source && rs_file_is(path, &f->source))
        return rs_fail(e, RS_ERR_ARG, "%.400s is the file this face was loaded from: not overwriting it", path);
    return RS_OK;
}

const char *rouge_result_name(rouge_result r)
{
    static const char *const names[] = {"ROUGE_OK", "ROUGE_ERR_IO", "ROUGE_ERR_FORMAT", "ROUGE_ERR_LIMIT",
                                        "ROUGE_ERR_NOMEM", "ROUGE_ERR_GL", "ROUGE_ERR_ARG",
                                        "ROUGE_ERR_CANCELLED"};
    return (unsigned)r < RS_COUNT_OF(names) ? names[r] : "ROUGE_ERR_?";
}

void rouge_free(void *p) { free(p); }

// The numbers are the header's; a host built against another header sees the difference here.
#define ROUGE_STR2(x) #x
#define ROUGE_STR(x) ROUGE_STR2(x)
const char *rouge_version(void)
{
    return ROUGE_STR(ROUGE_VERSION_MAJOR) "." ROUGE_STR(ROUGE_VERSION_MINOR) "." ROUGE_STR(ROUGE_VERSION_PATCH);
}

uint32_t rouge_version_number(void) { return ROUGE_VERSION_NUMBER; }

int rouge_environment_count(void) { return rs_env_name_count(); }
const char *rouge_environment_name(int i) { return rs_env_name(i); }

// --- streams ---------------------------------------------------------------------------------------------

rouge_result rouge_stream_create(const char *name, uint64_t total_bytes, rouge_stream **out, rouge_error *err)
{
    rs_error e = {0};
    if (!out) return fail_arg(err, "stream: out is required");
    rouge_stream *s = calloc(1, sizeof *s);
    if (!s) return rs_fail(&e, RS_ERR_NOMEM, "stream: out of memory"), fail_out(err, &e);
    if (rs_splat_loader_create(&(rs_splat_loader_desc){.name = name, .total_bytes = total_bytes}, &s->ld, &e)) {
        free(s);
        return fail_out(err, &e);
    }
    pthread_mutex_init(&s->mu, NULL);
    *out = s;
    return ROUGE_OK;
}

rouge_result rouge_stream_feed(rouge_stream *s, const void *data, size_t size, rouge_error *err)
{
    rs_error e = {0};
    if (!s) return fail_arg(err, "stream: no stream");
    if (!data && size) return fail_arg(err, "stream: no data for a non-zero size");
    pthread_mutex_lock(&s->mu);
    rs_result r = s->taken ? rs_fail(&e, RS_ERR_ARG, "stream: already handed to a face") : rs_splat_loader_feed(s->ld, data, size, &e);
    if (!r) s->bytes += size;
    pthread_mutex_unlock(&s->mu);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

static rouge_stream_progress stream_progress(rouge_stream *s)
{
    if (s->taken) return s->final;
    const rs_splat_header *h = rs_splat_loader_header(s->ld);
    return (rouge_stream_progress){.bytes = s->bytes, .splats = h ? h->count : 0,
                                   .decoded = rs_splat_loader_decoded(s->ld), .ready = rs_splat_loader_ready(s->ld),
                                   .complete = rs_splat_loader_complete(s->ld)};
}

rouge_stream_progress rouge_stream_get_progress(rouge_stream *s)
{
    if (!s) return (rouge_stream_progress){0};
    pthread_mutex_lock(&s->mu);
    rouge_stream_progress p = stream_progress(s);
    pthread_mutex_unlock(&s->mu);
    return p;
}

void rouge_stream_destroy(rouge_stream *s)
{
    if (!s) return;
    rs_splat_loader_destroy(s->ld);
    pthread_mutex_destroy(&s->mu);
    free(s);
}

// The cloud a face gets from a stream: all of it once complete (handed over), else a preview of the
// complete LOD levels.
static rs_result stream_cloud(rouge_stream *s, rs_splat_cloud **out, rs_error *e)
{
    pthread_mutex_lock(&s->mu);
    rs_result r;
    if (s->taken) {
        r = rs_fail(e, RS_ERR_ARG, "stream: its splats already went to a face");
    } else if (rs_splat_loader_complete(s->ld)) {
        // Still complete after the hand-over: a reading thread that checks between its last bytes and
        // its exit must not take the stream for a truncated one.
        rouge_stream_progress p = stream_progress(s);
        r = rs_splat_loader_finish(s->ld, out, e);
        s->taken = r == RS_OK;
        s->final = p;
    } else {
        uint32_t ready = rs_splat_loader_ready(s->ld);
        r = ready ? rs_splat_loader_preview(s->ld, ready, out, e)
                  : rs_fail(e, RS_ERR_ARG, "stream: no LOD level has arrived yet");
    }
    pthread_mutex_unlock(&s->mu);
    return r;
}

// --- the host's GL state -------------------------------------------------------------------------------------

// The pixel-store state every transfer reads (glReadPixels, glTexImage*, glTexSubImage*), GL's defaults
// while rouge runs: a host's row length or skips would make a transfer read or write outside rouge's
// buffers. The renderer sets the alignment it needs itself.
static const struct {
    GLenum name;
    GLint value;
} pixel_store[] = {
    {GL_PACK_ALIGNMENT, 4},   {GL_PACK_ROW_LENGTH, 0},     {GL_PACK_SKIP_PIXELS, 0},     {GL_PACK_SKIP_ROWS, 0},
    {GL_UNPACK_ALIGNMENT, 4}, {GL_UNPACK_ROW_LENGTH, 0},   {GL_UNPACK_IMAGE_HEIGHT, 0},  {GL_UNPACK_SKIP_PIXELS, 0},
    {GL_UNPACK_SKIP_ROWS, 0}, {GL_UNPACK_SKIP_IMAGES, 0},
};
#define PIXEL_STORE_COUNT 10
_Static_assert(RS_COUNT_OF(pixel_store) == PIXEL_STORE_COUNT, "pixel_store");

// The context current on this thread as a number; 0 when none (or one EGL does not know: GLX, WGL).
static uintptr_t current_context(void)
{
#ifdef __EMSCRIPTEN__
    // A WebGL context made through the html5 API is no EGL context.
    return (uintptr_t)emscripten_webgl_get_current_context();
#else
    return (uintptr_t)eglGetCurrentContext();
#endif
}

// A face's GL objects exist in the context it was created in: with none current, GL calls do nothing;
// with another, the face's object names would name the host's own objects.
static rs_result check_context(const rouge_face *f, rs_error *e)
{
    // 0: created in a context EGL does not know (GLX, WGL, CGL); it cannot be told apart, so trust it.
    if (!f->context) return RS_OK;
    uintptr_t now = current_context();
    if (!now) return rs_fail(e, RS_ERR_GL, "no GL context is current on this thread (the face's must be)");
    if (now != f->context)
        return rs_fail(e, RS_ERR_GL, "another GL context is current, not the one the face was created in");
    return RS_OK;
}

// The texture targets the renderer binds (the fine layer's fields are 3D, the lamps' shadow maps an array).
static const struct {
    GLenum target, binding;
} texture_targets[3] = {{GL_TEXTURE_2D, GL_TEXTURE_BINDING_2D},
                        {GL_TEXTURE_3D, GL_TEXTURE_BINDING_3D},
                        {GL_TEXTURE_2D_ARRAY, GL_TEXTURE_BINDING_2D_ARRAY}};

// Everything the renderer (or a blit) may change, saved on entry and put back on exit; on entry the
// state the renderer assumes but never sets itself (no culling, scissor, stencil, polygon offset,
// all colour channels written, default pixel store, depth range 0..1, no sampler objects, the default
// transform feedback object) is established.
typedef struct gl_saved {
    GLint draw_fbo, read_fbo, viewport[4], scissor_box[4];
    GLint program, vao, array_buffer, tf_buffer, pack_buffer, unpack_buffer;
    GLint active_texture, tex[RS_RENDER_TEXTURE_UNITS][3];  // per unit: 2D, 3D, 2D array
    GLint sampler[RS_RENDER_TEXTURE_UNITS];  // a host's sampler objects would override rouge's filtering
    GLint tf_object;
    GLint blend_src_rgb, blend_dst_rgb, blend_src_a, blend_dst_a, blend_eq_rgb, blend_eq_a;
    GLint depth_func, pixel_store[PIXEL_STORE_COUNT];
    GLboolean depth_mask, color_mask[4];
    GLboolean blend, depth_test, scissor_test, stencil_test, cull_face, polygon_offset, discard, alpha_cov;
    GLfloat depth_clear, depth_range[2], clear_color[4];
} gl_saved;

// Entry to every call that uses GL: the face's context must be current; errors the host left pending
// are taken off the context (the renderer's checks must see only rouge's own, and GL cannot put them
// back) and the first is kept for rouge_face_take_host_gl_error; then the state is saved. Nothing is
// saved on failure (no gl_restore then).
static void gl_capture(gl_saved *s);

// The GL errors the host left pending: off the context, the first kept for rouge_face_take_host_gl_error.
static void take_host_errors(rouge_face *f)
{
    // Bounded: a lost context may report its loss more than once.
    for (int i = 0; i < 32; i++) {
        GLenum pending = glGetError();
        if (pending == GL_NO_ERROR) break;
        if (!f->host_gl_error) f->host_gl_error = pending;
    }
}

static rs_result gl_save(rouge_face *f, gl_saved *s, rs_error *e)
{
    rs_result r = check_context(f, e);
    if (r) return r;
    take_host_errors(f);
    gl_capture(s);
    return RS_OK;
}

// Saves the state rouge touches into s, then sets rouge's defaults (pixel store, no scissor, ...).
static void gl_capture(gl_saved *s)
{
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &s->draw_fbo);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &s->read_fbo);
    glGetIntegerv(GL_VIEWPORT, s->viewport);
    glGetIntegerv(GL_SCISSOR_BOX, s->scissor_box);
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s->vao);
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &s->array_buffer);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BUFFER_BINDING, &s->tf_buffer);
    glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &s->pack_buffer);
    glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &s->unpack_buffer);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &s->active_texture);
    for (int i = 0; i < RS_RENDER_TEXTURE_UNITS; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        for (int t = 0; t < 3; t++) glGetIntegerv(texture_targets[t].binding, &s->tex[i][t]);
        glGetIntegerv(GL_SAMPLER_BINDING, &s->sampler[i]);
        glBindSampler((GLuint)i, 0);
    }
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BINDING, &s->tf_object);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
    glGetIntegerv(GL_BLEND_SRC_RGB, &s->blend_src_rgb);
    glGetIntegerv(GL_BLEND_DST_RGB, &s->blend_dst_rgb);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &s->blend_src_a);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &s->blend_dst_a);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &s->blend_eq_rgb);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &s->blend_eq_a);
    glGetIntegerv(GL_DEPTH_FUNC, &s->depth_func);
    for (int i = 0; i < PIXEL_STORE_COUNT; i++) {
        glGetIntegerv(pixel_store[i].name, &s->pixel_store[i]);
        glPixelStorei(pixel_store[i].name, pixel_store[i].value);
    }
    glGetBooleanv(GL_DEPTH_WRITEMASK, &s->depth_mask);
    glGetBooleanv(GL_COLOR_WRITEMASK, s->color_mask);
    glGetFloatv(GL_DEPTH_CLEAR_VALUE, &s->depth_clear);
    glGetFloatv(GL_DEPTH_RANGE, s->depth_range);
    glGetFloatv(GL_COLOR_CLEAR_VALUE, s->clear_color);
    glDepthRangef(0.0f, 1.0f);  // the renderer reconstructs points from depths in 0..1
    s->blend = glIsEnabled(GL_BLEND);
    s->depth_test = glIsEnabled(GL_DEPTH_TEST);
    s->scissor_test = glIsEnabled(GL_SCISSOR_TEST);
    s->stencil_test = glIsEnabled(GL_STENCIL_TEST);
    s->cull_face = glIsEnabled(GL_CULL_FACE);
    s->polygon_offset = glIsEnabled(GL_POLYGON_OFFSET_FILL);
    s->discard = glIsEnabled(GL_RASTERIZER_DISCARD);
    s->alpha_cov = glIsEnabled(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glDisable(GL_SCISSOR_TEST);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_RASTERIZER_DISCARD);
    glDisable(GL_SAMPLE_ALPHA_TO_COVERAGE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
}

static void gl_enable(GLenum cap, GLboolean on)
{
    if (on) glEnable(cap);
    else glDisable(cap);
}

static void gl_restore(const gl_saved *s)
{
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)s->draw_fbo);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, (GLuint)s->read_fbo);
    glViewport(s->viewport[0], s->viewport[1], s->viewport[2], s->viewport[3]);
    glScissor(s->scissor_box[0], s->scissor_box[1], s->scissor_box[2], s->scissor_box[3]);
    glUseProgram((GLuint)s->program);
    glBindVertexArray((GLuint)s->vao);
    glBindBuffer(GL_ARRAY_BUFFER, (GLuint)s->array_buffer);
    glBindBuffer(GL_TRANSFORM_FEEDBACK_BUFFER, (GLuint)s->tf_buffer);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, (GLuint)s->pack_buffer);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, (GLuint)s->unpack_buffer);
    for (int i = 0; i < RS_RENDER_TEXTURE_UNITS; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        for (int t = 0; t < 3; t++) glBindTexture(texture_targets[t].target, (GLuint)s->tex[i][t]);
        glBindSampler((GLuint)i, (GLuint)s->sampler[i]);
    }
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, (GLuint)s->tf_object);
    glActiveTexture((GLenum)s->active_texture);
    glBlendFuncSeparate((GLenum)s->blend_src_rgb, (GLenum)s->blend_dst_rgb, (GLenum)s->blend_src_a,
                        (GLenum)s->blend_dst_a);
    glBlendEquationSeparate((GLenum)s->blend_eq_rgb, (GLenum)s->blend_eq_a);
    glDepthFunc((GLenum)s->depth_func);
    glDepthMask(s->depth_mask);
    glClearDepthf(s->depth_clear);
    glDepthRangef(s->depth_range[0], s->depth_range[1]);
    glClearColor(s->clear_color[0], s->clear_color[1], s->clear_color[2], s->clear_color[3]);
    glColorMask(s->color_mask[0], s->color_mask[1], s->color_mask[2], s->color_mask[3]);
    for (int i = 0; i < PIXEL_STORE_COUNT; i++) glPixelStorei(pixel_store[i].name, s->pixel_store[i]);
    gl_enable(GL_BLEND, s->blend);
    gl_enable(GL_DEPTH_TEST, s->depth_test);
    gl_enable(GL_SCISSOR_TEST, s->scissor_test);
    gl_enable(GL_STENCIL_TEST, s->stencil_test);
    gl_enable(GL_CULL_FACE, s->cull_face);
    gl_enable(GL_POLYGON_OFFSET_FILL, s->polygon_offset);
    gl_enable(GL_RASTERIZER_DISCARD, s->discard);
    gl_enable(GL_SAMPLE_ALPHA_TO_COVERAGE, s->alpha_cov);
}

rouge_result rouge_query_caps(rouge_caps *out, rouge_error *err)
{
    rs_gl_caps c = {0};
    rs_error e = {0};
    if (!out) return fail_arg(err, "caps: out is required");
    if (rs_gl_query_caps(&c, &e) != RS_OK) return fail_out(err, &e);
    if (c.major < 3) {
        rs_fail(&e, RS_ERR_GL, "the current context is GLES %d.%d; rouge needs 3.0", c.major, c.minor);
        return fail_out(err, &e);
    }
    *out = (rouge_caps){.gles_major = c.major, .gles_minor = c.minor, .float_targets = c.float_rt,
                        .point_size_max = c.point_size_max, .max_draw_buffers = c.max_draw_buffers,
                        .max_texture_size = c.max_texture_size};
    snprintf(out->renderer, sizeof out->renderer, "%s", c.renderer);
    snprintf(out->version, sizeof out->version, "%s", c.version);
    return ROUGE_OK;
}

// --- the view --------------------------------------------------------------------------------------------

static bool all_zero(const void *p, size_t n)
{
    const unsigned char *b = p;
    for (size_t i = 0; i < n; i++)
        if (b[i]) return false;
    return true;
}

// The renderer's view for the public one, at w x h pixels: every zero field becomes its default.
static rs_view to_rs_view(const rouge_view *p, int w, int h)
{
    rs_view v = rs_view_defaults();
    v.width = w, v.height = h;
    v.yaw_deg = p->yaw_deg, v.pitch_deg = p->pitch_deg;
    if (p->zoom > 0) v.zoom = p->zoom;
    if (p->fov_deg > 0) v.fov_deg = p->fov_deg;
    v.pan[0] = p->pan[0], v.pan[1] = p->pan[1];
    const rouge_light *in[2] = {&p->key, &p->fill};
    rs_light *out[2] = {&v.key, &v.fill};
    for (int i = 0; i < 2; i++) {
        if (all_zero(in[i], sizeof *in[i])) continue;
        out[i]->yaw_deg = in[i]->yaw_deg, out[i]->pitch_deg = in[i]->pitch_deg;
        out[i]->intensity = in[i]->intensity > 0 ? in[i]->intensity : (i == 0 ? 1.0f : 0.0f);
        bool black = in[i]->color[0] <= 0 && in[i]->color[1] <= 0 && in[i]->color[2] <= 0;
        for (int c = 0; c < 3; c++) out[i]->color[c] = black ? 1.0f : in[i]->color[c];
    }
    if (p->ambient != 0) v.ambient = p->ambient > 0 ? p->ambient : 0.0f;
    // "paper": the paper's lamp (and, by the renderer's defaults, its composite and no tone curve).
    v.lighting = rs_env_is_paper(p->env) ? RS_LIGHTING_LIGHTS : RS_LIGHTING_ENV;
    v.env_rotate_deg = p->env_rotation_deg;
    v.mode = (rs_render_mode)p->mode;
    v.pipeline = p->pipeline == ROUGE_PIPELINE_REFERENCE ? RS_PIPELINE_REFERENCE : RS_PIPELINE_MOBILE;
    v.composite = (rs_composite)p->composite;
    if (p->exposure > 0) v.exposure = p->exposure;
    if (p->background[3] > 0)
        for (int c = 0; c < 3; c++) v.background[c] = p->background[c];
    v.no_shadows = p->no_shadows;
    v.hide_makeup = p->hide_makeup;
    if (p->specular_scale > 0) v.rho_s_scale = p->specular_scale;
    v.max_splats = p->max_splats;
    v.kernel_count = p->kernel_count;
    v.lod_density = p->lod_density;
    v.prim = (rs_splat_prim)p->primitive;
    v.use_matrices = p->use_matrices;
    if (p->use_matrices) {
        memcpy(v.view_matrix, p->view_matrix, sizeof v.view_matrix);
        memcpy(v.proj_matrix, p->proj_matrix, sizeof v.proj_matrix);
    }
    return v;
}

static float ratio_of(const rouge_view *v) { return v->pixel_ratio > 0 ? v->pixel_ratio : 1.0f; }

// The frame pointer coordinates refer to: the last one, or (before any) the view at its own size.
static const rs_view *pointer_view(rouge_face *f)
{
    if (!f->have_frame) {
        int w = f->view.width > 0 ? f->view.width : ROUGE_DEFAULT_SIZE;
        int h = f->view.height > 0 ? f->view.height : ROUGE_DEFAULT_SIZE;
        f->frame_view = to_rs_view(&f->view, w, h);
        f->frame_ratio = ratio_of(&f->view);
    }
    return &f->frame_view;
}

// Camera changes also apply to the last frame's view, so gestures later in the same batch of events
// pick through the camera they see.
static void camera_changed(rouge_face *f)
{
    f->frame_view.yaw_deg = f->view.yaw_deg, f->frame_view.pitch_deg = f->view.pitch_deg;
    f->frame_view.zoom = f->view.zoom > 0 ? f->view.zoom : 1.0f;
    f->frame_view.pan[0] = f->view.pan[0], f->frame_view.pan[1] = f->view.pan[1];
    f->changed = true;
}

// The host's camera (view.use_matrices): finite; the view matrix rigid (the renderer measures lengths in
// model units through it), the projection a perspective one (near and far follow from it). Column-major:
// m[col * 4 + row].
static rs_result check_matrices(const rouge_view *v, rs_error *e)
{
    const float *m = v->view_matrix, *p = v->proj_matrix;
    for (int i = 0; i < 32; i++) {
        float x = i < 16 ? m[i] : p[i - 16];
        if (!isfinite(x))
            return rs_fail(e, RS_ERR_ARG, "view.%s[%d] is %g", i < 16 ? "view_matrix" : "proj_matrix", i % 16, x);
    }
    for (int c = 0; c < 3; c++)
        for (int d = 0; d <= c; d++) {
            float dot = m[c * 4] * m[d * 4] + m[c * 4 + 1] * m[d * 4 + 1] + m[c * 4 + 2] * m[d * 4 + 2];
            if (fabsf(dot - (c == d ? 1.0f : 0.0f)) > 1e-3f)
                return rs_fail(e, RS_ERR_ARG, "view.view_matrix is not rigid (columns %d and %d: dot %g)", d, c, dot);
        }
    if (fabsf(m[3]) > 1e-6f || fabsf(m[7]) > 1e-6f || fabsf(m[11]) > 1e-6f || fabsf(m[15] - 1.0f) > 1e-6f)
        return rs_fail(e, RS_ERR_ARG, "view.view_matrix: last row is not 0 0 0 1");
    if (fabsf(p[3]) > 1e-6f || fabsf(p[7]) > 1e-6f || fabsf(p[11] + 1.0f) > 1e-6f || fabsf(p[15]) > 1e-6f)
        return rs_fail(e, RS_ERR_ARG, "view.proj_matrix: not a perspective projection (last row must be 0 0 -1 0)");
    float near_z = p[14] / (p[10] - 1.0f), far_z = p[14] / (p[10] + 1.0f);
    if (!(p[0] > 0) || !(p[5] > 0) || !(near_z > 0) || !(far_z > near_z) || !isfinite(far_z))
        return rs_fail(e, RS_ERR_ARG, "view.proj_matrix: no perspective with near > 0 (near %g, far %g, focal %g %g)",
                       near_z, far_z, p[0], p[5]);
    return RS_OK;
}

// Every field of a view the renderer would refuse later, named: a bad view fails at set_view (the
// previous one stays), never at every later frame.
static rs_result check_view(const rouge_view *v, rs_error *e)
{
    const struct {
        const char *name;
        int value, max;
    } enums[] = {{"mode", (int)v->mode, ROUGE_MODE_COUNT - 1},
                 {"pipeline", (int)v->pipeline, ROUGE_PIPELINE_REFERENCE},
                 {"composite", (int)v->composite, ROUGE_COMPOSITE_PHYSICAL},
                 {"primitive", (int)v->primitive, ROUGE_PRIMITIVE_QUADS}};
    for (size_t i = 0; i < RS_COUNT_OF(enums); i++)
        if (enums[i].value < 0 || enums[i].value > enums[i].max)
            return rs_fail(e, RS_ERR_ARG, "view.%s %d is unknown (0..%d)", enums[i].name, enums[i].value,
                           enums[i].max);
    if (v->width < 0 || v->width > ROUGE_VIEW_MAX_SIZE)
        return rs_fail(e, RS_ERR_ARG, "view.width %d is outside 0..%d", v->width, ROUGE_VIEW_MAX_SIZE);
    if (v->height < 0 || v->height > ROUGE_VIEW_MAX_SIZE)
        return rs_fail(e, RS_ERR_ARG, "view.height %d is outside 0..%d", v->height, ROUGE_VIEW_MAX_SIZE);
    if (v->kernel_count != 0 && (v->kernel_count < 2 || v->kernel_count > 4))
        return rs_fail(e, RS_ERR_ARG, "view.kernel_count %d is outside 2..4 (0 = 3)", v->kernel_count);
    const struct {
        const char *name;
        float value;
    } nums[] = {{"yaw_deg", v->yaw_deg}, {"pitch_deg", v->pitch_deg}, {"zoom", v->zoom}, {"fov_deg", v->fov_deg},
                {"pan[0]", v->pan[0]}, {"pan[1]", v->pan[1]}, {"env_rotation_deg", v->env_rotation_deg},
                {"key.yaw_deg", v->key.yaw_deg}, {"key.pitch_deg", v->key.pitch_deg},
                {"key.color[0]", v->key.color[0]}, {"key.color[1]", v->key.color[1]},
                {"key.color[2]", v->key.color[2]}, {"key.intensity", v->key.intensity},
                {"fill.yaw_deg", v->fill.yaw_deg}, {"fill.pitch_deg", v->fill.pitch_deg},
                {"fill.color[0]", v->fill.color[0]}, {"fill.color[1]", v->fill.color[1]},
                {"fill.color[2]", v->fill.color[2]}, {"fill.intensity", v->fill.intensity},
                {"ambient", v->ambient}, {"exposure", v->exposure}, {"background[0]", v->background[0]},
                {"background[1]", v->background[1]}, {"background[2]", v->background[2]},
                {"background[3]", v->background[3]}, {"specular_scale", v->specular_scale},
                {"lod_density", v->lod_density}};
    for (size_t i = 0; i < RS_COUNT_OF(nums); i++) {
        float x = nums[i].value;
        if (isnan(x)) return rs_fail(e, RS_ERR_ARG, "view.%s is NaN", nums[i].name);
        if (isinf(x)) return rs_fail(e, RS_ERR_ARG, "view.%s is %sinf", nums[i].name, x < 0 ? "-" : "");
        // The renderer's own bound on every number of a view.
        if (fabsf(x) > 1e6f) return rs_fail(e, RS_ERR_ARG, "view.%s %g is beyond +-1e6", nums[i].name, x);
    }
    if (v->fov_deg != 0 && !(v->fov_deg >= RS_VIEW_FOV_MIN_DEG && v->fov_deg <= RS_VIEW_FOV_MAX_DEG))
        return rs_fail(e, RS_ERR_ARG, "view.fov_deg %g is outside %g..%g (0 = 30)", v->fov_deg, RS_VIEW_FOV_MIN_DEG,
                       RS_VIEW_FOV_MAX_DEG);
    if (isnan(v->pixel_ratio) || (v->pixel_ratio != 0 && !(v->pixel_ratio >= PIXEL_RATIO_MIN && v->pixel_ratio <= PIXEL_RATIO_MAX)))
        return rs_fail(e, RS_ERR_ARG, "view.pixel_ratio %g is outside %g..%g (0 = 1)", v->pixel_ratio, PIXEL_RATIO_MIN,
                       PIXEL_RATIO_MAX);
    return v->use_matrices ? check_matrices(v, e) : RS_OK;
}

// An environment the host added from memory, or NULL.
static const rs_env *face_env(const rouge_face *f, const char *name)
{
    for (int i = 0; i < f->env_count; i++)
        if (!strcmp(f->envs[i].name, name)) return f->envs[i].env;
    return NULL;
}

rouge_result rouge_face_add_environment(rouge_face *f, const char *name, const void *rse, size_t size,
                                        rouge_error *err)
{
    rs_error e = {0};
    if (!f) return fail_arg(err, "environment: no face");
    if (!name || !name[0] || strlen(name) >= ROUGE_ENV_MAX || rs_env_is_paper(name))
        return fail_arg(err, "environment: the name must be 1..63 bytes and not \"paper\"");
    if (!rse) return fail_arg(err, "environment: no data");
    int slot = 0;
    while (slot < f->env_count && strcmp(f->envs[slot].name, name)) slot++;
    if (slot == ROUGE_MAX_ENVIRONMENTS)
        return rs_fail(&e, RS_ERR_LIMIT, "environment '%s': the face has %d already", name, ROUGE_MAX_ENVIRONMENTS),
               fail_out(err, &e);
    rs_env *env = NULL;
    rs_result r = rs_env_load_memory(rse, size, &env, &e);
    if (r) {
        rs_error inner = e;
        rs_fail(&e, inner.code, "environment '%s': %s", name, inner.msg);
        return fail_out(err, &e);
    }
    if (!strcmp(f->env_name, name)) {
        // The view lights with this name now: relight it with the new one.
        gl_saved s;
        if (!(r = gl_save(f, &s, &e))) {
            r = rs_render_set_env(f->ren, env, &e);
            gl_restore(&s);
        }
        if (r) {
            if (!rs_render_has_env(f->ren)) f->env_name[0] = 0;
            rs_env_destroy(env);
            return fail_out(err, &e);
        }
        f->changed = true;
    }
    if (slot == f->env_count) f->env_count++;
    rs_env_destroy(f->envs[slot].env);
    snprintf(f->envs[slot].name, sizeof f->envs[slot].name, "%s", name);
    f->envs[slot].env = env;
    return ROUGE_OK;
}

rouge_result rouge_face_set_view(rouge_face *f, const rouge_view *view, rouge_error *err)
{
    if (!f) return fail_arg(err, "view: no face");
    rouge_view v = view ? *view : (rouge_view){0};
    rs_error ve = {0};
    if (check_view(&v, &ve)) return fail_out(err, &ve);
    const char *env = v.env && v.env[0] ? v.env : RS_ENV_DEFAULT;
    if (strlen(env) >= ROUGE_ENV_MAX) return fail_arg(err, "view: environment name or path too long");
    if (!rs_env_is_paper(env) && strcmp(env, f->env_name) != 0) {
        // A new environment: load and upload it now, so a bad name or file fails here and the old
        // view stays.
        rs_env *e_cpu = NULL;
        const rs_env *own = face_env(f, env);
        rs_error e = {0};
        rs_result r = own ? RS_OK : rs_env_open(env, f->env_dir, &e_cpu, &e);
        gl_saved s;
        if (r == RS_OK && (r = gl_save(f, &s, &e)) == RS_OK) {
            r = rs_render_set_env(f->ren, own ? own : e_cpu, &e);
            gl_restore(&s);
        }
        rs_env_destroy(e_cpu);
        if (r != RS_OK) {
            // The renderer's environment is gone when the upload failed half-way: say so next time.
            if (!rs_render_has_env(f->ren)) f->env_name[0] = 0;
            return fail_out(err, &e);
        }
        snprintf(f->env_name, sizeof f->env_name, "%s", env);
    }
    // The view keeps its own copy of the name (the caller's string need not outlive the call).
    snprintf(f->view_env, sizeof f->view_env, "%s", env);
    v.env = f->view_env;
    f->view = v;
    if (f->have_frame) {
        // Keep the last frame's size for pointer coordinates until the next frame.
        int w = f->frame_view.width, h = f->frame_view.height;
        f->frame_view = to_rs_view(&f->view, w, h);
    }
    f->changed = true;
    return ROUGE_OK;
}

rouge_view rouge_face_get_view(const rouge_face *f) { return f ? f->view : (rouge_view){0}; }

rouge_result rouge_face_target(rouge_face *f, const char *region, float fill, rouge_error *err)
{
    if (!f) return fail_arg(err, "target: no face");
    const rs_splat_header *h = &f->cloud->hdr;
    int idx = -1;
    char names[RS_SPLAT_MAX_REGIONS * 17] = "";
    for (uint32_t k = 0; k < h->region_count; k++) {
        if (region && strcmp(h->regions[k].name, region) == 0) idx = (int)k;
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? "|" : "", h->regions[k].name);
    }
    if (idx < 0) {
        rs_error e = {0};
        rs_fail(&e, RS_ERR_ARG, "target: no region '%.32s' in this face (it has %s)", region ? region : "", names);
        return fail_out(err, &e);
    }
    if (!(fill > 0)) fill = 0.4f;
    int w = f->view.width > 0 ? f->view.width : 512, ht = f->view.height > 0 ? f->view.height : 512;
    rouge_view saved = f->view;
    f->view.pan[0] = f->view.pan[1] = 0;
    rs_view v = to_rs_view(&f->view, w, ht);
    // The region's splats that face the camera, each half of the face apart: a region on both sides
    // (cheeks) is framed on the side that faces the camera more, not between the two.
    float side[3] = {h->up[1] * h->forward[2] - h->up[2] * h->forward[1],
                     h->up[2] * h->forward[0] - h->up[0] * h->forward[2],
                     h->up[0] * h->forward[1] - h->up[1] * h->forward[0]};
    // One pass: per half, the count, the sums of positions and squared lengths (centre and spread follow)
    // and how squarely it faces the camera.
    double sum[2][3] = {{0}}, sq[2] = {0}, facing[2] = {0};
    uint32_t n[2] = {0}, middle = 0;
    for (uint32_t i = 0; i < h->count; i++) {
        if ((int)(f->cloud->packed[i].w[1] >> 24) != idx) continue;
        const float *p = f->cloud->pos[i], *nrm = f->cloud->normal[i];
        float dir[3];
        rs_render_view_dir(f->ren, &v, p, dir);
        float d = nrm[0] * dir[0] + nrm[1] * dir[1] + nrm[2] * dir[2];
        if (d < 0.2f) continue;
        float sd = (p[0] - h->centre[0]) * side[0] + (p[1] - h->centre[1]) * side[1] + (p[2] - h->centre[2]) * side[2];
        int s = sd >= 0;
        middle += fabsf(sd) < 0.05f * h->face_height;
        for (int a = 0; a < 3; a++) sum[s][a] += p[a];
        sq[s] += (double)p[0] * p[0] + (double)p[1] * p[1] + (double)p[2] * p[2];
        facing[s] += d;
        n[s]++;
    }
    if (n[0] + n[1] == 0) {
        f->view = saved;
        rs_error e = {0};
        rs_fail(&e, RS_ERR_ARG, "target: region '%s' does not face the camera from this view", region);
        return fail_out(err, &e);
    }
    uint32_t all = n[0] + n[1];
    // Two-sided when the region has (almost) nothing near the mid-plane: cheeks, not lips or nose.
    bool halves = n[0] > all / 4 && n[1] > all / 4 && middle < all / 20;
    int lo = 0, hi = 1;
    if (halves) lo = hi = facing[1] / n[1] > facing[0] / n[0] ? 1 : 0;
    double c[3] = {0}, q = 0, cn = 0;
    for (int k = lo; k <= hi; k++) {
        for (int a = 0; a < 3; a++) c[a] += sum[k][a];
        q += sq[k], cn += n[k];
    }
    for (int a = 0; a < 3; a++) c[a] /= cn;
    // Size: twice the RMS distance of those splats from their centre.
    double ss = fmax(q - cn * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), 0.0);
    double size = 2.0 * sqrt(ss / (double)cn);
    // Zoom moves the camera along its ray towards the face centre (render_view.c: distance = 0.625 H /
    // tan(fov/2) / zoom). Put it where the region, d_r in front of the centre, spans `fill` of the view.
    float toward[3], hc[3] = {h->centre[0], h->centre[1], h->centre[2]};
    rs_render_view_dir(f->ren, &v, hc, toward);
    double d_r = (c[0] - hc[0]) * toward[0] + (c[1] - hc[1]) * toward[1] + (c[2] - hc[2]) * toward[2];
    double t = tan(0.5 * v.fov_deg * 3.14159265358979 / 180.0);
    double dist = d_r + (size > 0 ? size : h->face_height) / (2.0 * t * fill);
    float zoom = dist > 0 ? (float)(0.625 * h->face_height / t / dist) : 1.0f;
    f->view.zoom = RS_CLAMP(zoom, 1.0f, 10.0f);
    v = to_rs_view(&f->view, w, ht);
    float centre[3] = {(float)c[0], (float)c[1], (float)c[2]}, px[2];
    if (!rs_render_project(f->ren, &v, centre, px)) {
        f->view = saved;
        return fail_arg(err, "target: the region is behind the camera");
    }
    // The pan moves the picture by pan * view height pixels (x right, y down).
    f->view.pan[0] = -(px[0] - 0.5f * (float)w) / (float)ht;
    f->view.pan[1] = -(px[1] - 0.5f * (float)ht) / (float)ht;
    f->changed = true;
    return ROUGE_OK;
}

void rouge_face_orbit(rouge_face *f, float yaw_deg, float pitch_deg)
{
    if (!f || !isfinite(yaw_deg) || !isfinite(pitch_deg)) return;
    f->view.yaw_deg = fmodf(f->view.yaw_deg + yaw_deg, 360.0f);
    f->view.pitch_deg = RS_CLAMP(f->view.pitch_deg + pitch_deg, -PITCH_LIMIT_DEG, PITCH_LIMIT_DEG);
    camera_changed(f);
}

// Pans by pixels of the last frame.
static void pan_px(rouge_face *f, float dx_px, float dy_px)
{
    const rs_view *fv = pointer_view(f);
    f->view.pan[0] += dx_px / (float)fv->height;
    f->view.pan[1] += dy_px / (float)fv->height;
    camera_changed(f);
}

void rouge_face_pan(rouge_face *f, float dx, float dy)
{
    if (!f || !isfinite(dx) || !isfinite(dy)) return;
    pointer_view(f);
    pan_px(f, dx * f->frame_ratio, dy * f->frame_ratio);
}

// Zooms about (x, y), pixels of the last frame.
static void zoom_at_px(rouge_face *f, float factor, float x_px, float y_px)
{
    const rs_view *fv = pointer_view(f);
    float z0 = f->view.zoom > 0 ? f->view.zoom : 1.0f, z1 = RS_CLAMP(z0 * factor, ZOOM_MIN, ZOOM_MAX);
    if (!(factor > 0) || z1 == z0) return;
    // The picture scales about the pan-shifted centre: move the pan so the point under (x, y) stays put.
    float w = (float)fv->width, h = (float)fv->height;
    float ox = (x_px - w * 0.5f) / h, oy = (y_px - h * 0.5f) / h, s = z1 / z0;
    f->view.pan[0] = ox - (ox - f->view.pan[0]) * s;
    f->view.pan[1] = oy - (oy - f->view.pan[1]) * s;
    f->view.zoom = z1;
    camera_changed(f);
}

void rouge_face_zoom_at(rouge_face *f, float factor, float x, float y)
{
    if (!f || !isfinite(factor) || !isfinite(x) || !isfinite(y)) return;
    pointer_view(f);
    zoom_at_px(f, factor, x * f->frame_ratio, y * f->frame_ratio);
}

rouge_result rouge_face_camera_matrices(rouge_face *f, float view_matrix[16], float proj_matrix[16],
                                        rouge_error *err)
{
    if (!f || !view_matrix || !proj_matrix) return fail_arg(err, "camera: face and both matrices are required");
    rs_render_view_matrices(f->ren, pointer_view(f), view_matrix, proj_matrix);
    return ROUGE_OK;
}

// --- picking (the paint session's picker: the ID buffer of the last frame's view) -------------------------

static bool pick_cb(void *user, float x, float y, uint32_t *idx, float hit[3])
{
    rouge_face *f = user;
    gl_saved s;
    rs_error ignored = {0};
    if (gl_save(f, &s, &ignored)) return false;
    bool ok = rs_render_pick(f->ren, pointer_view(f), x, y, idx, hit);
    gl_restore(&s);
    return ok;
}

static float ppu_cb(void *user, const float pos[3])
{
    rouge_face *f = user;
    return rs_render_pixels_per_unit(f->ren, pointer_view(f), pos);
}

static void dir_cb(void *user, const float pos[3], float dir[3])
{
    rouge_face *f = user;
    rs_render_view_dir(f->ren, pointer_view(f), pos, dir);
}

// --- lifecycle -------------------------------------------------------------------------------------------

// Create's stages as rouge_progress names them: its own, then (first_frame) the first frame's, then "done".
static const char *const create_stages[] = {"reading the face", "uploading and compiling", "makeup layer", "lighting"};
static const char *const frame_stages[RS_STAGE_COUNT] = {"shadow map", "visibility", "attributes",
                                                         "light and diffusion", "composite"};
// The first frame's stages' shares of its time (the bundled face on llvmpipe, 320 x 240 to 1280 x 800:
// the shadow map 30-50 %, as it compiles the first shaders; the rest 10-20 % each), cumulative: where
// the fraction stands as each begins.
static const float frame_share_before[RS_STAGE_COUNT] = {0.0f, 0.35f, 0.5f, 0.7f, 0.88f};
#define CREATE_SHARE_WITH_FRAME 0.1f  // create's own stages, when the first frame follows

typedef struct create_progress {
    const rouge_face_desc *d;
    int step, steps;
} create_progress;

// The host's progress callbacks (rouge_face_desc.progress, progress_stage): RS_OK to go on, else the
// cancellation (a code only the public API has) in e. `fraction` is of the whole create.
static rs_result progress(create_progress *p, float fraction, const char *stage, rs_error *e)
{
    const rouge_face_desc *d = p->d;
    p->step = RS_MIN(p->step + 1, p->steps);
    bool go = !d->progress || d->progress(d->progress_user, fraction);
    if (go && d->progress_stage) {
        rouge_progress pr = {fraction, stage, p->step, p->steps};
        go = d->progress_stage(d->progress_user, &pr);
    }
    return go ? RS_OK : rs_fail(e, (rs_result)ROUGE_ERR_CANCELLED, "cancelled");
}

// Create's own stage k (0..3) at its fraction of create without a first frame.
static rs_result create_stage(create_progress *p, int k, float fraction, rs_error *e)
{
    return progress(p, p->d->first_frame ? fraction * CREATE_SHARE_WITH_FRAME : fraction, create_stages[k], e);
}

typedef struct first_frame_ctx {
    rouge_face *f;
    create_progress *p;
    gl_saved *host;
    bool cancelled;
} first_frame_ctx;

// The renderer's stage hook during the first frame: the host's GL state is put back for its callbacks (a
// loading screen may draw and swap), rouge's after them.
static bool first_frame_stage(void *user, rs_render_stage next)
{
    first_frame_ctx *x = user;
    if (next >= RS_STAGE_COUNT) return true;  // "done" comes from create, last
    gl_saved mine;
    gl_capture(&mine);
    gl_restore(x->host);
    rs_error e = {0};
    float fraction = CREATE_SHARE_WITH_FRAME + (1.0f - CREATE_SHARE_WITH_FRAME) * frame_share_before[next];
    x->cancelled = progress(x->p, fraction, frame_stages[next], &e) != RS_OK;
    take_host_errors(x->f);  // the host's own, not the frame's
    gl_capture(x->host);
    gl_restore(&mine);
    return !x->cancelled;
}

static rs_result render_at(rouge_face *f, int w, int h, rs_error *e);

// rouge_face_desc.first_frame: the view's first frame, its stages reported.
static rs_result render_first_frame(rouge_face *f, create_progress *p, rs_error *e)
{
    gl_saved s;
    rs_result r = gl_save(f, &s, e);
    if (r) return r;
    first_frame_ctx x = {f, p, &s, false};
    // Without callbacks there is nothing to report (and no glFinish between the stages is needed).
    if (p->d->progress || p->d->progress_stage) rs_render_set_stage_hook(f->ren, first_frame_stage, &x);
    r = render_at(f, f->view.width > 0 ? f->view.width : ROUGE_DEFAULT_SIZE,
                  f->view.height > 0 ? f->view.height : ROUGE_DEFAULT_SIZE, e);
    rs_render_set_stage_hook(f->ren, NULL, NULL);
    gl_restore(&s);
    if (x.cancelled) return rs_fail(e, (rs_result)ROUGE_ERR_CANCELLED, "cancelled");
    return r;
}

rouge_result rouge_face_create(const rouge_face_desc *desc, rouge_face **out, rouge_error *err)
{
    rs_error e = {0};
    if (!desc || !out) return fail_arg(err, "rouge_face_create: desc and out are required");
    if (!desc->path && !desc->data && !desc->stream)
        return fail_arg(err, "rouge_face_create: desc needs a path, data or a stream");
    create_progress cp = {desc, 0, (int)RS_COUNT_OF(create_stages) + (desc->first_frame ? RS_STAGE_COUNT : 0) + 1};
    if (create_stage(&cp, 0, 0.0f, &e)) return fail_out(err, &e);
    rs_gl_caps caps = {0};
    if (rs_gl_query_caps(&caps, &e) != RS_OK) return fail_out(err, &e);
    rouge_face *f = calloc(1, sizeof *f);
    if (!f) return rs_fail(&e, RS_ERR_NOMEM, "out of memory"), fail_out(err, &e);
    f->context = current_context();
    // The file stays the face's input: saving over it would destroy the face (compared by identity).
    f->have_source = desc->path && rs_file_id_of(desc->path, &f->source);
    f->manual_navigation = desc->manual_navigation;
    f->painting = true;
    if (desc->env_dir) {
        size_t n = strlen(desc->env_dir) + 1;
        if (!(f->env_dir = malloc(n))) {
            free(f);
            return rs_fail(&e, RS_ERR_NOMEM, "out of memory"), fail_out(err, &e);
        }
        memcpy(f->env_dir, desc->env_dir, n);
    }
    rs_result r = desc->path     ? rs_splat_load(desc->path, &f->cloud, &e)
                  : desc->stream ? stream_cloud(desc->stream, &f->cloud, &e)
                                 : rs_splat_load_memory(desc->data, desc->size, &f->cloud, &e);
    // Parsing and decoding take about half of create, the upload and shaders most of the rest.
    if (!r) r = create_stage(&cp, 1, 0.5f, &e);
    gl_saved s;
    if (!r && !(r = gl_save(f, &s, &e))) {
        r = rs_render_create(&(rs_render_desc){.cloud = f->cloud, .caps = &caps,
                                               .force_no_float_targets = desc->no_float_targets},
                             &f->ren, &e);
        gl_restore(&s);
    }
    if (!r) r = create_stage(&cp, 2, 0.85f, &e);
    if (!r) r = rs_makeup_create(f->cloud, &(rs_makeup_desc){.undo_levels = desc->undo_levels}, &f->mk, &e);
    rs_paint_picker pk = {.user = f, .pick = pick_cb, .pixels_per_unit = ppu_cb, .view_dir = dir_cb};
    if (!r) r = rs_paint_create(f->mk, &pk, &(rs_paint_desc){.input.mode = RS_INPUT_PAINT}, &f->paint, &e);
    if (!r) {
        // The pigment is clamped into this face's colour range, in every host alike.
        rs_makeup_uniforms u;
        rs_makeup_get_uniforms(f->mk, &u);
        rs_render_set_makeup_uniforms(f->ren, &u);
        r = create_stage(&cp, 3, 0.9f, &e);
    }
    rouge_result pr = r ? ROUGE_OK : rouge_face_set_view(f, desc->view, err);
    if (!r && !pr && desc->first_frame) r = render_first_frame(f, &cp, &e);
    cp.step = cp.steps - 1;
    if (!r && !pr) r = progress(&cp, 1.0f, "done", &e);
    if (r || pr) {
        rouge_face_destroy(f);
        return r ? fail_out(err, &e) : pr;
    }
    f->changed = !f->have_frame;
    *out = f;
    return ROUGE_OK;
}

void rouge_face_destroy(rouge_face *f)
{
    if (!f) return;
    rs_error ignored = {0};
    rec_writer_stop(f->writer, &ignored);
    rs_strokes_destroy(f->rec);
    free(f->env_dir);
    rs_paint_destroy(f->paint);
    rs_makeup_destroy(f->mk);
    rs_makeup_destroy(f->cmp);
    gl_saved s;
    rs_error e = {0};
    // Only in the face's own context: in another, its object names would delete the host's objects, so
    // the renderer is leaked instead.
    if ((f->ren || f->srgb_tex) && !gl_save(f, &s, &e)) {
        glDeleteTextures(1, &f->srgb_tex);
        glDeleteBuffers(1, &f->srgb_pbo);
        rs_render_destroy(f->ren);
        gl_restore(&s);
    }
    for (int i = 0; i < f->env_count; i++) rs_env_destroy(f->envs[i].env);
    rs_splat_destroy(f->cloud);
    free(f);
}

// --- frames ----------------------------------------------------------------------------------------------

// Uploads the makeup records changed since the last frame, as the layer's per-LOD dirty bands (a stamp
// touches a compact run in every LOD level: one span would cover most of the cloud).
static rs_result flush_makeup(rouge_face *f, rs_error *e)
{
    rs_makeup_range bands[RS_MAKEUP_MAX_RANGES];
    uint32_t n = rs_makeup_take_dirty(f->mk, bands, RS_MAKEUP_MAX_RANGES);
    const rs_makeup_gpu *rec = rs_makeup_records(f->mk);
    f->uploaded = 0;
    for (uint32_t i = 0; i < n; i++) {
        uint32_t count = bands[i].hi - bands[i].lo;
        rs_result r = rs_render_update_makeup(f->ren, bands[i].lo, count, rec + bands[i].lo, e);
        if (r) return r;
        f->uploaded += count;
    }
    return RS_OK;
}

// Hands the renderer `mk`'s fine layer (the per-pixel stamps).
static rs_result upload_fine(rouge_face *f, const rs_makeup *mk, rs_error *e)
{
    rs_makeup_fine_stamp *s = NULL;
    uint32_t n = 0;
    rs_result r = rs_makeup_fine_stamps(mk, &s, &n, e);
    if (!r) r = rs_render_update_fine(f->ren, s, n, mk, e);
    free(s);
    return r;
}

// The painted layer's fine stamps, when they changed since the renderer last had them.
static rs_result flush_fine(rouge_face *f, rs_error *e)
{
    uint32_t v = rs_makeup_fine_version(f->mk);
    if (!f->fine_other && v == f->fine_version) return RS_OK;
    rs_result r = upload_fine(f, f->mk, e);
    if (!r) f->fine_version = v, f->fine_other = false;
    return r;
}

// GL state is saved by the caller.
static rs_result render_at(rouge_face *f, int w, int h, rs_error *e)
{
    if (w > RS_VIEW_MAX_SIZE_PX || h > RS_VIEW_MAX_SIZE_PX)
        return rs_fail(e, RS_ERR_LIMIT, "frame %dx%d is over the %d pixel limit (set view.width and height)", w, h,
                       RS_VIEW_MAX_SIZE_PX);
    rs_result r = flush_makeup(f, e);
    if (!r) r = flush_fine(f, e);
    rs_view v = to_rs_view(&f->view, w, h);
    if (!r && f->view.compare_look && f->cmp) {
        // The renderer holds one makeup layer: the compared look's for this frame, then the painted one's
        // back (both whole: the next frame is drawn in full, no dirty rectangle to gather).
        uint32_t n = rs_makeup_count(f->mk);
        rs_render_invalidate(f->ren);
        r = rs_render_update_makeup(f->ren, 0, n, rs_makeup_records(f->cmp), e);
        f->fine_other = true;
        if (!r) r = upload_fine(f, f->cmp, e);
        if (!r) r = rs_render_frame(f->ren, &v, e);
        rs_render_invalidate(f->ren);
        rs_error e2 = {0};
        rs_result r2 = rs_render_update_makeup(f->ren, 0, n, rs_makeup_records(f->mk), &e2);
        if (!r2) r2 = flush_fine(f, &e2);
        if (!r && r2) r = r2, *e = e2;
    } else {
        if (f->view.compare_look) v.hide_makeup = true;  // no look to compare with: the bare face
        if (!r) r = rs_render_frame(f->ren, &v, e);
    }
    if (r) return r;
    f->frame_view = v;
    f->frame_ratio = ratio_of(&f->view);
    f->have_frame = true;
    f->changed = false;
    return RS_OK;
}

rouge_result rouge_face_render(rouge_face *f, rouge_error *err)
{
    rs_error e = {0};
    gl_saved s;
    if (!f) return fail_arg(err, "render: no face");
    if (gl_save(f, &s, &e)) return fail_out(err, &e);
    int w = f->view.width > 0 ? f->view.width : ROUGE_DEFAULT_SIZE;
    int h = f->view.height > 0 ? f->view.height : ROUGE_DEFAULT_SIZE;
    rs_result r = render_at(f, w, h, &e);
    gl_restore(&s);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

// True when the framebuffer bound for drawing stores sRGB (SRGB8_ALPHA8, an sRGB EGL surface): GL then
// encodes what a blit writes. Its first draw buffer speaks for all.
static bool draw_target_is_srgb(void)
{
    GLint buf = GL_NONE, type = GL_NONE, enc = GL_LINEAR;
    glGetIntegerv(GL_DRAW_BUFFER0, &buf);
    if (buf != GL_NONE)
        glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, (GLenum)buf, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE,
                                              &type);
    if (type != GL_NONE)
        glGetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, (GLenum)buf,
                                              GL_FRAMEBUFFER_ATTACHMENT_COLOR_ENCODING, &enc);
    // A surfaceless context's framebuffer 0 has nothing to ask: an error of rouge's own query, not the copy's.
    for (int i = 0; i < 32 && glGetError() != GL_NO_ERROR; i++) {
    }
    return type != GL_NONE && enc == GL_SRGB;
}

// The frame's bytes (sRGB already) into an SRGB8_ALPHA8 texture of the face's, through a pixel buffer (no
// CPU round trip): blitting from it decodes to linear and the sRGB target encodes back, so the picture is
// encoded once. The frame is attached for reading.
static GLuint srgb_copy(rouge_face *f, int w, int h)
{
    if (!f->srgb_tex) glGenTextures(1, &f->srgb_tex), glGenBuffers(1, &f->srgb_pbo);
    glBindTexture(GL_TEXTURE_2D, f->srgb_tex);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, f->srgb_pbo);
    if (f->srgb_w != w || f->srgb_h != h) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_SRGB8_ALPHA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glBufferData(GL_PIXEL_PACK_BUFFER, (GLsizeiptr)w * h * 4, NULL, GL_STREAM_COPY);
        f->srgb_w = w, f->srgb_h = h;
    }
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, f->srgb_pbo);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, NULL);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    return f->srgb_tex;
}

rouge_result rouge_face_draw(rouge_face *f, int x, int y, int w, int h, rouge_error *err)
{
    rs_error e = {0};
    gl_saved s;
    if (!f) return fail_arg(err, "draw: no face");
    if (gl_save(f, &s, &e)) return fail_out(err, &e);
    if (w <= 0 || h <= 0) x = s.viewport[0], y = s.viewport[1], w = s.viewport[2], h = s.viewport[3];
    rs_result r = RS_OK;
    if (w <= 0 || h <= 0) r = rs_fail(&e, RS_ERR_ARG, "draw: empty rectangle %dx%d", w, h);
    int rw = f->view.width > 0 ? f->view.width : w, rh = f->view.height > 0 ? f->view.height : h;
    if (!r) r = render_at(f, rw, rh, &e);
    if (!r) {
        // The output texture is attached to a framebuffer of the renderer's; read from it through our own
        // so nothing of the renderer's is exposed.
        GLuint fbo = 0, tex = rs_render_output_texture(f->ren, NULL, NULL);
        glGenFramebuffers(1, &fbo);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, (GLuint)s.draw_fbo);
        if (draw_target_is_srgb())
            glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, srgb_copy(f, rw, rh), 0);
        glBlitFramebuffer(0, 0, rw, rh, x, y, x + w, y + h, GL_COLOR_BUFFER_BIT,
                          rw == w && rh == h ? GL_NEAREST : GL_LINEAR);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo);
        r = rs_gl_check("draw: copying the frame into the target framebuffer (is it multisampled?)", &e);
    }
    gl_restore(&s);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

uint32_t rouge_face_texture(const rouge_face *f, int *width, int *height)
{
    if (!f) {
        if (width) *width = 0;
        if (height) *height = 0;
        return 0;
    }
    return rs_render_output_texture(f->ren, width, height);
}

rouge_result rouge_face_read_rgba(rouge_face *f, uint8_t *rgba, size_t capacity, rouge_error *err)
{
    rs_error e = {0};
    rs_image img = {0};
    gl_saved s;
    if (!f) return fail_arg(err, "read: no face");
    if (gl_save(f, &s, &e)) return fail_out(err, &e);
    rs_result r = rs_render_read(f->ren, &img, &e);
    gl_restore(&s);
    size_t need = (size_t)img.width * (size_t)img.height * 4;
    if (!r && (!rgba || capacity < need))
        r = rs_fail(&e, RS_ERR_ARG, "read: the frame needs %zu bytes, the buffer has %zu", need, capacity);
    if (!r) memcpy(rgba, img.pixels, need);
    rs_image_free(&img);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_write_png(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    rs_image img = {0};
    gl_saved s;
    if (!f) return fail_arg(err, "png: no face");
    if (!path) return fail_arg(err, "png: no path");
    if (refuse_source(f, path, &e) || gl_save(f, &s, &e)) return fail_out(err, &e);
    rs_result r = rs_render_read(f->ren, &img, &e);
    gl_restore(&s);
    if (!r) r = rs_image_write_png(path, &img, &e);
    rs_image_free(&img);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

bool rouge_face_changed(const rouge_face *f) { return f && (f->changed || !f->have_frame); }

uint32_t rouge_face_take_host_gl_error(rouge_face *f)
{
    if (!f) return 0;
    uint32_t e = f->host_gl_error;
    f->host_gl_error = 0;
    return e;
}

// --- painting --------------------------------------------------------------------------------------------

int rouge_cosmetic_count(void) { return (int)rs_cosmetic_count(); }

bool rouge_cosmetic_get(int i, rouge_cosmetic *out)
{
    const rs_cosmetic *c = i >= 0 ? rs_cosmetic_get((uint32_t)i) : NULL;
    if (!c || !out) return false;
    rs_cosmetic_region reg = rs_cosmetic_region_of(c);
    *out = (rouge_cosmetic){.name = c->name, .kind = rs_cosmetic_kind_name(c->kind), .size = c->size_rel,
                            .opacity = c->opacity, .finish = (rouge_finish)(rs_cosmetic_finish(c) + 1),
                            .coverage = c->coverage,
                            .region = reg == RS_COSMETIC_REGION_ANY ? NULL : rs_cosmetic_region_name(reg)};
    memcpy(out->rgb, c->rgb, 3);
    return true;
}

rouge_result rouge_face_set_brush(rouge_face *f, const rouge_brush *brush, rouge_error *err)
{
    if (!f) return fail_arg(err, "brush: no face");
    rouge_brush b = brush ? *brush : (rouge_brush){0};
    const char *name = b.cosmetic ? b.cosmetic : "foundation_1";
    const rs_cosmetic *c = rs_cosmetic_find(name);
    if (!c) {
        rs_error e = {0};
        rs_fail(&e, RS_ERR_ARG, "brush: unknown cosmetic '%.64s'", name);
        return fail_out(err, &e);
    }
    if ((unsigned)b.pressure > ROUGE_PRESSURE_NONE) return fail_arg(err, "brush: unknown pressure map");
    if (!(b.size >= 0 && b.size <= 2) || !(b.opacity >= 0 && b.opacity <= 1))
        return fail_arg(err, "brush: size must be 0..2 (face heights), opacity 0..1");
    if ((unsigned)b.finish > ROUGE_FINISH_SHIMMER) return fail_arg(err, "brush: unknown finish");
    if ((unsigned)b.tool > ROUGE_TOOL_BLEND) {
        rs_error e = {0};
        rs_fail(&e, RS_ERR_ARG, "brush: unknown tool %d (0 paint, 1 smudge, 2 blend)", (int)b.tool);
        return fail_out(err, &e);
    }
    if (b.tool != ROUGE_TOOL_PAINT && b.eraser)
        return fail_arg(err, "brush: eraser and a smudge or blend tool at once (the eraser is a paint tool)");
    if (!(b.coverage <= 1) || !(b.color[3] >= 0) || !isfinite(b.color[0] + b.color[1] + b.color[2]))
        return fail_arg(err, "brush: coverage must be <= 1, the colour finite with alpha >= 0");
    rs_paint_brush pb = {.cosmetic = *c, .size_rel = b.size, .opacity = b.opacity,
                         .pressure = (rs_makeup_pressure)b.pressure, .eraser = b.eraser, .mirror = b.mirror,
                         .any_region = b.any_region, .tool = (rs_paint_tool)b.tool};
    if (b.color[3] > 0 || b.finish != ROUGE_FINISH_DEFAULT || b.coverage != 0) {
        // A custom product of the preset's kind: a recoloured lipstick still belongs on the lips.
        rs_cosmetic *pc = &pb.cosmetic;
        pc->region_mask = rs_cosmetic_region_of(c);
        if (b.color[3] > 0) {
            uint8_t rgb[3];
            for (int i = 0; i < 3; i++) rgb[i] = (uint8_t)lroundf(RS_CLAMP(b.color[i], 0.0f, 1.0f) * 255.0f);
            rs_cosmetic_set_rgb(pc, rgb);
        }
        if (b.finish != ROUGE_FINISH_DEFAULT) rs_cosmetic_set_finish(pc, (rs_finish)(b.finish - 1));
        if (b.coverage != 0) pc->coverage = RS_CLAMP(b.coverage, 0.0f, 1.0f);
        snprintf(pc->name, sizeof pc->name, "custom_%.*s", (int)sizeof pc->name - 8, c->name);
    }
    rs_paint_set_brush(f->paint, &pb);
    return ROUGE_OK;
}

void rouge_face_set_painting(rouge_face *f, bool painting)
{
    if (!f) return;
    f->painting = painting;
    rs_paint_set_mode(f->paint, painting ? RS_INPUT_PAINT : RS_INPUT_VIEW);
}

static rs_strokes_view strokes_view(const rs_view *v)
{
    return (rs_strokes_view){v->yaw_deg, v->pitch_deg, v->zoom, v->fov_deg, (uint32_t)v->width, (uint32_t)v->height,
                             {v->pan[0], v->pan[1]}};
}

rouge_result rouge_face_pointer(rouge_face *f, const rouge_pointer_event *ev, rouge_pointer_result *out,
                                rouge_error *err)
{
    if (!f) return fail_arg(err, "pointer: no face");
    if (!ev || (unsigned)ev->type > ROUGE_POINTER_CANCEL) return fail_arg(err, "pointer: unknown event type");
    if (!isfinite(ev->x) || !isfinite(ev->y) || !isfinite(ev->pressure) || !isfinite(ev->time_s))
        return fail_arg(err, "pointer: x, y, pressure and time_s must be finite");
    rs_error e = {0};
    // Picks happen inside: without the face's context they would silently miss.
    if (check_context(f, &e)) return fail_out(err, &e);
    const rs_view *fv = pointer_view(f);
    if (ev->type == ROUGE_POINTER_DOWN && f->rec) {
        // The stroke file records the camera the pixels refer to.
        rs_strokes_view sv = strokes_view(fv);
        rs_paint_set_recorder(f->paint, f->rec, &sv);
    }
    // Window units to the last frame's pixels; what comes back goes the other way.
    float k = f->frame_ratio;
    rs_input_event in = {(rs_input_type)ev->type, ev->id, ev->x * k, ev->y * k,
                         ev->pressure > 0 ? ev->pressure : 1.0f, ev->time_s};
    rs_paint_result res;
    rs_result r = rs_paint_feed(f->paint, &in, &res, &e);
    if (res.stamps || res.stroke_cancel || res.stroke_end) f->changed = true;
    if (!f->manual_navigation && !f->view.use_matrices) {
        // Degrees per window unit: a drag turns the face alike at every pixel ratio.
        if (res.orbit_dx_px != 0 || res.orbit_dy_px != 0)
            rouge_face_orbit(f, -res.orbit_dx_px / k * ORBIT_DEG_PER_PX, res.orbit_dy_px / k * ORBIT_DEG_PER_PX);
        if (res.pan_dx_px != 0 || res.pan_dy_px != 0) pan_px(f, res.pan_dx_px, res.pan_dy_px);
        if (res.zoom > 0 && res.zoom != 1.0f) zoom_at_px(f, res.zoom, res.zoom_cx_px, res.zoom_cy_px);
    }
    if (!r && res.stroke_end && f->rec) {
        char *text = NULL;
        size_t len = 0;
        r = rs_strokes_write_memory(f->rec, &text, &len, &e);
        if (!r) rec_writer_submit(f->writer, text, len);
    }
    if (!r && f->writer) r = rec_writer_status(f->writer, false, &e);
    if (out)
        *out = (rouge_pointer_result){.stamps = res.stamps, .misses = res.misses, .stroke_begin = res.stroke_begin,
                                      .stroke_end = res.stroke_end, .stroke_cancel = res.stroke_cancel,
                                      .orbit_dx = res.orbit_dx_px / k, .orbit_dy = res.orbit_dy_px / k,
                                      .pan_dx = res.pan_dx_px / k, .pan_dy = res.pan_dy_px / k, .zoom = res.zoom,
                                      .zoom_x = res.zoom_cx_px / k, .zoom_y = res.zoom_cy_px / k};
    (void)fv;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

bool rouge_face_undo(rouge_face *f)
{
    rs_makeup_range d;
    if (!f) return false;
    bool ok = rs_makeup_undo(f->mk, &d);
    f->changed |= ok;
    return ok;
}

bool rouge_face_redo(rouge_face *f)
{
    rs_makeup_range d;
    if (!f) return false;
    bool ok = rs_makeup_redo(f->mk, &d);
    f->changed |= ok;
    return ok;
}

rouge_result rouge_face_clear(rouge_face *f, rouge_error *err)
{
    rs_error e = {0};
    rs_makeup_range d;
    if (!f) return fail_arg(err, "clear: no face");
    f->changed = true;
    return rs_makeup_clear(f->mk, &d, &e) ? fail_out(err, &e) : ROUGE_OK;
}

// --- looks and stroke files -------------------------------------------------------------------------------

rouge_result rouge_face_load_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    rs_makeup_range d;
    if (!f || !path) return fail_arg(err, "look: no face or no path");
    rs_result r = rs_look_load(f->mk, path, &d, &e);
    f->changed = true;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_load_look_memory(rouge_face *f, const void *data, size_t size, rouge_error *err)
{
    rs_error e = {0};
    rs_look *look = NULL;
    rs_makeup_range d;
    if (!f || !data) return fail_arg(err, "look: no face or no data");
    rs_result r = rs_look_parse(data, size, &look, &e);
    if (!r) r = rs_look_apply(look, f->mk, &d, &e);
    rs_look_destroy(look);
    f->changed = true;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_save_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    if (!f || !path) return fail_arg(err, "look: no face or no path");
    return refuse_source(f, path, &e) || rs_look_save(f->mk, path, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_save_look_memory(rouge_face *f, char **data, size_t *size, rouge_error *err)
{
    rs_error e = {0};
    if (!f || !data || !size) return fail_arg(err, "look: face, data and size are required");
    return rs_look_write_memory(f->mk, data, size, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_set_compare_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    if (!f) return fail_arg(err, "compare look: no face");
    if (!path) {
        rs_makeup_destroy(f->cmp);
        f->cmp = NULL;
        f->changed = true;
        return ROUGE_OK;
    }
    rs_makeup *mk = NULL;
    rs_result r = rs_makeup_create(f->cloud, NULL, &mk, &e);
    if (!r) r = rs_look_load(mk, path, NULL, &e);
    if (r) {
        rs_makeup_destroy(mk);
        return fail_out(err, &e);
    }
    rs_makeup_destroy(f->cmp);
    f->cmp = mk;
    f->changed = true;
    return ROUGE_OK;
}

rouge_result rouge_face_record_strokes(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    if (!f) return fail_arg(err, "strokes: no face");
    struct stat st;
    // Refused up front, the recording as it was goes on: a directory would only fail at the first write.
    if (path && stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return rs_fail(&e, RS_ERR_IO, "%.400s: is a directory, not a stroke file", path), fail_out(err, &e);
    if (path && refuse_source(f, path, &e)) return fail_out(err, &e);
    rs_paint_set_recorder(f->paint, NULL, NULL);
    rs_result stopped = rec_writer_stop(f->writer, &e);
    rs_strokes_destroy(f->rec);
    f->rec = NULL, f->writer = NULL;
    if (stopped) return fail_out(err, &e);
    if (!path) return ROUGE_OK;
    if (rs_strokes_create(&f->rec, &e) != RS_OK) return fail_out(err, &e);
    if (rec_writer_start(path, &f->writer, &e) != RS_OK) {
        rs_strokes_destroy(f->rec);
        f->rec = NULL;
        return fail_out(err, &e);
    }
    rs_strokes_view sv = strokes_view(pointer_view(f));
    rs_paint_set_recorder(f->paint, f->rec, &sv);
    return ROUGE_OK;
}

rouge_result rouge_face_flush_strokes(rouge_face *f, rouge_error *err)
{
    rs_error e = {0};
    if (!f) return fail_arg(err, "strokes: no face");
    return f->writer && rec_writer_status(f->writer, true, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_play_strokes(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    rs_strokes *doc = NULL;
    if (!f || !path) return fail_arg(err, "strokes: no face or no path");
    // Each stamp picks through the face's ID buffer: without its context every one would miss.
    if (check_context(f, &e)) return fail_out(err, &e);
    rs_result r = rs_strokes_load(path, &doc, &e);
    // Picks must see each stroke's camera and pixel grid: its view becomes the "last frame" while it plays.
    rs_view saved = f->frame_view;
    bool had_frame = f->have_frame;
    rs_paint_set_recorder(f->paint, NULL, NULL);
    double cover = 0;
    for (uint32_t i = 0; !r && i < doc->count; i++) {
        const rs_strokes_view *sv = &doc->strokes[i].view;
        f->view.yaw_deg = sv->yaw_deg, f->view.pitch_deg = sv->pitch_deg;
        f->view.zoom = sv->zoom, f->view.fov_deg = sv->fov_deg;
        f->view.pan[0] = sv->pan[0], f->view.pan[1] = sv->pan[1];
        f->frame_view = to_rs_view(&f->view, (int)sv->width_px, (int)sv->height_px);
        f->have_frame = true;
        rs_paint_result res;
        r = rs_paint_replay(f->paint, doc, i, sv->width_px, sv->height_px, &res, &e);
        cover += res.cover;
        if (!r && cover > RS_PAINT_MAX_REPLAY_COVER)
            r = rs_fail(&e, RS_ERR_LIMIT, "strokes paint more than %.0f face areas by stroke %u",
                        RS_PAINT_MAX_REPLAY_COVER, i);
    }
    if (r && doc && !strstr(e.msg, path)) {
        // Name the file the bound was met in (the parser's own errors already do).
        rs_error named = e;
        rs_fail(&e, named.code, "%s: %s", path, named.msg);
    }
    if (f->rec) rs_paint_set_recorder(f->paint, f->rec, NULL);
    f->have_frame = had_frame;
    if (had_frame) {
        int w = saved.width, h = saved.height;
        f->frame_view = to_rs_view(&f->view, w, h);
    }
    f->changed = true;
    rs_strokes_destroy(doc);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

// --- queries ---------------------------------------------------------------------------------------------

rouge_result rouge_face_look_info(const rouge_face *f, rouge_look_item *items, int capacity, int *count,
                                  rouge_error *err)
{
    if (!f || !count || capacity < 0 || (capacity > 0 && !items))
        return fail_arg(err, "look info: face and count are required, items for a capacity over 0");
    // Stamps per product of the log (the layer as it is now); the log's product table is in order of
    // first use.
    uint32_t ncos = rs_makeup_log_cosmetic_count(f->mk), nst = rs_makeup_log_count(f->mk);
    uint32_t *stamps = calloc(ncos ? ncos : 1, sizeof *stamps);
    if (!stamps) {
        rs_error e = {0};
        return rs_fail(&e, RS_ERR_NOMEM, "look info: out of memory"), fail_out(err, &e);
    }
    const rs_makeup_applied *log = rs_makeup_log_stamps(f->mk);
    for (uint32_t i = 0; i < nst; i++)
        if (!log[i].eraser && log[i].cosmetic < ncos) stamps[log[i].cosmetic]++;
    int n = 0;
    for (uint32_t c = 0; c < ncos; c++) {
        if (!stamps[c]) continue;
        if (n < capacity) {
            const rs_cosmetic *cos = rs_makeup_log_cosmetic(f->mk, c);
            rouge_look_item *it = &items[n];
            *it = (rouge_look_item){.kind = rs_cosmetic_kind_name(cos->kind),
                                    .finish = (rouge_finish)(rs_cosmetic_finish(cos) + 1),
                                    .coverage = cos->coverage, .stamps = stamps[c]};
            snprintf(it->name, sizeof it->name, "%s", cos->name);
            memcpy(it->rgb, cos->rgb, 3);
        }
        n++;
    }
    free(stamps);
    *count = n;
    return ROUGE_OK;
}

bool rouge_face_pick(rouge_face *f, float x, float y, rouge_pick *out)
{
    uint32_t idx;
    float hit[3];
    if (!f || !isfinite(x) || !isfinite(y)) return false;
    pointer_view(f);
    float k = f->frame_ratio;
    if (!pick_cb(f, x * k, y * k, &idx, hit)) return false;
    if (out) {
        float ppu = rs_render_pixels_per_unit(f->ren, pointer_view(f), hit);
        *out = (rouge_pick){.splat = idx, .position = {hit[0], hit[1], hit[2]},
                            .region = (int)(f->cloud->packed[idx].w[1] >> 24),
                            .brush_radius_px = rs_paint_radius(f->paint) * ppu / k};
    }
    return true;
}

rouge_stats rouge_face_stats(const rouge_face *f)
{
    if (!f) return (rouge_stats){0};
    const rs_splat_header *h = &f->cloud->hdr;
    rs_render_stats rs = rs_render_get_stats(f->ren);
    rouge_stats s = {.splats = h->count, .lod_count = h->lod_count, .face_height_mm = h->face_height * h->mm_per_unit,
                     .splats_drawn = rs.splats_drawn, .kernel_count = rs.kernel_count,
                     .width = f->have_frame ? f->frame_view.width : 0,
                     .height = f->have_frame ? f->frame_view.height : 0, .frame_ms = rs.frame_ms,
                     .float_targets = rs.float_targets, .gpu_bytes = rs.gpu_bytes,
                     .can_undo = rs_makeup_can_undo(f->mk), .can_redo = rs_makeup_can_redo(f->mk),
                     .in_stroke = rs_makeup_in_stroke(f->mk), .look_stamps = rs_makeup_log_count(f->mk),
                     .uploaded_records = f->uploaded};
    memcpy(s.lods, h->lods, sizeof s.lods);
    int w = f->view.width > 0 ? f->view.width : (f->have_frame ? f->frame_view.width : ROUGE_DEFAULT_SIZE);
    int hh = f->view.height > 0 ? f->view.height : (f->have_frame ? f->frame_view.height : ROUGE_DEFAULT_SIZE);
    rs_view v = to_rs_view(&f->view, w, hh);
    v.max_splats = 0;
    s.auto_splats = rs_render_auto_splats(f->ren, &v);
    return s;
}
