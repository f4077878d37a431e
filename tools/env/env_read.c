// env_read.c — OpenEXR and Radiance .hdr latlong maps into floats, sizes checked before any pixel memory.
#include "env/env_read.h"

#include "env/exr_read.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>

// A whole file is read into memory first; an 8K float EXR is about 400 MB.
#define MAX_FILE_BYTES ((size_t)1 << 30)

static rs_result check_size(const char *name, long long w, long long h, int max_width, rs_error *err)
{
    if (w <= 0 || h <= 0 || w > max_width || h > max_width / 2)
        return rs_fail(err, RS_ERR_LIMIT, "%s: %lldx%lld pixels: an environment map is at most %dx%d", name, w, h,
                       max_width, max_width / 2);
    if (w != 2 * h || w < RS_ENVMAP_MIN_WIDTH)
        return rs_fail(err, RS_ERR_FORMAT,
                       "%s: %lldx%lld is not a latitude-longitude map (width = 2 x height, at least %dx%d)", name, w,
                       h, RS_ENVMAP_MIN_WIDTH, RS_ENVMAP_MIN_WIDTH / 2);
    return RS_OK;
}

// ---- Radiance .hdr ----

// stb_image decodes the pixels but reads zeros past the end of its buffer, so a truncated file would
// decode as black rows. This walks the pixel data's structure first (as stb reads it: flat RGBE when
// the first row does not start with the 2 2 run-length marker or the width is outside 8..32767,
// otherwise every row run-length encoded channel by channel) and refuses data that ends early.
static rs_result hdr_check_data(const uint8_t *b, size_t len, const char *name, long long w, long long h,
                                rs_error *err)
{
    // Header lines up to the first empty one, then the resolution line.
    size_t pos = 0;
    for (bool first = true;; first = false) {
        size_t e = pos;
        while (e < len && b[e] != '\n') e++;
        if (e >= len) return rs_fail(err, RS_ERR_FORMAT, "%s: the .hdr header never ends (truncated)", name);
        bool empty = e == pos;
        pos = e + 1;
        if (empty && !first) break;
    }
    while (pos < len && b[pos] != '\n') pos++;
    if (pos >= len) return rs_fail(err, RS_ERR_FORMAT, "%s: the .hdr file ends in its resolution line", name);
    pos++;
    size_t avail = len - pos;
    bool rle = w >= 8 && w < 32768 && avail >= 4 && b[pos] == 2 && b[pos + 1] == 2 && !(b[pos + 2] & 0x80);
    if (!rle) {
        if ((unsigned long long)avail / 4 / (unsigned long long)w < (unsigned long long)h)
            return rs_fail(err, RS_ERR_FORMAT, "%s: %zu bytes of pixels, %lldx%lld flat RGBE pixels need %lld (truncated)",
                           name, avail, w, h, 4 * w * h);
        return RS_OK;
    }
    for (long long j = 0; j < h; j++) {
        if (len - pos < 4) return rs_fail(err, RS_ERR_FORMAT, "%s: the file ends at row %lld of %lld (truncated)", name, j, h);
        if (b[pos] != 2 || b[pos + 1] != 2 || ((long long)b[pos + 2] << 8 | b[pos + 3]) != w)
            return rs_fail(err, RS_ERR_FORMAT, "%s: row %lld (byte %zu) does not start a %lld-pixel run-length encoded row",
                           name, j, pos, w);
        pos += 4;
        for (int c = 0; c < 4; c++)
            for (long long x = 0; x < w;) {
                if (pos >= len) return rs_fail(err, RS_ERR_FORMAT, "%s: the file ends at row %lld of %lld (truncated)", name, j, h);
                long long n = b[pos++];
                bool run = n > 128;
                if (run) n -= 128;
                if (n == 0 || n > w - x)
                    return rs_fail(err, RS_ERR_FORMAT, "%s: row %lld: bad run of %lld pixels at byte %zu", name, j, n, pos - 1);
                size_t bytes = run ? 1 : (size_t)n;
                if (len - pos < bytes) return rs_fail(err, RS_ERR_FORMAT, "%s: the file ends at row %lld of %lld (truncated)", name, j, h);
                pos += bytes;
                x += n;
            }
    }
    return RS_OK;
}

