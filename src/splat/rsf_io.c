// rsf_io.c — the .rsf file: explicit little-endian bytes, CRC-32, a loader that trusts nothing. Version 1
// (one 16-byte record per splat) is read and written here; load and save dispatch to rsf_v2.c for
// version 2. Layout and rules: docs/rsf.md. Offsets: splat_internal.h.
#define _POSIX_C_SOURCE 200809L  // strnlen
#include "splat_internal.h"

#include <assert.h>
#include <stdlib.h>
#include <string.h>

static const uint8_t rsf_magic[4] = {'R', 'S', 'F', 0};

// The largest file read: a v2 file is never larger than a v1 file plus its chunk table (a chunk never
// outgrows its records stored raw).
#define RSF_MAX_FILE_BYTES (RSF_MAX_FILE_BYTES_V1 + RSF2_MAX_HEADER)

// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as zlib's crc32(): the table is crc of each byte.
static const uint32_t crc_table[256] = {
    0x00000000u, 0x77073096u, 0xee0e612cu, 0x990951bau, 0x076dc419u, 0x706af48fu,
    0xe963a535u, 0x9e6495a3u, 0x0edb8832u, 0x79dcb8a4u, 0xe0d5e91eu, 0x97d2d988u,
    0x09b64c2bu, 0x7eb17cbdu, 0xe7b82d07u, 0x90bf1d91u, 0x1db71064u, 0x6ab020f2u,
    0xf3b97148u, 0x84be41deu, 0x1adad47du, 0x6ddde4ebu, 0xf4d4b551u, 0x83d385c7u,
    0x136c9856u, 0x646ba8c0u, 0xfd62f97au, 0x8a65c9ecu, 0x14015c4fu, 0x63066cd9u,
    0xfa0f3d63u, 0x8d080df5u, 0x3b6e20c8u, 0x4c69105eu, 0xd56041e4u, 0xa2677172u,
    0x3c03e4d1u, 0x4b04d447u, 0xd20d85fdu, 0xa50ab56bu, 0x35b5a8fau, 0x42b2986cu,
    0xdbbbc9d6u, 0xacbcf940u, 0x32d86ce3u, 0x45df5c75u, 0xdcd60dcfu, 0xabd13d59u,
    0x26d930acu, 0x51de003au, 0xc8d75180u, 0xbfd06116u, 0x21b4f4b5u, 0x56b3c423u,
    0xcfba9599u, 0xb8bda50fu, 0x2802b89eu, 0x5f058808u, 0xc60cd9b2u, 0xb10be924u,
    0x2f6f7c87u, 0x58684c11u, 0xc1611dabu, 0xb6662d3du, 0x76dc4190u, 0x01db7106u,
    0x98d220bcu, 0xefd5102au, 0x71b18589u, 0x06b6b51fu, 0x9fbfe4a5u, 0xe8b8d433u,
    0x7807c9a2u, 0x0f00f934u, 0x9609a88eu, 0xe10e9818u, 0x7f6a0dbbu, 0x086d3d2du,
    0x91646c97u, 0xe6635c01u, 0x6b6b51f4u, 0x1c6c6162u, 0x856530d8u, 0xf262004eu,
    0x6c0695edu, 0x1b01a57bu, 0x8208f4c1u, 0xf50fc457u, 0x65b0d9c6u, 0x12b7e950u,
    0x8bbeb8eau, 0xfcb9887cu, 0x62dd1ddfu, 0x15da2d49u, 0x8cd37cf3u, 0xfbd44c65u,
    0x4db26158u, 0x3ab551ceu, 0xa3bc0074u, 0xd4bb30e2u, 0x4adfa541u, 0x3dd895d7u,
    0xa4d1c46du, 0xd3d6f4fbu, 0x4369e96au, 0x346ed9fcu, 0xad678846u, 0xda60b8d0u,
    0x44042d73u, 0x33031de5u, 0xaa0a4c5fu, 0xdd0d7cc9u, 0x5005713cu, 0x270241aau,
    0xbe0b1010u, 0xc90c2086u, 0x5768b525u, 0x206f85b3u, 0xb966d409u, 0xce61e49fu,
    0x5edef90eu, 0x29d9c998u, 0xb0d09822u, 0xc7d7a8b4u, 0x59b33d17u, 0x2eb40d81u,
    0xb7bd5c3bu, 0xc0ba6cadu, 0xedb88320u, 0x9abfb3b6u, 0x03b6e20cu, 0x74b1d29au,
    0xead54739u, 0x9dd277afu, 0x04db2615u, 0x73dc1683u, 0xe3630b12u, 0x94643b84u,
    0x0d6d6a3eu, 0x7a6a5aa8u, 0xe40ecf0bu, 0x9309ff9du, 0x0a00ae27u, 0x7d079eb1u,
    0xf00f9344u, 0x8708a3d2u, 0x1e01f268u, 0x6906c2feu, 0xf762575du, 0x806567cbu,
    0x196c3671u, 0x6e6b06e7u, 0xfed41b76u, 0x89d32be0u, 0x10da7a5au, 0x67dd4accu,
    0xf9b9df6fu, 0x8ebeeff9u, 0x17b7be43u, 0x60b08ed5u, 0xd6d6a3e8u, 0xa1d1937eu,
    0x38d8c2c4u, 0x4fdff252u, 0xd1bb67f1u, 0xa6bc5767u, 0x3fb506ddu, 0x48b2364bu,
    0xd80d2bdau, 0xaf0a1b4cu, 0x36034af6u, 0x41047a60u, 0xdf60efc3u, 0xa867df55u,
    0x316e8eefu, 0x4669be79u, 0xcb61b38cu, 0xbc66831au, 0x256fd2a0u, 0x5268e236u,
    0xcc0c7795u, 0xbb0b4703u, 0x220216b9u, 0x5505262fu, 0xc5ba3bbeu, 0xb2bd0b28u,
    0x2bb45a92u, 0x5cb36a04u, 0xc2d7ffa7u, 0xb5d0cf31u, 0x2cd99e8bu, 0x5bdeae1du,
    0x9b64c2b0u, 0xec63f226u, 0x756aa39cu, 0x026d930au, 0x9c0906a9u, 0xeb0e363fu,
    0x72076785u, 0x05005713u, 0x95bf4a82u, 0xe2b87a14u, 0x7bb12baeu, 0x0cb61b38u,
    0x92d28e9bu, 0xe5d5be0du, 0x7cdcefb7u, 0x0bdbdf21u, 0x86d3d2d4u, 0xf1d4e242u,
    0x68ddb3f8u, 0x1fda836eu, 0x81be16cdu, 0xf6b9265bu, 0x6fb077e1u, 0x18b74777u,
    0x88085ae6u, 0xff0f6a70u, 0x66063bcau, 0x11010b5cu, 0x8f659effu, 0xf862ae69u,
    0x616bffd3u, 0x166ccf45u, 0xa00ae278u, 0xd70dd2eeu, 0x4e048354u, 0x3903b3c2u,
    0xa7672661u, 0xd06016f7u, 0x4969474du, 0x3e6e77dbu, 0xaed16a4au, 0xd9d65adcu,
    0x40df0b66u, 0x37d83bf0u, 0xa9bcae53u, 0xdebb9ec5u, 0x47b2cf7fu, 0x30b5ffe9u,
    0xbdbdf21cu, 0xcabac28au, 0x53b39330u, 0x24b4a3a6u, 0xbad03605u, 0xcdd70693u,
    0x54de5729u, 0x23d967bfu, 0xb3667a2eu, 0xc4614ab8u, 0x5d681b02u, 0x2a6f2b94u,
    0xb40bbe37u, 0xc30c8ea1u, 0x5a05df1bu, 0x2d02ef8du,
};

