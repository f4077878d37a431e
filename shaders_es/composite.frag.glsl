#version 300 es
// composite.frag.glsl — stage 5: normalises the accumulated attributes (albedo A, normal N, m, rho_s),
// evaluates the specular S per pixel (Kelemen/Szirmay-Kalos, shadowed key light + unshadowed fill), reads
// the diffuse D of stage 4, and composes F = A (D + S) (paper eq. 1) or F = A D + S; then exposure and the
// sRGB encoding. Also the debug views (render.h rs_render_mode).
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"
#include "shadow_lookup.glsl"
#include "skin_brdf.glsl"

// Same numbering as rs_render_mode in render.h.
#define MODE_FULL 0
#define MODE_ALBEDO 1
#define MODE_DIFFUSE 2
#define MODE_SPECULAR 3
#define MODE_NORMALS 4
#define MODE_REGIONS 5
#define MODE_SHADOW 6
#define MODE_LOD 7
#define MODE_IRRADIANCE 8

uniform highp sampler2D u_attr0;
uniform highp sampler2D u_attr1;
uniform highp sampler2D u_attr2;
uniform highp sampler2D u_diffuse;
uniform int u_mode;
uniform int u_physical;         // 1: F = A D + S
uniform float u_exposure;
uniform float u_linear_output;  // 1: no sRGB encoding (tests of the composite's algebra)
uniform vec3 u_background;      // already in the output encoding
uniform float u_rho_s_scale;
uniform float u_diffuse_scale;  // undoes the D target's scale (RGBA8 fallback)
uniform vec3 u_delta_weight;    // profile weight of the Gaussians too narrow to draw: per-pixel irradiance
uniform vec3 u_key_dir;
uniform vec3 u_key_color;
uniform vec3 u_fill_dir;
uniform vec3 u_fill_color;
uniform vec3 u_ambient;
uniform float u_min_weight;     // accumulated weights below this are unreliable (RGBA8 fallback): a hole
uniform int u_lean;             // 1: two attribute targets, RT1 = (normal.xy, m, rho_s) w (no RT2)

out vec4 o_color;

vec3 linear_to_srgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, c * 12.92, step(c, vec3(0.0031308)));  // linear at and below
}

// Image-space hole filling: a pixel that no disk covered while at least 6 of its 8 neighbours are covered
// is a gap between splats (a sparse spot of a random sampling, a crease seen edge-on), not background.
// The attribute targets hold weighted sums, so adding the neighbours' sums and normalising once gives
// their weighted mean; the surface point and D are the neighbours' means.
bool fill_hole(ivec2 px, out vec4 t0, out vec4 t1, out vec4 t2, out vec3 p, out vec3 D)
{
    t0 = t1 = t2 = vec4(0.0);
    p = D = vec3(0.0);
    ivec2 hi = ivec2(u_viewport) - 1;
    // Quick reject (most background pixels): with 3 of the 4 edge neighbours uncovered, at most 5 of 8
    // can be covered.
    int open = 0;
    for (int i = 0; i < 4; i++) {
        ivec2 q = clamp(px + ivec2(i == 0 ? -1 : i == 1 ? 1 : 0, i == 2 ? -1 : i == 3 ? 1 : 0), ivec2(0), hi);
        if (texelFetch(u_attr0, q, 0).a <= u_min_weight) open++;
    }
    if (open >= 3) return false;
    int k = 0;
    for (int i = 0; i < 9; i++) {
        if (i == 4) continue;
        ivec2 q = clamp(px + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), hi);
        vec4 a = texelFetch(u_attr0, q, 0);
        vec3 pq;
        if (a.a <= u_min_weight || !rs_visible_point_at(q, pq)) continue;
        t0 += a;
        t1 += texelFetch(u_attr1, q, 0);
        t2 += texelFetch(u_attr2, q, 0);
        p += pq;
        D += texelFetch(u_diffuse, q, 0).rgb;
        k++;
    }
    p /= max(float(k), 1.0);
    D /= max(float(k), 1.0);
    return k >= 6;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 t0 = texelFetch(u_attr0, px, 0), t1, t2;
    vec3 p, D;
    if (t0.a > u_min_weight && rs_visible_point(p)) {
        t1 = texelFetch(u_attr1, px, 0);
        t2 = texelFetch(u_attr2, px, 0);
        D = texelFetch(u_diffuse, px, 0).rgb;
    } else if (!fill_hole(px, t0, t1, t2, p, D)) {
        o_color = vec4(u_background, 1.0);
        return;
    }
    float inv = 1.0 / t0.a;
    vec3 A = t0.rgb * inv;
    vec3 N, debug = vec3(0.0);
    float m, rho_s;
    if (u_lean == 1) {
        // The visible side faces the camera: z >= 0 (silhouette splats tilted a little away excepted).
        vec2 nxy = t1.xy * inv;
        N = vec3(nxy, sqrt(max(1.0 - dot(nxy, nxy), 0.0)));
        N = normalize(N);
        m = t1.z * inv;
        rho_s = t1.w * inv * u_rho_s_scale;
    } else {
        N = normalize(t1.xyz * inv * 2.0 - 1.0);
        m = t1.a * inv;
        rho_s = t2.r * inv * u_rho_s_scale;
        debug = t2.gba * inv;
    }
    vec3 V = normalize(-p);

    if (u_mode == MODE_NORMALS) { o_color = vec4(N * 0.5 + 0.5, 1.0); return; }
    if (u_mode == MODE_REGIONS || u_mode == MODE_LOD) { o_color = vec4(debug, 1.0); return; }
    float shadow = rs_shadow(p, N);
    if (u_mode == MODE_SHADOW) { o_color = vec4(vec3(shadow), 1.0); return; }

    vec3 c;
    if (u_mode == MODE_ALBEDO) {
        c = A;
    } else {
        vec3 S = u_key_color * (rs_ksk_specular(N, u_key_dir, V, m, rho_s) * shadow)
               + u_fill_color * rs_ksk_specular(N, u_fill_dir, V, m, rho_s);
        vec3 E = u_key_color * max(dot(N, u_key_dir), 0.0) * shadow + u_fill_color * max(dot(N, u_fill_dir), 0.0)
               + u_ambient;
        D = D * u_diffuse_scale + u_delta_weight * E;
        if (u_mode == MODE_DIFFUSE) c = A * D;
        else if (u_mode == MODE_SPECULAR) c = S;
        else if (u_mode == MODE_IRRADIANCE) c = E;
        else c = u_physical == 1 ? A * D + S : A * (D + S);
        c *= u_exposure;
    }
    o_color = vec4(u_linear_output > 0.5 ? clamp(c, 0.0, 1.0) : linear_to_srgb(c), 1.0);
}
