// rouge.h — embed rouge: realistic skin rendering of a point-sampled face scan (the paper's subsurface
// scattering + measured specular) and touch makeup painting on it, in your own OpenGL ES 3 context.
//
// DOES:
//   - load a face (.rsf, from a file, memory, or a rouge_stream still arriving: a preview of its coarse LOD
//     levels first) into a rouge_face that owns the splat cloud, the renderer, the makeup layer and the
//     painting session, reporting progress to a callback that may cancel; lighting environments from
//     the bundled files, a .rse path, or memory (rouge_face_add_environment);
//   - render through its own orbit camera or the view and projection matrices of yours, at a pixel
//     ratio of your window units (pointer events stay in your window's coordinates);
//   - render it into your current GLES 3.0 context: into the framebuffer you have bound (rouge_face_draw),
//     or into an RGBA8 texture it owns (rouge_face_render + rouge_face_texture); every GL state it
//     touches (framebuffers, viewport, program, VAO, buffers, textures and samplers on every unit it
//     uses, blend/depth/scissor/stencil/cull, depth range, clear values, masks, the transform feedback
//     object, the whole pack and unpack pixel-store state) is restored before it returns; your scissor,
//     sampler objects, depth range, pixel-store settings and an sRGB framebuffer (it writes so the
//     picture is encoded once) do not change what it draws or reads;
//   - take pointer / touch events (ids, pressure, time) and paint: smoothing, stamp spacing, picking
//     through an ID buffer, one- and two-finger navigation; brush, eraser, smudge and blend tools,
//     mirror, undo / redo / clear;
//   - save and load looks (the makeup) as files or memory, list the products in one (look_info), show a
//     second look beside the painted one;
//     custom products (colour, finish, coverage) on the brush; record and replay stroke files;
//   - report capabilities of a context you made (rouge_query_caps), picks and statistics.
// DOES NOT:
//   - create windows or contexts, or read input devices (your app, GLFW, SDL, Android... does; see
//     examples/embed_headless.c for EGL and examples/glfw_painter.c for GLFW);
//   - print, exit, or keep global state: every failure is a rouge_result plus a one-line message in
//     the rouge_error you pass (may be NULL);
//   - block: except the file functions (they read / write files) and rouge_face_create (parses the face,
//     compiles shaders), calls return after queueing GL work; rouge_face_read_rgba, rouge_face_write_png
//     and rouge_face_pick wait for the GPU.
//   - work on several threads at once: call a face from the thread whose context is current, the
//     context it was created in, for its whole life.
//
// Structs are options: their zero value means the documented default (so `(rouge_view){0}` is the
// default view, `(rouge_brush){.cosmetic = "blush"}` a blush with its own size and opacity). Always
// zero-initialise the structs you pass (`= {0}` or designated initialisers): a field added later then
// keeps the behaviour you built against.
//
// Rules every function keeps:
//   - NULL: a NULL face or stream returns ROUGE_ERR_ARG (false, 0 or a zero struct where a function
//     returns those; void functions do nothing). `err` and the `out` of rouge_face_pointer and
//     rouge_face_pick may be NULL; so may the pointers a comment says may be. Any other NULL pointer is
//     ROUGE_ERR_ARG (false for rouge_cosmetic_get), never a crash.
//   - Outputs (`*out`, `*data`, `*size`, the buffer of read_rgba) are written only on success; on
//     failure they hold what they held before (one exception: rouge_face_pointer fills `out` for an
//     event it took even when it returns an earlier stroke file's write failure). A rouge_error is
//     written only on failure.
//   - Strings rouge returns (rouge_version, rouge_result_name, rouge_environment_name, the names in a
//     rouge_cosmetic) are static: valid for the life of the program. Strings you pass are copied or
//     used during the call only.
//   - GL: the calls that use GL (create, destroy, set_view with a new environment, draw, render,
//     read_rgba, write_png, pointer, pick, play_strokes) need the face's own context current: with none
//     or another one they return ROUGE_ERR_GL (pick: false) and touch nothing; destroy then leaks the
//     face's GL objects rather than delete another context's. The context is told apart through EGL
//     (WebGL: emscripten's html5 API); a face made in a context EGL does not know (GLX, WGL) is not checked.
//   - GL errors you left pending when such a call begins are yours: rouge takes them off the context
//     (GL cannot put them back) so they are never blamed on a stage of rouge's, and keeps the first for
//     rouge_face_take_host_gl_error (rouge_face_destroy drops them). Call glGetError before rouge if you
//     need them all, in order.
//
// ABI: this is 0.x. A patch release (0.1.x) changes neither API nor ABI. A minor release (0.2) may
// change both: struct fields are only ever appended (a new field's zero keeps the old behaviour),
// enum values only appended, nothing renamed in place; but a grown struct is an ABI change, so rebuild
// against the new header (the SONAME stays librouge.so.0 until 1.0; compare rouge_version_number() with
// ROUGE_VERSION_NUMBER to catch a host built against another minor).
//
//   rouge_error err;
//   rouge_face *face;
//   if (rouge_face_create(&(rouge_face_desc){.path = "face.rsf"}, &face, &err) != ROUGE_OK)
//       return fprintf(stderr, "%s\n", err.msg), 1;
//   rouge_face_set_brush(face, &(rouge_brush){.cosmetic = "lipstick_satin"}, &err);
//   // per frame, with your context current and your framebuffer bound:
//   rouge_face_pointer(face, &(rouge_pointer_event){ROUGE_POINTER_DOWN, 0, x, y}, NULL, &err);
//   rouge_face_draw(face, 0, 0, 0, 0, &err);          // fills the current viewport
//   rouge_face_destroy(face);
//
// Link with `pkg-config --cflags --libs rouge`. Names starting rouge_ / ROUGE_ are the public API;
// everything else in the library (rs_*) is internal and may change.
#ifndef ROUGE_H
#define ROUGE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ROUGE_VERSION_MAJOR 0
#define ROUGE_VERSION_MINOR 1
#define ROUGE_VERSION_PATCH 0
// major * 10000 + minor * 100 + patch: 100 for 0.1.0.
#define ROUGE_VERSION_NUMBER (ROUGE_VERSION_MAJOR * 10000 + ROUGE_VERSION_MINOR * 100 + ROUGE_VERSION_PATCH)

