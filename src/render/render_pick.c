// render_pick.c — the ID buffer for painting (paper §3.1: "the 2D cursor becomes a 3D point by reading the
// splat index stored in an FBO"): the visibility pass's ray-disk shader, without the push, writing
// index + 1 into an R32UI target (0 = background). Rendered on demand and cached while the view's
// geometry (size, camera, LOD, primitive) stays the same, so a stroke of many stamps renders it once;
// read back whole at that time, so each pick is a lookup in memory, not a pipeline stall.
#include "render/render_stages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define CULL_COS -0.25f

void rs_render_pick_release(rs_renderer *r)
{
    glDeleteFramebuffers(1, &r->fbo_pick);
    GLuint t[2] = {r->pick_tex, r->pick_depth};
    glDeleteTextures(2, t);
    r->fbo_pick = r->pick_tex = r->pick_depth = 0;
    r->pw = r->ph = 0;
    r->pick_valid = false;
    free(r->pick_ids);
    r->pick_ids = NULL;
}

static bool same_geometry(const rs_view *a, const rs_view *b)
{
    return a->width == b->width && a->height == b->height && a->yaw_deg == b->yaw_deg &&
           a->pitch_deg == b->pitch_deg && a->zoom == b->zoom && a->fov_deg == b->fov_deg &&
           a->pan[0] == b->pan[0] && a->pan[1] == b->pan[1] && a->max_splats == b->max_splats &&
           a->prim == b->prim && a->pipeline == b->pipeline && a->lod_density == b->lod_density &&
           a->use_matrices == b->use_matrices &&
           (!a->use_matrices || (!memcmp(a->view_matrix, b->view_matrix, sizeof a->view_matrix) &&
                                 !memcmp(a->proj_matrix, b->proj_matrix, sizeof a->proj_matrix)));
}

static bool ensure_pick_targets(rs_renderer *r, int w, int h)
{
    if (r->pw == w && r->ph == h) return true;
    rs_render_pick_release(r);
    r->pick_tex = rs_render_texture(GL_R32UI, w, h);
    r->pick_depth = rs_render_texture(GL_DEPTH_COMPONENT32F, w, h);
    glGenFramebuffers(1, &r->fbo_pick);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_pick);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, r->pick_tex, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r->pick_depth, 0);
    bool ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!ok) {
        rs_render_pick_release(r);
        return false;
    }
    r->pw = w;
    r->ph = h;
    return true;
}

static bool render_ids(rs_renderer *r, const rs_view *view)
{
    rs_frame f;
    rs_render_frame_setup(r, view, &f);
    if (!ensure_pick_targets(r, f.cam.width, f.cam.height)) return false;
    GLuint prog;
    rs_error err = {0};
    if (rs_render_program(r, RS_PROG_PICK, f.quads, &prog, &err) != RS_OK) return false;
    GLint saved_viewport[4];
    glGetIntegerv(GL_VIEWPORT, saved_viewport);
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_pick);
    glViewport(0, 0, f.cam.width, f.cam.height);
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferuiv(GL_COLOR, 0, zero);
    glClearDepthf(1.0f);
    glClear(GL_DEPTH_BUFFER_BIT);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glUseProgram(prog);
    rs_render_splat_uniforms(prog, f.cam.view, f.cam.proj, f.cam.inv_proj, f.cam.width, f.cam.height, true,
                             f.radius_scale, CULL_COS, r->caps.point_size_max);
    glUniform1f(rs_uloc(prog, "u_eps"), 0.0f);
    rs_render_draw_splats(r, f.count, f.quads);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(0);
    glUseProgram(0);
    // Integer targets read back as RGBA_INTEGER (the one format ES 3 guarantees); keep the red channel.
    size_t n = (size_t)f.cam.width * (size_t)f.cam.height;
    uint32_t *rgba = rs_alloc_array(n, 4 * sizeof(uint32_t));
    uint32_t *ids = realloc(r->pick_ids, n * sizeof *ids);
    bool ok = rgba && ids;
    if (ids) r->pick_ids = ids;
    if (ok) {
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, f.cam.width, f.cam.height, GL_RGBA_INTEGER, GL_UNSIGNED_INT, rgba);
        ok = glGetError() == GL_NO_ERROR;
        for (size_t i = 0; ok && i < n; i++) ids[i] = rgba[4 * i];
    }
    free(rgba);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(saved_viewport[0], saved_viewport[1], saved_viewport[2], saved_viewport[3]);
    r->pick_view = *view;
    r->pick_valid = ok;
    return ok;
}

// Where the eye ray through pixel (x, y) meets splat i's plane: the stamp centre must be the surface
// point under the finger, not the splat's centre, which can lie a splat radius (pixels, at coarse
// LOD) away. Falls back to the centre for grazing rays.
static void hit_point(rs_renderer *r, const rs_view *view, float x_px, float y_px, uint32_t i, float hit[3])
{
    const rs_splat_cloud *c = r->cloud;
    const float *ctr = c->pos[i], *n = c->normal[i];
    hit[0] = ctr[0], hit[1] = ctr[1], hit[2] = ctr[2];
    rs_frame f;
    rs_render_frame_setup(r, view, &f);
    mat4 vp, inv;
    glm_mat4_mul(f.cam.proj, f.cam.view, vp);
    glm_mat4_inv(vp, inv);
    vec4 ndc = {2.0f * x_px / (float)f.cam.width - 1.0f, 1.0f - 2.0f * y_px / (float)f.cam.height, 1.0f, 1.0f}, far;
    glm_mat4_mulv(inv, ndc, far);
    if (fabsf(far[3]) < 1e-12f) return;
    vec3 o = {f.cam.eye[0], f.cam.eye[1], f.cam.eye[2]};
    vec3 d = {far[0] / far[3] - o[0], far[1] / far[3] - o[1], far[2] / far[3] - o[2]};
    glm_vec3_normalize(d);
    float dn = glm_vec3_dot(d, (float *)n);
    if (fabsf(dn) < 0.05f) return;
    vec3 co = {ctr[0] - o[0], ctr[1] - o[1], ctr[2] - o[2]};
    float t = glm_vec3_dot(co, (float *)n) / dn;
    vec3 q = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
    // The ID pass draws disks slightly enlarged; never move further than two radii from the centre.
    float lim = 2.0f * c->radius[i] * f.radius_scale;
    if (!(glm_vec3_distance(q, (float *)ctr) <= lim)) return;
    hit[0] = q[0], hit[1] = q[1], hit[2] = q[2];
}

bool rs_render_pick(rs_renderer *r, const rs_view *view, float x_px, float y_px, uint32_t *splat_index, float hit[3])
{
    if (!view || view->width <= 0 || view->height <= 0 || view->width > r->caps.max_texture_size ||
        view->height > r->caps.max_texture_size)
        return false;
    if (!(x_px >= 0 && y_px >= 0 && x_px < (float)view->width && y_px < (float)view->height)) return false;
    if (!r->pick_valid || !same_geometry(&r->pick_view, view))
        if (!render_ids(r, view)) return false;
    int x = (int)x_px, y = view->height - 1 - (int)y_px;
    uint32_t id = r->pick_ids[(size_t)y * (size_t)view->width + (size_t)x];
    if (id == 0 || id > r->cloud->hdr.count) return false;
    *splat_index = id - 1;
    if (hit) hit_point(r, view, x_px + 0.5f, y_px + 0.5f, *splat_index, hit);
    return true;
}
