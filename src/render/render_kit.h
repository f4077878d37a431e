// render_kit.h — the renderer's layer below its stages (STYLE.md rule 15): the state every part shares
// and the toolbox the stages draw with. Not public API: render.h is.
//   Layers, each calling only the ones below it (tests/test_layering.sh checks the objects):
//     render.c            the orchestrator: the renderer object, targets, the frame (stages in order)
//     render_stages.h     the stages of the paper's Fig. 2, one file each: render_shadow.c (1),
//                         render_visibility.c (2), render_attribute.c (3), render_diffusion.c (4),
//                         render_composite.c (5); beside them render_pick.c (the ID buffer),
//                         render_env.c (the environment), render_fine.c (the fine makeup layer)
//     render_kit.h        this: render_view.c (camera, frame parameters, dirty rectangle) and
//                         render_kit.c (programs, textures, FBO check, splat drawing)
// struct rs_renderer is defined here, below the stages, not in render.c: it is the state they all share
// (each stage reads the splat buffers and the frame targets and keeps its own cache in it: shadow maps,
// ID buffer, environment, fine layer, diffusion levels), so no one layer owns it. render.c creates and
// destroys it and calls each stage's release; its own fields are the targets and the incremental frame.
#ifndef RS_RENDER_KIT_H
#define RS_RENDER_KIT_H

#include "formats/env.h"
#include "render/profile.h"
#include "render/render.h"

#include <cglm/cglm.h>

// Programs; the splat programs exist twice (point sprites, instanced quads).
typedef enum rs_prog {
    RS_PROG_SHADOW = 0,
    RS_PROG_VISIBILITY,
    RS_PROG_PICK,
    RS_PROG_ATTRIBUTE,
    RS_PROG_DIFFUSION,
    RS_PROG_SPLAT_COUNT,
    RS_PROG_RESOLVE = RS_PROG_SPLAT_COUNT,
    RS_PROG_REFLECT,        // stage 5's first pass: the face blocking the mirror direction
    RS_PROG_COMPOSITE,
    RS_PROG_IRRADIANCE,     // transform feedback: per-splat irradiance for stage 4
    RS_PROG_EDGES_FIND,     // stage 5's end: the contours' steps (and the picture copied),
    RS_PROG_EDGES,          // then the steps anti-aliased
    RS_PROG_COUNT
} rs_prog;

// Fixed texture units (set once per program when it is linked).
enum {
    RS_UNIT_DEPTH = 0,   // visibility depth (u_depth)
    RS_UNIT_PUSH,        // how far the visibility pass pushed each pixel's depth back (u_push)
    RS_UNIT_SHADOW,      // shadow map (u_shadow_map, compare mode)
    RS_UNIT_ATTR0,       // attribute targets (u_attr0..3)
    RS_UNIT_ATTR1,
    RS_UNIT_ATTR2,
    RS_UNIT_ATTR3,
    RS_UNIT_DIFFUSE,     // D (u_diffuse)
    RS_UNIT_LEVEL,       // one diffusion level's accumulation (u_level)
    RS_UNIT_ENV,         // the environment's prefiltered radiance (u_env_map)
    RS_UNIT_SPEC_LUT,    // the specular lobe's directional albedo (u_spec_lut)
    RS_UNIT_FINE,        // the fine layer's stamps and products (u_fine_data, RGBA32F)
    RS_UNIT_FINE_INDEX,  // the fine layer's grid: cells (start, count) then stamp lists (u_fine_index, R32UI)
    RS_UNIT_FINE_FIELD,  // the region masks' fields stacked along z (u_fine_field, R8 3D, linear)
    RS_UNIT_LAMP_SHADOW, // the environment's other lamps' shadow maps, one atlas (u_lamp_shadow_map)
    RS_UNIT_COLOR,       // the composite's picture before its contours are anti-aliased (u_color)
    RS_UNIT_EDGES,       // the depth steps in it (u_edges, RG8)
    RS_UNIT_REFLECT,     // the face blocking the mirror direction (u_reflect, RGBA32UI, half size)
    RS_UNIT_BODY,        // the cloud as a coarse grid for reflections that leave the frame (u_body, RG32UI 3D)
    RS_UNIT_COUNT
};
_Static_assert(RS_UNIT_COUNT <= RS_RENDER_TEXTURE_UNITS, "render.h's RS_RENDER_TEXTURE_UNITS");

