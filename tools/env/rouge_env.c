// rouge-env — turns an HDR latitude-longitude capture (OpenEXR or Radiance .hdr) into a rouge lighting
// environment (.rse, docs/env.md): the dominant light, SH irradiance of the rest, and the rest's radiance
// prefiltered for a ladder of Beckmann roughnesses. Tools-time only: the renderer reads the .rse and never
// needs OpenEXR.
//
//   rouge-env studio.exr -o assets/env/studio.rse --name studio [--key-yaw -35] [--notes TEXT] [--preview PNG]
//
// Reading: env_read.c (+ exr_read.cpp); the work: env_bake.c; here: options, notes, the preview.
#define _POSIX_C_SOURCE 200809L
#include "core/core.h"
#include "core/image.h"
#include "formats/env.h"

#include "env/env_bake.h"
#include "env/env_read.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_F 3.14159265358979f
#define ROUGE_ENV_VERSION "2"  // bumped when the bake's results change (notes record it)

// ---- preview ----

// Bilinear radiance of level k towards d (u wraps, v clamps), as the GPU samples it.
static void sample_level(const rs_env_level *l, const float d[3], float out[3])
{
    float uv[2];
    rs_env_dir_to_uv(d, uv);
    float fx = uv[0] * (float)l->width - 0.5f, fy = uv[1] * (float)l->height - 0.5f;
    int x0 = (int)floorf(fx), y0 = (int)floorf(fy);
    float tx = fx - (float)x0, ty = fy - (float)y0;
    out[0] = out[1] = out[2] = 0;
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            int x = ((x0 + i) % l->width + l->width) % l->width, y = RS_CLAMP(y0 + j, 0, l->height - 1);
            float c[3], wgt = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
            rs_rgb9e5_unpack(l->rgb9e5[(size_t)y * (size_t)l->width + (size_t)x], c);
            for (int k = 0; k < 3; k++) out[k] += wgt * c[k];
        }
}

static void put(rs_image *img, int x, int y, const float c[3], float exposure)
{
    uint8_t *p = img->pixels + ((size_t)y * (size_t)img->width + (size_t)x) * 3;
    for (int k = 0; k < 3; k++) {
        float v = RS_MAX(c[k], 0.0f) * exposure;
        p[k] = (uint8_t)lrintf(rs_linear_to_srgb(v / (1.0f + v)) * 255.0f);
    }
}

