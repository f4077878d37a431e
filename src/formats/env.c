// env.c — the .rse environment file (docs/env.md): load, validate, save; SH, equirect and RGB9E5 helpers.
#define _POSIX_C_SOURCE 200809L  // strnlen
#include "formats/env.h"

#include "splat/splat.h"  // rs_crc32

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RSE_MAGIC "RSE\0"
#define RSE_VERSION 1u
// Header layout (docs/env.md): fixed part, then notes, padded to 4 bytes; then the levels; then the CRC.
#define OFF_VERSION 4
#define OFF_HEADER_SIZE 8
#define OFF_FLAGS 12
#define OFF_NAME 16
#define OFF_SH 48           // 27 f32
#define OFF_LIGHT_DIR 156   // 3 f32
#define OFF_LIGHT_COLOR 168 // 3 f32
#define OFF_LIGHT_ANGLE 180
#define OFF_LEVEL_COUNT 184
#define OFF_LEVEL_M 188     // 8 f32
#define OFF_WIDTH 220
#define OFF_HEIGHT 224
#define OFF_NOTES_LEN 228
#define OFF_NOTES 232
#define PI_F 3.14159265358979f

// --- helpers ---------------------------------------------------------------------------------------------

void rs_env_sh_basis(const float d[3], float y[9])
{
    float x = d[0], yy = d[1], z = d[2];
    y[0] = 0.282095f;
    y[1] = 0.488603f * yy;
    y[2] = 0.488603f * z;
    y[3] = 0.488603f * x;
    y[4] = 1.092548f * x * yy;
    y[5] = 1.092548f * yy * z;
    y[6] = 0.315392f * (3.0f * z * z - 1.0f);
    y[7] = 1.092548f * x * z;
    y[8] = 0.546274f * (x * x - yy * yy);
}

float rs_env_sh_irradiance(const rs_env *env, const float n[3], float out[3])
{
    float y[9];
    rs_env_sh_basis(n, y);
    for (int c = 0; c < 3; c++) {
        float e = 0.0f;
        for (int k = 0; k < 9; k++) e += env->sh[k][c] * y[k];
        out[c] = RS_MAX(e, 0.0f);
    }
    return 0.2126f * out[0] + 0.7152f * out[1] + 0.0722f * out[2];
}

void rs_env_dir_to_uv(const float d[3], float uv[2])
{
    uv[0] = atan2f(d[0], d[2]) / (2.0f * PI_F) + 0.5f;
    uv[1] = acosf(RS_CLAMP(d[1], -1.0f, 1.0f)) / PI_F;
}

void rs_env_uv_to_dir(const float uv[2], float d[3])
{
    float phi = 2.0f * PI_F * (uv[0] - 0.5f), theta = PI_F * uv[1];
    d[0] = sinf(theta) * sinf(phi);
    d[1] = cosf(theta);
    d[2] = sinf(theta) * cosf(phi);
}

// GL_RGB9_E5 (the EXT_texture_shared_exponent rules: 9-bit mantissas, shared 5-bit exponent, bias 15).
uint32_t rs_rgb9e5_pack(const float rgb[3])
{
    const float max_val = (float)(0x1FF) / 512.0f * 65536.0f;  // 65408
    float c[3];
    for (int i = 0; i < 3; i++) c[i] = isfinite(rgb[i]) ? RS_CLAMP(rgb[i], 0.0f, max_val) : 0.0f;
    float m = RS_MAX(c[0], RS_MAX(c[1], c[2]));
    int e = m > 0.0f ? RS_MAX(-16, (int)floorf(log2f(m))) + 1 + 15 : 0;
    e = RS_CLAMP(e, 0, 31);
    float scale = ldexpf(1.0f, e - 15 - 9);
    if ((int)lrintf(m / scale) == 512 && e < 31) e++, scale *= 2.0f;
    uint32_t q[3];
    for (int i = 0; i < 3; i++) q[i] = (uint32_t)RS_MIN(lrintf(c[i] / scale), 511L);
    return q[0] | q[1] << 9 | q[2] << 18 | (uint32_t)e << 27;
}