// The fine layer as uploaded (render_fine.c): per-pixel stamps over a model-space grid.
typedef struct rs_render_fine {
    GLuint data_tex, index_tex;
    int data_rows, index_rows;   // texture heights allocated (RS_FINE_TEX_WIDTH wide)
    uint32_t count;              // stamps; 0 = no fine layer
    uint32_t products;           // first product texel
    float origin[3], inv_cell;
    int dim[3];
    rs_makeup_fine_stamp *last;  // the last upload's stamps (the dirty rectangle is their difference)
    uint32_t last_count;
    float *last_products;        // 12 floats per product
    uint32_t last_product_count;
    GLuint field_tex;            // the region fields (rs_makeup_region_field) stacked along z
    const uint8_t *field_value[RS_COSMETIC_REGION_COUNT];  // the fields uploaded (a field never changes)
    float field_box[RS_COSMETIC_REGION_COUNT][8];          // (origin, 1 / voxel), (dims, first slice)
    float field_ramp[RS_COSMETIC_REGION_COUNT][2];         // (threshold, band)
} rs_render_fine;

#define RS_ENV_LAMPS 3  // env_light.glsl's u_env_lamp_* arrays

// The environment as uploaded (render_env.c): radiance and SH scaled by the exposure normalisation.
typedef struct rs_render_env {
    bool on;
    float scale;                 // exposure normalisation (mean front irradiance -> a fixed target)
    float sh[9][3];
    float light_dir[3];          // environment frame, towards the light
    float light_color[3];
    float light_angle;           // radians
    // The environment's other compact lamps (render_env.c find_lamps): taken out of sh, lit exactly and
    // shadow-mapped (render_shadow.c), and out of the uploaded map: reflected exactly; colour 0 where unused.
    float lamp_dir[RS_ENV_LAMPS][3];
    float lamp_color[RS_ENV_LAMPS][3];
    float lamp_angle[RS_ENV_LAMPS];  // angular radius, radians (their reflections' size)
    int levels;
    float level_m[RS_ENV_MAX_LEVELS];
} rs_render_env;

// Disks are drawn (visibility, attributes, shadow map, ID buffer) out to RS_COVERAGE radii; the
// attribute weight stays a Gaussian of the distance in radii, so the extra rim only matters where nothing
// else covers a pixel: random samplings leave gaps of up to ~2 spacings that radii from k-nearest-neighbour
// distances don't close (measured on the 600k head at 1024^2: ~340 pinholes at 1.0, none left at 1.3 but
// single-pixel cracks at grazing creases, which the composite's hole filling takes).
#define RS_COVERAGE 1.3f

// Texture formats of the accumulation targets: RGBA16F when the driver renders to half floats, else the
// documented RGBA8 fallback with pre-scaled sums (render_attribute.c, render_diffusion.c).
#define RS_ATTR_TARGETS 4  // albedo; normal, m; rho_s and layers; bent normal (attribute.frag.glsl)
#define RS_ATTR_WEIGHT_SCALE_RGBA8 0.2f
#define RS_ATTR_WEIGHT_FLOOR_RGBA8 0.15f
#define RS_MIN_WEIGHT_RGBA8 (5.5f / 255.0f)  // attribute sums below this are rounding noise: holes
#define RS_DIFFUSE_SCALE_RGBA8 0.5f  // D stored halved (D reaches ~1.5 with a fill light)

typedef struct rs_camera {
    mat4 view, inv_view;     // model <-> view (rigid: lengths are model units)
    mat4 proj, inv_proj;     // view -> clip, with the pan folded in
    vec3 eye;                // model space
    float near_z, far_z;     // positive distances
    int width, height;
    float px_size;           // size of a pixel at view distance 1, view units (2 tan(fov/2) / height)
    float ppu_max;           // pixels per unit at the nearest point of the cloud's bounding sphere
} rs_camera;

