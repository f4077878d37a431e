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
// The level loop is generic over rs_diffusion_level. The mobile pipeline (docs/mobile.md) plugs in its K
// fitted Gaussians (rs_profile_fit at the frame's typical kernel floor, cached per K), a larger lod_factor (2),
// takes every Gaussian below the kernel floor as per-pixel irradiance, and draws the levels that remain
// at half or quarter resolution; the resolve upsamples them depth-aware (diffusion_resolve.frag.glsl).
// On the bundled head at 512x512 that leaves one level (sigma ~1.7 mm, the 74k prefix, 128x128).
// Splats no level carries to a visible pixel (the back of the head, off-screen shoulders) skip the
// irradiance pass's shadow lookup (both pipelines; the image is unchanged). The splats' irradiance depends
// on the lights, not on the camera, so it is kept while they hold still (irradiance_pass): an orbit's
// frames draw the levels from the same per-splat E, and each level culls the splats behind the visible
// surface itself (behind_surface.glsl).
//
// RGBA8 fallback (no float targets): E is scaled by 1 / (its largest possible value) and the weights by
// 1/4 (their sum is ~ (r / spacing)^2 ~ 1.7 by construction) so the level sums stay below 1; D is stored
// halved; wide levels use the mobile LOD factor (fewer, larger contributions lose less to 8-bit
// rounding); the resolve clamps E to its possible range, and a pixel whose level weight is under 16
// steps (reached only by kernels' faint tails) borrows its 3x3 neighbours' sums. Coarser, but it runs.
#include "render/render_stages.h"

#include <float.h>
#include <math.h>
#include <string.h>

// Reference: a level may use a coarser prefix while its typical splat radius stays below 1.25 sigma (the
// spacing, ~0.75 radius, below sigma: the normalised sum is then smooth).
#define LOD_FACTOR_REFERENCE 1.25f
#define LOD_FACTOR_MOBILE 2.0f
#define FALLBACK_WEIGHT_SCALE 0.25f
// A Gaussian narrower than this fraction of the typical kernel floor is taken as per-pixel irradiance.
// Reference: half (closer to no blur than to the floor's). Mobile: the whole floor: such a Gaussian would
// be drawn at the floor's width anyway; taken per pixel it gets the attribute pass's smoothing instead
// (sigma 0.45 of the mobile radius, about half the floor). Measured on the fixed views at 512x512: -0.1 dB
// against the reference, -25% frame time (-45% at 1280x720).
#define DELTA_BELOW_REFERENCE 0.5f
#define DELTA_BELOW_MOBILE 1.0f
// Mobile: a level is drawn at 1/2 (1/4) resolution when its kernel sigma spans at least this many pixels
// of the reduced target.
#define RES_MIN_SIGMA 0.5f

