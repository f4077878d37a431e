// splat_internal.h — what splat.c (the cloud and its codecs) and rsf_io.c (the .rsf file) share.
// Not part of the public API: the .rsf v1 byte layout (docs/rsf.md) and the checks both sides run.
#ifndef RS_SPLAT_INTERNAL_H
#define RS_SPLAT_INTERNAL_H

#include "splat.h"

// .rsf version 1 layout: byte offsets of every field (all little-endian), see docs/rsf.md.
enum {
    RSF_VERSION = 1,
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
};

// Radii are log-quantized over [radius_min, radius_max]; a wider ratio would make the 8-bit steps coarse
// (1e6 gives 5.6 % steps) and risk float overflow in the decode.
#define RS_SPLAT_RADIUS_RATIO_MAX 1e6
// Work bounds a valid file must keep, so no pass's cost can grow past what the view asks for: a splat's
// radius is at most RADIUS_EXTENT_MAX times the bbox's largest extent E, and the splats' disks together
// cover at most AREA_MAX * E^2 (real scans: 2-30; 20k whole-model disks once took hours to shadow).
#define RS_SPLAT_RADIUS_EXTENT_MAX 4.0
#define RS_SPLAT_AREA_MAX 256.0

// Checks every header field except the payload. `in_file`: errors are RS_ERR_FORMAT and end with
// "(byte N)" (loader), otherwise RS_ERR_ARG without offsets (create/save: the caller's header).
rs_result rs_splat_check_header(const rs_splat_header *h, const char *name, bool in_file, rs_error *err);

// A cloud with every array allocated for `count` splats and a zeroed header; NULL when out of memory.
rs_splat_cloud *rs_splat_alloc(uint32_t count);

// Checks each record (region in the table, flags 0) and fills pos/normal/radius/region_counts from
// `packed` with the decode the GPU uses. payload_off: file offset of record 0, for error messages.
rs_result rs_splat_decode_all(rs_splat_cloud *c, const char *name, bool in_file, size_t payload_off,
                              rs_error *err);

#endif
