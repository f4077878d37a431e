// env_bake.c — from a latlong HDR map to an rs_env: resampling, the dominant light, SH9, prefiltering.
// What each step computes and why: env_bake.h and docs/env.md.
#include "env/env_bake.h"

#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

const float rs_env_bake_level_m[RS_ENV_BAKE_LEVELS] = {0.06f, 0.12f, 0.22f, 0.38f, 0.6f, 1.0f};

static float lum(const float *c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// ---- maps ----

rs_result rs_envmap_alloc(rs_envmap *m, int w, int h, rs_error *err)
{
    m->w = w, m->h = h;
    m->rgb = calloc((size_t)w * (size_t)h * 3, sizeof(float));
    return m->rgb ? RS_OK : rs_fail(err, RS_ERR_NOMEM, "out of memory for a %dx%d map", w, h);
}

void rs_envmap_free(rs_envmap *m)
{
    free(m->rgb);
    m->rgb = NULL;
}

void rs_envmap_texel_dir(int w, int h, int i, int j, float d[3])
{
    float uv[2] = {((float)i + 0.5f) / (float)w, ((float)j + 0.5f) / (float)h};
    rs_env_uv_to_dir(uv, d);
}

double rs_envmap_texel_sr(int w, int h, int j)
{
    return (2.0 * PI / w) * (cos(PI * j / h) - cos(PI * (j + 1) / h));
}

// Every texel's direction, w * h * 3 floats (the loops below visit texels many times).
static float *texel_dirs(int w, int h)
{
    float *d = rs_alloc_array((size_t)w * (size_t)h * 3, sizeof(float));
    if (!d) return NULL;
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) rs_envmap_texel_dir(w, h, i, j, d + ((size_t)j * (size_t)w + (size_t)i) * 3);
    return d;
}

rs_result rs_envmap_resample(const rs_envmap *src, int w, rs_envmap *out, rs_error *err)
{
    int h = w / 2, sw = src->w, sh = src->h;
    rs_envmap tmp = {0};
    rs_result r = rs_envmap_alloc(&tmp, w, sh, err);
    if (r != RS_OK) return r;
    if ((r = rs_envmap_alloc(out, w, h, err)) != RS_OK) {
        rs_envmap_free(&tmp);
        return r;
    }
    // Columns: uniform in phi, so the weights are the overlaps of [i, i+1) * sw / w with source columns.
    double scale = (double)sw / w;
    for (int i = 0; i < w; i++) {
        double a = i * scale, b = (i + 1) * scale;
        for (int k = (int)floor(a); k < sw && k < b; k++) {
            double wgt = (fmin(b, k + 1.0) - fmax(a, (double)k)) / scale;
            if (wgt <= 0) continue;
            for (int j = 0; j < sh; j++)
                for (int c = 0; c < 3; c++)
                    tmp.rgb[((size_t)j * w + i) * 3 + c] += (float)(wgt * src->rgb[((size_t)j * sw + k) * 3 + c]);
        }
    }
    // Rows: weighted by solid angle, the overlap of the theta ranges measured in cos theta.
    for (int j = 0; j < h; j++) {
        double t0 = PI * j / h, t1 = PI * (j + 1) / h, total = cos(t0) - cos(t1);
        for (int k = (int)floor((double)j * sh / h); k < sh && PI * k / sh < t1; k++) {
            double lo = fmax(t0, PI * k / sh), hi = fmin(t1, PI * (k + 1) / sh);
            if (hi <= lo) continue;
            double wgt = (cos(lo) - cos(hi)) / total;
            for (int i = 0; i < w; i++)
                for (int c = 0; c < 3; c++)
                    out->rgb[((size_t)j * w + i) * 3 + c] += (float)(wgt * tmp.rgb[((size_t)k * w + i) * 3 + c]);
        }
    }
    rs_envmap_free(&tmp);
    return RS_OK;
}

void rs_envmap_roll(rs_envmap *m, int di)
{
    di = ((di % m->w) + m->w) % m->w;
    if (di == 0) return;
    size_t row = (size_t)m->w * 3;
    float *tmp = malloc(row * sizeof(float));
    if (!tmp) return;  // cannot happen for the sizes rouge-env uses; the caller checks nothing else
    for (int j = 0; j < m->h; j++) {
        float *r = m->rgb + (size_t)j * row;
        memcpy(tmp, r, row * sizeof(float));
        for (int i = 0; i < m->w; i++) memcpy(r + (size_t)((i + di) % m->w) * 3, tmp + (size_t)i * 3, 3 * sizeof(float));
    }
    free(tmp);
}

