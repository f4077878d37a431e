// test_face.c — the public face object (include/rouge.h) against the internal renderer it wraps: a zero
// view renders exactly what rs_view_defaults() renders; drawing into a host's framebuffer leaves every
// piece of the host's GL state as it was and puts exactly the face's frame into the host's viewport;
// painting through pointer events changes the picture, and undo / redo / looks in memory restore it bit
// for bit; only the dirty LOD bands are uploaded; bad arguments come back as values with a message.
// The bundled face from a 30k-splat LOD prefix at 96x96 (a few seconds on llvmpipe).
#include "support/harness.h"
#include "gl/gl.h"
#include "formats/env_lookup.h"
#include "formats/strokes.h"
#include "render/render.h"
#include "rouge.h"

#include <stdio.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>

#define SIZE 96
#define MAX_SPLATS 30000
#define FACE "assets/face.rsf"

static rs_gl_context *gl;
static rouge_face *face;

static rouge_view small_view(void)
{
    return (rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS, .pipeline = ROUGE_PIPELINE_REFERENCE};
}

// Renders the face's current view and reads it back (top-first RGBA).
static bool frame(rs_image *img)
{
    rouge_error e = {0};
    if (!RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render: %s", e.msg)) return false;
    if (rs_image_create(SIZE, SIZE, 4, img, NULL) != RS_OK) return false;
    return RS_CHECK(rouge_face_read_rgba(face, img->pixels, (size_t)SIZE * SIZE * 4, &e) == ROUGE_OK, "read: %s", e.msg);
}

static bool same(const rs_image *a, const rs_image *b)
{
    return a->width == b->width && a->height == b->height &&
           !memcmp(a->pixels, b->pixels, (size_t)a->width * (size_t)a->height * 4);
}

static int changed_pixels(const rs_image *a, const rs_image *b)
{
    int n = 0;
    for (size_t i = 0; i < (size_t)a->width * (size_t)a->height; i++)
        for (int c = 0; c < 3; c++)
            if (abs(a->pixels[i * 4 + c] - b->pixels[i * 4 + c]) > 2) {
                n++;
                break;
            }
    return n;
}

static void test_zero_view_is_the_default_view(void)
{
    rouge_view v = {.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS};
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    rs_image a = {0}, b = {0};
    if (!frame(&a)) return;
    // The same face through the internal renderer with its documented defaults (mobile, as rouge.h's 0).
    rs_splat_cloud *c = NULL;
    rs_renderer *r = NULL;
    rs_error re = {0};
    RS_REQUIRE(rs_splat_load(FACE, &c, &re) == RS_OK, "%s", re.msg);
    rs_view d = rs_view_defaults();
    d.width = d.height = SIZE, d.max_splats = MAX_SPLATS, d.pipeline = RS_PIPELINE_MOBILE;
    // ... lit by the default environment, as rouge.h's NULL env.
    rs_env *env = NULL;
    if (RS_CHECK(rs_render_create(&(rs_render_desc){.cloud = c, .caps = rs_gl_get_caps(gl)}, &r, &re) == RS_OK, "%s", re.msg) &&
        RS_CHECK(rs_env_open(RS_ENV_DEFAULT, NULL, &env, &re) == RS_OK, "%s", re.msg) &&
        RS_CHECK(rs_render_set_env(r, env, &re) == RS_OK, "%s", re.msg) &&
        RS_CHECK(rs_render_image(r, &d, &b, &re) == RS_OK, "%s", re.msg))
        RS_CHECK(same(&a, &b), "zero rouge_view differs from rs_view_defaults() (%d pixels)", changed_pixels(&a, &b));
    rs_env_destroy(env);
    rs_render_destroy(r);
    rs_splat_destroy(c);
    rs_image_free(&a);
    rs_image_free(&b);
}

// A host's framebuffer with odd state everywhere; rouge_face_draw must render into its viewport, draw the
// picture it draws without that state (a host's sampler objects once overrode the renderer's shadow
// comparison and filtering: 4059 pixels off), and leave all of it as it found it (the clear colour was
// left black by the visibility pass).
static void test_draw_into_host_framebuffer_restores_state(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    // The picture without the host's state: the frame drawn under it must be this one to the byte.
    rs_image clean = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    bool have_clean = frame(&clean);
    v.yaw_deg += 1.0f;  // another frame between, so that the draw below renders again
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK && rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);
    v.yaw_deg -= 1.0f;
    v.width = v.height = 0;  // the viewport's size
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    GLuint tex, fbo, vao, buf, tex3;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 160, 120);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glClearColor(1, 0, 1, 1);
    glClear(GL_COLOR_BUFFER_BIT);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &buf);
    glBindBuffer(GL_ARRAY_BUFFER, buf);
    // A texture of each target the renderer binds on every unit GLES 3 guarantees (the renderer binds up
    // to 17 units; a host's bindings on units 8 and up, and its 3D and array textures, were lost once).
    enum { UNITS = 32 };
    GLuint host_tex[UNITS][3];
    const GLenum targets[3] = {GL_TEXTURE_2D, GL_TEXTURE_3D, GL_TEXTURE_2D_ARRAY};
    const GLenum bindings[3] = {GL_TEXTURE_BINDING_2D, GL_TEXTURE_BINDING_3D, GL_TEXTURE_BINDING_2D_ARRAY};
    glGenTextures(UNITS * 3, &host_tex[0][0]);
    for (int u = 0; u < UNITS; u++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)u);
        for (int t = 0; t < 3; t++) glBindTexture(targets[t], host_tex[u][t]);
    }
    // A sampler object on every unit (it overrides a texture's own filtering and comparison), a depth
    // range, a clear colour and a transform feedback object of the host's.
    GLuint sampler, tfo;
    glGenSamplers(1, &sampler);
    glSamplerParameteri(sampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glSamplerParameteri(sampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glSamplerParameterf(sampler, GL_TEXTURE_MAX_LOD, 0.0f);
    glSamplerParameteri(sampler, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glSamplerParameteri(sampler, GL_TEXTURE_COMPARE_FUNC, GL_NEVER);
    for (int u = 0; u < UNITS; u++) glBindSampler((GLuint)u, sampler);
    glDepthRangef(0.25f, 0.75f);
    glGenTransformFeedbacks(1, &tfo);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, tfo);
    glDeleteTextures(1, &host_tex[3][0]);
    glGenTextures(1, &tex3);
    glActiveTexture(GL_TEXTURE3);
    glBindTexture(GL_TEXTURE_2D, tex3);
    host_tex[3][0] = tex3;
    glViewport(20, 10, SIZE, SIZE);
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, 30, 30);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ZERO);
    glEnable(GL_CULL_FACE);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glPixelStorei(GL_PACK_ALIGNMENT, 8);

    rouge_result r = rouge_face_draw(face, 0, 0, 0, 0, &e);
    RS_CHECK(r == ROUGE_OK, "draw: %s", e.msg);
    GLint i4[4], i;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &i);
    RS_CHECK(i == (GLint)fbo, "draw framebuffer %d, host had %u", i, fbo);
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &i);
    RS_CHECK(i == (GLint)fbo, "read framebuffer %d", i);
    glGetIntegerv(GL_VIEWPORT, i4);
    RS_CHECK(i4[0] == 20 && i4[1] == 10 && i4[2] == SIZE && i4[3] == SIZE, "viewport %d %d %d %d", i4[0], i4[1], i4[2], i4[3]);
    glGetIntegerv(GL_SCISSOR_BOX, i4);
    RS_CHECK(i4[2] == 30 && glIsEnabled(GL_SCISSOR_TEST), "scissor");
    RS_CHECK(glIsEnabled(GL_BLEND) && glIsEnabled(GL_CULL_FACE) && glIsEnabled(GL_DEPTH_TEST), "enables");
    glGetIntegerv(GL_BLEND_SRC_RGB, &i);
    RS_CHECK(i == GL_SRC_ALPHA, "blend func");
    glGetIntegerv(GL_DEPTH_FUNC, &i);
    RS_CHECK(i == GL_GREATER, "depth func");
    GLboolean dm;
    glGetBooleanv(GL_DEPTH_WRITEMASK, &dm);
    RS_CHECK(!dm, "depth mask");
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &i);
    RS_CHECK(i == (GLint)vao, "vertex array");
    glGetIntegerv(GL_ARRAY_BUFFER_BINDING, &i);
    RS_CHECK(i == (GLint)buf, "array buffer");
    glGetIntegerv(GL_ACTIVE_TEXTURE, &i);
    RS_CHECK(i == GL_TEXTURE3, "active texture");
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &i);
    RS_CHECK(i == (GLint)tex3, "texture on unit 3");
    int lost = 0;
    for (int u = 0; u < UNITS; u++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)u);
        for (int t = 0; t < 3; t++) {
            glGetIntegerv(bindings[t], &i);
            lost += i != (GLint)host_tex[u][t];
        }
    }
    glActiveTexture(GL_TEXTURE3);
    RS_CHECK(lost == 0, "%d of the host's %d texture bindings lost", lost, UNITS * 3);
    int samplers_lost = 0;
    for (int u = 0; u < UNITS; u++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)u);
        glGetIntegerv(GL_SAMPLER_BINDING, &i);
        samplers_lost += i != (GLint)sampler;
    }
    glActiveTexture(GL_TEXTURE3);
    RS_CHECK(samplers_lost == 0, "%d of the host's %d sampler bindings lost", samplers_lost, UNITS);
    GLfloat f4[4];
    glGetFloatv(GL_DEPTH_RANGE, f4);
    RS_CHECK(f4[0] == 0.25f && f4[1] == 0.75f, "depth range %g %g", f4[0], f4[1]);
    glGetFloatv(GL_COLOR_CLEAR_VALUE, f4);
    RS_CHECK(f4[0] == 1.0f && f4[1] == 0.0f && f4[2] == 1.0f && f4[3] == 1.0f, "clear colour %g %g %g %g", f4[0],
             f4[1], f4[2], f4[3]);
    glGetIntegerv(GL_TRANSFORM_FEEDBACK_BINDING, &i);
    RS_CHECK(i == (GLint)tfo, "transform feedback object %d, host had %u", i, tfo);
    glGetIntegerv(GL_PACK_ALIGNMENT, &i);
    RS_CHECK(i == 8, "pack alignment");
    RS_CHECK(glGetError() == GL_NO_ERROR, "GL error after draw");

    // The viewport holds exactly the face's frame; outside it the host's clear colour stays.
    rs_image want = {0};
    uint8_t *px = malloc(160 * 120 * 4);
    if (RS_CHECK(px && rs_image_create(SIZE, SIZE, 4, &want, NULL) == RS_OK, "alloc") &&
        RS_CHECK(rouge_face_read_rgba(face, want.pixels, (size_t)SIZE * SIZE * 4, &e) == ROUGE_OK, "%s", e.msg)) {
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, 160, 120, GL_RGBA, GL_UNSIGNED_BYTE, px);
        int bad = 0;
        for (int y = 0; y < 120; y++)
            for (int x = 0; x < 160; x++) {
                const uint8_t *p = px + ((size_t)y * 160 + (size_t)x) * 4;
                bool in = x >= 20 && x < 20 + SIZE && y >= 10 && y < 10 + SIZE;
                // read_rgba is top-first; GL rows bottom-first.
                const uint8_t *q = in ? want.pixels + ((size_t)(SIZE - 1 - (y - 10)) * SIZE + (size_t)(x - 20)) * 4 : NULL;
                bool ok = in ? !memcmp(p, q, 3) : (p[0] == 255 && p[1] == 0 && p[2] == 255);
                bad += !ok;
            }
        RS_CHECK(bad == 0, "%d pixels of the host framebuffer differ from the face's frame / the host's clear", bad);
        if (have_clean)
            RS_CHECK(changed_pixels(&want, &clean) == 0, "the frame drawn under the host's state differs from the "
                     "clean one by more than 2 levels in %d pixels", changed_pixels(&want, &clean));
    }
    free(px);
    rs_image_free(&want);
    glDisable(GL_SCISSOR_TEST), glDisable(GL_BLEND), glDisable(GL_CULL_FACE), glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE), glDepthFunc(GL_LESS);
    glActiveTexture(GL_TEXTURE0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &buf);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    glDeleteTextures(UNITS * 3, &host_tex[0][0]);  // tex3 among them
    for (int u = 0; u < UNITS; u++) glBindSampler((GLuint)u, 0);
    glDeleteSamplers(1, &sampler);
    glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
    glDeleteTransformFeedbacks(1, &tfo);
    glDepthRangef(0.0f, 1.0f);
    rs_image_free(&clean);
}

