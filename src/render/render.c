// render.c — the renderer object (GPU buffers, programs, targets), the camera, and the frame that runs the
// paper's five stages in order (Fig. 2): shadow map, visibility, attributes, diffusion, composite.
// Pass order and what each reads: (1) shadow map (splats from the light); (2) visibility depth; (3)
// attributes: per-splat albedo with the makeup's splat layer composed in (makeup.glsl), normal, m, rho_s,
// ao, coat, flakes, depth-tested against (2); (4) diffusion of per-splat irradiance into D (independent of
// albedo and finish); (5) composite: normalises (3), composes the makeup's fine layer per pixel at the
// surface point from (2) (render_fine.c: stamps + grid in textures never attached to a framebuffer), then
// F = A (D + S). A stamp's frame re-runs (3) and (5) only, inside its rectangle (incremental_frame).
#include "render/render_internal.h"

#include "gl/shader.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define DEG2RAD(d) ((d) * 0.017453292519943295f)

// Display defaults: a dark neutral grey behind the face, and a key light from the upper left-front
// (the classic portrait "loop light": cheek and nose shadow on the far side).
static const float default_background[3] = {0.16f, 0.16f, 0.17f};

rs_view rs_view_defaults(void)
{
    return (rs_view){
        .width = 512,
        .height = 512,
        .zoom = 1.0f,
        .fov_deg = 30.0f,
        .key = {.yaw_deg = -35.0f, .pitch_deg = 30.0f, .color = {1, 1, 1}, .intensity = 1.0f},
        .fill = {.yaw_deg = 50.0f, .pitch_deg = 0.0f, .color = {1, 1, 1}, .intensity = 0.0f},
        .exposure = 1.0f,
        .background = {default_background[0], default_background[1], default_background[2]},
        .rho_s_scale = 1.0f,
        .ambient = 0.05f,
    };
}

// ---- camera ----

// Unit vector of direction (yaw, pitch) in the face frame: yaw turns from `forward` towards the
// subject's left (image right), pitch towards `up`.
static void frame_dir(const rs_splat_header *h, float yaw_deg, float pitch_deg, vec3 out)
{
    vec3 f, u, right;
    glm_vec3_normalize_to((float *)h->forward, f);
    glm_vec3_copy((float *)h->up, u);
    // Up made orthogonal to forward (the header only promises "not parallel").
    vec3 tmp;
    glm_vec3_scale(f, glm_vec3_dot(f, u), tmp);
    glm_vec3_sub(u, tmp, u);
    glm_vec3_normalize(u);
    glm_vec3_cross(u, f, right);
    float y = DEG2RAD(yaw_deg), p = DEG2RAD(pitch_deg);
    for (int a = 0; a < 3; a++)
        out[a] = cosf(p) * (cosf(y) * f[a] + sinf(y) * right[a]) + sinf(p) * u[a];
}

// The host's camera (rs_view.use_matrices): near and far come from the perspective projection
// (P[2][2] = -(f+n)/(f-n), P[3][2] = -2fn/(f-n)), the pixel size from its focal length.
static void host_camera(const rs_renderer *r, const rs_view *v, rs_camera *cam)
{
    memcpy(cam->view, v->view_matrix, sizeof cam->view);
    memcpy(cam->proj, v->proj_matrix, sizeof cam->proj);
    glm_mat4_inv(cam->view, cam->inv_view);
    glm_mat4_inv(cam->proj, cam->inv_proj);
    for (int a = 0; a < 3; a++) cam->eye[a] = cam->inv_view[3][a];
    cam->near_z = cam->proj[3][2] / (cam->proj[2][2] - 1.0f);
    cam->far_z = cam->proj[3][2] / (cam->proj[2][2] + 1.0f);
    cam->width = v->width;
    cam->height = v->height;
    cam->px_size = 2.0f / (cam->proj[1][1] * (float)v->height);
    vec3 bc = {r->bound_centre[0], r->bound_centre[1], r->bound_centre[2]};
    float bd = glm_vec3_distance(cam->eye, bc);
    cam->ppu_max = 1.0f / (cam->px_size * fmaxf(bd - r->bound_radius, cam->near_z));
}

void rs_render_camera(const rs_renderer *r, const rs_view *v, rs_camera *cam)
{
    if (v->use_matrices) {
        host_camera(r, v, cam);
        return;
    }
    const rs_splat_header *h = &r->cloud->hdr;
    float pitch = RS_CLAMP(v->pitch_deg, -89.0f, 89.0f);
    vec3 d, up;
    frame_dir(h, v->yaw_deg, pitch, d);
    // The camera's up: the face's up tilted with the pitch (never parallel to d).
    frame_dir(h, v->yaw_deg, pitch + 90.0f, up);
    float half_fov = DEG2RAD(v->fov_deg) * 0.5f;
    // Face height fills ~80% of the view height at zoom 1.
    float dist = h->face_height * 0.5f / 0.8f / tanf(half_fov) / v->zoom;
    vec3 centre = {h->centre[0], h->centre[1], h->centre[2]};
    for (int a = 0; a < 3; a++) cam->eye[a] = centre[a] + d[a] * dist;
    glm_lookat(cam->eye, centre, up, cam->view);
    glm_mat4_inv(cam->view, cam->inv_view);

    // Near/far from the cloud's bounding sphere, so depth precision is spent on the face.
    vec3 bc = {r->bound_centre[0], r->bound_centre[1], r->bound_centre[2]};
    float bd = glm_vec3_distance(cam->eye, bc), R = r->bound_radius;
    cam->far_z = bd + R * 1.01f;
    cam->near_z = fmaxf(bd - R * 1.01f, cam->far_z * 1e-3f);
    float aspect = (float)v->width / (float)v->height;
    glm_perspective(2.0f * half_fov, aspect, cam->near_z, cam->far_z, cam->proj);
    // Pan: a shift in normalised device coordinates (fractions of the view height; +x right, +y down).
    mat4 pan;
    glm_translate_make(pan, (vec3){2.0f * v->pan[0] / aspect, -2.0f * v->pan[1], 0.0f});
    glm_mat4_mul(pan, cam->proj, cam->proj);
    glm_mat4_inv(cam->proj, cam->inv_proj);
    cam->width = v->width;
    cam->height = v->height;
    cam->px_size = 2.0f * tanf(half_fov) / (float)v->height;
    cam->ppu_max = 1.0f / (cam->px_size * fmaxf(bd - R, cam->near_z));
}

