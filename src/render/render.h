// render.h — the splat renderer: the paper's five stages (shadow map, visibility splatting, attribute
// splatting, splat-based diffusion, composite F = A(D + S)) in a reference and a mobile pipeline.
//
// Does: upload a splat cloud (the packed 16-byte records, as is) and its makeup layer (12-byte records);
// render a view into the renderer's own RGBA8 output texture (headless and windowed alike); read it
// back; pick the splat under a pixel through an ID buffer; update makeup records by sub-range.
// Does not: create the GL context (gl/gl.h), handle input, or own the makeup layer's CPU state.
// Stage code lives in the file named after it: render_shadow.c, render_visibility.c,
// render_attribute.c, render_diffusion.c, render_composite.c; render_pick.c is the ID buffer.
//
//   rs_renderer *r;
//   if (rs_render_create(&(rs_render_desc){.cloud = cloud, .caps = rs_gl_get_caps(gl)}, &r, &err)) return 1;
//   rs_view v = rs_view_defaults();  v.width = v.height = 512;  v.mode = RS_MODE_FULL;
//   rs_image img = {0};
//   if (rs_render_image(r, &v, &img, &err) == RS_OK) rs_image_write_png("face.png", &img, &err);
//   rs_render_destroy(r);
#ifndef RS_RENDER_H
#define RS_RENDER_H

#include "core/core.h"
#include "gl/gl.h"
#include "core/image.h"
#include "formats/env.h"
#include "makeup/makeup.h"
#include "splat/splat.h"

// Largest render-target memory a frame may ask for (depth, attributes, diffusion, output, ID buffer).
#define RS_RENDER_MAX_TARGET_BYTES (1536.0 * 1024 * 1024)
// Texture units a frame binds, 0 .. RS_RENDER_TEXTURE_UNITS - 1 (2D, 3D and 2D-array targets), and leaves
// empty: what an embedding that keeps its host's bindings saves.
#define RS_RENDER_TEXTURE_UNITS 19

typedef enum rs_render_mode {
    RS_MODE_FULL = 0,   // subsurface + specular (paper Fig. 7 right)
    RS_MODE_ALBEDO,     // no lighting (Fig. 7 left)
    RS_MODE_DIFFUSE,    // subsurface only (Fig. 7 middle): A * D
    RS_MODE_SPECULAR,   // S alone (debug)
    RS_MODE_NORMALS,    // interpolated normals as colour (debug)
    RS_MODE_REGIONS,    // face regions as flat colours (debug)
    RS_MODE_SHADOW,     // light visibility from the shadow map (debug)
    RS_MODE_LOD,        // splat LOD level as colour (debug)
    RS_MODE_IRRADIANCE, // plain per-pixel N.L * shadow, no diffusion (the test baseline for diffusion)
    RS_MODE_COUNT
} rs_render_mode;

typedef enum rs_pipeline {
    RS_PIPELINE_REFERENCE = 0,  // six Gaussians, all splats: the quality bar
    RS_PIPELINE_MOBILE,         // LOD decimation + reduced kernel count, matched within a stated tolerance
} rs_pipeline;

typedef enum rs_composite {
    RS_COMPOSITE_DEFAULT = 0,   // PAPER under the paper's lights, PHYSICAL under an environment
    RS_COMPOSITE_PAPER,         // F = A (D + S), paper eq. 1
    RS_COMPOSITE_PHYSICAL,      // F = A D + S (specular not tinted by albedo: a dielectric's white highlight)
} rs_composite;

typedef enum rs_splat_prim {
    RS_PRIM_AUTO = 0,           // point sprites when the needed size fits GL_ALIASED_POINT_SIZE_RANGE
    RS_PRIM_POINTS,
    RS_PRIM_QUADS,              // instanced screen-aligned quads
} rs_splat_prim;

// Where the light comes from (rs_view.lighting).
typedef enum rs_lighting {
    RS_LIGHTING_ENV = 0,        // the renderer's environment (rs_render_set_env): its brightest region as
                                // the shadowed key light, the rest as SH irradiance and prefiltered
                                // radiance; without one, the lights below
    RS_LIGHTING_LIGHTS,         // key + fill + ambient only (the paper's single lamp: `--env paper`)
} rs_lighting;

typedef enum rs_tonemap {
    RS_TONEMAP_DEFAULT = 0,     // CLAMP under the paper's lights, FILMIC under an environment
    RS_TONEMAP_FILMIC,          // ACES filmic fit after exposure: HDR light rolls off instead of clipping
    RS_TONEMAP_CLAMP,           // exposure then clamp to 0..1 (the paper's figures)
} rs_tonemap;