void rs_rgb9e5_unpack(uint32_t v, float rgb[3])
{
    float scale = ldexpf(1.0f, (int)(v >> 27) - 15 - 9);
    for (int i = 0; i < 3; i++) rgb[i] = (float)((v >> (9 * i)) & 0x1FF) * scale;
}

// --- memory ----------------------------------------------------------------------------------------------

void rs_env_destroy(rs_env *env)
{
    if (!env) return;
    for (int k = 0; k < RS_ENV_MAX_LEVELS; k++) free(env->levels[k].rgb9e5);
    free(env);
}

static bool valid_size(int width, int levels)
{
    if (levels < 1 || levels > RS_ENV_MAX_LEVELS || width < 2 || width > RS_ENV_MAX_WIDTH) return false;
    // Every level halves exactly and keeps at least 2 x 1 texels.
    int height = width / 2;
    return width % 2 == 0 && height % (1 << (levels - 1)) == 0;
}

rs_result rs_env_create(int width, int levels, rs_env **out, rs_error *err)
{
    *out = NULL;
    if (!valid_size(width, levels))
        return rs_fail(err, RS_ERR_ARG, "environment: %d levels of a %d-wide map do not halve evenly (width <= %d)",
                       levels, width, RS_ENV_MAX_WIDTH);
    rs_env *e = calloc(1, sizeof *e);
    if (!e) return rs_fail(err, RS_ERR_NOMEM, "environment: out of memory");
    e->level_count = levels;
    for (int k = 0; k < levels; k++) {
        rs_env_level *l = &e->levels[k];
        l->width = width >> k, l->height = (width / 2) >> k;
        l->rgb9e5 = calloc((size_t)l->width * (size_t)l->height, sizeof(uint32_t));
        if (!l->rgb9e5) {
            rs_env_destroy(e);
            return rs_fail(err, RS_ERR_NOMEM, "environment: out of memory");
        }
    }
    *out = e;
    return RS_OK;
}

// --- validation ------------------------------------------------------------------------------------------

static size_t texel_total(int width, int levels)
{
    size_t n = 0;
    for (int k = 0; k < levels; k++) n += (size_t)(width >> k) * (size_t)((width / 2) >> k);
    return n;
}