// Fills the zero-means-default fields.
static rs_view view_resolved(const rs_view *in)
{
    rs_view v = *in;
    if (v.zoom <= 0) v.zoom = 1.0f;
    if (v.fov_deg <= 0) v.fov_deg = 30.0f;
    if (v.exposure <= 0) v.exposure = 1.0f;
    if (v.rho_s_scale <= 0) v.rho_s_scale = 1.0f;
    if (!(v.lod_density > 0)) v.lod_density = RS_LOD_DENSITY_DEFAULT;
    if (!(v.env_intensity > 0)) v.env_intensity = 1.0f;
    if (v.key.intensity <= 0) v.key.intensity = 1.0f;
    rs_light *lights[2] = {&v.key, &v.fill};
    for (int i = 0; i < 2; i++)
        if (lights[i]->color[0] <= 0 && lights[i]->color[1] <= 0 && lights[i]->color[2] <= 0)
            lights[i]->color[0] = lights[i]->color[1] = lights[i]->color[2] = 1.0f;
    return v;
}

// The face's screen area in pixels (*face_px) and the number of splats of the whole cloud per visible
// splat (the returned ratio A_total / A_visible), from an even subsample (the coarsest LOD prefix): each
// sample stands for area_total / n of the surface, and counts when it faces the camera and projects into
// the view, with its foreshortening (n.v) over its squared distance. Overlapping layers (an ear in front
// of the cheek) count twice: a few percent on a face (measured within 2% of the covered pixels).
static float face_pixels(const rs_renderer *r, const rs_camera *cam, float *face_px)
{
    const rs_splat_cloud *c = r->cloud;
    const rs_splat_header *h = &c->hdr;
    uint32_t n = h->lod_count > 0 ? h->lods[h->lod_count - 1] : h->count;
    // Without a coarse LOD level, every k-th record.
    uint32_t step = 1;
    if (h->lod_count <= 1 || n > 40000) {
        step = RS_MAX(h->count / 20000u, 1u);
        n = h->count;
    }
    mat4 vp;
    glm_mat4_mul((vec4 *)cam->proj, (vec4 *)cam->view, vp);
    double solid = 0;
    uint32_t visible = 0, samples = 0;
    for (uint32_t i = 0; i < n; i += step) {
        samples++;
        vec3 d = {cam->eye[0] - c->pos[i][0], cam->eye[1] - c->pos[i][1], cam->eye[2] - c->pos[i][2]};
        float facing = glm_vec3_dot(d, c->normal[i]);
        if (facing <= 0) continue;
        vec4 p = {c->pos[i][0], c->pos[i][1], c->pos[i][2], 1.0f}, q;
        glm_mat4_mulv(vp, p, q);
        if (!(q[3] > 0 && fabsf(q[0]) <= q[3] && fabsf(q[1]) <= q[3])) continue;
        float dist2 = glm_vec3_dot(d, d);
        solid += facing / (dist2 * sqrtf(dist2));
        visible++;
    }
    float per_sample = r->area_total / (float)samples;
    *face_px = (float)(solid * per_sample) / (cam->px_size * cam->px_size);
    return visible ? (float)samples / (float)visible : 0.0f;
}

// Splats in the main passes: the max_splats cap; the mobile pipeline also the LOD prefix nearest (in log)
// to lod_density visible splats per pixel of the face's screen area (the prefix is spread evenly over
// the whole surface, so it holds `ratio` times the visible ones). The LOD table steps by ~2x: the density
// drawn is within ~0.7x..1.4x of the asked one. Zooming in raises it, up to the whole cloud; small views
// stop at RS_MOBILE_MAX_LOD_STEPS below the cap.
static uint32_t main_count(const rs_renderer *r, const rs_view *v, const rs_camera *cam, float *face_px)
{
    const rs_splat_header *h = &r->cloud->hdr;
    uint32_t n = h->count;
    if (v->max_splats > 0 && v->max_splats < n) n = rs_splat_lod_count(r->cloud, v->max_splats);
    *face_px = 0;
    if (v->pipeline != RS_PIPELINE_MOBILE) return n;
    float density = v->lod_density > 0 ? v->lod_density : RS_LOD_DENSITY_DEFAULT;
    float ratio = face_pixels(r, cam, face_px);
    double want = fmax((double)density * *face_px * ratio, 1.0);
    uint32_t best = n, steps = 0;
    double best_err = INFINITY;
    for (uint32_t k = 0; k < h->lod_count; k++) {
        uint32_t m = h->lods[k];
        if (m > n) continue;
        if (m < n && ++steps > RS_MOBILE_MAX_LOD_STEPS) break;
        double e = fabs(log((double)m / want));
        if (e < best_err) best_err = e, best = m;
    }
    return best;
}

uint32_t rs_render_auto_splats(const rs_renderer *r, const rs_view *view)
{
    rs_view v = view_resolved(view);
    if (v.width <= 0 || v.height <= 0) return 0;
    rs_camera cam;
    rs_render_camera(r, &v, &cam);
    float face_px;
    return main_count(r, &v, &cam, &face_px);
}

bool rs_render_needs_quads(const rs_renderer *r, const rs_frame *f, float radius)
{
    float size = 2.0f * radius * f->cam.ppu_max * 1.15f + 2.0f;
    return size > r->caps.point_size_max;
}

