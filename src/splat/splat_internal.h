// splat_internal.h — what splat.c (the cloud and its codecs), rsf_io.c (the .rsf file, version 1 and the
// dispatch) and rsf_v2.c (version 2: chunked, entropy-coded records; the progressive loader) share.
// Not part of the public API: the .rsf byte layouts (docs/rsf.md) and the checks all sides run.
#ifndef RS_SPLAT_INTERNAL_H
#define RS_SPLAT_INTERNAL_H

#include "splat.h"

// .rsf layout: byte offsets of every field of the fixed header (all little-endian), see docs/rsf.md.
// Versions 1 and 2 share it; they differ in what follows the notes.
enum {
    RSF_VERSION_1 = 1,
    RSF_VERSION_2 = 2,
    RSF_OFF_MAGIC = 0,
    RSF_OFF_VERSION = 4,
    RSF_OFF_HEADER_SIZE = 8,
    RSF_OFF_FLAGS = 12,
    RSF_OFF_COUNT = 16,
    RSF_OFF_BBOX_MIN = 20,
    RSF_OFF_BBOX_MAX = 32,
    RSF_OFF_RADIUS_MIN = 44,
    RSF_OFF_RADIUS_MAX = 48,
    RSF_OFF_MM_PER_UNIT = 52,
    RSF_OFF_CENTRE = 56,
    RSF_OFF_FORWARD = 68,
    RSF_OFF_UP = 80,
    RSF_OFF_FACE_HEIGHT = 92,
    RSF_OFF_LOD_COUNT = 96,
    RSF_OFF_LODS = 100,
    RSF_OFF_REGION_COUNT = 196,
    RSF_OFF_REGIONS = 200,
    RSF_REGION_SIZE = 24,  // name[16], m f32, rho_s f32
    RSF_OFF_NOTES_LEN = 584,
    RSF_OFF_NOTES = 588,
    RSF_PAYLOAD_ALIGN = 16,  // records start 16-byte aligned (one uvec4 each)
    RSF_RECORD_SIZE = 16,
    RSF_CRC_SIZE = 4,
    // Version 2: after the notes (16-aligned) the chunk table, then the header CRC ending the header.
    RSF2_TABLE_HEAD = 8,    // chunk_count u32, reserved u32
    RSF2_ENTRY_SIZE = 16,   // splats u32, bytes u32, crc u32, codec u32
    RSF2_PLANES = 16,       // codec 1: one byte plane per record byte
    RSF2_PLANE_TABLE = 64,  // codec 1: the 16 planes' compressed sizes, u32 each
};

// Chunk codecs (docs/rsf.md, "Version 2").
enum {
    RSF2_CODEC_STORED = 0,  // the records as in version 1
    RSF2_CODEC_ZSTD = 1,    // per-field delta + zigzag, one byte plane per record byte, one zstd frame per plane
};

#define RSF2_MAX_CHUNKS 4096u
#define RSF2_MAX_CHUNK_SPLATS (1u << 20)  // 16 MiB of records: bounds one chunk's work and buffers
// A chunk may expand at most this much (16 B records from >= 0.25 B): anything more is refused as a
// decompression bomb before a byte is allocated for it; the writer stores such chunks raw instead.
#define RSF2_MAX_EXPANSION 64u
// The largest v2 header: fixed part, notes, padding, the largest chunk table, CRC.
#define RSF2_MAX_HEADER \
    ((size_t)RSF_OFF_NOTES + RS_SPLAT_MAX_NOTES + RSF_PAYLOAD_ALIGN + RSF2_TABLE_HEAD + \
     (size_t)RSF2_MAX_CHUNKS * RSF2_ENTRY_SIZE + RSF_CRC_SIZE + RSF_PAYLOAD_ALIGN)

// A whole version-1 file: fixed header, largest notes, padding, the most records allowed, CRC.
#define RSF_MAX_FILE_BYTES_V1 \
    ((size_t)RSF_OFF_NOTES + RS_SPLAT_MAX_NOTES + RSF_PAYLOAD_ALIGN + (size_t)RS_SPLAT_MAX_COUNT * RSF_RECORD_SIZE + \
     RSF_CRC_SIZE)


static inline size_t rsf_align16(size_t n) { return (n + RSF_PAYLOAD_ALIGN - 1) / RSF_PAYLOAD_ALIGN * RSF_PAYLOAD_ALIGN; }