// The library's own version (the one linked, which may differ from the header's macros): "0.1.0".
const char *rouge_version(void);
uint32_t rouge_version_number(void);  // the library's ROUGE_VERSION_NUMBER

// --- errors ------------------------------------------------------------------------------------------

typedef enum rouge_result {
    ROUGE_OK = 0,
    ROUGE_ERR_IO,      // file system: missing, unreadable, unwritable
    ROUGE_ERR_FORMAT,  // malformed file or buffer contents
    ROUGE_ERR_LIMIT,   // a count or size beyond what rouge accepts
    ROUGE_ERR_NOMEM,   // out of memory
    ROUGE_ERR_GL,      // no current GLES 3 context, shader or framebuffer failure
    ROUGE_ERR_ARG,     // bad argument (unknown cosmetic, view out of range, ...)
    ROUGE_ERR_CANCELLED, // the host's progress callback returned false (rouge_face_desc.progress)
} rouge_result;

// The detail of a failure: "face.rsf: header: bad CRC (byte 8)". Untouched on success.
typedef struct rouge_error {
    rouge_result code;
    char msg[512];
} rouge_error;

const char *rouge_result_name(rouge_result r);  // "ROUGE_ERR_IO"
void rouge_free(void *p);                        // frees memory rouge handed you (looks in memory)

// --- the GL context you made ---------------------------------------------------------------------------

typedef struct rouge_caps {
    int gles_major, gles_minor;
    char renderer[128];      // GL_RENDERER
    char version[128];       // GL_VERSION
    bool float_targets;      // RGBA16F render targets: the full-precision path (else an RGBA8 fallback)
    float point_size_max;    // GL_ALIASED_POINT_SIZE_RANGE (splats beyond it are drawn as quads)
    int max_draw_buffers;
    int max_texture_size;
} rouge_caps;

// What rouge sees of the context current on this thread. ROUGE_ERR_GL when none is current or it is
// not GLES 3.
rouge_result rouge_query_caps(rouge_caps *out, rouge_error *err);

// --- the view: camera, light, what is drawn --------------------------------------------------------------

typedef enum rouge_mode {
    ROUGE_MODE_FULL = 0,    // subsurface + specular
    ROUGE_MODE_ALBEDO,      // colour only, no lighting
    ROUGE_MODE_DIFFUSE,     // subsurface only
    ROUGE_MODE_SPECULAR,    // debug views from here on
    ROUGE_MODE_NORMALS,
    ROUGE_MODE_REGIONS,
    ROUGE_MODE_SHADOW,
    ROUGE_MODE_LOD,
    ROUGE_MODE_IRRADIANCE,
    ROUGE_MODE_COUNT
} rouge_mode;

