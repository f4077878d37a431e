// test_embed.c — the embedding contract of include/rouge.h, from a host that behaves like a real one:
// pixel-store state, a pending GL error, an sRGB framebuffer, no or another current context, NULL for
// every handle and pointer, views with one bad field, output paths naming the face's own file, the
// environments found from the library's location rather than the working directory, and the version.
// Each case gives correct pixels or a clear error value, never a crash or wrong bytes. The bundled
// face from a 20k-splat LOD prefix at 64x64 (a few seconds on llvmpipe).
#define _DEFAULT_SOURCE  // mkdtemp, realpath, link
#include "support/harness.h"
#include "gl/gl.h"
#include "rouge.h"

#include <EGL/egl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define SIZE 64
#define MAX_SPLATS 20000
#define FACE "assets/face.rsf"

static rs_gl_context *gl;
static rouge_face *face;

static rouge_view small_view(void) { return (rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}; }

// Renders and reads the face's frame (top-first RGBA, SIZE x SIZE) into px.
static bool frame(rouge_face *f, uint8_t *px)
{
    rouge_error e = {0};
    return RS_CHECK(rouge_face_render(f, &e) == ROUGE_OK, "render: %s", e.msg) &&
           RS_CHECK(rouge_face_read_rgba(f, px, (size_t)SIZE * SIZE * 4, &e) == ROUGE_OK, "read: %s", e.msg);
}

static int max_diff(const uint8_t *a, const uint8_t *b, size_t n)
{
    int m = 0;
    for (size_t i = 0; i < n; i++) m = RS_MAX(m, abs(a[i] - b[i]));
    return m;
}

static const GLenum store_names[] = {GL_PACK_ALIGNMENT,     GL_PACK_ROW_LENGTH,     GL_PACK_SKIP_PIXELS,
                                     GL_PACK_SKIP_ROWS,     GL_UNPACK_ALIGNMENT,    GL_UNPACK_ROW_LENGTH,
                                     GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_PIXELS, GL_UNPACK_SKIP_ROWS,
                                     GL_UNPACK_SKIP_IMAGES};
// A host's odd but legal settings: rows longer than rouge's, skips, 8-byte alignment.
static const GLint host_store[] = {8, 300, 7, 3, 8, 41, 5, 6, 2, 1};

static void set_store(const GLint *v)
{
    for (size_t i = 0; i < RS_COUNT_OF(store_names); i++) glPixelStorei(store_names[i], v[i]);
}

static bool store_is(const GLint *v)
{
    for (size_t i = 0; i < RS_COUNT_OF(store_names); i++) {
        GLint now = -1;
        glGetIntegerv(store_names[i], &now);
        if (now != v[i]) return false;
    }
    return true;
}

// With the host's pack and unpack state set, a face made (splats, environment uploaded), rendered, read and
// picked gives the bytes and the pick a face made under GL's defaults gives; the host's state stays.
static void test_pixel_store_state_does_not_reach_rouge(void)
{
    static const GLint defaults[] = {4, 0, 0, 0, 4, 0, 0, 0, 0, 0};
    size_t n = (size_t)SIZE * SIZE * 4;
    // Room past the frame: a transfer that honoured the host's row length would write there.
    uint8_t *ref = calloc(n, 1), *got = calloc(2 * n, 1);
    RS_REQUIRE(ref && got, "alloc");
    rouge_pick p_ref = {0}, p_got = {0};
    bool hit_ref = false, hit_got = false;
    set_store(defaults);
    if (!frame(face, ref)) goto out;
    hit_ref = rouge_face_pick(face, SIZE * 0.5f, SIZE * 0.5f, &p_ref);

    set_store(host_store);
    rouge_face *g = NULL;
    rouge_error e = {0};
    rouge_view v = small_view();
    v.env = "daylight";  // a second environment upload, under the host's unpack state
    bool made = RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = FACE, .view = &v}, &g, &e) == ROUGE_OK, "%s", e.msg);
    v.env = NULL;
    if (made && RS_CHECK(rouge_face_set_view(g, &v, &e) == ROUGE_OK, "%s", e.msg) && frame(g, got)) {
        hit_got = rouge_face_pick(g, SIZE * 0.5f, SIZE * 0.5f, &p_got);
        RS_CHECK(max_diff(ref, got, n) == 0, "frame under the host's pixel-store state differs by up to %d",
                 max_diff(ref, got, n));
        RS_CHECK(max_diff(got + n, got + n + n / 2, n / 2) == 0 && got[n] == 0, "bytes written past the frame");
        RS_CHECK(hit_ref && hit_got && p_ref.splat == p_got.splat, "pick %d %u vs %d %u", hit_ref, p_ref.splat, hit_got,
                 p_got.splat);
    }
    RS_CHECK(store_is(host_store), "the host's pixel-store state was changed");
    RS_CHECK(glGetError() == GL_NO_ERROR, "GL error left behind");
    rouge_face_destroy(g);
out:
    set_store(defaults);
    free(ref), free(got);
}

