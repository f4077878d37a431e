// render_shadow.c — stage 1, the shadow maps (paper Fig. 2): the splats' depth seen from the key light,
// an orthographic frustum fitted to the cloud's bounding sphere, drawn with the visibility pass's ray-disk
// shader (no push). Lookups (shaders_es/shadow_lookup.glsl) compare each PCF tap against the receiver's
// own plane (receiver-plane depth bias, no normal offset) on a turned 4x4 grid of hardware 2x2 PCF. The
// map only depends on the light and the LOD, so it is cached across camera moves, one per pipeline (the
// mobile one at half the resolution, from the mobile LOD prefix). Under an environment its other compact
// lamps (render_env.c find_lamps) get a map each too, smaller and from a coarser LOD prefix (they are
// soft sources and their shadows matter less than the key's): the layers of one depth array, cached per
// lamp and shared by both pipelines.
#include "render/render_stages.h"

#include <math.h>
#include <string.h>

// Reference: up to 4096^2, texels of 0.14 mm on the bundled bust (bounding sphere 6.2 units, 47 mm/unit).
// An occluder's edge in the map is quantised to texels, which moves its shadow's edge by up to half a
// texel / cos(theta) on the receiver: 0.29 mm at 60 degrees with 2048^2 (over the 0.3 mm the edge may be
// off), 0.14 mm with 4096^2 (tests/test_shadow.c). Mobile: up to 2048^2 (RS_SHADOW_SIZE_MOBILE), texels
// of 0.28 mm, below the PCF penumbra (~2 mm). A smaller picture needs fewer: a map texel no larger than a
// pixel at the nearest point of the bounding sphere (which the map spans) keeps its quantisation within
// a pixel wherever the face is. At the default 512^2 view that asks for 2400 texels, so both pipelines
// keep their caps from there up (the viewer, the figures, every close-up); a 256^2 picture draws a
// quarter of the reference's texels (the map pass's cost is its texels), a 48^2 one a sixteenth of the
// mobile's, and both pipelines get the same map where both caps allow (a 256^2 comparison of the two
// measures their diffusion, not their maps: test_mobile's K = 3 edge test). The lamps' layers, soft
// sources: half that, up to 1024^2.
static int map_size(const rs_renderer *r, const rs_frame *f, float texels_per_px, int lo, int hi)
{
    float need = 2.02f * r->bound_radius * f->cam.ppu_max * texels_per_px;  // the ortho range is 2.02 R
    int size = lo;
    while ((float)size < need && size < hi) size *= 2;
    return RS_MIN(size, r->caps.max_texture_size);
}

// Deletes a map's framebuffer and depth texture (either may be 0).
static void drop_depth(GLuint *fbo, GLuint *tex)
{
    glDeleteFramebuffers(1, fbo);
    glDeleteTextures(1, tex);
    *fbo = *tex = 0;
}

void rs_render_shadow_release(rs_renderer *r)
{
    for (int i = 0; i < 2; i++) {
        drop_depth(&r->shadow[i].fbo, &r->shadow[i].tex);
        memset(&r->shadow[i], 0, sizeof r->shadow[i]);
    }
    drop_depth(&r->lamp_shadow.fbo, &r->lamp_shadow.tex);
    memset(&r->lamp_shadow, 0, sizeof r->lamp_shadow);
}