// The typical kernel floor of the frame (model units): half the median radius of the main passes' prefix
// or half a pixel at the face, whichever is larger. The mobile fit and the level plan both use it, so the
// Gaussians the fit is made for are the ones the renderer draws (issue 12).
static float typical_floor(const rs_renderer *r, const rs_frame *f)
{
    float lod_scale = rs_splat_lod_radius_scale(r->cloud, f->count);
    float dist = glm_vec3_distance((float *)f->cam.eye, (float *)r->cloud->hdr.centre);
    return 0.5f * fmaxf(r->radius_median * lod_scale, f->cam.px_size * dist);
}

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
    // Fit at the kernel floor (mm) the plan below uses, cached per K while it stays within 10%.
    float footprint = typical_floor(r, f) * r->cloud->hdr.mm_per_unit;
    if (!(fabsf(r->fit_footprint[k] - footprint) <= 0.1f * footprint)) {
        rs_profile fit;
        if (rs_profile_fit(k, footprint, &fit, NULL, NULL) != RS_OK) return;
        r->fit[k] = fit;
        r->fit_footprint[k] = footprint;
    }
    *out = r->fit[k];
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
    // (The kernels' radii are the prefix's sqrt(N / n) ones in both pipelines: they measure the spacing.)
    float lod_scale = rs_splat_lod_radius_scale(r->cloud, f->count);
    float floor_sigma = 0.5f * fmaxf(h->radius_min * lod_scale, 1.0f / f->cam.ppu_max);
    float floor_typ = typical_floor(r, f);
    delta_weight[0] = delta_weight[1] = delta_weight[2] = 0.0f;
    int n = 0;
    for (int i = 0; i < prof.count; i++) {
        float sigma = sqrtf(prof.variance_mm2[i]) / h->mm_per_unit;
        if (sigma <= (f->mobile ? DELTA_BELOW_MOBILE : DELTA_BELOW_REFERENCE) * floor_typ) {
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
        l->res_div = 1;
    }
    for (int i = 0; i < n; i++) {
        rs_diffusion_level *l = &levels[i];
        float scale = rs_splat_lod_radius_scale(r->cloud, l->count);
        if (f->mobile) {
            // Wide levels at half or quarter resolution: the level's kernel (at least half the typical
            // radius of its prefix) spans at least RES_MIN_SIGMA of the reduced target's pixels at the face.
            float sigma_eff = fmaxf(l->sigma, 0.5f * r->radius_median * scale);
            float px = f->cam.px_size * glm_vec3_distance((float *)f->cam.eye, (float *)h->centre);
            while (l->res_div < 4 && sigma_eff >= RES_MIN_SIGMA * px * (float)(2 * l->res_div))
                l->res_div *= 2;
        }
        float rmax = h->radius_max * scale;
        float reach = 3.0f * fmaxf(l->sigma, 0.5f * rmax) / (float)l->res_div;
        l->quads = f->view.prim == RS_PRIM_QUADS ||
                   (f->view.prim == RS_PRIM_AUTO && rs_render_needs_quads(r, f, reach));
    }
    return n;
}

void rs_render_level_release(rs_renderer *r)
{
    glDeleteFramebuffers(RS_LEVEL_DIVS, r->fbo_level);
    glDeleteTextures(RS_LEVEL_DIVS, r->level_tex);
    memset(r->fbo_level, 0, sizeof r->fbo_level);
    memset(r->level_tex, 0, sizeof r->level_tex);
}

static int div_index(int div) { return div >= 4 ? 2 : div >= 2 ? 1 : 0; }

static void level_size(const rs_frame *f, int div, int *w, int *h)
{
    *w = (f->cam.width + div - 1) / div;
    *h = (f->cam.height + div - 1) / div;
}

// The level target for a resolution divisor, made on first use (the frame targets' size).
static rs_result ensure_level(rs_renderer *r, const rs_frame *f, int div, rs_error *err)
{
    int k = div_index(div);
    if (r->level_tex[k]) return RS_OK;
    int w, h;
    level_size(f, div, &w, &h);
    r->level_tex[k] = rs_render_texture(r->float_rt ? GL_RGBA16F : GL_RGBA8, w, h);
    glGenFramebuffers(1, &r->fbo_level[k]);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_level[k]);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->level_tex[k], 0);
    char what[96];
    snprintf(what, sizeof what, "diffusion level target (%s %dx%d)", r->float_rt ? "RGBA16F" : "RGBA8", w, h);
    rs_result res = rs_render_fbo_check(what, err);
    if (res != RS_OK) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &r->fbo_level[k]);
        glDeleteTextures(1, &r->level_tex[k]);
        r->fbo_level[k] = r->level_tex[k] = 0;
    }
    return res;
}

static rs_result draw_level(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *l, float e_scale,
                            rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_DIFFUSION, l->quads, &prog, err);
    if (res == RS_OK) res = ensure_level(r, f, l->res_div, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    int w, h;
    level_size(f, l->res_div, &w, &h);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_level[div_index(l->res_div)]);
    glViewport(0, 0, w, h);
    const GLfloat zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glUseProgram(prog);
    // No threshold culling here: the shader drops only back-facing splats hidden deep behind the surface.
    rs_render_splat_uniforms(prog, cam->view, cam->proj, cam->inv_proj, w, h, true,
                             rs_splat_lod_radius_scale(r->cloud, l->count), -2.0f, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_sigma"), l->sigma);
    // The kernel floor follows the target's pixels (a reduced target's are larger).
    glUniform1f(rs_uloc(prog, "u_px_size"), cam->px_size * (float)l->res_div);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform2f(rs_uloc(prog, "u_acc_scale"), e_scale, r->float_rt ? 1.0f : FALLBACK_WEIGHT_SCALE);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
    rs_render_draw_splats(r, l->count, l->quads);
    return RS_OK;
}

