// render_diffusion.c — stage 4, splat-based diffusion (Kim et al. 2010; paper Fig. 2): subsurface scattering
// in object space. For each Gaussian of the skin profile (d'Eon & Luebke's six, METHOD.md), every splat's
// irradiance E_j (key N.L with its shadow-map visibility, fill N.L, ambient) is spread with an isotropic 3D
// Gaussian of that width (mm, through the model's mm_per_unit) and evaluated at each pixel's visible
// surface point P. The level image is a normalised convolution,
//   D_i(P) = sum_j E_j a_j G(v_j, |P - c_j|) / sum_j a_j G(v_j, |P - c_j|),  a_j = splat area,
// accumulated as (E w, w) and divided in a resolve pass that adds w_i(rgb) D_i into D (D = sum_i w_i D_i;
// each channel's weights sum to 1, so D conserves energy). Measuring in 3D keeps light from crossing to the
// far side of the head; normalising makes D independent of the sampling density and of the LOD.
//
// A kernel can't resolve below the sample spacing or a pixel: v_j = max(sigma_i, r_j / 2, pixel / 2)^2,
// so narrow levels become a smooth interpolation of E instead of speckles. Gaussians narrower than half
// that floor (typically: half a sample spacing) are closer to no blur than to the floor's: they are not
// drawn but taken as the per-pixel irradiance (normal interpolated by stage 3, shadow by PCF) in the
// composite, the sigma -> 0 limit (as Jimenez et al. use the unblurred image for d'Eon's narrowest
// Gaussian). Levels at or below the floor for every splat give identical images and are drawn once
// with their weights summed. Wide levels draw a coarser LOD prefix whose typical radius stays within
// lod_factor * sigma_i of the kernel (reference: 1.25, quality first), which bounds their overdraw at
// ~pi (3 sigma)^2 / spacing^2.
//
// The level loop is generic over rs_diffusion_level: the mobile pipeline (issue 5) plugs in its K fitted
// Gaussians (rs_profile_fit) and a larger lod_factor.
//
// RGBA8 fallback (no float targets): E is scaled by 1 / (its largest possible value) and the weights by
// 1/4 (their sum is ~ (r / spacing)^2 ~ 1.7 by construction) so the level sums stay below 1; D is stored
// halved; wide levels use the mobile LOD factor (fewer, larger contributions lose less to 8-bit
// rounding); the resolve clamps E to its possible range, and a pixel whose level weight is under 16
// steps (reached only by kernels' faint tails) borrows its 3x3 neighbours' sums. Coarser, but it runs.
#include "render/render_internal.h"

#include <math.h>
#include <string.h>

// Reference: a level may use a coarser prefix while its typical splat radius stays below 1.25 sigma (the
// spacing, ~0.75 radius, below sigma: the normalised sum is then smooth).
#define LOD_FACTOR_REFERENCE 1.25f
#define LOD_FACTOR_MOBILE 2.0f
#define FALLBACK_WEIGHT_SCALE 0.25f

// The coarsest LOD prefix (at most the main passes' count) whose typical radius is <= factor * sigma.
static uint32_t level_count(const rs_renderer *r, const rs_frame *f, float sigma, float factor)
{
    const rs_splat_header *h = &r->cloud->hdr;
    for (int k = (int)h->lod_count - 1; k >= 0; k--) {
        uint32_t n = h->lods[k];
        if (n > f->count) continue;
        if (r->radius_median * rs_splat_lod_radius_scale(r->cloud, n) <= factor * sigma) return n;
    }
    return f->count;
}