// Large buffers go 8 bytes per step ("slicing-by-8", Kounavis & Berry 2005): t[k][b] is the CRC of byte b
// followed by k zero bytes. The tables take ~2 us to build, so they live on the stack, not in a global.
static uint32_t crc32_sliced(uint32_t crc, const uint8_t *p, size_t len)
{
    uint32_t t[8][256];
    memcpy(t[0], crc_table, sizeof t[0]);
    for (int k = 1; k < 8; k++)
        for (int b = 0; b < 256; b++) t[k][b] = (t[k - 1][b] >> 8) ^ crc_table[t[k - 1][b] & 0xffu];
    for (; len >= 8; len -= 8, p += 8) {
        uint32_t lo = crc ^ rs_le32_get(p), hi = rs_le32_get(p + 4);
        crc = t[7][lo & 0xffu] ^ t[6][(lo >> 8) & 0xffu] ^ t[5][(lo >> 16) & 0xffu] ^ t[4][lo >> 24] ^
              t[3][hi & 0xffu] ^ t[2][(hi >> 8) & 0xffu] ^ t[1][(hi >> 16) & 0xffu] ^ t[0][hi >> 24];
    }
    for (; len > 0; len--, p++) crc = crc_table[(crc ^ *p) & 0xffu] ^ (crc >> 8);
    return crc;
}