// Top: the work map without its light (the region keeps the surrounding level), outlined in red, the
// light's direction marked by a cross. Bottom, spheres seen from the front: white Lambert under SH + light,
// under SH alone, and mirror-like reflections of levels 0 (m 0.06) and 3 (m 0.38) plus the light's
// highlight. One exposure for all: the brightest Lambert normal reads as 0.6.
static rs_result write_preview(const rs_env *e, const rs_envmap *work, const uint8_t *mask, const char *path,
                               rs_error *err)
{
    enum { W = 512, H = 256, S = 128 };
    rs_envmap small = {0};
    rs_image img = {0};
    rs_result r = rs_envmap_resample(work, W, &small, err);
    if (r == RS_OK) r = rs_image_create(W, H + S, 3, &img, err);
    if (r != RS_OK) {
        rs_envmap_free(&small);
        return r;
    }
    float emax = 1e-6f;
    for (int t = 0; t < 2000; t++) {
        float z = 1.0f - 2.0f * ((float)t + 0.5f) / 2000.0f, a = (float)t * 2.39996f, s = sqrtf(1 - z * z);
        float n[3] = {s * cosf(a), z, s * sinf(a)}, c[3];
        float nl = RS_MAX(0.0f, n[0] * e->light_dir[0] + n[1] * e->light_dir[1] + n[2] * e->light_dir[2]);
        rs_env_sh_irradiance(e, n, c);
        for (int k = 0; k < 3; k++) emax = RS_MAX(emax, c[k] + e->light_color[k] * nl);
    }
    float exposure = 1.5f / emax;
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            // Region border: a region texel of the work map with a neighbour outside.
            int wi = x * work->w / W, wj = y * work->h / H;
            bool border = false;
            if (mask[(size_t)wj * (size_t)work->w + (size_t)wi])
                for (int dj = -1; dj <= 1; dj++)
                    for (int di = -1; di <= 1; di++) {
                        int j = wj + dj * RS_MAX(1, work->h / H), i = (wi + di * RS_MAX(1, work->w / W) + work->w) % work->w;
                        if (j >= 0 && j < work->h && !mask[(size_t)j * (size_t)work->w + (size_t)i]) border = true;
                    }
            static const float red[3] = {1e3f, 0, 0};
            put(&img, x, y, border ? red : small.rgb + ((size_t)y * W + (size_t)x) * 3, border ? 1.0f : exposure);
        }
    float uv[2];
    rs_env_dir_to_uv(e->light_dir, uv);
    int lx = (int)(uv[0] * W), ly = (int)(uv[1] * H);
    static const float cyan[3] = {0, 1e3f, 1e3f};
    for (int k = -6; k <= 6; k++) {
        if (ly + k >= 0 && ly + k < H) put(&img, (lx + W) % W, ly + k, cyan, 1.0f);
        put(&img, (lx + k + W) % W, RS_CLAMP(ly, 0, H - 1), cyan, 1.0f);
    }
    // Spheres.
    for (int tile = 0; tile < 4; tile++)
        for (int y = 0; y < S; y++)
            for (int x = 0; x < S; x++) {
                float px = ((float)x + 0.5f) / S * 2 - 1, py = 1 - ((float)y + 0.5f) / S * 2, c[3] = {0, 0, 0};
                float rr = px * px + py * py;
                if (rr < 1) {
                    float n[3] = {px, py, sqrtf(1 - rr)};
                    float nl = RS_MAX(0.0f, n[0] * e->light_dir[0] + n[1] * e->light_dir[1] + n[2] * e->light_dir[2]);
                    if (tile < 2) {
                        rs_env_sh_irradiance(e, n, c);
                        if (tile == 0)
                            for (int k = 0; k < 3; k++) c[k] += e->light_color[k] * nl;
                    } else {
                        // Reflection of the view (0, 0, 1): R = 2 n.z n - v.
                        float R[3] = {2 * n[2] * n[0], 2 * n[2] * n[1], 2 * n[2] * n[2] - 1};
                        int level = tile == 2 ? 0 : 3;
                        float m = e->level_m[level];
                        sample_level(&e->levels[level], R, c);
                        // The light's highlight: its Beckmann lobe, widened by its size (roughness added in
                        // quadrature with half its radius), a quarter of it as KSK's 1/(h.h) at N = V.
                        float ml = sqrtf(m * m + 0.25f * e->light_angle * e->light_angle);
                        float h[3] = {e->light_dir[0], e->light_dir[1], e->light_dir[2] + 1};
                        float hl = sqrtf(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
                        float nh = (n[0] * h[0] + n[1] * h[1] + n[2] * h[2]) / RS_MAX(hl, 1e-6f);
                        if (nh > 0 && nl > 0)
                            for (int k = 0; k < 3; k++) c[k] += e->light_color[k] * rs_env_beckmann(nh, ml) * 0.25f * nl;
                    }
                }
                put(&img, tile * S + x, H + y, c, rr < 1 ? exposure : 0.0f);
            }
    r = rs_image_write_png(path, &img, err);
    rs_image_free(&img);
    rs_envmap_free(&small);
    return r;
}

// ---- main ----