static rouge_error stroke_err;  // why the last stroke() failed

static rouge_result stroke(float x0, float y0, float x1, float y1, rouge_pointer_result *total)
{
    rouge_error e = {0};
    stroke_err = e;
    rouge_pointer_result res;
    *total = (rouge_pointer_result){0};
    for (int i = 0; i <= 10; i++) {
        float t = (float)i / 10.0f;
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : i == 10 ? ROUGE_POINTER_UP : ROUGE_POINTER_MOVE, 7,
                                  x0 + (x1 - x0) * t, y0 + (y1 - y0) * t, 1.0f, 0.02 * i};
        rouge_result r = rouge_face_pointer(face, &ev, &res, &e);
        if (r) {
            stroke_err = e;
            return r;
        }
        total->stamps += res.stamps;
    }
    return ROUGE_OK;
}

static void test_paint_undo_redo_and_look_in_memory(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) == ROUGE_OK,
               "%s", e.msg);
    rs_image bare = {0}, painted = {0}, undone = {0}, redone = {0}, looked = {0};
    if (!frame(&bare)) return;
    rouge_pick pk;
    RS_CHECK(rouge_face_pick(face, SIZE * 0.5f, SIZE * 0.55f, &pk) && pk.brush_radius_px > 1, "pick at the centre");
    rouge_pointer_result res;
    RS_REQUIRE(stroke(SIZE * 0.35f, SIZE * 0.6f, SIZE * 0.65f, SIZE * 0.6f, &res) == ROUGE_OK, "stroke");
    RS_CHECK(res.stamps > 3, "stamps %u", res.stamps);
    RS_CHECK(rouge_face_changed(face), "painting marks the face changed");
    if (!frame(&painted)) goto out;
    rouge_stats st = rouge_face_stats(face);
    RS_CHECK(st.uploaded_records > 0 && st.uploaded_records < st.splats / 4,
             "uploaded %u of %u records: only the dirty LOD bands should go up", st.uploaded_records, st.splats);
    RS_CHECK(!rouge_face_changed(face), "a frame clears the changed flag");
    int n = changed_pixels(&bare, &painted);
    RS_CHECK(n > 50, "the stroke changed %d pixels", n);
    char *look = NULL;
    size_t look_len = 0;
    RS_CHECK(rouge_face_save_look_memory(face, &look, &look_len, &e) == ROUGE_OK && look_len > 0, "save: %s", e.msg);
    RS_CHECK(rouge_face_undo(face), "undo");
    if (!frame(&undone)) goto out;
    RS_CHECK(same(&bare, &undone), "undo differs from the bare face (%d pixels)", changed_pixels(&bare, &undone));
    RS_CHECK(rouge_face_redo(face), "redo");
    if (!frame(&redone)) goto out;
    RS_CHECK(same(&painted, &redone), "redo differs from the painted face");
    RS_CHECK(rouge_face_clear(face, &e) == ROUGE_OK, "clear");
    RS_CHECK(rouge_face_load_look_memory(face, look, look_len, &e) == ROUGE_OK, "load: %s", e.msg);
    if (!frame(&looked)) goto out;
    RS_CHECK(same(&painted, &looked), "look from memory differs from the painted face (%d pixels)",
             changed_pixels(&painted, &looked));
