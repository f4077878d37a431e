// splat.c — the splat cloud: quantisation codecs, create/destroy, header checks, LOD queries.
// The .rsf byte layout lives in rsf_io.c; both follow docs/rsf.md.
#define _POSIX_C_SOURCE 200809L  // strnlen
#include "splat_internal.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

// ---- codecs (what the GPU decodes; docs/rsf.md "Record") ----

static double sign_not_zero(double v) { return v < 0 ? -1.0 : 1.0; }
static float sign_not_zero_f(float v) { return v < 0 ? -1.0f : 1.0f; }

static int snorm16_of(uint32_t bits)
{
    int s = (int)(bits & 0xffffu);
    return s >= 32768 ? s - 65536 : s;
}

// Octahedral decode (Meyer et al. 2010; Cigolle et al. 2014, "A Survey of Efficient Representations for
// Independent Unit Vectors"): snorm16 as GL unpacks it, then unfold the lower hemisphere.
void rs_splat_decode_normal(uint32_t code, float n[3])
{
    // max(c / 32767, -1) as GL unpacks snorm16; a compare, not fmaxf (a libm call in the load loop).
    float u = (float)snorm16_of(code) / 32767.0f, v = (float)snorm16_of(code >> 16) / 32767.0f;
    u = u < -1.0f ? -1.0f : u;
    v = v < -1.0f ? -1.0f : v;
    float z = 1.0f - fabsf(u) - fabsf(v);
    if (z < 0.0f) {
        float fu = (1.0f - fabsf(v)) * sign_not_zero_f(u);
        float fv = (1.0f - fabsf(u)) * sign_not_zero_f(v);
        u = fu;
        v = fv;
    }
    float inv = 1.0f / sqrtf(u * u + v * v + z * z);
    n[0] = u * inv;
    n[1] = v * inv;
    n[2] = z * inv;
}

// The bent normal, the low 6 bits of each half of w[2] (RS_SPLAT_FLAG_BENT): the direction it turns
// away from the normal, along the normal's tangents (Duff et al. 2017's orthonormal basis, the same in
// splat_decode.glsl), at a radius that grows as (angle / 90 deg)^(2/3), each coordinate a snorm6 (+-31):
// exact where it is the normal (open skin keeps its normal's light to the bit), ~1.7 degree steps at a
// 5-degree bend, ~3 at 30, ~4 at 60.
static void tangents_of(const float n[3], float t1[3], float t2[3])
{
    float s = n[2] < 0.0f ? -1.0f : 1.0f, a = -1.0f / (s + n[2]), b = n[0] * n[1] * a;
    t1[0] = 1.0f + s * n[0] * n[0] * a, t1[1] = s * b, t1[2] = -s * n[0];
    t2[0] = b, t2[1] = s + n[1] * n[1] * a, t2[2] = -n[1];
}

static int snorm6_of(uint32_t bits)
{
    int s = (int)(bits & 63u);
    return s >= 32 ? s - 64 : s;
}

static void decode_bent(uint32_t w2, const float n[3], float out[3])
{
    float u = (float)snorm6_of(w2) / 31.0f, v = (float)snorm6_of(w2 >> 16) / 31.0f, rho = sqrtf(u * u + v * v);
    if (rho == 0.0f) {
        memcpy(out, n, sizeof(float) * 3);
        return;
    }
    float t1[3], t2[3];
    tangents_of(n, t1, t2);
    float r = fminf(rho, 1.0f), angle = r * sqrtf(r) * 1.5707963f, c = cosf(angle), s = sinf(angle) / rho, l = 0.0f;
    for (int k = 0; k < 3; k++) out[k] = c * n[k] + s * (u * t1[k] + v * t2[k]), l += out[k] * out[k];
    l = 1.0f / sqrtf(l);
    for (int k = 0; k < 3; k++) out[k] *= l;
}

static uint32_t encode_bent(const float b[3], const float n[3])
{
    float t1[3], t2[3];
    tangents_of(n, t1, t2);
    double x = (double)b[0] * t1[0] + (double)b[1] * t1[1] + (double)b[2] * t1[2];
    double y = (double)b[0] * t2[0] + (double)b[1] * t2[1] + (double)b[2] * t2[2];
    double c = (double)b[0] * n[0] + (double)b[1] * n[1] + (double)b[2] * n[2], t = sqrt(x * x + y * y);
    if (!(t > 0.0) || !isfinite(t) || !isfinite(c)) return 0;
    // Past the horizon (a splat never sees the sky only behind itself) it lies on the horizon.
    double angle = fmin(atan2(t, c), 1.5707963267948966), rho = pow(angle / 1.5707963267948966, 2.0 / 3.0);
    int qu = (int)lround(31.0 * rho * x / t), qv = (int)lround(31.0 * rho * y / t);
    return (uint32_t)(qu & 63) | (uint32_t)(qv & 63) << 16;
}

static uint32_t pack_snorm16x2(int u, int v) { return (uint32_t)(u & 0xffff) | (uint32_t)(v & 0xffff) << 16; }