uint32_t rs_crc32(uint32_t crc, const void *data, size_t len)
{
    const uint8_t *p = data;
    crc = ~crc;
    if (len >= 4096) return ~crc32_sliced(crc, p, len);
    for (size_t i = 0; i < len; i++) crc = crc_table[(crc ^ p[i]) & 0xffu] ^ (crc >> 8);
    return ~crc;
}

// ---- little-endian fields (core.h), independent of the host ----

static void rd_vec3(const uint8_t *b, size_t off, float v[3])
{
    for (int a = 0; a < 3; a++) v[a] = rs_lef32_get(b + off + 4 * (size_t)a);
}

static void wr_vec3(uint8_t *b, size_t off, const float v[3])
{
    for (int a = 0; a < 3; a++) rs_lef32_put(b + off + 4 * (size_t)a, v[a]);
}

static size_t header_size_for(size_t notes_len) { return rsf_align16(RSF_OFF_NOTES + notes_len); }

// The fixed part of the header (bytes 0..587), field by field; the caller checked len >= RSF_OFF_NOTES.
void rs_rsf_read_fixed_header(const uint8_t *b, rs_splat_header *h)
{
    memset(h, 0, sizeof *h);
    h->flags = rs_le32_get(b + RSF_OFF_FLAGS);
    h->count = rs_le32_get(b + RSF_OFF_COUNT);
    rd_vec3(b, RSF_OFF_BBOX_MIN, h->bbox_min);
    rd_vec3(b, RSF_OFF_BBOX_MAX, h->bbox_max);
    h->radius_min = rs_lef32_get(b + RSF_OFF_RADIUS_MIN);
    h->radius_max = rs_lef32_get(b + RSF_OFF_RADIUS_MAX);
    h->mm_per_unit = rs_lef32_get(b + RSF_OFF_MM_PER_UNIT);
    rd_vec3(b, RSF_OFF_CENTRE, h->centre);
    rd_vec3(b, RSF_OFF_FORWARD, h->forward);
    rd_vec3(b, RSF_OFF_UP, h->up);
    h->face_height = rs_lef32_get(b + RSF_OFF_FACE_HEIGHT);
    h->lod_count = rs_le32_get(b + RSF_OFF_LOD_COUNT);
    for (size_t k = 0; k < RS_SPLAT_MAX_LODS; k++) h->lods[k] = rs_le32_get(b + RSF_OFF_LODS + 4 * k);
    h->region_count = rs_le32_get(b + RSF_OFF_REGION_COUNT);
    for (size_t k = 0; k < RS_SPLAT_MAX_REGIONS; k++) {
        const uint8_t *r = b + RSF_OFF_REGIONS + k * RSF_REGION_SIZE;
        memcpy(h->regions[k].name, r, sizeof h->regions[k].name);
        h->regions[k].m = rs_lef32_get(r + 16);
        h->regions[k].rho_s = rs_lef32_get(r + 20);
    }
}

