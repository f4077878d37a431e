// render_visibility.c — stage 2, visibility splatting (Botsch et al. 2005; paper Fig. 2): a depth pass
// of the splats as disks (per-pixel ray-disk intersection), each hit pushed back by frame->eps along its
// view ray, so that stage 3 blends every splat of the front surface layer and nothing behind it. The push
// grows towards the disk's rim (visibility.frag.glsl); an R8 target keeps each pixel's, so that the stages
// that reconstruct the visible point from the depth undo it exactly.
#include "render/render_stages.h"

// Splats facing away beyond this are dropped (their front-facing neighbours cover the silhouette).
#define CULL_COS -0.25f

rs_result rs_render_visibility(rs_renderer *r, const rs_frame *f, rs_error *err)
{
    GLuint prog;
    rs_result res = rs_render_program(r, RS_PROG_VISIBILITY, f->quads, &prog, err);
    if (res != RS_OK) return res;
    const rs_camera *cam = &f->cam;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_vis);
    glViewport(0, 0, cam->width, cam->height);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepthf(1.0f);
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClear(GL_DEPTH_BUFFER_BIT | GL_COLOR_BUFFER_BIT);
    glUseProgram(prog);
    rs_render_splat_uniforms(prog, cam->view, cam->proj, cam->inv_proj, cam->width, cam->height, true,
                             f->radius_scale, CULL_COS, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_eps"), f->eps);
    rs_render_draw_splats(r, f->count, f->quads);
    return RS_OK;
}