static int usage(const char *msg)
{
    if (msg) {
        fprintf(stderr, "rouge-env: %s (rouge-env --help)\n", msg);
        return 2;
    }
    printf("usage: rouge-env IN.exr|IN.hdr -o OUT.rse --name NAME [--key-yaw DEG] [--light-near U,V] [--notes TEXT]\n"
           "                 [--preview PNG]\n"
           "       rouge-env --info FILE.rse\n"
           "  Turns a latitude-longitude HDR capture (width = 2 x height, %d..%d wide; OpenEXR, any compression,\n"
           "  or Radiance .hdr) into a rouge lighting environment: the most powerful compact bright region (a\n"
           "  softbox, the sun, a window) becomes the key light, turned to yaw --key-yaw (default -35: front-left\n"
           "  in a frontal view, like the paper's lamp); the rest becomes SH9 irradiance and radiance\n"
           "  prefiltered for Beckmann roughness %.2f..%.2f (%d levels from %dx%d, RGB9E5).\n"
           "  --light-near U,V: take the light near this point of the source image (fractions of its width and\n"
           "  height) instead of the brightest region, e.g. a window rather than a brighter small lamp.\n"
           "  NAME: 1..31 of a-z 0-9 _ - (what --env takes). --notes: source, author, licence (kept in the file).\n"
           "  --preview: a PNG of the map without its light (region outlined red, direction marked) and spheres\n"
           "  lit by it, to check what was found. --info: what a .rse file holds (and whether it loads).\n",
           RS_ENVMAP_MIN_WIDTH, RS_ENVMAP_MAX_WIDTH, (double)rs_env_bake_level_m[0],
           (double)rs_env_bake_level_m[RS_ENV_BAKE_LEVELS - 1], RS_ENV_BAKE_LEVELS, RS_ENV_BAKE_WIDTH,
           RS_ENV_BAKE_WIDTH / 2);
    return 0;
}

// --info: what a .rse holds, through the run-time loader (so it also checks a file).
static int info(const char *path)
{
    rs_env *e = NULL;
    rs_error err = {0};
    if (rs_env_load(path, &e, &err) != RS_OK) {
        fprintf(stderr, "rouge-env: %s\n", err.msg);
        return 1;
    }
    char notes[RS_ENV_MAX_NOTES * 4];
    rs_text_sanitize(notes, sizeof notes, e->notes, strlen(e->notes));
    float up[3] = {0, 1, 0}, amb[3];
    rs_env_sh_irradiance(e, up, amb);
    printf("name: %s\nlevels: %d, level 0 %dx%d, m =", e->name, e->level_count, e->levels[0].width,
           e->levels[0].height);
    for (int k = 0; k < e->level_count; k++) printf(" %g", (double)e->level_m[k]);
    printf("\nlight: yaw %.1f pitch %.1f deg, radius %.2f deg, colour %.4g %.4g %.4g\n"
           "SH irradiance from above: %.4g %.4g %.4g\nnotes: %s\n",
           (double)(atan2f(e->light_dir[0], e->light_dir[2]) * 180.0f / PI_F),
           (double)(asinf(RS_CLAMP(e->light_dir[1], -1.0f, 1.0f)) * 180.0f / PI_F),
           (double)(e->light_angle * 180.0f / PI_F), (double)e->light_color[0], (double)e->light_color[1],
           (double)e->light_color[2], (double)amb[0], (double)amb[1], (double)amb[2], notes);
    rs_env_destroy(e);
    return 0;
}

