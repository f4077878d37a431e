// test_first_frame.c — loading shows real progress (issue 21, item 4): rouge_face_create with first_frame
// renders the view's first frame inside create and reports every stage of it (shaders compiled on first
// use, shadow map, ...) through progress and progress_stage, in order, never going back; the frame is the
// one a later render would have made (that render then only copies it out); a callback may draw with its
// own GL state in between, and cancel at any stage.
#include "support/harness.h"
#include "gl/gl.h"
#include "rouge.h"

#include <GLES3/gl3.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FACE_PATH "assets/face.rsf"
#define W 320
#define H 240

static double now_s(void) { return rs_time_now(); }

typedef struct seen {
    int calls, stage_calls;
    float fractions[32], stage_fractions[32];
    char stages[32][32];
    int steps[32], totals[32];
    double times[32];
    const char *cancel_at;  // return false when this stage begins
    bool draw;              // draw with the host's own GL state in the callback
    GLuint host_fbo;        // the framebuffer the host had bound at create
    bool host_state_ok;     // every callback saw the host's framebuffer and viewport
} seen;

static bool on_progress(void *user, float fraction)
{
    seen *s = user;
    if (s->calls < 32) s->fractions[s->calls] = fraction;
    s->calls++;
    return true;
}

static bool on_stage(void *user, const rouge_progress *p)
{
    seen *s = user;
    int k = s->stage_calls++;
    if (k < 32) {
        s->stage_fractions[k] = p->fraction;
        snprintf(s->stages[k], sizeof s->stages[k], "%s", p->stage ? p->stage : "(null)");
        s->steps[k] = p->step, s->totals[k] = p->steps, s->times[k] = now_s();
    }
    GLint fbo = -1, vp[4] = {0};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &fbo);
    glGetIntegerv(GL_VIEWPORT, vp);
    if ((GLuint)fbo != s->host_fbo || vp[2] != 7 || vp[3] != 5) s->host_state_ok = false;
    if (s->draw) {
        // A host's loading screen: its own program-less clear into its own framebuffer, another viewport,
        // a scissor, and a GL error left behind; none of it may reach rouge's frame.
        glViewport(1, 2, 3, 4);
        glEnable(GL_SCISSOR_TEST);
        glScissor(0, 0, 2, 2);
        glClearColor(1, 0, 1, 1);
        glClear(GL_COLOR_BUFFER_BIT);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, 0);
        glEnable(GL_BLEND);
        glGetError();
        glEnable(0x1234);  // GL_INVALID_ENUM, the host's own
        glDisable(GL_SCISSOR_TEST);
        glDisable(GL_BLEND);
        glActiveTexture(GL_TEXTURE0);
        glViewport(0, 0, 7, 5);
    }
    return !(s->cancel_at && p->stage && strcmp(p->stage, s->cancel_at) == 0);
}

static GLuint host_fbo, host_tex;

static rouge_result create(bool first_frame, seen *s, rouge_face **out, rouge_error *e)
{
    static const rouge_view view = {.width = W, .height = H};
    s->host_fbo = host_fbo;
    s->host_state_ok = true;
    glBindFramebuffer(GL_FRAMEBUFFER, host_fbo);
    glViewport(0, 0, 7, 5);
    return rouge_face_create(&(rouge_face_desc){.path = FACE_PATH, .view = &view, .env_dir = "assets/env",
                                                .first_frame = first_frame, .progress = on_progress,
                                                .progress_stage = on_stage, .progress_user = s},
                             out, e);
}

static bool read_frame(rouge_face *f, uint8_t *px)
{
    rouge_error e = {0};
    return rouge_face_read_rgba(f, px, (size_t)W * H * 4, &e) == ROUGE_OK;
}

