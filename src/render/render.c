// render.c — the orchestrator: the renderer object (GPU buffers, targets), and the frame that runs the
// paper's five stages in order (Fig. 2): shadow map, visibility, attributes, diffusion, composite.
// Pass order and what each reads: (1) shadow map (splats from the light); (2) visibility depth; (3)
// attributes: per-splat albedo with the makeup's splat layer composed in (makeup.glsl), normal, m, rho_s,
// ao, coat, flakes, depth-tested against (2); (4) diffusion of per-splat irradiance into D (independent of
// albedo and finish); (5) composite: normalises (3), composes the makeup's fine layer per pixel at the
// surface point from (2) (render_fine.c: stamps + grid in textures never attached to a framebuffer), then
// F = A (D + S). A stamp's frame re-runs (3) and (5) only, inside its rectangle (incremental_frame).
// Layering (STYLE.md rule 15): this file sits above the stages (render_stages.h), which sit above the kit
// (render_kit.h: state, camera and frame in render_view.c, GL toolbox in render_kit.c); only this file calls
// the stages, and no stage calls into it (tests/test_layering.sh checks the objects).
#include "render/render_stages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

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
    glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, RS_IRRADIANCE_BYTES, (void *)0);
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
    size_t bytes_irradiance = (size_t)c->hdr.count * RS_IRRADIANCE_BYTES;  // < bytes_splats
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)bytes_irradiance, NULL, GL_DYNAMIC_COPY);
    glGenVertexArrays(1, &r->vao_points);
    glGenVertexArrays(1, &r->vao_quads);
    glGenVertexArrays(1, &r->vao_empty);
    glGenVertexArrays(1, &r->vao_feedback);
    setup_vao(r, r->vao_points, 0, false);
    setup_vao(r, r->vao_quads, 1, false);
    setup_vao(r, r->vao_feedback, 0, true);
    r->stats.gpu_bytes = bytes_splats + bytes_irradiance + bytes_makeup;
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
    GLuint fbos[] = {r->fbo_vis, r->fbo_attr, r->fbo_diffuse, r->fbo_reflect, r->fbo_pre, r->fbo_edges, r->fbo_out};
    glDeleteFramebuffers((GLsizei)RS_COUNT_OF(fbos), fbos);
    GLuint texs[] = {r->depth_tex, r->push_tex, r->diffuse_tex, r->pre_tex, r->out_steps_tex[0], r->out_steps_tex[1],
                     r->mask_tex, r->reflect_tex};
    glDeleteTextures((GLsizei)RS_COUNT_OF(texs), texs);
    glDeleteTextures(RS_ATTR_TARGETS, r->attr_tex);
    rs_render_level_release(r);
    r->fbo_vis = r->fbo_attr = r->fbo_diffuse = r->fbo_reflect = r->fbo_pre = r->fbo_edges = r->fbo_out = 0;
    r->depth_tex = r->push_tex = 0;
    memset(r->attr_tex, 0, sizeof r->attr_tex);
    r->diffuse_tex = r->pre_tex = r->out_steps_tex[0] = r->out_steps_tex[1] = r->mask_tex = r->reflect_tex = 0;
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

