// splat.h — the splat cloud in memory and the compact .rsf file format (docs/rsf.md).
//
// Does: hold a face as splats (packed 16-byte records, GPU-ready, plus decoded float copies for the CPU);
// encode float splats into records; load/validate and save .rsf files (atomic write; version 2, chunked
// and entropy-coded, by default; version 1 still loads and can be written); load progressively, the
// coarse LOD levels first, from bytes as they arrive (rs_splat_loader); LOD prefixes; region table with
// the specular parameters; the face frame (centre, forward, up) used by the camera and by mirror painting.
// Does not: touch GL (the renderer uploads `packed` as is), read PLY (tools/pack/ply.c), or paint.
//
//   rs_error err = {0};
//   rs_splat_cloud *c = NULL;
//   if (rs_splat_load("assets/face.rsf", &c, &err) != RS_OK) { puts(err.msg); return 1; }
//   uint32_t n = rs_splat_lod_count(c, 50000);   // largest LOD prefix with <= 50k splats
//   rs_splat_destroy(c);
#ifndef RS_SPLAT_H
#define RS_SPLAT_H

#include "core/core.h"

#define RS_SPLAT_MAX_LODS 24
#define RS_SPLAT_MAX_REGIONS 16
#define RS_SPLAT_MAX_NOTES 8192         // attribution / provenance text carried from the source scan
#define RS_SPLAT_MAX_COUNT (64u << 20)  // 64M splats: far above any face scan, keeps sizes in 32 bits
#define RS_SPLAT_FLAG_AO (1u << 0)      // header flag: byte 15 of every record is its ambient occlusion
// Header flag (with RS_SPLAT_FLAG_AO only): the low 6 bits of each half of w[2] are the splat's bent normal
// (below), its normal is the rest (a 10-bit octahedral lattice). Bit 1 is never used: files from before
// it was defined were rejected with it set, so it stays an error.
#define RS_SPLAT_FLAG_BENT (1u << 2)

// Built-in region ids. Every file carries the first five (rs_splat_default_regions); rouge-pack adds
// eyelid and brow; a table may add more after these. Brushes find regions by name.
typedef enum rs_region {
    RS_REGION_OTHER = 0,  // other skin (ears, neck, scalp, chin...)
    RS_REGION_CHEEK = 1,
    RS_REGION_NOSE = 2,
    RS_REGION_FOREHEAD = 3,
    RS_REGION_LIPS = 4,
    RS_REGION_BUILTIN_COUNT = 5,   // the regions a file must have
    RS_REGION_EYELID = 5,          // the eye area: upper and lower lids, from the lash lines to the brow
    RS_REGION_BROW = 6,            // eyebrows (hair)
    RS_REGION_STANDARD_COUNT = 7,  // the regions rouge-pack writes
} rs_region;

// One splat as floats, in model units. Colour is sRGB-encoded 8-bit, as in the scan.
typedef struct rs_splat {
    float pos[3];
    float normal[3];   // unit length, pointing out of the surface
    float radius;      // disk radius, model units
    uint8_t rgb[3];    // sRGB
    uint8_t region;    // index into the region table
} rs_splat;

// The 16-byte record stored in the file and in the GPU buffer (read in shaders as one uvec4):
//   w[0] = x16 | y16 << 16                      position, unorm16 over the bounding box
//   w[1] = z16 | radius8 << 16 | region8 << 24  radius log-quantized over [radius_min, radius_max]
//   w[2] = oct_u16 | oct_v16 << 16              normal, octahedral, snorm16 (max error ~0.003 deg); with
//          RS_SPLAT_FLAG_BENT each half's low 6 bits are the bent normal (the mean open direction) as a
//          turn away from the normal along its two tangents (splat.c), and the normal the code with them
//          cleared (a 10-bit lattice, ~0.2 deg)
//   w[3] = r8 | g8 << 8 | b8 << 16 | ao8 << 24      sRGB colour; ambient occlusion (0 without RS_SPLAT_FLAG_AO)
typedef struct rs_splat_packed {
    uint32_t w[4];
} rs_splat_packed;

typedef struct rs_region_info {
    char name[16];     // "cheek", NUL-terminated
    float m;           // Beckmann roughness
    float rho_s;       // specular scale, Weyrich et al.'s relative units (RS_RHO_S_PHYSICAL)
} rs_region_info;

// The rho_s whose Kelemen/Szirmay-Kalos lobe is the physical one (albedo F0 at normal incidence): the mean
// of Weyrich et al. 2006's per-region values (the region table's "other"). Their rho_s are relative
// strengths; taken as absolute GPU Gems 3 scales skin would reflect 0.7 % at normal incidence, a quarter of
// Fresnel for n = 1.4. The composite divides every rho_s (regions, makeup finishes) by it; the path-traced
// reference (tools/truth/) uses F0 0.028 x rho_s / rho_s(other) the same way.
#define RS_RHO_S_PHYSICAL 0.2725f

