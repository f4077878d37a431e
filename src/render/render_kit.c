// render_kit.c — the renderer's GL toolbox, below the stages (render_kit.h): the lazily linked programs
// and their constant uniforms, textures, the framebuffer check, and the splat draw every splat pass shares.
// Calls nothing above it: no stage, nothing in render.c.
#include "render/render_kit.h"

#include "gl/shader.h"

#include <math.h>
#include <stdio.h>

GLuint rs_render_texture(GLenum internal_format, int w, int h)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal_format, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return t;
}

void rs_render_bind_texture(int unit, GLuint tex)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    glBindTexture(GL_TEXTURE_2D, tex);
}

rs_result rs_render_fbo_check(const char *what, rs_error *err)
{
    GLenum s = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (s == GL_FRAMEBUFFER_COMPLETE) return RS_OK;
    return rs_fail(err, RS_ERR_GL, "render: %s: framebuffer incomplete (status 0x%04x)", what, s);
}

static const char *const prog_files[RS_PROG_COUNT][2] = {
    [RS_PROG_SHADOW] = {"visibility.vert.glsl", "visibility.frag.glsl"},
    [RS_PROG_VISIBILITY] = {"visibility.vert.glsl", "visibility.frag.glsl"},
    [RS_PROG_PICK] = {"visibility.vert.glsl", "visibility.frag.glsl"},
    [RS_PROG_ATTRIBUTE] = {"attribute.vert.glsl", "attribute.frag.glsl"},
    [RS_PROG_DIFFUSION] = {"diffusion.vert.glsl", "diffusion.frag.glsl"},
    [RS_PROG_RESOLVE] = {"fullscreen.vert.glsl", "diffusion_resolve.frag.glsl"},
    [RS_PROG_REFLECT] = {"fullscreen.vert.glsl", "reflect.frag.glsl"},
    [RS_PROG_COMPOSITE] = {"fullscreen.vert.glsl", "composite.frag.glsl"},
    [RS_PROG_IRRADIANCE] = {"irradiance.vert.glsl", "irradiance.frag.glsl"},
    [RS_PROG_EDGES_FIND] = {"fullscreen.vert.glsl", "edges_find.frag.glsl"},
    [RS_PROG_EDGES] = {"fullscreen.vert.glsl", "edges.frag.glsl"},
};

static const char *const prog_defines[RS_PROG_COUNT] = {
    [RS_PROG_SHADOW] = "#define RS_SHADOW 1\n",
    [RS_PROG_PICK] = "#define RS_PICK 1\n",
};