out:
    rouge_free(look);
    rouge_face_clear(face, NULL);
    rs_image_free(&bare), rs_image_free(&painted), rs_image_free(&undone), rs_image_free(&redone);
    rs_image_free(&looked);
}

// The recording is written by a background thread: after a flush the file holds every stroke; a write
// that fails comes back from the flush with the file's name; a face made with an environment folder
// survives recording and destruction (record_strokes once freed that folder's name).
static void test_stroke_recording(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) == ROUGE_OK,
               "%s", e.msg);
    rs_image img = {0};
    if (!frame(&img)) return;  // picks refer to the last frame
    rs_image_free(&img);
    const char *dir = getenv("RS_TEST_OUT");
    char path[512], bad[600];
    snprintf(path, sizeof path, "%s/test_face_recording.strokes", dir ? dir : "/tmp");
    snprintf(bad, sizeof bad, "%s/no/such/dir/x.strokes", dir ? dir : "/tmp");
    remove(path);
    RS_REQUIRE(rouge_face_record_strokes(face, path, &e) == ROUGE_OK, "record: %s", e.msg);
    rouge_pointer_result res;
    for (int i = 0; i < 3; i++)
        RS_CHECK(stroke(SIZE * 0.35f, SIZE * (0.5f + 0.05f * (float)i), SIZE * 0.65f, SIZE * 0.6f, &res) == ROUGE_OK,
                 "stroke %d: %s", i, stroke_err.msg);
    RS_CHECK(rouge_face_flush_strokes(face, &e) == ROUGE_OK, "flush: %s", e.msg);
    rs_strokes *doc = NULL;
    rs_error re = {0};
    if (RS_CHECK(rs_strokes_load(path, &doc, &re) == RS_OK, "load the recording: %s", re.msg))
        RS_CHECK(doc->count == 3, "the recording holds %u strokes, want 3", doc->count);
    rs_strokes_destroy(doc);
    RS_CHECK(rouge_face_record_strokes(face, bad, &e) == ROUGE_OK, "record to %s: %s", bad, e.msg);
    // The failed write comes back from the first call after it: a pointer event of this stroke (the writer
    // was quick), the flush, or stopping the recording.
    rouge_result sr = stroke(SIZE * 0.35f, SIZE * 0.6f, SIZE * 0.65f, SIZE * 0.6f, &res);
    RS_CHECK(sr == ROUGE_OK || strstr(stroke_err.msg, "x.strokes"), "stroke: %s", stroke_err.msg);
    rouge_result fr = sr ? sr : rouge_face_flush_strokes(face, &e);
    if (sr) e = stroke_err;
    if (fr == ROUGE_OK) fr = rouge_face_record_strokes(face, NULL, &e);  // the error may have come with the stroke
    RS_CHECK(fr == ROUGE_ERR_IO || strstr(e.msg, "x.strokes"), "a failed write is reported: %d %s", fr, e.msg);
    RS_CHECK(rouge_face_record_strokes(face, NULL, &e) == ROUGE_OK, "stop after the reported failure: %s", e.msg);
    rouge_face_clear(face, NULL);

    rouge_face *g = NULL;
    rouge_view gv = small_view();
    gv.max_splats = 2000;
    gv.pipeline = ROUGE_PIPELINE_MOBILE;  // about env_dir and the recorder, not the reference's ~3 CPU-s setup
    if (!RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = FACE, .view = &gv, .env_dir = "assets/env"}, &g, &e) ==
                      ROUGE_OK,
                  "face with env_dir: %s", e.msg))
        return;
    RS_CHECK(rouge_face_record_strokes(g, path, &e) == ROUGE_OK && rouge_face_record_strokes(g, NULL, &e) == ROUGE_OK,
             "record on a face with env_dir: %s", e.msg);
    RS_CHECK(rouge_face_render(g, &e) == ROUGE_OK, "render after recording: %s", e.msg);
    rouge_face_destroy(g);
}