static void roll_mask(uint8_t *mask, int w, int h, int di)
{
    di = ((di % w) + w) % w;
    uint8_t *tmp = malloc((size_t)w);
    if (!tmp) return;
    for (int j = 0; j < h; j++) {
        uint8_t *r = mask + (size_t)j * w;
        memcpy(tmp, r, (size_t)w);
        for (int i = 0; i < w; i++) r[(i + di) % w] = tmp[i];
    }
    free(tmp);
}

void rs_envmap_mirror(rs_envmap *m)
{
    for (int j = 0; j < m->h; j++) {
        float *r = m->rgb + (size_t)j * m->w * 3;
        for (int a = 0, b = m->w - 1; a < b; a++, b--)
            for (int c = 0; c < 3; c++) {
                float t = r[a * 3 + c];
                r[a * 3 + c] = r[b * 3 + c];
                r[b * 3 + c] = t;
            }
    }
}

// ---- the dominant light ----

typedef struct lum_sr {
    float lum, sr;
} lum_sr;

static int cmp_lum(const void *a, const void *b)
{
    float x = ((const lum_sr *)a)->lum, y = ((const lum_sr *)b)->lum;
    return (x > y) - (x < y);
}

// Solid-angle-weighted median luminance of the texels with sel[t] (all when sel is NULL); -1 if none.
static float median_lum(const rs_envmap *m, const uint8_t *sel, rs_error *err)
{
    size_t n = (size_t)m->w * m->h, k = 0;
    lum_sr *v = rs_alloc_array(n, sizeof *v);
    if (!v) {
        rs_fail(err, RS_ERR_NOMEM, "out of memory");
        return -2;
    }
    double total = 0;
    for (int j = 0; j < m->h; j++) {
        float sr = (float)rs_envmap_texel_sr(m->w, m->h, j);
        for (int i = 0; i < m->w; i++) {
            size_t t = (size_t)j * m->w + i;
            if (sel && !sel[t]) continue;
            v[k++] = (lum_sr){lum(m->rgb + t * 3), sr};
            total += sr;
        }
    }
    float med = -1;
    if (k > 0) {
        qsort(v, k, sizeof *v, cmp_lum);
        double acc = 0;
        for (size_t q = 0; q < k; q++)
            if ((acc += v[q].sr) >= 0.5 * total) {
                med = v[q].lum;
                break;
            }
    }
    free(v);
    return med;
}

// Grows `region` from texel p over 8-connected texels (u wraps) with luminance >= threshold and direction
// within cos_reach of dirs[p]. Returns the texel count.
static int flood(const rs_envmap *m, const float *dirs, size_t p, float threshold, float cos_reach, uint8_t *region,
                 int *stack)
{
    int w = m->w, h = m->h, top = 0, count = 0;
    const float *pd = dirs + p * 3;
    region[p] = 1;
    stack[top++] = (int)p;
    while (top > 0) {
        int t = stack[--top], ti = t % w, tj = t / w;
        count++;
        for (int dj = -1; dj <= 1; dj++)
            for (int di = -1; di <= 1; di++) {
                int j = tj + dj, i = (ti + di + w) % w;
                if (j < 0 || j >= h) continue;
                size_t q = (size_t)j * w + i;
                if (region[q] || lum(m->rgb + q * 3) < threshold || dot3(dirs + q * 3, pd) < cos_reach) continue;
                region[q] = 1;
                stack[top++] = (int)q;
            }
    }
    return count;
}

// One step of 8-neighbour dilation of `in` into `out` (u wraps).
static void dilate(const uint8_t *in, uint8_t *out, int w, int h)
{
    for (int j = 0; j < h; j++)
        for (int i = 0; i < w; i++) {
            uint8_t v = 0;
            for (int dj = -1; dj <= 1 && !v; dj++)
                for (int di = -1; di <= 1 && !v; di++)
                    if (j + dj >= 0 && j + dj < h) v = in[(size_t)(j + dj) * w + (i + di + w) % w];
            out[(size_t)j * w + i] = v;
        }
}

