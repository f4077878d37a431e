// render_env.c — the lighting environment on the GPU: its prefiltered radiance (one RGB9E5 texture whose
// mip levels are the roughness levels), its SH irradiance and dominant light (uniforms), the exposure
// normalisation that makes every environment light the face about as brightly, and the lookup table of
// the specular lobe's directional albedo that turns prefiltered radiance into reflected light (split sum).
#include "render/render_stages.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846
#define LUT_SIZE 32
#define LUT_SAMPLES 512
// Linear RGB -> luminance (Rec. 709).
#define LUM(c) (0.2126f * (c)[0] + 0.7152f * (c)[1] + 0.0722f * (c)[2])
// What the normalisation aims at: the mean irradiance of the face's surface as a camera in front sees it
// (facing_irradiance). 0.53 keeps the bundled environments' mean brightness what it was when they were
// normalised over the front half-space of normals uniformly (0.5 then), which left a surface facing the
// camera lit from 0.48 (office) to 0.71 (studio); now the face's picture gets the same light in each.
#define ENV_TARGET_FRONT 0.53f

// Smith's Lambda for Beckmann roughness m at cos(theta) = c (skin_brdf.glsl's rs_beckmann_lambda).
static float beckmann_lambda(float c, float m)
{
    float a = c / (m * sqrtf(RS_MAX(1.0f - c * c, 1e-8f)));  // 1 / (m tan(theta))
    if (a >= 1.6f) return 0.0f;
    return (1.0f - 1.259f * a + 0.396f * a * a) / (3.535f * a + 2.181f * a * a);
}

// Directional albedo of the lobe S = P_H F G / (4 N.V) (rho_s 1; skin_brdf.glsl: the microfacet lobe with
// Smith's height-correlated masking-shadowing for Beckmann) over the hemisphere, divided by pi as every
// light in the renderer is (a white Lambertian surface under irradiance E reflects E): F0 A + B.
// Importance-sampled with Beckmann half vectors: with pdf(L) = P_H (N.H) / (4 pi V.H), each sample weighs
// F G (V.H) / ((N.V) (N.H)). Hammersley points: the table is the same on every machine.
static void lobe_albedo(float ndotv, float m, float *a, float *b)
{
    float V[3] = {sqrtf(RS_MAX(1.0f - ndotv * ndotv, 0.0f)), 0.0f, ndotv};
    double sa = 0.0, sb = 0.0;
    for (uint32_t i = 0; i < LUT_SAMPLES; i++) {
        float u1 = ((float)i + 0.5f) / LUT_SAMPLES;
        uint32_t bits = i;
        bits = (bits << 16) | (bits >> 16);
        bits = ((bits & 0x55555555u) << 1) | ((bits & 0xAAAAAAAAu) >> 1);
        bits = ((bits & 0x33333333u) << 2) | ((bits & 0xCCCCCCCCu) >> 2);
        bits = ((bits & 0x0F0F0F0Fu) << 4) | ((bits & 0xF0F0F0F0u) >> 4);
        bits = ((bits & 0x00FF00FFu) << 8) | ((bits & 0xFF00FF00u) >> 8);
        float u2 = (float)bits * 2.3283064365386963e-10f;
        // Beckmann: tan^2(theta_h) = -m^2 ln(1 - u).
        float t2 = -m * m * logf(1.0f - u1);
        float ch = 1.0f / sqrtf(1.0f + t2), sh = sqrtf(RS_MAX(1.0f - ch * ch, 0.0f));
        float phi = 6.2831853f * u2;
        float H[3] = {sh * cosf(phi), sh * sinf(phi), ch};
        float vh = V[0] * H[0] + V[1] * H[1] + V[2] * H[2];
        if (vh <= 0.0f) continue;
        float L[3] = {2.0f * vh * H[0] - V[0], 2.0f * vh * H[1] - V[1], 2.0f * vh * H[2] - V[2]};
        float nl = L[2];
        if (nl <= 0.0f) continue;
        float g = 1.0f / (1.0f + beckmann_lambda(ndotv, m) + beckmann_lambda(nl, m));
        float w = g * vh / (ndotv * ch);
        float e = powf(1.0f - vh, 5.0f);
        sa += w * (1.0f - e);
        sb += w * e;
    }
    *a = (float)(sa / LUT_SAMPLES);
    *b = (float)(sb / LUT_SAMPLES);
}