// What the splats' irradiance depends on besides the splats: the lights in model space, the shadows,
// the LOD prefix (and with it the shadow map's). Not the camera: E is kept across views while this holds.
static void irradiance_key(const rs_frame *f, float k[RS_IRR_KEY])
{
    mat3 inv_rot;
    glm_mat4_pick3((vec4 *)f->cam.inv_view, inv_rot);
    glm_mat3_mulv(inv_rot, (float *)f->key_dir, k);
    glm_mat3_mulv(inv_rot, (float *)f->fill_dir, k + 3);
    memcpy(k + 6, f->key_color, 3 * sizeof(float));
    memcpy(k + 9, f->fill_color, 3 * sizeof(float));
    memcpy(k + 12, f->ambient, 3 * sizeof(float));
    k[15] = f->env_on ? 1.0f : 0.0f;
    k[16] = f->env_on ? f->view.env_rotate_deg : 0.0f;
    k[17] = f->env_on ? f->view.env_intensity : 0.0f;
    k[18] = f->shadows ? 1.0f : 0.0f;
    k[19] = (float)f->shadow_slot;
    k[20] = (float)f->count;
    k[21] = f->eps;
}

// Within float rounding: a direction brought back to model space differs in its last bits from view to
// view (as the shadow maps' keys, render_shadow.c).
static bool irradiance_key_holds(const float a[RS_IRR_KEY], const float b[RS_IRR_KEY])
{
    for (int i = 0; i < RS_IRR_KEY; i++)
        if (!(fabsf(a[i] - b[i]) <= 1e-5f * fmaxf(1.0f, fabsf(b[i])))) return false;
    return true;
}

// Per-splat irradiance for the frame's first `count` splats (every level draws a prefix of those), by
// transform feedback: the shadow-map PCF runs once per splat instead of once per splat and level. E does
// not depend on the camera: while the lights hold still, the same view reuses it, and the first other
// view runs the pass once more over every splat of the prefix, which then serves every view (orbiting,
// zooming within a LOD prefix, painting) until the lights move.
static rs_result irradiance_pass(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *levels, int count,
                                 rs_error *err)
{
    // The farthest any level's kernel reaches (its sigma, or the floor of the widest splat of its prefix,
    // or of a pixel at the far end of the cloud): splats deeper behind the visible surface or farther
    // outside the view than this reach no pixel, so their shadow lookup is skipped -- unless the result
    // is to be kept for other views.
    float reach = 0;
    for (int i = 0; i < count; i++) {
        float rmax = r->cloud->hdr.radius_max * rs_splat_lod_radius_scale(r->cloud, levels[i].count);
        float px = f->cam.px_size * (float)levels[i].res_div * f->cam.far_z;
        reach = fmaxf(reach, 3.0f * fmaxf(levels[i].sigma, 0.5f * fmaxf(rmax, px)));
    }
    float key[RS_IRR_KEY];
    irradiance_key(f, key);
    bool held = r->irr_state > 0 && r->irr_serial == r->light_serial && irradiance_key_holds(key, r->irr_key);
    // The same view may reuse a pass that skipped splats only if its levels reach no farther (another
    // kernel count may draw a wider level; the key does not hold it).
    bool same_view = memcmp(r->irr_view, f->cam.view, sizeof(mat4)) == 0 &&
                     memcmp(r->irr_proj, f->cam.proj, sizeof(mat4)) == 0 && reach <= r->irr_reach;
    r->stats.irradiance_kept = held && (r->irr_state == 2 || same_view);
    if (r->stats.irradiance_kept) return RS_OK;
    if (held) reach = FLT_MAX;
    r->irr_state = 0;
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_IRRADIANCE, false, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    glUseProgram(prog);
    glUniformMatrix4fv(rs_uloc(prog, "u_view"), 1, GL_FALSE, (const float *)cam->view);
    glUniformMatrix4fv(rs_uloc(prog, "u_proj"), 1, GL_FALSE, (const float *)cam->proj);
    glUniformMatrix4fv(rs_uloc(prog, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    glUniform3fv(rs_uloc(prog, "u_key_dir"), 1, f->key_dir);
    glUniform3fv(rs_uloc(prog, "u_key_color"), 1, f->key_color);
    glUniform3fv(rs_uloc(prog, "u_fill_dir"), 1, f->fill_dir);
    glUniform3fv(rs_uloc(prog, "u_fill_color"), 1, f->fill_color);
    glUniform3fv(rs_uloc(prog, "u_ambient"), 1, f->ambient);
    glUniform1f(rs_uloc(prog, "u_reach"), reach);
    rs_render_shadow_uniforms(r, f, prog);
    rs_render_env_uniforms(r, f, prog);
    rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
    rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
    // The depth texture is sampled: the framebuffer bound must not hold it, even with rasterisation off
    // (a feedback loop that WebGL refuses and GLES leaves undefined). The diffuse target has no depth.
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_diffuse);
    glBindVertexArray(r->vao_feedback);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, r->vbo_irradiance);
    glEnable(GL_RASTERIZER_DISCARD);
    glBeginTransformFeedback(GL_POINTS);
    glDrawArrays(GL_POINTS, 0, (GLsizei)f->count);
    glEndTransformFeedback();
    glDisable(GL_RASTERIZER_DISCARD);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, 0);
    res = rs_gl_check("render: irradiance pass", err);
    if (res != RS_OK) return res;
    memcpy(r->irr_key, key, sizeof key);
    r->irr_serial = r->light_serial;
    memcpy(r->irr_view, f->cam.view, sizeof(mat4));
    memcpy(r->irr_proj, f->cam.proj, sizeof(mat4));
    r->irr_reach = reach;
    r->irr_state = held ? 2 : 1;
    return RS_OK;
}

