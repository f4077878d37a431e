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

// The public result codes are the library's, name for name.
_Static_assert((int)ROUGE_ERR_ARG == (int)RS_ERR_ARG && (int)ROUGE_ERR_GL == (int)RS_ERR_GL, "rouge_result");
_Static_assert((int)ROUGE_MODE_COUNT == (int)RS_MODE_COUNT, "rouge_mode");
_Static_assert(ROUGE_MAX_LODS == RS_SPLAT_MAX_LODS, "ROUGE_MAX_LODS");
_Static_assert((int)ROUGE_COMPOSITE_PHYSICAL == (int)RS_COMPOSITE_PHYSICAL, "rouge_composite");
_Static_assert(sizeof(((rouge_error *)0)->msg) == sizeof(((rs_error *)0)->msg), "rouge_error");

#define ROUGE_ENV_MAX 64
#define ROUGE_DEFAULT_SIZE 512
#define ORBIT_DEG_PER_PX 0.35f
#define PITCH_LIMIT_DEG 80.0f
#define ZOOM_MIN 0.3f
#define ZOOM_MAX 12.0f
#define MAX_TEXTURE_UNITS 8  // the renderer uses units 0..RS_UNIT_LEVEL (render_internal.h)

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
    bool have_frame;
    bool changed;                 // view or makeup changed since the last frame
    bool manual_navigation, painting;
    rs_strokes *rec;              // stroke recording (rouge_face_record_strokes)
    rec_writer *writer;           // writes it to its file off the pointer path
    uint32_t uploaded;            // records uploaded for the last frame
    rs_makeup *cmp;               // the compared look (rouge_face_set_compare_look), NULL = bare
};

// A file arriving piece by piece: the splat loader behind a lock (one thread feeds, the GL thread makes
// faces from it).
struct rouge_stream {
    pthread_mutex_t mu;
    rs_splat_loader *ld;
    uint64_t bytes;
    bool taken;                   // a complete stream's splats went to a face
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

const char *rouge_result_name(rouge_result r)
{
    static const char *const names[] = {"ROUGE_OK", "ROUGE_ERR_IO", "ROUGE_ERR_FORMAT", "ROUGE_ERR_LIMIT",
                                        "ROUGE_ERR_NOMEM", "ROUGE_ERR_GL", "ROUGE_ERR_ARG"};
    return (unsigned)r < RS_COUNT_OF(names) ? names[r] : "ROUGE_ERR_?";
}

void rouge_free(void *p) { free(p); }

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
    pthread_mutex_lock(&s->mu);
    rs_result r = s->taken ? rs_fail(&e, RS_ERR_ARG, "stream: already handed to a face") : rs_splat_loader_feed(s->ld, data, size, &e);
    if (!r) s->bytes += size;
    pthread_mutex_unlock(&s->mu);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_stream_progress rouge_stream_get_progress(rouge_stream *s)
{
    pthread_mutex_lock(&s->mu);
    const rs_splat_header *h = rs_splat_loader_header(s->ld);
    rouge_stream_progress p = {.bytes = s->bytes, .splats = h ? h->count : 0,
                               .decoded = rs_splat_loader_decoded(s->ld), .ready = rs_splat_loader_ready(s->ld),
                               .complete = rs_splat_loader_complete(s->ld)};
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
        r = rs_splat_loader_finish(s->ld, out, e);
        s->taken = r == RS_OK;
    } else {
        uint32_t ready = rs_splat_loader_ready(s->ld);
        r = ready ? rs_splat_loader_preview(s->ld, ready, out, e)
                  : rs_fail(e, RS_ERR_ARG, "stream: no LOD level has arrived yet");
    }
    pthread_mutex_unlock(&s->mu);
    return r;
}

// --- the host's GL state -------------------------------------------------------------------------------------