typedef struct rs_splat_header {
    uint32_t count;
    float bbox_min[3], bbox_max[3];  // quantization frame, model units
    float radius_min, radius_max;    // log-quantization range of radii, model units
    float mm_per_unit;               // physical scale (diffusion widths are in mm)
    // Face frame: camera yaw/pitch 0 looks at the face from `forward`; mirror plane goes through
    // `centre` with normal cross(up, forward).
    float centre[3], forward[3], up[3];
    float face_height;               // model units; brush sizes are fractions of this
    uint32_t lod_count;              // LOD table: prefix lengths, descending, lods[0] == count
    uint32_t lods[RS_SPLAT_MAX_LODS];
    uint32_t region_count;
    rs_region_info regions[RS_SPLAT_MAX_REGIONS];
    uint32_t flags;                  // RS_SPLAT_FLAG_AO or 0
    char notes[RS_SPLAT_MAX_NOTES];  // attribution (CC-BY) and provenance, NUL-terminated UTF-8
} rs_splat_header;

typedef struct rs_splat_cloud {
    rs_splat_header hdr;
    rs_splat_packed *packed;  // hdr.count records, in LOD order
    // Decoded from `packed` at load (what the renderer will see), for picking, brushes and tests.
    float (*pos)[3];
    float (*normal)[3];
    float *radius;
    uint32_t region_counts[RS_SPLAT_MAX_REGIONS];
} rs_splat_cloud;

// Fills the region table with the five built-in regions and Weyrich et al.'s means
// (other skin = mean of the four measured regions).
void rs_splat_default_regions(rs_splat_header *hdr);

// Builds a cloud from float splats already in LOD order (the converter orders them). `hdr` supplies
// mm_per_unit, face frame, LOD table, regions and notes; count/bbox/radius range are computed here.
// Zero fields (or hdr == NULL) take defaults: mm_per_unit 1, forward +z, up +y, face_height the bbox
// extent along up, LOD table {count}, rs_splat_default_regions. forward/up are stored orthonormalised.
rs_result rs_splat_create(const rs_splat *splats, uint32_t count, const rs_splat_header *hdr,
                          rs_splat_cloud **out, rs_error *err);
void rs_splat_destroy(rs_splat_cloud *c);

// Loads and fully validates a .rsf file (magic, version, sizes, CRC32, finite floats, LOD and region
// tables, field ranges). Errors name the field and byte offset.
rs_result rs_splat_load(const char *path, rs_splat_cloud **out, rs_error *err);
rs_result rs_splat_load_memory(const void *data, size_t len, rs_splat_cloud **out, rs_error *err);
// Serialises to .rsf version 2 (atomic: temp file + rename).
rs_result rs_splat_save(const rs_splat_cloud *c, const char *path, rs_error *err);
rs_result rs_splat_save_memory(const rs_splat_cloud *c, void **out_data, size_t *out_len, rs_error *err);

// How to write a file; the zero value is the default (rs_splat_save's).
typedef struct rs_splat_save_desc {
    uint32_t version;       // 0: the newest (2); 1: version 1 (16 B a splat, for old readers and tests)
    uint32_t chunk_splats;  // v2: at most this many splats per chunk (0: 65536); chunks never straddle a
                            // LOD level, so a reader can draw each level as soon as its chunks arrive
    int level;              // v2: zstd level 1..22 (0: 17; the size barely changes above 15, the time does)
} rs_splat_save_desc;
rs_result rs_splat_save_with(const rs_splat_cloud *c, const char *path, const rs_splat_save_desc *desc,
                             rs_error *err);
rs_result rs_splat_save_memory_with(const rs_splat_cloud *c, const rs_splat_save_desc *desc, void **out_data,
                                    size_t *out_len, rs_error *err);

// ---- progressive loading ----
//
// Feed a file's bytes as they arrive (from a slow disk, a pipe, the network), in pieces of any size; the
// loader checks the header, then decodes and checks each chunk as soon as it is complete. A v2 file
// stores the coarsest LOD level first, so the face can be drawn from the first few percent of the file
// and refined as the rest arrives. A version-1 file is decoded when it is complete.
//
//   rs_splat_loader *l;
//   rs_splat_loader_create(&(rs_splat_loader_desc){.name = path}, &l, &err);
//   while ((n = read(fd, buf, sizeof buf)) > 0 && rs_splat_loader_feed(l, buf, n, &err) == RS_OK)
//       if (rs_splat_loader_ready(l) > shown) { rs_splat_loader_preview(l, rs_splat_loader_ready(l), &p, &err); ... }
//   rs_splat_loader_finish(l, &cloud, &err);  rs_splat_loader_destroy(l);
typedef struct rs_splat_loader rs_splat_loader;

typedef struct rs_splat_loader_desc {
    const char *name;       // for messages (NULL: "(stream)"); copied
    uint64_t total_bytes;   // the file's size when known (a regular file): checked against the header
                            // before anything is allocated. 0: unknown (a stream); then memory grows
                            // only with the chunks that have arrived, whatever the header claims
} rs_splat_loader_desc;

