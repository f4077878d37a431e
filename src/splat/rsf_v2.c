// rsf_v2.c — .rsf version 2: the records in chunks that never straddle a LOD level, each entropy-coded
// (per-field delta + zigzag, one byte plane per record byte, one zstd frame per plane) with its own
// CRC, behind a header with its own CRC; and the progressive loader that checks and decodes each chunk
// as soon as its bytes have arrived, so the coarse levels can be drawn while the rest loads.
// Layout and rules: docs/rsf.md ("Version 2"). Every size is checked before anything is allocated.
#include "splat_internal.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zstd.h>

#define DEFAULT_CHUNK_SPLATS 65536u
#define DEFAULT_LEVEL 17  // the 600k scan: 7.81 B/splat in ~1 s; 19 saves nothing and takes 3x as long

typedef struct rsf2_chunk {
    uint32_t first, splats, bytes, crc, codec;
    uint64_t off;  // file offset of its first byte
} rsf2_chunk;

// ---- the record transform (codec 1) ----
//
// Record byte b of every splat of a chunk goes to plane b. The 16-bit fields (x, y, z, normal u, v) and
// the 8-bit ones (radius, region, r - g, g, b - g, flags) are stored as the zigzag of their difference
// from the previous splat's (0 before the first): neighbours in Morton order are close, so most
// differences are small, and the planes of high bytes are nearly constant; zstd's entropy coder does
// the rest. Colour as g with r - g and b - g: skin's channels move together.

static inline uint32_t zz16(uint32_t d) { return ((d << 1) ^ (0u - ((d >> 15) & 1u))) & 0xffffu; }
static inline uint32_t unzz16(uint32_t z) { return ((z >> 1) ^ (0u - (z & 1u))) & 0xffffu; }
static inline uint32_t zz8(uint32_t d) { return ((d << 1) ^ (0u - ((d >> 7) & 1u))) & 0xffu; }
static inline uint32_t unzz8(uint32_t z) { return ((z >> 1) ^ (0u - (z & 1u))) & 0xffu; }

// The record's fields in transform order: 5 of 16 bits, then 6 of 8 bits, with their planes.
enum { F16 = 5, F8 = 6 };
static const uint8_t plane16[F16] = {0, 2, 4, 8, 10};         // low byte; the high byte is the next plane
static const uint8_t plane8[F8] = {6, 7, 12, 13, 14, 15};

static void fields_of(const uint32_t w[4], uint32_t v16[F16], uint32_t v8[F8])
{
    v16[0] = w[0] & 0xffffu, v16[1] = w[0] >> 16, v16[2] = w[1] & 0xffffu;
    v16[3] = w[2] & 0xffffu, v16[4] = w[2] >> 16;
    uint32_t g = (w[3] >> 8) & 0xffu;
    v8[0] = (w[1] >> 16) & 0xffu, v8[1] = w[1] >> 24;
    v8[2] = ((w[3] & 0xffu) - g) & 0xffu, v8[3] = g, v8[4] = (((w[3] >> 16) & 0xffu) - g) & 0xffu;
    v8[5] = w[3] >> 24;
}

static void forward(const rs_splat_packed *rec, uint32_t n, uint8_t *planes)
{
    uint32_t p16[F16] = {0}, p8[F8] = {0};
    for (uint32_t i = 0; i < n; i++) {
        uint32_t v16[F16], v8[F8];
        fields_of(rec[i].w, v16, v8);
        for (int f = 0; f < F16; f++) {
            uint32_t z = zz16((v16[f] - p16[f]) & 0xffffu);
            planes[(size_t)plane16[f] * n + i] = (uint8_t)z;
            planes[(size_t)(plane16[f] + 1) * n + i] = (uint8_t)(z >> 8);
            p16[f] = v16[f];
        }
        for (int f = 0; f < F8; f++) {
            planes[(size_t)plane8[f] * n + i] = (uint8_t)zz8((v8[f] - p8[f]) & 0xffu);
            p8[f] = v8[f];
        }
    }
}

// The inverse, writing the records' words directly (the same on any host byte order). Blocks of
// splats keep the running sums field by field in short loops (one stream in, one out, in L1), then
// assemble the words: one loop over all sixteen planes at once spills registers and runs 2x slower.
#define INV_BLOCK 256
// After each block, `done(user, i0, m)` checks and decodes it while it is in the cache; non-zero stops.
typedef rs_result (*block_fn)(void *user, uint32_t i0, uint32_t m);