typedef enum rouge_pipeline {
    ROUGE_PIPELINE_DEFAULT = 0,  // mobile
    ROUGE_PIPELINE_MOBILE,       // LOD decimation + 3 Gaussians: matched to the reference within 34 dB per view
    ROUGE_PIPELINE_REFERENCE,    // all splats, six Gaussians: the quality bar (slow)
} rouge_pipeline;

typedef enum rouge_primitive {
    ROUGE_PRIMITIVE_AUTO = 0,    // point sprites when they are large enough, else instanced quads
    ROUGE_PRIMITIVE_POINTS,
    ROUGE_PRIMITIVE_QUADS,
} rouge_primitive;

typedef enum rouge_composite {
    ROUGE_COMPOSITE_DEFAULT = 0, // PAPER with env "paper", PHYSICAL under an environment
    ROUGE_COMPOSITE_PAPER,       // F = A (D + S): the paper's eq. 1, the highlight tinted by the skin
    ROUGE_COMPOSITE_PHYSICAL,    // F = A D + S: a dielectric's white highlight
} rouge_composite;

// A directional light, given as the direction it comes FROM in the face's frame (0, 0: from the front,
// + yaw towards the subject's left, + pitch from above).
typedef struct rouge_light {
    float yaw_deg, pitch_deg;
    float color[3];     // linear RGB; all zero = white
    float intensity;    // 0 = 1 (key light); the fill light is on only when intensity > 0
} rouge_light;

// The largest frame side rouge renders, in pixels (a view's width and height, a draw rectangle's size).
#define ROUGE_VIEW_MAX_SIZE 8192

typedef struct rouge_view {
    int width, height;           // render size in pixels, 0..ROUGE_VIEW_MAX_SIZE; 0 = the draw rectangle's
                                 // (or 512 x 512)
    float yaw_deg, pitch_deg;    // camera orbiting the face centre; 0, 0 = frontal
    float zoom;                  // 0 = 1: the face height fills ~80% of the view height; 2 = twice as close
    float fov_deg;               // vertical field of view, 1..150; 0 = 30
    float pan[2];                // screen shift, fractions of the view height (+x right, +y down)
    const char *env;             // lighting: "studio" (NULL or "" = this), "daylight", "office", "sunset", a
                                 // path to a .rse file (tools/env), or "paper": the key/fill/ambient below
    float env_rotation_deg;      // environment turned about the face's up axis (+ moves its light like + yaw)
    // Only with env "paper" (the paper's single lamp, no tone curve):
    rouge_light key;             // all zero = the default key light (yaw -35, pitch 30: upper left-front, white, 1)
    rouge_light fill;            // all zero = no fill light
    float ambient;               // uniform sky light; 0 = 0.05, negative = none
    rouge_mode mode;
    rouge_pipeline pipeline;
    rouge_composite composite;
    float exposure;              // linear multiplier before the filmic tone curve and sRGB; 0 = 1
    float background[4];         // sRGB 0..1 + alpha; alpha 0 = the default dark grey
    bool no_shadows;
    bool hide_makeup;            // the bare face (a before / after comparison)
    bool compare_look;           // the look set with rouge_face_set_compare_look instead of the painted one
                                 // (the bare face while none is set): two looks side by side
    float specular_scale;        // multiplies the skin's specular; 0 = 1 (2 = oily skin)
    uint32_t max_splats;         // cap on the splats drawn (an LOD prefix); 0 = the pipeline decides
    int kernel_count;            // mobile: Gaussians of the subsurface profile (2..4); 0 = 3
    float lod_density;           // mobile: visible splats per face pixel; 0 = 0.3
    rouge_primitive primitive;   // how splats are rasterised (a debugging choice; both agree)
    // Render pixels per window unit (a browser's devicePixelRatio, a desktop's content scale); 0 = 1,
    // else 0.1..16. Pointer events, rouge_face_pick, rouge_face_pan and rouge_face_zoom_at take window
    // units: pixels of the last frame divided by the pixel_ratio that frame was rendered with, so a host
    // passes its events as they come while width and height are its framebuffer's pixels.
    float pixel_ratio;
    // The host's camera: view_matrix and proj_matrix replace the orbit camera (yaw, pitch, zoom, fov, pan)
    // for rendering and picking. Column-major like glUniformMatrix4fv with transpose GL_FALSE. view_matrix:
    // model -> eye, rigid (rotation + translation: lengths stay model units; rouge_face_camera_matrices
    // gives rouge's own as a start); proj_matrix: eye -> clip, a perspective projection (last row 0 0 -1 0,
    // as glm_perspective / glFrustum make it) whose aspect is the frame's. While set, pointer gestures only
    // report (as with manual_navigation) and orbit / pan / zoom_at / target move the orbit camera, which
    // comes back when use_matrices is cleared. Stroke recordings store the orbit camera: strokes painted
    // through host matrices do not replay where they were painted. Checked at set_view: every number
    // finite, the view rigid, the projection a perspective with near > 0 (ROUGE_ERR_ARG names the field).
    bool use_matrices;
    float view_matrix[16];
    float proj_matrix[16];
} rouge_view;