// The host's error is its own: rouge's calls succeed, the error is not left on the context (rouge took
// it) but handed back once through rouge_face_take_host_gl_error.
static void test_pending_host_gl_error_is_not_rouge_s(void)
{
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, &e) ==
                   ROUGE_OK,
               "%s", e.msg);
    rouge_face_take_host_gl_error(face);
    glEnable(0x1234);  // GL_INVALID_ENUM, left pending
    RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render with a host error pending: %s", e.msg);
    RS_CHECK(glGetError() == GL_NO_ERROR, "an error left on the context after rouge");
    uint32_t host = rouge_face_take_host_gl_error(face);
    RS_CHECK(host == GL_INVALID_ENUM, "host error 0x%04x, want 0x0500", host);
    RS_CHECK(rouge_face_take_host_gl_error(face) == 0, "asking clears it");
    glEnable(0x1234);
    uint8_t *px = malloc((size_t)SIZE * SIZE * 4);
    RS_CHECK(px && rouge_face_read_rgba(face, px, (size_t)SIZE * SIZE * 4, &e) == ROUGE_OK, "read: %s", e.msg);
    RS_CHECK(rouge_face_take_host_gl_error(face) == GL_INVALID_ENUM, "read: the host's error kept");
    free(px);
}

// Draws into a host framebuffer of `format` (SIZE x SIZE) and reads its bytes back (GL rows).
static bool draw_into(GLenum format, uint8_t *px)
{
    GLuint tex, fbo;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, SIZE, SIZE);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glViewport(0, 0, SIZE, SIZE);
    rouge_error e = {0};
    bool ok = RS_CHECK(rouge_face_draw(face, 0, 0, 0, 0, &e) == ROUGE_OK, "draw: %s", e.msg);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, SIZE, SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    return ok && RS_CHECK(glGetError() == GL_NO_ERROR, "GL error drawing into 0x%04x", format);
}

// An SRGB8_ALPHA8 target stores the same bytes as an RGBA8 one: the frame is sRGB already, and encoding
// it again brightened it by about 62 levels.
static void test_draw_into_srgb_framebuffer_encodes_once(void)
{
    rouge_error e = {0};
    rouge_view v = small_view();
    v.width = v.height = 0;
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
    size_t n = (size_t)SIZE * SIZE * 4;
    uint8_t *lin = malloc(n), *srgb = malloc(n);
    if (RS_CHECK(lin && srgb, "alloc") && draw_into(GL_RGBA8, lin) && draw_into(GL_SRGB8_ALPHA8, srgb)) {
        double mean = 0;
        for (size_t i = 0; i < n; i++) mean += (double)srgb[i] - lin[i];
        RS_CHECK(max_diff(lin, srgb, n) <= 2, "sRGB target differs from RGBA8 by up to %d (mean %+.1f)",
                 max_diff(lin, srgb, n), mean / (double)n);
    }
    free(lin), free(srgb);
}

// EGL's config of the context current now (for a second context like it).
static EGLConfig current_config(EGLDisplay dpy, EGLContext ctx)
{
    EGLint id = 0, n = 0;
    EGLConfig cfg = NULL;
    eglQueryContext(dpy, ctx, EGL_CONFIG_ID, &id);
    const EGLint attr[] = {EGL_CONFIG_ID, id, EGL_NONE};
    return eglChooseConfig(dpy, attr, &cfg, 1, &n) && n == 1 ? cfg : NULL;
}

static void expect_gl_error(const char *what, rouge_result r, const rouge_error *e, const char *words)
{
    RS_CHECK(r == ROUGE_ERR_GL && strstr(e->msg, words), "%s: %s (%s), want ROUGE_ERR_GL naming '%s'", what,
             rouge_result_name(r), e->msg, words);
}

static void calls_fail(const char *words)
{
    rouge_error e = {0};
    uint8_t px[4];
    rouge_result r = rouge_face_render(face, &e);
    expect_gl_error("render", r, &e, words);
    e = (rouge_error){0};
    r = rouge_face_draw(face, 0, 0, 8, 8, &e);
    expect_gl_error("draw", r, &e, words);
    e = (rouge_error){0};
    r = rouge_face_read_rgba(face, px, sizeof px, &e);
    expect_gl_error("read", r, &e, words);
    e = (rouge_error){0};
    r = rouge_face_write_png(face, "/nonexistent/x.png", &e);
    expect_gl_error("write_png", r, &e, words);
    e = (rouge_error){0};
    r = rouge_face_pointer(face, &(rouge_pointer_event){ROUGE_POINTER_DOWN, 1, 10, 10, 1, 0}, NULL, &e);
    expect_gl_error("pointer", r, &e, words);
    RS_CHECK(!rouge_face_pick(face, SIZE * 0.5f, SIZE * 0.5f, NULL), "pick without the face's context");
}

// With no context current, or another one, every GL call of the face refuses (before: it returned OK,
// drawing nothing or into the other context's objects).
static void test_calls_need_the_face_s_context(void)
{
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, &e) ==
                   ROUGE_OK,
               "%s", e.msg);
    RS_REQUIRE(rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);
    EGLDisplay dpy = eglGetCurrentDisplay();
    EGLContext ctx = eglGetCurrentContext();
    RS_REQUIRE(ctx != EGL_NO_CONTEXT, "the test's context is current");
    RS_REQUIRE(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT), "release the context");
    calls_fail("no GL context");
    EGLConfig cfg = current_config(dpy, ctx);
    const EGLint attr[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_NONE};
    EGLContext other = cfg ? eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, attr) : EGL_NO_CONTEXT;
    if (RS_CHECK(other != EGL_NO_CONTEXT, "a second context") &&
        RS_CHECK(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, other), "make the second current")) {
        calls_fail("another GL context");
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    if (other != EGL_NO_CONTEXT) eglDestroyContext(dpy, other);
    RS_REQUIRE(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx), "the test's context back");
    RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render back in the face's context: %s", e.msg);
}