static rs_result inverse(const uint8_t *planes, uint32_t n, rs_splat_packed *rec, block_fn done, void *user)
{
    uint32_t p16[F16] = {0}, p8[F8] = {0};
    uint16_t v16[F16][INV_BLOCK];
    uint8_t v8[F8][INV_BLOCK];
    for (uint32_t i0 = 0; i0 < n; i0 += INV_BLOCK) {
        uint32_t m = RS_MIN(n - i0, (uint32_t)INV_BLOCK);
        // Differences first (independent, and a constant trip count: vectorised), then the running sums
        // (one add per splat). A last short block reads past its plane into the next (or into the
        // buffer's slack): those values are never stored.
        for (int f = 0; f < F16; f++) {
            const uint8_t *lo = planes + (size_t)plane16[f] * n + i0, *hi = lo + n;
            uint16_t *v = v16[f];
            for (uint32_t i = 0; i < INV_BLOCK; i++) v[i] = (uint16_t)unzz16((uint32_t)lo[i] | (uint32_t)hi[i] << 8);
            uint16_t run = (uint16_t)p16[f];
            for (uint32_t i = 0; i < m; i++) v[i] = run = (uint16_t)(run + v[i]);
            p16[f] = run;
        }
        for (int f = 0; f < F8; f++) {
            const uint8_t *q = planes + (size_t)plane8[f] * n + i0;
            uint8_t *v = v8[f];
            for (uint32_t i = 0; i < INV_BLOCK; i++) v[i] = (uint8_t)unzz8(q[i]);
            uint8_t run = (uint8_t)p8[f];
            for (uint32_t i = 0; i < m; i++) v[i] = run = (uint8_t)(run + v[i]);
            p8[f] = run;
        }
        rs_splat_packed *r = rec + i0;
        for (uint32_t i = 0; i < m; i++) {
            uint32_t g = v8[3][i];
            r[i].w[0] = (uint32_t)v16[0][i] | (uint32_t)v16[1][i] << 16;
            r[i].w[1] = (uint32_t)v16[2][i] | (uint32_t)v8[0][i] << 16 | (uint32_t)v8[1][i] << 24;
            r[i].w[2] = (uint32_t)v16[3][i] | (uint32_t)v16[4][i] << 16;
            r[i].w[3] = ((v8[2][i] + g) & 0xffu) | g << 8 | ((v8[4][i] + g) & 0xffu) << 16 | (uint32_t)v8[5][i] << 24;
        }
        rs_result res = done(user, i0, m);
        if (res != RS_OK) return res;
    }
    return RS_OK;
}

// ---- writer ----

// Chunk plan: the levels coarsest first, each cut into near-equal pieces of at most `per` splats.
static uint32_t plan_chunks(const rs_splat_header *h, uint32_t per, rsf2_chunk *out, uint32_t cap)
{
    uint32_t k = 0, start = 0;
    for (uint32_t l = h->lod_count; l-- > 0;) {
        uint32_t end = h->lods[l], len = end - start;
        uint32_t pieces = (len + per - 1) / per;
        for (uint32_t p = 0; p < pieces; p++) {
            uint32_t a = start + (uint32_t)((uint64_t)len * p / pieces), b = start + (uint32_t)((uint64_t)len * (p + 1) / pieces);
            if (k < cap) out[k] = (rsf2_chunk){.first = a, .splats = b - a};
            k++;
        }
        start = end;
    }
    return k;
}

static size_t header_size_v2(size_t notes_len, uint32_t chunks)
{
    return rsf_align16(rsf_align16(RSF_OFF_NOTES + notes_len) + RSF2_TABLE_HEAD + (size_t)chunks * RSF2_ENTRY_SIZE +
                       RSF_CRC_SIZE);
}

// Encodes one chunk at `dst` (room for 64 + 16 bounds); stored raw when coding does not pay, or when it
// would pay more than a reader accepts (RSF2_MAX_EXPANSION).
static rs_result encode_chunk(const rs_splat_packed *rec, rsf2_chunk *ch, int level, ZSTD_CCtx *cc, uint8_t *planes,
                              uint8_t *dst, const char *name, rs_error *err)
{
    uint32_t n = ch->splats;
    size_t raw = (size_t)n * RSF_RECORD_SIZE, bound = ZSTD_compressBound(n), total = RSF2_PLANE_TABLE;
    forward(rec, n, planes);
    for (int b = 0; b < RSF2_PLANES; b++) {
        const uint8_t *plane = planes + (size_t)b * n;
        size_t r = ZSTD_compressCCtx(cc, dst + total, bound, plane, n, level);
        if (ZSTD_isError(r))
            return rs_fail(err, RS_ERR_NOMEM, "%s: zstd: %s (chunk of %u splats)", name, ZSTD_getErrorName(r), n);
        // A plane zstd barely shrinks (the low bytes of positions: near noise) is stored as it is, at
        // exactly n bytes: reading it is a copy, not an entropy decode, for a loss under 1/32 of it.
        if (r >= n - n / 32) {
            memcpy(dst + total, plane, n);
            r = n;
        }
        rs_le32_put(dst + 4 * (size_t)b, (uint32_t)r);
        total += r;
    }
    if (total >= raw || (uint64_t)total * RSF2_MAX_EXPANSION < raw) {
        for (uint32_t i = 0; i < n; i++)
            for (int k = 0; k < 4; k++) rs_le32_put(dst + 16 * (size_t)i + 4 * (size_t)k, rec[i].w[k]);
        ch->codec = RSF2_CODEC_STORED;
        ch->bytes = (uint32_t)raw;
    } else {
        ch->codec = RSF2_CODEC_ZSTD;
        ch->bytes = (uint32_t)total;
    }
    ch->crc = rs_crc32(0, dst, ch->bytes);
    return RS_OK;
}

