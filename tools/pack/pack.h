// pack.h — rouge-pack's library: turns a PLY scan (point cloud or textured mesh) into an .rsf splat cloud.
//
// Does: sample a textured mesh area-uniformly into splats (colour and normal maps), decimate clouds,
// estimate and orient missing normals (k-nearest-neighbour PCA), give each splat a radius from the local
// spacing, order splats into LOD prefixes (Poisson-disk dart throwing coarse to fine, Morton order
// inside a level), find the face frame and landmarks of a front-facing head and segment it into the skin regions
// of the region table (cheek, nose, forehead, lips, other), and draw a CPU preview for people to check.
// Does not: parse PLY (tools/pack/ply.h), encode or write .rsf (src/splat/splat.h), read PNGs (src/core/image.h) or
// print anything (tools/rouge_pack.c does, through the progress callback and the report).
//
//   rs_pack_desc d = { .points = 600000, .texture = &colour_png };  // zeros mean defaults
//   rs_pack_report rep;
//   rs_splat_cloud *cloud = NULL;
//   if (rs_pack_convert(mesh, &d, &cloud, &rep, &err) == RS_OK) rs_splat_save(cloud, "face.rsf", &err);
//   rs_splat_destroy(cloud);
#ifndef RS_PACK_H
#define RS_PACK_H

#include "core/core.h"
#include "core/image.h"
#include "pack/ply.h"
#include "splat/splat.h"

#define RS_PACK_NONE UINT32_MAX          // "no neighbour" in kNN tables
#define RS_PACK_REGION_AUTO 255u         // region not given by the input: segment automatically
#define RS_PACK_DEFAULT_MESH_POINTS 600000u
#define RS_PACK_DEFAULT_MIN_LOD 10000u
#define RS_PACK_DEFAULT_SEED 20240600u
// A mesh's face (frame and landmarks) is found on its own sample of this many points, drawn with the same
// seed whatever --points asks for, so the face height does not depend on the requested count. A small mesh
// gets RS_PACK_FACE_SAMPLE_PER_TRIANGLE points a triangle it keeps, at least RS_PACK_FACE_SAMPLE_MIN: its
// shape is all in its few flat triangles, and the search's work follows the sample's size (any mesh of
// 3125 triangles or more, every scan, gets the whole sample).
#define RS_PACK_FACE_SAMPLE_POINTS 50000u
#define RS_PACK_FACE_SAMPLE_PER_TRIANGLE 16u
#define RS_PACK_FACE_SAMPLE_MIN 2000u
// Normals are stored on a 12-bit octahedral lattice (at most 0.05 degrees from the 16-bit code; a scan's
// normal map resolves ~0.5 degrees): 2 bytes a splat less in a v2 .rsf (rs_splat_quantize_normals); 10
// bits (~0.2 degrees) with the occlusion, whose bent normal takes the low bits.
#define RS_PACK_NORMAL_BITS 12
// Radius codes on a 6-bit lattice (multiples of 4 of the 8-bit log code: 1.3 % steps for the bundled
// head, whose radii, the 8th-neighbour distance, spread over 0.6..1.4 mm from splat to splat with no
// correlation between neighbours): 2 bits a splat less in a v2 file.
#define RS_PACK_RADIUS_BITS 6
// Colour given to inputs without colour (a marble bust, a bare mesh): a light warm grey, sRGB.
#define RS_PACK_DEFAULT_RGB_R 200
#define RS_PACK_DEFAULT_RGB_G 178
#define RS_PACK_DEFAULT_RGB_B 160
// Head height (vertex to menton) assumed when estimating mm_per_unit: adult men 225-232 mm, women ~218.
#define RS_PACK_ASSUMED_HEAD_MM 225.0f
// The scale rule (rouge-pack --help, docs/import.md). A scale given by the user wins; else the unit the
// file declares, unless it makes the head shorter than RS_PACK_DECLARED_HEAD_MIN_MM or taller than
// RS_PACK_DECLARED_HEAD_MAX_MM (LeePerrySmith.glb's "metres" make a 4.7 m head); else the first of mm,
// cm, m, in that makes the head RS_PACK_HEAD_MIN_MM..RS_PACK_HEAD_MAX_MM tall (a toddler's head is about
// 170 mm, an adult's up to ~260; the range is narrower than the 2.54 between cm and in, so at most one
// unit fits, and it keeps the bundled head's 4.75 units from reading as a 121 mm head in inches); else
// the head is taken as RS_PACK_ASSUMED_HEAD_MM.
#define RS_PACK_HEAD_MIN_MM 150.0f
#define RS_PACK_HEAD_MAX_MM 300.0f
#define RS_PACK_DECLARED_HEAD_MIN_MM 60.0f
#define RS_PACK_DECLARED_HEAD_MAX_MM 600.0f