void rs_render_frame_setup(const rs_renderer *r, const rs_view *view, rs_frame *f)
{
    memset(f, 0, sizeof *f);
    f->view = view_resolved(view);
    const rs_view *v = &f->view;
    rs_render_camera(r, v, &f->cam);
    f->mobile = v->pipeline == RS_PIPELINE_MOBILE;
    f->shadow_slot = f->mobile ? 1 : 0;
    f->count = main_count(r, v, &f->cam, &f->face_px);
    f->radius_scale = rs_splat_lod_radius_scale(r->cloud, f->count);
    if (f->mobile) {
        // Even prefixes close the surface with smaller radii than sqrt(N / n) x the full cloud's
        // (RS_MOBILE_COVER), never below the full cloud's own: the reconstruction filter, and with it
        // the silhouette, stays as close as the sampling allows to the reference's of all splats.
        f->radius_scale = fmaxf(1.0f, RS_MOBILE_COVER * f->radius_scale);
    }
    float rmax = r->cloud->hdr.radius_max * f->radius_scale * RS_COVERAGE;
    f->quads = v->prim == RS_PRIM_QUADS || (v->prim == RS_PRIM_AUTO && rs_render_needs_quads(r, f, rmax));
    // Half a typical splat radius: overlapping splats of one surface blend, a surface behind (the far
    // side of a lip, an ear) stays hidden. Constant per frame so stage 4 and 5 can undo it exactly.
    f->eps = 0.5f * r->radius_median * f->radius_scale;

    rs_render_mode m = v->mode;
    f->lit = m == RS_MODE_FULL || m == RS_MODE_DIFFUSE || m == RS_MODE_SPECULAR || m == RS_MODE_SHADOW ||
             m == RS_MODE_IRRADIANCE;
    f->diffuse = m == RS_MODE_FULL || m == RS_MODE_DIFFUSE;
    f->shadows = f->lit && !v->no_shadows;

    const rs_splat_header *h = &r->cloud->hdr;
    vec3 d;
    mat3 rot;
    glm_mat4_pick3(f->cam.view, rot);
    f->env_on = f->lit && v->lighting == RS_LIGHTING_ENV && r->env.on;
    if (f->env_on) {
        // The environment's frame is the face frame (x right = the subject's left, y up, z forward)
        // turned by env_rotate_deg about up. Its brightest region is the key light.
        vec3 right, up, fwd;
        frame_dir(h, 90.0f, 0.0f, right);
        frame_dir(h, 0.0f, 90.0f, up);
        frame_dir(h, 0.0f, 0.0f, fwd);
        float a = DEG2RAD(v->env_rotate_deg), ca = cosf(a), sa = sinf(a);
        // Face-frame coordinates -> environment coordinates: a turn by -a about y.
        mat3 face_to_env = {{ca, 0, sa}, {0, 1, 0}, {-sa, 0, ca}};
        mat3 model_to_face = {{right[0], up[0], fwd[0]}, {right[1], up[1], fwd[1]}, {right[2], up[2], fwd[2]}};
        mat3 inv_rot, m2;
        glm_mat4_pick3(f->cam.inv_view, inv_rot);
        glm_mat3_mul(model_to_face, inv_rot, m2);
        glm_mat3_mul(face_to_env, m2, f->env_from_view);
        // The light back: environment -> view is the transpose (all rotations).
        mat3 view_from_env;
        glm_mat3_transpose_to(f->env_from_view, view_from_env);
        glm_mat3_mulv(view_from_env, (float *)r->env.light_dir, f->key_dir);
        glm_vec3_normalize(f->key_dir);
        glm_vec3_scale((float *)r->env.light_color, v->env_intensity, f->key_color);
        f->key_widen = 0.5f * r->env.light_angle;
        return;
    }
    frame_dir(h, v->key.yaw_deg, v->key.pitch_deg, d);
    glm_mat3_mulv(rot, d, f->key_dir);
    glm_vec3_scale((float *)v->key.color, v->key.intensity, f->key_color);
    frame_dir(h, v->fill.yaw_deg, v->fill.pitch_deg, d);
    glm_mat3_mulv(rot, d, f->fill_dir);
    if (v->fill.intensity > 0) glm_vec3_scale((float *)v->fill.color, v->fill.intensity, f->fill_color);
    float amb = fmaxf(v->ambient, 0.0f);
    glm_vec3_fill(f->ambient, amb);
}

// ---- GL helpers ----

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
    [RS_PROG_COMPOSITE] = {"fullscreen.vert.glsl", "composite.frag.glsl"},
    [RS_PROG_IRRADIANCE] = {"irradiance.vert.glsl", "irradiance.frag.glsl"},
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
    glUniform1i(rs_uloc(p, "u_shadow_map"), RS_UNIT_SHADOW);
    glUniform1i(rs_uloc(p, "u_attr0"), RS_UNIT_ATTR0);
    glUniform1i(rs_uloc(p, "u_attr1"), RS_UNIT_ATTR1);
    glUniform1i(rs_uloc(p, "u_attr2"), RS_UNIT_ATTR2);
    glUniform1i(rs_uloc(p, "u_diffuse"), RS_UNIT_DIFFUSE);
    glUniform1i(rs_uloc(p, "u_level"), RS_UNIT_LEVEL);
    glUniform1i(rs_uloc(p, "u_env_map"), RS_UNIT_ENV);
    glUniform1i(rs_uloc(p, "u_spec_lut"), RS_UNIT_SPEC_LUT);
    glUniform1f(rs_uloc(p, "u_has_ao"), (h->flags & RS_SPLAT_FLAG_AO) ? 1.0f : 0.0f);
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

// ---- create / destroy ----