rs_result rs_rsf2_encode(const rs_splat_cloud *c, const rs_splat_save_desc *d, const char *name, void **out_data,
                         size_t *out_len, rs_error *err)
{
    const rs_splat_header *h = &c->hdr;
    rs_result r = rs_rsf_check_for_save(c, name, err);
    if (r != RS_OK) return r;
    int level = d->level ? d->level : DEFAULT_LEVEL;
    if (level < 1 || level > ZSTD_maxCLevel())
        return rs_fail(err, RS_ERR_ARG, "%s: zstd level %d, must be 1..%d", name, level, ZSTD_maxCLevel());
    uint32_t per = d->chunk_splats ? d->chunk_splats : DEFAULT_CHUNK_SPLATS;
    if (per > RSF2_MAX_CHUNK_SPLATS)
        return rs_fail(err, RS_ERR_ARG, "%s: chunk_splats %u, at most %u", name, per, RSF2_MAX_CHUNK_SPLATS);
    uint32_t nchunks = plan_chunks(h, per, NULL, 0);
    if (nchunks > RSF2_MAX_CHUNKS)
        return rs_fail(err, RS_ERR_ARG, "%s: %u chunks of at most %u splats, more than the %u a file may have", name,
                       nchunks, per, RSF2_MAX_CHUNKS);
    rsf2_chunk *chunks = calloc(nchunks, sizeof *chunks);
    if (!chunks) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", name);
    size_t notes_len = strlen(h->notes), header_size = header_size_v2(notes_len, nchunks);
    // Room for the worst case of every chunk; the file is trimmed to what was written.
    size_t cap = header_size, largest = 0;
    plan_chunks(h, per, chunks, nchunks);
    for (uint32_t k = 0; k < nchunks; k++) {
        cap += RSF2_PLANE_TABLE + RSF2_PLANES * ZSTD_compressBound(chunks[k].splats);
        largest = RS_MAX(largest, (size_t)chunks[k].splats);
    }
    uint8_t *b = calloc(1, cap), *planes = rs_alloc_array(largest, RSF2_PLANES);
    ZSTD_CCtx *cc = ZSTD_createCCtx();
    if (!b || !planes || !cc) {
        r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %zu bytes", name, cap);
        goto out;
    }
    size_t at = header_size;
    for (uint32_t k = 0; k < nchunks && r == RS_OK; k++) {
        r = encode_chunk(c->packed + chunks[k].first, &chunks[k], level, cc, planes, b + at, name, err);
        at += chunks[k].bytes;
    }
    if (r != RS_OK) goto out;
    rs_rsf_write_fixed_header(b, h, RSF_VERSION_2, notes_len, header_size);
    uint8_t *t = b + rsf_align16(RSF_OFF_NOTES + notes_len);
    rs_le32_put(t, nchunks);
    for (uint32_t k = 0; k < nchunks; k++) {
        uint8_t *e = t + RSF2_TABLE_HEAD + (size_t)k * RSF2_ENTRY_SIZE;
        rs_le32_put(e, chunks[k].splats);
        rs_le32_put(e + 4, chunks[k].bytes);
        rs_le32_put(e + 8, chunks[k].crc);
        rs_le32_put(e + 12, chunks[k].codec);
    }
    rs_le32_put(b + header_size - RSF_CRC_SIZE, rs_crc32(0, b, header_size - RSF_CRC_SIZE));
    uint8_t *shrunk = realloc(b, at);
    *out_data = shrunk ? shrunk : b;
    *out_len = at;
    b = NULL;
out:
    ZSTD_freeCCtx(cc);
    free(planes);
    free(b);
    free(chunks);
    return r;
}

// ---- the progressive loader ----

typedef enum ld_state {
    LD_START,   // before the magic, version and header_size (12 bytes)
    LD_HEADER,  // v2: until header_size bytes
    LD_CHUNK,   // v2: until chunk `next` is complete
    LD_DONE,    // v2: every chunk decoded
    LD_V1,      // a version-1 (or unknown) file: kept whole, checked at finish
} ld_state;

struct rs_splat_loader {
    char name[256];
    uint64_t total_known;       // desc.total_bytes
    ld_state st;
    rs_result failed;           // sticky
    char fail_msg[sizeof(((rs_error *)0)->msg)];
    uint8_t *buf;               // bytes of the unit in progress (the whole file for v1)
    size_t have, cap;
    size_t header_size;
    rs_splat_cloud *c;          // the header, and arrays for cap_splats splats
    uint32_t cap_splats;
    rsf2_chunk *chunks;
    uint32_t chunk_count, next, decoded;
    rs_splat_decode_state ds;
    ZSTD_DCtx *dctx;
    uint8_t *planes;
    size_t planes_cap;
};

