// rouge-env — turns an HDR latitude-longitude capture (OpenEXR or Radiance .hdr) into a rouge lighting
// environment (.rse, docs/env.md): the dominant light, SH irradiance of the rest, and the rest's radiance
// prefiltered for a ladder of Beckmann roughnesses. Tools-time only: the renderer reads the .rse and never
// needs OpenEXR.
//
//   rouge-env studio.exr -o assets/env/studio.rse --name studio [--key-yaw -35] [--notes TEXT]
//
// Steps (each a function below): read -> find the brightest compact region -> take it out as a light
// (its excess over the surrounding level, so nothing is counted twice) -> turn the map about up so the
// light sits at --key-yaw -> SH9 of the remainder's irradiance -> prefilter the remainder.
#define _POSIX_C_SOURCE 200809L
#include "core/core.h"
#include "core/image.h"
#include "formats/env.h"

#include "env/exr_read.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_HDR
#define STBI_NO_STDIO
#define STBI_FAILURE_USERMSG
#include <stb/stb_image.h>

#define PI_F 3.14159265358979f
#define MAX_SIDE 16384              // input width at most (height = width / 2)
#define MAX_FILE_BYTES (1u << 30)
#define OUT_WIDTH 256               // level 0 of the prefiltered chain
#define LEVELS 6
static const float level_m[LEVELS] = {0.06f, 0.12f, 0.22f, 0.38f, 0.6f, 1.0f};

typedef struct map {
    int w, h;
    float *rgb;  // w * h * 3, rows top (up) first
} map;

static void map_free(map *m) { free(m->rgb), m->rgb = NULL; }

static rs_result map_alloc(map *m, int w, int h, rs_error *err)
{
    m->w = w, m->h = h;
    m->rgb = rs_alloc_array((size_t)w * (size_t)h * 3, sizeof(float));
    return m->rgb ? RS_OK : rs_fail(err, RS_ERR_NOMEM, "out of memory (%dx%d map)", w, h);
}

static float lum(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

// Texel centre direction and solid angle of row j (equirect: dw = (2 pi / w)(pi / h) sin theta).
static void texel_dir(const map *m, int i, int j, float d[3])
{
    float uv[2] = {((float)i + 0.5f) / (float)m->w, ((float)j + 0.5f) / (float)m->h};
    rs_env_uv_to_dir(uv, d);
}
static float texel_sr(const map *m, int j)
{
    return (2.0f * PI_F / (float)m->w) * (PI_F / (float)m->h) * sinf(PI_F * ((float)j + 0.5f) / (float)m->h);
}

// --- reading ----------------------------------------------------------------------------------------------

static rs_result check_size(const char *path, long long w, long long h, rs_error *err)
{
    if (w <= 0 || h <= 0 || w > MAX_SIDE || h > MAX_SIDE / 2)
        return rs_fail(err, RS_ERR_LIMIT, "%s: %lldx%lld: an environment is at most %dx%d", path, w, h, MAX_SIDE,
                       MAX_SIDE / 2);
    if (w != 2 * h || w < 16)
        return rs_fail(err, RS_ERR_FORMAT, "%s: %lldx%lld is not a latitude-longitude map (width = 2 x height, >= 16)",
                       path, w, h);
    return RS_OK;
}

static rs_result read_hdr(const char *path, const void *data, size_t len, map *out, rs_error *err)
{
    int w = 0, h = 0, comp = 0;
    if (len > (size_t)INT32_MAX) return rs_fail(err, RS_ERR_LIMIT, "%s: too large", path);
    // Size first: a header may claim any size, and stb would allocate it.
    if (!stbi_info_from_memory(data, (int)len, &w, &h, &comp))
        return rs_fail(err, RS_ERR_FORMAT, "%s: not a readable Radiance .hdr (%s)", path, stbi_failure_reason());
    rs_result r = check_size(path, w, h, err);
    if (r != RS_OK) return r;
    float *px = stbi_loadf_from_memory(data, (int)len, &w, &h, &comp, 3);
    if (!px) return rs_fail(err, RS_ERR_FORMAT, "%s: cannot decode (%s)", path, stbi_failure_reason());
    out->w = w, out->h = h, out->rgb = px;
    return RS_OK;
}

// OpenEXR through the C++ library (exr_read.cpp: the 3.1 C core cannot decode DWA, which Blender's HDRIs
// use).
static rs_result read_exr(const char *path, map *out, rs_error *err)
{
    char msg[256] = "";
    int w = 0, h = 0;
    float *rgb = NULL;
    int rc = rs_exr_read(path, MAX_SIDE, &w, &h, &rgb, msg, sizeof msg);
    if (rc == 2) return check_size(path, w, h, err);
    if (rc != 0) return rs_fail(err, RS_ERR_FORMAT, "%s: OpenEXR: %.200s", path, msg);
    rs_result r = check_size(path, w, h, err);
    if (r != RS_OK) {
        free(rgb);
        return r;
    }
    out->w = w, out->h = h, out->rgb = rgb;
    return RS_OK;
}

static rs_result read_map(const char *path, map *out, rs_error *err)
{
    void *data = NULL;
    size_t len = 0;
    rs_result r = rs_file_read_all(path, MAX_FILE_BYTES, &data, &len, err);
    if (r != RS_OK) return r;
    static const uint8_t exr_magic[4] = {0x76, 0x2f, 0x31, 0x01};
    if (len >= 4 && memcmp(data, exr_magic, 4) == 0) r = read_exr(path, out, err);
    else if (len >= 2 && memcmp(data, "#?", 2) == 0) r = read_hdr(path, data, len, out, err);
    else r = rs_fail(err, RS_ERR_FORMAT, "%s: neither OpenEXR nor Radiance .hdr", path);
    free(data);
    if (r != RS_OK) return r;
    // Negative, NaN or infinite radiance is a broken capture; keep what is usable.
    size_t n = (size_t)out->w * (size_t)out->h * 3;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(out->rgb[i]) || out->rgb[i] < 0.0f) out->rgb[i] = 0.0f;
        else if (out->rgb[i] > 65000.0f) out->rgb[i] = 65000.0f;
    return RS_OK;
}