// NULL for every handle and required pointer: an error value (or false / 0 / a zero struct), never a crash
// or an assert.
static void test_null_everywhere(void)
{
    rouge_error e = {0};
    rouge_face *nf = NULL;
    rouge_stream *ns = NULL;
    uint8_t px[16];
    RS_CHECK(rouge_query_caps(NULL, &e) == ROUGE_ERR_ARG, "query_caps(NULL)");
    RS_CHECK(rouge_face_create(NULL, &nf, &e) == ROUGE_ERR_ARG, "create(NULL desc)");
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = FACE}, NULL, &e) == ROUGE_ERR_ARG, "create(NULL out)");
    RS_CHECK(rouge_stream_create(NULL, 0, NULL, &e) == ROUGE_ERR_ARG, "stream_create(NULL out)");
    RS_CHECK(rouge_stream_feed(NULL, px, 4, &e) == ROUGE_ERR_ARG, "stream_feed(NULL)");
    rouge_stream_progress sp = rouge_stream_get_progress(NULL);
    RS_CHECK(sp.bytes == 0 && !sp.complete, "stream_get_progress(NULL)");
    rouge_stream_destroy(NULL);
    RS_CHECK(rouge_face_set_view(nf, NULL, &e) == ROUGE_ERR_ARG, "set_view");
    rouge_view v = rouge_face_get_view(nf);
    RS_CHECK(v.width == 0 && v.env == NULL, "get_view");
    RS_CHECK(rouge_face_target(nf, "lips", 0, &e) == ROUGE_ERR_ARG, "target");
    rouge_face_orbit(nf, 1, 1), rouge_face_pan(nf, 1, 1), rouge_face_zoom_at(nf, 2, 1, 1);
    RS_CHECK(rouge_face_draw(nf, 0, 0, 0, 0, &e) == ROUGE_ERR_ARG, "draw");
    RS_CHECK(rouge_face_render(nf, &e) == ROUGE_ERR_ARG, "render");
    int w = 7, h = 7;
    RS_CHECK(rouge_face_texture(nf, &w, &h) == 0 && w == 0 && h == 0, "texture");
    RS_CHECK(rouge_face_read_rgba(nf, px, sizeof px, &e) == ROUGE_ERR_ARG, "read_rgba");
    RS_CHECK(rouge_face_write_png(nf, "/tmp/x.png", &e) == ROUGE_ERR_ARG, "write_png");
    RS_CHECK(!rouge_face_changed(nf), "changed");
    RS_CHECK(rouge_face_take_host_gl_error(nf) == 0, "take_host_gl_error");
    RS_CHECK(rouge_face_set_brush(nf, NULL, &e) == ROUGE_ERR_ARG, "set_brush");
    rouge_face_set_painting(nf, false);
    RS_CHECK(rouge_face_pointer(nf, &(rouge_pointer_event){0}, NULL, &e) == ROUGE_ERR_ARG, "pointer");
    RS_CHECK(!rouge_face_undo(nf) && !rouge_face_redo(nf), "undo / redo");
    RS_CHECK(rouge_face_clear(nf, &e) == ROUGE_ERR_ARG, "clear");
    RS_CHECK(rouge_face_load_look(nf, "x.look", &e) == ROUGE_ERR_ARG, "load_look");
    RS_CHECK(rouge_face_load_look_memory(nf, "x", 1, &e) == ROUGE_ERR_ARG, "load_look_memory");
    RS_CHECK(rouge_face_save_look(nf, "/tmp/x.look", &e) == ROUGE_ERR_ARG, "save_look");
    char *data = NULL;
    size_t size = 0;
    RS_CHECK(rouge_face_save_look_memory(nf, &data, &size, &e) == ROUGE_ERR_ARG, "save_look_memory");
    RS_CHECK(rouge_face_set_compare_look(nf, NULL, &e) == ROUGE_ERR_ARG, "set_compare_look");
    RS_CHECK(rouge_face_record_strokes(nf, NULL, &e) == ROUGE_ERR_ARG, "record_strokes");
    RS_CHECK(rouge_face_flush_strokes(nf, &e) == ROUGE_ERR_ARG, "flush_strokes");
    RS_CHECK(rouge_face_play_strokes(nf, "x.strokes", &e) == ROUGE_ERR_ARG, "play_strokes");
    RS_CHECK(!rouge_face_pick(nf, 1, 1, NULL), "pick");
    rouge_stats st = rouge_face_stats(nf);
    RS_CHECK(st.splats == 0, "stats");
    rouge_face_destroy(nf);
    // NULL pointers with a real face and stream.
    RS_CHECK(rouge_face_write_png(face, NULL, &e) == ROUGE_ERR_ARG, "write_png(face, NULL)");
    RS_CHECK(rouge_face_load_look_memory(face, NULL, 10, &e) == ROUGE_ERR_ARG, "load_look_memory(face, NULL, 10)");
    RS_CHECK(!rouge_cosmetic_get(0, NULL), "cosmetic_get(0, NULL)");
    RS_CHECK(rouge_face_pointer(face, NULL, NULL, &e) == ROUGE_ERR_ARG, "pointer(face, NULL)");
    RS_CHECK(rouge_face_read_rgba(face, NULL, 0, &e) != ROUGE_OK, "read_rgba(face, NULL)");
    RS_CHECK(rouge_face_save_look_memory(face, NULL, NULL, &e) == ROUGE_ERR_ARG, "save_look_memory(face, NULL)");
    if (RS_CHECK(rouge_stream_create(NULL, 0, &ns, &e) == ROUGE_OK, "%s", e.msg)) {
        RS_CHECK(rouge_stream_feed(ns, NULL, 10, &e) == ROUGE_ERR_ARG, "stream_feed(s, NULL, 10)");
        RS_CHECK(rouge_stream_feed(ns, NULL, 0, &e) == ROUGE_OK, "stream_feed(s, NULL, 0): %s", e.msg);
        rouge_stream_destroy(ns);
    }
    // The face still works.
    RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render after the NULL calls: %s", e.msg);
}