// The bundled lighting environments ("studio", "daylight", ...) a view's env may name, then "paper";
// NULL when i is out of range.
int rouge_environment_count(void);
const char *rouge_environment_name(int i);

// --- the face ------------------------------------------------------------------------------------------

typedef struct rouge_face rouge_face;
typedef struct rouge_stream rouge_stream;

// Where a rouge_face_create stands (rouge_face_desc.progress_stage).
typedef struct rouge_progress {
    float fraction;              // as rouge_face_desc.progress has it: 0..1, never decreasing
    const char *stage;           // what runs from now (static): "reading the face", "uploading and compiling",
                                 // "makeup layer", "lighting", then with first_frame "shadow map",
                                 // "visibility", "attributes", "light and diffusion", "composite"; "done" last
    int step, steps;             // this stage's number (1-based) and how many there are; step == steps: done
} rouge_progress;

typedef struct rouge_face_desc {
    const char *path;            // a .rsf file; or
    const void *data;            // the bytes of one (not kept after create); or
    size_t size;
    rouge_stream *stream;        // a file still arriving (below): the face so far, or all of it
    const rouge_view *view;      // the initial view; NULL = (rouge_view){0}
    uint32_t undo_levels;        // strokes kept for undo; 0 = 64
    bool manual_navigation;      // pointer gestures only report orbit / pan / zoom, the camera stays
    bool no_float_targets;       // force the RGBA8 fallback (tests; drivers with broken float blending)
    const char *env_dir;         // where the named environments' .rse files are looked for first; then
                                 // beside the library's own file (found at run time): share/rouge/env of
                                 // the prefix its lib/ (or a static host's bin/) is in, wherever it was
                                 // installed, or assets/env of the source tree whose build/ holds it;
                                 // last the PREFIX it was built for. Never the working directory.
    // Called (when not NULL) on the creating thread as create goes, with the fraction done: 0 at the
    // start, then after each stage (the splats parsed and decoded, uploaded with the shaders compiled,
    // the makeup layer made, the environment uploaded), 1 last; never decreasing. Returning false cancels:
    // create frees what it made and returns ROUGE_ERR_CANCELLED ("cancelled"), *out untouched. It must not
    // call rouge on this face (there is none yet). It may draw in the creating context (a loading
    // screen, then swap buffers): your GL state is in place during the call, rouge's is put back after.
    bool (*progress)(void *user, float fraction);
    void *progress_user;         // handed to progress and progress_stage
    // Also render the view's first frame before returning (as rouge_face_render would: into the face's
    // texture, at the view's size, 0 = 512 x 512). Its stages compile their shaders on first use and make
    // the shadow map and the light, seconds for a large face on a software GPU: inside create they are
    // reported (and may be cancelled) like the rest, and the host's first render or draw of that view at
    // that size only copies the frame out. The fractions are then about shares of the time: create's own
    // stages take 0..0.1, the frame 0.1..1.
    bool first_frame;
    // Called (when not NULL) with progress, at the same moments, with the stage about to run by name and
    // number (rouge_progress), e.g. for "Compiling: shadow map (5 of 10)". Returning false cancels, as
    // progress. The same rules.
    bool (*progress_stage)(void *user, const rouge_progress *p);
} rouge_face_desc;

// Loads the face and creates its GL objects in the current context. Blocks (file, shaders).
rouge_result rouge_face_create(const rouge_face_desc *desc, rouge_face **out, rouge_error *err);