// --- resampling -------------------------------------------------------------------------------------------

// Box-filtered copy at w x h (w <= src.w): each source texel adds into the target texel it falls in,
// weighted by its solid angle.
static rs_result downsample(const map *src, int w, int h, map *out, rs_error *err)
{
    rs_result r = map_alloc(out, w, h, err);
    if (r != RS_OK) return r;
    float *wsum = calloc((size_t)w * (size_t)h, sizeof(float));
    if (!wsum) return map_free(out), rs_fail(err, RS_ERR_NOMEM, "out of memory");
    memset(out->rgb, 0, (size_t)w * (size_t)h * 3 * sizeof(float));
    for (int j = 0; j < src->h; j++) {
        int tj = (int)((long long)j * h / src->h);
        float sr = texel_sr(src, j);
        for (int i = 0; i < src->w; i++) {
            int ti = (int)((long long)i * w / src->w);
            size_t t = (size_t)tj * (size_t)w + (size_t)ti;
            const float *s = src->rgb + ((size_t)j * (size_t)src->w + (size_t)i) * 3;
            for (int c = 0; c < 3; c++) out->rgb[t * 3 + c] += s[c] * sr;
            wsum[t] += sr;
        }
    }
    for (size_t t = 0; t < (size_t)w * (size_t)h; t++)
        for (int c = 0; c < 3; c++) out->rgb[t * 3 + c] /= RS_MAX(wsum[t], 1e-20f);
    free(wsum);
    return RS_OK;
}

// Turns the map about up by `dphi` radians (a light at phi moves to phi + dphi): a column shift with
// linear interpolation, wrapping.
static void rotate_map(map *m, float dphi)
{
    float shift = dphi / (2.0f * PI_F) * (float)m->w;
    float *row = malloc((size_t)m->w * 3 * sizeof(float));
    if (!row) return;
    for (int j = 0; j < m->h; j++) {
        float *r = m->rgb + (size_t)j * (size_t)m->w * 3;
        memcpy(row, r, (size_t)m->w * 3 * sizeof(float));
        for (int i = 0; i < m->w; i++) {
            float x = (float)i - shift;
            float fl = floorf(x), t = x - fl;
            int a = (((int)fl % m->w) + m->w) % m->w, b = (a + 1) % m->w;
            for (int c = 0; c < 3; c++) r[i * 3 + c] = row[a * 3 + c] * (1 - t) + row[b * 3 + c] * t;
        }
    }
    free(row);
}