static void test_errors_are_values(void)
{
    rouge_error e = {0};
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "warpaint"}, &e) == ROUGE_ERR_ARG &&
                 strstr(e.msg, "warpaint"),
             "unknown cosmetic: %s", e.msg);
    RS_CHECK(rouge_face_set_view(face, &(rouge_view){.env = "moon"}, &e) == ROUGE_ERR_ARG && strstr(e.msg, "moon"),
             "unknown environment: %s", e.msg);
    RS_CHECK(rouge_face_set_view(face, &(rouge_view){.mode = (rouge_mode)99}, &e) == ROUGE_ERR_ARG, "bad mode");
    rouge_face *f = NULL;
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = "tests/no/such.rsf"}, &f, &e) == ROUGE_ERR_IO && !f &&
                 strstr(e.msg, "such.rsf"),
             "missing face: %s", e.msg);
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.data = "RSF?", .size = 4}, &f, &e) == ROUGE_ERR_FORMAT && !f,
             "garbage in memory: %s", e.msg);
    RS_CHECK(rouge_face_load_look_memory(face, "rouge-look 9\n", 13, &e) != ROUGE_OK && e.msg[0], "bad look");
    rouge_caps caps;
    RS_CHECK(rouge_query_caps(&caps, &e) == ROUGE_OK && caps.gles_major >= 3 && caps.renderer[0], "caps: %s", e.msg);
    RS_CHECK(!strcmp(rouge_result_name(ROUGE_ERR_GL), "ROUGE_ERR_GL"), "result names");
}