rs_result rs_render_diffusion(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *levels, int count,
                              rs_error *err)
{
    if (count > 0) {
        rs_result res = irradiance_pass(r, f, levels, count, err);
        if (res != RS_OK) return res;
    }
    const rs_camera *cam = &f->cam;
    GLuint resolve;
    rs_result res = rs_render_program(r, RS_PROG_RESOLVE, false, &resolve, err);
    if (res != RS_OK) return res;
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
        glViewport(0, 0, cam->width, cam->height);
        glUseProgram(resolve);
        glUniformMatrix4fv(rs_uloc(resolve, "u_proj"), 1, GL_FALSE, (const float *)cam->proj);
        glUniformMatrix4fv(rs_uloc(resolve, "u_inv_proj"), 1, GL_FALSE, (const float *)cam->inv_proj);
        glUniform2f(rs_uloc(resolve, "u_viewport"), (float)cam->width, (float)cam->height);
        glUniform1f(rs_uloc(resolve, "u_eps"), f->eps);
        glUniform1i(rs_uloc(resolve, "u_res_div"), levels[i].res_div);
        // Depth-aware upsampling: reduced-resolution samples on another surface (more than about the
        // kernel's width away in 3D) don't count.
        float sb = fmaxf(levels[i].sigma,
                         0.5f * r->radius_median * rs_splat_lod_radius_scale(r->cloud, levels[i].count));
        glUniform1f(rs_uloc(resolve, "u_inv_two_sb2"), 0.5f / (sb * sb));
        glUniform3fv(rs_uloc(resolve, "u_weight"), 1, levels[i].weight);
        glUniform1f(rs_uloc(resolve, "u_smooth"), i == 0 ? 1.0f : 0.0f);
        glUniform1f(rs_uloc(resolve, "u_scale"), d_scale / e_scale);
        glUniform1f(rs_uloc(resolve, "u_e_max"), r->float_rt ? 1e30f : 1.0f);
        // A level's weights sum to ~0.4 (100 steps) where sampled; under 16 steps, rounding dominates.
        glUniform1f(rs_uloc(resolve, "u_min_weight"), r->float_rt ? 0.0f : 16.0f / 255.0f);
        rs_render_bind_texture(RS_UNIT_LEVEL, r->level_tex[div_index(levels[i].res_div)]);
        rs_render_bind_texture(RS_UNIT_DEPTH, r->depth_tex);
        rs_render_bind_texture(RS_UNIT_PUSH, r->push_tex);
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