// One Gaussian of the diffusion profile as drawn: stage 4 loops over these (reference: d'Eon's six, with
// identical narrow ones merged; the mobile pipeline: its K fitted Gaussians at coarser LOD).
typedef struct rs_diffusion_level {
    float sigma;        // kernel sigma, model units (sqrt(variance_mm2) / mm_per_unit)
    float weight[3];    // RGB weight of this level in D
    uint32_t count;     // LOD prefix drawn
    bool quads;         // instanced quads (the kernel sprite outgrows point sprites)
    int res_div;        // the level is drawn at 1/res_div of the frame's resolution (1, 2 or 4)
} rs_diffusion_level;

// Level targets exist at full, half and quarter resolution (rs_diffusion_level.res_div 1, 2, 4).
#define RS_LEVEL_DIVS 3
#define RS_IRRADIANCE_BYTES 12  // per splat: E, 3 floats (irradiance.vert.glsl)
#define RS_IRR_KEY 22           // floats in the irradiance pass's key (render_diffusion.c irradiance_key)

// The mobile pipeline's defaults (render_view.c, render_diffusion.c; docs/mobile.md has the measurements).
// Main passes: the LOD prefix nearest (in log) to this many visible splats per pixel of the face's screen
// area (at 512x512 and the default framing: the 145k prefix of the 600k head, ~1.3 drawn splats per face
// pixel), but never more than RS_MOBILE_MAX_LOD_STEPS LOD levels (each ~2x) below the max_splats cap:
// mobile-vs-reference PSNR follows the decimation ratio whatever the view size (on the bundled head at
// 512^2: 2x 45 dB, 4x 42 dB, 8x 38 dB, 16x 34 dB; 16x at 256^2 34 dB too).
#define RS_LOD_DENSITY_DEFAULT 0.3f
#define RS_MOBILE_MAX_LOD_STEPS 2
// An even (Poisson-disk) LOD prefix closes the surface with radii of ~0.5 x sqrt(N / n) x the full
// cloud's k-nearest-neighbour radii (measured: pinholes below 0.5 on the bundled head); the mobile
// pipeline draws 0.55 of that (never less than the full cloud's radii). sqrt(N / n) itself (the
// reference's rule) blurs the decimated image and grows its silhouette: 34.7 instead of 41.8 dB
// against the reference at 512x512 with the 145k prefix.
#define RS_MOBILE_COVER 0.55f
// The environment's specular (env_light.glsl rs_env_specular): one lookup of the prefiltered map from this
// N.V on, a grid of taps below it; the mobile pipeline's grid has no taps across the plane of incidence.
// Mobile: ~3.5 ms less of a 512^2 frame on llvmpipe; 0.0-0.2 dB further from the reference (docs/mobile.md).
#define RS_ENV_ONE_LOOKUP_REFERENCE 0.6f
#define RS_ENV_ONE_LOOKUP_MOBILE 0.55f
// The reference's grid of the cloud for reflections that leave the frame: cells per side over the cloud's
// largest extent (the bundled bust, ~0.3 m: ~5 mm cells; 96 measured the same against the path tracer).
#define RS_BODY_GRID 64
// The key's map: at most this size, and no larger than the output needs (render_shadow.c map_size).
#define RS_SHADOW_SIZE_REFERENCE 4096
#define RS_SHADOW_SIZE_MOBILE 2048
// The PCF filter's grid step is 1.5 texels of a map this size whatever the map's own size, so that
// every pipeline casts the same penumbra (render_shadow.c).
#define RS_SHADOW_SIZE_PCF 2048

// A shadow map and what it was drawn for (cached while the light, LOD and radius stay the same); one per
// pipeline so that switching pipelines (the bench's interleaved frames, the viewer's toggle) redraws none.
typedef struct rs_shadow_map {
    GLuint tex, fbo;
    int size;
    mat4 vp;                 // model -> light clip
    float key[6];            // light dir, count, radius scale, valid
    float radius;            // typical splat radius in the map, model units
} rs_shadow_map;