// Render targets of a w x h frame: depth and its push, four attribute targets, diffuse, the reflections'
// blocking (half size, 16 B), the composite's picture, the output (the picture's depth steps
// anti-aliased), the steps and their mask, the reduced-resolution diffusion levels (at most 4/3 of one
// accumulation target) and the ID buffer (R32UI + depth). llvmpipe keeps all of it in CPU memory, so
// this is what a frame size costs the machine.
static double target_estimate(int w, int h, bool float_rt)
{
    double px = (double)w * h, acc = float_rt ? 8 : 4;
    return px * (4 + 1 + (RS_ATTR_TARGETS - 1) * acc + 4 + acc + 4 + 4 + 4 + 2 + 2 + acc * 4.0 / 3.0 + 8);
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
    r->push_tex = rs_render_texture(GL_R8, w, h);
    // The bent normal's target is RGBA8 whatever the others are (attribute.frag.glsl).
    for (int i = 0; i < RS_ATTR_TARGETS; i++) r->attr_tex[i] = rs_render_texture(i < 3 ? acc : GL_RGBA8, w, h);
    r->diffuse_tex = rs_render_texture(acc, w, h);
    r->reflect_tex = rs_render_texture(GL_RGBA32UI, (w + 1) / 2, (h + 1) / 2);
    r->pre_tex = rs_render_texture(GL_RGBA8, w, h);
    r->out_steps_tex[0] = rs_render_texture(GL_RGBA8, w, h);
    r->out_steps_tex[1] = rs_render_texture(GL_RG8, w, h);
    r->mask_tex = rs_render_texture(GL_DEPTH_COMPONENT16, w, h);
    const char *acc_name = r->float_rt ? "RGBA16F" : "RGBA8";
    struct {
        GLuint *fbo;
        const GLuint *colour;
        int n;
        GLuint depth;
        const char *what;
        const char *fmt;
    } t[] = {
        {&r->fbo_vis, &r->push_tex, 1, r->depth_tex, "visibility target", "DEPTH_COMPONENT32F + R8"},
        {&r->fbo_attr, r->attr_tex, RS_ATTR_TARGETS, r->depth_tex, "attribute targets", acc_name},
        {&r->fbo_diffuse, &r->diffuse_tex, 1, 0, "diffuse target", acc_name},
        {&r->fbo_reflect, &r->reflect_tex, 1, 0, "reflections target", "RGBA32UI, half size"},
        {&r->fbo_pre, &r->pre_tex, 1, 0, "composite target", "RGBA8"},
        {&r->fbo_edges, r->out_steps_tex, 2, r->mask_tex, "depth steps targets", "RGBA8 + RG8 + DEPTH_COMPONENT16"},
        {&r->fbo_out, r->out_steps_tex, 1, r->mask_tex, "output target", "RGBA8 + DEPTH_COMPONENT16"},
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
    // depth, push, attributes, D, the reflections' blocking, the composite's picture, the output, its
    // steps and their mask
    size_t bytes = px * (4 + 1 + (RS_ATTR_TARGETS - 1) * acc + 4 + acc + 4 + 4 + 2 + 2) +
                   (size_t)((r->tw + 1) / 2) * (size_t)((r->th + 1) / 2) * 16;
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
           a->linear_output == b->linear_output && a->sharp_contours == b->sharp_contours &&
           a->use_matrices == b->use_matrices &&
           (!a->use_matrices || (!memcmp(a->view_matrix, b->view_matrix, sizeof a->view_matrix) &&
                                 !memcmp(a->proj_matrix, b->proj_matrix, sizeof a->proj_matrix)));
}

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

static void clear_dirty(rs_renderer *r)
{
    r->dirty[0] = r->dirty[1] = INFINITY;
    r->dirty[2] = r->dirty[3] = -INFINITY;
}

// Stages 3 and 5 again inside the dirty rectangle (the reflections' pass a little around it), over the
// last frame's depth, shadow map and D.
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
    // The skin the face's blocked reflections see there was painted too.
    const int rect[4] = {x0, y0, x1, y1};
    if (res == RS_OK) res = rs_render_reflections(r, f, rect, err);
    glScissor(x0, y0, x1 - x0, y1 - y0);
    if (res == RS_OK) res = rs_render_composite(r, f, err);
    // An output pixel mixes its 4-neighbours' colours.
    glScissor(x0 - 1, y0 - 1, x1 - x0 + 2, y1 - y0 + 2);
    if (res == RS_OK) res = rs_render_edges(r, f, err);
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
    r->stats.irradiance_kept = false;  // until stage 4 says so (an incremental frame does not run it)
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
    // The reference's reflections that leave the frame march the cloud's grid (built at the first such frame).
    if (res == RS_OK && f.env_on && !f.mobile) res = rs_render_env_body(r, err);
    if (res == RS_OK) res = rs_render_reflections(r, &f, NULL, err);
    if (res == RS_OK) res = rs_render_composite(r, &f, err);
    if (res == RS_OK) res = rs_render_edges(r, &f, err);
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
    shadow_bytes += (size_t)r->lamp_shadow.size * (size_t)r->lamp_shadow.size * 4 * RS_ENV_LAMPS;  // a layer each
    size_t pick_bytes = (size_t)r->pw * (size_t)r->ph * 8;
    size_t body_bytes = r->body_tex ? (size_t)RS_BODY_GRID * RS_BODY_GRID * RS_BODY_GRID * 8 : 0;
    r->stats.gpu_bytes = (size_t)r->cloud->hdr.count * 40 + target_bytes(r) + shadow_bytes + pick_bytes + body_bytes;
    r->stats.frame_ms = (rs_time_now() - t_start) * 1000.0;
    return RS_OK;
}

GLuint rs_render_output_texture(const rs_renderer *r, int *width, int *height)
{
    if (width) *width = r->have_frame ? r->tw : 0;
    if (height) *height = r->have_frame ? r->th : 0;
    return r->have_frame ? r->out_steps_tex[0] : 0;
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