// Bytes 0..587 and the notes; `b` is zeroed (unused slots stay 0: one canonical byte form per cloud).
void rs_rsf_write_fixed_header(uint8_t *b, const rs_splat_header *h, uint32_t version, size_t notes_len,
                               size_t header_size)
{
    memcpy(b + RSF_OFF_MAGIC, rsf_magic, sizeof rsf_magic);
    rs_le32_put(b + RSF_OFF_VERSION, version);
    rs_le32_put(b + RSF_OFF_HEADER_SIZE, (uint32_t)header_size);
    rs_le32_put(b + RSF_OFF_FLAGS, h->flags);
    rs_le32_put(b + RSF_OFF_COUNT, h->count);
    wr_vec3(b, RSF_OFF_BBOX_MIN, h->bbox_min);
    wr_vec3(b, RSF_OFF_BBOX_MAX, h->bbox_max);
    rs_lef32_put(b + RSF_OFF_RADIUS_MIN, h->radius_min);
    rs_lef32_put(b + RSF_OFF_RADIUS_MAX, h->radius_max);
    rs_lef32_put(b + RSF_OFF_MM_PER_UNIT, h->mm_per_unit);
    wr_vec3(b, RSF_OFF_CENTRE, h->centre);
    wr_vec3(b, RSF_OFF_FORWARD, h->forward);
    wr_vec3(b, RSF_OFF_UP, h->up);
    rs_lef32_put(b + RSF_OFF_FACE_HEIGHT, h->face_height);
    rs_le32_put(b + RSF_OFF_LOD_COUNT, h->lod_count);
    // Unused slots stay 0 (the buffer is zeroed): one canonical byte form per cloud.
    for (size_t k = 0; k < h->lod_count; k++) rs_le32_put(b + RSF_OFF_LODS + 4 * k, h->lods[k]);
    rs_le32_put(b + RSF_OFF_REGION_COUNT, h->region_count);
    for (size_t k = 0; k < h->region_count; k++) {
        uint8_t *r = b + RSF_OFF_REGIONS + k * RSF_REGION_SIZE;
        memcpy(r, h->regions[k].name, strnlen(h->regions[k].name, sizeof h->regions[k].name));
        rs_lef32_put(r + 16, h->regions[k].m);
        rs_lef32_put(r + 20, h->regions[k].rho_s);
    }
    rs_le32_put(b + RSF_OFF_NOTES_LEN, (uint32_t)notes_len);
    memcpy(b + RSF_OFF_NOTES, h->notes, notes_len);
}

// ---- load ----