// One bad field per view: refused at set_view with the field in the message, the previous view kept,
// later frames fine.
static void test_set_view_names_the_bad_field(void)
{
    rouge_error e = {0};
    rouge_view good = small_view();
    good.yaw_deg = 12;
    RS_REQUIRE(rouge_face_set_view(face, &good, &e) == ROUGE_OK, "%s", e.msg);
    struct {
        rouge_view v;
        const char *words;
    } bad[] = {
        {{.yaw_deg = NAN}, "view.yaw_deg is NaN"},
        {{.width = 100000, .height = 100000}, "view.width 100000 is outside 0..8192"},
        {{.width = 64, .height = 8193}, "view.height 8193"},
        {{.kernel_count = 99}, "view.kernel_count 99 is outside 2..4"},
        {{.exposure = NAN}, "view.exposure is NaN"},
        {{.ambient = NAN}, "view.ambient is NaN"},
        {{.lod_density = NAN}, "view.lod_density is NaN"},
        {{.key = {.color = {INFINITY, 1, 1}}}, "view.key.color[0] is inf"},
        {{.fill = {.intensity = -INFINITY}}, "view.fill.intensity is -inf"},
        {{.zoom = INFINITY}, "view.zoom is inf"},
        {{.fov_deg = 170}, "view.fov_deg 170"},
        {{.fov_deg = NAN}, "view.fov_deg is NaN"},
        {{.pan = {0, NAN}}, "view.pan[1] is NaN"},
        {{.env_rotation_deg = INFINITY}, "view.env_rotation_deg is inf"},
        {{.specular_scale = NAN}, "view.specular_scale is NaN"},
        {{.pitch_deg = 3e7f}, "view.pitch_deg"},
        {{.mode = (rouge_mode)99}, "view.mode 99"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(bad); i++) {
        e = (rouge_error){0};
        rouge_result r = rouge_face_set_view(face, &bad[i].v, &e);
        RS_CHECK(r == ROUGE_ERR_ARG && strstr(e.msg, bad[i].words), "case %zu: %s '%s', want '%s'", i,
                 rouge_result_name(r), e.msg, bad[i].words);
    }
    rouge_view now = rouge_face_get_view(face);
    RS_CHECK(now.yaw_deg == 12 && now.width == SIZE && now.max_splats == MAX_SPLATS, "the previous view stays");
    RS_CHECK(rouge_face_render(face, &e) == ROUGE_OK, "render after the refusals: %s", e.msg);
}

static bool file_bytes(const char *path, void **data, size_t *len)
{
    return rs_file_read_all(path, 64u << 20, data, len, NULL) == RS_OK;
}

// The .rsf a face was loaded from, under its own name, another name and a hard link, is never overwritten
// by save_look, write_png or record_strokes; record_strokes refuses a directory at once.
static void test_outputs_never_overwrite_the_face_file(void)
{
    char dir[] = "/tmp/rouge_embed_XXXXXX", rsf[64], alias[96], link_path[64], sub[64];
    RS_REQUIRE(mkdtemp(dir), "mkdtemp");
    snprintf(rsf, sizeof rsf, "%s/face.rsf", dir);
    snprintf(alias, sizeof alias, "%s/../%s/./face.rsf", dir, strrchr(dir, '/') + 1);
    snprintf(link_path, sizeof link_path, "%s/linked.rsf", dir);
    snprintf(sub, sizeof sub, "%s/sub", dir);
    void *orig = NULL, *after = NULL;
    size_t orig_len = 0, after_len = 0;
    rouge_face *g = NULL;
    rouge_error e = {0};
    if (!RS_CHECK(file_bytes(FACE, &orig, &orig_len), "read the face") ||
        !RS_CHECK(rs_file_write_atomic(rsf, orig, orig_len, NULL) == RS_OK, "copy the face") ||
        !RS_CHECK(link(rsf, link_path) == 0 && mkdir(sub, 0755) == 0, "link, mkdir"))
        goto out;
    rouge_view v = small_view();
    if (!RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = rsf, .view = &v}, &g, &e) == ROUGE_OK, "%s", e.msg))
        goto out;
    RS_CHECK(rouge_face_render(g, &e) == ROUGE_OK, "render: %s", e.msg);
    const char *names[] = {rsf, alias, link_path};
    for (size_t i = 0; i < RS_COUNT_OF(names); i++) {
        e = (rouge_error){0};
        RS_CHECK(rouge_face_save_look(g, names[i], &e) == ROUGE_ERR_ARG && strstr(e.msg, "loaded from"), "save_look %s: %s",
                 names[i], e.msg);
        e = (rouge_error){0};
        RS_CHECK(rouge_face_write_png(g, names[i], &e) == ROUGE_ERR_ARG && strstr(e.msg, "loaded from"),
                 "write_png %s: %s", names[i], e.msg);
        e = (rouge_error){0};
        RS_CHECK(rouge_face_record_strokes(g, names[i], &e) == ROUGE_ERR_ARG && strstr(e.msg, "loaded from"),
                 "record_strokes %s: %s", names[i], e.msg);
    }
    e = (rouge_error){0};
    RS_CHECK(rouge_face_record_strokes(g, sub, &e) == ROUGE_ERR_IO && strstr(e.msg, "directory"),
             "record_strokes into a directory: %s %s", rouge_result_name(e.code), e.msg);
    RS_CHECK(rouge_face_flush_strokes(g, &e) == ROUGE_OK, "nothing recording: %s", e.msg);
    RS_CHECK(file_bytes(rsf, &after, &after_len) && after_len == orig_len && !memcmp(orig, after, orig_len),
             "the face file changed");