static rs_result ld_fail(rs_splat_loader *l, rs_error *err, rs_result code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static rs_result ld_fail(rs_splat_loader *l, rs_error *err, rs_result code, const char *fmt, ...)
{
    char msg[sizeof l->fail_msg];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    rs_error e = {0};
    rs_fail(&e, code, "%s", msg);
    l->failed = code;
    memcpy(l->fail_msg, e.msg, sizeof l->fail_msg);
    if (err) *err = e;
    return code;
}

// A failure already in *err (from a shared check): remembered as the sticky one.
static rs_result ld_keep(rs_splat_loader *l, rs_error *err, rs_result code)
{
    l->failed = code;
    memcpy(l->fail_msg, err->msg, sizeof l->fail_msg);
    return code;
}

rs_result rs_splat_loader_create(const rs_splat_loader_desc *desc, rs_splat_loader **out, rs_error *err)
{
    assert(out);
    rs_splat_loader *l = calloc(1, sizeof *l);
    if (!l) return rs_fail(err, RS_ERR_NOMEM, "out of memory for a loader");
    const char *name = desc && desc->name ? desc->name : "(stream)";
    snprintf(l->name, sizeof l->name, "%s", name);
    l->total_known = desc ? desc->total_bytes : 0;
    *out = l;
    return RS_OK;
}

void rs_splat_loader_destroy(rs_splat_loader *l)
{
    if (!l) return;
    rs_splat_destroy(l->c);
    ZSTD_freeDCtx(l->dctx);
    free(l->chunks);
    free(l->planes);
    free(l->buf);
    free(l);
}

// Grows `buf` to hold `need` bytes (need is bounded by the caller: a checked unit, or the v1 file cap).
static bool ensure_buf(rs_splat_loader *l, size_t need)
{
    if (need <= l->cap) return true;
    size_t cap = RS_MAX(need, RS_MAX(l->cap * 2, (size_t)4096));
    uint8_t *p = realloc(l->buf, cap);
    if (!p) return false;
    l->buf = p;
    l->cap = cap;
    return true;
}

// Arrays for at least n splats (n <= count): doubling, so a stream's memory follows what has arrived.
static bool reserve(rs_splat_loader *l, uint32_t n)
{
    rs_splat_cloud *c = l->c;
    if (n <= l->cap_splats) return true;
    uint64_t want = RS_MAX((uint64_t)n, 2 * (uint64_t)l->cap_splats);
    uint32_t cap = (uint32_t)RS_MIN(want, (uint64_t)c->hdr.count);
    void *p;
    if (!(p = realloc(c->packed, (size_t)cap * sizeof *c->packed))) return false;
    c->packed = p;
    if (!(p = realloc(c->pos, (size_t)cap * sizeof *c->pos))) return false;
    c->pos = p;
    if (!(p = realloc(c->normal, (size_t)cap * sizeof *c->normal))) return false;
    c->normal = p;
    if (!(p = realloc(c->radius, (size_t)cap * sizeof *c->radius))) return false;
    c->radius = p;
    l->cap_splats = cap;
    return true;
}

// The first 12 bytes: magic, version (1: kept whole for the v1 loader; anything else refused at once,
// with the v1 loader's words, so a stream of something else is not read to its end), header_size.
static rs_result start(rs_splat_loader *l, const uint8_t *b, rs_error *err)
{
    static const uint8_t magic[4] = {'R', 'S', 'F', 0};
    uint32_t version = rs_le32_get(b + RSF_OFF_VERSION);
    if (memcmp(b, magic, 4) != 0 || (version != RSF_VERSION_1 && version != RSF_VERSION_2)) {
        rs_splat_cloud *c = NULL;
        rs_result r = rs_rsf1_load(b, 12, l->name, &c, err);
        rs_splat_destroy(c);  // cannot load: 12 bytes are no file
        return ld_keep(l, err, r != RS_OK ? r : RS_ERR_FORMAT);
    }
    if (version == RSF_VERSION_1) {
        l->st = LD_V1;
        return RS_OK;
    }
    uint32_t hs = rs_le32_get(b + RSF_OFF_HEADER_SIZE);
    size_t min = header_size_v2(0, 1);
    if (hs < min || hs > RSF2_MAX_HEADER || hs % RSF_PAYLOAD_ALIGN != 0)
        return ld_fail(l, err, RS_ERR_FORMAT,
                       "%s: header_size: %u, a version-2 header is %zu..%zu bytes, a multiple of 16 (byte %d)", l->name,
                       hs, min, (size_t)RSF2_MAX_HEADER, RSF_OFF_HEADER_SIZE);
    l->header_size = hs;
    l->st = LD_HEADER;
    return RS_OK;
}

// Each LOD level must be a whole number of chunks, so a level is complete when its last chunk is.
static rs_result check_chunk_levels(rs_splat_loader *l, size_t table, rs_error *err)
{
    const rs_splat_header *h = &l->c->hdr;
    uint32_t lv = h->lod_count - 1;  // the coarsest level ends at lods[lod_count - 1]
    for (uint32_t k = 0; k < l->chunk_count; k++) {
        const rsf2_chunk *ch = &l->chunks[k];
        while (h->lods[lv] <= ch->first) lv--;  // lods[0] = count > first: stops
        if (ch->first + ch->splats > h->lods[lv])
            return ld_fail(l, err, RS_ERR_FORMAT,
                           "%s: chunks[%u]: splats %u..%u straddle the end of LOD level %u at %u (byte %zu)", l->name, k,
                           ch->first, ch->first + ch->splats - 1, lv, h->lods[lv],
                           table + RSF2_TABLE_HEAD + (size_t)k * RSF2_ENTRY_SIZE);
    }
    return RS_OK;
}

static rs_result parse_table(rs_splat_loader *l, const uint8_t *b, size_t table, rs_error *err)
{
    const rs_splat_header *h = &l->c->hdr;
    uint64_t first = 0, off = l->header_size;
    for (uint32_t k = 0; k < l->chunk_count; k++) {
        size_t e = table + RSF2_TABLE_HEAD + (size_t)k * RSF2_ENTRY_SIZE;
        rsf2_chunk *ch = &l->chunks[k];
        *ch = (rsf2_chunk){(uint32_t)RS_MIN(first, UINT32_MAX), rs_le32_get(b + e), rs_le32_get(b + e + 4),
                           rs_le32_get(b + e + 8), rs_le32_get(b + e + 12), off};
        if (ch->splats == 0 || ch->splats > RSF2_MAX_CHUNK_SPLATS)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunks[%u].splats: %u, must be 1..%u (byte %zu)", l->name, k,
                           ch->splats, RSF2_MAX_CHUNK_SPLATS, e);
        if (first + ch->splats > h->count)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunks[%u].splats: chunks 0..%u hold %llu splats, count is %u (byte %zu)",
                           l->name, k, k, (unsigned long long)(first + ch->splats), h->count, e);
        uint64_t raw = (uint64_t)ch->splats * RSF_RECORD_SIZE;
        if (ch->codec == RSF2_CODEC_STORED) {
            if (ch->bytes != raw)
                return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunks[%u].bytes: %u, a stored chunk of %u splats is %llu (byte %zu)",
                               l->name, k, ch->bytes, ch->splats, (unsigned long long)raw, e + 4);
        } else if (ch->codec == RSF2_CODEC_ZSTD) {
            if (ch->bytes < RSF2_PLANE_TABLE + RSF2_PLANES || ch->bytes >= raw)
                return ld_fail(l, err, RS_ERR_FORMAT,
                               "%s: chunks[%u].bytes: %u, a coded chunk of %u splats is %d..%llu bytes (byte %zu)", l->name,
                               k, ch->bytes, ch->splats, RSF2_PLANE_TABLE + RSF2_PLANES, (unsigned long long)raw - 1, e + 4);
            // The decoded size is known from the header: refuse a bomb before allocating for it.
            if ((uint64_t)ch->bytes * RSF2_MAX_EXPANSION < raw)
                return ld_fail(l, err, RS_ERR_LIMIT,
                               "%s: chunks[%u].bytes: %u bytes would expand to %llu, more than %ux: a decompression "
                               "bomb? (byte %zu)", l->name, k, ch->bytes, (unsigned long long)raw, RSF2_MAX_EXPANSION, e + 4);
        } else {
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunks[%u].codec: %u, this build knows 0 (stored) and 1 (zstd) (byte %zu)",
                           l->name, k, ch->codec, e + 12);
        }
        first += ch->splats;
        off += ch->bytes;
    }
    if (first != h->count)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunks: %u chunks hold %llu splats, count is %u (byte %zu)", l->name,
                       l->chunk_count, (unsigned long long)first, h->count, table);
    rs_result r = check_chunk_levels(l, table, err);
    if (r != RS_OK || !l->total_known || off == l->total_known) return r;
    // A file of known size that the table does not fill exactly: the same words as a stream's end.
    if (l->total_known > off)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: file: %llu unexpected bytes after the last chunk (byte %llu)", l->name,
                       (unsigned long long)(l->total_known - off), (unsigned long long)off);
    uint32_t k = 0;
    while (l->chunks[k].off + l->chunks[k].bytes <= l->total_known) k++;
    const rsf2_chunk *ch = &l->chunks[k];
    return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: file ends after %llu of its %u bytes (byte %llu)", l->name, k,
                   (unsigned long long)(l->total_known > ch->off ? l->total_known - ch->off : 0), ch->bytes,
                   (unsigned long long)l->total_known);
}