// --target frames a region: measured on the picture, the splat under the view's centre belongs to it and
// the frame is closer than the whole-face view; an unknown name lists the face's regions.
static void test_target_centres_each_region(void)
{
    const char *names[] = {"lips", "nose", "forehead", "cheek"};
    const int ids[] = {4, 2, 3, 1};  // the bundled face's region table (docs/regions.md)
    rouge_error e = {0};
    for (int i = 0; i < 4; i++) {
        rouge_view v = small_view();
        RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
        RS_CHECK(rouge_face_target(face, names[i], 0, &e) == ROUGE_OK, "%s: %s", names[i], e.msg);
        RS_CHECK(rouge_face_get_view(face).zoom > 1.2f, "%s: zoom %g", names[i], rouge_face_get_view(face).zoom);
        RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);
        // Where the region is in the picture, measured by picking a grid: its centroid must sit at the
        // view's centre, and it must cover a good part of the view.
        double sx = 0, sy = 0;
        int n = 0, step = 4;
        for (int y = step / 2; y < SIZE; y += step)
            for (int x = step / 2; x < SIZE; x += step) {
                rouge_pick p;
                if (rouge_face_pick(face, (float)x, (float)y, &p) && p.region == ids[i]) sx += x, sy += y, n++;
            }
        int cells = (SIZE / step) * (SIZE / step);
        RS_CHECK(n > cells / 20, "%s: covers %d of %d grid points", names[i], n, cells);
        if (n > 0)
            RS_CHECK(fabs(sx / n - SIZE / 2.0) < 0.08 * SIZE && fabs(sy / n - SIZE / 2.0) < 0.08 * SIZE,
                     "%s: centroid at (%.1f, %.1f) of a %d px view", names[i], sx / n, sy / n, SIZE);
    }
    RS_CHECK(rouge_face_target(face, "elbow", 0, &e) == ROUGE_ERR_ARG && strstr(e.msg, "lips") != NULL,
             "unknown region: %s", e.msg);
    rouge_view v = small_view();
    rouge_face_set_view(face, &v, &e);
}