out:
    rouge_face_destroy(g);
    free(orig), free(after);
    remove(link_path), remove(rsf), rmdir(sub), rmdir(dir);
}

// The bundled environments come from beside the library (here: the test program in build/tests/, so the
// tree's assets/env), not from the working directory: a host running elsewhere still gets them.
static void test_environments_found_from_any_working_directory(void)
{
    char face_abs[PATH_MAX], cwd[PATH_MAX], dir[] = "/tmp/rouge_embed_cwd_XXXXXX";
    RS_REQUIRE(realpath(FACE, face_abs) && getcwd(cwd, sizeof cwd) && mkdtemp(dir), "paths");
    RS_REQUIRE(chdir(dir) == 0, "chdir");
    rouge_face *g = NULL;
    rouge_error e = {0};
    rouge_view v = small_view();
    v.env = "sunset";
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = face_abs, .view = &v}, &g, &e) == ROUGE_OK,
             "default environments from %s: %s", dir, e.msg);
    rouge_face_destroy(g);
    RS_CHECK(chdir(cwd) == 0, "chdir back");
    rmdir(dir);
}

// rouge.h promises that loading a look is not undoable: undo and redo are empty after it, and a look that
// does not parse leaves the painted makeup and its undo as they were.
static void test_load_look_clears_undo(void)
{
    rouge_error e = {0};
    RS_REQUIRE(rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, &e) ==
                   ROUGE_OK,
               "%s", e.msg);
    RS_REQUIRE(rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);  // pointer pixels refer to a frame
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) ==
                   ROUGE_OK,
               "%s", e.msg);
    for (int i = 0; i <= 8; i++) {
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : i == 8 ? ROUGE_POINTER_UP : ROUGE_POINTER_MOVE, 1,
                                  SIZE * (0.35f + 0.03f * (float)i), SIZE * 0.6f, 1, 0.02 * i};
        RS_REQUIRE(rouge_face_pointer(face, &ev, NULL, &e) == ROUGE_OK, "%s", e.msg);
    }
    char *look = NULL;
    size_t len = 0;
    RS_REQUIRE(rouge_face_stats(face).can_undo, "a stroke is undoable");
    RS_REQUIRE(rouge_face_save_look_memory(face, &look, &len, &e) == ROUGE_OK, "%s", e.msg);
    RS_CHECK(rouge_face_load_look_memory(face, "not a look", 10, &e) != ROUGE_OK && rouge_face_stats(face).can_undo,
             "a bad look keeps undo");
    RS_CHECK(rouge_face_load_look_memory(face, look, len, &e) == ROUGE_OK, "load: %s", e.msg);
    rouge_stats st = rouge_face_stats(face);
    RS_CHECK(!st.can_undo && !st.can_redo && st.look_stamps > 0, "after load_look: undo %d redo %d stamps %u",
             st.can_undo, st.can_redo, st.look_stamps);
    RS_CHECK(!rouge_face_undo(face), "undo after load_look");
    rouge_free(look);
    rouge_face_clear(face, NULL);
}

static void test_version_matches_the_header(void)
{
    char want[32];
    snprintf(want, sizeof want, "%d.%d.%d", ROUGE_VERSION_MAJOR, ROUGE_VERSION_MINOR, ROUGE_VERSION_PATCH);
    RS_CHECK(rouge_version() && !strcmp(rouge_version(), want), "rouge_version() '%s', want '%s'", rouge_version(), want);
    RS_CHECK(rouge_version_number() == ROUGE_VERSION_NUMBER && ROUGE_VERSION_NUMBER == 100, "version number %u",
             rouge_version_number());
}

// A blush stroke along the cheek, its coordinates scaled by k; the stamps it applied.
static uint32_t cheek_stroke(rouge_face *f, float k)
{
    rouge_error e = {0};
    uint32_t stamps = 0;
    for (int i = 0; i <= 8; i++) {
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : i == 8 ? ROUGE_POINTER_UP : ROUGE_POINTER_MOVE, 1,
                                  SIZE * (0.35f + 0.03f * (float)i) * k, SIZE * 0.6f * k, 1, 0.02 * i};
        rouge_pointer_result res = {0};
        RS_CHECK(rouge_face_pointer(f, &ev, &res, &e) == ROUGE_OK, "%s", e.msg);
        stamps += res.stamps;
    }
    return stamps;
}

// The look after one cheek stroke at view.pixel_ratio `ratio` with coordinates scaled by k (then cleared).
static char *look_of_stroke(float ratio, float k, size_t *len, uint32_t *stamps)
{
    rouge_error e = {0};
    rouge_view v = small_view();
    v.pixel_ratio = ratio;
    char *look = NULL;
    if (RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK && rouge_face_render(face, &e) == ROUGE_OK &&
                     rouge_face_clear(face, &e) == ROUGE_OK &&
                     rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) ==
                         ROUGE_OK,
                 "%s", e.msg)) {
        *stamps = cheek_stroke(face, k);
        RS_CHECK(rouge_face_save_look_memory(face, &look, len, &e) == ROUGE_OK, "%s", e.msg);
    }
    rouge_face_clear(face, NULL);
    return look;
}

