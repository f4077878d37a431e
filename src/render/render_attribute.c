// render_attribute.c — stage 3, attribute splatting (paper Fig. 2): the splats again, depth-tested (LEQUAL,
// no writes) against stage 2, their Gaussian-weighted attributes added into three targets:
//   RT0 = (albedo, 1) w,  RT1 = (normal * 0.5 + 0.5, m) w,
//   RT2 = (rho_s, ambient occlusion, clear coat, flakes) w (the debug views: (rho_s, debug colour) w).
// w = exp(-l^2 / (2 sigma^2)) with l the hit's distance from the disk centre in radii.
// Targets are RGBA16F when the driver can blend into half floats (EXT_color_buffer_half_float/_float).
// Fallback without them: RGBA8 with every weight scaled by RS_ATTR_WEIGHT_SCALE_RGBA8 (1/5) so the sums of
// the overlapping splats (2-4 at a pixel, by construction of the radii) stay below 1, and raised to at
// least RS_ATTR_WEIGHT_FLOOR_RGBA8 so a lone rim still counts several 8-bit steps; the scale cancels in
// the composite's division. Both constants were tuned on the bundled head (PSNR vs the float path ~38 dB
// at 256^2 / 50k splats); what remains is 8-bit blending noise where few splats overlap (brows, creases
// next to occluding edges). Every GLES 3 GPU we know of has EXT_color_buffer_half_float; the fallback
// exists so the viewer still runs without it.
#include "render/render_stages.h"

#include <math.h>
#include <string.h>

#define CULL_COS -0.25f
// Gaussian sigma in disk radii: 0.45 blends neighbours smoothly (splat radius ~1.3x the spacing)
// while the weight at the rim (0.085) lets the disk edge fade out instead of showing.
#define ATTR_SIGMA 0.45f

// Region colours for the `regions` view (sRGB): other, cheek, nose, forehead, lips, then extras.
static const float region_palette[16][3] = {
    {0.55f, 0.55f, 0.55f}, {0.90f, 0.35f, 0.35f}, {0.30f, 0.75f, 0.30f}, {0.30f, 0.45f, 0.95f},
    {0.95f, 0.80f, 0.20f}, {0.70f, 0.30f, 0.85f}, {0.20f, 0.80f, 0.85f}, {0.95f, 0.55f, 0.15f},
    {0.45f, 0.30f, 0.15f}, {0.60f, 0.90f, 0.55f}, {0.95f, 0.60f, 0.75f}, {0.25f, 0.25f, 0.50f},
    {0.80f, 0.80f, 0.50f}, {0.40f, 0.60f, 0.60f}, {0.85f, 0.45f, 0.55f}, {0.95f, 0.95f, 0.95f},
};

// LOD level colours for the `lod` view: blue (splats only in the full set) through green to red
// (the coarsest prefix).
static void lod_palette(int levels, float out[24][3])
{
    for (int k = 0; k < 24; k++) {
        float t = levels > 1 ? RS_MIN((float)k / (float)(levels - 1), 1.0f) : 1.0f;
        out[k][0] = t;
        out[k][1] = 1.0f - fabsf(2.0f * t - 1.0f);
        out[k][2] = 1.0f - t;
    }
}

rs_result rs_render_attributes(rs_renderer *r, const rs_frame *f, rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_ATTRIBUTE, f->quads, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    const rs_splat_header *h = &r->cloud->hdr;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_attr);
    glViewport(0, 0, cam->width, cam->height);
    // The bent normals only light an environment: without one their target is not written.
    const int targets = f->env_on ? RS_ATTR_TARGETS : RS_ATTR_TARGETS - 1;
    const GLenum bufs[RS_ATTR_TARGETS] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2,
                                          GL_COLOR_ATTACHMENT3};
    glDrawBuffers(targets, bufs);
    const GLfloat zero[4] = {0, 0, 0, 0};
    for (int i = 0; i < targets; i++) glClearBufferfv(GL_COLOR, i, zero);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFunc(GL_ONE, GL_ONE);
    glUseProgram(prog);
    rs_render_splat_uniforms(prog, cam->view, cam->proj, cam->inv_proj, cam->width, cam->height, true,
                             f->radius_scale, CULL_COS, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_inv_two_sigma2"), 1.0f / (2.0f * ATTR_SIGMA * ATTR_SIGMA));
    glUniform1f(rs_uloc(prog, "u_weight_scale"), r->float_rt ? 1.0f : RS_ATTR_WEIGHT_SCALE_RGBA8);
    glUniform1f(rs_uloc(prog, "u_weight_floor"), r->float_rt ? 0.0f : RS_ATTR_WEIGHT_FLOOR_RGBA8);
    glUniform1f(rs_uloc(prog, "u_bent_scale"), r->float_rt ? RS_ATTR_WEIGHT_SCALE_RGBA8 : 1.0f);
    glUniform1f(rs_uloc(prog, "u_env_on"), f->env_on ? 1.0f : 0.0f);
    glUniform1f(rs_uloc(prog, "u_makeup_on"), f->view.hide_makeup ? 0.0f : 1.0f);
    glUniform3fv(rs_uloc(prog, "rs_makeup_range_lo"), 1, r->makeup_uni.range_lo);
    glUniform3fv(rs_uloc(prog, "rs_makeup_range_hi"), 1, r->makeup_uni.range_hi);

    float m[16] = {0}, rho[16] = {0};
    for (uint32_t i = 0; i < h->region_count && i < 16; i++) {
        m[i] = h->regions[i].m;
        rho[i] = h->regions[i].rho_s;
    }
    glUniform1fv(rs_uloc(prog, "u_region_m"), 16, m);
    glUniform1fv(rs_uloc(prog, "u_region_rho"), 16, rho);
    int debug = f->view.mode == RS_MODE_REGIONS ? 1 : f->view.mode == RS_MODE_LOD ? 2 : 0;
    glUniform1i(rs_uloc(prog, "u_debug"), debug);
    float colours[24][3] = {{0}};
    if (debug == 1) memcpy(colours, region_palette, sizeof region_palette);
    if (debug == 2) lod_palette((int)h->lod_count, colours);
    glUniform3fv(rs_uloc(prog, "u_debug_color"), 24, &colours[0][0]);
    GLuint lods[24] = {0};
    for (uint32_t k = 0; k < h->lod_count && k < 24; k++) lods[k] = h->lods[k];
    glUniform1uiv(rs_uloc(prog, "u_lods"), 24, lods);
    glUniform1i(rs_uloc(prog, "u_lod_count"), (int)RS_MIN(h->lod_count, 24u));

    rs_render_draw_splats(r, f->count, f->quads);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    return RS_OK;
}