// Checks the fields the loader and the writer agree on (everything but sizes and bytes).
static rs_result check_fields(const rs_env *e, const char *what, rs_error *err)
{
    const char *end = memchr(e->name, 0, sizeof e->name);
    if (!end || end == e->name) return rs_fail(err, RS_ERR_FORMAT, "%s: name empty or not NUL-terminated (byte %d)", what, OFF_NAME);
    for (const char *p = e->name; p < end; p++)
        if (!((*p >= 'a' && *p <= 'z') || (*p >= '0' && *p <= '9') || *p == '_' || *p == '-'))
            return rs_fail(err, RS_ERR_FORMAT, "%s: name: only a-z, 0-9, _ and - allowed (byte %d)", what, OFF_NAME);
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++)
            if (!isfinite(e->sh[k][c]) || fabsf(e->sh[k][c]) > 1e6f)
                return rs_fail(err, RS_ERR_FORMAT, "%s: sh[%d][%d] not a finite, sane number (byte %d)", what, k, c,
                               OFF_SH + 4 * (3 * k + c));
    float len2 = 0.0f;
    for (int c = 0; c < 3; c++) {
        if (!isfinite(e->light_dir[c])) return rs_fail(err, RS_ERR_FORMAT, "%s: light direction not finite (byte %d)", what, OFF_LIGHT_DIR);
        len2 += e->light_dir[c] * e->light_dir[c];
        if (!isfinite(e->light_color[c]) || e->light_color[c] < 0.0f || e->light_color[c] > 1e6f)
            return rs_fail(err, RS_ERR_FORMAT, "%s: light colour outside 0..1e6 (byte %d)", what, OFF_LIGHT_COLOR);
    }
    if (fabsf(len2 - 1.0f) > 1e-3f) return rs_fail(err, RS_ERR_FORMAT, "%s: light direction not unit length (byte %d)", what, OFF_LIGHT_DIR);
    if (!isfinite(e->light_angle) || e->light_angle < 0.0f || e->light_angle > PI_F)
        return rs_fail(err, RS_ERR_FORMAT, "%s: light angle outside 0..pi (byte %d)", what, OFF_LIGHT_ANGLE);
    if (e->level_count < 1 || e->level_count > RS_ENV_MAX_LEVELS)
        return rs_fail(err, RS_ERR_FORMAT, "%s: level count %d outside 1..%d (byte %d)", what, e->level_count,
                       RS_ENV_MAX_LEVELS, OFF_LEVEL_COUNT);
    for (int k = 0; k < e->level_count; k++)
        if (!isfinite(e->level_m[k]) || e->level_m[k] <= 0.0f || e->level_m[k] > 4.0f ||
            (k > 0 && e->level_m[k] <= e->level_m[k - 1]))
            return rs_fail(err, RS_ERR_FORMAT, "%s: level %d roughness %g not in (0, 4] and increasing (byte %d)",
                           what, k, e->level_m[k], OFF_LEVEL_M + 4 * k);
    return RS_OK;
}

// --- load ------------------------------------------------------------------------------------------------

