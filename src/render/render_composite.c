// render_composite.c — stage 5 (paper Fig. 2, eq. 1): a full-screen pass that normalises the attribute
// sums, evaluates the Kelemen/Szirmay-Kalos specular S per pixel, reads D from stage 4 and writes
// F = A (D + S) (RS_COMPOSITE_PAPER, the default under the paper's lights: the paper's composite, which
// tints the highlight by the skin colour) or F = A D + S (RS_COMPOSITE_PHYSICAL, the default under an
// environment: a dielectric's white highlight), plus the makeup's clear coat and flakes; then exposure
// and sRGB into the RGBA8 output. The makeup's fine layer (narrow brushes) is composed per pixel here, over
// the splat layer's A, m, rho_s, coat and flakes (render_fine.c). The debug views are branches of the same pass.
#include "render/render_stages.h"

#include <math.h>

// Whether the edges pass anti-aliases the frame: not the views of data (normals, regions, LOD levels and
// the shadow factor show each pixel's own, unmixed) nor rs_view.sharp_contours.
static bool edges_on(const rs_frame *f)
{
    rs_render_mode m = f->view.mode;
    bool data = m == RS_MODE_NORMALS || m == RS_MODE_REGIONS || m == RS_MODE_LOD || m == RS_MODE_SHADOW;
    return !data && !f->view.sharp_contours;
}