// Attributes: 0 the splat record, 1 its makeup record, 2 its irradiance (stage 4). The feedback VAO has
// the record alone.
static void setup_vao(rs_renderer *r, GLuint vao, GLuint divisor, bool feedback)
{
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_splats);
    glEnableVertexAttribArray(0);
    glVertexAttribIPointer(0, 4, GL_UNSIGNED_INT, sizeof(rs_splat_packed), (void *)0);
    glVertexAttribDivisor(0, divisor);
    if (feedback) {
        glBindVertexArray(0);
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        return;
    }
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_irradiance);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, 16, (void *)0);
    glVertexAttribDivisor(2, divisor);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_makeup);
    glEnableVertexAttribArray(1);
    glVertexAttribIPointer(1, 3, GL_UNSIGNED_INT, (GLsizei)sizeof(rs_makeup_gpu), (void *)0);
    glVertexAttribDivisor(1, divisor);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

// Median radius from the 8-bit radius codes (a histogram: no sort of 600k floats).
static float median_radius(const rs_splat_cloud *c)
{
    uint32_t hist[256] = {0};
    for (uint32_t i = 0; i < c->hdr.count; i++) hist[(c->packed[i].w[1] >> 16) & 0xffu]++;
    uint32_t half = c->hdr.count / 2, acc = 0;
    int q = 0;
    for (; q < 255; q++) {
        acc += hist[q];
        if (acc > half) break;
    }
    return c->hdr.radius_min * powf(c->hdr.radius_max / c->hdr.radius_min, (float)q / 255.0f);
}

rs_result rs_render_create(const rs_render_desc *desc, rs_renderer **out, rs_error *err)
{
    if (!desc || !desc->cloud || !desc->caps) return rs_fail(err, RS_ERR_ARG, "render: desc needs a cloud and caps");
    const rs_splat_cloud *c = desc->cloud;
    if (c->hdr.count == 0) return rs_fail(err, RS_ERR_ARG, "render: the cloud has no splats");
    if (!(c->hdr.face_height > 0) || !(c->hdr.mm_per_unit > 0))
        return rs_fail(err, RS_ERR_ARG, "render: the cloud's face_height and mm_per_unit must be > 0");
    size_t bytes_splats, bytes_makeup;
    if (!rs_size_mul(c->hdr.count, sizeof(rs_splat_packed), &bytes_splats) ||
        !rs_size_mul(c->hdr.count, sizeof(rs_makeup_gpu), &bytes_makeup) || bytes_splats > (size_t)INT32_MAX)
        return rs_fail(err, RS_ERR_LIMIT, "render: %u splats do not fit a GL buffer", c->hdr.count);
    rs_renderer *r = calloc(1, sizeof *r);
    void *zeros = calloc(1, bytes_makeup);
    if (!r || !zeros) {
        free(r);
        free(zeros);
        return rs_fail(err, RS_ERR_NOMEM, "render: out of memory");
    }
    r->cloud = c;
    r->caps = *desc->caps;
    r->float_rt = desc->caps->float_rt && !desc->force_no_float_targets;
    r->time_stages = desc->time_stages;
    r->radius_median = median_radius(c);
    // Surface area from the radii: rouge-pack's radius is the distance to the 8th nearest neighbour, so
    // a disk of that radius holds ~8 samples and each sample stands for pi r^2 / 8 of the surface.
    double area = 0;
    for (uint32_t i = 0; i < c->hdr.count; i++) area += (double)c->radius[i] * c->radius[i];
    r->area_total = (float)(area * 3.14159265358979 / 8.0);
    // Until the makeup layer says otherwise, the pigment clamp is the whole 0..1 range.
    for (int ch = 0; ch < 3; ch++) r->makeup_uni.range_lo[ch] = 0.0f, r->makeup_uni.range_hi[ch] = 1.0f;
    float ext2 = 0;
    for (int a = 0; a < 3; a++) {
        r->bound_centre[a] = 0.5f * (c->hdr.bbox_min[a] + c->hdr.bbox_max[a]);
        float e = 0.5f * (c->hdr.bbox_max[a] - c->hdr.bbox_min[a]);
        ext2 += e * e;
    }
    r->bound_radius = sqrtf(ext2) + c->hdr.radius_max;

    while (glGetError() != GL_NO_ERROR) {
    }
    glGenBuffers(1, &r->vbo_splats);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_splats);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes_splats, c->packed, GL_STATIC_DRAW);
    // Zero records: no makeup until rs_render_update_makeup.
    glGenBuffers(1, &r->vbo_makeup);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_makeup);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes_makeup, zeros, GL_DYNAMIC_DRAW);
    free(zeros);
    glGenBuffers(1, &r->vbo_irradiance);
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_irradiance);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes_splats, NULL, GL_DYNAMIC_COPY);
    glGenVertexArrays(1, &r->vao_points);
    glGenVertexArrays(1, &r->vao_quads);
    glGenVertexArrays(1, &r->vao_empty);
    glGenVertexArrays(1, &r->vao_feedback);
    setup_vao(r, r->vao_points, 0, false);
    setup_vao(r, r->vao_quads, 1, false);
    setup_vao(r, r->vao_feedback, 0, true);
    r->stats.gpu_bytes = 2 * bytes_splats + bytes_makeup;
    r->stats.float_targets = r->float_rt;
    rs_result res = rs_gl_check("render: uploading the splats", err);
    if (res != RS_OK) {
        rs_render_destroy(r);
        return res;
    }
    *out = r;
    return RS_OK;
}

static void release_targets(rs_renderer *r)
{
    GLuint fbos[] = {r->fbo_vis, r->fbo_attr, r->fbo_diffuse, r->fbo_out};
    glDeleteFramebuffers((GLsizei)RS_COUNT_OF(fbos), fbos);
    GLuint texs[] = {r->depth_tex, r->attr_tex[0], r->attr_tex[1], r->attr_tex[2], r->diffuse_tex, r->out_tex};
    glDeleteTextures((GLsizei)RS_COUNT_OF(texs), texs);
    rs_render_level_release(r);
    r->fbo_vis = r->fbo_attr = r->fbo_diffuse = r->fbo_out = 0;
    r->depth_tex = r->attr_tex[0] = r->attr_tex[1] = r->attr_tex[2] = 0;
    r->diffuse_tex = r->out_tex = 0;
    r->tw = r->th = 0;
    r->have_frame = false;
    r->inc_valid = false;
}