// A large face over a slow disk or network: feed the file's bytes as they arrive (one thread feeds; any
// thread may ask for progress and create faces meanwhile, the stream locks itself). A .rsf v2 file
// stores its coarse LOD levels first, so a face made from a stream still arriving is a preview: the
// complete LOD levels so far (rouge_stream_progress().ready splats), drawn closed at that density. Once
// the stream is complete a face made from it takes all the splats (the stream hands them over: a second
// face from it is ROUGE_ERR_ARG). Version 1 files show nothing before they are complete.
typedef struct rouge_stream_progress {
    uint64_t bytes;              // fed so far
    uint32_t splats;             // the face's splat count once the header has arrived, else 0
    uint32_t decoded;            // splats decoded and checked
    uint32_t ready;              // splats a preview would show (a LOD prefix), 0 while none
    bool complete;               // every byte has arrived: a face from the stream is the whole face (and
                                 // stays true, with the counts, once a face took the splats)
} rouge_stream_progress;

// `name` names the stream in messages (NULL = "(stream)"); total_bytes is the file's size when known
// (checked against the header before anything is allocated), 0 when not.
rouge_result rouge_stream_create(const char *name, uint64_t total_bytes, rouge_stream **out, rouge_error *err);
// The next bytes (data may be NULL only when size is 0). Errors (malformed or surplus bytes) are sticky:
// every later call repeats the first.
rouge_result rouge_stream_feed(rouge_stream *s, const void *data, size_t size, rouge_error *err);
rouge_stream_progress rouge_stream_get_progress(rouge_stream *s);
void rouge_stream_destroy(rouge_stream *s);  // NULL is fine; faces made from it keep their splats
// With the creating context current (else its GL objects are leaked, not deleted). NULL is fine.
void rouge_face_destroy(rouge_face *face);

// A lighting environment from memory (a host without files: the browser): the bytes of a .rse file
// (tools/env; parsed and checked now, not kept) under `name`, which a view's env then names. 1..63 bytes,
// not "paper"; it goes before the bundled names and files of that name. Adding a name again replaces it
// (a view using it is relit at once: its context must be current then). ROUGE_ERR_FORMAT for bytes that
// are no environment, ROUGE_ERR_LIMIT past 16 names; the face's environments stay as they were then.
#define ROUGE_MAX_ENVIRONMENTS 16
rouge_result rouge_face_add_environment(rouge_face *face, const char *name, const void *rse, size_t size,
                                        rouge_error *err);

// The view (copied, also the env string). ROUGE_ERR_ARG for an unknown mode, pipeline or environment,
// a size over ROUGE_VIEW_MAX_SIZE, kernel_count outside 2..4, any number NaN, infinite or beyond +-1e6
// (the message names the field: "view.yaw_deg is NaN"); ROUGE_ERR_IO / ROUGE_ERR_FORMAT for an
// environment file that is missing or corrupt; the previous view stays then. NULL view = the default.
rouge_result rouge_face_set_view(rouge_face *face, const rouge_view *view, rouge_error *err);
// The view as set, with the camera as navigation left it.
rouge_view rouge_face_get_view(const rouge_face *face);
// Frames a region of the face ("lips", "nose", "cheek", "forehead", ...: the names in the face's region
// table) from the current yaw and pitch: centres it and zooms so it fills about `fill` of the view height
// (0 = 0.4). A region on both sides of the face is framed on the side facing the camera more.
// ROUGE_ERR_ARG for a name the face does not have (the message lists those it has).
rouge_result rouge_face_target(rouge_face *face, const char *region, float fill, rouge_error *err);
// Navigation in window units of the last frame (its pixels / its view's pixel_ratio; what gestures do;
// for keys, wheels and your own gestures). With view.use_matrices they move only the orbit camera.
void rouge_face_orbit(rouge_face *face, float yaw_deg, float pitch_deg);
void rouge_face_pan(rouge_face *face, float dx, float dy);
void rouge_face_zoom_at(rouge_face *face, float factor, float x, float y);  // keeps (x, y) in place
// The camera of the last frame (before any: the view at its own size) as GL matrices, column-major:
// model -> eye and eye -> clip. The orbit camera's, or the host's with view.use_matrices. A host starts
// its own camera from them, or places its own objects over the face. Both may not be NULL.
rouge_result rouge_face_camera_matrices(rouge_face *face, float view_matrix[16], float proj_matrix[16],
                                        rouge_error *err);