typedef struct rs_light {
    float yaw_deg, pitch_deg;   // direction the light comes FROM, in the face frame (0,0 = from the front)
    float color[3];             // linear RGB; zero means white
    float intensity;            // zero means 1 for the key light
} rs_light;

typedef struct rs_view {
    int width, height;          // pixels
    // Camera orbiting the face centre in the face frame (yaw 0, pitch 0: frontal).
    float yaw_deg, pitch_deg;
    float zoom;                 // 1: the face height fills ~80% of the view height; 2: twice as close
    float fov_deg;              // vertical field of view
    float pan[2];               // screen-space pan, fractions of the view height
    rs_light key;
    rs_light fill;              // second light; used when fill.intensity > 0
    rs_render_mode mode;
    rs_pipeline pipeline;
    rs_composite composite;
    float exposure;             // linear multiplier before sRGB encoding
    float background[3];        // sRGB 0..1
    bool no_shadows;
    bool hide_makeup;           // render the bare face (before/after split)
    float rho_s_scale;          // multiplies every rho_s (tests, paper Fig. 11); 0 means 1
    uint32_t max_splats;        // cap on the LOD prefix drawn (0: pipeline decides)
    int kernel_count;           // mobile pipeline: K Gaussians (0: default, 3)
    float lod_density;          // mobile pipeline: main passes draw the LOD prefix giving about this many
                                // visible splats per pixel of the face's screen area, at most 2 LOD
                                // levels (4x) below max_splats (0: default 0.3; docs/mobile.md)
    rs_splat_prim prim;         // primitive choice (AUTO by caps)
    float ambient;              // uniform sky irradiance added to every splat (linear, unshadowed); 0: none
    rs_lighting lighting;       // ENV (default): key, fill and ambient above are ignored when an environment is set
    float env_rotate_deg;       // the environment turned about the face's up axis (+: its light moves like +yaw)
    float env_intensity;        // multiplies the environment (after its normalisation); 0 means 1
    rs_tonemap tonemap;
    bool linear_output;         // debug/tests: write linear values (no sRGB encoding, clamped to 0..1)
    bool sharp_contours;        // tests: no edges pass (one surface per pixel; the outline the composite's 3x3 rule)
    // A host's camera instead of the orbit one (yaw, pitch, zoom, fov, pan ignored): model -> eye (rigid)
    // and a perspective eye -> clip, column-major (rouge.h rouge_view.use_matrices; checked by the caller).
    bool use_matrices;
    float view_matrix[16], proj_matrix[16];
} rs_view;

// Defaults: 512x512, frontal, zoom 1, fov 30, key light from upper left-front (yaw -35, pitch 30), fill
// off, ambient 0.05, full mode, reference pipeline, paper composite, exposure 1, dark grey background.
rs_view rs_view_defaults(void);

typedef struct rs_render_desc {
    const rs_splat_cloud *cloud;     // kept by pointer: must outlive the renderer
    const rs_gl_caps *caps;
    bool force_no_float_targets;     // test the RGBA8 fallback path on drivers that have float targets
    bool time_stages;                // glFinish after each stage and time it (rs_render_stats.stage_ms)
} rs_render_desc;

typedef struct rs_renderer rs_renderer;

// The paper's five stages (Fig. 2), for per-stage timings.
typedef enum rs_render_stage {
    RS_STAGE_SHADOW = 0,
    RS_STAGE_VISIBILITY,
    RS_STAGE_ATTRIBUTE,
    RS_STAGE_DIFFUSION,
    RS_STAGE_COMPOSITE,  // with its last step, the contours anti-aliased (rs_render_edges)
    RS_STAGE_COUNT
} rs_render_stage;

typedef struct rs_render_stats {
    uint32_t splats_drawn;           // main passes
    uint32_t diffusion_splats;       // summed over diffusion levels
    bool irradiance_kept;            // stage 4 reused the splats' irradiance of an earlier frame (same lights)
    int kernel_count;
    bool used_points;                // point sprites (true) or instanced quads (false)
    bool float_targets;
    size_t gpu_bytes;                // buffers + textures owned by the renderer
    double stage_ms[RS_STAGE_COUNT]; // last frame, glFinish-timed (desc.time_stages); 0 otherwise
    double frame_ms;                 // last frame's rs_render_frame wall time (glFinish-timed if time_stages)
    double level_ms[6];              // stage 4 per drawn Gaussian level, same timing (kernel_count entries)
    float face_pixels;               // mobile: the face's estimated screen area that chose the LOD prefix
} rs_render_stats;

rs_result rs_render_create(const rs_render_desc *desc, rs_renderer **out, rs_error *err);
void rs_render_destroy(rs_renderer *r);