rs_result rs_env_load_memory(const void *data, size_t len, rs_env **out, rs_error *err)
{
    *out = NULL;
    const uint8_t *b = data;
    const char *what = "environment";
    if (!b || len < OFF_NOTES + 4) return rs_fail(err, RS_ERR_FORMAT, "%s: %zu bytes, too short for a .rse file", what, len);
    if (memcmp(b, RSE_MAGIC, 4) != 0) return rs_fail(err, RS_ERR_FORMAT, "%s: not a .rse file (magic, byte 0)", what);
    uint32_t version = rs_le32_get(b + OFF_VERSION);
    if (version != RSE_VERSION)
        return rs_fail(err, RS_ERR_FORMAT, "%s: version %u, this build reads %u (byte %d)", what, version, RSE_VERSION, OFF_VERSION);
    if (rs_le32_get(b + OFF_FLAGS) != 0) return rs_fail(err, RS_ERR_FORMAT, "%s: unknown flags (byte %d)", what, OFF_FLAGS);
    uint32_t notes_len = rs_le32_get(b + OFF_NOTES_LEN);
    if (notes_len >= RS_ENV_MAX_NOTES)
        return rs_fail(err, RS_ERR_FORMAT, "%s: notes of %u bytes (at most %d; byte %d)", what, notes_len, RS_ENV_MAX_NOTES - 1, OFF_NOTES_LEN);
    uint32_t header_size = rs_le32_get(b + OFF_HEADER_SIZE);
    if (header_size != ((OFF_NOTES + notes_len + 3u) & ~3u))
        return rs_fail(err, RS_ERR_FORMAT, "%s: header size %u does not match the notes (byte %d)", what, header_size, OFF_HEADER_SIZE);
    uint32_t width = rs_le32_get(b + OFF_WIDTH), height = rs_le32_get(b + OFF_HEIGHT);
    uint32_t levels = rs_le32_get(b + OFF_LEVEL_COUNT);
    if (width > RS_ENV_MAX_WIDTH || (uint64_t)height * 2 != width || levels < 1 || levels > RS_ENV_MAX_LEVELS ||
        !valid_size((int)width, (int)levels))
        return rs_fail(err, RS_ERR_FORMAT, "%s: a %ux%u map with %u levels is not a 2:1 map <= %d wide that halves evenly (byte %d)",
                       what, width, height, levels, RS_ENV_MAX_WIDTH, OFF_WIDTH);
    // Exact length before anything is allocated: a file cannot claim more than it holds.
    size_t texels = texel_total((int)width, (int)levels);
    size_t want = (size_t)header_size + texels * 4 + 4;
    if (len != want) return rs_fail(err, RS_ERR_FORMAT, "%s: %zu bytes, the header says %zu (truncated or extended)", what, len, want);
    uint32_t crc = rs_crc32(0, b, len - 4);
    if (crc != rs_le32_get(b + len - 4)) return rs_fail(err, RS_ERR_FORMAT, "%s: bad CRC (byte %zu)", what, len - 4);
    for (uint32_t i = 0; i < notes_len; i++)
        if (b[OFF_NOTES + i] == 0) return rs_fail(err, RS_ERR_FORMAT, "%s: NUL in the notes (byte %u)", what, OFF_NOTES + i);
    for (uint32_t i = OFF_NOTES + notes_len; i < header_size; i++)
        if (b[i]) return rs_fail(err, RS_ERR_FORMAT, "%s: padding not zero (byte %u)", what, i);

    rs_env *e = NULL;
    rs_result r = rs_env_create((int)width, (int)levels, &e, err);
    if (r != RS_OK) return r;
    memcpy(e->name, b + OFF_NAME, sizeof e->name);
    // Zero after the name's NUL, as the writer leaves it: one byte form per environment (save(load(f)) == f).
    const char *nul = memchr(e->name, 0, sizeof e->name);
    for (const char *p = nul ? nul : e->name + sizeof e->name; p < e->name + sizeof e->name; p++)
        if (*p) {
            rs_env_destroy(e);
            return rs_fail(err, RS_ERR_FORMAT, "%s: name: bytes after its NUL must be 0 (byte %d)", what,
                           OFF_NAME + (int)(p - e->name));
        }
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++) e->sh[k][c] = rs_lef32_get(b + OFF_SH + 4 * (3 * k + c));
    for (int c = 0; c < 3; c++) {
        e->light_dir[c] = rs_lef32_get(b + OFF_LIGHT_DIR + 4 * c);
        e->light_color[c] = rs_lef32_get(b + OFF_LIGHT_COLOR + 4 * c);
    }
    e->light_angle = rs_lef32_get(b + OFF_LIGHT_ANGLE);
    for (int k = 0; k < RS_ENV_MAX_LEVELS; k++) {
        e->level_m[k] = rs_lef32_get(b + OFF_LEVEL_M + 4 * k);
        if (k >= (int)levels && rs_le32_get(b + OFF_LEVEL_M + 4 * k) != 0) {
            rs_env_destroy(e);
            return rs_fail(err, RS_ERR_FORMAT, "%s: unused level slot %d not zero (byte %d)", what, k, OFF_LEVEL_M + 4 * k);
        }
    }
    memcpy(e->notes, b + OFF_NOTES, notes_len);
    r = check_fields(e, what, err);
    if (r != RS_OK) {
        rs_env_destroy(e);
        return r;
    }
    const uint8_t *p = b + header_size;
    for (int k = 0; k < (int)levels; k++) {
        size_t n = (size_t)e->levels[k].width * (size_t)e->levels[k].height;
        for (size_t i = 0; i < n; i++, p += 4) e->levels[k].rgb9e5[i] = rs_le32_get(p);
    }
    *out = e;
    return RS_OK;
}

