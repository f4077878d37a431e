// splat_decode.glsl — the 16-byte splat record (src/splat/splat.h, docs/rsf.md) decoded exactly as
// rs_splat_get does on the CPU, so picking, brushes and pixels agree.
#include "tangent_basis.glsl"

uniform vec3 u_bbox_min;      // quantization frame, model units
uniform vec3 u_bbox_step;     // (bbox_max - bbox_min) / 65535
uniform vec2 u_radius_log;    // radius = u_radius_log.x * exp(u_radius_log.y * q), q = 0..255
uniform float u_has_ao;       // 1: byte 15 of the record is the splat's ambient occlusion (RS_SPLAT_FLAG_AO)
#ifndef RS_HAS_BENT_DECLARED  // env_light.glsl declares it too
#define RS_HAS_BENT_DECLARED
uniform float u_has_bent;     // 1: the low 6 bits of each half of w.z are the bent normal (RS_SPLAT_FLAG_BENT)
#endif

struct rs_splat {
    vec3 pos;       // model units
    vec3 normal;    // unit, outward
    float radius;   // model units (before the LOD scale)
    vec3 albedo;    // linear RGB
    uint region;
    float ao;       // ambient occlusion, 1 = open sky (1 when the file has none)
};

float rs_snorm16(uint bits)
{
    float s = float(bits & 0xffffu);
    return max((s >= 32768.0 ? s - 65536.0 : s) / 32767.0, -1.0);
}

// Octahedral decode (Cigolle et al. 2014), the mirror of rs_splat_decode_normal.
vec3 rs_decode_normal(uint code)
{
    vec2 e = vec2(rs_snorm16(code), rs_snorm16(code >> 16));
    float z = 1.0 - abs(e.x) - abs(e.y);
    if (z < 0.0) {
        vec2 s = vec2(e.x < 0.0 ? -1.0 : 1.0, e.y < 0.0 ? -1.0 : 1.0);
        e = (1.0 - abs(e.yx)) * s;
    }
    return normalize(vec3(e, z));
}

// The bent normal of record w whose normal is n, unit, the axis of the sky it sees (n when the file has
// none): a turn away from n along its tangents (rs_splat_bent, splat.c: Duff et al. 2017's basis), by
// 90 deg x rho^1.5 for the snorm6 pair's length rho. Apart from rs_decode_splat: only environment light
// needs it.
vec3 rs_decode_bent(uvec4 w, vec3 n)
{
    if (u_has_bent < 0.5) return n;
    uint code = w.z;
    ivec2 q = ivec2(int(code & 63u), int((code >> 16) & 63u));
    q -= 64 * ivec2(greaterThanEqual(q, ivec2(32)));
    vec2 x = vec2(q) / 31.0;
    float rho = length(x);
    if (rho == 0.0) return n;
    vec3 t1, t2;
    rs_tangents(n, t1, t2);
    float r = min(rho, 1.0), angle = r * sqrt(r) * 1.5707963;
    return normalize(cos(angle) * n + (sin(angle) / rho) * (x.x * t1 + x.y * t2));
}

vec3 rs_srgb_to_linear(vec3 c)
{
    return mix(pow((c + 0.055) / 1.055, vec3(2.4)), c / 12.92, step(c, vec3(0.04045)));  // linear at and below
}

rs_splat rs_decode_splat(uvec4 w)
{
    rs_splat s;
    s.pos = u_bbox_min + vec3(float(w.x & 0xffffu), float(w.x >> 16), float(w.y & 0xffffu)) * u_bbox_step;
    s.radius = u_radius_log.x * exp(u_radius_log.y * float((w.y >> 16) & 0xffu));
    s.region = w.y >> 24;
    s.ao = u_has_ao > 0.5 ? float(w.w >> 24) / 255.0 : 1.0;
    s.normal = rs_decode_normal(u_has_bent > 0.5 ? w.z & 0xffc0ffc0u : w.z);
    s.albedo = rs_srgb_to_linear(vec3(float(w.w & 0xffu), float((w.w >> 8) & 0xffu),
                                      float((w.w >> 16) & 0xffu)) / 255.0);
    return s;
}
