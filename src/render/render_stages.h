// render_stages.h — the renderer's stages, the layer between the orchestrator (render.c, the only caller
// of a stage's pass or release) and the kit below them (render_kit.h). A stage may use a sibling's lookup
// uniforms (shadow map, environment, fine layer) but never calls into render.c.
// Not public API: render.h is.
#ifndef RS_RENDER_STAGES_H
#define RS_RENDER_STAGES_H

#include "render/render_kit.h"

// The passes, in the order of the paper's Fig. 2.
rs_result rs_render_shadow(rs_renderer *r, rs_frame *f, rs_error *err);
rs_result rs_render_visibility(rs_renderer *r, const rs_frame *f, rs_error *err);
rs_result rs_render_attributes(rs_renderer *r, const rs_frame *f, rs_error *err);
// Fills levels[] for the frame's pipeline and returns their number; delta_weight gets the summed RGB
// weights of the Gaussians too narrow to draw (the composite adds them as per-pixel irradiance).
int rs_render_diffusion_plan(rs_renderer *r, const rs_frame *f, rs_diffusion_level levels[RS_PROFILE_MAX],
                             float delta_weight[3]);
rs_result rs_render_diffusion(rs_renderer *r, const rs_frame *f, const rs_diffusion_level *levels, int count,
                              rs_error *err);
// The composite's first step, at half size: whether the face blocks each pixel's mirror direction and the
// skin it sees there (under an environment only). rect (x0, y0, x1, y1; NULL: all): the pixels an
// incremental frame composes again, with the scissor test on; it leaves the scissor box changed.
rs_result rs_render_reflections(rs_renderer *r, const rs_frame *f, const int *rect, rs_error *err);
rs_result rs_render_composite(rs_renderer *r, const rs_frame *f, rs_error *err);
// The composite's last step: its picture with its contours (the depth steps inside the face, the outline)
// anti-aliased, into the output. An output pixel reads its 4-neighbours' colours and the steps along its
// contours.
rs_result rs_render_edges(rs_renderer *r, const rs_frame *f, rs_error *err);

// Lookups a pass sets on its programs. render_shadow.c: the shadow_lookup.glsl uniforms for the frame.
void rs_render_shadow_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog);
// render_env.c: the env_light.glsl uniforms and textures for the frame.
void rs_render_env_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog);
// render_fine.c: the fine layer's uniforms and textures for the composite.
void rs_render_fine_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog);
void rs_render_fine_unbind(void);  // after the composite: the fields' 3D texture off its unit

// Each part's GL objects (rs_render_destroy and the target resizes).
void rs_render_shadow_release(rs_renderer *r);
void rs_render_level_release(rs_renderer *r);
void rs_render_pick_release(rs_renderer *r);
void rs_render_env_release(rs_renderer *r);
// The cloud as a coarse grid (built once, at the first frame under an environment): what a reflection that
// leaves the frame meets (composite.frag.glsl body_seen).
rs_result rs_render_env_body(rs_renderer *r, rs_error *err);
void rs_render_fine_release(rs_renderer *r);

#endif