// The unit direction (x, y, z) on the lattice of codes that are multiples of `step` (a power of two),
// within +-(32767 rounded down to it): of the four codes around the projected point, the one whose
// *decoded* normal is closest in angle (plain rounding can be ~2x worse near the fold edges).
static uint32_t encode_normal_on(double x, double y, double z, int step)
{
    double l1 = fabs(x) + fabs(y) + fabs(z);
    double u = x / l1, v = y / l1;
    if (z < 0.0) {
        double fu = (1.0 - fabs(v)) * sign_not_zero(u);
        double fv = (1.0 - fabs(u)) * sign_not_zero(v);
        u = fu;
        v = fv;
    }
    int lim = 32767 / step * step;
    int u0 = (int)floor(u * 32767.0 / step) * step, v0 = (int)floor(v * 32767.0 / step) * step;
    uint32_t best = 0;
    double best_dot = -2.0;
    for (int k = 0; k < 4; k++) {
        int cu = RS_CLAMP(u0 + (k & 1) * step, -lim, lim);
        int cv = RS_CLAMP(v0 + (k >> 1) * step, -lim, lim);
        uint32_t code = pack_snorm16x2(cu, cv);
        float d[3];
        rs_splat_decode_normal(code, d);
        // Renormalised in double: the float decode's length error (~1e-7) exceeds 1 - cos(error) (~1e-9).
        double dl = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
        double dot = (x * d[0] + y * d[1] + z * d[2]) / dl;
        if (dot > best_dot) {
            best_dot = dot;
            best = code;
        }
    }
    return best;
}

uint32_t rs_splat_encode_normal(const float n[3])
{
    double x = n[0], y = n[1], z = n[2];
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0) || !isfinite(len)) return pack_snorm16x2(0, 0);  // +z; callers validate first
    return encode_normal_on(x / len, y / len, z / len, 1);
}

// A normal as the 16-bit code decodes it, re-encoded on the coarser lattice of multiples of `step`.
static uint32_t encode_normal_lattice(const float n[3], int step)
{
    float d[3];
    rs_splat_decode_normal(rs_splat_encode_normal(n), d);
    return encode_normal_on(d[0], d[1], d[2], step);
}

void rs_splat_quantize_normals(rs_splat_cloud *c, int bits)
{
    assert(c && bits >= 8 && bits <= 16);
    // A bent normal keeps its bits, the normal its coarser lattice under them.
    bool bent = c->hdr.flags & RS_SPLAT_FLAG_BENT;
    if (bent) bits = RS_MIN(bits, 10);
    if (bits == 16) return;
    int step = 1 << (16 - bits);
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        uint32_t keep = c->packed[i].w[2] & ~rs_splat_normal_mask(c->hdr.flags);
        c->packed[i].w[2] = encode_normal_lattice(c->normal[i], step);
        rs_splat_decode_normal(c->packed[i].w[2], c->normal[i]);
        c->packed[i].w[2] |= keep;
    }
}

// r = radius_min * (radius_max / radius_min)^(q / 255)
static float decode_radius(const rs_splat_header *h, uint32_t q)
{
    double rmin = h->radius_min, rmax = h->radius_max;
    return (float)(rmin * pow(rmax / rmin, (double)q / 255.0));
}

void rs_splat_quantize_radii(rs_splat_cloud *c, int bits)
{
    assert(c && bits >= 4 && bits <= 8);
    if (bits == 8) return;
    uint32_t step = 1u << (8 - bits), top = 255u / step * step;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        uint32_t w = c->packed[i].w[1], q = (w >> 16) & 0xffu;
        // Nearest multiple of step, in the log domain where the codes are even.
        q = RS_MIN((q + step / 2) / step * step, top);
        c->packed[i].w[1] = (w & 0xff00ffffu) | q << 16;
        c->radius[i] = decode_radius(&c->hdr, q);
    }
}

// Rounding in the log domain minimises the relative error: at most half a log step.
static uint32_t encode_radius(float r, const rs_splat_header *h)
{
    double t = 255.0 * log((double)r / h->radius_min) / log((double)h->radius_max / h->radius_min);
    return (uint32_t)lround(RS_CLAMP(t, 0.0, 255.0));
}

// pos = bbox_min + q * step, step = (bbox_max - bbox_min) / 65535, in float as the GPU computes it.
static float decode_unorm16(uint32_t q, float lo, float hi) { return lo + (float)q * ((hi - lo) / 65535.0f); }

// The nearest code, then its neighbours judged by the float decode, so that float rounding never
// pushes the error past half a step by more than the decode's own rounding.
static uint32_t encode_unorm16(float p, float lo, float hi)
{
    double t = ((double)p - lo) / ((double)hi - lo) * 65535.0;
    uint32_t q0 = (uint32_t)lround(RS_CLAMP(t, 0.0, 65535.0)), best = q0;
    double best_err = fabs((double)decode_unorm16(q0, lo, hi) - p);
    for (uint32_t q = q0 > 0 ? q0 - 1 : 0; q <= RS_MIN(q0 + 1, 65535u); q++) {
        double e = fabs((double)decode_unorm16(q, lo, hi) - p);
        if (e < best_err) best = q, best_err = e;
    }
    return best;
}

static rs_splat_packed encode_splat(const rs_splat *s, float radius, const rs_splat_header *h)
{
    uint32_t q[3];
    for (int a = 0; a < 3; a++) q[a] = encode_unorm16(s->pos[a], h->bbox_min[a], h->bbox_max[a]);
    rs_splat_packed p;
    p.w[0] = q[0] | q[1] << 16;
    p.w[1] = q[2] | encode_radius(radius, h) << 16 | (uint32_t)s->region << 24;
    p.w[2] = rs_splat_encode_normal(s->normal);
    p.w[3] = (uint32_t)s->rgb[0] | (uint32_t)s->rgb[1] << 8 | (uint32_t)s->rgb[2] << 16;
    return p;
}