// The light's region grown from peak texel p: the connected texels within 45 degrees brighter than the
// geometric mean of the peak and the map's typical level (a sun 10^4 above the sky keeps only its core, a
// softbox 100 above a dark studio all of its face; the floor keeps a black map finite). Returns the count.
static int grow_region(const rs_envmap *m, const float *dirs, size_t p, float median, uint8_t *region, int *stack,
                       float *threshold)
{
    float peak = lum(m->rgb + p * 3);
    *threshold = sqrtf(peak * fmaxf(median, 1e-3f * peak));
    return flood(m, dirs, p, *threshold, (float)cos(45.0 * PI / 180), region, stack);
}

// The seed: the brightest texel of a 64 x 32 copy (5.6 degrees a texel: the mean over a lamp-sized patch,
// so a hot pixel does not win over a softbox) smoothed by a [1 2 1] tent in both directions.
static rs_result blurred_peak(const rs_envmap *m, float seed[3], rs_error *err)
{
    enum { CW = 64, CH = 32 };
    rs_envmap c = {0};
    rs_result r = rs_envmap_resample(m, CW, &c, err);
    if (r != RS_OK) return r;
    float best = -1;
    int bi = 0, bj = 0;
    for (int j = 0; j < CH; j++)
        for (int i = 0; i < CW; i++) {
            float s = 0, wsum = 0;
            for (int dj = -1; dj <= 1; dj++)
                for (int di = -1; di <= 1; di++) {
                    if (j + dj < 0 || j + dj >= CH) continue;
                    float wgt = (float)((2 - abs(di)) * (2 - abs(dj)));
                    s += wgt * lum(c.rgb + ((size_t)(j + dj) * CW + (size_t)((i + di + CW) % CW)) * 3);
                    wsum += wgt;
                }
            if (s / wsum > best) best = s / wsum, bi = i, bj = j;
        }
    rs_envmap_texel_dir(CW, CH, bi, bj, seed);
    rs_envmap_free(&c);
    return RS_OK;
}

rs_result rs_env_find_light(rs_envmap *m, const float *near, rs_env_light *out, uint8_t *mask, rs_error *err)
{
    int w = m->w, h = m->h;
    size_t n = (size_t)w * h;
    rs_result r = RS_OK;
    float *dirs = texel_dirs(w, h), *excess_lum = rs_alloc_array(n, sizeof(float));
    uint8_t *region = calloc(n, 1), *ring = calloc(n, 1), *tmp = calloc(n, 1);
    int *stack = rs_alloc_array(n, sizeof(int));
    if (!dirs || !excess_lum || !region || !ring || !tmp || !stack) {
        r = rs_fail(err, RS_ERR_NOMEM, "out of memory finding the light of a %dx%d map", w, h);
        goto done;
    }
    float seed[3];
    if (near) memcpy(seed, near, sizeof seed);
    else if ((r = blurred_peak(m, seed, err)) != RS_OK) goto done;
    float median = median_lum(m, NULL, err);
    if (median < -1.5f) {
        r = RS_ERR_NOMEM;
        goto done;
    }
    // The peak: the brightest texel within 9 degrees of the seed (the tent's reach), 20 of a given one.
    size_t p = 0;
    float peak = -1, cos_seed = (float)cos((near ? 20.0 : 9.0) * PI / 180);
    for (size_t t = 0; t < n; t++)
        if (dot3(dirs + t * 3, seed) >= cos_seed && lum(m->rgb + t * 3) > peak) peak = lum(m->rgb + t * 3), p = t;
    float threshold;
    int texels = grow_region(m, dirs, p, median, region, stack, &threshold);

    // The surrounding level: a ring about 3 degrees wide (at least 2 texels) outside the region.
    int steps = (int)RS_MAX(2.0, ceil(3.0 / (360.0 / w)));
    memcpy(ring, region, n);
    for (int s = 0; s < steps; s++) {
        dilate(ring, tmp, w, h);
        memcpy(ring, tmp, n);
    }
    for (size_t t = 0; t < n; t++) ring[t] = ring[t] && !region[t];
    float ring_med = median_lum(m, ring, err);
    if (ring_med < -1.5f) {
        r = RS_ERR_NOMEM;
        goto done;
    }
    double mean[3] = {0, 0, 0}, sr_sum = 0;
    for (size_t t = 0; t < n; t++)
        if (ring[t]) {
            double sr = rs_envmap_texel_sr(w, h, (int)(t / w));
            for (int c = 0; c < 3; c++) mean[c] += m->rgb[t * 3 + c] * sr;
            sr_sum += sr;
        }
    // The ring's colour at its median level: a bright object grazing the ring does not raise it.
    float surround[3] = {0, 0, 0}, mean_rgb[3];
    for (int c = 0; c < 3; c++) mean_rgb[c] = sr_sum > 0 ? (float)(mean[c] / sr_sum) : 0.0f;
    float mean_lum = lum(mean_rgb);
    for (int c = 0; c < 3; c++) surround[c] = mean_lum > 0 && ring_med > 0 ? mean_rgb[c] * ring_med / mean_lum : 0.0f;

    // Take the excess out: it is the light.
    rs_env_light L = {.peak = peak, .threshold = threshold, .texels = texels};
    memcpy(L.surround, surround, sizeof surround);
    double color[3] = {0, 0, 0}, dir[3] = {0, 0, 0}, omega = 0;
    for (size_t t = 0; t < n; t++) {
        if (!region[t]) continue;
        double sr = rs_envmap_texel_sr(w, h, (int)(t / w));
        float ex[3];
        for (int c = 0; c < 3; c++) {
            ex[c] = fmaxf(m->rgb[t * 3 + c] - surround[c], 0.0f);
            m->rgb[t * 3 + c] -= ex[c];
            color[c] += ex[c] * sr / PI;
        }
        excess_lum[t] = (float)(lum(ex) * sr);
        for (int c = 0; c < 3; c++) dir[c] += dirs[t * 3 + c] * excess_lum[t];
        omega += sr;
    }
    double len = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    for (int c = 0; c < 3; c++) {
        L.color[c] = (float)color[c];
        L.dir[c] = len > 0 ? (float)(dir[c] / len) : dirs[p * 3 + c];
    }
    L.solid_angle = (float)omega;
    // Angular radius from the excess's second moment: a uniform disc of radius a has <theta^2> = a^2 / 2.
    double m2 = 0, wsum = 0;
    for (size_t t = 0; t < n; t++) {
        if (!region[t]) continue;
        double th = acos(fmin(fmax(dot3(dirs + t * 3, L.dir), -1.0f), 1.0f));
        m2 += excess_lum[t] * th * th;
        wsum += excess_lum[t];
    }
    L.angle = (float)fmax(wsum > 0 ? sqrt(2 * m2 / wsum) : 0.0, 0.5 * PI / h);
    if (mask) memcpy(mask, region, n);
    *out = L;
done:
    free(dirs);
    free(excess_lum);
    free(region);
    free(ring);
    free(tmp);
    free(stack);
    return r;
}

