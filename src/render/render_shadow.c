// render_shadow.c — stage 1, the shadow map (paper Fig. 2): the splats' depth seen from the key light,
// an orthographic frustum fitted to the cloud's bounding sphere, drawn with the visibility pass's ray-disk
// shader (no push). Lookups (shaders_es/shadow_lookup.glsl) compare each PCF tap against the receiver's
// own plane (receiver-plane depth bias, no normal offset) on a turned 4x4 grid of hardware 2x2 PCF. The
// map only depends on the light and the LOD, so it is cached across camera moves, one per pipeline (the
// mobile one at a quarter of the resolution, from the mobile LOD prefix).
#include "render/render_stages.h"

#include <math.h>
#include <string.h>

// Reference: 4096^2, texels of 0.14 mm on the bundled bust (bounding sphere 6.2 units, 47 mm/unit). An
// occluder's edge in the map is quantised to texels, which moves its shadow's edge by up to half a texel
// / cos(theta) on the receiver: 0.29 mm at 60 degrees with 2048^2 (over the 0.3 mm the edge may be off),
// 0.14 mm with 4096^2 (tests/test_shadow.c). Mobile: 1024^2 (RS_SHADOW_SIZE_MOBILE), texels of 0.57 mm,
// still below the PCF penumbra (~2 mm); its edges are within 0.6 mm.

void rs_render_shadow_release(rs_renderer *r)
{
    for (int i = 0; i < 2; i++) {
        rs_shadow_map *m = &r->shadow[i];
        glDeleteFramebuffers(1, &m->fbo);
        glDeleteTextures(1, &m->tex);
        memset(m, 0, sizeof *m);
    }
}

static rs_result ensure_map(rs_renderer *r, rs_shadow_map *m, int want, rs_error *err)
{
    if (m->tex) return RS_OK;
    int size = RS_MIN(want, r->caps.max_texture_size);
    m->tex = rs_render_texture(GL_DEPTH_COMPONENT32F, size, size);
    // Hardware PCF: compare mode + linear filtering gives a bilinear 2x2 comparison per lookup.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glGenFramebuffers(1, &m->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, m->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, m->tex, 0);
    GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
    glReadBuffer(GL_NONE);
    char what[64];
    snprintf(what, sizeof what, "shadow map (DEPTH_COMPONENT32F %dx%d)", size, size);
    rs_result res = rs_render_fbo_check(what, err);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (res != RS_OK) {
        glDeleteFramebuffers(1, &m->fbo);
        glDeleteTextures(1, &m->tex);
        memset(m, 0, sizeof *m);
        return res;
    }
    m->size = size;
    return RS_OK;
}

// Light view and orthographic projection around the cloud's bounding sphere; L points towards the light.
static void light_matrices(const rs_renderer *r, const vec3 L, mat4 view, mat4 proj)
{
    vec3 c = {r->bound_centre[0], r->bound_centre[1], r->bound_centre[2]}, eye, up = {0, 1, 0};
    float R = r->bound_radius;
    for (int a = 0; a < 3; a++) eye[a] = c[a] + L[a] * 2.0f * R;
    const float *fu = r->cloud->hdr.up;
    glm_vec3_copy((float *)fu, up);
    if (fabsf(glm_vec3_dot(up, (float *)L)) > 0.95f) glm_vec3_copy((float *)r->cloud->hdr.forward, up);
    glm_lookat(eye, c, up, view);
    glm_ortho(-R, R, -R, R, R * 0.99f, R * 3.01f, proj);
}