// Everything the renderer (or a blit) may change, saved on entry and put back on exit; on entry the
// state the renderer assumes but never sets itself (no culling, scissor, stencil, polygon offset,
// all colour channels written) is established.
typedef struct gl_saved {
    GLint draw_fbo, read_fbo, viewport[4], scissor_box[4];
    GLint program, vao, array_buffer, tf_buffer, pack_buffer, unpack_buffer;
    GLint active_texture, tex2d[MAX_TEXTURE_UNITS];
    GLint blend_src_rgb, blend_dst_rgb, blend_src_a, blend_dst_a, blend_eq_rgb, blend_eq_a;
    GLint depth_func, pack_align, unpack_align;
    GLboolean depth_mask, color_mask[4];
    GLboolean blend, depth_test, scissor_test, stencil_test, cull_face, polygon_offset, discard, alpha_cov;
    GLfloat depth_clear;
} gl_saved;

static void gl_save(gl_saved *s)
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
    for (int i = 0; i < MAX_TEXTURE_UNITS; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &s->tex2d[i]);
    }
    glGetIntegerv(GL_BLEND_SRC_RGB, &s->blend_src_rgb);
    glGetIntegerv(GL_BLEND_DST_RGB, &s->blend_dst_rgb);
    glGetIntegerv(GL_BLEND_SRC_ALPHA, &s->blend_src_a);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &s->blend_dst_a);
    glGetIntegerv(GL_BLEND_EQUATION_RGB, &s->blend_eq_rgb);
    glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &s->blend_eq_a);
    glGetIntegerv(GL_DEPTH_FUNC, &s->depth_func);
    glGetIntegerv(GL_PACK_ALIGNMENT, &s->pack_align);
    glGetIntegerv(GL_UNPACK_ALIGNMENT, &s->unpack_align);
    glGetBooleanv(GL_DEPTH_WRITEMASK, &s->depth_mask);
    glGetBooleanv(GL_COLOR_WRITEMASK, s->color_mask);
    glGetFloatv(GL_DEPTH_CLEAR_VALUE, &s->depth_clear);
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
    for (int i = 0; i < MAX_TEXTURE_UNITS; i++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)i);
        glBindTexture(GL_TEXTURE_2D, (GLuint)s->tex2d[i]);
    }
    glActiveTexture((GLenum)s->active_texture);
    glBlendFuncSeparate((GLenum)s->blend_src_rgb, (GLenum)s->blend_dst_rgb, (GLenum)s->blend_src_a,
                        (GLenum)s->blend_dst_a);
    glBlendEquationSeparate((GLenum)s->blend_eq_rgb, (GLenum)s->blend_eq_a);
    glDepthFunc((GLenum)s->depth_func);
    glDepthMask(s->depth_mask);
    glClearDepthf(s->depth_clear);
    glColorMask(s->color_mask[0], s->color_mask[1], s->color_mask[2], s->color_mask[3]);
    glPixelStorei(GL_PACK_ALIGNMENT, s->pack_align);
    glPixelStorei(GL_UNPACK_ALIGNMENT, s->unpack_align);
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
    return v;
}

