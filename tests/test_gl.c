// test_gl.c — the GL foundation: headless GLES 3 context, embedded shaders and their error messages,
// and a known scene rendered to an FBO compared with a committed golden image.
#include "support/harness.h"
#include "gl/gl.h"
#include "gl/shader.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static rs_gl_context *gl;

static void test_headless_context_is_gles3(void)
{
    const rs_gl_caps *c = rs_gl_get_caps(gl);
    RS_CHECK(c->major >= 3, "GLES %d.%d", c->major, c->minor);
    RS_CHECK(c->point_size_max >= 1.0f, "point size max %g", c->point_size_max);
    RS_CHECK(c->max_draw_buffers >= 4, "MRT %d", c->max_draw_buffers);
}

static void test_broken_shader_error_names_file_and_line(void)
{
    const char *vs = rs_shader_find("smoke.vert.glsl");
    RS_REQUIRE(vs != NULL, "smoke.vert.glsl not embedded");
    const char *bad = "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() {\n  o = vec4(undeclared_thing);\n}\n";
    GLuint prog = 0;
    rs_error err = {0};
    rs_result r = rs_shader_program_from_source("smoke.vert.glsl", vs, "broken.frag.glsl", bad, NULL, &prog, &err);
    RS_CHECK(r == RS_ERR_GL, "expected RS_ERR_GL, got %d", r);
    RS_CHECK(strstr(err.msg, "broken.frag.glsl:5:") != NULL, "message lacks file:line: %s", err.msg);
    RS_CHECK(strchr(err.msg, '\n') == NULL, "message is not one line: %s", err.msg);
}

static void test_broken_shader_with_defines_keeps_line_numbers(void)
{
    const char *vs = rs_shader_find("smoke.vert.glsl");
    const char *bad = "#version 300 es\nprecision highp float;\nout vec4 o;\nvoid main() { o = vec4(X + y_missing); }\n";
    GLuint prog = 0;
    rs_error err = {0};
    rs_shader_program_from_source("smoke.vert.glsl", vs, "b.frag.glsl", bad, "#define X 1.0\n#define Y 2.0\n", &prog,
                                  &err);
    RS_CHECK(strstr(err.msg, "b.frag.glsl:4:") != NULL, "defines shifted the line: %s", err.msg);
}

static void test_missing_embedded_shader_is_a_clear_error(void)
{
    GLuint prog = 0;
    rs_error err = {0};
    rs_result r = rs_shader_program("nope.vert.glsl", "smoke.frag.glsl", NULL, &prog, &err);
    RS_CHECK(r == RS_ERR_GL && strstr(err.msg, "nope.vert.glsl"), "%s", err.msg);
}

// Renders the smoke scene into an RGBA8 FBO and reads it back top row first.
static bool render_smoke(int w, int h, rs_image *out)
{
    GLuint prog;
    rs_error err = {0};
    if (!RS_CHECK(rs_shader_program("smoke.vert.glsl", "smoke.frag.glsl", NULL, &prog, &err) == RS_OK, "%s", err.msg))
        return false;
    GLuint tex, fbo, vao;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, w, h);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex, 0);
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glViewport(0, 0, w, h);
    glUseProgram(prog);
    glUniform3f(glGetUniformLocation(prog, "u_light"), -0.4f, 0.5f, 0.8f);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    rs_image_create(w, h, 4, out, &err);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, out->pixels);
    // GL rows are bottom-first; images are top-first.
    size_t row = (size_t)w * 4;
    unsigned char *tmp = malloc(row);
    for (int y = 0; y < h / 2; y++) {
        memcpy(tmp, out->pixels + (size_t)y * row, row);
        memcpy(out->pixels + (size_t)y * row, out->pixels + (size_t)(h - 1 - y) * row, row);
        memcpy(out->pixels + (size_t)(h - 1 - y) * row, tmp, row);
    }
    free(tmp);
    bool ok = RS_CHECK(rs_gl_check("smoke render", &err) == RS_OK, "%s", err.msg);
    glDeleteVertexArrays(1, &vao);
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &tex);
    glDeleteProgram(prog);
    return ok;
}

static void test_smoke_scene_matches_golden(void)
{
    rs_image img = {0};
    if (render_smoke(128, 128, &img))
        // Different GPUs round the shading differently: allow small differences on a few pixels.
        rs_test_golden("gl_smoke", &img, 3, 0.002, 40.0);
    rs_image_free(&img);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    rs_error err = {0};
    if (rs_gl_create(&(rs_gl_desc){0}, &gl, &err) != RS_OK) {
        printf("FAIL - gl_context: %s\n", err.msg);
        return 1;
    }
    RS_RUN(test_headless_context_is_gles3);
    RS_RUN(test_broken_shader_error_names_file_and_line);
    RS_RUN(test_broken_shader_with_defines_keeps_line_numbers);
    RS_RUN(test_missing_embedded_shader_is_a_clear_error);
    RS_RUN(test_smoke_scene_matches_golden);
    rs_gl_destroy(gl);
    return rs_test_finish();
}