static rs_result make_lut(rs_renderer *r, rs_error *err)
{
    if (r->lut_tex) return RS_OK;
    float *t = malloc(sizeof(float) * 2 * LUT_SIZE * LUT_SIZE);
    if (!t) return rs_fail(err, RS_ERR_NOMEM, "render: out of memory (specular table)");
    for (int j = 0; j < LUT_SIZE; j++)       // m at texel centres over 0..1 (the shader clamps m >= 0.02)
        for (int i = 0; i < LUT_SIZE; i++) { // N.V likewise
            float ndotv = RS_MAX(((float)i + 0.5f) / LUT_SIZE, 1e-3f);
            float m = RS_MAX(((float)j + 0.5f) / LUT_SIZE, 0.02f);
            lobe_albedo(ndotv, m, &t[2 * (j * LUT_SIZE + i)], &t[2 * (j * LUT_SIZE + i) + 1]);
        }
    glGenTextures(1, &r->lut_tex);
    glBindTexture(GL_TEXTURE_2D, r->lut_tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RG16F, LUT_SIZE, LUT_SIZE);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, LUT_SIZE, LUT_SIZE, GL_RG, GL_FLOAT, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    free(t);
    return rs_gl_check("render: specular table", err);
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

// The environment's other compact lamps. SH9 cannot hold a small bright source's irradiance (a clamped
// cosine): with the key light alone taken out, `studio`'s two side lamps left the SH up to 36 % off on
// normals facing away from the key (12 % of the front's mean irradiance; test_env_specular). So up to
// RS_ENV_LAMPS more are found in the level-0 map (the remainder, prefiltered with m 0.06: ~5 deg):
// the brightest texel not yet taken; its region: the texels within 20 deg brighter than
// sqrt(peak x median); its surround: the mean of the ring 20-25 deg out; the lamp: the region's excess
// over the surround, (1/pi) sum excess dw at the excess-weighted mean direction. A lamp that carries less
// than 5 % of the map's mean irradiance is not worth it and ends the search. Each one's SH projection
// (a directional light of colour c: sh_k = pi a_l c Y_k(d), a_l = 1, 2/3, 1/4) leaves the SH, and the
// shader adds it exactly, shadow-mapped (env_light.glsl, render_shadow.c). The specular reflects them
// exactly too (env_light.glsl rs_env_lamp_specular): rgb (3 floats a texel of level 0) gets level 0
// decoded and without them (each region's texels down to its surround), and lamp_free_levels takes them out of the coarser
// levels. False when out of memory.
static bool find_lamps(const rs_env *env, rs_render_env *e, float *rgb)
{
    const rs_env_level *lv = &env->levels[0];
    int w = lv->width, h = lv->height;
    size_t n = (size_t)w * h;
    float *lum = malloc(sizeof(float) * n), *dir = malloc(sizeof(float) * 3 * n);
    float *sorted = malloc(sizeof(float) * n);
    double *sr = malloc(sizeof(double) * (size_t)h);
    bool ok = lum && dir && sorted && sr;
    if (!ok) goto done;
    for (int j = 0; j < h; j++) {
        double t0 = PI * j / h, t1 = PI * (j + 1) / h, th = PI * (j + 0.5) / h;
        sr[j] = 2.0 * PI / w * (cos(t0) - cos(t1));
        for (int i = 0; i < w; i++) {
            size_t t = (size_t)j * w + i;
            double ph = 2.0 * PI * ((i + 0.5) / w - 0.5);
            dir[3 * t] = (float)(sin(th) * sin(ph)), dir[3 * t + 1] = (float)cos(th), dir[3 * t + 2] = (float)(sin(th) * cos(ph));
            rs_rgb9e5_unpack(lv->rgb9e5[t], rgb + 3 * t);
            lum[t] = sorted[t] = LUM(rgb + 3 * t);
        }
    }
    qsort(sorted, n, sizeof *sorted, cmp_float);
    float median = sorted[n / 2];
    double mean = 0;  // the map's mean irradiance / pi: its mean radiance
    for (size_t t = 0; t < n; t++) mean += lum[t] * sr[t / (size_t)w];
    mean /= 4.0 * PI;
    const float cos_region = cosf(20.0f * (float)PI / 180), cos_ring = cosf(25.0f * (float)PI / 180);
    for (int k = 0; k < RS_ENV_LAMPS; k++) {
        size_t peak = 0;
        for (size_t t = 1; t < n; t++)
            if (lum[t] > lum[peak]) peak = t;
        const float *pd = dir + 3 * peak;
        float thr = sqrtf(lum[peak] * RS_MAX(median, 1e-12f));
        double ring[3] = {0, 0, 0}, ring_sr = 0;
        for (size_t t = 0; t < n; t++) {
            float c = pd[0] * dir[3 * t] + pd[1] * dir[3 * t + 1] + pd[2] * dir[3 * t + 2];
            if (c < cos_region && c >= cos_ring) {
                for (int q = 0; q < 3; q++) ring[q] += rgb[3 * t + q] * sr[t / (size_t)w];
                ring_sr += sr[t / (size_t)w];
            }
        }
        for (int q = 0; q < 3; q++) ring[q] /= RS_MAX(ring_sr, 1e-12);
        double col[3] = {0, 0, 0}, d[3] = {0, 0, 0}, lsum = 0;
        for (size_t t = 0; t < n; t++) {
            float c = pd[0] * dir[3 * t] + pd[1] * dir[3 * t + 1] + pd[2] * dir[3 * t + 2];
            if (c < cos_region || lum[t] <= thr) continue;
            double dw = sr[t / (size_t)w], ex[3];
            for (int q = 0; q < 3; q++) {
                ex[q] = RS_MAX(rgb[3 * t + q] - ring[q], 0.0);
                col[q] += ex[q] * dw;
            }
            double le = LUM(ex) * dw;
            lsum += le;
            for (int q = 0; q < 3; q++) d[q] += le * dir[3 * t + q];
        }
        lum[peak] = 0;  // taken, whatever its region held
        double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int q = 0; q < 3; q++) col[q] /= PI;
        if (dl <= 0 || LUM(col) < 0.05 * mean) break;
        // A lamp: its region's texels keep only the surround (the next lamp is looked for without it).
        for (size_t t = 0; t < n; t++) {
            float c = pd[0] * dir[3 * t] + pd[1] * dir[3 * t + 1] + pd[2] * dir[3 * t + 2];
            if (c < cos_region || lum[t] <= thr) continue;
            for (int q = 0; q < 3; q++) rgb[3 * t + q] = (float)RS_MIN((double)rgb[3 * t + q], ring[q]);
            lum[t] = LUM(rgb + 3 * t);
        }
        float ld[3] = {(float)(d[0] / dl), (float)(d[1] / dl), (float)(d[2] / dl)}, y[9];
        rs_env_sh_basis(ld, y);
        static const float band[9] = {1.0f, 2.0f / 3, 2.0f / 3, 2.0f / 3, 0.25f, 0.25f, 0.25f, 0.25f, 0.25f};
        for (int b = 0; b < 9; b++)
            for (int q = 0; q < 3; q++) e->sh[b][q] -= (float)(PI * band[b] * col[q] * y[b]);
        for (int q = 0; q < 3; q++) e->lamp_dir[k][q] = ld[q], e->lamp_color[k][q] = (float)col[q];
        // Its angular radius as rouge-env measures the key's (a uniform disc's, sqrt(2 <theta^2>)), about
        // the mean direction: <theta^2> ~ 2 (1 - <cos theta>), and <cos theta> = |d| / sum of the weights.
        // Level 0 is prefiltered (m0): its lobe, exp(-theta^2 / (4 m0^2)), adds 4 m0^2 to <theta^2>, as much
        // as a studio lamp's own (a 10 deg blob for a 3 deg lamp, which then reflected over the horizon).
        double t2 = 4.0 * RS_MAX(1.0 - dl / RS_MAX(lsum, 1e-30), 0.0) - 8.0 * (double)env->level_m[0] * env->level_m[0];
        e->lamp_angle[k] = (float)sqrt(RS_MAX(t2, 1e-4));
    }
done:
    free(lum);
    free(dir);
    free(sorted);
    free(sr);
    return ok;
}