// --- the dominant light -----------------------------------------------------------------------------------

typedef struct light {
    float dir[3], color[3], angle;
    float solid_angle;
} light;

// The brightest compact region: the peak of a 64x32 copy (about 6 degrees a texel), then every texel of
// the full map within 30 degrees of it brighter than a quarter of the peak's mean and than 1/20 of the
// brightest texel there. Its excess over the
// level around it (a 10-degree ring outside the region) becomes the light; the texels keep that level.
static rs_result extract_light(map *m, light *out, rs_error *err)
{
    map small = {0};
    rs_result r = downsample(m, 64, 32, &small, err);
    if (r != RS_OK) return r;
    int best = 0;
    for (int t = 1; t < 64 * 32; t++)
        if (lum(small.rgb + t * 3) > lum(small.rgb + best * 3)) best = t;
    float peak[3];
    texel_dir(&small, best % 64, best / 64, peak);
    float peak_lum = lum(small.rgb + best * 3);
    map_free(&small);

    const float cos_reach = cosf(30.0f * PI_F / 180.0f);
    size_t n = (size_t)m->w * (size_t)m->h;
    // A sun is far brighter than the sky it sits in, which the coarse copy averages it with: the
    // threshold also follows the full-resolution peak near the coarse one, so the light is the sun's
    // disc and not the bright sky around it; a softbox (about uniform) keeps all of its area.
    float fine_peak = 0.0f;
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            float d[3];
            texel_dir(m, i, j, d);
            if (d[0] * peak[0] + d[1] * peak[1] + d[2] * peak[2] >= cos_reach)
                fine_peak = RS_MAX(fine_peak, lum(m->rgb + ((size_t)j * (size_t)m->w + (size_t)i) * 3));
        }
    float threshold = RS_MAX(0.25f * peak_lum, 0.05f * fine_peak);
    uint8_t *in = calloc(n, 1);
    if (!in) return rs_fail(err, RS_ERR_NOMEM, "out of memory");
    float max_angle = 0.0f;
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            float d[3];
            texel_dir(m, i, j, d);
            float c = d[0] * peak[0] + d[1] * peak[1] + d[2] * peak[2];
            size_t t = (size_t)j * (size_t)m->w + (size_t)i;
            if (c >= cos_reach && lum(m->rgb + t * 3) > threshold) {
                in[t] = 1;
                max_angle = RS_MAX(max_angle, acosf(RS_MIN(c, 1.0f)));
            }
        }
    // The surrounding level: the mean of a ring 10 degrees wide outside the region.
    float ring_lo = cosf(RS_MIN(max_angle + 10.0f * PI_F / 180.0f, PI_F)), ring[3] = {0, 0, 0}, ring_w = 0;
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            size_t t = (size_t)j * (size_t)m->w + (size_t)i;
            float d[3];
            texel_dir(m, i, j, d);
            float c = d[0] * peak[0] + d[1] * peak[1] + d[2] * peak[2];
            if (in[t] || c < ring_lo) continue;
            float sr = texel_sr(m, j);
            for (int k = 0; k < 3; k++) ring[k] += m->rgb[t * 3 + k] * sr;
            ring_w += sr;
        }
    for (int k = 0; k < 3; k++) ring[k] = ring_w > 0 ? ring[k] / ring_w : 0.0f;
    light L = {{0, 0, 0}, {0, 0, 0}, 0, 0};
    double dir[3] = {0, 0, 0};
    for (int j = 0; j < m->h; j++)
        for (int i = 0; i < m->w; i++) {
            size_t t = (size_t)j * (size_t)m->w + (size_t)i;
            if (!in[t]) continue;
            float d[3], sr = texel_sr(m, j), ex[3];
            texel_dir(m, i, j, d);
            for (int k = 0; k < 3; k++) {
                ex[k] = RS_MAX(m->rgb[t * 3 + k] - ring[k], 0.0f);
                L.color[k] += ex[k] * sr / PI_F;
                m->rgb[t * 3 + k] -= ex[k];
            }
            float e = lum(ex) * sr;
            for (int k = 0; k < 3; k++) dir[k] += d[k] * e;
            L.solid_angle += sr;
        }
    free(in);
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    if (len <= 0.0) {
        for (int k = 0; k < 3; k++) L.dir[k] = peak[k];
    } else {
        for (int k = 0; k < 3; k++) L.dir[k] = (float)(dir[k] / len);
    }
    // The equivalent disc's angular radius (the region's solid angle as a cap).
    L.angle = acosf(RS_CLAMP(1.0f - L.solid_angle / (2.0f * PI_F), -1.0f, 1.0f));
    *out = L;
    return RS_OK;
}

