// env_read.c — OpenEXR and Radiance .hdr latlong maps into floats, sizes checked before any pixel memory.
#include "env/env_read.h"

#include "env/exr_read.h"

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

static rs_result read_exr(const uint8_t *data, size_t len, const char *name, int max_width, rs_envmap *out,
                          rs_error *err)
{
    char msg[256] = "";
    int w = 0, h = 0;
    float *rgb = NULL;
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
    // Negative, NaN or infinite radiance is a broken capture; keep what is usable. 1e9 keeps sums finite.
    size_t n = (size_t)m.w * m.h * 3;
    for (size_t i = 0; i < n; i++)
        if (!(m.rgb[i] >= 0.0f)) m.rgb[i] = 0.0f;
        else if (m.rgb[i] > 1e9f) m.rgb[i] = 1e9f;
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