static double dot3(const float a[3], const float b[3])
{
    return (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
}

// ---- header checks (shared with the loader) ----

typedef struct check_ctx {
    const char *name;
    bool in_file;
    rs_error *err;
} check_ctx;

__attribute__((format(printf, 3, 4)))
static rs_result bad(const check_ctx *x, size_t off, const char *fmt, ...)
{
    char what[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    if (x->in_file) return rs_fail(x->err, RS_ERR_FORMAT, "%s: %s (byte %zu)", x->name, what, off);
    return rs_fail(x->err, RS_ERR_ARG, "%s: %s", x->name, what);
}

static rs_result check_bbox(const check_ctx *x, const rs_splat_header *h)
{
    for (int a = 0; a < 3; a++) {
        float lo = h->bbox_min[a], hi = h->bbox_max[a];
        size_t off_lo = RSF_OFF_BBOX_MIN + 4 * (size_t)a, off_hi = RSF_OFF_BBOX_MAX + 4 * (size_t)a;
        if (!isfinite(lo)) return bad(x, off_lo, "bbox_min[%d]: %g is not finite", a, lo);
        if (!isfinite(hi)) return bad(x, off_hi, "bbox_max[%d]: %g is not finite", a, hi);
        if (!(hi > lo)) return bad(x, off_hi, "bbox_max[%d]: %g is not above bbox_min[%d] = %g", a, hi, a, lo);
        if (!isfinite(hi - lo)) return bad(x, off_hi, "bbox_max[%d]: extent %g..%g overflows a float", a, lo, hi);
    }
    return RS_OK;
}

// The bbox's largest extent (check_bbox has made sure it is finite and positive).
static double bbox_extent(const rs_splat_header *h)
{
    double e = 0;
    for (int a = 0; a < 3; a++) e = fmax(e, (double)h->bbox_max[a] - h->bbox_min[a]);
    return e;
}

static rs_result check_radius(const check_ctx *x, const rs_splat_header *h)
{
    float lo = h->radius_min, hi = h->radius_max;
    if (!isfinite(lo) || !(lo > 0.0f))
        return bad(x, RSF_OFF_RADIUS_MIN, "radius_min: %g, must be finite and > 0", lo);
    if (!isfinite(hi) || !(hi > lo))
        return bad(x, RSF_OFF_RADIUS_MAX, "radius_max: %g, must be finite and above radius_min %g", hi, lo);
    // Slack for the float rounding of radius_min = radius_max / ratio in rs_splat_create.
    if ((double)hi > (double)lo * RS_SPLAT_RADIUS_RATIO_MAX * (1.0 + 1e-5))
        return bad(x, RSF_OFF_RADIUS_MAX, "radius_max: %g is more than %g times radius_min %g", hi,
                   RS_SPLAT_RADIUS_RATIO_MAX, lo);
    double e = bbox_extent(h);
    if ((double)hi > RS_SPLAT_RADIUS_EXTENT_MAX * e * (1.0 + 1e-5))
        return bad(x, RSF_OFF_RADIUS_MAX, "radius_max: %g is more than %g times the bounding box (%g)", hi,
                   RS_SPLAT_RADIUS_EXTENT_MAX, e);
    return RS_OK;
}

static rs_result check_vec(const check_ctx *x, size_t off, const char *field, const float v[3], bool unit)
{
    for (int a = 0; a < 3; a++)
        if (!isfinite(v[a])) return bad(x, off + 4 * (size_t)a, "%s[%d]: %g is not finite", field, a, v[a]);
    double len = sqrt(dot3(v, v));
    if (unit && fabs(len - 1.0) > 1e-3) return bad(x, off, "%s: length %g, must be a unit vector", field, len);
    return RS_OK;
}

static rs_result check_frame(const check_ctx *x, const rs_splat_header *h)
{
    if (!isfinite(h->mm_per_unit) || !(h->mm_per_unit > 0.0f))
        return bad(x, RSF_OFF_MM_PER_UNIT, "mm_per_unit: %g, must be finite and > 0", h->mm_per_unit);
    rs_result r;
    if ((r = check_vec(x, RSF_OFF_CENTRE, "centre", h->centre, false)) != RS_OK) return r;
    if ((r = check_vec(x, RSF_OFF_FORWARD, "forward", h->forward, true)) != RS_OK) return r;
    if ((r = check_vec(x, RSF_OFF_UP, "up", h->up, true)) != RS_OK) return r;
    double d = dot3(h->up, h->forward);
    if (fabs(d) > 1e-3) return bad(x, RSF_OFF_UP, "up: not perpendicular to forward (dot %g)", d);
    if (!isfinite(h->face_height) || !(h->face_height > 0.0f))
        return bad(x, RSF_OFF_FACE_HEIGHT, "face_height: %g, must be finite and > 0", h->face_height);
    // Finite is not enough: the camera frames the face from these, and a centre of 3e38 or a face 1e-30
    // units tall rendered blank. Both are judged against the box's largest extent (splat_internal.h).
    double e = bbox_extent(h), far = RS_SPLAT_FACE_EXTENT_MAX * e;
    for (int a = 0; a < 3; a++)
        if (!((double)h->centre[a] >= h->bbox_min[a] - far && (double)h->centre[a] <= h->bbox_max[a] + far))
            return bad(x, RSF_OFF_CENTRE + 4 * (size_t)a, "centre[%d]: %g lies far outside the bounding box %g..%g", a,
                       h->centre[a], h->bbox_min[a], h->bbox_max[a]);
    if ((double)h->face_height < RS_SPLAT_FACE_EXTENT_MIN * e || (double)h->face_height > RS_SPLAT_FACE_EXTENT_MAX * e)
        return bad(x, RSF_OFF_FACE_HEIGHT, "face_height: %g is implausible for a scan %g units across (allowed %g..%g)",
                   h->face_height, e, RS_SPLAT_FACE_EXTENT_MIN * e, RS_SPLAT_FACE_EXTENT_MAX * e);
    return RS_OK;
}

static rs_result check_lods(const check_ctx *x, const rs_splat_header *h)
{
    if (h->lod_count < 1 || h->lod_count > RS_SPLAT_MAX_LODS)
        return bad(x, RSF_OFF_LOD_COUNT, "lod_count: %u, must be 1..%d", h->lod_count, RS_SPLAT_MAX_LODS);
    if (h->lods[0] != h->count)
        return bad(x, RSF_OFF_LODS, "lods[0]: %u, must equal count %u", h->lods[0], h->count);
    for (uint32_t k = 1; k < RS_SPLAT_MAX_LODS; k++) {
        size_t off = RSF_OFF_LODS + 4 * (size_t)k;
        if (k >= h->lod_count) {
            if (x->in_file && h->lods[k] != 0)
                return bad(x, off, "lods[%u]: %u in an unused slot, must be 0", k, h->lods[k]);
            continue;
        }
        if (h->lods[k] == 0) return bad(x, off, "lods[%u]: 0, a level must hold splats", k);
        if (h->lods[k] >= h->lods[k - 1])
            return bad(x, off, "lods[%u]: %u is not below lods[%u] = %u (levels must descend)", k, h->lods[k],
                       k - 1, h->lods[k - 1]);
    }
    return RS_OK;
}

static rs_result check_region(const check_ctx *x, const rs_region_info *ri, uint32_t k)
{
    size_t off = RSF_OFF_REGIONS + (size_t)k * RSF_REGION_SIZE;
    const char *end = memchr(ri->name, 0, sizeof ri->name);
    if (!end) return bad(x, off, "regions[%u].name: not NUL-terminated within 16 bytes", k);
    size_t len = (size_t)(end - ri->name);
    if (len == 0) return bad(x, off, "regions[%u].name: empty", k);
    for (size_t j = 0; j < sizeof ri->name; j++) {
        unsigned char ch = (unsigned char)ri->name[j];
        if (j < len && (ch < 0x20 || ch > 0x7e))
            return bad(x, off + j, "regions[%u].name: byte 0x%02x is not printable ASCII", k, ch);
        if (j > len && ch != 0 && x->in_file)
            return bad(x, off + j, "regions[%u].name: bytes after the NUL must be 0", k);
    }
    if (!isfinite(ri->m) || !(ri->m > 0.0f))
        return bad(x, off + 16, "regions[%u].m: %g, Beckmann roughness must be finite and > 0", k, ri->m);
    if (!isfinite(ri->rho_s) || !(ri->rho_s >= 0.0f))
        return bad(x, off + 20, "regions[%u].rho_s: %g, must be finite and >= 0", k, ri->rho_s);
    return RS_OK;
}

static rs_result check_regions(const check_ctx *x, const rs_splat_header *h)
{
    if (h->region_count < RS_REGION_BUILTIN_COUNT || h->region_count > RS_SPLAT_MAX_REGIONS)
        return bad(x, RSF_OFF_REGION_COUNT, "region_count: %u, must be %d..%d (the built-in regions come first)",
                   h->region_count, RS_REGION_BUILTIN_COUNT, RS_SPLAT_MAX_REGIONS);
    static const rs_region_info zero;
    for (uint32_t k = 0; k < RS_SPLAT_MAX_REGIONS; k++) {
        if (k < h->region_count) {
            rs_result r = check_region(x, &h->regions[k], k);
            if (r != RS_OK) return r;
        } else if (x->in_file && memcmp(&h->regions[k], &zero, sizeof zero) != 0) {
            return bad(x, RSF_OFF_REGIONS + (size_t)k * RSF_REGION_SIZE, "regions[%u]: unused slot must be all 0", k);
        }
    }
    return RS_OK;
}

// Index of the first byte that is not part of well-formed UTF-8 (RFC 3629), or n.
static size_t utf8_bad_at(const unsigned char *s, size_t n)
{
    size_t i = 0;
    while (i < n) {
        unsigned c = s[i];
        size_t k;
        uint32_t cp, lo;
        if (c < 0x80) {
            i++;
            continue;
        } else if ((c & 0xe0) == 0xc0) {
            k = 1, cp = c & 0x1f, lo = 0x80;
        } else if ((c & 0xf0) == 0xe0) {
            k = 2, cp = c & 0x0f, lo = 0x800;
        } else if ((c & 0xf8) == 0xf0) {
            k = 3, cp = c & 0x07, lo = 0x10000;
        } else {
            return i;
        }
        if (k >= n - i) return i;
        for (size_t j = 1; j <= k; j++) {
            if ((s[i + j] & 0xc0) != 0x80) return i;
            cp = cp << 6 | (s[i + j] & 0x3fu);
        }
        // Overlong forms, UTF-16 surrogates and code points past U+10FFFF are not UTF-8.
        if (cp < lo || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return i;
        i += k + 1;
    }
    return n;
}

static rs_result check_notes(const check_ctx *x, const rs_splat_header *h)
{
    size_t len = strnlen(h->notes, RS_SPLAT_MAX_NOTES);
    if (len == RS_SPLAT_MAX_NOTES)
        return bad(x, RSF_OFF_NOTES_LEN, "notes: not NUL-terminated within %d bytes", RS_SPLAT_MAX_NOTES);
    size_t at = utf8_bad_at((const unsigned char *)h->notes, len);
    if (at != len) return bad(x, RSF_OFF_NOTES + at, "notes: invalid UTF-8 at notes byte %zu", at);
    return RS_OK;
}

rs_result rs_splat_check_header(const rs_splat_header *h, const char *name, bool in_file, rs_error *err)
{
    check_ctx x = {name, in_file, err};
    if (h->count == 0 || h->count > RS_SPLAT_MAX_COUNT)
        return bad(&x, RSF_OFF_COUNT, "count: %u splats, must be 1..%u", h->count, RS_SPLAT_MAX_COUNT);
    if (h->flags & ~(RS_SPLAT_FLAG_AO | RS_SPLAT_FLAG_BENT))
        return bad(&x, RSF_OFF_FLAGS, "flags: 0x%08x, unknown bits must be 0", h->flags);
    if ((h->flags & RS_SPLAT_FLAG_BENT) && !(h->flags & RS_SPLAT_FLAG_AO))
        return bad(&x, RSF_OFF_FLAGS, "flags: 0x%08x, bent normals without ambient occlusion", h->flags);
    rs_result r;
    if ((r = check_bbox(&x, h)) != RS_OK) return r;
    if ((r = check_radius(&x, h)) != RS_OK) return r;
    if ((r = check_frame(&x, h)) != RS_OK) return r;
    if ((r = check_lods(&x, h)) != RS_OK) return r;
    if ((r = check_regions(&x, h)) != RS_OK) return r;
    return check_notes(&x, h);
}

// ---- the cloud ----

rs_splat_cloud *rs_splat_alloc(uint32_t count)
{
    rs_splat_cloud *c = calloc(1, sizeof *c);
    if (!c) return NULL;
    c->packed = rs_alloc_array(count, sizeof *c->packed);
    c->pos = rs_alloc_array(count, sizeof *c->pos);
    c->normal = rs_alloc_array(count, sizeof *c->normal);
    c->radius = rs_alloc_array(count, sizeof *c->radius);
    if (!c->packed || !c->pos || !c->normal || !c->radius) {
        rs_splat_destroy(c);
        return NULL;
    }
    return c;
}

void rs_splat_destroy(rs_splat_cloud *c)
{
    if (!c) return;
    free(c->packed);
    free(c->pos);
    free(c->normal);
    free(c->radius);
    free(c);
}

rs_result rs_splat_decode_range(rs_splat_cloud *c, uint32_t first, uint32_t n, rs_splat_decode_state *st,
                                const rs_splat_where *where, rs_error *err)
{
    const rs_splat_header *h = &c->hdr;
    check_ctx x = {where->name, where->in_file, err};
    char chunk[32] = "";
    if (where->chunk >= 0) snprintf(chunk, sizeof chunk, "chunk %lld: ", (long long)where->chunk);
    if (!st->ready) {
        // decode_unorm16 with the step hoisted out of the loop (same float operations, same result).
        for (int a = 0; a < 3; a++) {
            st->lo[a] = h->bbox_min[a];
            st->step[a] = (h->bbox_max[a] - h->bbox_min[a]) / 65535.0f;
        }
        // 256 radii per file: a table keeps pow() out of the per-splat loop.
        for (uint32_t q = 0; q < 256; q++) st->radius_of[q] = decode_radius(h, q);
        st->ready = true;
    }
    const float *lo = st->lo, *step = st->step, *radius_of = st->radius_of;
    const uint32_t mask = rs_splat_normal_mask(h->flags);
    double area = 0;
    for (uint32_t i = first; i < first + n; i++) {
        const uint32_t *w = c->packed[i].w;
        uint32_t region = w[1] >> 24, flags = w[3] >> 24;
        size_t off = where->off + (size_t)(i - first) * where->stride;
        if (region >= h->region_count)
            return bad(&x, off + (where->stride ? 7 : 0), "%ssplat %u: region %u is not in the region table (%u regions)",
                       chunk, i, region, h->region_count);
        if (flags != 0 && !(h->flags & RS_SPLAT_FLAG_AO))
            return bad(&x, off + (where->stride ? 15 : 0), "%ssplat %u: byte 15 is 0x%02x but the header has no ambient "
                       "occlusion", chunk, i, flags);
        c->pos[i][0] = lo[0] + (float)(w[0] & 0xffffu) * step[0];
        c->pos[i][1] = lo[1] + (float)(w[0] >> 16) * step[1];
        c->pos[i][2] = lo[2] + (float)(w[1] & 0xffffu) * step[2];
        rs_splat_decode_normal(w[2] & mask, c->normal[i]);
        c->radius[i] = radius_of[(w[1] >> 16) & 0xffu];
        area += (double)c->radius[i] * c->radius[i];
        st->region_counts[region]++;
    }
    st->area += area;
    double extent = bbox_extent(h), total = st->area * 3.14159265358979;
    if (total > RS_SPLAT_AREA_MAX * extent * extent)
        return bad(&x, where->off, "%sradii: the splats cover %.3g times the bounding box's largest face (at most %g): "
                   "not a surface scan, and too costly to draw", chunk, total / (extent * extent), RS_SPLAT_AREA_MAX);
    return RS_OK;
}

rs_result rs_splat_decode_all(rs_splat_cloud *c, const char *name, bool in_file, size_t payload_off,
                              rs_error *err)
{
    rs_splat_decode_state st = {0};
    rs_splat_where where = {name, in_file, payload_off, RSF_RECORD_SIZE, -1};
    rs_result r = rs_splat_decode_range(c, 0, c->hdr.count, &st, &where, err);
    if (r == RS_OK) memcpy(c->region_counts, st.region_counts, sizeof st.region_counts);
    return r;
}

// Weyrich et al. 2006, Table 1 (METHOD.md): the midpoint of each measured range; "other" skin is the
// mean of the four measured regions.
void rs_splat_default_regions(rs_splat_header *hdr)
{
    static const rs_region_info builtin[RS_REGION_BUILTIN_COUNT] = {
        [RS_REGION_OTHER] = {"other", 0.265f, 0.2725f},
        [RS_REGION_CHEEK] = {"cheek", 0.275f, 0.235f},
        [RS_REGION_NOSE] = {"nose", 0.235f, 0.305f},
        [RS_REGION_FOREHEAD] = {"forehead", 0.265f, 0.265f},
        [RS_REGION_LIPS] = {"lips", 0.285f, 0.285f},
    };
    memset(hdr->regions, 0, sizeof hdr->regions);
    memcpy(hdr->regions, builtin, sizeof builtin);
    hdr->region_count = RS_REGION_BUILTIN_COUNT;
}

static bool normalize3(float v[3])
{
    double len = sqrt(dot3(v, v));
    if (!(len > 0.0) || !isfinite(len)) return false;
    for (int a = 0; a < 3; a++) v[a] = (float)(v[a] / len);
    return true;
}

// Copies the caller's header fields, applying the zero defaults and making the stored form canonical
// (unit orthogonal frame, zeroed unused slots and bytes after NULs).
static rs_result fill_header(rs_splat_header *h, const rs_splat_header *in, rs_error *err)
{
    static const char *who = "rs_splat_create";
    static const rs_splat_header none;
    if (!in) in = &none;
    memset(h, 0, sizeof *h);
    if (in->flags & RS_SPLAT_FLAG_BENT)
        return rs_fail(err, RS_ERR_ARG, "%s: flags: RS_SPLAT_FLAG_BENT comes with the bent normals (rs_splat_set_bent)",
                       who);
    if (in->flags & ~RS_SPLAT_FLAG_AO) return rs_fail(err, RS_ERR_ARG, "%s: flags: 0x%08x, unknown bits", who, in->flags);
    if (in->lod_count > RS_SPLAT_MAX_LODS)
        return rs_fail(err, RS_ERR_ARG, "%s: lod_count: %u, at most %d", who, in->lod_count, RS_SPLAT_MAX_LODS);
    // Checked here, before the splats' region ids are checked against it.
    uint32_t nr = in->region_count;
    if (nr != 0 && (nr < RS_REGION_BUILTIN_COUNT || nr > RS_SPLAT_MAX_REGIONS))
        return rs_fail(err, RS_ERR_ARG, "%s: region_count: %u, must be 0 (defaults) or %d..%d", who, nr,
                       RS_REGION_BUILTIN_COUNT, RS_SPLAT_MAX_REGIONS);
    size_t notes_len = strnlen(in->notes, RS_SPLAT_MAX_NOTES);
    if (notes_len == RS_SPLAT_MAX_NOTES)
        return rs_fail(err, RS_ERR_ARG, "%s: notes: not NUL-terminated within %d bytes", who, RS_SPLAT_MAX_NOTES);
    memcpy(h->notes, in->notes, notes_len);

    h->flags = in->flags;
    h->mm_per_unit = in->mm_per_unit != 0.0f ? in->mm_per_unit : 1.0f;
    h->face_height = in->face_height;
    memcpy(h->centre, in->centre, sizeof h->centre);
    static const float fwd0[3] = {0, 0, 1}, up0[3] = {0, 1, 0}, zero3[3] = {0, 0, 0};
    memcpy(h->forward, memcmp(in->forward, zero3, sizeof zero3) ? in->forward : fwd0, sizeof h->forward);
    memcpy(h->up, memcmp(in->up, zero3, sizeof zero3) ? in->up : up0, sizeof h->up);
    // Gram-Schmidt so readers get an orthonormal frame; non-finite input is left for the checks to name.
    if (normalize3(h->forward)) {
        double d = dot3(h->up, h->forward);
        float up[3];
        for (int a = 0; a < 3; a++) up[a] = (float)(h->up[a] - d * h->forward[a]);
        // What is left of `up` after removing its forward part: nothing means the two were parallel.
        if (isfinite(d) && !(dot3(up, up) > 1e-12 * dot3(h->up, h->up)))
            return rs_fail(err, RS_ERR_ARG, "%s: up: parallel to forward", who);
        if (normalize3(up)) memcpy(h->up, up, sizeof up);
    }

    h->lod_count = in->lod_count;
    memcpy(h->lods, in->lods, in->lod_count * sizeof in->lods[0]);
    if (in->region_count == 0) {
        rs_splat_default_regions(h);
    } else {
        h->region_count = in->region_count;
        for (uint32_t k = 0; k < in->region_count; k++) {
            memcpy(h->regions[k].name, in->regions[k].name, strnlen(in->regions[k].name, 16));
            h->regions[k].m = in->regions[k].m;
            h->regions[k].rho_s = in->regions[k].rho_s;
        }
    }
    return RS_OK;
}

// Validates every splat and derives the quantisation frame: the bbox (degenerate axes padded so that
// max > min) and the radius range (radii at or below radius_max / 1e6, zero and negative included,
// are raised to the smallest radius kept; see docs/rsf.md).
static rs_result scan_splats(const rs_splat *s, uint32_t count, rs_splat_header *h, rs_error *err)
{
    static const char *who = "rs_splat_create";
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    float rmax = 0.0f;
    for (uint32_t i = 0; i < count; i++) {
        const rs_splat *p = &s[i];
        for (int a = 0; a < 3; a++) {
            if (!isfinite(p->pos[a]))
                return rs_fail(err, RS_ERR_FORMAT, "%s: splat %u: position[%d] %g is not finite", who, i, a, p->pos[a]);
            if (!isfinite(p->normal[a]))
                return rs_fail(err, RS_ERR_FORMAT, "%s: splat %u: normal[%d] %g is not finite", who, i, a,
                               p->normal[a]);
            lo[a] = fminf(lo[a], p->pos[a]);
            hi[a] = fmaxf(hi[a], p->pos[a]);
        }
        if (p->normal[0] == 0.0f && p->normal[1] == 0.0f && p->normal[2] == 0.0f)
            return rs_fail(err, RS_ERR_FORMAT, "%s: splat %u: normal is zero", who, i);
        if (!isfinite(p->radius))
            return rs_fail(err, RS_ERR_FORMAT, "%s: splat %u: radius %g is not finite", who, i, p->radius);
        if (p->region >= h->region_count)
            return rs_fail(err, RS_ERR_FORMAT, "%s: splat %u: region %u is not in the region table (%u regions)",
                           who, i, p->region, h->region_count);
        rmax = fmaxf(rmax, p->radius);
    }
    if (!(rmax > 0.0f)) return rs_fail(err, RS_ERR_FORMAT, "%s: radius: no splat has a radius > 0", who);

    float floor_r = (float)(rmax / RS_SPLAT_RADIUS_RATIO_MAX), rmin = rmax;
    for (uint32_t i = 0; i < count; i++)
        if (s[i].radius > floor_r) rmin = fminf(rmin, s[i].radius);
    if (rmin == rmax) {
        // One radius for all: any wider range decodes q = 0 exactly to radius_min.
        if (isfinite(rmax * 2.0f)) rmax *= 2.0f;
        else rmin *= 0.5f;
    }
    h->radius_min = rmin;
    h->radius_max = rmax;

    float extent = 0.0f;
    for (int a = 0; a < 3; a++) extent = fmaxf(extent, hi[a] - lo[a]);
    for (int a = 0; a < 3; a++) {
        // A flat or single-point cloud: the pad is arbitrary but must survive float rounding at |lo|.
        if (!(hi[a] > lo[a])) {
            // At least the disk's radius, so the box holds the splats (and radius_max fits the bound below).
            float pad = fmaxf(0.5e-3f * fmaxf(fmaxf(extent, fabsf(lo[a])), 1.0f), rmax);
            lo[a] -= pad;
            hi[a] += pad;
        }
        if (!isfinite(hi[a] - lo[a]))
            return rs_fail(err, RS_ERR_LIMIT, "%s: positions along axis %d span %g..%g, more than a float holds",
                           who, a, lo[a], hi[a]);
        h->bbox_min[a] = lo[a];
        h->bbox_max[a] = hi[a];
    }
    // Radii beyond the work bound (RS_SPLAT_RADIUS_EXTENT_MAX) are no surface samples: clamp them.
    double cap = RS_SPLAT_RADIUS_EXTENT_MAX * bbox_extent(h);
    if (h->radius_max > cap) {
        h->radius_max = (float)(0.5 * cap);
        h->radius_min = fminf(h->radius_min, (float)(0.5 * cap / 2.0));
    }
    return RS_OK;
}

rs_result rs_splat_create(const rs_splat *splats, uint32_t count, const rs_splat_header *hdr,
                          rs_splat_cloud **out, rs_error *err)
{
    assert(out && (splats || count == 0));
    static const char *who = "rs_splat_create";
    if (count == 0) return rs_fail(err, RS_ERR_ARG, "%s: count: no splats", who);
    if (count > RS_SPLAT_MAX_COUNT)
        return rs_fail(err, RS_ERR_LIMIT, "%s: count: %u splats, more than the %u allowed", who, count,
                       RS_SPLAT_MAX_COUNT);
    rs_splat_header *h = malloc(sizeof *h);
    if (!h) return rs_fail(err, RS_ERR_NOMEM, "%s: out of memory", who);
    rs_result r = fill_header(h, hdr, err);
    if (r == RS_OK) r = scan_splats(splats, count, h, err);
    if (r != RS_OK) {
        free(h);
        return r;
    }
    h->count = count;
    if (h->lod_count == 0) {
        h->lod_count = 1;
        h->lods[0] = count;
    }
    if (h->face_height == 0.0f) {
        // Extent of the bbox along `up`.
        for (int a = 0; a < 3; a++) h->face_height += fabsf(h->up[a]) * (h->bbox_max[a] - h->bbox_min[a]);
    }
    r = rs_splat_check_header(h, who, false, err);
    rs_splat_cloud *c = r == RS_OK ? rs_splat_alloc(count) : NULL;
    if (r == RS_OK && !c) r = rs_fail(err, RS_ERR_NOMEM, "%s: out of memory for %u splats", who, count);
    if (r != RS_OK) {
        free(h);
        return r;
    }
    c->hdr = *h;
    free(h);
    for (uint32_t i = 0; i < count; i++) {
        float radius = fmaxf(splats[i].radius, c->hdr.radius_min);
        c->packed[i] = encode_splat(&splats[i], radius, &c->hdr);
    }
    r = rs_splat_decode_all(c, who, false, 0, err);
    if (r != RS_OK) {
        rs_splat_destroy(c);
        return r;
    }
    *out = c;
    return RS_OK;
}

// ---- queries ----

void rs_splat_get(const rs_splat_cloud *c, uint32_t i, rs_splat *out)
{
    assert(c && out && i < c->hdr.count);
    const uint32_t *w = c->packed[i].w;
    const rs_splat_header *h = &c->hdr;
    uint32_t q[3] = {w[0] & 0xffffu, w[0] >> 16, w[1] & 0xffffu};
    for (int a = 0; a < 3; a++) out->pos[a] = decode_unorm16(q[a], h->bbox_min[a], h->bbox_max[a]);
    rs_splat_decode_normal(w[2] & rs_splat_normal_mask(h->flags), out->normal);
    out->radius = decode_radius(h, (w[1] >> 16) & 0xffu);
    out->rgb[0] = (uint8_t)(w[3] & 0xffu);
    out->rgb[1] = (uint8_t)((w[3] >> 8) & 0xffu);
    out->rgb[2] = (uint8_t)((w[3] >> 16) & 0xffu);
    out->region = (uint8_t)(w[1] >> 24);
}

void rs_splat_set_ao(rs_splat_cloud *c, const uint8_t *ao)
{
    for (uint32_t i = 0; i < c->hdr.count; i++)
        c->packed[i].w[3] = (c->packed[i].w[3] & 0x00ffffffu) | (ao ? (uint32_t)ao[i] << 24 : 0u);
    if (ao) c->hdr.flags |= RS_SPLAT_FLAG_AO;
    else c->hdr.flags &= ~RS_SPLAT_FLAG_AO, rs_splat_set_bent(c, NULL, NULL);  // a cone needs its opening
}

float rs_splat_ao(const rs_splat_cloud *c, uint32_t i)
{
    return (c->hdr.flags & RS_SPLAT_FLAG_AO) ? (float)(c->packed[i].w[3] >> 24) / 255.0f : 1.0f;
}

rs_result rs_splat_set_bent(rs_splat_cloud *c, const float (*bent)[3], rs_error *err)
{
    if (!bent) {
        if (c->hdr.flags & RS_SPLAT_FLAG_BENT)
            for (uint32_t i = 0; i < c->hdr.count; i++) c->packed[i].w[2] &= rs_splat_normal_mask(c->hdr.flags);
        c->hdr.flags &= ~RS_SPLAT_FLAG_BENT;
        return RS_OK;
    }
    if (!(c->hdr.flags & RS_SPLAT_FLAG_AO))
        return rs_fail(err, RS_ERR_ARG, "bent normals: the cloud has no ambient occlusion (rs_splat_set_ao first)");
    if (!(c->hdr.flags & RS_SPLAT_FLAG_BENT)) rs_splat_quantize_normals(c, 10);
    const uint32_t mask = rs_splat_normal_mask(RS_SPLAT_FLAG_BENT);
    for (uint32_t i = 0; i < c->hdr.count; i++)
        c->packed[i].w[2] = (c->packed[i].w[2] & mask) | encode_bent(bent[i], c->normal[i]);
    c->hdr.flags |= RS_SPLAT_FLAG_BENT;
    return RS_OK;
}

void rs_splat_bent(const rs_splat_cloud *c, uint32_t i, float out[3])
{
    if (c->hdr.flags & RS_SPLAT_FLAG_BENT) decode_bent(c->packed[i].w[2], c->normal[i], out);
    else memcpy(out, c->normal[i], sizeof(float) * 3);
}

uint32_t rs_splat_lod_count(const rs_splat_cloud *c, uint32_t max_count)
{
    const rs_splat_header *h = &c->hdr;
    assert(h->lod_count >= 1);
    // Levels descend, so the first that fits is the largest.
    for (uint32_t k = 0; k < h->lod_count; k++)
        if (h->lods[k] <= max_count) return h->lods[k];
    return h->lods[h->lod_count - 1];
}

// A prefix of n splats covers the surface with count/n fewer disks; area per disk grows by that factor.
float rs_splat_lod_radius_scale(const rs_splat_cloud *c, uint32_t n)
{
    uint32_t count = c->hdr.count;
    n = RS_CLAMP(n, 1u, count);
    return (float)sqrt((double)count / n);
}