// The frame pointer coordinates refer to: the last one, or (before any) the view at its own size.
static const rs_view *pointer_view(rouge_face *f)
{
    if (!f->have_frame) {
        int w = f->view.width > 0 ? f->view.width : ROUGE_DEFAULT_SIZE;
        int h = f->view.height > 0 ? f->view.height : ROUGE_DEFAULT_SIZE;
        f->frame_view = to_rs_view(&f->view, w, h);
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

rouge_result rouge_face_set_view(rouge_face *f, const rouge_view *view, rouge_error *err)
{
    rouge_view v = view ? *view : (rouge_view){0};
    if ((unsigned)v.mode >= ROUGE_MODE_COUNT) return fail_arg(err, "view: unknown mode");
    if ((unsigned)v.pipeline > ROUGE_PIPELINE_REFERENCE) return fail_arg(err, "view: unknown pipeline");
    if ((unsigned)v.composite > ROUGE_COMPOSITE_PHYSICAL) return fail_arg(err, "view: unknown composite");
    if ((unsigned)v.primitive > ROUGE_PRIMITIVE_QUADS) return fail_arg(err, "view: unknown primitive");
    if (v.width < 0 || v.height < 0) return fail_arg(err, "view: negative size");
    if (!isfinite(v.env_rotation_deg) || fabsf(v.env_rotation_deg) > 1e6f)
        return fail_arg(err, "view: environment rotation not a finite, sane number");
    const char *env = v.env && v.env[0] ? v.env : RS_ENV_DEFAULT;
    if (strlen(env) >= ROUGE_ENV_MAX) return fail_arg(err, "view: environment name or path too long");
    if (!rs_env_is_paper(env) && strcmp(env, f->env_name) != 0) {
        // A new environment: load and upload it now, so a bad name or file fails here and the old
        // view stays.
        rs_env *e_cpu = NULL;
        rs_error e = {0};
        rs_result r = rs_env_open(env, f->env_dir, &e_cpu, &e);
        if (r == RS_OK) {
            gl_saved s;
            gl_save(&s);
            r = rs_render_set_env(f->ren, e_cpu, &e);
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

rouge_view rouge_face_get_view(const rouge_face *f) { return f->view; }

rouge_result rouge_face_target(rouge_face *f, const char *region, float fill, rouge_error *err)
{
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
    // Zoom moves the camera along its ray towards the face centre (render.c: distance = 0.625 H /
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
    f->view.yaw_deg = fmodf(f->view.yaw_deg + yaw_deg, 360.0f);
    f->view.pitch_deg = RS_CLAMP(f->view.pitch_deg + pitch_deg, -PITCH_LIMIT_DEG, PITCH_LIMIT_DEG);
    camera_changed(f);
}

void rouge_face_pan(rouge_face *f, float dx_px, float dy_px)
{
    const rs_view *fv = pointer_view(f);
    f->view.pan[0] += dx_px / (float)fv->height;
    f->view.pan[1] += dy_px / (float)fv->height;
    camera_changed(f);
}

void rouge_face_zoom_at(rouge_face *f, float factor, float x_px, float y_px)
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

// --- picking (the paint session's picker: the ID buffer of the last frame's view) -------------------------

static bool pick_cb(void *user, float x, float y, uint32_t *idx, float hit[3])
{
    rouge_face *f = user;
    gl_saved s;
    gl_save(&s);
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

rouge_result rouge_face_create(const rouge_face_desc *desc, rouge_face **out, rouge_error *err)
{
    rs_error e = {0};
    if (!desc || !out) return fail_arg(err, "rouge_face_create: desc and out are required");
    if (!desc->path && !desc->data && !desc->stream)
        return fail_arg(err, "rouge_face_create: desc needs a path, data or a stream");
    rs_gl_caps caps = {0};
    if (rs_gl_query_caps(&caps, &e) != RS_OK) return fail_out(err, &e);
    rouge_face *f = calloc(1, sizeof *f);
    if (!f) return rs_fail(&e, RS_ERR_NOMEM, "out of memory"), fail_out(err, &e);
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
    gl_saved s;
    gl_save(&s);
    if (!r)
        r = rs_render_create(&(rs_render_desc){.cloud = f->cloud, .caps = &caps,
                                               .force_no_float_targets = desc->no_float_targets},
                             &f->ren, &e);
    gl_restore(&s);
    if (!r) r = rs_makeup_create(f->cloud, &(rs_makeup_desc){.undo_levels = desc->undo_levels}, &f->mk, &e);
    rs_paint_picker pk = {.user = f, .pick = pick_cb, .pixels_per_unit = ppu_cb, .view_dir = dir_cb};
    if (!r) r = rs_paint_create(f->mk, &pk, &(rs_paint_desc){.input.mode = RS_INPUT_PAINT}, &f->paint, &e);
    if (!r) {
        // The pigment is clamped into this face's colour range, in every host alike.
        rs_makeup_uniforms u;
        rs_makeup_get_uniforms(f->mk, &u);
        rs_render_set_makeup_uniforms(f->ren, &u);
    }
    rouge_result pr = r ? ROUGE_OK : rouge_face_set_view(f, desc->view, err);
    if (r || pr) {
        rouge_face_destroy(f);
        return r ? fail_out(err, &e) : pr;
    }
    f->changed = true;
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
    if (f->ren) {
        gl_saved s;
        gl_save(&s);
        rs_render_destroy(f->ren);
        gl_restore(&s);
    }
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

// GL state is saved by the caller.
static rs_result render_at(rouge_face *f, int w, int h, rs_error *e)
{
    rs_result r = flush_makeup(f, e);
    rs_view v = to_rs_view(&f->view, w, h);
    if (!r && f->view.compare_look && f->cmp) {
        // The renderer holds one makeup layer: the compared look's for this frame, then the painted one's
        // back (both whole: the next frame is drawn in full, no dirty rectangle to gather).
        uint32_t n = rs_makeup_count(f->mk);
        rs_render_invalidate(f->ren);
        r = rs_render_update_makeup(f->ren, 0, n, rs_makeup_records(f->cmp), e);
        if (!r) r = rs_render_frame(f->ren, &v, e);
        rs_render_invalidate(f->ren);
        rs_error e2 = {0};
        rs_result r2 = rs_render_update_makeup(f->ren, 0, n, rs_makeup_records(f->mk), &e2);
        if (!r && r2) r = r2, *e = e2;
    } else {
        if (f->view.compare_look) v.hide_makeup = true;  // no look to compare with: the bare face
        if (!r) r = rs_render_frame(f->ren, &v, e);
    }
    if (r) return r;
    f->frame_view = v;
    f->have_frame = true;
    f->changed = false;
    return RS_OK;
}

rouge_result rouge_face_render(rouge_face *f, rouge_error *err)
{
    rs_error e = {0};
    gl_saved s;
    gl_save(&s);
    int w = f->view.width > 0 ? f->view.width : ROUGE_DEFAULT_SIZE;
    int h = f->view.height > 0 ? f->view.height : ROUGE_DEFAULT_SIZE;
    rs_result r = render_at(f, w, h, &e);
    gl_restore(&s);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_draw(rouge_face *f, int x, int y, int w, int h, rouge_error *err)
{
    rs_error e = {0};
    gl_saved s;
    gl_save(&s);
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
    return rs_render_output_texture(f->ren, width, height);
}

rouge_result rouge_face_read_rgba(rouge_face *f, uint8_t *rgba, size_t capacity, rouge_error *err)
{
    rs_error e = {0};
    rs_image img = {0};
    gl_saved s;
    gl_save(&s);
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
    gl_save(&s);
    rs_result r = rs_render_read(f->ren, &img, &e);
    gl_restore(&s);
    if (!r) r = rs_image_write_png(path, &img, &e);
    rs_image_free(&img);
    return r ? fail_out(err, &e) : ROUGE_OK;
}

bool rouge_face_changed(const rouge_face *f) { return f->changed || !f->have_frame; }

// --- painting --------------------------------------------------------------------------------------------

int rouge_cosmetic_count(void) { return (int)rs_cosmetic_count(); }

bool rouge_cosmetic_get(int i, rouge_cosmetic *out)
{
    const rs_cosmetic *c = i >= 0 ? rs_cosmetic_get((uint32_t)i) : NULL;
    if (!c) return false;
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
    if (!(b.coverage <= 1) || !(b.color[3] >= 0) || !isfinite(b.color[0] + b.color[1] + b.color[2]))
        return fail_arg(err, "brush: coverage must be <= 1, the colour finite with alpha >= 0");
    rs_paint_brush pb = {.cosmetic = *c, .size_rel = b.size, .opacity = b.opacity,
                         .pressure = (rs_makeup_pressure)b.pressure, .eraser = b.eraser, .mirror = b.mirror,
                         .any_region = b.any_region};
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
    if (!ev || (unsigned)ev->type > ROUGE_POINTER_CANCEL) return fail_arg(err, "pointer: unknown event type");
    rs_error e = {0};
    const rs_view *fv = pointer_view(f);
    if (ev->type == ROUGE_POINTER_DOWN && f->rec) {
        // The stroke file records the camera the pixels refer to.
        rs_strokes_view sv = strokes_view(fv);
        rs_paint_set_recorder(f->paint, f->rec, &sv);
    }
    rs_input_event in = {(rs_input_type)ev->type, ev->id, ev->x, ev->y, ev->pressure > 0 ? ev->pressure : 1.0f,
                         ev->time_s};
    rs_paint_result res;
    rs_result r = rs_paint_feed(f->paint, &in, &res, &e);
    if (res.stamps || res.stroke_cancel || res.stroke_end) f->changed = true;
    if (!f->manual_navigation) {
        if (res.orbit_dx_px != 0 || res.orbit_dy_px != 0)
            rouge_face_orbit(f, -res.orbit_dx_px * ORBIT_DEG_PER_PX, res.orbit_dy_px * ORBIT_DEG_PER_PX);
        if (res.pan_dx_px != 0 || res.pan_dy_px != 0) rouge_face_pan(f, res.pan_dx_px, res.pan_dy_px);
        if (res.zoom > 0 && res.zoom != 1.0f) rouge_face_zoom_at(f, res.zoom, res.zoom_cx_px, res.zoom_cy_px);
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
                                      .orbit_dx = res.orbit_dx_px, .orbit_dy = res.orbit_dy_px,
                                      .pan_dx = res.pan_dx_px, .pan_dy = res.pan_dy_px, .zoom = res.zoom,
                                      .zoom_x = res.zoom_cx_px, .zoom_y = res.zoom_cy_px};
    (void)fv;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

bool rouge_face_undo(rouge_face *f)
{
    rs_makeup_range d;
    bool ok = rs_makeup_undo(f->mk, &d);
    f->changed |= ok;
    return ok;
}

bool rouge_face_redo(rouge_face *f)
{
    rs_makeup_range d;
    bool ok = rs_makeup_redo(f->mk, &d);
    f->changed |= ok;
    return ok;
}

rouge_result rouge_face_clear(rouge_face *f, rouge_error *err)
{
    rs_error e = {0};
    rs_makeup_range d;
    f->changed = true;
    return rs_makeup_clear(f->mk, &d, &e) ? fail_out(err, &e) : ROUGE_OK;
}

// --- looks and stroke files -------------------------------------------------------------------------------

rouge_result rouge_face_load_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    rs_makeup_range d;
    if (!path) return fail_arg(err, "look: no path");
    rs_result r = rs_look_load(f->mk, path, &d, &e);
    f->changed = true;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_load_look_memory(rouge_face *f, const void *data, size_t size, rouge_error *err)
{
    rs_error e = {0};
    rs_look *look = NULL;
    rs_makeup_range d;
    rs_result r = rs_look_parse(data, size, &look, &e);
    if (!r) r = rs_look_apply(look, f->mk, &d, &e);
    rs_look_destroy(look);
    f->changed = true;
    return r ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_save_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    if (!path) return fail_arg(err, "look: no path");
    return rs_look_save(f->mk, path, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_save_look_memory(rouge_face *f, char **data, size_t *size, rouge_error *err)
{
    rs_error e = {0};
    if (!data || !size) return fail_arg(err, "look: data and size are required");
    return rs_look_write_memory(f->mk, data, size, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_set_compare_look(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
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
    return f->writer && rec_writer_status(f->writer, true, &e) ? fail_out(err, &e) : ROUGE_OK;
}

rouge_result rouge_face_play_strokes(rouge_face *f, const char *path, rouge_error *err)
{
    rs_error e = {0};
    rs_strokes *doc = NULL;
    if (!path) return fail_arg(err, "strokes: no path");
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

bool rouge_face_pick(rouge_face *f, float x, float y, rouge_pick *out)
{
    uint32_t idx;
    float hit[3];
    if (!pick_cb(f, x, y, &idx, hit)) return false;
    if (out) {
        float ppu = rs_render_pixels_per_unit(f->ren, pointer_view(f), hit);
        *out = (rouge_pick){.splat = idx, .position = {hit[0], hit[1], hit[2]},
                            .region = (int)(f->cloud->packed[idx].w[1] >> 24),
                            .brush_radius_px = rs_paint_radius(f->paint) * ppu};
    }
    return true;
}

rouge_stats rouge_face_stats(const rouge_face *f)
{
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