// The prefilter's lobe (tools/env/env_bake.c, N = V = R) at R.l = x for roughness m, and its integral over
// the sphere: a lamp of power P (the integral of its radiance) adds P lobe(R.d) / integral at R.
static double prefilter_lobe(double x, double m)
{
    if (x <= 0.0) return 0.0;
    double c2 = 0.5 * (1.0 + x);
    return exp(-(1.0 - x) / (1.0 + x) / (m * m)) / (c2 * c2) * x;
}

static double prefilter_integral(double m)
{
    enum { STEPS = 2048 };
    double s = 0.0;
    for (int i = 0; i < STEPS; i++) s += prefilter_lobe((i + 0.5) / STEPS, m);
    return 2.0 * PI * s / STEPS;  // dw = 2 pi d(cos) about R
}

// The map the shaders reflect, without the lamps find_lamps found (they are reflected exactly, shadowed,
// env_light.glsl: in the map, the blur of the prefilter and of the specular's taps spread a lamp that lies
// below a surface's horizon over it, the wet sheen studio's back lamp drew on the temple, issue 22). Level 0
// is rgb0 (find_lamps took each lamp's region down to its surround); each coarser level loses each lamp as
// a point of its power through the level's lobe, widened by the lamp's size as the shader widens its
// reflection. Each level's texels in out[k] (one allocation, freed by the caller). False when out of memory.
static bool lamp_free_levels(const rs_env *env, const rs_render_env *e, const float *rgb0, uint32_t **out)
{
    size_t total = 0;
    for (int k = 0; k < env->level_count; k++) total += (size_t)env->levels[k].width * env->levels[k].height;
    uint32_t *buf = malloc(total * sizeof *buf);
    if (!buf) return false;
    for (int k = 0; k < env->level_count; k++) {
        const rs_env_level *lv = &env->levels[k];
        out[k] = buf;
        buf += (size_t)lv->width * lv->height;
        double norm[RS_ENV_LAMPS] = {0}, m[RS_ENV_LAMPS] = {0};
        for (int i = 0; k > 0 && i < RS_ENV_LAMPS; i++) {
            double wid = 0.5 * e->lamp_angle[i];
            m[i] = sqrt((double)env->level_m[k] * env->level_m[k] + wid * wid);
            norm[i] = LUM(e->lamp_color[i]) > 0 ? PI / prefilter_integral(m[i]) : 0.0;  // power = pi x colour
        }
        for (int j = 0; j < lv->height; j++)
            for (int t = 0; t < lv->width; t++) {
                size_t at = (size_t)j * lv->width + t;
                float c[3];
                if (k == 0) {
                    memcpy(c, rgb0 + 3 * at, sizeof c);
                } else {
                    rs_rgb9e5_unpack(lv->rgb9e5[at], c);
                    float R[3], uv[2] = {(t + 0.5f) / lv->width, (j + 0.5f) / lv->height};
                    rs_env_uv_to_dir(uv, R);
                    for (int i = 0; i < RS_ENV_LAMPS; i++) {
                        if (norm[i] <= 0) continue;
                        const float *d = e->lamp_dir[i];
                        double f = norm[i] * prefilter_lobe(R[0] * d[0] + R[1] * d[1] + R[2] * d[2], m[i]);
                        for (int q = 0; q < 3; q++) c[q] = (float)RS_MAX(c[q] - f * e->lamp_color[i][q], 0.0);
                    }
                }
                out[k][at] = rs_rgb9e5_pack(c);
            }
    }
    return true;
}