typedef enum rs_pack_scale {
    RS_PACK_SCALE_GIVEN,      // desc.mm_per_unit (--units, --mm-per-unit)
    RS_PACK_SCALE_DECLARED,   // the file's own unit (desc.declared_mm_per_unit)
    RS_PACK_SCALE_INFERRED,   // the standard unit that makes the head a head's size
    RS_PACK_SCALE_ESTIMATED,  // none fits (or no face): the head taken as RS_PACK_ASSUMED_HEAD_MM
} rs_pack_scale;

// Millimetres per unit of "mm", "cm", "m", "in" (also "inch"); 0 for anything else.
float rs_pack_unit_parse(const char *s);

// ---------------------------------------------------------------------------------------------------
// Small shared pieces: deterministic random numbers, Morton codes.

// PCG32 (O'Neill 2014): small, fast and the same on every platform, so conversions are reproducible.
typedef struct rs_pack_rng {
    uint64_t state, inc;
} rs_pack_rng;
void rs_pack_rng_seed(rs_pack_rng *r, uint64_t seed);
uint32_t rs_pack_rng_u32(rs_pack_rng *r);
double rs_pack_rng_unit(rs_pack_rng *r);  // uniform in [0, 1)

// Interleaves the low 21 bits of x, y, z (x in bit 0).
uint64_t rs_pack_morton3(uint32_t x, uint32_t y, uint32_t z);

// ---------------------------------------------------------------------------------------------------
// k nearest neighbours (pack_knn.c): a balanced k-d tree (median splits, so duplicates and clusters stay
// O(N log N)).

typedef struct rs_pack_knn {
    uint32_t count, k;
    uint32_t *idx;  // count * k neighbour indices, nearest first, never the point itself; RS_PACK_NONE pads
    float *dist;    // the matching distances in model units; INFINITY pads
} rs_pack_knn;

// k is 1..RS_PACK_KNN_MAX_K. Progress (0..1) goes to `progress` if non-NULL.
#define RS_PACK_KNN_MAX_K 32
rs_result rs_pack_knn_compute(const float (*pos)[3], uint32_t count, uint32_t k, rs_pack_knn *out,
                              void (*progress)(void *user, double fraction), void *user, rs_error *err);
void rs_pack_knn_free(rs_pack_knn *knn);

// The tree itself, for queries at arbitrary points (tests measure coverage and spacing with it).
typedef struct rs_pack_kdtree rs_pack_kdtree;
rs_result rs_pack_kdtree_create(const float (*pos)[3], uint32_t count, rs_pack_kdtree **out, rs_error *err);
void rs_pack_kdtree_destroy(rs_pack_kdtree *tree);
// Up to k (<= RS_PACK_KNN_MAX_K) nearest points to q, nearest first, never the point `skip`
// (RS_PACK_NONE skips none). Returns how many were found.
uint32_t rs_pack_kdtree_query(const rs_pack_kdtree *tree, const float q[3], uint32_t k, uint32_t skip,
                              uint32_t *idx, float *dist);
// The nearest point to q if one is closer than sqrt(bound2): true and its squared distance in *d2.
bool rs_pack_kdtree_nearest_within(const rs_pack_kdtree *tree, const float q[3], float bound2, float *d2);
// Every point within sqrt(r2) of q (distance <= it), in tree order, into ids (room for all the tree's
// points); returns the count.
uint32_t rs_pack_kdtree_within(const rs_pack_kdtree *tree, const float q[3], float r2, uint32_t *ids);

// ---------------------------------------------------------------------------------------------------
// Normals and radii (pack_normals.c).

// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: values ascending, vectors[i]
// the unit eigenvector of values[i].
void rs_pack_eigen_sym3(const double a[3][3], double values[3], double vectors[3][3]);

// Normals by PCA of each point's neighbourhood (the point and its knn->k neighbours): the eigenvector of
// the smallest eigenvalue of the covariance (Hoppe et al. 1992). Then oriented consistently: starting
// from the point farthest from the centroid, turned away from the centroid, orientation spreads along a
// minimum spanning tree of the kNN graph weighted by 1 - |n_i . n_j|, so it crosses the smoothest
// edges first (Hoppe et al. 1992, §3.3). Each connected part of the graph gets its own seed.
rs_result rs_pack_estimate_normals(const float (*pos)[3], const rs_pack_knn *knn, float (*normal)[3],
                                   rs_error *err);