rs_result rs_render_program(rs_renderer *r, rs_prog kind, bool quads, GLuint *out, rs_error *err)
{
    int q = kind < RS_PROG_SPLAT_COUNT && quads ? 1 : 0;
    if (r->prog[kind][q]) {
        *out = r->prog[kind][q];
        return RS_OK;
    }
    char defines[128];
    snprintf(defines, sizeof defines, "%s%s", prog_defines[kind] ? prog_defines[kind] : "",
             q ? "#define RS_QUADS 1\n" : "");
    GLuint p = 0;
    rs_result res = rs_shader_program(prog_files[kind][0], prog_files[kind][1], defines, &p, err);
    if (res != RS_OK) return res;
    if (kind == RS_PROG_IRRADIANCE) {
        // Feedback varyings must be named before linking: the shaders are still attached, so link again.
        const char *varyings[1] = {"v_irradiance"};
        glTransformFeedbackVaryings(p, 1, varyings, GL_INTERLEAVED_ATTRIBS);
        glLinkProgram(p);
        GLint ok = 0;
        glGetProgramiv(p, GL_LINK_STATUS, &ok);
        if (!ok) {
            char log[512] = "";
            glGetProgramInfoLog(p, sizeof log, NULL, log);
            glDeleteProgram(p);
            return rs_fail(err, RS_ERR_GL, "shader link error (irradiance transform feedback): %.400s", log);
        }
    }
    // Constants of the program: the record's quantization frame, the texture units.
    const rs_splat_header *h = &r->cloud->hdr;
    glUseProgram(p);
    glUniform3fv(rs_uloc(p, "u_bbox_min"), 1, h->bbox_min);
    float step[3];
    for (int a = 0; a < 3; a++) step[a] = (h->bbox_max[a] - h->bbox_min[a]) / 65535.0f;
    glUniform3fv(rs_uloc(p, "u_bbox_step"), 1, step);
    glUniform2f(rs_uloc(p, "u_radius_log"), h->radius_min, logf(h->radius_max / h->radius_min) / 255.0f);
    glUniform1i(rs_uloc(p, "u_depth"), RS_UNIT_DEPTH);
    glUniform1i(rs_uloc(p, "u_push"), RS_UNIT_PUSH);
    glUniform1i(rs_uloc(p, "u_shadow_map"), RS_UNIT_SHADOW);
    glUniform1i(rs_uloc(p, "u_lamp_shadow_map"), RS_UNIT_LAMP_SHADOW);
    glUniform1i(rs_uloc(p, "u_attr0"), RS_UNIT_ATTR0);
    glUniform1i(rs_uloc(p, "u_attr1"), RS_UNIT_ATTR1);
    glUniform1i(rs_uloc(p, "u_attr2"), RS_UNIT_ATTR2);
    glUniform1i(rs_uloc(p, "u_attr3"), RS_UNIT_ATTR3);
    glUniform1i(rs_uloc(p, "u_diffuse"), RS_UNIT_DIFFUSE);
    glUniform1i(rs_uloc(p, "u_level"), RS_UNIT_LEVEL);
    glUniform1i(rs_uloc(p, "u_env_map"), RS_UNIT_ENV);
    glUniform1i(rs_uloc(p, "u_spec_lut"), RS_UNIT_SPEC_LUT);
    glUniform1i(rs_uloc(p, "u_color"), RS_UNIT_COLOR);
    glUniform1i(rs_uloc(p, "u_edges"), RS_UNIT_EDGES);
    glUniform1i(rs_uloc(p, "u_reflect"), RS_UNIT_REFLECT);
    glUniform1i(rs_uloc(p, "u_body"), RS_UNIT_BODY);
    glUniform1f(rs_uloc(p, "u_has_ao"), (h->flags & RS_SPLAT_FLAG_AO) ? 1.0f : 0.0f);
    glUniform1f(rs_uloc(p, "u_has_bent"), (h->flags & RS_SPLAT_FLAG_BENT) ? 1.0f : 0.0f);
    r->prog[kind][q] = p;
    *out = p;
    return RS_OK;
}

void rs_render_splat_uniforms(GLuint p, const mat4 view, const mat4 proj, const mat4 inv_proj, int w, int h,
                              bool persp, float radius_scale, float cull_cos, float point_max)
{
    glUniformMatrix4fv(rs_uloc(p, "u_view"), 1, GL_FALSE, (const float *)view);
    glUniformMatrix4fv(rs_uloc(p, "u_proj"), 1, GL_FALSE, (const float *)proj);
    glUniformMatrix4fv(rs_uloc(p, "u_inv_proj"), 1, GL_FALSE, (const float *)inv_proj);
    glUniform2f(rs_uloc(p, "u_viewport"), (float)w, (float)h);
    glUniform1f(rs_uloc(p, "u_persp"), persp ? 1.0f : 0.0f);
    glUniform1f(rs_uloc(p, "u_radius_scale"), radius_scale);
    glUniform1f(rs_uloc(p, "u_cull_cos"), cull_cos);
    glUniform1f(rs_uloc(p, "u_point_max"), point_max);
    glUniform1f(rs_uloc(p, "u_coverage"), RS_COVERAGE);
}

void rs_render_draw_splats(const rs_renderer *r, uint32_t count, bool quads)
{
    if (count == 0) return;
    glBindVertexArray(quads ? r->vao_quads : r->vao_points);
    if (quads) glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, (GLsizei)count);
    else glDrawArrays(GL_POINTS, 0, (GLsizei)count);
}