// Mean irradiance (SH + the dominant light + `lamps` more lamps) of the skin facing direction fwd
// (environment frame), as a camera looking along -fwd sees it: normals spread over the hemisphere around
// fwd in proportion to the area they fill in its picture, cos(angle to fwd) (a sphere's picture), by a
// fixed spiral of directions.
static void facing_irradiance(const float sh[9][3], const float light_dir[3], const float light_color[3],
                              const float (*lamp_dir)[3], const float (*lamp_color)[3], int lamps,
                              const float fwd[3], float out[3])
{
    const int n = 256;
    // An orthonormal frame (t, b, fwd).
    float t[3] = {fwd[2], 0.0f, -fwd[0]};
    float tl = sqrtf(t[0] * t[0] + t[2] * t[2]);
    if (tl < 1e-6f) t[0] = 1.0f, t[2] = 0.0f, tl = 1.0f;
    for (int c = 0; c < 3; c++) t[c] /= tl;
    float b[3] = {fwd[1] * t[2] - fwd[2] * t[1], fwd[2] * t[0] - fwd[0] * t[2], fwd[0] * t[1] - fwd[1] * t[0]};
    double sum[3] = {0.0, 0.0, 0.0};
    for (int i = 0; i < n; i++) {
        float z = sqrtf(((float)i + 0.5f) / (float)n);  // cosine-weighted over the hemisphere
        float s = sqrtf(1.0f - z * z), phi = 2.39996323f * (float)i;
        float u = s * cosf(phi), v = s * sinf(phi), d[3], e[3];
        for (int c = 0; c < 3; c++) d[c] = u * t[c] + v * b[c] + z * fwd[c];
        float y[9];
        rs_env_sh_basis(d, y);
        for (int c = 0; c < 3; c++) {
            e[c] = 0.0f;
            for (int k = 0; k < 9; k++) e[c] += sh[k][c] * y[k];
            e[c] = RS_MAX(e[c], 0.0f);
        }
        float nl = RS_MAX(d[0] * light_dir[0] + d[1] * light_dir[1] + d[2] * light_dir[2], 0.0f);
        for (int c = 0; c < 3; c++) e[c] += light_color[c] * nl;
        for (int k = 0; k < lamps; k++) {
            float kl = RS_MAX(d[0] * lamp_dir[k][0] + d[1] * lamp_dir[k][1] + d[2] * lamp_dir[k][2], 0.0f);
            for (int c = 0; c < 3; c++) e[c] += lamp_color[k][c] * kl;
        }
        for (int c = 0; c < 3; c++) sum[c] += e[c];
    }
    for (int c = 0; c < 3; c++) out[c] = (float)(sum[c] / n);
}