rs_result rs_env_load(const char *path, rs_env **out, rs_error *err)
{
    *out = NULL;
    void *data = NULL;
    size_t len = 0;
    size_t max = (size_t)OFF_NOTES + RS_ENV_MAX_NOTES + 8 + texel_total(RS_ENV_MAX_WIDTH, RS_ENV_MAX_LEVELS) * 4;
    rs_result r = rs_file_read_all(path, max, &data, &len, err);
    if (r != RS_OK) return r;
    r = rs_env_load_memory(data, len, out, err);
    free(data);
    if (r != RS_OK) {
        // Name the file in front of the loader's message.
        char msg[sizeof err->msg];
        snprintf(msg, sizeof msg, "%s", err->msg);
        rs_fail(err, r, "%.300s: %s", path, msg);
    }
    return r;
}

// --- save ------------------------------------------------------------------------------------------------

rs_result rs_env_save_memory(const rs_env *e, void **out_data, size_t *out_len, rs_error *err)
{
    *out_data = NULL;
    *out_len = 0;
    rs_result r = check_fields(e, "environment", err);
    if (r != RS_OK) return r;
    int width = e->levels[0].width;
    if (!valid_size(width, e->level_count) || e->levels[0].height * 2 != width)
        return rs_fail(err, RS_ERR_ARG, "environment: level sizes do not form a 2:1 map that halves evenly");
    for (int k = 0; k < e->level_count; k++)
        if (!e->levels[k].rgb9e5 || e->levels[k].width != width >> k || e->levels[k].height != (width / 2) >> k)
            return rs_fail(err, RS_ERR_ARG, "environment: level %d is not half of level %d", k, k - 1);
    size_t notes_len = strnlen(e->notes, sizeof e->notes);
    if (notes_len >= sizeof e->notes) return rs_fail(err, RS_ERR_ARG, "environment: notes not NUL-terminated");
    size_t header = (OFF_NOTES + notes_len + 3u) & ~(size_t)3u;
    size_t len = header + texel_total(width, e->level_count) * 4 + 4;
    uint8_t *b = calloc(1, len);
    if (!b) return rs_fail(err, RS_ERR_NOMEM, "environment: out of memory");
    memcpy(b, RSE_MAGIC, 4);
    rs_le32_put(b + OFF_VERSION, RSE_VERSION);
    rs_le32_put(b + OFF_HEADER_SIZE, (uint32_t)header);
    memcpy(b + OFF_NAME, e->name, strnlen(e->name, sizeof e->name));
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++) rs_lef32_put(b + OFF_SH + 4 * (3 * k + c), e->sh[k][c]);
    for (int c = 0; c < 3; c++) {
        rs_lef32_put(b + OFF_LIGHT_DIR + 4 * c, e->light_dir[c]);
        rs_lef32_put(b + OFF_LIGHT_COLOR + 4 * c, e->light_color[c]);
    }
    rs_lef32_put(b + OFF_LIGHT_ANGLE, e->light_angle);
    rs_le32_put(b + OFF_LEVEL_COUNT, (uint32_t)e->level_count);
    for (int k = 0; k < e->level_count; k++) rs_lef32_put(b + OFF_LEVEL_M + 4 * k, e->level_m[k]);
    rs_le32_put(b + OFF_WIDTH, (uint32_t)width);
    rs_le32_put(b + OFF_HEIGHT, (uint32_t)(width / 2));
    rs_le32_put(b + OFF_NOTES_LEN, (uint32_t)notes_len);
    memcpy(b + OFF_NOTES, e->notes, notes_len);
    uint8_t *p = b + header;
    for (int k = 0; k < e->level_count; k++) {
        size_t n = (size_t)e->levels[k].width * (size_t)e->levels[k].height;
        for (size_t i = 0; i < n; i++, p += 4) rs_le32_put(p, e->levels[k].rgb9e5[i]);
    }
    rs_le32_put(b + len - 4, rs_crc32(0, b, len - 4));
    *out_data = b;
    *out_len = len;
    return RS_OK;
}

rs_result rs_env_save(const rs_env *e, const char *path, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_env_save_memory(e, &data, &len, err);
    if (r == RS_OK) r = rs_file_write_atomic(path, data, len, err);
    free(data);
    return r;
}