// --- drawing -------------------------------------------------------------------------------------------

// Renders the face into the rectangle (x, y, w, h) of the framebuffer bound for drawing (GL pixels,
// origin bottom-left); w or h 0 = the current viewport. Rendered at the view's size (0 = the rectangle's)
// and copied (scaled when sizes differ). The target must be single-sampled. Your scissor test does not
// apply (the rectangle is the only clip); an sRGB target (SRGB8_ALPHA8, an sRGB surface) gets the same
// picture as an RGBA8 one. The frame it renders is "the last frame" pointer events and picks refer to.
rouge_result rouge_face_draw(rouge_face *face, int x, int y, int w, int h, rouge_error *err);
// Renders into the face's own texture only (view size; 0 = 512 x 512).
rouge_result rouge_face_render(rouge_face *face, rouge_error *err);
// The last frame: a GL texture name (GLuint; RGBA8, rows bottom-first as GL has them) owned by the face,
// valid until the next render or destroy; 0 before the first frame.
uint32_t rouge_face_texture(const rouge_face *face, int *width, int *height);
// The last frame as RGBA8, rows top-first, into rgba (at least width * height * 4 bytes).
rouge_result rouge_face_read_rgba(rouge_face *face, uint8_t *rgba, size_t capacity, rouge_error *err);
// The last frame as a PNG (written to a temporary file and renamed: never half-written). ROUGE_ERR_ARG
// for the .rsf the face was loaded from (same file by device and inode, under any name).
rouge_result rouge_face_write_png(rouge_face *face, const char *path, rouge_error *err);
// True when the view or the makeup changed since the last frame (a host that redraws on demand asks).
bool rouge_face_changed(const rouge_face *face);
// The first GL error (a GLenum: 0x0502 GL_INVALID_OPERATION, ...) that was pending in your context when a
// call of this face began, since the last time you asked; 0 when none. Asking clears it.
uint32_t rouge_face_take_host_gl_error(rouge_face *face);

// --- painting ------------------------------------------------------------------------------------------

typedef enum rouge_pointer_type {
    ROUGE_POINTER_DOWN = 0,
    ROUGE_POINTER_MOVE,
    ROUGE_POINTER_UP,
    ROUGE_POINTER_CANCEL,  // the system took the pointer back (palm rejection): the stroke is rolled back
} rouge_pointer_type;

typedef struct rouge_pointer_event {
    rouge_pointer_type type;
    int id;            // the touch / pointer id; two ids down at once pinch and pan
    float x, y;        // window units of the last frame, origin its top-left: its pixels divided by its
                       // view's pixel_ratio (1: pixels). The frame of the latest draw or render, whichever
                       // came last (a draw's frame covers its rectangle: subtract the rectangle's top-left
                       // and scale by view size / rectangle size when they differ); before any frame, the
                       // view's size (0 = 512 x 512) and pixel_ratio
    float pressure;    // 0..1; 0 = 1 (a mouse)
    double time_s;     // any monotonic clock, seconds
} rouge_pointer_event;

typedef struct rouge_pointer_result {
    uint32_t stamps;                 // brush stamps applied
    uint32_t misses;                 // stamps that fell on the background
    bool stroke_begin, stroke_end, stroke_cancel;
    float orbit_dx, orbit_dy;        // one-finger drag when not painting, window units (as x, y)
    float pan_dx, pan_dy;            // two-finger drag, window units
    float zoom, zoom_x, zoom_y;      // pinch factor (1 = none) and centre
} rouge_pointer_result;

typedef enum rouge_pressure {
    ROUGE_PRESSURE_FLOOR = 0,   // opacity * (0.3 + 0.7 p): a light touch still paints
    ROUGE_PRESSURE_LINEAR,      // opacity * p
    ROUGE_PRESSURE_NONE,
} rouge_pressure;

typedef enum rouge_finish {
    ROUGE_FINISH_DEFAULT = 0,    // the product's own
    ROUGE_FINISH_MATTE,          // rough, dull: powder
    ROUGE_FINISH_SATIN,          // about the skin's own sheen
    ROUGE_FINISH_GLOSS,          // smooth with a clear coat: sharp reflections (lip gloss)
    ROUGE_FINISH_SHIMMER,        // pigment-tinted flakes that glint (highlighter)
} rouge_finish;