// ---- SH9 ----

void rs_env_project_sh(const rs_envmap *m, float sh[9][3])
{
    static const double a[9] = {1.0, 2.0 / 3, 2.0 / 3, 2.0 / 3, 0.25, 0.25, 0.25, 0.25, 0.25};  // A_l / pi
    double acc[9][3] = {{0}};
    for (int j = 0; j < m->h; j++) {
        double sr = rs_envmap_texel_sr(m->w, m->h, j);
        for (int i = 0; i < m->w; i++) {
            float d[3], y[9];
            rs_envmap_texel_dir(m->w, m->h, i, j, d);
            rs_env_sh_basis(d, y);
            const float *c = m->rgb + ((size_t)j * m->w + i) * 3;
            for (int k = 0; k < 9; k++)
                for (int ch = 0; ch < 3; ch++) acc[k][ch] += c[ch] * y[k] * sr;
        }
    }
    for (int k = 0; k < 9; k++)
        for (int ch = 0; ch < 3; ch++) sh[k][ch] = (float)(acc[k][ch] * a[k]);
}

// ---- prefiltering ----

float rs_env_beckmann(float ndoth, float m)
{
    float c2 = ndoth * ndoth, m2 = m * m;
    return expf((c2 - 1.0f) / (c2 * m2)) / (m2 * c2 * c2);
}