// Renders into the renderer's output texture (resized to the view as needed).
rs_result rs_render_frame(rs_renderer *r, const rs_view *view, rs_error *err);
// A hook called as a full frame (not an incremental one) begins each of its stages, and once more with
// RS_STAGE_COUNT when the frame is done. A first frame's stages also compile their shaders and make the
// shadow map: seconds on a software GPU, which a loading screen wants to show. The GL work queued so far
// is finished before each call (so the call sees real progress). Returning false stops the frame there:
// rs_render_frame fails with RS_ERR_ARG "render: stopped" and the last complete frame stays the last.
// NULL removes the hook.
typedef bool (*rs_render_stage_fn)(void *user, rs_render_stage next);
void rs_render_set_stage_hook(rs_renderer *r, rs_render_stage_fn fn, void *user);
// The RGBA8 output texture of the last frame (for the viewer to draw), and its size.
GLuint rs_render_output_texture(const rs_renderer *r, int *width, int *height);
// Reads the last frame back into a new RGBA image (rows top-first).
rs_result rs_render_read(rs_renderer *r, rs_image *out, rs_error *err);
// rs_render_frame + rs_render_read.
rs_result rs_render_image(rs_renderer *r, const rs_view *view, rs_image *out, rs_error *err);

// ID buffer: the visible splat under pixel (x, y) (top-left origin) for this view, and (hit, may be NULL)
// the point on that splat's disk under the pixel. False on background.
bool rs_render_pick(rs_renderer *r, const rs_view *view, float x_px, float y_px, uint32_t *splat_index,
                    float hit[3]);
// Pixels per model unit at a model-space point for this view (brush size on screen).
float rs_render_pixels_per_unit(const rs_renderer *r, const rs_view *view, const float pos[3]);
// Unit vector from a model-space point towards the camera.
void rs_render_view_dir(const rs_renderer *r, const rs_view *view, const float pos[3], float dir[3]);
// The camera's model -> eye and eye -> clip matrices for this view, column-major.
void rs_render_view_matrices(const rs_renderer *r, const rs_view *view, float view_m[16], float proj_m[16]);
// Projects a model-space point to pixels (top-left origin); false when behind the camera.
bool rs_render_project(const rs_renderer *r, const rs_view *view, const float pos[3], float px[2]);

// Makeup layer records (rs_makeup_gpu, 12 bytes each) for splats [first, first + count). The next frame
// of an unchanged view redraws only the attribute and composite passes inside the screen rectangle these
// splats cover (the result equals a full frame's); anything else (view, environment, makeup uniforms)
// makes it a full frame.
rs_result rs_render_update_makeup(rs_renderer *r, uint32_t first, uint32_t count, const void *records,
                                  rs_error *err);

// The makeup shader's uniforms (rs_makeup_get_uniforms: the face's colour range the pigment is clamped
// into). Call once after creating the makeup layer; until then the range is 0..1.
void rs_render_set_makeup_uniforms(rs_renderer *r, const rs_makeup_uniforms *u);

// The fine layer (rs_makeup_fine_stamps; cosmetics from mk's log), evaluated per pixel in the composite.
// Stamps that differ from the last call's (usually the new tail: one stamp) mark their screen rectangle
// dirty, so a stamp stays incremental; a changed product list makes the next frame a full one.
rs_result rs_render_update_fine(rs_renderer *r, const rs_makeup_fine_stamp *stamps, uint32_t count,
                                const rs_makeup *mk, rs_error *err);

rs_render_stats rs_render_get_stats(const rs_renderer *r);

// Uploads a lighting environment (formats/env.h; not kept: the renderer copies what it needs) that views
// with lighting RS_LIGHTING_ENV use; NULL removes it. Its exposure is normalised so that every
// environment lights the front of the face about equally (render_env.c).
rs_result rs_render_set_env(rs_renderer *r, const rs_env *env, rs_error *err);
bool rs_render_has_env(const rs_renderer *r);

// The next frame is drawn in full (tests of incremental frames; nothing else needs it).
void rs_render_invalidate(rs_renderer *r);
// Frames drawn incrementally so far (a makeup change of an unchanged view).
uint32_t rs_render_incremental_frames(const rs_renderer *r);

// Splats the main passes would draw for this view: the max_splats cap, and in the mobile pipeline the
// LOD prefix chosen by lod_density from the face's screen area (cheap: a few thousand dot products).
// The viewer's adaptive ladder starts from it and coarsens from there while interacting.
uint32_t rs_render_auto_splats(const rs_renderer *r, const rs_view *view);

#endif