// What a brush does with the makeup. DOES: smudge drags the product already on the face along the stroke
// (what lies under the first stamp is picked up, laid down where the brush moves wherever it is stronger
// than what is there, and mixed with what the brush passes over, so it fades along the drag: a higher
// opacity carries it further); blend evens the makeup in place (each stamp lays its footprint's average
// into the weaker part: a hard edge becomes a soft ramp, an even area stays). Both sample the whole
// makeup (every product, both resolutions) on the face's own side (a mirrored stroke samples its
// mirror side there), ignore the region mask and the cosmetic (the cosmetic only gives the default
// size), and are recorded in stroke files and saved in looks like any painting (undo: one stroke).
// DOES NOT: thin or remove product (a stroke only adds: smudging bare skin into a lipstick leaves it,
// blending a hard edge feathers it outwards); use the eraser (eraser with a tool is ROUGE_ERR_ARG).
typedef enum rouge_tool {
    ROUGE_TOOL_PAINT = 0,        // lay the brush's product down (or erase, with eraser)
    ROUGE_TOOL_SMUDGE,           // drag the makeup under the brush along the stroke
    ROUGE_TOOL_BLEND,            // soften edges in place
} rouge_tool;

typedef struct rouge_brush {
    const char *cosmetic;        // a preset name (rouge_cosmetic_get); NULL = "foundation_1"
    // A custom product made from the preset (it keeps the preset's kind, region and brush; looks record it
    // as "custom_<preset>"):
    float color[4];              // sRGB 0..1 + alpha: alpha > 0 replaces the colour (a colourless product, a
                                 // gloss, gains one); alpha 0 = the preset's colour
    rouge_finish finish;         // 0 = the preset's
    float coverage;              // 0 = the preset's; else sheer 0..1 opaque (negative = 0, fully sheer)
    float size;                  // diameter as a fraction of the face height; 0 = the cosmetic's
    float opacity;               // 0..1; 0 = the cosmetic's
    rouge_pressure pressure;
    bool eraser, mirror;         // mirror: also paint the mirror image across the face's mid-plane
    // Region-aware by default: lipstick and gloss stay on the lips, shadow on the eye area, base,
    // powder, blush, bronzer and highlighter off the lips, eyes and brows, with a soft edge (~1.5 mm) at
    // the region's border. true paints anywhere. Faces converted without eyelid/brow regions keep eye
    // products unmasked. A brush kept to the lips or the eyes is drawn per pixel, masked by a smooth
    // field of its region (the lips': where the lip colour ends), so its edge is a clean line at the
    // picture's resolution. A brush narrower than 4 mm (liner, brow pencil, mascara at their sizes) is
    // drawn per pixel exactly where it is painted and is not masked: a pencil is its own mask.
    bool any_region;
    // 0 = paint. With smudge or blend, opacity is the tool's strength (0 = 0.8) and size its size.
    rouge_tool tool;
} rouge_brush;

typedef struct rouge_cosmetic {
    const char *name;            // "lipstick_satin"
    const char *kind;            // "lipstick"
    uint8_t rgb[3];              // sRGB
    float size, opacity;         // its default brush
    rouge_finish finish;         // the family nearest to its finish (never DEFAULT)
    float coverage;              // sheer 0..1 opaque
    const char *region;          // where its brush stays: "lips", "eyes", "skin", or NULL: anywhere
} rouge_cosmetic;

int rouge_cosmetic_count(void);
bool rouge_cosmetic_get(int i, rouge_cosmetic *out);  // false when i is out of range

// ROUGE_ERR_ARG for an unknown cosmetic (the brush stays). Takes effect at the next stroke.
rouge_result rouge_face_set_brush(rouge_face *face, const rouge_brush *brush, rouge_error *err);
// One pointer paints (true, the default) or orbits (false); two always pinch and pan.
void rouge_face_set_painting(rouge_face *face, bool painting);
// Feeds one event; `out` may be NULL. Picks use the last frame's view (draw or render first).
rouge_result rouge_face_pointer(rouge_face *face, const rouge_pointer_event *ev, rouge_pointer_result *out,
                                rouge_error *err);
bool rouge_face_undo(rouge_face *face);   // false when there is nothing to undo
bool rouge_face_redo(rouge_face *face);
rouge_result rouge_face_clear(rouge_face *face, rouge_error *err);  // undoable