// The environment's other lamps' shadow maps (render_shadow.c): one depth array, a layer per lamp,
// shared by both pipelines (drawn from one LOD prefix whatever the pipeline), cached per lamp.
#define RS_LAMP_SHADOW_SIZE 1024       // a layer's side, at most
#define RS_LAMP_SHADOW_SPLATS 160000   // the LOD prefix drawn (at most)
typedef struct rs_lamp_shadows {
    GLuint tex, fbo;
    int size;                          // a layer's side
    mat4 vp[RS_ENV_LAMPS];             // model -> the tile's light clip
    float key[RS_ENV_LAMPS][6];        // as rs_shadow_map.key
    float radius;                      // typical splat radius in the maps, model units
} rs_lamp_shadows;

typedef struct rs_frame {
    rs_view view;            // with zero fields replaced by their defaults
    rs_camera cam;
    uint32_t count;          // splats in the main passes (an LOD prefix)
    float radius_scale;      // reference: rs_splat_lod_radius_scale(count); mobile: see RS_MOBILE_COVER
    bool mobile;             // RS_PIPELINE_MOBILE
    float face_px;           // mobile: estimated screen area of the face, pixels (render_view.c face_pixels)
    int shadow_slot;         // which of the renderer's shadow maps (0 reference, 1 mobile)
    bool quads;              // main passes drawn as instanced quads
    float eps;               // visibility push along the view ray, model units
    bool lit;                // mode needs lights (shadow map, irradiance)
    bool diffuse;            // mode needs stage 4
    bool shadows;            // key light shadow-mapped
    vec3 key_dir, key_color;     // view space, towards the light; linear RGB * intensity
    vec3 fill_dir, fill_color;   // fill_color zero when off
    vec3 ambient;
    mat4 shadow_matrix;      // view space -> light clip space
    mat3 shadow_normals;     // view-space normals -> light clip space (inverse transpose)
    float shadow_bias, shadow_texel;
    bool lamp_shadows;                            // the environment's lamps shadow-mapped too
    mat4 lamp_shadow_matrix[RS_ENV_LAMPS];        // view space -> a lamp's tile's light clip space
    mat3 lamp_shadow_normals[RS_ENV_LAMPS];
    vec3 lamp_shadow_dir[RS_ENV_LAMPS];           // view space, towards the lamp
    float lamp_shadow_on[RS_ENV_LAMPS];           // 1: the lamp has a tile
    float lamp_shadow_bias;
    float delta_weight[3];   // profile weight taken by per-pixel irradiance (stage 4's narrow Gaussians)
    bool env_on;             // lit by the renderer's environment (its light is then the key light)
    mat3 env_from_view;      // view-space directions -> the environment's frame (rotation included)
    float key_widen;         // half the key light's angular radius, radians (0: a point light)
} rs_frame;

struct rs_renderer {
    const rs_splat_cloud *cloud;
    rs_gl_caps caps;
    bool float_rt;
    bool time_stages;
    rs_render_stage_fn stage_hook;  // rs_render_set_stage_hook
    void *stage_user;
    float radius_median;        // model units, full cloud
    float bound_centre[3], bound_radius;  // bounding sphere of the quantization box

    GLuint vbo_splats, vbo_makeup;
    GLuint vbo_irradiance;      // per splat E (RS_IRRADIANCE_BYTES), the irradiance pass's (render_diffusion.c)
    GLuint vao_points, vao_quads, vao_empty;
    GLuint vao_feedback;        // the splats alone (the irradiance buffer is the feedback target there)
    GLuint prog[RS_PROG_COUNT][2];   // [kind][quads]; 0 until first use

    // Frame targets (width x height).
    int tw, th;
    GLuint depth_tex, push_tex, attr_tex[RS_ATTR_TARGETS], diffuse_tex;
    GLuint pre_tex;             // the composite's picture, before its contours are anti-aliased
    GLuint out_steps_tex[2];    // the output, and the depth steps in it (RG8; edges_find.frag.glsl)
    GLuint mask_tex;            // depth 0 where a pixel has a step: the edges pass shades only those
    GLuint reflect_tex;         // the face blocking the mirror direction, half size (RGBA32UI; reflect.frag.glsl)
    GLuint fbo_vis, fbo_attr, fbo_diffuse, fbo_reflect, fbo_pre, fbo_edges, fbo_out;
    GLuint level_tex[RS_LEVEL_DIVS], fbo_level[RS_LEVEL_DIVS];  // full, half, quarter size; made on first use
    bool have_frame;
    // What the splats' light reads besides the frame's lights: bumped by every shadow map drawn and every
    // environment set (render_shadow.c, render_env.c), so that kept irradiance made before is not reused.
    uint32_t light_serial;
    // The irradiance pass's key (render_diffusion.c): the lights in model space, the LOD prefix, and
    // light_serial when it ran. Kept E: 0 none, 1 the splats within irr_reach of what irr_view / irr_proj
    // see, 2 every splat of the prefix (reused while the key holds).
    float irr_key[RS_IRR_KEY], irr_reach;
    uint32_t irr_serial;
    int irr_state;
    mat4 irr_view, irr_proj;