// Splat radius from the local spacing: RS_PACK_RADIUS_SCALE x the distance to the RS_PACK_RADIUS_K-th
// neighbour (knn->k must be >= RS_PACK_RADIUS_K), clamped to the [1st, 99th] percentile range so stray
// points neither vanish nor cover the face.
#define RS_PACK_RADIUS_K 8
#define RS_PACK_RADIUS_SCALE 1.0f
rs_result rs_pack_radii(const rs_pack_knn *knn, float *radius, rs_error *err);

// ---------------------------------------------------------------------------------------------------
// LOD ordering and decimation (pack_lod.c).

// Reorders ids[0..n) so that ids[0..target) are a Poisson-disk-like subset of the points ids[0..n):
// weighted sample elimination (Yuksel 2015, "Sample Elimination for Generating Poisson Disk Sample
// Sets", eq. 1-3, alpha = 8, weight limiting with beta = 0.65, gamma = 1.5) on the kNN graph.
rs_result rs_pack_eliminate(const float (*pos)[3], uint32_t *ids, uint32_t n, uint32_t target,
                            rs_error *err);

// Computes the splat order: coarse to fine levels by Poisson-disk dart throwing, prefix sizes about
// N/2^i, each prefix a maximal Poisson-disk subset containing the coarser ones; Morton order inside each
// level. order[0..count) receives point indices; lods[0..*lod_count) the prefix lengths, descending,
// lods[0] == count, the smallest >= min_lod (0 = RS_PACK_DEFAULT_MIN_LOD) unless count itself is smaller.
rs_result rs_pack_lod_order(const float (*pos)[3], uint32_t count, uint32_t min_lod, uint32_t *order,
                            uint32_t lods[RS_SPLAT_MAX_LODS], uint32_t *lod_count,
                            void (*progress)(void *user, double fraction), void *user, rs_error *err);

// ---------------------------------------------------------------------------------------------------
// Points being converted, and mesh sampling (pack_sample.c).

typedef struct rs_pack_points {
    uint32_t count;
    float (*pos)[3];
    float (*normal)[3];   // NULL until known
    uint8_t (*rgb)[3];    // NULL when the input has no colour
    uint8_t *region;      // region id or RS_PACK_REGION_AUTO, never NULL
    float *specular;      // specular-map value 0..1 per point, or NULL (measured for the report only)
    uint32_t default_rgb; // points given the default colour (no texture page or vertex colour where they lie)
} rs_pack_points;

void rs_pack_points_free(rs_pack_points *p);

// How texture coordinates outside [0, 1] read an image (a material's wrap mode): repeat (tiling, the
// default of glTF, OBJ and GL), clamp to the edge, or mirrored repeat. Inside [0, 1] every mode samples
// the same texels.
typedef enum rs_pack_wrap { RS_PACK_WRAP_REPEAT = 0, RS_PACK_WRAP_CLAMP, RS_PACK_WRAP_MIRROR } rs_pack_wrap;

typedef struct rs_pack_sample_desc {
    uint32_t points;             // samples to draw (0 = RS_PACK_DEFAULT_MESH_POINTS)
    uint64_t seed;               // 0 = RS_PACK_DEFAULT_SEED
    bool all_components;         // false: keep only the largest connected component (by area)
    const rs_image *texture;     // sRGB colour, texel (s W, (1 - t) H) from the top row, bilinear
    // Per-material colour pages when `texture` is NULL: triangle t samples pages[m->tri_page[t]] (page 0
    // when the mesh has no tri_page); a page without pixels falls back to vertex colours.
    const rs_image *pages;
    uint32_t page_count;
    const uint8_t (*page_wrap)[2];  // per page: rs_pack_wrap along u and v (NULL: every page repeats)
    const rs_image *normal_map;  // tangent space, OpenGL convention (+G along +t)
    const rs_image *specular_map;
    const rs_image *region_map;  // UV-space region codes (see rs_pack_region_from_rgb)
} rs_pack_sample_desc;

// Samples a triangle mesh area-uniformly: triangle by the area CDF, barycentric coordinates by the sqrt
// method (Osada et al. 2002, eq. 1). Normals: interpolated vertex normals (or area-weighted face normals
// when the file has none) perturbed by the normal map in the tangent frame from the UV derivatives
// (Lengyel 2001, per vertex, with a handedness sign for mirrored UVs). Maps need texture coordinates.
// *triangles_dropped counts triangles outside the kept component.
rs_result rs_pack_sample_mesh(const rs_ply_mesh *m, const rs_pack_sample_desc *d, rs_pack_points *out,
                              uint32_t *triangles_dropped, rs_error *err);