static rs_result parse_header(rs_splat_loader *l, const uint8_t *b, rs_error *err)
{
    size_t hs = l->header_size, crc_off = hs - RSF_CRC_SIZE;
    uint32_t stored = rs_le32_get(b + crc_off), computed = rs_crc32(0, b, crc_off);
    if (stored != computed)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: header crc: stored 0x%08x, computed 0x%08x: the file is damaged (byte %zu)",
                       l->name, stored, computed, crc_off);
    uint32_t notes_len = rs_le32_get(b + RSF_OFF_NOTES_LEN);
    if (notes_len > RS_SPLAT_MAX_NOTES - 1)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: notes_len: %u bytes, at most %d allowed (byte %d)", l->name, notes_len,
                       RS_SPLAT_MAX_NOTES - 1, RSF_OFF_NOTES_LEN);
    size_t table = rsf_align16(RSF_OFF_NOTES + notes_len);
    if (table + RSF2_TABLE_HEAD > crc_off)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: notes_len: %u bytes of notes leave no room for the chunk table in a "
                       "%zu-byte header (byte %d)", l->name, notes_len, hs, RSF_OFF_NOTES_LEN);
    uint32_t nchunks = rs_le32_get(b + table);
    if (nchunks == 0 || nchunks > RSF2_MAX_CHUNKS)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk_count: %u, must be 1..%u (byte %zu)", l->name, nchunks,
                       RSF2_MAX_CHUNKS, table);
    if (header_size_v2(notes_len, nchunks) != hs)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: header_size: %zu, expected %zu for %u bytes of notes and %u chunks "
                       "(byte %d)", l->name, hs, header_size_v2(notes_len, nchunks), notes_len, nchunks,
                       RSF_OFF_HEADER_SIZE);
    const uint8_t *nul = memchr(b + RSF_OFF_NOTES, 0, notes_len);
    if (nul)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: notes: NUL byte inside the notes (byte %zu)", l->name,
                       (size_t)(nul - b));
    // Zero padding after the notes and after the table.
    size_t table_end = table + RSF2_TABLE_HEAD + (size_t)nchunks * RSF2_ENTRY_SIZE;
    for (size_t i = RSF_OFF_NOTES + notes_len; i < crc_off; i++) {
        if (i == table) i = table_end;
        if (i < crc_off && b[i] != 0) return ld_fail(l, err, RS_ERR_FORMAT, "%s: padding: must be 0 (byte %zu)", l->name, i);
        if (i >= crc_off) break;
    }
    if (rs_le32_get(b + table + 4) != 0)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk table: reserved word must be 0 (byte %zu)", l->name, table + 4);

    l->c = calloc(1, sizeof *l->c);
    l->chunks = calloc(nchunks, sizeof *l->chunks);
    if (!l->c || !l->chunks) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
    rs_splat_header *h = &l->c->hdr;
    rs_rsf_read_fixed_header(b, h);
    memcpy(h->notes, b + RSF_OFF_NOTES, notes_len);
    rs_result r = rs_splat_check_header(h, l->name, true, err);
    if (r != RS_OK) return ld_keep(l, err, r);
    l->chunk_count = nchunks;
    if ((r = parse_table(l, b, table, err)) != RS_OK) return r;
    // A file whose size is known and matches: every array at once. A stream: as chunks arrive.
    if (l->total_known && !reserve(l, h->count))
        return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory for %u splats", l->name, h->count);
    l->st = LD_CHUNK;
    return RS_OK;
}