    // Shadow maps (reference, mobile), re-rendered only when the light or the LOD changes.
    rs_shadow_map shadow[2];
    rs_lamp_shadows lamp_shadow;  // the environment's other lamps, both pipelines
    float area_total;           // the cloud's surface area, model units^2 (render_view.c face_pixels)

    // ID buffer, re-rendered only when the view changes.
    int pw, ph;
    GLuint pick_tex, pick_depth, fbo_pick;
    uint32_t *pick_ids;         // the ID buffer read back once per view (rows bottom-first): picks are lookups
    rs_view pick_view;
    bool pick_valid;

    rs_makeup_uniforms makeup_uni;  // makeup.glsl's colour range
    rs_render_fine fine;            // render_fine.c

    rs_render_env env;          // render_env.c
    GLuint env_tex, lut_tex;
    GLuint body_tex;            // render_env.c rs_render_env_body: the cloud's grid, RS_BODY_GRID^3 RG32UI
    float body_lo[3], body_cell; // the grid's corner and cell size, model units

    // Incremental frames (render.c): the last full frame's view and what it drew; makeup uploads since
    // then mark the screen rectangle their splats cover, and the next frame of the same view re-runs
    // only stages 3 and 5 inside it (D does not depend on albedo or finish: F = A (D + S)).
    bool inc_valid;
    rs_view inc_view;
    rs_camera inc_cam;
    uint32_t inc_count;
    float inc_radius;           // the frame's largest drawn splat reach, model units
    rs_region_info inc_regions[RS_SPLAT_MAX_REGIONS];  // the region table the frame used (callers may edit it)
    float dirty[4];             // x0, y0, x1, y1 in target pixels (GL, bottom-left origin); x0 > x1: none
    uint32_t inc_frames;        // incremental frames drawn (stats, tests)

    // Mobile profile cache, one per K (a fit takes milliseconds to tens of milliseconds).
    rs_profile fit[RS_PROFILE_FIT_MAX + 1];
    float fit_footprint[RS_PROFILE_FIT_MAX + 1];  // 0: none yet

    rs_render_stats stats;
};

// render_view.c
void rs_render_frame_setup(const rs_renderer *r, const rs_view *view, rs_frame *f);
void rs_render_camera(const rs_renderer *r, const rs_view *view, rs_camera *cam);
// Quads when a sphere of radius `radius` (model units) at the nearest depth outgrows point sprites.
bool rs_render_needs_quads(const rs_renderer *r, const rs_frame *f, float radius);
// Grows the incremental frame's dirty rectangle by a model-space sphere's screen footprint.
void rs_render_mark_dirty_sphere(rs_renderer *r, const float pos[3], float radius);

// render_kit.c
rs_result rs_render_program(rs_renderer *r, rs_prog kind, bool quads, GLuint *out, rs_error *err);
// Uniforms every splat program shares: transform, sprite placement, LOD radius, culling.
void rs_render_splat_uniforms(GLuint prog, const mat4 view, const mat4 proj, const mat4 inv_proj, int w, int h,
                              bool persp, float radius_scale, float cull_cos, float point_max);
void rs_render_draw_splats(const rs_renderer *r, uint32_t count, bool quads);
rs_result rs_render_fbo_check(const char *what, rs_error *err);
GLuint rs_render_texture(GLenum internal_format, int w, int h);
void rs_render_bind_texture(int unit, GLuint tex);

static inline GLint rs_uloc(GLuint prog, const char *name) { return glGetUniformLocation(prog, name); }

#endif