rs_result rs_render_shadow(rs_renderer *r, rs_frame *f, rs_error *err)
{
    rs_shadow_map *m = &r->shadow[f->shadow_slot];
    rs_result res = ensure_map(r, m, f->mobile ? RS_SHADOW_SIZE_MOBILE : RS_SHADOW_SIZE_REFERENCE, err);
    if (res != RS_OK) return res;
    // The key light direction back in model space.
    vec3 L;
    mat3 inv_rot;
    glm_mat4_pick3(f->cam.inv_view, inv_rot);
    glm_mat3_mulv(inv_rot, f->key_dir, L);
    glm_vec3_normalize(L);
    uint32_t count = f->count;
    float scale = f->radius_scale;
    float R = r->bound_radius;
    float key[6] = {L[0], L[1], L[2], (float)count, scale, 1.0f};
    bool cached = true;
    for (int i = 0; i < 6; i++) cached = cached && fabsf(key[i] - m->key[i]) < 1e-6f;

    mat4 view, proj, inv_proj;
    light_matrices(r, L, view, proj);
    glm_mat4_inv(proj, inv_proj);
    glm_mat4_mul(proj, view, m->vp);
    if (!cached) {
        // Instanced quads, each in its disk's plane (visibility.vert.glsl RS_SHADOW: rasterised depth, early
        // depth test; ~7x cheaper on llvmpipe, the same map to rounding), unless points are asked for.
        GLuint prog;
        bool quads = f->view.prim != RS_PRIM_POINTS;
        res = rs_render_program(r, RS_PROG_SHADOW, quads, &prog, err);
        if (res != RS_OK) return res;
        glBindFramebuffer(GL_FRAMEBUFFER, m->fbo);
        glViewport(0, 0, m->size, m->size);
        glDisable(GL_BLEND);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glClear(GL_DEPTH_BUFFER_BIT);
        glUseProgram(prog);
        // Splats facing well away from the light are behind its front surface anyway.
        rs_render_splat_uniforms(prog, view, proj, inv_proj, m->size, m->size, false, scale, -0.3f,
                                 r->caps.point_size_max);
        glUniform1f(rs_uloc(prog, "u_eps"), 0.0f);
        rs_render_draw_splats(r, count, quads);
        memcpy(m->key, key, sizeof key);
        m->radius = r->radius_median * scale;
    }
    // Lookups come from view space: view -> model -> light clip.
    glm_mat4_mul(m->vp, f->cam.inv_view, f->shadow_matrix);
    // The filter is sized in texels of a 2048^2 map whatever this map's size, so that every pipeline
    // gives the same penumbra (the taps are 3 texels apart in the reference's map, 0.75 in the mobile's;
    // the turned grid keeps the former smooth); the bias's texel terms follow the map's own texels.
    float texel = 2.0f * R / (float)m->size;
    float texel_pcf = 2.0f * R / (float)RS_SHADOW_SIZE_PCF;
    f->shadow_texel = texel_pcf / (2.0f * R);
    // A disk departs from the surface it samples by ~r^2 / 2R at its rim (curvature radius R ~ 0.3 of
    // the face height on cheeks and nose) plus r sin(3 deg) from normal noise: ~0.15 r on the bundled
    // head (no acne at 0.15 r on the test sphere or the cheek under grazing light); 0.5 r keeps a margin
    // for the normal map's tilts, and moves only contact shadows, by bias x tan(theta). A texel of
    // quantisation on top. Depth bias in window units (the ortho range is 2.02 R). The slope is the
    // receiver plane's, per PCF tap (shadow_lookup.glsl): no normal offset.
    f->shadow_bias = (0.5f * m->radius + texel) / (2.02f * R);
    // Normals into light clip space: the inverse transpose of the view -> light clip map's linear part.
    mat3 a, inv;
    glm_mat4_pick3(f->shadow_matrix, a);
    glm_mat3_inv(a, inv);
    glm_mat3_transpose_to(inv, f->shadow_normals);
    return rs_gl_check("render: shadow map", err);
}

void rs_render_shadow_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog)
{
    GLuint tex = r->shadow[f->shadow_slot].tex;
    rs_render_bind_texture(RS_UNIT_SHADOW, f->shadows ? tex : 0);
    glUniform1f(rs_uloc(prog, "u_shadow_on"), f->shadows && tex ? 1.0f : 0.0f);
    glUniformMatrix4fv(rs_uloc(prog, "u_shadow_matrix"), 1, GL_FALSE, (const float *)f->shadow_matrix);
    glUniform1f(rs_uloc(prog, "u_shadow_texel"), f->shadow_texel);
    glUniform1f(rs_uloc(prog, "u_shadow_map_texel"), 1.0f / (float)RS_MAX(r->shadow[f->shadow_slot].size, 1));
    glUniform1f(rs_uloc(prog, "u_shadow_bias"), f->shadow_bias);
    glUniformMatrix3fv(rs_uloc(prog, "u_shadow_normals"), 1, GL_FALSE, (const float *)f->shadow_normals);
    glUniform3fv(rs_uloc(prog, "u_shadow_dir"), 1, f->key_dir);
}