static void test_first_frame_stages_are_reported_in_order(void)
{
    seen s = {.draw = true};
    rouge_face *f = NULL;
    rouge_error e = {0};
    double t0 = now_s();
    RS_REQUIRE(create(true, &s, &f, &e) == ROUGE_OK, "create: %s", e.msg);
    double t1 = now_s();
    static const char *const want[] = {"reading the face", "uploading and compiling", "makeup layer", "lighting",
                                       "shadow map", "visibility", "attributes", "light and diffusion",
                                       "composite", "done"};
    int n = (int)(sizeof want / sizeof *want);
    RS_CHECK(s.stage_calls == n, "%d stages reported, want %d", s.stage_calls, n);
    RS_CHECK(s.calls == s.stage_calls, "progress called %d times, progress_stage %d", s.calls, s.stage_calls);
    bool order = true, mono = true, steps = true;
    for (int k = 0; k < n && k < s.stage_calls; k++) {
        order &= strcmp(s.stages[k], want[k]) == 0;
        steps &= s.steps[k] == k + 1 && s.totals[k] == n;
        mono &= s.fractions[k] == s.stage_fractions[k] && (k == 0 || s.fractions[k] >= s.fractions[k - 1]);
    }
    RS_CHECK(order, "the stages are not in order");
    RS_CHECK(steps, "the step numbers are not 1..%d of %d", n, n);
    RS_CHECK(mono && s.fractions[0] == 0.0f && s.fractions[n - 1] == 1.0f, "fractions not 0 .. 1, non-decreasing");
    RS_CHECK(s.host_state_ok, "a callback saw rouge's framebuffer or viewport, not the host's");
    // The frame's stages took their time inside create: between "shadow map" and "done" lies most of it.
    double frame_s = s.times[n - 1] - s.times[4], create_s = t1 - t0;
    printf("# create with the first frame: %.2f s, of which the frame's stages %.2f s; fractions:", create_s, frame_s);
    for (int k = 0; k < n; k++) printf(" %.3f", s.fractions[k]);
    printf("\n");
    for (int k = 0; k + 1 < n && k < s.stage_calls; k++) printf("#   %-24s %.2f s\n", s.stages[k], s.times[k + 1] - s.times[k]);
    RS_CHECK(frame_s > 0.5 * (s.times[n - 1] - s.times[0]), "the first frame's stages took %.2f of %.2f s: not reported "
             "where the time goes", frame_s, s.times[n - 1] - s.times[0]);
    RS_CHECK(!rouge_face_changed(f), "the face says it changed: the host would render the first frame again");
    RS_CHECK(rouge_face_take_host_gl_error(f) == GL_INVALID_ENUM, "the host's GL error in the callback was not kept as the host's");

    // The frame is the one a face made without it renders, and rendering it again costs nothing.
    uint8_t *a = malloc((size_t)W * H * 4), *b = malloc((size_t)W * H * 4);
    RS_REQUIRE(read_frame(f, a), "read");
    double r0 = now_s();
    RS_CHECK(rouge_face_render(f, &e) == ROUGE_OK, "render: %s", e.msg);
    double again_s = now_s() - r0;
    seen s2 = {0};
    rouge_face *g = NULL;
    RS_REQUIRE(create(false, &s2, &g, &e) == ROUGE_OK, "create: %s", e.msg);
    RS_CHECK(s2.stage_calls == 5 && strcmp(s2.stages[4], "done") == 0 && s2.totals[0] == 5,
             "without first_frame: %d stages, last '%s'", s2.stage_calls, s2.stages[4]);
    RS_CHECK(s2.fractions[1] == 0.5f && s2.fractions[2] == 0.85f && s2.fractions[3] == 0.9f,
             "without first_frame the fractions changed: %g %g %g", s2.fractions[1], s2.fractions[2], s2.fractions[3]);
    double g0 = now_s();
    RS_CHECK(rouge_face_render(g, &e) == ROUGE_OK, "render: %s", e.msg);
    double first_s = now_s() - g0;
    RS_REQUIRE(read_frame(g, b), "read");
    int maxd = 0;
    for (size_t i = 0; i < (size_t)W * H * 4; i++) maxd = RS_MAX(maxd, abs(a[i] - b[i]));
    RS_CHECK(maxd == 0, "the first frame made in create differs from a render's by up to %d/255", maxd);
    printf("# the host's first render: %.3f s after a first_frame create, %.2f s without\n", again_s, first_s);
    RS_CHECK(again_s < 0.25 * first_s, "the render after a first_frame create took %.3f s (a first one: %.2f s)",
             again_s, first_s);
    free(a), free(b);
    rouge_face_destroy(f);
    rouge_face_destroy(g);
}