// pixel_ratio: a host passes window units (frame pixels / ratio). The stroke at ratio 2 with its coordinates
// halved paints the stamps the stroke in pixels paints at ratio 1 (and not those of halved pixels); picks
// and pan take window units too.
static void test_pixel_ratio_takes_window_units(void)
{
    size_t la = 0, lb = 0, lc = 0;
    uint32_t sa = 0, sb = 0, sc = 0;
    char *a = look_of_stroke(1, 1, &la, &sa), *b = look_of_stroke(2, 0.5f, &lb, &sb), *c = look_of_stroke(1, 0.5f, &lc, &sc);
    RS_CHECK(a && b && c && sa > 0, "looks %p %p %p, %u stamps", (void *)a, (void *)b, (void *)c, sa);
    if (a && b && c) {
        RS_CHECK(sa == sb && la == lb && !memcmp(a, b, la), "ratio 2 with halved coordinates: %u stamps vs %u, look differs",
                 sb, sa);
        RS_CHECK(lc != la || memcmp(a, c, la), "halved pixels at ratio 1 paint elsewhere (the check means something)");
    }
    rouge_free(a), rouge_free(b), rouge_free(c);
    rouge_error e = {0};
    rouge_view v = small_view();
    rouge_pick p1 = {0}, p2 = {0};
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK && rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);
    bool h1 = rouge_face_pick(face, SIZE * 0.45f, SIZE * 0.55f, &p1);
    v.pixel_ratio = 2;
    RS_REQUIRE(rouge_face_set_view(face, &v, &e) == ROUGE_OK && rouge_face_render(face, &e) == ROUGE_OK, "%s", e.msg);
    bool h2 = rouge_face_pick(face, SIZE * 0.225f, SIZE * 0.275f, &p2);
    RS_CHECK(h1 && h2 && p1.splat == p2.splat && fabsf(p2.brush_radius_px * 2 - p1.brush_radius_px) < 1e-3f,
             "pick %d %u r %g vs %d %u r %g", h1, p1.splat, p1.brush_radius_px, h2, p2.splat, p2.brush_radius_px);
    rouge_face_pan(face, 8, 0);
    RS_CHECK(fabsf(rouge_face_get_view(face).pan[0] - 16.0f / SIZE) < 1e-6f, "pan 8 window units = 16 pixels: %g",
             rouge_face_get_view(face).pan[0]);
    v.pixel_ratio = -1;
    RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_ERR_ARG && strstr(e.msg, "pixel_ratio"), "%s", e.msg);
    v = small_view();
    RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK, "%s", e.msg);
}

// The host's camera: the matrices rouge built for a turned view, handed back with use_matrices on an
// unturned orbit view, give that turned view's picture and picks; the orbit view alone does not.
static void test_host_matrices_replace_the_orbit_camera(void)
{
    size_t n = (size_t)SIZE * SIZE * 4;
    uint8_t *a = malloc(n), *b = malloc(n), *c = malloc(n);
    RS_REQUIRE(a && b && c, "alloc");
    rouge_error e = {0};
    rouge_view v = small_view();
    v.yaw_deg = 30, v.pitch_deg = 10, v.zoom = 1.4f, v.pan[0] = 0.05f;
    float vm[16], pm[16];
    rouge_pick pa = {0}, pb = {0};
    if (!RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(face, a), "%s", e.msg)) goto out;
    bool ha = rouge_face_pick(face, SIZE * 0.5f, SIZE * 0.5f, &pa);
    RS_REQUIRE(rouge_face_camera_matrices(face, vm, pm, &e) == ROUGE_OK, "%s", e.msg);
    rouge_view w = small_view();
    w.use_matrices = true;
    memcpy(w.view_matrix, vm, sizeof vm), memcpy(w.proj_matrix, pm, sizeof pm);
    if (!RS_CHECK(rouge_face_set_view(face, &w, &e) == ROUGE_OK && frame(face, b), "%s", e.msg)) goto out;
    bool hb = rouge_face_pick(face, SIZE * 0.5f, SIZE * 0.5f, &pb);
    RS_CHECK(max_diff(a, b, n) <= 1, "host matrices differ from the camera they came from by %d", max_diff(a, b, n));
    RS_CHECK(ha && hb && pa.splat == pb.splat, "pick %d %u vs %d %u", ha, pa.splat, hb, pb.splat);
    // Gestures only report: a one-finger orbit leaves the picture alone.
    rouge_face_set_painting(face, false);
    rouge_pointer_result res = {0};
    for (int i = 0; i < 3; i++) {
        rouge_pointer_event ev = {i == 0 ? ROUGE_POINTER_DOWN : i == 2 ? ROUGE_POINTER_UP : ROUGE_POINTER_MOVE, 1,
                                  10.0f + 10.0f * (float)i, 30, 1, 0.05 * i};
        RS_CHECK(rouge_face_pointer(face, &ev, i == 1 ? &res : NULL, &e) == ROUGE_OK, "%s", e.msg);
    }
    rouge_face_set_painting(face, true);
    RS_CHECK(frame(face, c) && max_diff(b, c, n) == 0 && res.orbit_dx != 0, "an orbit gesture moved the host's camera");
    if (!RS_CHECK(rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, &e) ==
                      ROUGE_OK && frame(face, c), "%s", e.msg))
        goto out;
    RS_CHECK(max_diff(b, c, n) > 32, "the orbit view looks like the turned one (max diff %d)", max_diff(b, c, n));
    // Refused at set_view, naming the field: NaN, a scaled view, an orthographic projection.
    rouge_view bad = w;
    bad.proj_matrix[5] = NAN;
    RS_CHECK(rouge_face_set_view(face, &bad, &e) == ROUGE_ERR_ARG && strstr(e.msg, "proj_matrix[5]"), "%s", e.msg);
    bad = w;
    for (int i = 0; i < 3; i++) bad.view_matrix[i] *= 2;
    RS_CHECK(rouge_face_set_view(face, &bad, &e) == ROUGE_ERR_ARG && strstr(e.msg, "rigid"), "%s", e.msg);
    bad = w;
    bad.proj_matrix[11] = 0, bad.proj_matrix[15] = 1;
    RS_CHECK(rouge_face_set_view(face, &bad, &e) == ROUGE_ERR_ARG && strstr(e.msg, "perspective"), "%s", e.msg);
    RS_CHECK(rouge_face_camera_matrices(face, vm, NULL, &e) == ROUGE_ERR_ARG, "NULL matrix");