void rs_render_destroy(rs_renderer *r)
{
    if (!r) return;
    release_targets(r);
    rs_render_shadow_release(r);
    rs_render_pick_release(r);
    rs_render_env_release(r);
    rs_render_fine_release(r);
    for (int k = 0; k < RS_PROG_COUNT; k++)
        for (int q = 0; q < 2; q++)
            if (r->prog[k][q]) glDeleteProgram(r->prog[k][q]);
    GLuint vaos[] = {r->vao_points, r->vao_quads, r->vao_empty, r->vao_feedback};
    glDeleteVertexArrays(4, vaos);
    GLuint bufs[] = {r->vbo_splats, r->vbo_makeup, r->vbo_irradiance};
    glDeleteBuffers(3, bufs);
    free(r);
}

// ---- frame targets ----

static GLuint fbo_with(const GLuint *colour, int ncolour, GLuint depth)
{
    GLuint fbo;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    GLenum bufs[4] = {GL_NONE, GL_NONE, GL_NONE, GL_NONE};
    for (int i = 0; i < ncolour; i++) {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + (GLenum)i, GL_TEXTURE_2D, colour[i], 0);
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
    }
    if (depth) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    glDrawBuffers(ncolour ? ncolour : 1, bufs);
    if (!ncolour) glReadBuffer(GL_NONE);
    return fbo;
}

// Render targets of a w x h frame: depth, three attribute targets, diffuse, output, the reduced-resolution
// diffusion levels (at most 4/3 of one accumulation target) and the ID buffer (R32UI + depth). llvmpipe keeps
// all of it in CPU memory, so this is what a frame size costs the machine.
static double target_estimate(int w, int h, bool float_rt)
{
    double px = (double)w * h, acc = float_rt ? 8 : 4;
    return px * (4 + 4 * acc + 4 + acc * 4.0 / 3.0 + 8);
}