// --pan shifts the picture: the panned frame is the unpanned one moved by pan x view height pixels.
static void test_pan_shifts_the_picture(void)
{
    rouge_error e = {0};
    rouge_view v = small_view();
    rs_image a = {0}, b = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(&a), "%s", e.msg);
    v.pan[0] = 0.125f, v.pan[1] = -0.0625f;  // 12 px right, 6 px up at 96 px
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(&b), "%s", e.msg);
    int dx = 12, dy = -6, bad = 0, n = 0;
    for (int y = 10; y < SIZE - 10; y++)
        for (int x = 14; x < SIZE - 14; x++, n++) {
            const uint8_t *pa = a.pixels + ((size_t)y * SIZE + x) * 4, *pb = b.pixels + ((size_t)(y + dy) * SIZE + x + dx) * 4;
            for (int c = 0; c < 3; c++)
                if (abs(pa[c] - pb[c]) > 24) {
                    bad++;
                    break;
                }
        }
    RS_CHECK(bad < n / 50, "%d of %d pixels differ from the shifted unpanned frame", bad, n);
    rs_image_free(&a), rs_image_free(&b);
    v = small_view();
    rouge_face_set_view(face, &v, &e);
}


// A face from a stream: before any LOD level nothing; mid-stream a preview of the complete levels (fewer
// splats, drawable); complete, the whole face, identical to one loaded from the file; the stream is
// handed over once; hostile bytes fail and stay failed.
static void test_stream_previews_then_the_whole_face(void)
{
    rouge_error e = {0};
    void *data = NULL;
    size_t n = 0;
    rs_error re = {0};
    RS_REQUIRE(rs_file_read_all(FACE, 64u << 20, &data, &n, &re) == RS_OK, "%s", re.msg);
    const uint8_t *bytes = data;
    rouge_stream *s = NULL;
    RS_REQUIRE(rouge_stream_create("face", n, &s, &e) == ROUGE_OK, "%s", e.msg);
    rouge_view v = small_view();
    v.max_splats = 0;
    v.pipeline = ROUGE_PIPELINE_MOBILE;  // about the stream, not the reference's fixed setup
    rouge_face *f = NULL;
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.stream = s, .view = &v}, &f, &e) == ROUGE_ERR_ARG,
             "a face before any LOD level arrived: %s", e.msg);
    // Feed in uneven pieces until the first level is ready.
    size_t at = 0, piece = 7777;
    while (at < n && rouge_stream_get_progress(s).ready == 0) {
        size_t k = RS_MIN(piece, n - at);
        RS_REQUIRE(rouge_stream_feed(s, bytes + at, k, &e) == ROUGE_OK, "feed at %zu: %s", at, e.msg);
        at += k;
    }
    rouge_stream_progress p = rouge_stream_get_progress(s);
    RS_CHECK(p.ready > 0 && p.ready < p.splats && !p.complete && p.bytes == at, "progress: ready %u of %u, %llu bytes",
             p.ready, p.splats, (unsigned long long)p.bytes);
    if (RS_CHECK(rouge_face_create(&(rouge_face_desc){.stream = s, .view = &v}, &f, &e) == ROUGE_OK, "preview: %s",
                 e.msg)) {
        rouge_stats st = rouge_face_stats(f);
        RS_CHECK(st.splats == p.ready, "the preview holds %u splats, the stream had %u ready", st.splats, p.ready);
        RS_CHECK(rouge_face_render(f, &e) == ROUGE_OK, "render the preview: %s", e.msg);
        rouge_face_destroy(f);
    }
    RS_REQUIRE(rouge_stream_feed(s, bytes + at, n - at, &e) == ROUGE_OK, "feed the rest: %s", e.msg);
    RS_CHECK(rouge_stream_get_progress(s).complete, "complete after every byte");
    f = NULL;
    if (RS_CHECK(rouge_face_create(&(rouge_face_desc){.stream = s, .view = &v}, &f, &e) == ROUGE_OK, "whole: %s",
                 e.msg)) {
        rouge_stats st = rouge_face_stats(f), want = rouge_face_stats(face);
        RS_CHECK(st.splats == want.splats && st.lod_count == want.lod_count, "whole face %u splats, the file has %u",
                 st.splats, want.splats);
        rouge_face *g = NULL;
        RS_CHECK(rouge_face_create(&(rouge_face_desc){.stream = s, .view = &v}, &g, &e) == ROUGE_ERR_ARG,
                 "a second face from a handed-over stream: %s", e.msg);
        rouge_face_destroy(f);
    }
    RS_CHECK(rouge_stream_feed(s, bytes, 1, &e) != ROUGE_OK, "bytes after the end are refused");
    rouge_stream_destroy(s);
    // Garbage: the first error sticks.
    RS_REQUIRE(rouge_stream_create(NULL, 0, &s, &e) == ROUGE_OK, "%s", e.msg);
    RS_CHECK(rouge_stream_feed(s, "not a face file at all, really", 30, &e) == ROUGE_ERR_FORMAT, "garbage: %s", e.msg);
    RS_CHECK(rouge_stream_feed(s, bytes, 64, &e) == ROUGE_ERR_FORMAT, "the error sticks: %s", e.msg);
    RS_CHECK(!rouge_stream_get_progress(s).complete, "garbage never completes");
    rouge_stream_destroy(s);
    free(data);
}