// Region id for a region-map texel: black other, red cheek, green nose, blue forehead, yellow lips, white
// (or anything else far from these five) RS_PACK_REGION_AUTO (= leave it to the segmentation).
uint8_t rs_pack_region_from_rgb(const uint8_t rgb[3]);

// ---------------------------------------------------------------------------------------------------
// Face frame, landmarks and regions (pack_face.c, pack_regions.c).

typedef enum rs_pack_axis {
    RS_PACK_AXIS_DEFAULT = 0,  // up: +Y, forward: +Z (the frame of the bundled scans)
    RS_PACK_AXIS_POS_X, RS_PACK_AXIS_NEG_X,
    RS_PACK_AXIS_POS_Y, RS_PACK_AXIS_NEG_Y,
    RS_PACK_AXIS_POS_Z, RS_PACK_AXIS_NEG_Z,
} rs_pack_axis;

// Parses "+x", "-y", "z" (= +z) ...; RS_PACK_AXIS_DEFAULT on anything else.
rs_pack_axis rs_pack_axis_parse(const char *s);

#define RS_PACK_FACE_MIN_CONFIDENCE 0.6f

typedef struct rs_pack_face {
    bool found;               // false: no face could be read; the whole scan is `other`
    float up[3], forward[3];  // unit, orthogonal
    float side[3];            // cross(up, forward): towards the subject's left
    float top[3];             // vertex: highest point of the head
    float nose_tip[3];        // pronasale
    float mouth[3];           // stomion (the lip line on the midline)
    float mouth_corner[2][3]; // cheilion: [0] subject's right (-side), [1] left (+side)
    float chin[3];            // pogonion
    float brow_y;             // height (along up, relative to the nose tip) of the brow line
    float face_height;        // vertex to menton, model units
    float face_width;         // silhouette width at the nose tip's height (ears included), model units
    float centre[3];          // centre of the head (orbit centre); the mirror plane goes through it
    bool crown;               // the scan has the top of the head (false: a face-only scan; H from the lips)
    // How sure the finder is that this is a face, in [0, 1]: the mean of the evidence below. Under
    // RS_PACK_FACE_MIN_CONFIDENCE the face is not used (found false; the model framed by its bounds).
    float confidence;
    float evidence[4];        // each in [0, 1]: mirror symmetry, nose, two eye sockets, mouth line
} rs_pack_face;

// Finds the face of a head. With both axes RS_PACK_AXIS_DEFAULT the frame comes from the scan itself in
// any orientation (rs_pack_orient); when that finds no face, or with axes given, the head is assumed
// upright along `up` (within ~20 deg, default +Y) and looking roughly along `forward` (default +Z).
// The nose is the sharpest forward protrusion of the upper face.
rs_result rs_pack_find_face(const float (*pos)[3], const float (*normal)[3], uint32_t count,
                            rs_pack_axis up, rs_pack_axis forward, rs_pack_face *out, rs_error *err);
// The same in a given frame (unit, orthogonal vectors).
rs_result rs_pack_find_face_frame(const float (*pos)[3], const float (*normal)[3], uint32_t count, const float up[3],
                                  const float forward[3], rs_pack_face *out, rs_error *err);
// The face frame of a scan in any orientation (pack_frame.c): the mirror plane gives the side, the nose
// tip and the mean normal of the face around it the forward, a depth template of the face up from down.
// Needs outward normals; *found is false when no face could be read.
// *mirror_offset: the mirror plane is { p : p . side = *mirror_offset }, side = up x forward.
rs_result rs_pack_orient(const float (*pos)[3], const float (*normal)[3], uint32_t count, float up[3], float forward[3],
                         float *mirror_offset, bool *found, rs_error *err);

// Fills every RS_PACK_REGION_AUTO entry of region[] by geometry relative to the face landmarks
// (docs/regions.md); colour is not used. Without a face, AUTO becomes other.
void rs_pack_segment(const float (*pos)[3], const float (*normal)[3], uint32_t count,
                     const rs_pack_face *face, uint8_t *region);

// ---------------------------------------------------------------------------------------------------
// The whole conversion (pack_convert.c).

typedef enum rs_pack_step {
    RS_PACK_STEP_SAMPLE,   // mesh sampling or cloud decimation
    RS_PACK_STEP_NEIGHBOURS,
    RS_PACK_STEP_NORMALS,
    RS_PACK_STEP_RADII,
    RS_PACK_STEP_LOD,
    RS_PACK_STEP_REGIONS,
    RS_PACK_STEP_ENCODE,
    RS_PACK_STEP_AO,       // ambient occlusion (pack_ao.c)
    RS_PACK_STEP_COUNT,
} rs_pack_step;