// Radii are log-quantized over [radius_min, radius_max]; a wider ratio would make the 8-bit steps coarse
// (1e6 gives 5.6 % steps) and risk float overflow in the decode.
#define RS_SPLAT_RADIUS_RATIO_MAX 1e6
// Work bounds a valid file must keep, so no pass's cost can grow past what the view asks for: a splat's
// radius is at most RADIUS_EXTENT_MAX times the bbox's largest extent E, and the splats' disks together
// cover at most AREA_MAX * E^2 (real scans: 2-30; 20k whole-model disks once took hours to shadow).
#define RS_SPLAT_RADIUS_EXTENT_MAX 4.0
// The face frame against the bounding box's largest extent E (a face-only scan's face height is about
// 1 E, a bust's 0.5 E): the height within MIN..MAX E, the centre within MAX E of the box. Generous, so
// any cloud rs_splat_create frames by default passes; what they refuse cannot be framed by a camera.
#define RS_SPLAT_FACE_EXTENT_MIN 1e-6
#define RS_SPLAT_FACE_EXTENT_MAX 1e3
#define RS_SPLAT_AREA_MAX 256.0

// Checks every header field except the payload. `in_file`: errors are RS_ERR_FORMAT and end with
// "(byte N)" (loader), otherwise RS_ERR_ARG without offsets (create/save: the caller's header).
rs_result rs_splat_check_header(const rs_splat_header *h, const char *name, bool in_file, rs_error *err);

// A cloud with every array allocated for `count` splats and a zeroed header; NULL when out of memory.
rs_splat_cloud *rs_splat_alloc(uint32_t count);

// Where records came from, for error messages: `name`; in a file (`in_file`) record i of the range
// starts at byte `off + stride * (i - first)` (stride 0: a compressed chunk, `off` is where it starts),
// and `chunk` >= 0 names the v2 chunk.
typedef struct rs_splat_where {
    const char *name;
    bool in_file;
    size_t off, stride;
    int64_t chunk;
} rs_splat_where;

// Running totals of a decode that goes range by range (the progressive loader), zero to start; the
// quantisation tables are made on the first range.
typedef struct rs_splat_decode_state {
    double area;  // sum of r^2 so far
    uint32_t region_counts[RS_SPLAT_MAX_REGIONS];
    bool ready;
    float lo[3], step[3], radius_of[256];
} rs_splat_decode_state;

// Checks records [first, first + n) (region in the table, flags 0) and fills pos/normal/radius from
// `packed` with the decode the GPU uses; adds to `st` and checks the area bound on the running total
// (it only grows, so a hostile file fails at the first range past it).
rs_result rs_splat_decode_range(rs_splat_cloud *c, uint32_t first, uint32_t n, rs_splat_decode_state *st,
                                const rs_splat_where *where, rs_error *err);
// The whole cloud in one range; fills region_counts. payload_off: file offset of record 0.
rs_result rs_splat_decode_all(rs_splat_cloud *c, const char *name, bool in_file, size_t payload_off,
                              rs_error *err);

// Version 1: checks and loads a whole file (rsf_io.c).
rs_result rs_rsf1_load(const uint8_t *b, size_t len, const char *name, rs_splat_cloud **out, rs_error *err);
// The fixed part of a version-1 header (its first RSF_OFF_NOTES bytes; RS_OK for fewer or a wrong magic):
// header size, counts and every field rs_splat_check_header judges, so a stream refuses a bad header
// before it buffers the records the header announces.
rs_result rs_rsf1_check_head(const uint8_t *b, size_t len, const char *name, rs_error *err);
// Version 2 (rsf_v2.c): writes a whole file; loads one (through the progressive loader).
rs_result rs_rsf2_encode(const rs_splat_cloud *c, const rs_splat_save_desc *d, const char *name, void **out_data,
                         size_t *out_len, rs_error *err);
rs_result rs_rsf2_load(const uint8_t *b, size_t len, const char *name, rs_splat_cloud **out, rs_error *err);
// The v2 chunk codec alone, for tests: n records to the bytes of one chunk (*out: malloc'd; *codec: 0 or
// 1, as the writer chose) and back.
rs_result rs_rsf2_chunk_encode(const rs_splat_packed *rec, uint32_t n, int level, uint8_t **out, size_t *len,
                               uint32_t *codec, rs_error *err);
rs_result rs_rsf2_chunk_decode(const uint8_t *b, size_t len, uint32_t codec, uint32_t n, rs_splat_packed *out,
                               rs_error *err);
// Header fields of both versions: bytes 0..587 into *h (notes excluded); the caller checked the length.
void rs_rsf_read_fixed_header(const uint8_t *b, rs_splat_header *h);
void rs_rsf_write_fixed_header(uint8_t *b, const rs_splat_header *h, uint32_t version, size_t notes_len,
                               size_t header_size);
// The records a writer may write: the header and every record pass what a loader checks.
rs_result rs_rsf_check_for_save(const rs_splat_cloud *c, const char *name, rs_error *err);

#endif