static rs_result ensure_targets(rs_renderer *r, int w, int h, rs_error *err)
{
    if (r->tw == w && r->th == h) return RS_OK;
    // Bounded by memory, not by side length alone: 8192^2 once peaked at 3.65 GB.
    double need = target_estimate(w, h, r->float_rt);
    if (need > RS_RENDER_MAX_TARGET_BYTES)
        return rs_fail(err, RS_ERR_LIMIT, "render: %dx%d needs about %.1f GiB of render targets, more than the %.1f GiB "
                       "allowed (use a smaller --size)", w, h, need / (1u << 30),
                       (double)RS_RENDER_MAX_TARGET_BYTES / (1u << 30));
    release_targets(r);
    GLenum acc = r->float_rt ? GL_RGBA16F : GL_RGBA8;
    r->depth_tex = rs_render_texture(GL_DEPTH_COMPONENT32F, w, h);
    for (int i = 0; i < 3; i++) r->attr_tex[i] = rs_render_texture(acc, w, h);
    r->diffuse_tex = rs_render_texture(acc, w, h);
    r->out_tex = rs_render_texture(GL_RGBA8, w, h);
    const char *acc_name = r->float_rt ? "RGBA16F" : "RGBA8";
    struct {
        GLuint *fbo;
        const GLuint *colour;
        int n;
        GLuint depth;
        const char *what;
        const char *fmt;
    } t[] = {
        {&r->fbo_vis, NULL, 0, r->depth_tex, "visibility target", "DEPTH_COMPONENT32F"},
        {&r->fbo_attr, r->attr_tex, 3, r->depth_tex, "attribute targets", acc_name},
        {&r->fbo_diffuse, &r->diffuse_tex, 1, 0, "diffuse target", acc_name},
        {&r->fbo_out, &r->out_tex, 1, 0, "output target", "RGBA8"},
    };
    for (size_t i = 0; i < RS_COUNT_OF(t); i++) {
        *t[i].fbo = fbo_with(t[i].colour, t[i].n, t[i].depth);
        char what[128];
        snprintf(what, sizeof what, "%s (%s %dx%d)", t[i].what, t[i].fmt, w, h);
        rs_result res = rs_render_fbo_check(what, err);
        if (res != RS_OK) {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            release_targets(r);
            return res;
        }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    r->tw = w;
    r->th = h;
    return rs_gl_check("render: creating targets", err);
}

static size_t target_bytes(const rs_renderer *r)
{
    size_t px = (size_t)r->tw * (size_t)r->th, acc = r->float_rt ? 8 : 4;
    size_t bytes = px * (4 + 4 * acc + 4);
    for (int i = 0; i < RS_LEVEL_DIVS; i++)
        if (r->level_tex[i]) bytes += px * acc >> (2 * i);
    return bytes;
}

// ---- the frame ----

static void stage_mark(rs_renderer *r, int stage, double *t)
{
    if (!r->time_stages) return;
    glFinish();
    double now = rs_time_now();
    if (stage >= 0) r->stats.stage_ms[stage] += (now - *t) * 1000.0;
    *t = now;
}

void rs_render_set_stage_hook(rs_renderer *r, rs_render_stage_fn fn, void *user)
{
    r->stage_hook = fn;
    r->stage_user = fn ? user : NULL;
}

// The hook before stage `next` (RS_STAGE_COUNT: the frame is done); RS_OK to go on.
static rs_result stage_hook(rs_renderer *r, rs_render_stage next, rs_error *err)
{
    if (!r->stage_hook) return RS_OK;
    glFinish();
    if (r->stage_hook(r->stage_user, next)) return RS_OK;
    return rs_fail(err, RS_ERR_ARG, "render: stopped");
}

// The fields a frame depends on (padding aside, which a caller's struct may leave undefined).
static bool same_view(const rs_view *a, const rs_view *b)
{
    const rs_light *la[2] = {&a->key, &a->fill}, *lb[2] = {&b->key, &b->fill};
    for (int i = 0; i < 2; i++)
        if (la[i]->yaw_deg != lb[i]->yaw_deg || la[i]->pitch_deg != lb[i]->pitch_deg ||
            la[i]->intensity != lb[i]->intensity || memcmp(la[i]->color, lb[i]->color, sizeof la[i]->color))
            return false;
    return a->width == b->width && a->height == b->height && a->yaw_deg == b->yaw_deg &&
           a->pitch_deg == b->pitch_deg && a->zoom == b->zoom && a->fov_deg == b->fov_deg && a->pan[0] == b->pan[0] &&
           a->pan[1] == b->pan[1] && a->mode == b->mode && a->pipeline == b->pipeline && a->composite == b->composite &&
           a->exposure == b->exposure && !memcmp(a->background, b->background, sizeof a->background) &&
           a->no_shadows == b->no_shadows && a->hide_makeup == b->hide_makeup && a->rho_s_scale == b->rho_s_scale &&
           a->max_splats == b->max_splats && a->kernel_count == b->kernel_count && a->lod_density == b->lod_density &&
           a->prim == b->prim && a->ambient == b->ambient && a->lighting == b->lighting &&
           a->env_rotate_deg == b->env_rotate_deg && a->env_intensity == b->env_intensity && a->tonemap == b->tonemap &&
           a->linear_output == b->linear_output && a->use_matrices == b->use_matrices &&
           (!a->use_matrices || (!memcmp(a->view_matrix, b->view_matrix, sizeof a->view_matrix) &&
                                 !memcmp(a->proj_matrix, b->proj_matrix, sizeof a->proj_matrix)));
}

void rs_render_invalidate(rs_renderer *r) { r->inc_valid = false; }
uint32_t rs_render_incremental_frames(const rs_renderer *r) { return r->inc_frames; }

// Grows the dirty rectangle by the splats [first, first + count) of the last full frame's prefix, as the
// attribute pass draws them (out to RS_COVERAGE radii), plus 2 pixels: the composite's hole filling reads
// a pixel's 3x3 neighbourhood.
static void mark_dirty(rs_renderer *r, uint32_t first, uint32_t count)
{
    const rs_camera *cam = &r->inc_cam;
    uint32_t end = RS_MIN(first + count, r->inc_count);
    float focal = cam->proj[1][1] * 0.5f * (float)cam->height;  // pixels per unit at view distance 1
    float *d = r->dirty;
    for (uint32_t i = first; i < end; i++) {
        vec4 p = {r->cloud->pos[i][0], r->cloud->pos[i][1], r->cloud->pos[i][2], 1.0f}, v, c;
        glm_mat4_mulv((vec4 *)cam->view, p, v);
        if (v[2] > -1e-6f) continue;  // behind the camera: not drawn
        glm_mat4_mulv((vec4 *)cam->proj, v, c);
        float x = (c[0] / c[3] * 0.5f + 0.5f) * (float)cam->width, y = (c[1] / c[3] * 0.5f + 0.5f) * (float)cam->height;
        float rad = r->inc_radius * focal / -v[2] + 2.0f;
        d[0] = fminf(d[0], x - rad), d[1] = fminf(d[1], y - rad);
        d[2] = fmaxf(d[2], x + rad), d[3] = fmaxf(d[3], y + rad);
    }
}

void rs_render_mark_dirty_sphere(rs_renderer *r, const float pos[3], float radius)
{
    const rs_camera *cam = &r->inc_cam;
    vec4 p = {pos[0], pos[1], pos[2], 1.0f}, v, c;
    glm_mat4_mulv((vec4 *)cam->view, p, v);
    float *d = r->dirty;
    if (v[2] > -radius) {  // reaches the camera plane: the whole target
        d[0] = d[1] = -INFINITY, d[2] = d[3] = INFINITY;
        return;
    }
    glm_mat4_mulv((vec4 *)cam->proj, v, c);
    float focal = cam->proj[1][1] * 0.5f * (float)cam->height;
    float x = (c[0] / c[3] * 0.5f + 0.5f) * (float)cam->width, y = (c[1] / c[3] * 0.5f + 0.5f) * (float)cam->height;
    // The sphere's projection fits within radius / (distance - radius); 2 pixels for the composite's 3x3 reads.
    float rad = radius * focal / (-v[2] - radius) + 2.0f;
    d[0] = fminf(d[0], x - rad), d[1] = fminf(d[1], y - rad);
    d[2] = fmaxf(d[2], x + rad), d[3] = fmaxf(d[3], y + rad);
}

static void clear_dirty(rs_renderer *r)
{
    r->dirty[0] = r->dirty[1] = INFINITY;
    r->dirty[2] = r->dirty[3] = -INFINITY;
}

// Stages 3 and 5 again inside the dirty rectangle, over the last frame's depth, shadow map and D.
static rs_result incremental_frame(rs_renderer *r, rs_frame *f, rs_error *err)
{
    float *d = r->dirty, w = (float)f->cam.width, h = (float)f->cam.height;
    // Clamped to the target before the conversion: an empty rectangle is (inf, -inf), no int.
    int x0 = (int)floorf(RS_CLAMP(d[0], 0.0f, w)), y0 = (int)floorf(RS_CLAMP(d[1], 0.0f, h));
    int x1 = (int)ceilf(RS_CLAMP(d[2], 0.0f, w)), y1 = (int)ceilf(RS_CLAMP(d[3], 0.0f, h));
    clear_dirty(r);
    r->inc_frames++;
    if (x1 <= x0 || y1 <= y0) return RS_OK;  // nothing drawn changed
    rs_result res = RS_OK;
    if (f->shadows) res = rs_render_shadow(r, f, err);  // cached: sets the lookup's matrices and biases
    glEnable(GL_SCISSOR_TEST);
    glScissor(x0, y0, x1 - x0, y1 - y0);
    if (res == RS_OK) res = rs_render_attributes(r, f, err);
    if (res == RS_OK && f->diffuse) {
        rs_diffusion_level levels[RS_PROFILE_MAX];
        rs_render_diffusion_plan(r, f, levels, f->delta_weight);  // the per-pixel weights; D stays
    }
    if (res == RS_OK) res = rs_render_composite(r, f, err);
    glDisable(GL_SCISSOR_TEST);
    return res;
}

rs_result rs_render_frame(rs_renderer *r, const rs_view *view, rs_error *err)
{
    if (!view || view->width <= 0 || view->height <= 0 || view->width > r->caps.max_texture_size ||
        view->height > r->caps.max_texture_size || view->width > RS_IMAGE_MAX_DIM ||
        view->height > RS_IMAGE_MAX_DIM)
        return rs_fail(err, RS_ERR_ARG, "render: view size %dx%d outside 1..%d", view ? view->width : 0,
                       view ? view->height : 0, RS_MIN(r->caps.max_texture_size, RS_IMAGE_MAX_DIM));
    if ((unsigned)view->mode >= RS_MODE_COUNT) return rs_fail(err, RS_ERR_ARG, "render: unknown mode %d", view->mode);
    if (!(view->fov_deg >= RS_VIEW_FOV_MIN_DEG && view->fov_deg <= RS_VIEW_FOV_MAX_DEG))
        return rs_fail(err, RS_ERR_ARG, "render: field of view %g outside %g..%g degrees", view->fov_deg,
                       RS_VIEW_FOV_MIN_DEG, RS_VIEW_FOV_MAX_DEG);
    const float nums[] = {view->yaw_deg, view->pitch_deg, view->zoom, view->pan[0], view->pan[1], view->exposure,
                          view->ambient, view->rho_s_scale, view->key.yaw_deg, view->key.pitch_deg,
                          view->key.intensity, view->fill.yaw_deg, view->fill.pitch_deg, view->fill.intensity,
                          view->env_rotate_deg, view->env_intensity};
    for (size_t i = 0; i < RS_COUNT_OF(nums); i++)
        if (!isfinite(nums[i]) || fabsf(nums[i]) > 1e6f)
            return rs_fail(err, RS_ERR_ARG, "render: view parameter %zu is %g (not a finite, sane number)", i,
                           nums[i]);
    double t_start = rs_time_now(), t = t_start;
    memset(r->stats.stage_ms, 0, sizeof r->stats.stage_ms);
    if (r->time_stages) glFinish();

    rs_frame f;
    rs_render_frame_setup(r, view, &f);
    rs_result res = ensure_targets(r, f.cam.width, f.cam.height, err);
    if (res != RS_OK) return res;

    GLint saved_viewport[4];
    glGetIntegerv(GL_VIEWPORT, saved_viewport);
    if (r->have_frame && r->inc_valid && !r->time_stages && same_view(&f.view, &r->inc_view) &&
        !memcmp(r->inc_regions, r->cloud->hdr.regions, sizeof r->inc_regions)) {
        res = incremental_frame(r, &f, err);
        glDisable(GL_BLEND);
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_TRUE);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glBindVertexArray(0);
        glUseProgram(0);
        glActiveTexture(GL_TEXTURE0);
        glViewport(saved_viewport[0], saved_viewport[1], saved_viewport[2], saved_viewport[3]);
        if (res == RS_OK) res = rs_gl_check("render: incremental frame", err);
        r->stats.frame_ms = (rs_time_now() - t_start) * 1000.0;
        return res;
    }
    stage_mark(r, -1, &t);
    res = stage_hook(r, RS_STAGE_SHADOW, err);
    if (res == RS_OK && f.shadows) res = rs_render_shadow(r, &f, err);
    stage_mark(r, RS_STAGE_SHADOW, &t);
    if (res == RS_OK) res = stage_hook(r, RS_STAGE_VISIBILITY, err);
    if (res == RS_OK) res = rs_render_visibility(r, &f, err);
    stage_mark(r, RS_STAGE_VISIBILITY, &t);
    if (res == RS_OK) res = stage_hook(r, RS_STAGE_ATTRIBUTE, err);
    if (res == RS_OK) res = rs_render_attributes(r, &f, err);
    stage_mark(r, RS_STAGE_ATTRIBUTE, &t);
    rs_diffusion_level levels[RS_PROFILE_MAX];
    int nlevels = 0;
    r->stats.diffusion_splats = 0;
    if (res == RS_OK) res = stage_hook(r, RS_STAGE_DIFFUSION, err);
    if (res == RS_OK && f.diffuse) {
        nlevels = rs_render_diffusion_plan(r, &f, levels, f.delta_weight);
        res = rs_render_diffusion(r, &f, levels, nlevels, err);
    }
    stage_mark(r, RS_STAGE_DIFFUSION, &t);
    if (res == RS_OK) res = stage_hook(r, RS_STAGE_COMPOSITE, err);
    if (res == RS_OK) res = rs_render_composite(r, &f, err);
    stage_mark(r, RS_STAGE_COMPOSITE, &t);
    if (res == RS_OK) res = stage_hook(r, RS_STAGE_COUNT, err);

    // Leave the caller's GL state as it was where it would surprise: blend, depth, viewport, FBO.
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glBindVertexArray(0);
    glUseProgram(0);
    glActiveTexture(GL_TEXTURE0);
    glViewport(saved_viewport[0], saved_viewport[1], saved_viewport[2], saved_viewport[3]);
    if (res == RS_OK) res = rs_gl_check("render: frame", err);
    if (res != RS_OK) return res;

    r->have_frame = true;
    r->inc_valid = true;
    r->inc_view = f.view;
    r->inc_cam = f.cam;
    r->inc_count = f.count;
    r->inc_radius = r->cloud->hdr.radius_max * f.radius_scale * RS_COVERAGE;
    memcpy(r->inc_regions, r->cloud->hdr.regions, sizeof r->inc_regions);
    clear_dirty(r);
    r->stats.splats_drawn = f.count;
    r->stats.face_pixels = f.face_px;
    r->stats.kernel_count = nlevels;
    r->stats.used_points = !f.quads;
    r->stats.float_targets = r->float_rt;
    size_t shadow_bytes = 0;
    for (int i = 0; i < 2; i++) shadow_bytes += (size_t)r->shadow[i].size * (size_t)r->shadow[i].size * 4;
    size_t pick_bytes = (size_t)r->pw * (size_t)r->ph * 8;
    r->stats.gpu_bytes = (size_t)r->cloud->hdr.count * 40 + target_bytes(r) + shadow_bytes + pick_bytes;
    r->stats.frame_ms = (rs_time_now() - t_start) * 1000.0;
    return RS_OK;
}