// What the per-block check needs: the loader, the chunk, and where errors point.
typedef struct block_ctx {
    rs_splat_loader *l;
    const rsf2_chunk *ch;
    rs_splat_where where;
    rs_error *err;
} block_ctx;

static rs_result check_block(void *user, uint32_t i0, uint32_t m)
{
    block_ctx *x = user;
    rs_result r = rs_splat_decode_range(x->l->c, x->ch->first + i0, m, &x->l->ds, &x->where, x->err);
    return r == RS_OK ? r : ld_keep(x->l, x->err, r);
}

static rs_result decode_planes(rs_splat_loader *l, const rsf2_chunk *ch, uint32_t k, const uint8_t *b, block_fn done,
                               void *user, rs_error *err)
{
    uint32_t n = ch->splats;
    size_t need = (size_t)n * RSF2_PLANES + INV_BLOCK;  // slack: inverse() reads whole blocks
    if (need > l->planes_cap) {
        free(l->planes);
        l->planes_cap = 0;
        if (!(l->planes = malloc(need))) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
        l->planes_cap = need;
    }
    if (!l->dctx && !(l->dctx = ZSTD_createDCtx())) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
    uint64_t at = RSF2_PLANE_TABLE;
    for (int p = 0; p < RSF2_PLANES; p++) {
        uint32_t size = rs_le32_get(b + 4 * (size_t)p);
        uint64_t where = ch->off + at;
        if (size > ch->bytes - at)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: plane %d: %u bytes run past the chunk's end (byte %llu)",
                           l->name, k, p, size, (unsigned long long)(ch->off + 4 * (uint64_t)p));
        const uint8_t *src = b + at;
        uint8_t *dst = l->planes + (size_t)p * n;
        at += size;
        if (size == n) {  // stored as it is
            memcpy(dst, src, n);
            continue;
        }
        // Exactly one frame, announcing exactly the plane's size: zstd then writes into the plane and no further.
        size_t fsize = ZSTD_findFrameCompressedSize(src, size);
        unsigned long long content = ZSTD_isError(fsize) ? 0 : ZSTD_getFrameContentSize(src, size);
        if (ZSTD_isError(fsize) || fsize != size || content != n)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: plane %d: not one zstd frame of %u bytes (%s) (byte %llu)",
                           l->name, k, p, n, ZSTD_isError(fsize) ? ZSTD_getErrorName(fsize) : "size differs",
                           (unsigned long long)where);
        size_t got = ZSTD_decompressDCtx(l->dctx, dst, n, src, size);
        if (ZSTD_isError(got) || got != n)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: plane %d: zstd: %s (byte %llu)", l->name, k, p,
                           ZSTD_isError(got) ? ZSTD_getErrorName(got) : "short frame", (unsigned long long)where);
    }
    if (at != ch->bytes)
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: planes hold %llu of its %u bytes (byte %llu)", l->name, k,
                       (unsigned long long)at, ch->bytes, (unsigned long long)ch->off);
    return inverse(l->planes, n, l->c->packed + ch->first, done, user);
}

static rs_result decode_chunk(rs_splat_loader *l, const uint8_t *b, rs_error *err)
{
    uint32_t k = l->next;
    const rsf2_chunk *ch = &l->chunks[k];
    uint32_t computed = rs_crc32(0, b, ch->bytes);
    if (computed != ch->crc)
        return ld_fail(l, err, RS_ERR_FORMAT,
                       "%s: chunk %u: crc: stored 0x%08x, computed 0x%08x: the file is damaged (byte %llu)", l->name, k,
                       ch->crc, computed, (unsigned long long)ch->off);
    if (!reserve(l, ch->first + ch->splats))
        return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory for %u splats", l->name, ch->first + ch->splats);
    bool stored = ch->codec == RSF2_CODEC_STORED;
    block_ctx x = {l, ch, {l->name, true, (size_t)ch->off, stored ? RSF_RECORD_SIZE : 0, k}, err};
    rs_result r;
    if (stored) {
        rs_splat_packed *rec = l->c->packed + ch->first;
        for (uint32_t i = 0; i < ch->splats; i++)
            for (int w = 0; w < 4; w++) rec[i].w[w] = rs_le32_get(b + 16 * (size_t)i + 4 * (size_t)w);
        r = check_block(&x, 0, ch->splats);
    } else {
        r = decode_planes(l, ch, k, b, check_block, &x, err);
    }
    if (r != RS_OK) return r;
    l->decoded = ch->first + ch->splats;
    if (++l->next == l->chunk_count) l->st = LD_DONE;
    return RS_OK;
}

static size_t unit_size(const rs_splat_loader *l)
{
    switch (l->st) {
    case LD_START: return 12;
    case LD_HEADER: return l->header_size;
    case LD_CHUNK: return l->chunks[l->next].bytes;
    default: return 0;
    }
}