// The profile the frame's pipeline draws: d'Eon's six (reference) or a K-Gaussian fit (mobile).
static void frame_profile(rs_renderer *r, const rs_frame *f, rs_profile *out, float *lod_factor)
{
    *out = rs_profile_deon();
    // Without float targets, fewer and larger contributions round better in 8 bits.
    *lod_factor = r->float_rt ? LOD_FACTOR_REFERENCE : LOD_FACTOR_MOBILE;
    if (f->view.pipeline != RS_PIPELINE_MOBILE) return;
    int k = f->view.kernel_count > 0 ? f->view.kernel_count : RS_PROFILE_DEFAULT_COUNT;
    k = RS_CLAMP(k, RS_PROFILE_FIT_MIN, RS_PROFILE_FIT_MAX);
    // Fit at the half-pixel footprint (mm) at the face centre, cached: a fit costs ~1 ms.
    float dist = glm_vec3_distance((float *)f->cam.eye, (float *)r->cloud->hdr.centre);
    float footprint = 0.5f * f->cam.px_size * dist * r->cloud->hdr.mm_per_unit;
    if (r->fit_k != k || fabsf(r->fit_footprint - footprint) > 0.1f * footprint) {
        rs_profile fit;
        if (rs_profile_fit(k, footprint, &fit, NULL, NULL) != RS_OK) return;
        r->fit = fit;
        r->fit_k = k;
        r->fit_footprint = footprint;
    }
    *out = r->fit;
    *lod_factor = LOD_FACTOR_MOBILE;
}

int rs_render_diffusion_plan(rs_renderer *r, const rs_frame *f, rs_diffusion_level levels[RS_PROFILE_MAX],
                             float delta_weight[3])
{
    const rs_splat_header *h = &r->cloud->hdr;
    rs_profile prof;
    float lod_factor;
    frame_profile(r, f, &prof, &lod_factor);
    // No splat's kernel is narrower than this (half the smallest radius, half the nearest pixel).
    float floor_sigma = 0.5f * fmaxf(h->radius_min * f->radius_scale, 1.0f / f->cam.ppu_max);
    // The typical floor: half the median radius or half a pixel at the face.
    float dist = glm_vec3_distance((float *)f->cam.eye, (float *)h->centre);
    float typical_floor = 0.5f * fmaxf(r->radius_median * f->radius_scale, f->cam.px_size * dist);
    delta_weight[0] = delta_weight[1] = delta_weight[2] = 0.0f;
    int n = 0;
    for (int i = 0; i < prof.count; i++) {
        float sigma = sqrtf(prof.variance_mm2[i]) / h->mm_per_unit;
        if (sigma <= 0.5f * typical_floor) {
            for (int c = 0; c < 3; c++) delta_weight[c] += prof.weight[i][c];
            continue;
        }
        if (n > 0 && sigma <= floor_sigma && levels[n - 1].sigma <= floor_sigma) {
            for (int c = 0; c < 3; c++) levels[n - 1].weight[c] += prof.weight[i][c];
            levels[n - 1].sigma = sigma;
            continue;
        }
        rs_diffusion_level *l = &levels[n++];
        l->sigma = sigma;
        for (int c = 0; c < 3; c++) l->weight[c] = prof.weight[i][c];
        l->count = sigma <= floor_sigma ? f->count : level_count(r, f, sigma, lod_factor);
        float rmax = h->radius_max * rs_splat_lod_radius_scale(r->cloud, l->count);
        float reach = 3.0f * fmaxf(sigma, 0.5f * rmax);
        l->quads = f->view.prim == RS_PRIM_QUADS ||
                   (f->view.prim == RS_PRIM_AUTO && rs_render_needs_quads(r, f, reach));
    }
    return n;
}

static rs_result draw_level(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *l, float e_scale,
                            rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_DIFFUSION, l->quads, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_level);
    const GLfloat zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glUseProgram(prog);
    // No threshold culling here: the shader drops only back-facing splats hidden deep behind the surface.
    rs_render_splat_uniforms(prog, cam->view, cam->proj, cam->inv_proj, cam->width, cam->height, true,
                             rs_splat_lod_radius_scale(r->cloud, l->count), -2.0f, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_sigma"), l->sigma);
    glUniform1f(rs_uloc(prog, "u_px_size"), cam->px_size);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform2f(rs_uloc(prog, "u_acc_scale"), e_scale, r->float_rt ? 1.0f : FALLBACK_WEIGHT_SCALE);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_draw_splats(r, l->count, l->quads);
    return RS_OK;
}