rs_result rs_render_set_env(rs_renderer *r, const rs_env *env, rs_error *err)
{
    r->inc_valid = false;
    r->light_serial++;  // the splats' irradiance reads the environment
    if (r->env_tex) glDeleteTextures(1, &r->env_tex);
    r->env_tex = 0;
    memset(&r->env, 0, sizeof r->env);
    if (!env) return RS_OK;
    rs_result res = make_lut(r, err);
    if (res != RS_OK) return res;
    if (env->level_count < 1 || env->level_count > RS_ENV_MAX_LEVELS)
        return rs_fail(err, RS_ERR_ARG, "render: environment %s: %d levels", env->name, env->level_count);
    int w = env->levels[0].width, h = env->levels[0].height;
    if (w > r->caps.max_texture_size || h > r->caps.max_texture_size)
        return rs_fail(err, RS_ERR_GL, "render: environment %s: %dx%d exceeds the GPU's %d", env->name, w, h,
                       r->caps.max_texture_size);
    rs_render_env *e = &r->env;
    float *rgb0 = malloc(sizeof(float) * 3 * (size_t)w * h);
    uint32_t *level[RS_ENV_MAX_LEVELS] = {NULL};
    bool ok = rgb0 != NULL;
    memcpy(e->sh, env->sh, sizeof e->sh);  // find_lamps takes the lamps out of it
    ok = ok && find_lamps(env, e, rgb0) && lamp_free_levels(env, e, rgb0, level);
    free(rgb0);
    if (!ok) {
        memset(e, 0, sizeof *e);
        return rs_fail(err, RS_ERR_NOMEM, "render: environment %s: out of memory", env->name);
    }
    glGenTextures(1, &r->env_tex);
    glBindTexture(GL_TEXTURE_2D, r->env_tex);
    glTexStorage2D(GL_TEXTURE_2D, env->level_count, GL_RGB9_E5, w, h);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int k = 0; k < env->level_count; k++)
        glTexSubImage2D(GL_TEXTURE_2D, k, 0, 0, env->levels[k].width, env->levels[k].height, GL_RGB,
                        GL_UNSIGNED_INT_5_9_9_9_REV, level[k]);
    free(level[0]);  // the one allocation
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);  // longitude wraps
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, env->level_count - 1);
    glBindTexture(GL_TEXTURE_2D, 0);
    res = rs_gl_check("render: environment upload", err);
    if (res != RS_OK) {
        glDeleteTextures(1, &r->env_tex);
        r->env_tex = 0;
        memset(e, 0, sizeof *e);
        return res;
    }
    e->on = true;
    const float fwd[3] = {0.0f, 0.0f, 1.0f};  // the face frame's forward: the face seen from the front
    float fe[3];
    facing_irradiance(env->sh, env->light_dir, env->light_color, NULL, NULL, 0, fwd, fe);  // lamps still in the SH
    float front = LUM(fe);
    e->scale = front > 1e-6f ? ENV_TARGET_FRONT / front : 1.0f;
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++) e->sh[k][c] *= e->scale;
    for (int k = 0; k < RS_ENV_LAMPS; k++)
        for (int c = 0; c < 3; c++) e->lamp_color[k][c] *= e->scale;
    for (int c = 0; c < 3; c++) {
        e->light_dir[c] = env->light_dir[c];
        e->light_color[c] = env->light_color[c] * e->scale;
    }
    e->light_angle = env->light_angle;
    e->levels = env->level_count;
    for (int k = 0; k < env->level_count; k++) e->level_m[k] = env->level_m[k];
    for (int k = env->level_count; k < RS_ENV_MAX_LEVELS; k++) e->level_m[k] = 2.0f;
    return RS_OK;
}