// Sizes, CRC and notes: everything that must hold before any field is believed. On success *h holds the
// whole header and *payload_off the offset of record 0.
static rs_result check_layout(const uint8_t *b, size_t len, const char *name, rs_splat_header *h,
                              size_t *payload_off, rs_error *err)
{
    if (len < sizeof rsf_magic)
        return rs_fail(err, RS_ERR_FORMAT, "%s: magic: file is %zu bytes, too short for an .rsf file (byte %zu)", name,
                       len, len);
    if (memcmp(b, rsf_magic, sizeof rsf_magic) != 0)
        return rs_fail(err, RS_ERR_FORMAT,
                       "%s: magic: not an .rsf file (starts %02x %02x %02x %02x, expected 52 53 46 00) (byte 0)", name,
                       b[0], b[1], b[2], b[3]);
    if (len < RSF_OFF_VERSION + 4)
        return rs_fail(err, RS_ERR_FORMAT, "%s: version: file ends inside the header (byte %zu)", name, len);
    uint32_t version = rs_le32_get(b + RSF_OFF_VERSION);
    if (version != RSF_VERSION_1)
        return rs_fail(err, RS_ERR_FORMAT,
                       "%s: version: unsupported version %u (this build reads versions 1 and 2) (byte %d)", name,
                       version, RSF_OFF_VERSION);
    if (len < RSF_OFF_NOTES)
        return rs_fail(err, RS_ERR_FORMAT,
                       "%s: header: file is %zu bytes, ends inside the %d-byte fixed header (byte %zu)", name, len,
                       RSF_OFF_NOTES, len);

    uint32_t notes_len = rs_le32_get(b + RSF_OFF_NOTES_LEN);
    if (notes_len > RS_SPLAT_MAX_NOTES - 1)
        return rs_fail(err, RS_ERR_FORMAT, "%s: notes_len: %u bytes, at most %d allowed (byte %d)", name, notes_len,
                       RS_SPLAT_MAX_NOTES - 1, RSF_OFF_NOTES_LEN);
    if (notes_len > len - RSF_OFF_NOTES)
        return rs_fail(err, RS_ERR_FORMAT,
                       "%s: notes_len: %u bytes of notes run past the end of the file (%zu bytes) (byte %d)", name,
                       notes_len, len, RSF_OFF_NOTES_LEN);
    uint32_t header_size = rs_le32_get(b + RSF_OFF_HEADER_SIZE);
    size_t expected = header_size_for(notes_len);
    if (header_size != expected)
        return rs_fail(err, RS_ERR_FORMAT, "%s: header_size: %u, expected %zu for %u bytes of notes (byte %d)", name,
                       header_size, expected, notes_len, RSF_OFF_HEADER_SIZE);

    uint32_t count = rs_le32_get(b + RSF_OFF_COUNT);
    if (count == 0) return rs_fail(err, RS_ERR_FORMAT, "%s: count: 0 splats (byte %d)", name, RSF_OFF_COUNT);
    if (count > RS_SPLAT_MAX_COUNT)
        return rs_fail(err, RS_ERR_LIMIT, "%s: count: %u splats, more than the %u allowed (byte %d)", name, count,
                       RS_SPLAT_MAX_COUNT, RSF_OFF_COUNT);
    size_t payload, total;
    if (!rs_size_mul(count, RSF_RECORD_SIZE, &payload) || !rs_size_add(payload, header_size, &total) ||
        !rs_size_add(total, RSF_CRC_SIZE, &total))
        return rs_fail(err, RS_ERR_LIMIT, "%s: count: %u splats overflow the file size (byte %d)", name, count,
                       RSF_OFF_COUNT);
    if (total > len)
        return rs_fail(err, RS_ERR_FORMAT, "%s: count: %u splats need a %zu-byte file, this one has %zu (byte %d)",
                       name, count, total, len, RSF_OFF_COUNT);
    if (total < len)
        return rs_fail(err, RS_ERR_FORMAT, "%s: file: %zu unexpected bytes after the CRC (byte %zu)", name, len - total,
                       total);

    size_t crc_off = total - RSF_CRC_SIZE;
    uint32_t stored = rs_le32_get(b + crc_off), computed = rs_crc32(0, b, crc_off);
    if (stored != computed)
        return rs_fail(err, RS_ERR_FORMAT, "%s: crc: stored 0x%08x, computed 0x%08x: the file is damaged (byte %zu)",
                       name, stored, computed, crc_off);

    const uint8_t *nul = memchr(b + RSF_OFF_NOTES, 0, notes_len);
    if (nul)
        return rs_fail(err, RS_ERR_FORMAT, "%s: notes: NUL byte inside the notes (byte %zu)", name,
                       (size_t)(nul - b));
    for (size_t i = RSF_OFF_NOTES + notes_len; i < header_size; i++)
        if (b[i] != 0) return rs_fail(err, RS_ERR_FORMAT, "%s: padding: must be 0 (byte %zu)", name, i);

    rs_rsf_read_fixed_header(b, h);
    memcpy(h->notes, b + RSF_OFF_NOTES, notes_len);
    *payload_off = header_size;
    return RS_OK;
}