static rs_result read_hdr(const uint8_t *data, size_t len, const char *name, int max_width, rs_envmap *out,
                          rs_error *err)
{
    int w = 0, h = 0, comp = 0;
    if (len > (size_t)INT32_MAX) return rs_fail(err, RS_ERR_LIMIT, "%s: %zu bytes, too large for a .hdr", name, len);
    // The size first: a header may claim any size, and stb would allocate it.
    if (!stbi_info_from_memory(data, (int)len, &w, &h, &comp))
        return rs_fail(err, RS_ERR_FORMAT, "%s: not a readable Radiance .hdr (%s)", name, stbi_failure_reason());
    rs_result r = check_size(name, w, h, max_width, err);
    if (r == RS_OK) r = hdr_check_data(data, len, name, w, h, err);
    if (r != RS_OK) return r;
    float *px = stbi_loadf_from_memory(data, (int)len, &w, &h, &comp, 3);
    if (!px) return rs_fail(err, RS_ERR_FORMAT, "%s: cannot decode the .hdr (%s)", name, stbi_failure_reason());
    out->w = w, out->h = h, out->rgb = px;
    return RS_OK;
}

// ---- OpenEXR ----

// OpenEXR's C++ library (which alone decodes DWA in 3.1) reads the attributes it knows by their structure
// and an unknown one by allocating its claimed size: where a claimed size disagrees with the structure the
// two parses part ways and a 300-byte file could make it allocate gigabytes (found by fuzz_envmap). So
// every attribute is walked first: its size fits in the file, and for the types the C++ library parses
// structurally the structure ends exactly at the claimed size. (exr_read.cpp then has OpenEXR's C core
// check the header's values.)
static bool exr_attr_consistent(const char *type, const uint8_t *v, size_t size)
{
    static const struct { const char *type; size_t size; } fixed[] = {
        {"box2i", 16}, {"box2f", 16}, {"v2i", 8}, {"v2f", 8}, {"v2d", 16}, {"v3i", 12}, {"v3f", 12}, {"v3d", 24},
        {"int", 4}, {"float", 4}, {"double", 8}, {"compression", 1}, {"lineOrder", 1}, {"envmap", 1},
        {"deepImageState", 1}, {"chromaticities", 32}, {"m33f", 36}, {"m44f", 64}, {"m33d", 72}, {"m44d", 128},
        {"tiledesc", 9}, {"keycode", 28}, {"timecode", 8}, {"rational", 8},
    };
    for (size_t k = 0; k < RS_COUNT_OF(fixed); k++)
        if (!strcmp(type, fixed[k].type)) return size == fixed[k].size;
    if (!strcmp(type, "chlist")) {  // (name\0, 16 bytes)*, \0
        size_t p = 0;
        while (p < size && v[p]) {
            const uint8_t *nul = memchr(v + p, 0, size - p);
            if (!nul) return false;
            p = (size_t)(nul - v) + 1;
            if (size - p < 16) return false;
            p += 16;
        }
        return p + 1 == size;
    }
    if (!strcmp(type, "preview")) {  // width, height, width * height * 4 bytes
        if (size < 8) return false;
        uint64_t w = rs_le32_get(v), h = rs_le32_get(v + 4);
        return w * h * 4 + 8 == size;
    }
    if (!strcmp(type, "stringvector")) {  // (i32 length, bytes)*
        size_t p = 0;
        while (p < size) {
            if (size - p < 4) return false;
            int32_t n = (int32_t)rs_le32_get(v + p);
            p += 4;
            if (n < 0 || (size_t)n > size - p) return false;
            p += (size_t)n;
        }
        return true;
    }
    return true;  // string, floatvector, opaque types: read by their claimed size
}

static rs_result exr_check_attributes(const uint8_t *b, size_t len, const char *name, rs_error *err)
{
    if (len < 8) return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: the file ends in its version field", name);
    uint32_t version = rs_le32_get(b + 4);
    bool multipart = version & 0x1000;
    size_t pos = 8, max_name = version & 0x400 ? 255 : 31;
    for (int part = 0;; part++) {
        int attrs = 0;
        for (;; attrs++) {
            char tok[2][256];
            for (int t = 0; t < 2; t++) {
                size_t t0 = pos;
                while (pos < len && b[pos] && pos - t0 < max_name) pos++;
                if (pos >= len || b[pos])
                    return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: header %d: attribute %s at byte %zu is cut or too long",
                                   name, part, t ? "type" : "name", t0);
                memcpy(tok[t], b + t0, pos - t0);
                tok[t][pos - t0] = 0;
                pos++;
                if (t == 0 && !tok[0][0]) break;  // an empty name ends the header
            }
            if (!tok[0][0]) break;
            if (len - pos < 4) return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: the header ends early (truncated)", name);
            int32_t size = (int32_t)rs_le32_get(b + pos);
            pos += 4;
            if (size < 0 || (size_t)size > len - pos)
                return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: attribute '%.40s' claims %d bytes, %zu remain (byte %zu)",
                               name, tok[0], size, len - pos, pos - 4);
            if (!exr_attr_consistent(tok[1], b + pos, (size_t)size))
                return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: attribute '%.40s' (%.40s): %d bytes do not match its contents",
                               name, tok[0], tok[1], size);
            pos += (size_t)size;
        }
        if (!multipart || attrs == 0) break;  // a multipart file's headers end with an empty one
    }
    return RS_OK;
}