bool rs_render_has_env(const rs_renderer *r) { return r->env.on; }

void rs_render_env_uniforms(const rs_renderer *r, const rs_frame *f, GLuint prog)
{
    bool on = f->env_on;
    glUniform1f(rs_uloc(prog, "u_env_on"), on ? 1.0f : 0.0f);
    rs_render_bind_texture(RS_UNIT_ENV, on ? r->env_tex : 0);
    rs_render_bind_texture(RS_UNIT_SPEC_LUT, on ? r->lut_tex : 0);
    if (!on) return;
    float e = RS_MAX(f->view.env_intensity, 0.0f);
    float sh[9][3];
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++) sh[k][c] = r->env.sh[k][c] * e;
    glUniformMatrix3fv(rs_uloc(prog, "u_env_from_view"), 1, GL_FALSE, (const float *)f->env_from_view);
    glUniform3fv(rs_uloc(prog, "u_env_sh"), 9, &sh[0][0]);
    float lamp[RS_ENV_LAMPS][3];
    for (int k = 0; k < RS_ENV_LAMPS; k++)
        for (int c = 0; c < 3; c++) lamp[k][c] = r->env.lamp_color[k][c] * e;
    glUniform3fv(rs_uloc(prog, "u_env_lamp_dir"), RS_ENV_LAMPS, &r->env.lamp_dir[0][0]);
    glUniform3fv(rs_uloc(prog, "u_env_lamp_color"), RS_ENV_LAMPS, &lamp[0][0]);
    float widen[RS_ENV_LAMPS];
    for (int k = 0; k < RS_ENV_LAMPS; k++) widen[k] = 0.5f * r->env.lamp_angle[k];
    glUniform1fv(rs_uloc(prog, "u_env_lamp_widen"), RS_ENV_LAMPS, widen);
    glUniform1fv(rs_uloc(prog, "u_env_m"), RS_ENV_MAX_LEVELS, r->env.level_m);
    glUniform1i(rs_uloc(prog, "u_env_levels"), r->env.levels);
    glUniform1f(rs_uloc(prog, "u_env_scale"), r->env.scale * e);
    float one_lookup = f->mobile ? RS_ENV_ONE_LOOKUP_MOBILE : RS_ENV_ONE_LOOKUP_REFERENCE;
    glUniform1f(rs_uloc(prog, "u_env_one_lookup"), one_lookup);
    glUniform1f(rs_uloc(prog, "u_env_across"), f->mobile ? 0.0f : 1.0f);
    // What the skin around a hollow is lit by, on average (bounce.glsl): the face's own front surface
    // (its forward turned into the environment's frame with the environment), SH and light together.
    float a = f->view.env_rotate_deg * 0.017453293f;
    const float fwd[3] = {-sinf(a), 0.0f, cosf(a)};
    float surround[3];
    facing_irradiance(r->env.sh, r->env.light_dir, r->env.light_color, (const float (*)[3])r->env.lamp_dir,
                      (const float (*)[3])r->env.lamp_color, RS_ENV_LAMPS, fwd, surround);
    for (int c = 0; c < 3; c++) surround[c] *= e;
    glUniform3fv(rs_uloc(prog, "u_env_surround"), 1, surround);
    glUniform3fv(rs_uloc(prog, "u_body_lo"), 1, r->body_lo);
    glUniform1f(rs_uloc(prog, "u_body_cell"), r->body_cell);
    glUniform1i(rs_uloc(prog, "u_body_n"), RS_BODY_GRID);
}

