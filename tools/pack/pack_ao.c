// pack_ao.c — per-splat ambient occlusion for environment lighting (issue 12): the cosine-weighted fraction
// of the sky each splat sees, so that eye sockets, nostrils, the inside of the ears and under the chin are
// not lit by the environment like the cheek. Computed from software orthographic depth maps of the cloud
// from RS_PACK_AO_DIRS directions spread over the sphere (a Fibonacci spiral): a splat sees direction d
// when nothing of the cloud lies in front of it seen from d. The renderer multiplies the environment's SH
// irradiance and its specular by it (byte 15 of the record, RS_SPLAT_FLAG_AO).
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define AO_MAP 512      // depth map side, texels, over the cloud's bounding sphere

// One direction's orthonormal frame: d towards the sky, (u, v) across it.
typedef struct ao_dir {
    float d[3], u[3], v[3];
} ao_dir;

static ao_dir fibonacci_dir(int k)
{
    // Fibonacci sphere: evenly spread directions.
    ao_dir o;
    float z = 1.0f - (2.0f * (float)k + 1.0f) / RS_PACK_AO_DIRS, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = 2.39996323f * (float)k;
    float *d = o.d, *u = o.u, *v = o.v;
    d[0] = r * cosf(phi), d[1] = r * sinf(phi), d[2] = z;
    float t[3] = {fabsf(d[0]) < 0.9f ? 1.0f : 0.0f, fabsf(d[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
    u[0] = d[1] * t[2] - d[2] * t[1], u[1] = d[2] * t[0] - d[0] * t[2], u[2] = d[0] * t[1] - d[1] * t[0];
    float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) u[a] /= ul;
    v[0] = d[1] * u[2] - d[2] * u[1], v[1] = d[2] * u[0] - d[0] * u[2], v[2] = d[0] * u[1] - d[1] * u[0];
    return o;
}

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Draws splat s (centre p relative to the cloud's centre) into the depth map seen from o.d, keeping the
// depth nearest to the sky: the disk as what it is from there, an ellipse (semi-axes r across its tilt,
// r |n.d| along it, at least ~a texel) at its plane's depth. A circle of radius r at the centre's depth
// would stand up to r tan(angle) above a tilted neighbour's centre and hide it from the sky: every open
// surface came out ~0.07 too dark, grainy with the normal map's tilts.
static void draw_disk(float *depth, const ao_dir *o, const float p[3], const rs_splat *s, float R, float texel)
{
    float x = (dot3(p, o->u) + R) / texel, y = (dot3(p, o->v) + R) / texel, h = dot3(p, o->d);
    float nu = dot3(s->normal, o->u), nv = dot3(s->normal, o->v), nd = dot3(s->normal, o->d);
    float r = s->radius / texel, tilt = sqrtf(nu * nu + nv * nv);
    // e: the tilt's direction in the map (the ellipse's minor axis); edge-on disks get a texel of width.
    float ex = tilt > 1e-6f ? nu / tilt : 1.0f, ey = tilt > 1e-6f ? nv / tilt : 0.0f;
    float rr = fmaxf(r, 0.71f), minor = fmaxf(r * fabsf(nd), 0.71f);
    // Depth along d per texel of map offset, on the disk's plane (bounded: the disk spans +-r in depth).
    float gx = fabsf(nd) > 1e-3f ? -nu / nd * texel : 0.0f, gy = fabsf(nd) > 1e-3f ? -nv / nd * texel : 0.0f;
    float reach = s->radius;
    // Clamped to the map before the conversion (a degenerate cloud can put a disk 1e20 texels away).
    const float lo = -1.0f, hi = (float)AO_MAP;
    int x0 = (int)floorf(RS_CLAMP(x - rr, lo, hi)), x1 = (int)floorf(RS_CLAMP(x + rr, lo, hi));
    int y0 = (int)floorf(RS_CLAMP(y - rr, lo, hi)), y1 = (int)floorf(RS_CLAMP(y + rr, lo, hi));
    for (int yy = RS_MAX(y0, 0); yy <= RS_MIN(y1, AO_MAP - 1); yy++)
        for (int xx = RS_MAX(x0, 0); xx <= RS_MIN(x1, AO_MAP - 1); xx++) {
            float dx = (float)xx + 0.5f - x, dy = (float)yy + 0.5f - y;
            float along = dx * ex + dy * ey, across = dy * ex - dx * ey;
            if (across * across / (rr * rr) + along * along / (minor * minor) > 1.0f) continue;
            float hh = h + RS_CLAMP(dx * gx + dy * gy, -reach, reach);
            float *z = &depth[yy * AO_MAP + xx];
            if (hh > *z) *z = hh;
        }
}

// A splat is open towards d when its own depth is within `bias` of the map's at its centre: a radius
// (neighbouring disks on a curved surface, or tilted by the normal map, stand a little proud of each
// other) plus a texel scaled by the slope towards d (the texel's centre is up to a texel from the splat's).
rs_result rs_pack_ao(const rs_splat *s, uint32_t n, uint8_t *ao, rs_error *err)
{
    if (n == 0) return RS_OK;
    double c[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) c[a] += s[i].pos[a];
    for (int a = 0; a < 3; a++) c[a] /= n;
    float R = 0.0f;
    for (uint32_t i = 0; i < n; i++) {
        float d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (float)((s[i].pos[a] - c[a]) * (s[i].pos[a] - c[a]));
        R = fmaxf(R, sqrtf(d2) + s[i].radius);
    }
    if (!(R > 0) || !isfinite(R)) R = 1.0f;
    float *depth = malloc(sizeof(float) * AO_MAP * AO_MAP);
    float *open = calloc(n, sizeof(float)), *total = calloc(n, sizeof(float));
    if (!depth || !open || !total) {
        free(depth), free(open), free(total);
        return rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    }
    float texel = 2.0f * R / AO_MAP;
    for (int k = 0; k < RS_PACK_AO_DIRS; k++) {
        ao_dir o = fibonacci_dir(k);
        for (int i = 0; i < AO_MAP * AO_MAP; i++) depth[i] = -INFINITY;
        for (uint32_t i = 0; i < n; i++) {
            float p[3] = {(float)(s[i].pos[0] - c[0]), (float)(s[i].pos[1] - c[1]), (float)(s[i].pos[2] - c[2])};
            draw_disk(depth, &o, p, &s[i], R, texel);
        }
        for (uint32_t i = 0; i < n; i++) {
            float nd = dot3(s[i].normal, o.d);
            if (nd <= 0.0f) continue;
            float p[3] = {(float)(s[i].pos[0] - c[0]), (float)(s[i].pos[1] - c[1]), (float)(s[i].pos[2] - c[2])};
            const float hi = (float)(AO_MAP - 1);
            int x = (int)floorf(RS_CLAMP((dot3(p, o.u) + R) / texel, 0.0f, hi));
            int y = (int)floorf(RS_CLAMP((dot3(p, o.v) + R) / texel, 0.0f, hi));
            float slope = fminf(sqrtf(fmaxf(1.0f - nd * nd, 0.0f)) / nd, 10.0f);
            float bias = s[i].radius + texel * (1.0f + slope);
            total[i] += nd;
            if (dot3(p, o.d) >= depth[y * AO_MAP + x] - bias) open[i] += nd;
        }
    }
    for (uint32_t i = 0; i < n; i++) {
        float a = total[i] > 0.0f ? open[i] / total[i] : 1.0f;
        ao[i] = (uint8_t)lrintf(RS_CLAMP(a, 0.0f, 1.0f) * 255.0f);
    }
    free(depth);
    free(open);
    free(total);
    return RS_OK;
}

rs_result rs_pack_ao_cloud(rs_splat_cloud *c, rs_error *err)
{
    uint32_t n = c->hdr.count;
    rs_splat *s = malloc(sizeof *s * (size_t)RS_MAX(n, 1u));
    uint8_t *ao = malloc(RS_MAX(n, 1u));
    rs_result r = s && ao ? RS_OK : rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    for (uint32_t i = 0; r == RS_OK && i < n; i++) rs_splat_get(c, i, &s[i]);
    if (r == RS_OK) r = rs_pack_ao(s, n, ao, err);
    if (r == RS_OK) rs_splat_set_ao(c, ao);
    free(s);
    free(ao);
    return r;
}