// The compare look: drawn instead of the painted one when the view asks; none set = the bare face; the
// painted look is untouched by it (a frame after one of the compared look is the painted picture).
static void test_compare_look(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) == ROUGE_OK,
               "%s", e.msg);
    rs_image bare = {0}, a = {0}, b = {0}, cmp_none = {0}, cmp_a = {0}, after = {0};
    rouge_pointer_result res;
    const char *dir = getenv("RS_TEST_OUT");
    char path[512];
    snprintf(path, sizeof path, "%s/test_face_compare.look", dir ? dir : "/tmp");
    if (!frame(&bare)) return;
    RS_REQUIRE(stroke(SIZE * 0.35f, SIZE * 0.6f, SIZE * 0.65f, SIZE * 0.6f, &res) == ROUGE_OK, "stroke a");
    if (!frame(&a)) goto out;
    RS_REQUIRE(rouge_face_save_look(face, path, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(rouge_face_clear(face, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_matte", .size = 0.1f, .opacity = 1,
                                                         .any_region = true}, &e) == ROUGE_OK, "%s", e.msg);
    RS_REQUIRE(stroke(SIZE * 0.4f, SIZE * 0.4f, SIZE * 0.6f, SIZE * 0.45f, &res) == ROUGE_OK, "stroke b");
    if (!frame(&b)) goto out;
    v.compare_look = true;
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    if (!frame(&cmp_none)) goto out;
    RS_CHECK(same(&cmp_none, &bare), "no compare look: the bare face (%d pixels differ)", changed_pixels(&cmp_none, &bare));
    RS_CHECK(rouge_face_set_compare_look(face, "no/such.look", &e) == ROUGE_ERR_IO, "missing look: %s", e.msg);
    RS_REQUIRE(rouge_face_set_compare_look(face, path, &e) == ROUGE_OK, "%s", e.msg);
    if (!frame(&cmp_a)) goto out;
    RS_CHECK(same(&cmp_a, &a), "the compare look draws as look a did (%d pixels differ)", changed_pixels(&cmp_a, &a));
    v.compare_look = false;
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    if (!frame(&after)) goto out;
    RS_CHECK(same(&after, &b), "the painted look after a compared frame (%d pixels differ)", changed_pixels(&after, &b));
    RS_CHECK(rouge_face_set_compare_look(face, NULL, &e) == ROUGE_OK, "unset: %s", e.msg);
out:
    rouge_face_clear(face, NULL);
    rs_image_free(&bare), rs_image_free(&a), rs_image_free(&b), rs_image_free(&cmp_none), rs_image_free(&cmp_a);
    rs_image_free(&after);
}