static void test_cancel_at_a_frame_stage(void)
{
    static const char *const at[] = {"shadow map", "composite"};
    for (size_t i = 0; i < sizeof at / sizeof *at; i++) {
        seen s = {.cancel_at = at[i]};
        rouge_face *f = (rouge_face *)&s;  // untouched on failure
        rouge_error e = {0};
        rouge_result r = create(true, &s, &f, &e);
        RS_CHECK(r == ROUGE_ERR_CANCELLED && strcmp(e.msg, "cancelled") == 0 && f == (rouge_face *)&s,
                 "cancel at %s: %s (%s)", at[i], rouge_result_name(r), e.msg);
        RS_CHECK(strcmp(s.stages[s.stage_calls - 1], at[i]) == 0, "cancel at %s: went on to %s", at[i],
                 s.stages[s.stage_calls - 1]);
    }
    // The context is left usable: a face made after a cancelled one renders.
    seen s = {0};
    rouge_face *f = NULL;
    rouge_error e = {0};
    RS_CHECK(create(false, &s, &f, &e) == ROUGE_OK && rouge_face_render(f, &e) == ROUGE_OK, "after cancels: %s",
             e.msg);
    rouge_face_destroy(f);
}

// A stream's progress stays complete once a face took its splats: the viewer's reading thread checks it
// after its last bytes, and once took a face made meanwhile for a truncated file.
static void test_stream_stays_complete_after_the_hand_over(void)
{
    FILE *fp = fopen(FACE_PATH, "rb");
    RS_REQUIRE(fp, "open %s", FACE_PATH);
    static uint8_t buf[1 << 16];
    rouge_stream *st = NULL;
    rouge_error e = {0};
    RS_REQUIRE(rouge_stream_create("face", 0, &st, &e) == ROUGE_OK, "stream: %s", e.msg);
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, fp)) > 0) rouge_stream_feed(st, buf, n, &e);
    fclose(fp);
    rouge_stream_progress before = rouge_stream_get_progress(st);
    rouge_face *f = NULL;
    RS_REQUIRE(rouge_face_create(&(rouge_face_desc){.stream = st, .env_dir = "assets/env"}, &f, &e) == ROUGE_OK,
               "create: %s", e.msg);
    rouge_stream_progress after = rouge_stream_get_progress(st);
    RS_CHECK(before.complete && after.complete && after.splats == before.splats && after.bytes == before.bytes &&
                 after.decoded == before.decoded,
             "after the hand-over: complete %d, %u splats, %u decoded (before: %d, %u, %u)", after.complete,
             after.splats, after.decoded, before.complete, before.splats, before.decoded);
    rouge_face_destroy(f);
    rouge_stream_destroy(st);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_gl_context *gl = NULL;
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("skip - first_frame: no GL context: %s\n", err.msg);
        return rs_test_finish();
    }
    // The host's own framebuffer, bound while it creates faces.
    glGenTextures(1, &host_tex);
    glBindTexture(GL_TEXTURE_2D, host_tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 16, 16);
    glGenFramebuffers(1, &host_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, host_fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, host_tex, 0);
    RS_RUN(test_first_frame_stages_are_reported_in_order);
    RS_RUN(test_cancel_at_a_frame_stage);
    RS_RUN(test_stream_stays_complete_after_the_hand_over);
    glDeleteFramebuffers(1, &host_fbo);
    glDeleteTextures(1, &host_tex);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