rs_result rs_env_prefilter(const rs_envmap *full, rs_env_level *lvl, float m, rs_error *err)
{
    // The source is a whole number of times the level's width, so that turning an output texel one column
    // about up turns its lobe by whole source columns: every texel of an output row then has the same
    // weights, shifted, and a row's weights are computed once (the weight of each source texel for the
    // row's first texel), not once per output texel.
    int lw = lvl->width, lh = lvl->height, min_w = RS_MAX(64, 2 * lw), scale = (min_w + lw - 1) / lw;
    rs_envmap src = {0};
    rs_result r = rs_envmap_resample(full, scale * lw, &src, err);
    if (r != RS_OK) return r;
    int sw = src.w, sh = src.h;
    // Rows twice as long (the row, then the row again), so a lobe that wraps round the seam is one run.
    float *rows = rs_alloc_array((size_t)sh * 2 * (size_t)sw * 3, sizeof(float));
    float *row_sr = malloc((size_t)sh * sizeof(float));
    float *wts = rs_alloc_array((size_t)sh * (size_t)sw, sizeof(float));
    int *run = rs_alloc_array((size_t)sh * 3, sizeof(int));  // per source row: first column, length, row
    float *dirs = texel_dirs(sw, sh);
    if (!rows || !row_sr || !wts || !run || !dirs) {
        free(rows), free(row_sr), free(wts), free(run), free(dirs);
        rs_envmap_free(&src);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory prefiltering");
    }
    for (int j = 0; j < sh; j++) {
        row_sr[j] = (float)rs_envmap_texel_sr(sw, sh, j);
        float *d = rows + (size_t)j * 2 * sw * 3;
        memcpy(d, src.rgb + (size_t)j * sw * 3, (size_t)sw * 3 * sizeof(float));
        memcpy(d + (size_t)sw * 3, d, (size_t)sw * 3 * sizeof(float));
    }
    // The lobe is below 1e-5 of its peak where tan(alpha) > m sqrt(ln 1e5) = 3.4 m; l turns twice as far
    // as h. A texel's diagonal more, and never past the horizon (max(R.l, 0) ends the lobe there).
    double texel = 2 * PI / sw, reach = fmin(2 * atan(3.4 * m) + 1.5 * texel, PI / 2 + 1.5 * texel);
    double cos_reach = cos(reach), inv_m2 = 1.0 / ((double)m * m);
    // The weight depends on R.l alone (N = R: N.h = sqrt((1 + R.l) / 2), tan^2 = (1 - R.l) / (1 + R.l)):
    // a table over R.l in [max(cos reach, 0), 1], read with linear interpolation, instead of exp() per texel.
    enum { TABLE = 4096 };
    static_assert(TABLE > 1, "table");
    float table[TABLE + 1];
    double rl0 = fmax(cos_reach, 0.0), step = (1.0 - rl0) / TABLE;
    for (int k = 0; k <= TABLE; k++) {
        double rl = rl0 + k * step, c2 = 0.5 * (1.0 + rl);
        table[k] = rl <= 0 ? 0.0f : (float)(exp(-(1.0 - rl) / (1.0 + rl) * inv_m2) / (c2 * c2) * rl);
    }
    for (int oj = 0; oj < lh; oj++) {
        // The weights of the row's first texel: per source row, the run of columns where the lobe is
        // above its cut (an arc about the texel's own column: R.l falls with the azimuth difference).
        float R[3];
        rs_envmap_texel_dir(lw, lh, 0, oj, R);
        double theta_r = PI * (oj + 0.5) / lh;
        int j0 = RS_MAX(0, (int)floor((theta_r - reach) / PI * sh));
        int j1 = RS_MIN(sh - 1, (int)ceil((theta_r + reach) / PI * sh));
        int ic = (int)floor((0.5 / lw) * sw), runs = 0;
        size_t used = 0;
        double wsum = 0;
        for (int j = j0; j <= j1; j++) {
            // Walk out from ic both ways while the lobe lasts (half a turn at most each way).
            int lo = 0, hi = -1;
            for (int k = 0; k <= sw / 2; k++) {
                int i = ((ic - k) % sw + sw) % sw;
                if (dot3(R, dirs + ((size_t)j * sw + (size_t)i) * 3) <= rl0) break;
                lo = -k;
                if (hi < 0) hi = 0;
            }
            if (hi < 0) continue;
            for (int k = 1; k - lo < sw && k <= sw / 2; k++) {
                if (dot3(R, dirs + ((size_t)j * sw + (size_t)((ic + k) % sw)) * 3) <= rl0) break;
                hi = k;
            }
            int first = ((ic + lo) % sw + sw) % sw, len = hi - lo + 1;
            run[runs * 3] = first, run[runs * 3 + 1] = len, run[runs * 3 + 2] = j;
            runs++;
            for (int k = 0; k < len; k++) {
                float rl = dot3(R, dirs + ((size_t)j * sw + (size_t)((first + k) % sw)) * 3);
                float x = rl > rl0 ? (float)((rl - rl0) / step) : 0.0f;
                int t = RS_MIN((int)x, TABLE - 1);
                float wgt = rl > rl0 ? (table[t] + (x - (float)t) * (table[t + 1] - table[t])) * row_sr[j] : 0.0f;
                wts[used + k] = wgt;
                wsum += wgt;
            }
            used += len;
        }
        for (int oi = 0; oi < lw; oi++) {
            // (Three scalars, not an array: the compiler keeps them in registers in the inner loop.)
            double acc0 = 0, acc1 = 0, acc2 = 0;
            const float *w = wts;
            for (int q = 0; q < runs; q++) {
                int first = (run[q * 3] + scale * oi) % sw, len = run[q * 3 + 1];
                const float *c = rows + ((size_t)run[q * 3 + 2] * 2 * sw + (size_t)first) * 3;
                for (int k = 0; k < len; k++, c += 3) {
                    float wgt = w[k];
                    acc0 += c[0] * wgt, acc1 += c[1] * wgt, acc2 += c[2] * wgt;
                }
                w += len;
            }
            double acc[3] = {acc0, acc1, acc2};
            float out[3];
            for (int k = 0; k < 3; k++) out[k] = wsum > 0 ? (float)(acc[k] / wsum) : 0.0f;
            lvl->rgb9e5[(size_t)oj * lw + oi] = rs_rgb9e5_pack(out);
        }
    }
    free(rows);
    free(row_sr);
    free(wts);
    free(run);
    free(dirs);
    rs_envmap_free(&src);
    return RS_OK;
}