static void depth_compare(GLenum target)
{
    // Hardware PCF: compare mode + linear filtering gives a bilinear 2x2 comparison per lookup.
    glTexParameteri(target, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(target, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

// A depth-only framebuffer (bound, its depth attached): no colour buffers; checked, unbound; on failure
// the framebuffer and texture are deleted.
static rs_result finish_depth_fbo(GLuint *fbo, GLuint *tex, const char *what, rs_error *err)
{
    GLenum none = GL_NONE;
    glDrawBuffers(1, &none);
    glReadBuffer(GL_NONE);
    rs_result res = rs_render_fbo_check(what, err);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (res != RS_OK) drop_depth(fbo, tex);
    return res;
}

// The key's map of side `size` (a new one when the size changes: the old drawing is dropped with it).
static rs_result ensure_map(rs_shadow_map *m, int size, rs_error *err)
{
    if (m->tex && m->size == size) return RS_OK;
    drop_depth(&m->fbo, &m->tex);
    memset(m, 0, sizeof *m);
    m->tex = rs_render_texture(GL_DEPTH_COMPONENT32F, size, size);
    depth_compare(GL_TEXTURE_2D);
    glGenFramebuffers(1, &m->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, m->fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, m->tex, 0);
    char what[64];
    snprintf(what, sizeof what, "shadow map (DEPTH_COMPONENT32F %dx%d)", size, size);
    rs_result res = finish_depth_fbo(&m->fbo, &m->tex, what, err);
    if (res != RS_OK) {
        memset(m, 0, sizeof *m);
        return res;
    }
    m->size = size;
    return RS_OK;
}

// The lamps' depth array (a layer each) and the framebuffer their layers are attached to in turn.
static rs_result ensure_lamp_maps(rs_renderer *r, int size, rs_error *err)
{
    rs_lamp_shadows *l = &r->lamp_shadow;
    if (l->tex && l->size == size) return RS_OK;
    drop_depth(&l->fbo, &l->tex);
    memset(l, 0, sizeof *l);
    glGenTextures(1, &l->tex);
    glBindTexture(GL_TEXTURE_2D_ARRAY, l->tex);
    glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_DEPTH_COMPONENT32F, size, size, RS_ENV_LAMPS);
    depth_compare(GL_TEXTURE_2D_ARRAY);
    glBindTexture(GL_TEXTURE_2D_ARRAY, 0);
    glGenFramebuffers(1, &l->fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, l->fbo);
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, l->tex, 0, 0);
    char what[80];
    snprintf(what, sizeof what, "lamp shadow maps (DEPTH_COMPONENT32F %dx%dx%d)", size, size, RS_ENV_LAMPS);
    rs_result res = finish_depth_fbo(&l->fbo, &l->tex, what, err);
    if (res != RS_OK) {
        memset(l, 0, sizeof *l);
        return res;
    }
    l->size = size;
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

// The splats' depth from the light (view, proj) into the bound framebuffer's size x size depth.
static rs_result draw_map(rs_renderer *r, const rs_frame *f, int size, const mat4 view, const mat4 proj,
                          uint32_t count, float scale, rs_error *err)
{
    GLuint prog;
    mat4 inv_proj;
    glm_mat4_inv((vec4 *)proj, inv_proj);
    // Instanced quads, each in its disk's plane (visibility.vert.glsl RS_SHADOW: rasterised depth, early
    // depth test; ~7x cheaper on llvmpipe, the same map to rounding), unless points are asked for.
    bool quads = f->view.prim != RS_PRIM_POINTS;
    rs_result res = rs_render_program(r, RS_PROG_SHADOW, quads, &prog, err);
    if (res != RS_OK) return res;
    glViewport(0, 0, size, size);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glUseProgram(prog);
    // Splats facing well away from the light are behind its front surface anyway.
    rs_render_splat_uniforms(prog, view, proj, inv_proj, size, size, false, scale, -0.3f, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_eps"), 0.0f);
    rs_render_draw_splats(r, count, quads);
    return RS_OK;
}

// Depth bias in window units for a map of `size` texels drawn with splats of typical radius `radius`.
// A disk departs from the surface it samples by ~r^2 / 2R at its rim (curvature radius R ~ 0.3 of the
// face height on cheeks and nose) plus r sin(3 deg) from normal noise: ~0.15 r on the bundled head (no
// acne at 0.15 r on the test sphere or the cheek under grazing light); 0.5 r keeps a margin for the
// normal map's tilts, and moves only contact shadows, by bias x tan(theta). A texel of quantisation on
// top. The ortho range is 2.02 R. The slope is the receiver plane's, per PCF tap (shadow_lookup.glsl):
// no normal offset.
static float depth_bias(const rs_renderer *r, float radius, int size)
{
    float R = r->bound_radius;
    return (0.5f * radius + 2.0f * R / (float)size) / (2.02f * R);
}

// view -> light clip (vp: model -> light clip) and the inverse transpose of its linear part (normals).
static void lookup_matrices(const rs_frame *f, const mat4 vp, mat4 out, mat3 normals)
{
    glm_mat4_mul((vec4 *)vp, (vec4 *)f->cam.inv_view, out);
    mat3 a, inv;
    glm_mat4_pick3(out, a);
    glm_mat3_inv(a, inv);
    glm_mat3_transpose_to(inv, normals);
}

// The environment's other lamps: a map each (cached: redrawn when its direction, in model space, or the
// prefix changes), and their lookups' matrices for the frame. One LOD prefix for both pipelines (at most
// RS_LAMP_SHADOW_SPLATS, within the view's cap), so the pipelines share the maps and agree on them.
static rs_result lamp_shadows(rs_renderer *r, rs_frame *f, rs_error *err)
{
    rs_result res = ensure_lamp_maps(r, map_size(r, f, 0.5f, 256, RS_LAMP_SHADOW_SIZE), err);
    if (res != RS_OK) return res;
    rs_lamp_shadows *l = &r->lamp_shadow;
    const rs_splat_cloud *c = r->cloud;
    uint32_t cap = f->view.max_splats > 0 ? RS_MIN(f->view.max_splats, c->hdr.count) : c->hdr.count;
    uint32_t count = rs_splat_lod_count(c, RS_MIN(cap, (uint32_t)RS_LAMP_SHADOW_SPLATS));
    float scale = rs_splat_lod_radius_scale(c, count);
    l->radius = r->radius_median * scale;
    mat3 view_from_env, inv_rot;
    glm_mat3_transpose_to(f->env_from_view, view_from_env);
    glm_mat4_pick3(f->cam.inv_view, inv_rot);
    for (int k = 0; k < RS_ENV_LAMPS; k++) {
        const float *col = r->env.lamp_color[k];
        f->lamp_shadow_on[k] = 0.0f;
        if (!(col[0] > 0 || col[1] > 0 || col[2] > 0)) continue;  // unused: no light, no map
        vec3 L;
        glm_mat3_mulv(view_from_env, (float *)r->env.lamp_dir[k], f->lamp_shadow_dir[k]);
        glm_vec3_normalize(f->lamp_shadow_dir[k]);
        glm_mat3_mulv(inv_rot, f->lamp_shadow_dir[k], L);
        glm_vec3_normalize(L);
        float key[6] = {L[0], L[1], L[2], (float)count, scale, 1.0f};
        bool cached = true;
        for (int i = 0; i < 6; i++) cached = cached && fabsf(key[i] - l->key[k][i]) < 1e-6f;
        mat4 view, proj;
        light_matrices(r, L, view, proj);
        glm_mat4_mul(proj, view, l->vp[k]);
        if (!cached) {
            glBindFramebuffer(GL_FRAMEBUFFER, l->fbo);
            glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, l->tex, 0, k);
            res = draw_map(r, f, l->size, view, proj, count, scale, err);
            r->light_serial++;  // the splats' irradiance reads the maps
            if (res != RS_OK) {
                memset(l->key[k], 0, sizeof l->key[k]);
                return res;
            }
            memcpy(l->key[k], key, sizeof key);
        }
        lookup_matrices(f, l->vp[k], f->lamp_shadow_matrix[k], f->lamp_shadow_normals[k]);
        f->lamp_shadow_on[k] = 1.0f;
    }
    f->lamp_shadow_bias = depth_bias(r, l->radius, l->size);
    f->lamp_shadows = true;
    return RS_OK;
}

rs_result rs_render_shadow(rs_renderer *r, rs_frame *f, rs_error *err)
{
    rs_shadow_map *m = &r->shadow[f->shadow_slot];
    int cap = f->mobile ? RS_SHADOW_SIZE_MOBILE : RS_SHADOW_SIZE_REFERENCE;
    rs_result res = ensure_map(m, map_size(r, f, 1.0f, 512, cap), err);
    if (res != RS_OK) return res;
    // The key light direction back in model space.
    vec3 L;
    mat3 inv_rot;
    glm_mat4_pick3(f->cam.inv_view, inv_rot);
    glm_mat3_mulv(inv_rot, f->key_dir, L);
    glm_vec3_normalize(L);
    uint32_t count = f->count;
    float scale = f->radius_scale;
    float key[6] = {L[0], L[1], L[2], (float)count, scale, 1.0f};
    bool cached = true;
    for (int i = 0; i < 6; i++) cached = cached && fabsf(key[i] - m->key[i]) < 1e-6f;

    mat4 view, proj;
    light_matrices(r, L, view, proj);
    glm_mat4_mul(proj, view, m->vp);
    if (!cached) {
        glBindFramebuffer(GL_FRAMEBUFFER, m->fbo);
        res = draw_map(r, f, m->size, view, proj, count, scale, err);
        r->light_serial++;  // the splats' irradiance reads the map
        if (res != RS_OK) return res;
        memcpy(m->key, key, sizeof key);
        m->radius = r->radius_median * scale;
    }
    // Lookups come from view space: view -> model -> light clip; normals by the inverse transpose.
    lookup_matrices(f, m->vp, f->shadow_matrix, f->shadow_normals);
    // The filter is sized in texels of a 2048^2 map whatever this map's size, so that every pipeline
    // gives the same penumbra (the taps are 3 texels apart in the reference's map, 1.5 in the mobile's;
    // the turned grid keeps the former smooth); the bias's texel terms follow the map's own texels.
    f->shadow_texel = 1.0f / (float)RS_SHADOW_SIZE_PCF;
    f->shadow_bias = depth_bias(r, m->radius, m->size);
    if (f->env_on) res = lamp_shadows(r, f, err);
    if (res != RS_OK) return res;
    return rs_gl_check("render: shadow maps", err);
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
    // The lamps' maps (layers of one depth array).
    bool lamps = f->lamp_shadows && r->lamp_shadow.tex;
    glActiveTexture(GL_TEXTURE0 + RS_UNIT_LAMP_SHADOW);
    glBindTexture(GL_TEXTURE_2D_ARRAY, lamps ? r->lamp_shadow.tex : 0);
    float on[RS_ENV_LAMPS] = {0};
    for (int k = 0; lamps && k < RS_ENV_LAMPS; k++) on[k] = f->lamp_shadow_on[k];
    glUniform1fv(rs_uloc(prog, "u_lamp_shadow_on"), RS_ENV_LAMPS, on);
    glUniformMatrix4fv(rs_uloc(prog, "u_lamp_shadow_matrix"), RS_ENV_LAMPS, GL_FALSE,
                       (const float *)f->lamp_shadow_matrix);
    glUniformMatrix3fv(rs_uloc(prog, "u_lamp_shadow_normals"), RS_ENV_LAMPS, GL_FALSE,
                       (const float *)f->lamp_shadow_normals);
    glUniform3fv(rs_uloc(prog, "u_lamp_shadow_dir"), RS_ENV_LAMPS, (const float *)f->lamp_shadow_dir);
    glUniform1f(rs_uloc(prog, "u_lamp_shadow_bias"), f->lamp_shadow_bias);
    glUniform1f(rs_uloc(prog, "u_lamp_shadow_texel"), 1.0f / (float)RS_MAX(r->lamp_shadow.size, 1));
}