rs_result rs_splat_loader_create(const rs_splat_loader_desc *desc, rs_splat_loader **out, rs_error *err);
void rs_splat_loader_destroy(rs_splat_loader *l);
// Takes the next `len` bytes of the file. Errors (malformed bytes, bytes past the end) are sticky: the
// loader refuses everything after its first error and repeats it.
rs_result rs_splat_loader_feed(rs_splat_loader *l, const void *data, size_t len, rs_error *err);
// The checked header once it has arrived, else NULL.
const rs_splat_header *rs_splat_loader_header(const rs_splat_loader *l);
// Splats decoded and checked so far, a prefix of the LOD order (a v1 file: 0 until rs_splat_loader_finish).
uint32_t rs_splat_loader_decoded(const rs_splat_loader *l);
// The largest LOD prefix (a value of the LOD table) decoded so far, 0 while there is none.
uint32_t rs_splat_loader_ready(const rs_splat_loader *l);
// True once every byte the header announces has arrived (then rs_splat_loader_finish succeeds).
bool rs_splat_loader_complete(const rs_splat_loader *l);
// A cloud of its own holding the first n splats (n: a LOD prefix <= rs_splat_loader_ready), for drawing
// while the rest loads: its header is the file's with count n, the LOD levels up to n, and the radius
// range scaled by sqrt(count / n) so the smaller set still closes the surface (rs_splat_lod_radius_scale).
rs_result rs_splat_loader_preview(const rs_splat_loader *l, uint32_t n, rs_splat_cloud **out, rs_error *err);
// After the last byte: checks that the file was complete and hands over the whole cloud (the loader
// keeps nothing of it). *out is untouched on failure.
rs_result rs_splat_loader_finish(rs_splat_loader *l, rs_splat_cloud **out, rs_error *err);

// Decodes record i (as the GPU sees it).
void rs_splat_get(const rs_splat_cloud *c, uint32_t i, rs_splat *out);
// Per-splat ambient occlusion (byte 15, RS_SPLAT_FLAG_AO): sets it from ao[count] (q/255, 255 = open sky)
// or removes it (NULL; the bent normals go with it); reads it (1 when the cloud has none).
void rs_splat_set_ao(rs_splat_cloud *c, const uint8_t *ao);
float rs_splat_ao(const rs_splat_cloud *c, uint32_t i);
// Per-splat bent normal (RS_SPLAT_FLAG_BENT): the cosine-weighted mean of the directions a splat sees the
// sky in, unit, model space; with the occlusion it makes a cone of visible sky that environments light
// (bent cones). Setting it (bent[count], unit vectors) moves every normal onto the 10-bit lattice the bits
// leave, and fails on a cloud without ambient occlusion; NULL removes it (the normals stay where they are).
// Reading gives the normal when the cloud has none.
rs_result rs_splat_set_bent(rs_splat_cloud *c, const float (*bent)[3], rs_error *err);
void rs_splat_bent(const rs_splat_cloud *c, uint32_t i, float out[3]);
// Largest LOD prefix from the table with at most max_count splats (the smallest level if none fits).
uint32_t rs_splat_lod_count(const rs_splat_cloud *c, uint32_t max_count);
// Radius multiplier for drawing only the first n splats: sqrt(count / n).
float rs_splat_lod_radius_scale(const rs_splat_cloud *c, uint32_t n);

// Re-encodes every normal on a coarser octahedral lattice: codes that are multiples of 2^(16 - bits),
// bits 8..16 (the records stay 16-bit; a reader sees no difference). A scan's normals carry far less
// precision than 16 bits give (0.0025 degrees); each bit dropped saves about 2 bits a splat in a v2
// file. 12 bits: at most 0.05 degrees of error (docs/rsf.md). pos/normal arrays follow the records.
void rs_splat_quantize_normals(rs_splat_cloud *c, int bits);

// Rounds every radius code to a multiple of 2^(8 - bits), bits 4..8 (codes stay 8-bit): a scan's
// radius (its local spacing) is far noisier than the 8-bit log code's steps (0.33 % for the bundled
// head). 6 bits: relative error at most 2 codes' worth, 2 x ln(radius_max / radius_min) / 255 (0.67 %
// for the bundled head), 3 at the top of the range (253..255 go to 252); 2 bits a splat less in a v2
// file. The radius array follows the records.
void rs_splat_quantize_radii(rs_splat_cloud *c, int bits);

// Octahedral normal coding, exposed for tests and shaders' CPU mirror. A record's normal is decoded from
// w[2] & rs_splat_normal_mask(flags) (the bent normal's bits cleared).
uint32_t rs_splat_encode_normal(const float n[3]);
void rs_splat_decode_normal(uint32_t code, float n[3]);
static inline uint32_t rs_splat_normal_mask(uint32_t flags)
{
    return (flags & RS_SPLAT_FLAG_BENT) ? 0xffc0ffc0u : 0xffffffffu;
}

uint32_t rs_crc32(uint32_t crc, const void *data, size_t len);

#endif