// --- SH and prefiltering ----------------------------------------------------------------------------------

// Irradiance / pi of the map as SH9: E_lm = A_l L_lm (Ramamoorthi & Hanrahan), A = pi, 2pi/3, pi/4.
static void project_sh(const map *m, float sh[9][3])
{
    double acc[9][3] = {{0}};
    for (int j = 0; j < m->h; j++) {
        float sr = texel_sr(m, j);
        for (int i = 0; i < m->w; i++) {
            float d[3], y[9];
            texel_dir(m, i, j, d);
            rs_env_sh_basis(d, y);
            const float *c = m->rgb + ((size_t)j * (size_t)m->w + (size_t)i) * 3;
            for (int k = 0; k < 9; k++)
                for (int ch = 0; ch < 3; ch++) acc[k][ch] += (double)c[ch] * y[k] * sr;
        }
    }
    static const float a[9] = {1.0f, 2.0f / 3, 2.0f / 3, 2.0f / 3, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};  // A_l / pi
    for (int k = 0; k < 9; k++)
        for (int ch = 0; ch < 3; ch++) sh[k][ch] = (float)(acc[k][ch] * a[k]);
}

static float beckmann(float ndoth, float m)
{
    float c2 = ndoth * ndoth, m2 = m * m;
    return expf((c2 - 1.0f) / (c2 * m2)) / (m2 * c2 * c2);
}

// Level k: for each output direction R, the source radiance weighted by the Beckmann lobe of roughness m
// around R with N = V = R: w = P_H(N.h) max(R.l, 0) dw, h = normalize(l + R). The sum is windowed to
// where the lobe is above ~1e-5 of its peak.
static rs_result prefilter(const map *src_full, rs_env_level *lvl, float m, rs_error *err)
{
    int sw = RS_MIN(src_full->w, RS_MAX(64, 2 * lvl->width));
    map src = {0};
    rs_result r = downsample(src_full, sw, sw / 2, &src, err);
    if (r != RS_OK) return r;
    float *dirs = malloc((size_t)src.w * (size_t)src.h * 3 * sizeof(float));
    if (!dirs) return map_free(&src), rs_fail(err, RS_ERR_NOMEM, "out of memory");
    for (int j = 0; j < src.h; j++)
        for (int i = 0; i < src.w; i++) texel_dir(&src, i, j, dirs + ((size_t)j * (size_t)src.w + (size_t)i) * 3);
    // Half-vector angle where exp(-tan^2/m^2) falls below 1e-5: tan = m sqrt(ln 1e5); l turns twice as far.
    float reach = RS_MIN(2.0f * atanf(m * 3.4f) + 2.0f * PI_F / (float)src.w, PI_F);
    for (int oj = 0; oj < lvl->height; oj++)
        for (int oi = 0; oi < lvl->width; oi++) {
            float uv[2] = {((float)oi + 0.5f) / (float)lvl->width, ((float)oj + 0.5f) / (float)lvl->height}, R[3];
            rs_env_uv_to_dir(uv, R);
            float theta0 = PI_F * uv[1];
            int j0 = RS_MAX(0, (int)floorf((theta0 - reach) / PI_F * (float)src.h));
            int j1 = RS_MIN(src.h - 1, (int)ceilf((theta0 + reach) / PI_F * (float)src.h));
            double acc[3] = {0, 0, 0}, wsum = 0;
            for (int j = j0; j <= j1; j++) {
                float sr = texel_sr(&src, j);
                float st = sinf(PI_F * ((float)j + 0.5f) / (float)src.h);
                int half = src.w / 2;
                if (st > 1e-3f && reach < PI_F * 0.5f) half = RS_MIN(half, (int)ceilf(reach / st / (2.0f * PI_F) * (float)src.w) + 1);
                int ic = (int)floorf(uv[0] * (float)src.w);
                for (int di = -half; di < half + (half == src.w / 2 ? 0 : 1); di++) {
                    int i = ((ic + di) % src.w + src.w) % src.w;
                    const float *l = dirs + ((size_t)j * (size_t)src.w + (size_t)i) * 3;
                    float rl = R[0] * l[0] + R[1] * l[1] + R[2] * l[2];
                    if (rl <= 0.0f) continue;
                    float h[3] = {l[0] + R[0], l[1] + R[1], l[2] + R[2]};
                    float hl = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
                    float ndoth = (R[0] * h[0] + R[1] * h[1] + R[2] * h[2]) / hl;
                    float w = beckmann(ndoth, m) * rl * sr;
                    if (!(w > 0.0f)) continue;
                    const float *c = src.rgb + ((size_t)j * (size_t)src.w + (size_t)i) * 3;
                    for (int k = 0; k < 3; k++) acc[k] += c[k] * w;
                    wsum += w;
                }
            }
            float out[3];
            for (int k = 0; k < 3; k++) out[k] = wsum > 0 ? (float)(acc[k] / wsum) : 0.0f;
            lvl->rgb9e5[(size_t)oj * (size_t)lvl->width + (size_t)oi] = rs_rgb9e5_pack(out);
        }
    free(dirs);
    map_free(&src);
    return RS_OK;
}