static rs_result read_exr(const uint8_t *data, size_t len, const char *name, int max_width, rs_envmap *out,
                          rs_error *err)
{
    char msg[256] = "";
    int w = 0, h = 0;
    float *rgb = NULL;
    rs_result cr = exr_check_attributes(data, len, name, err);
    if (cr != RS_OK) return cr;
    int rc = rs_exr_read_memory(data, len, name, max_width, &w, &h, &rgb, msg, sizeof msg);
    if (rc == 2) {
        rs_result r = check_size(name, w, h, max_width, err);
        return r != RS_OK ? r : rs_fail(err, RS_ERR_FORMAT, "%s: %dx%d refused", name, w, h);
    }
    if (rc != 0) return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: %.400s", name, msg);
    rs_result r = check_size(name, w, h, max_width, err);
    if (r != RS_OK) {
        free(rgb);
        return r;
    }
    out->w = w, out->h = h, out->rgb = rgb;
    return RS_OK;
}

rs_result rs_envmap_read_memory(const void *data, size_t len, const char *name, int max_width, rs_envmap *out,
                                rs_error *err)
{
    static const uint8_t exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    const uint8_t *b = data;
    max_width = RS_CLAMP(max_width, RS_ENVMAP_MIN_WIDTH, RS_ENVMAP_MAX_WIDTH);
    rs_envmap m = {0};
    rs_result r;
    if (len >= 4 && memcmp(b, exr_magic, 4) == 0) r = read_exr(b, len, name, max_width, &m, err);
    else if (len >= 2 && memcmp(b, "#?", 2) == 0) r = read_hdr(b, len, name, max_width, &m, err);
    else return rs_fail(err, RS_ERR_FORMAT, "%s: neither OpenEXR nor Radiance .hdr (by its first bytes)", name);
    if (r != RS_OK) return r;
    // A few negative or NaN texels (a bad pixel) are dropped, denormals flushed to 0 (they made the bake
    // 4x slower), and 1e9 keeps sums finite. An infinite texel (an overflowed export), or a capture with
    // no light left (all NaN, negative, zero or denormal: the face rendered black), is refused.
    size_t n = (size_t)m.w * m.h * 3, nan = 0, inf = 0, neg = 0;
    float peak = 0.0f;
    for (size_t i = 0; i < n; i++) {
        float v = m.rgb[i];
        if (isnan(v)) nan++, v = 0.0f;
        else if (isinf(v)) inf++, v = 0.0f;
        else if (v < 0.0f) neg++, v = 0.0f;
        else if (v < FLT_MIN) v = 0.0f;
        else if (v > 1e9f) v = 1e9f;
        m.rgb[i] = v;
        peak = fmaxf(peak, v);
    }
    const char *why = peak > 0.0f ? NULL
                      : nan == n ? "NaN"
                      : neg && neg + nan == n ? "negative (or NaN)"
                      : "0 or denormal (below 1e-38)";
    if (inf || why) {
        free(m.rgb);
        if (inf)
            return rs_fail(err, RS_ERR_FORMAT, "%s: %zu of its %zu values are infinite (an overflowed export: re-export "
                                               "with finite values)", name, inf, n);
        return rs_fail(err, RS_ERR_FORMAT, "%s: every value is %s: the capture holds no light", name, why);
    }
    *out = m;
    return RS_OK;
}

rs_result rs_envmap_read(const char *path, rs_envmap *out, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, MAX_FILE_BYTES, &data, &len, err);
    if (r != RS_OK) return r;
    r = rs_envmap_read_memory(data, len, path, RS_ENVMAP_MAX_WIDTH, out, err);
    free(data);
    return r;
}