const char *rs_pack_step_name(rs_pack_step s);

typedef struct rs_pack_desc {
    uint32_t points;              // mesh: samples (0 = 600000); cloud: decimate to this many (0 = keep all)
    uint64_t seed;                // 0 = RS_PACK_DEFAULT_SEED
    bool all_components;          // mesh: keep every component (default: the largest, i.e. the skin)
    const rs_image *texture, *normal_map, *specular_map, *region_map;  // need texture coordinates
    const rs_image *pages;        // mesh: per-material colour pages when texture is NULL (see sampling)
    uint32_t page_count;
    const uint8_t (*page_wrap)[2];  // per page: rs_pack_wrap along u, v (NULL: repeat; other maps repeat)
    float mm_per_unit;            // 0 = the scale rule above (declared, inferred or estimated)
    float declared_mm_per_unit;   // the unit the input file declares (0 = none), and why ("glTF: metres")
    const char *declared_unit;
    uint32_t min_lod;             // smallest LOD prefix (0 = RS_PACK_DEFAULT_MIN_LOD)
    rs_pack_axis up, forward;     // 0 = +Y up, +Z forward
    const char *notes;            // appended to the input's PLY comments in the header notes
    bool no_ao;                   // skip the per-splat ambient occlusion (the file then has none)
    void (*progress)(void *user, rs_pack_step step, double fraction);
    void *progress_user;
} rs_pack_desc;

typedef struct rs_pack_report {
    uint32_t input_vertices, input_triangles;
    uint32_t triangles_dropped;   // outside the largest component
    uint32_t duplicates_dropped;  // points at the same position as another
    uint32_t splats;
    uint32_t colour_default_points;  // samples given the default grey (all when colour_default)
    bool sampled_mesh, normals_estimated, colour_default, mm_estimated;  // mm_estimated: scale == ESTIMATED
    rs_pack_scale scale;          // which rule set mm_per_unit, and in words why
    char scale_why[256];
    uint32_t normals_replaced;  // input normals that were zero or not finite, re-estimated (0: all usable)
    uint32_t regions_given;       // splats whose region came from the input (map or PLY property)
    rs_pack_face face;
    bool face_rejected;           // a face was found but its frame was not finite: converted as no face
    float specular_mean[RS_SPLAT_MAX_REGIONS];  // mean specular-map value per region, NAN without a map
    double seconds[RS_PACK_STEP_COUNT];
} rs_pack_report;

// Ambient occlusion per splat (pack_ao.c): the cosine-weighted fraction of RS_PACK_AO_DIRS directions over
// the sphere from which nothing of the cloud hides the splat, q/255, and (bent, may be NULL) the unit
// cosine-weighted mean of those open directions (the normal where none is open). A few seconds for 600k
// splats.
#define RS_PACK_AO_DIRS 96
rs_result rs_pack_ao(const rs_splat *splats, uint32_t n, uint8_t *ao, float (*bent)[3], rs_error *err);
// The same with only splats[0..occluders) drawn as occluders, their radii scaled by sqrt(n / occluders)
// (an LOD prefix: an even subsample covering the same surface); every splat is tested.
rs_result rs_pack_ao_prefix(const rs_splat *splats, uint32_t n, uint32_t occluders, uint8_t *ao, float (*bent)[3],
                            rs_error *err);
// The same for a cloud's splats as the file stores them (quantised), set into it (RS_SPLAT_FLAG_AO and
// RS_SPLAT_FLAG_BENT): converting and `rouge-pack --ao` on the result give the same bytes.
rs_result rs_pack_ao_cloud(rs_splat_cloud *c, rs_error *err);

// Converts a loaded PLY into a cloud ready for rs_splat_save. `report` may be NULL.
rs_result rs_pack_convert(const rs_ply_mesh *in, const rs_pack_desc *desc, rs_splat_cloud **out,
                          rs_pack_report *report, rs_error *err);

// ---------------------------------------------------------------------------------------------------
// CPU preview (pack_preview.c): an orthographic z-buffered disk rasteriser, for people and tests to
// check a conversion without GL. Panels left to right: front colour (headlight shading), front
// regions, side (from the subject's left) regions: cheek red, nose green, forehead blue, lips yellow,
// other grey. Framed on the head (1.3 face heights around the centre) when the scan is larger.
rs_result rs_pack_preview(const rs_splat_cloud *c, int panel_px, rs_image *out, rs_error *err);

#endif