out:
    rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, NULL);
    free(a), free(b), free(c);
}

// After a blush stroke and a custom red lipstick stroke the look lists both, in that order, with their
// colours, finishes and stamps (all the look's); asking for the count only works; undo drops the second.
static void test_look_info_lists_the_products(void)
{
    rouge_error e = {0};
    rouge_cosmetic blush = {0}, lip = {0};
    for (int i = 0; i < rouge_cosmetic_count(); i++) {
        rouge_cosmetic c;
        rouge_cosmetic_get(i, &c);
        if (!strcmp(c.name, "blush")) blush = c;
        if (!strcmp(c.name, "lipstick_satin")) lip = c;
    }
    RS_REQUIRE(blush.name && lip.name, "presets");
    RS_REQUIRE(rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, &e) ==
                       ROUGE_OK && rouge_face_render(face, &e) == ROUGE_OK && rouge_face_clear(face, &e) == ROUGE_OK,
               "%s", e.msg);
    int n = -1;
    RS_CHECK(rouge_face_look_info(face, NULL, 0, &n, &e) == ROUGE_OK && n == 0, "bare face: %d products", n);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "blush", .size = 0.15f, .opacity = 1}, &e) == ROUGE_OK,
               "%s", e.msg);
    uint32_t s1 = cheek_stroke(face, 1);
    RS_REQUIRE(rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_satin", .color = {1, 0, 0, 1},
                                                         .size = 0.1f, .opacity = 1, .any_region = true},
                                    &e) == ROUGE_OK,
               "%s", e.msg);
    uint32_t s2 = cheek_stroke(face, 1);
    rouge_look_item items[4];
    memset(items, 0xab, sizeof items);
    RS_CHECK(rouge_face_look_info(face, NULL, 0, &n, &e) == ROUGE_OK && n == 2, "count only: %d", n);
    n = -1;
    RS_REQUIRE(rouge_face_look_info(face, items, 4, &n, &e) == ROUGE_OK && n == 2, "%d products: %s", n, e.msg);
    rouge_look_item *b = &items[0], *l = &items[1];
    RS_CHECK(!strcmp(b->name, "blush") && !strcmp(b->kind, blush.kind) && !memcmp(b->rgb, blush.rgb, 3) &&
                 b->finish == blush.finish && b->coverage == blush.coverage && b->stamps == s1 && s1 > 0,
             "blush: %s %s rgb %u %u %u finish %d stamps %u (painted %u)", b->name, b->kind, b->rgb[0], b->rgb[1],
             b->rgb[2], b->finish, b->stamps, s1);
    RS_CHECK(!strcmp(l->name, "custom_lipstick_satin") && !strcmp(l->kind, lip.kind) && l->rgb[0] == 255 &&
                 l->rgb[1] == 0 && l->rgb[2] == 0 && l->stamps == s2 && s2 > 0,
             "lipstick: %s %s rgb %u %u %u stamps %u (painted %u)", l->name, l->kind, l->rgb[0], l->rgb[1], l->rgb[2],
             l->stamps, s2);
    RS_CHECK(b->stamps + l->stamps == rouge_face_stats(face).look_stamps, "stamps %u + %u of %u", b->stamps, l->stamps,
             rouge_face_stats(face).look_stamps);
    n = -1;
    RS_CHECK(rouge_face_look_info(face, items, 1, &n, &e) == ROUGE_OK && n == 2 && !strcmp(items[0].name, "blush"),
             "capacity 1: %d", n);
    RS_CHECK(rouge_face_undo(face) && rouge_face_look_info(face, items, 4, &n, &e) == ROUGE_OK && n == 1,
             "after undo: %d products", n);
    RS_CHECK(rouge_face_look_info(face, NULL, 2, &n, &e) == ROUGE_ERR_ARG && rouge_face_look_info(NULL, items, 4, &n, &e) ==
                 ROUGE_ERR_ARG, "NULL items or face");
    rouge_face_clear(face, NULL);
}

typedef struct progress_log {
    float last;
    int calls;
    bool monotonic;
    float cancel_at;  // returns false from this fraction on (negative: never)
} progress_log;

static bool on_progress(void *user, float fraction)
{
    progress_log *p = user;
    if (!(fraction >= p->last && fraction >= 0 && fraction <= 1)) p->monotonic = false;
    p->last = fraction;
    p->calls++;
    return !(p->cancel_at >= 0 && fraction >= p->cancel_at);
}