rs_result rs_splat_loader_feed(rs_splat_loader *l, const void *data, size_t len, rs_error *err)
{
    assert(l && (data || len == 0));
    rs_error local;
    if (!err) err = &local;
    if (l->failed) return rs_fail(err, l->failed, "%s", l->fail_msg);
    const uint8_t *p = data;
    while (len > 0) {
        if (l->st == LD_V1 && l->have < RSF_OFF_NOTES) {
            // The fixed header is judged as soon as it is all here, before any record it announces is
            // buffered (a header claiming 1 GiB of records used to be buffered whole first).
            size_t take = RS_MIN(len, (size_t)RSF_OFF_NOTES - l->have);
            if (!ensure_buf(l, l->have + take)) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
            memcpy(l->buf + l->have, p, take);
            l->have += take, p += take, len -= take;
            if (l->have < RSF_OFF_NOTES) return RS_OK;
            rs_error e = {0};
            rs_result r = rs_rsf1_check_head(l->buf, l->have, l->name, &e);
            if (r != RS_OK) return ld_fail(l, err, r, "%s", e.msg);
            continue;
        }
        if (l->st == LD_V1) {
            // Kept whole for the v1 loader, up to the length its header announces (the loader judges a
            // shorter file) and the largest file it accepts.
            uint64_t total = RSF_MAX_FILE_BYTES_V1;
            if (l->have >= RSF_OFF_COUNT + 4)
                total = RS_MIN(total, (uint64_t)rs_le32_get(l->buf + RSF_OFF_HEADER_SIZE) +
                                          (uint64_t)rs_le32_get(l->buf + RSF_OFF_COUNT) * RSF_RECORD_SIZE + RSF_CRC_SIZE);
            if (len > total - RS_MIN(total, (uint64_t)l->have))
                return ld_fail(l, err, RS_ERR_FORMAT, "%s: file: more bytes than the %llu its header announces (byte %llu)",
                               l->name, (unsigned long long)total, (unsigned long long)total);
            if (!ensure_buf(l, l->have + len)) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
            memcpy(l->buf + l->have, p, len);
            l->have += len;
            return RS_OK;
        }
        if (l->st == LD_DONE) {
            uint64_t end = l->chunks[l->chunk_count - 1].off + l->chunks[l->chunk_count - 1].bytes;
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: file: unexpected bytes after the last chunk (byte %llu)", l->name,
                           (unsigned long long)end);
        }
        size_t need = unit_size(l);
        const uint8_t *unit;
        if (l->have == 0 && len >= need) {
            // Whole in the caller's buffer: used in place (a file in memory is never copied).
            unit = p;
            if (l->st != LD_START) p += need, len -= need;
        } else {
            // Grown as bytes arrive (doubling), not to the size the table claims.
            size_t take = RS_MIN(need - l->have, len);
            if (!ensure_buf(l, l->have + take)) return ld_fail(l, err, RS_ERR_NOMEM, "%s: out of memory", l->name);
            memcpy(l->buf + l->have, p, take);
            l->have += take, p += take, len -= take;
            if (l->have < need) return RS_OK;
            unit = l->buf;
        }
        rs_result r;
        if (l->st == LD_START) {
            // Only looked at: these bytes begin the header (or the v1 file) and stay where they are.
            if ((r = start(l, unit, err)) != RS_OK) return r;
            continue;
        }
        r = l->st == LD_HEADER ? parse_header(l, unit, err) : decode_chunk(l, unit, err);
        if (r != RS_OK) return r;
        if (unit == l->buf) l->have = 0;
    }
    return RS_OK;
}

const rs_splat_header *rs_splat_loader_header(const rs_splat_loader *l)
{
    return l->c && (l->st == LD_CHUNK || l->st == LD_DONE) && !l->failed ? &l->c->hdr : NULL;
}

uint32_t rs_splat_loader_decoded(const rs_splat_loader *l) { return l->failed ? 0 : l->decoded; }

uint32_t rs_splat_loader_ready(const rs_splat_loader *l)
{
    const rs_splat_header *h = rs_splat_loader_header(l);
    if (!h) return 0;
    for (uint32_t k = 0; k < h->lod_count; k++)
        if (h->lods[k] <= l->decoded) return h->lods[k];
    return 0;
}

// A v1 file is complete once the length its header announces has arrived.
static bool v1_complete(const rs_splat_loader *l)
{
    if (l->have < RSF_OFF_COUNT + 4) return false;
    uint64_t total = (uint64_t)rs_le32_get(l->buf + RSF_OFF_HEADER_SIZE) +
                     (uint64_t)rs_le32_get(l->buf + RSF_OFF_COUNT) * RSF_RECORD_SIZE + RSF_CRC_SIZE;
    return l->have >= total;
}

bool rs_splat_loader_complete(const rs_splat_loader *l)
{
    if (l->failed) return false;
    return l->st == LD_DONE || (l->st == LD_V1 && v1_complete(l));
}

rs_result rs_splat_loader_preview(const rs_splat_loader *l, uint32_t n, rs_splat_cloud **out, rs_error *err)
{
    assert(l && out);
    const rs_splat_header *h = rs_splat_loader_header(l);
    bool level = false;
    for (uint32_t k = 0; h && k < h->lod_count; k++) level |= h->lods[k] == n;
    if (!h || !level || n > l->decoded)
        return rs_fail(err, RS_ERR_ARG, "%s: preview of %u splats: not a LOD prefix decoded yet", l->name, n);
    rs_splat_header *ph = malloc(sizeof *ph);
    if (!ph) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", l->name);
    *ph = *h;
    ph->count = n;
    uint32_t lc = 0;
    memset(ph->lods, 0, sizeof ph->lods);
    for (uint32_t k = 0; k < h->lod_count; k++)
        if (h->lods[k] <= n) ph->lods[lc++] = h->lods[k];
    ph->lod_count = lc;
    // Same codes, radii scaled: drawn alone, the prefix closes the surface as it does inside the whole.
    float s = (float)sqrt((double)h->count / n);
    ph->radius_min *= s;
    ph->radius_max *= s;
    rs_result r = rs_splat_check_header(ph, l->name, false, err);
    rs_splat_cloud *c = r == RS_OK ? rs_splat_alloc(n) : NULL;
    if (r == RS_OK && !c) r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %u splats", l->name, n);
    if (r == RS_OK) {
        c->hdr = *ph;
        memcpy(c->packed, l->c->packed, (size_t)n * sizeof *c->packed);
        r = rs_splat_decode_all(c, l->name, false, 0, err);
    }
    free(ph);
    if (r != RS_OK) {
        rs_splat_destroy(c);
        return r;
    }
    *out = c;
    return RS_OK;
}

