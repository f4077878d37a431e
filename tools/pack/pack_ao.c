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
#define PI_F 3.14159265358979f

// Splats are drawn into the depth maps as discs of their radius (at least one texel), keeping the depth
// nearest to the sky. A splat is open towards d when its own depth is within `bias` of the map's: two
// radii (neighbouring discs on a curved surface stand a little proud of each other) plus a texel scaled
// by the slope towards d.
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
        // Fibonacci sphere: evenly spread directions.
        float z = 1.0f - (2.0f * (float)k + 1.0f) / RS_PACK_AO_DIRS, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
        float phi = 2.39996323f * (float)k;
        float d[3] = {r * cosf(phi), r * sinf(phi), z};
        // An orthonormal basis (u, v) across d.
        float t[3] = {fabsf(d[0]) < 0.9f ? 1.0f : 0.0f, fabsf(d[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
        float u[3] = {d[1] * t[2] - d[2] * t[1], d[2] * t[0] - d[0] * t[2], d[0] * t[1] - d[1] * t[0]};
        float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
        for (int a = 0; a < 3; a++) u[a] /= ul;
        float v[3] = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
        for (int i = 0; i < AO_MAP * AO_MAP; i++) depth[i] = -INFINITY;
        for (uint32_t i = 0; i < n; i++) {
            float p[3] = {(float)(s[i].pos[0] - c[0]), (float)(s[i].pos[1] - c[1]), (float)(s[i].pos[2] - c[2])};
            float x = (p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + R) / texel;
            float y = (p[0] * v[0] + p[1] * v[1] + p[2] * v[2] + R) / texel;
            float h = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
            float rr = fmaxf(s[i].radius / texel, 0.71f);
            int x0 = (int)floorf(x - rr), x1 = (int)floorf(x + rr), y0 = (int)floorf(y - rr), y1 = (int)floorf(y + rr);
            for (int yy = RS_MAX(y0, 0); yy <= RS_MIN(y1, AO_MAP - 1); yy++)
                for (int xx = RS_MAX(x0, 0); xx <= RS_MIN(x1, AO_MAP - 1); xx++) {
                    float dx = (float)xx + 0.5f - x, dy = (float)yy + 0.5f - y;
                    if (dx * dx + dy * dy > rr * rr) continue;
                    float *o = &depth[yy * AO_MAP + xx];
                    if (h > *o) *o = h;
                }
        }
        for (uint32_t i = 0; i < n; i++) {
            float nd = s[i].normal[0] * d[0] + s[i].normal[1] * d[1] + s[i].normal[2] * d[2];
            if (nd <= 0.0f) continue;
            float p[3] = {(float)(s[i].pos[0] - c[0]), (float)(s[i].pos[1] - c[1]), (float)(s[i].pos[2] - c[2])};
            int x = (int)floorf((p[0] * u[0] + p[1] * u[1] + p[2] * u[2] + R) / texel);
            int y = (int)floorf((p[0] * v[0] + p[1] * v[1] + p[2] * v[2] + R) / texel);
            float h = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
            x = RS_CLAMP(x, 0, AO_MAP - 1), y = RS_CLAMP(y, 0, AO_MAP - 1);
            // Slope-scaled, as for any depth map: seen at a grazing angle a texel spans depth.
            float slope = fminf(sqrtf(fmaxf(1.0f - nd * nd, 0.0f)) / nd, 10.0f);
            float bias = 2.0f * s[i].radius + texel * (1.0f + slope);
            total[i] += nd;
            if (h >= depth[y * AO_MAP + x] - bias) open[i] += nd;
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