GLuint rs_render_output_texture(const rs_renderer *r, int *width, int *height)
{
    if (width) *width = r->have_frame ? r->tw : 0;
    if (height) *height = r->have_frame ? r->th : 0;
    return r->have_frame ? r->out_tex : 0;
}

rs_result rs_render_read(rs_renderer *r, rs_image *out, rs_error *err)
{
    if (!r->have_frame) return rs_fail(err, RS_ERR_ARG, "render: no frame rendered yet");
    rs_image img = {0};
    rs_result res = rs_image_create(r->tw, r->th, 4, &img, err);
    if (res != RS_OK) return res;
    glBindFramebuffer(GL_FRAMEBUFFER, r->fbo_out);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, r->tw, r->th, GL_RGBA, GL_UNSIGNED_BYTE, img.pixels);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    res = rs_gl_check("render: reading the frame back", err);
    if (res != RS_OK) {
        rs_image_free(&img);
        return res;
    }
    // GL rows are bottom-first; images are top-first.
    size_t row = (size_t)r->tw * 4;
    uint8_t *tmp = malloc(row);
    if (!tmp) {
        rs_image_free(&img);
        return rs_fail(err, RS_ERR_NOMEM, "render: out of memory");
    }
    for (int y = 0; y < r->th / 2; y++) {
        uint8_t *a = img.pixels + (size_t)y * row, *b = img.pixels + (size_t)(r->th - 1 - y) * row;
        memcpy(tmp, a, row);
        memcpy(a, b, row);
        memcpy(b, tmp, row);
    }
    free(tmp);
    *out = img;
    return RS_OK;
}