rs_result rs_splat_loader_finish(rs_splat_loader *l, rs_splat_cloud **out, rs_error *err)
{
    assert(l && out);
    rs_error local;
    if (!err) err = &local;
    if (l->failed) return rs_fail(err, l->failed, "%s", l->fail_msg);
    switch (l->st) {
    case LD_V1: {
        rs_result r = rs_rsf1_load(l->buf, l->have, l->name, out, err);
        return r == RS_OK ? r : ld_keep(l, err, r);
    }
    case LD_START:
        if (l->have >= RSF_OFF_VERSION + 4 && memcmp(l->buf, "RSF", 4) == 0 &&
            rs_le32_get(l->buf + RSF_OFF_VERSION) == RSF_VERSION_2)
            return ld_fail(l, err, RS_ERR_FORMAT, "%s: header_size: file ends inside the header (byte %zu)", l->name,
                           l->have);
        // Fewer than 12 bytes: what the v1 loader says about a file this short (magic, version, header).
        {
            static const uint8_t empty[1];
            rs_result r = rs_rsf1_load(l->have ? l->buf : empty, l->have, l->name, out, err);
            if (r == RS_OK) return r;  // cannot happen: a v1 file is longer
            return ld_keep(l, err, r);
        }
    case LD_HEADER:
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: header: file ends after %zu of the %zu header bytes (byte %zu)", l->name,
                       l->have, l->header_size, l->have);
    case LD_CHUNK: {
        const rsf2_chunk *ch = &l->chunks[l->next];
        return ld_fail(l, err, RS_ERR_FORMAT, "%s: chunk %u: file ends after %zu of its %u bytes (byte %llu)", l->name,
                       l->next, l->have, ch->bytes, (unsigned long long)(ch->off + l->have));
    }
    case LD_DONE: break;
    }
    rs_splat_cloud *c = l->c;
    memcpy(c->region_counts, l->ds.region_counts, sizeof c->region_counts);
    l->c = NULL;
    l->st = LD_START;
    l->failed = RS_ERR_ARG;
    snprintf(l->fail_msg, sizeof l->fail_msg, "%s: the loader has handed over its cloud", l->name);
    *out = c;
    return RS_OK;
}

// ---- the chunk codec alone (tests) ----

rs_result rs_rsf2_chunk_encode(const rs_splat_packed *rec, uint32_t n, int level, uint8_t **out, size_t *len,
                               uint32_t *codec, rs_error *err)
{
    assert(n >= 1 && n <= RSF2_MAX_CHUNK_SPLATS);
    rsf2_chunk ch = {.splats = n};
    uint8_t *dst = malloc(RSF2_PLANE_TABLE + RSF2_PLANES * ZSTD_compressBound(n)), *planes = malloc((size_t)n * RSF2_PLANES);
    ZSTD_CCtx *cc = ZSTD_createCCtx();
    rs_result r = dst && planes && cc ? encode_chunk(rec, &ch, level, cc, planes, dst, "(chunk)", err)
                                      : rs_fail(err, RS_ERR_NOMEM, "out of memory");
    ZSTD_freeCCtx(cc);
    free(planes);
    if (r != RS_OK) {
        free(dst);
        return r;
    }
    *out = dst;
    *len = ch.bytes;
    *codec = ch.codec;
    return RS_OK;
}

static rs_result no_check(void *user, uint32_t i0, uint32_t m)
{
    (void)user, (void)i0, (void)m;
    return RS_OK;
}

rs_result rs_rsf2_chunk_decode(const uint8_t *b, size_t len, uint32_t codec, uint32_t n, rs_splat_packed *out,
                               rs_error *err)
{
    rs_splat_loader l = {.name = "(chunk)"};
    rs_splat_cloud c = {.packed = out};
    rsf2_chunk ch = {.splats = n, .bytes = (uint32_t)len, .codec = codec};
    l.c = &c;
    rs_result r = RS_OK;
    if (codec == RSF2_CODEC_STORED && len == (size_t)n * RSF_RECORD_SIZE) {
        for (uint32_t i = 0; i < n; i++)
            for (int w = 0; w < 4; w++) out[i].w[w] = rs_le32_get(b + 16 * (size_t)i + 4 * (size_t)w);
    } else if (codec == RSF2_CODEC_ZSTD && len >= RSF2_PLANE_TABLE && len <= UINT32_MAX) {
        r = decode_planes(&l, &ch, 0, b, no_check, NULL, err);
    } else {
        r = rs_fail(err, RS_ERR_FORMAT, "(chunk): codec %u with %zu bytes for %u splats", codec, len, n);
    }
    ZSTD_freeDCtx(l.dctx);
    free(l.planes);
    return r;
}

rs_result rs_rsf2_load(const uint8_t *b, size_t len, const char *name, rs_splat_cloud **out, rs_error *err)
{
    rs_splat_loader *l = NULL;
    rs_result r = rs_splat_loader_create(&(rs_splat_loader_desc){.name = name, .total_bytes = len}, &l, err);
    if (r == RS_OK) r = rs_splat_loader_feed(l, b, len, err);
    if (r == RS_OK) r = rs_splat_loader_finish(l, out, err);
    rs_splat_loader_destroy(l);
    return r;
}