// create reports 0 .. 1, never decreasing; a false return at any stage cancels: ROUGE_ERR_CANCELLED,
// "cancelled", *out untouched, nothing leaked (asan) and no GL error left.
static void test_create_reports_progress_and_cancels(void)
{
    rouge_view v = small_view();
    rouge_error e = {0};
    progress_log p = {-1, 0, true, -1};
    rouge_face *g = NULL;
    RS_CHECK(rouge_face_create(&(rouge_face_desc){.path = FACE, .view = &v, .progress = on_progress, .progress_user = &p},
                               &g, &e) == ROUGE_OK,
             "%s", e.msg);
    RS_CHECK(p.monotonic && p.last == 1 && p.calls >= 4, "progress: %d calls, last %g, monotonic %d", p.calls, p.last,
             p.monotonic);
    rouge_face_destroy(g);
    const float stops[] = {0, 0.5f, 0.85f, 0.9f, 1};
    for (size_t i = 0; i < RS_COUNT_OF(stops); i++) {
        p = (progress_log){-1, 0, true, stops[i]};
        rouge_face *sentinel = (rouge_face *)&p;
        g = sentinel;
        e = (rouge_error){0};
        rouge_result r = rouge_face_create(
            &(rouge_face_desc){.path = FACE, .view = &v, .progress = on_progress, .progress_user = &p}, &g, &e);
        RS_CHECK(r == ROUGE_ERR_CANCELLED && e.code == ROUGE_ERR_CANCELLED && !strcmp(e.msg, "cancelled") && g == sentinel,
                 "cancel at %g: %s '%s'", stops[i], rouge_result_name(r), e.msg);
        RS_CHECK(p.last == stops[i], "cancelled at %g, last call %g", stops[i], p.last);
        RS_CHECK(glGetError() == GL_NO_ERROR, "GL error after a cancel");
    }
    RS_CHECK(!strcmp(rouge_result_name(ROUGE_ERR_CANCELLED), "ROUGE_ERR_CANCELLED"), "name");
}

// A host without files hands an environment's bytes: under a new name it lights the face as the file
// of the same bytes does; adding another under that name while in use relights at once; bad bytes and
// "paper" are refused.
static void test_environment_from_memory_renders_like_the_file(void)
{
    size_t n = (size_t)SIZE * SIZE * 4, dlen = 0, slen = 0;
    uint8_t *a = malloc(n), *b = malloc(n);
    void *day = NULL, *studio = NULL;
    rouge_error e = {0};
    rouge_view v = small_view();
    RS_REQUIRE(a && b, "alloc");
    if (!RS_CHECK(file_bytes("assets/env/daylight.rse", &day, &dlen) && file_bytes("assets/env/studio.rse", &studio, &slen),
                  "read the environments"))
        goto out;
    v.env = "from_memory";
    RS_CHECK(rouge_face_set_view(face, &v, &e) != ROUGE_OK, "an unknown name before it is added");
    v.env = "daylight";
    if (!RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(face, a), "%s", e.msg)) goto out;
    RS_CHECK(rouge_face_add_environment(face, "from_memory", day, dlen, &e) == ROUGE_OK, "add: %s", e.msg);
    v.env = "from_memory";
    if (!RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(face, b), "%s", e.msg)) goto out;
    RS_CHECK(max_diff(a, b, n) == 0, "daylight from memory differs from the file by %d", max_diff(a, b, n));
    // Replaced while the view uses it: the next frame is lit by the new one.
    RS_CHECK(rouge_face_add_environment(face, "from_memory", studio, slen, &e) == ROUGE_OK, "replace: %s", e.msg);
    RS_CHECK(frame(face, b), "frame");
    v.env = "studio";
    if (!RS_CHECK(rouge_face_set_view(face, &v, &e) == ROUGE_OK && frame(face, a), "%s", e.msg)) goto out;
    RS_CHECK(max_diff(a, b, n) == 0, "replaced environment: differs from studio by %d", max_diff(a, b, n));
    e = (rouge_error){0};
    RS_CHECK(rouge_face_add_environment(face, "junk", "not an environment", 18, &e) == ROUGE_ERR_FORMAT &&
                 strstr(e.msg, "junk"),
             "bad bytes: %s %s", rouge_result_name(e.code), e.msg);
    RS_CHECK(rouge_face_add_environment(face, "paper", day, dlen, &e) == ROUGE_ERR_ARG, "paper: %s", e.msg);
    RS_CHECK(rouge_face_add_environment(face, "x", NULL, 10, &e) == ROUGE_ERR_ARG, "NULL bytes");
out:
    rouge_face_set_view(face, &(rouge_view){.width = SIZE, .height = SIZE, .max_splats = MAX_SPLATS}, NULL);
    free(a), free(b), free(day), free(studio);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    rouge_error e = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - test_embed: %s\n", err.msg);
        return rs_test_finish();
    }
    rouge_view v = small_view();
    if (rouge_face_create(&(rouge_face_desc){.path = FACE, .view = &v}, &face, &e) != ROUGE_OK) {
        printf("FAIL - test_embed: %s\n", e.msg);
        rs_gl_destroy(gl);
        return 1;
    }
    RS_RUN(test_pixel_store_state_does_not_reach_rouge);
    RS_RUN(test_pending_host_gl_error_is_not_rouge_s);
    RS_RUN(test_draw_into_srgb_framebuffer_encodes_once);
    RS_RUN(test_calls_need_the_face_s_context);
    RS_RUN(test_null_everywhere);
    RS_RUN(test_set_view_names_the_bad_field);
    RS_RUN(test_outputs_never_overwrite_the_face_file);
    RS_RUN(test_environments_found_from_any_working_directory);
    RS_RUN(test_load_look_clears_undo);
    RS_RUN(test_version_matches_the_header);
    RS_RUN(test_pixel_ratio_takes_window_units);
    RS_RUN(test_host_matrices_replace_the_orbit_camera);
    RS_RUN(test_look_info_lists_the_products);
    RS_RUN(test_create_reports_progress_and_cancels);
    RS_RUN(test_environment_from_memory_renders_like_the_file);
    rouge_face_destroy(face);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