// --- looks and stroke files -------------------------------------------------------------------------------

// One product of the current look (the makeup as painted now: undone strokes are not in it).
typedef struct rouge_look_item {
    char name[32];               // as a look file names it: "lipstick_satin", "custom_blush"
    const char *kind;            // "lipstick", ... (static)
    uint8_t rgb[3];              // sRGB
    rouge_finish finish;         // the family nearest to its finish (never DEFAULT)
    float coverage;              // sheer 0..1 opaque
    uint32_t stamps;             // brush stamps of it in the look (mirror images count)
} rouge_look_item;

// The products of the current look, in the order they were first painted: *count is how many there are;
// the first min(capacity, *count) are written to items (NULL when capacity is 0). Erasers are no product.
rouge_result rouge_face_look_info(const rouge_face *face, rouge_look_item *items, int capacity, int *count,
                                  rouge_error *err);

// Replaces the makeup with the look's and clears undo and redo (loading is not undoable). A look that
// cannot be read or parsed, or was made on another face, leaves the makeup and undo as they were.
rouge_result rouge_face_load_look(rouge_face *face, const char *path, rouge_error *err);
rouge_result rouge_face_load_look_memory(rouge_face *face, const void *data, size_t size, rouge_error *err);
// ROUGE_ERR_ARG for the .rsf the face was loaded from (compared by device and inode).
rouge_result rouge_face_save_look(rouge_face *face, const char *path, rouge_error *err);
// *data (free with rouge_free) holds *size bytes of look text.
rouge_result rouge_face_save_look_memory(rouge_face *face, char **data, size_t *size, rouge_error *err);
// The second look for comparisons (drawn when the view's compare_look is set): a look file, or NULL for
// none (the bare face). It is only shown, never painted. On failure the previous one stays.
rouge_result rouge_face_set_compare_look(rouge_face *face, const char *path, rouge_error *err);
// Records each stroke painted from now on to a stroke file; NULL stops. After every stroke the whole
// recording is rewritten atomically on a background thread (never a half-written file, and no disk wait
// on the pointer path); a failed write is returned by a later rouge_face_pointer, rouge_face_flush_strokes
// or rouge_face_record_strokes call. Stopping (or destroying the face) writes what is pending first.
// A directory or the face's own .rsf is refused at once (the recording so far goes on then).
rouge_result rouge_face_record_strokes(rouge_face *face, const char *path, rouge_error *err);
// Waits until every finished stroke is in the recording's file; returns a write failure, if any.
rouge_result rouge_face_flush_strokes(rouge_face *face, rouge_error *err);
// Replays a stroke file (each stroke seen through the camera it was recorded with); the camera is
// left at the last stroke's.
rouge_result rouge_face_play_strokes(rouge_face *face, const char *path, rouge_error *err);

// --- queries -------------------------------------------------------------------------------------------

typedef struct rouge_pick {
    uint32_t splat;              // index in the face's cloud
    float position[3];           // the surface point under the pixel, model units
    int region;                  // 0 other, 1 cheek, 2 nose, 3 forehead, 4 lips, ...
    float brush_radius_px;       // the current brush's radius on screen at that point, window units (as x, y)
} rouge_pick;

// The face under (x, y) of the last frame, window units as a pointer event's (top-left origin); false on
// background.
bool rouge_face_pick(rouge_face *face, float x, float y, rouge_pick *out);

#define ROUGE_MAX_LODS 24

typedef struct rouge_stats {
    uint32_t splats;             // in the face
    uint32_t lod_count;          // LOD prefixes: lods[0] = splats > lods[1] > ...
    uint32_t lods[ROUGE_MAX_LODS];
    float face_height_mm;
    uint32_t splats_drawn;       // last frame
    uint32_t auto_splats;        // what the current view would draw with max_splats 0 (the mobile LOD)
    int kernel_count;            // Gaussians of the last frame's subsurface pass
    int width, height;           // last frame
    double frame_ms;             // last frame's render time (CPU wall clock; GL work may still run)
    bool float_targets;
    size_t gpu_bytes;
    bool can_undo, can_redo, in_stroke;
    uint32_t look_stamps;        // stamps that make the current makeup
    uint32_t uploaded_records;   // makeup records sent to the GPU by the last frame (dirty LOD bands)
} rouge_stats;

rouge_stats rouge_face_stats(const rouge_face *face);

#ifdef __cplusplus
}
#endif
#endif