rs_result rs_rsf1_check_head(const uint8_t *b, size_t len, const char *name, rs_error *err)
{
    if (len < RSF_OFF_NOTES || memcmp(b, rsf_magic, sizeof rsf_magic) != 0) return RS_OK;  // check_layout says why
    uint32_t notes_len = rs_le32_get(b + RSF_OFF_NOTES_LEN), header_size = rs_le32_get(b + RSF_OFF_HEADER_SIZE);
    if (notes_len > RS_SPLAT_MAX_NOTES - 1)
        return rs_fail(err, RS_ERR_FORMAT, "%s: notes_len: %u bytes, at most %d allowed (byte %d)", name, notes_len,
                       RS_SPLAT_MAX_NOTES - 1, RSF_OFF_NOTES_LEN);
    if (header_size != header_size_for(notes_len))
        return rs_fail(err, RS_ERR_FORMAT, "%s: header_size: %u, expected %zu for %u bytes of notes (byte %d)", name,
                       header_size, header_size_for(notes_len), notes_len, RSF_OFF_HEADER_SIZE);
    rs_splat_header *h = calloc(1, sizeof *h);
    if (!h) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", name);
    rs_rsf_read_fixed_header(b, h);
    // The notes are not here yet (their own check comes with the whole file): judged as empty.
    rs_result r = rs_splat_check_header(h, name, true, err);
    free(h);
    return r;
}

rs_result rs_rsf1_load(const uint8_t *b, size_t len, const char *name, rs_splat_cloud **out, rs_error *err)
{
    rs_splat_header *h = malloc(sizeof *h);
    if (!h) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", name);
    size_t payload_off = 0;
    rs_result r = check_layout(b, len, name, h, &payload_off, err);
    if (r == RS_OK) r = rs_splat_check_header(h, name, true, err);
    // Sizes were checked against the file above, so this allocation is bounded by the file's length.
    rs_splat_cloud *c = r == RS_OK ? rs_splat_alloc(h->count) : NULL;
    if (r == RS_OK && !c) r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %u splats", name, h->count);
    if (r != RS_OK) {
        free(h);
        return r;
    }
    c->hdr = *h;
    free(h);
    const uint8_t *p = b + payload_off;
    for (size_t i = 0; i < c->hdr.count; i++, p += RSF_RECORD_SIZE)
        for (size_t k = 0; k < 4; k++) c->packed[i].w[k] = rs_le32_get(p + 4 * k);
    r = rs_splat_decode_all(c, name, true, payload_off, err);
    if (r != RS_OK) {
        rs_splat_destroy(c);
        return r;
    }
    *out = c;
    return RS_OK;
}

// Version 2 goes to rsf_v2.c; everything else to the version-1 loader, which names a wrong magic or an
// unknown version.
static rs_result load_bytes(const uint8_t *b, size_t len, const char *name, rs_splat_cloud **out, rs_error *err)
{
    if (len >= RSF_OFF_VERSION + 4 && memcmp(b, rsf_magic, sizeof rsf_magic) == 0 &&
        rs_le32_get(b + RSF_OFF_VERSION) == RSF_VERSION_2)
        return rs_rsf2_load(b, len, name, out, err);
    return rs_rsf1_load(b, len, name, out, err);
}

rs_result rs_splat_load_memory(const void *data, size_t len, rs_splat_cloud **out, rs_error *err)
{
    assert(out && (data || len == 0));
    static const uint8_t empty[1];
    return load_bytes(data ? data : empty, len, "(memory)", out, err);
}