void rs_render_env_release(rs_renderer *r)
{
    GLuint t[3] = {r->env_tex, r->lut_tex, r->body_tex};
    glDeleteTextures(3, t);
    r->env_tex = r->lut_tex = r->body_tex = 0;
    r->env.on = false;
}

rs_result rs_render_env_body(rs_renderer *r, rs_error *err)
{
    if (r->body_tex) return RS_OK;
    const rs_splat_cloud *c = r->cloud;
    float ext = 0.0f;
    for (int k = 0; k < 3; k++) ext = fmaxf(ext, c->hdr.bbox_max[k] - c->hdr.bbox_min[k]);
    r->body_cell = fmaxf(ext, 1e-6f) / (RS_BODY_GRID - 1);
    for (int k = 0; k < 3; k++) r->body_lo[k] = c->hdr.bbox_min[k];
    // Per cell: the mean linear albedo and the summed normal of the splats in it.
    const size_t cells = (size_t)RS_BODY_GRID * RS_BODY_GRID * RS_BODY_GRID;
    float *acc = calloc(cells * 7, sizeof(float));
    uint32_t *grid = calloc(cells * 2, sizeof(uint32_t));
    if (!acc || !grid) {
        free(acc), free(grid);
        return rs_fail(err, RS_ERR_NOMEM, "render: body grid: out of memory");
    }
    float lin[256];
    for (int v = 0; v < 256; v++) lin[v] = rs_srgb_to_linear((float)v / 255.0f);
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        int q[3];
        for (int k = 0; k < 3; k++) q[k] = (int)floorf((c->pos[i][k] - r->body_lo[k]) / r->body_cell);
        if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= RS_BODY_GRID || q[1] >= RS_BODY_GRID || q[2] >= RS_BODY_GRID) continue;
        rs_splat s;
        rs_splat_get(c, i, &s);
        float *a = acc + 7 * (((size_t)q[2] * RS_BODY_GRID + (size_t)q[1]) * RS_BODY_GRID + (size_t)q[0]);
        for (int k = 0; k < 3; k++) a[k] += lin[s.rgb[k]], a[3 + k] += c->normal[i][k];
        a[6] += 1.0f;
    }
    // Per cell, RG32UI: bit 31 set where the cell holds surface, the albedo 10:10:10; the normal coded as
    // a splat record's (octahedral snorm16 x 2).
    for (size_t v = 0; v < cells; v++) {
        const float *a = acc + 7 * v;
        if (a[6] <= 0.0f || !(fabsf(a[3]) + fabsf(a[4]) + fabsf(a[5]) > 0.0f)) continue;
        uint32_t w = 1u << 31;
        for (int k = 0; k < 3; k++)
            w |= (uint32_t)lrintf(RS_CLAMP(a[k] / a[6], 0.0f, 1.0f) * 1023.0f) << (20 - 10 * k);
        grid[2 * v] = w;
        grid[2 * v + 1] = rs_splat_encode_normal(a + 3);
    }
    free(acc);
    glGenTextures(1, &r->body_tex);
    glBindTexture(GL_TEXTURE_3D, r->body_tex);
    glTexStorage3D(GL_TEXTURE_3D, 1, GL_RG32UI, RS_BODY_GRID, RS_BODY_GRID, RS_BODY_GRID);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, RS_BODY_GRID, RS_BODY_GRID, RS_BODY_GRID, GL_RG_INTEGER, GL_UNSIGNED_INT, grid);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindTexture(GL_TEXTURE_3D, 0);
    free(grid);
    rs_result res = rs_gl_check("render: body grid upload", err);
    if (res != RS_OK) {
        glDeleteTextures(1, &r->body_tex);
        r->body_tex = 0;
    }
    return res;
}