// A custom product through the brush: colour (black too: alpha says "given"), finish and coverage
// reach the look under the preset's name with "custom_"; a zero brush colour keeps the preset's.
static void test_custom_brush_product(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    rs_image img = {0};
    if (!frame(&img)) return;
    rs_image_free(&img);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lip_gloss", .color = {0, 0, 0, 1},
                                                         .finish = ROUGE_FINISH_MATTE, .coverage = 0.9f,
                                                         .size = 0.1f, .opacity = 1, .any_region = true}, &e) == ROUGE_OK,
               "%s", e.msg);
    rouge_pointer_result res;
    RS_REQUIRE(stroke(SIZE * 0.4f, SIZE * 0.5f, SIZE * 0.6f, SIZE * 0.5f, &res) == ROUGE_OK, "stroke");
    char *look = NULL;
    size_t len = 0;
    RS_REQUIRE(rouge_face_save_look_memory(face, &look, &len, &e) == ROUGE_OK, "%s", e.msg);
    RS_CHECK(strstr(look, "custom_lip_gloss") && strstr(look, "rgb=0,0,0") && strstr(look, "coverage=0.89"),
             "the look carries the custom product: %.300s", look);
    RS_CHECK(strstr(look, "kind=lip_gloss"), "it keeps the preset's kind: %.300s", look);
    rouge_free(look);
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .finish = (rouge_finish)9}, &e) == ROUGE_ERR_ARG,
             "unknown finish: %s", e.msg);
    RS_CHECK(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .color = {NAN, 0, 0, 1}}, &e) == ROUGE_ERR_ARG,
             "a NaN colour: %s", e.msg);
    rouge_cosmetic c;
    bool found = false;
    for (int i = 0; rouge_cosmetic_get(i, &c); i++)
        if (!strcmp(c.name, "lip_gloss")) {
            found = true;
            RS_CHECK(c.finish == ROUGE_FINISH_GLOSS && c.region && !strcmp(c.region, "lips"), "lip gloss: finish %d, region %s",
                     c.finish, c.region ? c.region : "(any)");
        }
    RS_CHECK(found, "lip_gloss is a preset");
    RS_CHECK(rouge_environment_count() >= 2 && !strcmp(rouge_environment_name(rouge_environment_count() - 1), "paper") &&
                 !rouge_environment_name(rouge_environment_count()),
             "environments end with paper");
    rouge_face_clear(face, NULL);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    rouge_error e = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - test_face: %s\n", err.msg);
        return rs_test_finish();
    }
    rouge_view v = small_view();
    if (rouge_face_create(&(rouge_face_desc){.path = FACE, .view = &v}, &face, &e) != ROUGE_OK) {
        printf("FAIL - test_face: %s\n", e.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    RS_RUN(test_zero_view_is_the_default_view);
    RS_RUN(test_draw_into_host_framebuffer_restores_state);
    RS_RUN(test_paint_undo_redo_and_look_in_memory);
    RS_RUN(test_stroke_recording);
    RS_RUN(test_errors_are_values);
    RS_RUN(test_target_centres_each_region);
    RS_RUN(test_pan_shifts_the_picture);
    RS_RUN(test_stream_previews_then_the_whole_face);
    RS_RUN(test_compare_look);
    RS_RUN(test_custom_brush_product);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