// ---- the whole bake ----

rs_result rs_env_bake(const rs_envmap *src, const rs_env_bake_desc *desc, rs_env **out, rs_env_light *light,
                      rs_envmap *work_out, uint8_t **mask_out, rs_error *err)
{
    rs_envmap work = {0};
    rs_env *e = NULL;
    uint8_t *mask = NULL;
    rs_env_light L;
    rs_result r = rs_envmap_resample(src, RS_MIN(src->w, RS_ENV_BAKE_WORK_WIDTH), &work, err);
    if (r != RS_OK) return r;
    rs_envmap_mirror(&work);
    mask = calloc((size_t)work.w * work.h, 1);
    if (!mask) r = rs_fail(err, RS_ERR_NOMEM, "out of memory");
    if (r == RS_OK) {
        float near[3];
        if (desc->light_near) {
            // The hint is in the source image's u, v; the work map is mirrored.
            float uv[2] = {1.0f - desc->light_near_uv[0], desc->light_near_uv[1]};
            rs_env_uv_to_dir(uv, near);
        }
        r = rs_env_find_light(&work, desc->light_near ? near : NULL, &L, mask, err);
    }
    if (r == RS_OK && !desc->keep_yaw) {
        // Whole columns: no resampling blur; the light lands within half a column of the key yaw.
        double col = 2 * PI / work.w, phi = atan2(L.dir[0], L.dir[2]);
        int di = (int)lround((desc->key_yaw_deg * PI / 180 - phi) / col);
        rs_envmap_roll(&work, di);
        roll_mask(mask, work.w, work.h, di);
        double s = hypot(L.dir[0], L.dir[2]), phi2 = phi + di * col;
        L.dir[0] = (float)(s * sin(phi2));
        L.dir[2] = (float)(s * cos(phi2));
    }
    if (r == RS_OK) r = rs_env_create(RS_ENV_BAKE_WIDTH, RS_ENV_BAKE_LEVELS, &e, err);
    if (r == RS_OK) {
        snprintf(e->name, sizeof e->name, "%s", desc->name ? desc->name : "");
        rs_env_project_sh(&work, e->sh);
        memcpy(e->light_dir, L.dir, sizeof L.dir);
        memcpy(e->light_color, L.color, sizeof L.color);
        e->light_angle = L.angle;
        for (int k = 0; k < RS_ENV_BAKE_LEVELS && r == RS_OK; k++) {
            e->level_m[k] = rs_env_bake_level_m[k];
            r = rs_env_prefilter(&work, &e->levels[k], rs_env_bake_level_m[k], err);
        }
    }
    if (r != RS_OK) {
        rs_env_destroy(e);
        rs_envmap_free(&work);
        free(mask);
        return r;
    }
    *out = e;
    if (light) *light = L;
    if (work_out) *work_out = work;
    else rs_envmap_free(&work);
    if (mask_out) *mask_out = mask;
    else free(mask);
    return RS_OK;
}