// --- preview ----------------------------------------------------------------------------------------------

// Level 0 (with the light added back as a disc) tone mapped, for a person to check the light was found.
static rs_result write_preview(const rs_env *e, const char *path, rs_error *err)
{
    const rs_env_level *l = &e->levels[0];
    rs_image img = {0};
    rs_result r = rs_image_create(l->width, l->height, 4, &img, err);
    if (r != RS_OK) return r;
    float cos_light = cosf(RS_MAX(e->light_angle, 0.02f));
    float omega = 2.0f * PI_F * (1.0f - cos_light);
    for (int j = 0; j < l->height; j++)
        for (int i = 0; i < l->width; i++) {
            float c[3], d[3], uv[2] = {((float)i + 0.5f) / (float)l->width, ((float)j + 0.5f) / (float)l->height};
            rs_rgb9e5_unpack(l->rgb9e5[(size_t)j * (size_t)l->width + (size_t)i], c);
            rs_env_uv_to_dir(uv, d);
            if (d[0] * e->light_dir[0] + d[1] * e->light_dir[1] + d[2] * e->light_dir[2] >= cos_light)
                for (int k = 0; k < 3; k++) c[k] += e->light_color[k] * PI_F / omega;
            uint8_t *p = img.pixels + ((size_t)j * (size_t)l->width + (size_t)i) * 4;
            for (int k = 0; k < 3; k++) p[k] = (uint8_t)lrintf(rs_linear_to_srgb(c[k] / (1.0f + c[k])) * 255.0f);
            p[3] = 255;
        }
    r = rs_image_write_png(path, &img, err);
    rs_image_free(&img);
    return r;
}

// --- main -------------------------------------------------------------------------------------------------