rs_result rs_render_image(rs_renderer *r, const rs_view *view, rs_image *out, rs_error *err)
{
    rs_result res = rs_render_frame(r, view, err);
    return res == RS_OK ? rs_render_read(r, out, err) : res;
}

// ---- queries for brushes and the viewer ----

float rs_render_pixels_per_unit(const rs_renderer *r, const rs_view *view, const float pos[3])
{
    rs_view v = view_resolved(view);
    rs_camera cam;
    rs_render_camera(r, &v, &cam);
    vec4 p = {pos[0], pos[1], pos[2], 1.0f}, q;
    glm_mat4_mulv(cam.view, p, q);
    float dist = fmaxf(-q[2], cam.near_z);
    return 1.0f / (cam.px_size * dist);
}

void rs_render_view_dir(const rs_renderer *r, const rs_view *view, const float pos[3], float dir[3])
{
    rs_view v = view_resolved(view);
    rs_camera cam;
    rs_render_camera(r, &v, &cam);
    vec3 d = {cam.eye[0] - pos[0], cam.eye[1] - pos[1], cam.eye[2] - pos[2]};
    glm_vec3_normalize(d);
    dir[0] = d[0], dir[1] = d[1], dir[2] = d[2];
}

void rs_render_view_matrices(const rs_renderer *r, const rs_view *view, float view_m[16], float proj_m[16])
{
    rs_view v = view_resolved(view);
    rs_camera cam;
    rs_render_camera(r, &v, &cam);
    memcpy(view_m, cam.view, sizeof cam.view);
    memcpy(proj_m, cam.proj, sizeof cam.proj);
}

bool rs_render_project(const rs_renderer *r, const rs_view *view, const float pos[3], float px[2])
{
    rs_view v = view_resolved(view);
    rs_camera cam;
    rs_render_camera(r, &v, &cam);
    mat4 vp;
    glm_mat4_mul(cam.proj, cam.view, vp);
    vec4 p = {pos[0], pos[1], pos[2], 1.0f}, c;
    glm_mat4_mulv(vp, p, c);
    if (c[3] <= 1e-6f) return false;
    px[0] = (c[0] / c[3] * 0.5f + 0.5f) * (float)v.width;
    px[1] = (0.5f - c[1] / c[3] * 0.5f) * (float)v.height;
    return true;
}

rs_result rs_render_update_makeup(rs_renderer *r, uint32_t first, uint32_t count, const void *records,
                                  rs_error *err)
{
    uint32_t n = r->cloud->hdr.count;
    if (first > n || count > n - first)
        return rs_fail(err, RS_ERR_ARG, "render: makeup range [%u, %u+%u) outside the %u splats", first, first,
                       count, n);
    if (count == 0) return RS_OK;
    if (!records) return rs_fail(err, RS_ERR_ARG, "render: makeup records missing");
    glBindBuffer(GL_ARRAY_BUFFER, r->vbo_makeup);
    glBufferSubData(GL_ARRAY_BUFFER, (GLintptr)first * (GLintptr)sizeof(rs_makeup_gpu),
                    (GLsizeiptr)count * (GLsizeiptr)sizeof(rs_makeup_gpu), records);
    if (r->inc_valid) mark_dirty(r, first, count);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    return rs_gl_check("render: makeup upload", err);
}

void rs_render_set_makeup_uniforms(rs_renderer *r, const rs_makeup_uniforms *u)
{
    r->makeup_uni = *u;
    r->inc_valid = false;
}

rs_render_stats rs_render_get_stats(const rs_renderer *r) { return r->stats; }