static bool valid_name(const char *s)
{
    size_t n = strlen(s);
    if (n == 0 || n > 31) return false;
    for (; *s; s++)
        if (!((*s >= 'a' && *s <= 'z') || (*s >= '0' && *s <= '9') || *s == '_' || *s == '-')) return false;
    return true;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *name = NULL, *notes = "", *preview = NULL;
    float key_yaw = -35.0f;
    rs_env_bake_desc desc = {0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) return usage(NULL);
        if (!strcmp(a, "--info")) {
            if (i + 1 >= argc || argc != 3) return usage("--info FILE.rse takes nothing else");
            return info(argv[i + 1]);
        }
        if (!strcmp(a, "-o") || !strcmp(a, "--name") || !strcmp(a, "--key-yaw") || !strcmp(a, "--notes") ||
            !strcmp(a, "--preview") || !strcmp(a, "--light-near")) {
            if (i + 1 >= argc) {
                fprintf(stderr, "rouge-env: %s needs a value (rouge-env --help)\n", a);
                return 2;
            }
            const char *v = argv[++i];
            if (!strcmp(a, "-o")) out = v;
            else if (!strcmp(a, "--name")) name = v;
            else if (!strcmp(a, "--notes")) notes = v;
            else if (!strcmp(a, "--preview")) preview = v;
            else if (!strcmp(a, "--light-near")) {
                double uv[2];
                if (!rs_parse_list(v, ',', 2, 0.0, 1.0, uv)) return usage("--light-near: U,V of the source image, each 0..1 (e.g. 0.55,0.4)");
                desc.light_near_uv[0] = (float)uv[0], desc.light_near_uv[1] = (float)uv[1];
                desc.light_near = true;
            } else {
                double yaw;
                if (!rs_parse_number(v, -360.0, 360.0, &yaw)) return usage("--key-yaw: a number of degrees in -360..360");
                key_yaw = (float)yaw;
            }
        } else if (a[0] == '-' && a[1]) {
            char msg[160];
            snprintf(msg, sizeof msg, "unknown option '%.100s'", a);
            return usage(msg);
        } else if (!in) {
            in = a;
        } else {
            return usage("one input file only");
        }
    }
    if (!in || !out || !name) return usage("needs IN, -o OUT.rse and --name NAME");
    if (!valid_name(name)) return usage("--name: 1..31 characters of a-z 0-9 _ -");
    if (strlen(notes) > RS_ENV_MAX_NOTES / 2) return usage("--notes: at most 2048 bytes");

    desc.name = name;
    desc.key_yaw_deg = key_yaw;
    rs_error err = {0};
    rs_envmap src = {0}, work = {0};
    uint8_t *mask = NULL;
    rs_env *e = NULL;
    rs_env_light L;
    rs_result r = rs_envmap_read(in, &src, &err);
    if (r == RS_OK) r = rs_env_bake(&src, &desc, &e, &L, &work, &mask, &err);
    if (r == RS_OK) {
        const char *base = strrchr(in, '/');
        float pitch = asinf(RS_CLAMP(L.dir[1], -1.0f, 1.0f)) * 180.0f / PI_F;
        snprintf(e->notes, sizeof e->notes,
                 "%s%srouge-env %s: from %s (%dx%d), mirrored into the face frame (u grows towards the subject's "
                 "left); dominant light turned to yaw %.1f deg, pitch %.1f deg, radius %.2f deg (%d texels of %dx%d "
                 "above luminance %.3g, clamped to %.3g); levels m = 0.06 0.12 0.22 0.38 0.6 1.0",
                 notes, notes[0] ? "\n" : "", ROUGE_ENV_VERSION, base ? base + 1 : in, src.w, src.h,
                 (double)(atan2f(L.dir[0], L.dir[2]) * 180.0f / PI_F), (double)pitch,
                 (double)(L.angle * 180.0f / PI_F), L.texels, work.w, work.h, (double)L.threshold,
                 (double)(0.2126f * L.surround[0] + 0.7152f * L.surround[1] + 0.0722f * L.surround[2]));
        r = rs_env_save(e, out, &err);
    }
    if (r == RS_OK && preview) r = write_preview(e, &work, mask, preview, &err);
    if (r == RS_OK) {
        float amb[3], up[3] = {0, 1, 0};
        rs_env_sh_irradiance(e, up, amb);
        printf("rouge-env: %s: light at yaw %.1f pitch %.1f deg, radius %.2f deg, colour %.3g %.3g %.3g; "
               "SH irradiance from above %.3g %.3g %.3g\n",
               out, (double)(atan2f(L.dir[0], L.dir[2]) * 180.0f / PI_F),
               (double)(asinf(RS_CLAMP(L.dir[1], -1.0f, 1.0f)) * 180.0f / PI_F), (double)(L.angle * 180.0f / PI_F),
               (double)L.color[0], (double)L.color[1], (double)L.color[2], (double)amb[0], (double)amb[1],
               (double)amb[2]);
    }
    rs_env_destroy(e);
    rs_envmap_free(&src);
    rs_envmap_free(&work);
    free(mask);
    if (r != RS_OK) {
        fprintf(stderr, "rouge-env: %s\n", err.msg);
        return 1;
    }
    return 0;
}