// Per-splat irradiance and "behind the visible surface" distance for the frame's first `count` splats
// (every level draws a prefix of those), by transform feedback: the shadow-map PCF runs once per splat
// instead of once per splat and level.
static rs_result irradiance_pass(rs_renderer *r, const rs_frame *f, rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_IRRADIANCE, false, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    glUseProgram(prog);
    glUniformMatrix4fv(rs_uloc(prog, "u_view"), 1, GL_FALSE, (const float *)cam->view);
    glUniformMatrix4fv(rs_uloc(prog, "u_proj"), 1, GL_FALSE, (const float *)cam->proj);
    glUniformMatrix4fv(rs_uloc(prog, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
    glUniform2f(rs_uloc(prog, "u_viewport"), (float)cam->width, (float)cam->height);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform3fv(rs_uloc(prog, "u_key_dir"), 1, f->key_dir);
    glUniform3fv(rs_uloc(prog, "u_key_color"), 1, f->key_color);
    glUniform3fv(rs_uloc(prog, "u_fill_dir"), 1, f->fill_dir);
    glUniform3fv(rs_uloc(prog, "u_fill_color"), 1, f->fill_color);
    glUniform3fv(rs_uloc(prog, "u_ambient"), 1, f->ambient);
    rs_render_shadow_uniforms(r, f, prog);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    glBindVertexArray(r->vao_feedback);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, r->vbo_irradiance);
    glEnable(GL_RASTERIZER_DISCARD);
    glBeginTransformFeedback(GL_POINTS);
    glDrawArrays(GL_POINTS, 0, (GLsizei)f->count);
    glEndTransformFeedback();
    glDisable(GL_RASTERIZER_DISCARD);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
    return rs_gl_check("render: irradiance pass", err);
}

rs_result rs_render_diffusion(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *levels, int count,
                              rs_error *err)
{
    if (count > 0) {
        rs_result res = irradiance_pass(r, f, err);
        if (res != RS_OK) return res;
    }
    const rs_camera *cam = &f->cam;
    GLuint resolve;
    rs_result res = rs_render_program(r, RS_PROG_RESOLVE, false, &resolve, err);
    if (res != RS_OK) return res;
    glViewport(0, 0, cam->width, cam->height);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_diffuse);
    const GLfloat zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);

    // Fallback: E over its largest possible value, so E w stays below w.
    float e_scale = 1.0f, d_scale = 1.0f;
    if (!r->float_rt) {
        float emax = 1e-6f;
        for (int c = 0; c < 3; c++) emax = fmaxf(emax, f->key_color[c] + f->fill_color[c] + f->ambient[c]);
        e_scale = 1.0f / emax;
        d_scale = RS_DIFFUSE_SCALE_RGBA8;
    }
    uint32_t drawn = 0;
    memset(r->stats.level_ms, 0, sizeof r->stats.level_ms);
    for (int i = 0; i < count; i++) {
        double t0 = r->time_stages ? rs_time_now() : 0.0;
        res = draw_level(r, f, &levels[i], e_scale, err);
        if (res != RS_OK) break;
        drawn += levels[i].count;
        glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_diffuse);
        glUseProgram(resolve);
        glUniform3fv(rs_uloc(resolve, "u_weight"), 1, levels[i].weight);
        glUniform1f(rs_uloc(resolve, "u_scale"), d_scale / e_scale);
        glUniform1f(rs_uloc(resolve, "u_e_max"), r->float_rt ? 1e30f : 1.0f);
        // A level's weights sum to ~0.4 (100 steps) where sampled; under 16 steps, rounding dominates.
        glUniform1f(rs_uloc(resolve, "u_min_weight"), r->float_rt ? 0.0f : 16.0f / 255.0f);
        rs_render_bind_texture(RS_UNIT_LEVEL, r->level_tex);
        glBindVertexArray(r->vao_empty);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        if (r->time_stages && i < (int)RS_COUNT_OF(r->stats.level_ms)) {
            glFinish();
            r->stats.level_ms[i] = (rs_time_now() - t0) * 1000.0;
        }
    }
    rs_render_bind_texture(RS_UNIT_LEVEL, 0);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    r->stats.diffusion_splats = drawn;
    return res;
}