static int usage(const char *msg)
{
    if (msg) {
        fprintf(stderr, "rouge-env: %s (see --help)\n", msg);
        return 2;
    }
    fprintf(stdout,
            "usage: rouge-env IN.exr|IN.hdr -o OUT.rse --name NAME [--key-yaw DEG] [--notes TEXT] [--preview PNG]\n"
            "  Turns a latitude-longitude HDR capture (width = 2 x height, OpenEXR scanline R,G,B or Radiance\n"
            "  .hdr) into a rouge lighting environment: the brightest compact region becomes the key light\n"
            "  (turned to --key-yaw, default -35: front-left, like the paper's lamp), the rest SH irradiance\n"
            "  and radiance prefiltered for roughness %.2f..%.2f. NAME: a-z 0-9 _ -. --preview writes the\n"
            "  map with the light as a PNG to check it.\n",
            level_m[0], level_m[LEVELS - 1]);
    return 0;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *name = NULL, *notes = "", *preview = NULL;
    float key_yaw = -35.0f;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) return usage(NULL);
        bool has = i + 1 < argc;
        if (!strcmp(a, "-o") || !strcmp(a, "--name") || !strcmp(a, "--key-yaw") || !strcmp(a, "--notes") ||
            !strcmp(a, "--preview")) {
            if (!has) return usage("an option needs a value");
            const char *v = argv[++i];
            if (!strcmp(a, "-o")) out = v;
            else if (!strcmp(a, "--name")) name = v;
            else if (!strcmp(a, "--notes")) notes = v;
            else if (!strcmp(a, "--preview")) preview = v;
            else {
                char *end;
                errno = 0;
                key_yaw = strtof(v, &end);
                if (end == v || *end || errno || !isfinite(key_yaw) || fabsf(key_yaw) > 360.0f)
                    return usage("--key-yaw: a number of degrees in -360..360");
            }
        } else if (a[0] == '-') {
            fprintf(stderr, "rouge-env: unknown option '%s' (see --help)\n", a);
            return 2;
        } else if (!in) {
            in = a;
        } else {
            return usage("one input file only");
        }
    }
    if (!in || !out || !name) return usage("needs IN, -o OUT.rse and --name NAME");
    rs_error err = {0};
    map m = {0};
    rs_env *e = NULL;
    light L;
    rs_result r = read_map(in, &m, &err);
    if (r == RS_OK) r = extract_light(&m, &L, &err);
    if (r == RS_OK) {
        // Turn the world so the light sits at the key yaw.
        float phi = atan2f(L.dir[0], L.dir[2]), dphi = key_yaw * PI_F / 180.0f - phi;
        rotate_map(&m, dphi);
        float c = cosf(dphi), s = sinf(dphi), x = L.dir[0], z = L.dir[2];
        L.dir[0] = s * z + c * x, L.dir[2] = c * z - s * x;
        r = rs_env_create(OUT_WIDTH, LEVELS, &e, &err);
    }
    if (r == RS_OK) {
        snprintf(e->name, sizeof e->name, "%s", name);
        memcpy(e->light_dir, L.dir, sizeof L.dir);
        memcpy(e->light_color, L.color, sizeof L.color);
        e->light_angle = L.angle;
        project_sh(&m, e->sh);
        for (int k = 0; k < LEVELS && r == RS_OK; k++) {
            e->level_m[k] = level_m[k];
            r = prefilter(&m, &e->levels[k], level_m[k], &err);
        }
        const char *base = strrchr(in, '/');
        snprintf(e->notes, sizeof e->notes, "%s%srouge-env: from %s, dominant light turned to yaw %g deg", notes,
                 notes[0] ? "\n" : "", base ? base + 1 : in, (double)key_yaw);
    }
    if (r == RS_OK) r = rs_env_save(e, out, &err);
    if (r == RS_OK && preview) r = write_preview(e, preview, &err);
    if (r == RS_OK) {
        float pitch = asinf(RS_CLAMP(L.dir[1], -1.0f, 1.0f)) * 180.0f / PI_F;
        printf("rouge-env: %s: light at yaw %.1f pitch %.1f deg, radius %.1f deg, colour %.3g %.3g %.3g; "
               "SH ambient %.3g %.3g %.3g\n",
               out, (double)key_yaw, (double)pitch, (double)(L.angle * 180.0f / PI_F), (double)L.color[0],
               (double)L.color[1], (double)L.color[2], (double)(e->sh[0][0] * 0.282095f),
               (double)(e->sh[0][1] * 0.282095f), (double)(e->sh[0][2] * 0.282095f));
    }
    rs_env_destroy(e);
    map_free(&m);
    if (r != RS_OK) {
        fprintf(stderr, "rouge-env: %s\n", err.msg);
        return 1;
    }
    return 0;
}