rs_result rs_render_reflections(rs_renderer *r, const rs_frame *f, const int *rect, rs_error *err)
{
    if (!f->env_on) return RS_OK;
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_REFLECT, false, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    // At half size: the composite averages it over a millimetre around each pixel anyway.
    int w = (cam->width + 1) / 2, h = (cam->height + 1) / 2;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_reflect);
    glViewport(0, 0, w, h);
    // A composite pixel averages what lies up to 16 px around it (composite.frag.glsl reflection_near).
    if (rect)
        glScissor((rect[0] - 16) / 2, (rect[1] - 16) / 2, (rect[2] - rect[0] + 34) / 2, (rect[3] - rect[1] + 34) / 2);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(prog);
    glUniformMatrix4fv(rs_uloc(prog, "u_proj"), 1, GL_FALSE, (const float *)cam->proj);
    glUniformMatrix4fv(rs_uloc(prog, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
    glUniform2f(rs_uloc(prog, "u_viewport"), (float)w, (float)h);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform1f(rs_uloc(prog, "u_contour_reach"), 20.0f / RS_MAX(r->cloud->hdr.mm_per_unit, 1e-6f));
    glUniform1f(rs_uloc(prog, "u_min_weight"), r->float_rt ? 0.0f : RS_MIN_WEIGHT_RGBA8);
    glUniform1f(rs_uloc(prog, "u_diffuse_scale"), r->float_rt ? 1.0f : 1.0f / RS_DIFFUSE_SCALE_RGBA8);
    glUniform3fv(rs_uloc(prog, "u_delta_weight"), 1, f->delta_weight);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
    rs_render_bind_texture(RS_UNIT_ATTR0, r->attr_tex[0]);
    rs_render_bind_texture(RS_UNIT_ATTR1, r->attr_tex[1]);
    rs_render_bind_texture(RS_UNIT_DIFFUSE, f->diffuse ? r->diffuse_tex : 0);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    return RS_OK;
}

rs_result rs_render_composite(rs_renderer *r, const rs_frame *f, rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_COMPOSITE, false, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    const rs_view *v = &f->view;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_pre);
    glViewport(0, 0, cam->width, cam->height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(prog);
    glUniformMatrix4fv(rs_uloc(prog, "u_proj"), 1, GL_FALSE, (const float *)cam->proj);
    glUniformMatrix4fv(rs_uloc(prog, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
    glUniform2f(rs_uloc(prog, "u_viewport"), (float)cam->width, (float)cam->height);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform1i(rs_uloc(prog, "u_mode"), (int)v->mode);
    glUniform1f(rs_uloc(prog, "u_key_widen"), f->key_widen);
    bool filmic = v->tonemap == RS_TONEMAP_FILMIC || (v->tonemap == RS_TONEMAP_DEFAULT && f->env_on);
    glUniform1i(rs_uloc(prog, "u_tonemap"), filmic ? 0 : 1);
    glUniformMatrix4fv(rs_uloc(prog, "u_inv_view"), 1, GL_FALSE, (const float *)cam->inv_view);
    // Shimmer flakes of 60 um: pearl pigments are 10-60 um, the sparkling grades at the top of that range.
    // Below a pixel even in a 3x close-up (~0.2 mm): a pixel sums a few to hundreds of them.
    glUniform1f(rs_uloc(prog, "u_flake_size"), 0.060f / RS_MAX(r->cloud->hdr.mm_per_unit, 1e-6f));
    glUniform1f(rs_uloc(prog, "u_contour_reach"), 20.0f / RS_MAX(r->cloud->hdr.mm_per_unit, 1e-6f));
    // The outline's coverage: the edges pass's when it runs, else the composite's 3x3 rule.
    glUniform1i(rs_uloc(prog, "u_outline_coverage"), edges_on(f) ? 0 : 1);
    rs_render_env_uniforms(r, f, prog);
    // Under an environment the highlight is what skin's surface reflects, white (a dielectric); the
    // paper's A (D + S) tints it with the albedo, which the paper's figures keep.
    bool physical = v->composite == RS_COMPOSITE_PHYSICAL || (v->composite == RS_COMPOSITE_DEFAULT && f->env_on);
    glUniform1i(rs_uloc(prog, "u_physical"), physical ? 1 : 0);
    glUniform1f(rs_uloc(prog, "u_exposure"), v->exposure);
    glUniform1f(rs_uloc(prog, "u_linear_output"), v->linear_output ? 1.0f : 0.0f);
    // The background is given in sRGB; linear output shows it linear too.
    float bg[3];
    for (int c = 0; c < 3; c++) {
        float b = RS_CLAMP(v->background[c], 0.0f, 1.0f);
        bg[c] = v->linear_output ? rs_srgb_to_linear(b) : b;
    }
    glUniform3fv(rs_uloc(prog, "u_background"), 1, bg);
    glUniform1f(rs_uloc(prog, "u_rho_s_scale"), v->rho_s_scale / RS_RHO_S_PHYSICAL);  // relative to physical
    glUniform1f(rs_uloc(prog, "u_diffuse_scale"), r->float_rt ? 1.0f : 1.0f / RS_DIFFUSE_SCALE_RGBA8);
    glUniform3fv(rs_uloc(prog, "u_delta_weight"), 1, f->delta_weight);
    glUniform3fv(rs_uloc(prog, "u_key_dir"), 1, f->key_dir);
    glUniform3fv(rs_uloc(prog, "u_key_color"), 1, f->key_color);
    glUniform3fv(rs_uloc(prog, "u_fill_dir"), 1, f->fill_dir);
    glUniform3fv(rs_uloc(prog, "u_fill_color"), 1, f->fill_color);
    glUniform3fv(rs_uloc(prog, "u_ambient"), 1, f->ambient);
    // RGBA8 fallback: a sum of a few 8-bit steps is a faint disk rim rounded to garbage colours; such
    // pixels are filled from their neighbours like holes.
    glUniform1f(rs_uloc(prog, "u_min_weight"), r->float_rt ? 0.0f : RS_MIN_WEIGHT_RGBA8);
    glUniform1f(rs_uloc(prog, "u_bent_scale"), r->float_rt ? RS_ATTR_WEIGHT_SCALE_RGBA8 : 1.0f);
    rs_render_shadow_uniforms(r, f, prog);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
    for (int i = 0; i < RS_ATTR_TARGETS; i++) rs_render_bind_texture(RS_UNIT_ATTR0 + i, r->attr_tex[i]);
    rs_render_bind_texture(RS_UNIT_DIFFUSE, f->diffuse ? r->diffuse_tex : 0);
    rs_render_bind_texture(RS_UNIT_REFLECT, f->env_on ? r->reflect_tex : 0);
    glActiveTexture(GL_TEXTURE0 + RS_UNIT_BODY);
    glBindTexture(GL_TEXTURE_3D, f->env_on && !f->mobile ? r->body_tex : 0);
    glUniform1f(rs_uloc(prog, "u_body_on"), f->env_on && !f->mobile ? 1.0f : 0.0f);
    // The walls a hollow's bounce reads (composite.frag.glsl surround_seen). None on mobile: its bounce keeps
    // the face's mean light (8 samples cost llvmpipe ~5 ms of a 512^2 frame, the environment's budget there
    // being ~15 %, issue 12; docs/mobile.md).
    glUniform1i(rs_uloc(prog, "u_surround_samples"), f->mobile ? 0 : 16);
    rs_render_fine_uniforms(r, f, prog);
    glBindVertexArray(r->vao_empty);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    // Unbind what later passes render into (a bound sampler on an attached texture is a feedback loop).
    for (int i = RS_UNIT_DEPTH; i <= RS_UNIT_FINE_INDEX; i++) rs_render_bind_texture(i, 0);
    rs_render_bind_texture(RS_UNIT_REFLECT, 0);
    glActiveTexture(GL_TEXTURE0 + RS_UNIT_BODY);
    glBindTexture(GL_TEXTURE_3D, 0);
    rs_render_fine_unbind();
    return RS_OK;
}

rs_result rs_render_edges(rs_renderer *r, const rs_frame *f, rs_error *err)
{
    GLuint find, blend;
    rs_result res = rs_render_program(r, RS_PROG_EDGES_FIND, false, &find, err);
    if (res == RS_OK) res = rs_render_program(r, RS_PROG_EDGES, false, &blend, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    glViewport(0, 0, cam->width, cam->height);
    glDisable(GL_BLEND);
    glBindVertexArray(r->vao_empty);
    // The steps, the picture copied to the output, and the mask: depth 0 on a step, 1 elsewhere.
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_edges);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDepthMask(GL_TRUE);
    glUseProgram(find);
    glUniformMatrix4fv(rs_uloc(find, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
    glUniform2f(rs_uloc(find, "u_viewport"), (float)cam->width, (float)cam->height);
    glUniform1f(rs_uloc(find, "u_eps"), f->eps);
    // Half a millimetre: the lip line's step, the smallest contour that draws a staircase.
    glUniform1f(rs_uloc(find, "u_step_min"), 0.5f / RS_MAX(r->cloud->hdr.mm_per_unit, 1e-6f));
    glUniform1i(rs_uloc(find, "u_enabled"), edges_on(f) ? 1 : 0);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
    rs_render_bind_texture(RS_UNIT_COLOR, r->pre_tex);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    // The mixing, only where the mask is nearer than the triangle (depth 0.5): early depth tests skip the
    // rest of the picture, which was copied.
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_out);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_FALSE);
    glUseProgram(blend);
    glUniform1f(rs_uloc(blend, "u_linear_output"), f->view.linear_output ? 1.0f : 0.0f);
    rs_render_bind_texture(RS_UNIT_EDGES, r->out_steps_tex[1]);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);  // GL's default, as the caller may expect it
    rs_render_bind_texture(RS_UNIT_DEPTH, 0);
    rs_render_bind_texture(RS_UNIT_PUSH, 0);
    rs_render_bind_texture(RS_UNIT_COLOR, 0);
    rs_render_bind_texture(RS_UNIT_EDGES, 0);
    return RS_OK;
}