rs_result rs_splat_load(const char *path, rs_splat_cloud **out, rs_error *err)
{
    assert(path && out);
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, RSF_MAX_FILE_BYTES, &data, &len, err);
    if (r != RS_OK) return r;
    r = load_bytes(data, len, path, out, err);
    free(data);
    return r;
}

// ---- save ----

rs_result rs_rsf_check_for_save(const rs_splat_cloud *c, const char *name, rs_error *err)
{
    const rs_splat_header *h = &c->hdr;
    // The cloud may have been edited since create/load: write only what a loader would accept.
    rs_result r = rs_splat_check_header(h, name, false, err);
    if (r != RS_OK) return r;
    for (uint32_t i = 0; i < h->count; i++) {
        const uint32_t *w = c->packed[i].w;
        if ((w[1] >> 24) >= h->region_count || ((w[3] >> 24) != 0 && !(h->flags & RS_SPLAT_FLAG_AO)))
            return rs_fail(err, RS_ERR_ARG, "%s: splat %u: region %u / flags 0x%02x out of range", name, i, w[1] >> 24,
                           w[3] >> 24);
    }
    return RS_OK;
}

static rs_result encode_v1(const rs_splat_cloud *c, const char *name, void **out_data, size_t *out_len,
                           rs_error *err)
{
    const rs_splat_header *h = &c->hdr;
    rs_result r = rs_rsf_check_for_save(c, name, err);
    if (r != RS_OK) return r;
    size_t notes_len = strlen(h->notes), header_size = header_size_for(notes_len);
    size_t total = header_size + (size_t)h->count * RSF_RECORD_SIZE + RSF_CRC_SIZE;
    uint8_t *b = calloc(1, total);
    if (!b) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %zu bytes", name, total);
    rs_rsf_write_fixed_header(b, h, RSF_VERSION_1, notes_len, header_size);
    uint8_t *p = b + header_size;
    for (size_t i = 0; i < h->count; i++, p += RSF_RECORD_SIZE)
        for (size_t k = 0; k < 4; k++) rs_le32_put(p + 4 * k, c->packed[i].w[k]);
    rs_le32_put(p, rs_crc32(0, b, total - RSF_CRC_SIZE));
    *out_data = b;
    *out_len = total;
    return RS_OK;
}

static rs_result encode_file(const rs_splat_cloud *c, const rs_splat_save_desc *desc, const char *name,
                             void **out_data, size_t *out_len, rs_error *err)
{
    static const rs_splat_save_desc defaults;
    if (!desc) desc = &defaults;
    switch (desc->version) {
    case 0:
    case RSF_VERSION_2: return rs_rsf2_encode(c, desc, name, out_data, out_len, err);
    case RSF_VERSION_1: return encode_v1(c, name, out_data, out_len, err);
    default:
        return rs_fail(err, RS_ERR_ARG, "%s: cannot write .rsf version %u (versions 1 and 2 exist)", name,
                       desc->version);
    }
}

rs_result rs_splat_save_memory_with(const rs_splat_cloud *c, const rs_splat_save_desc *desc, void **out_data,
                                    size_t *out_len, rs_error *err)
{
    assert(c && out_data && out_len);
    return encode_file(c, desc, "(memory)", out_data, out_len, err);
}

rs_result rs_splat_save_memory(const rs_splat_cloud *c, void **out_data, size_t *out_len, rs_error *err)
{
    return rs_splat_save_memory_with(c, NULL, out_data, out_len, err);
}

rs_result rs_splat_save_with(const rs_splat_cloud *c, const char *path, const rs_splat_save_desc *desc,
                             rs_error *err)
{
    assert(c && path);
    void *data;
    size_t len;
    rs_result r = encode_file(c, desc, path, &data, &len, err);
    if (r != RS_OK) return r;
    r = rs_file_write_atomic(path, data, len, err);
    free(data);
    return r;
}

rs_result rs_splat_save(const rs_splat_cloud *c, const char *path, rs_error *err)
{
    return rs_splat_save_with(c, path, NULL, err);
}
