// render_view.c — from an rs_view to what the stages draw with, below the stages (render_kit.h): the
// camera, the frame's parameters (LOD prefix, radii, primitive, lights, environment frame), the camera
// queries of the public API, and the dirty rectangle that uploads grow for the next incremental frame.
// Calls nothing above it: no stage, nothing in render.c.
#include "render/render_kit.h"

#include <math.h>
#include <string.h>

#define DEG2RAD(d) ((d) * 0.017453292519943295f)

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

// ---- the next incremental frame (render.c incremental_frame) ----

void rs_render_invalidate(rs_renderer *r) { r->inc_valid = false; }

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
