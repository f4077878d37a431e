#version 300 es
// attribute.frag.glsl — stage 3: the ray-disk hit's Gaussian weight w, and w-weighted attributes added
// (GL_ONE, GL_ONE) into three targets; the composite divides by the summed weight. Depth-tested (LEQUAL,
// no writes) against the visibility pass, so only the front surface layer accumulates.
//   RT0 = (albedo, 1) w      RT1 = (normal * 0.5 + 0.5, m) w
//   RT2 = (rho_s, ambient occlusion, clear coat, flakes) w, or (rho_s, debug colour) w in the debug views
//   RT3 = (u+, u-, v+, v-) w: the bent normal's components (u, v) along the normal's tangents
//         (tangent_basis.glsl), each split into its positive and negative part: the axis of the sky the
//         surface sees (env_light.glsl rs_env_sky). Always RGBA8 (half-float blending costs llvmpipe two
//         to four times as much), its weights RT0's times u_bent_scale (sums below 1); 0 where the bent
//         normal is the normal, so open skin's pixel gets exactly its normal back, and a pixel whose
//         weights are too small for 8 bits gets its normal too
// Normals are stored offset to 0..1 so the RGBA8 fallback needs no signed format; u_weight_scale keeps the
// fallback's sums below 1 (it cancels in the division) and u_weight_floor keeps a disk's rim from
// rounding to nothing where it alone covers a pixel (next to occluding edges).
precision highp float;
precision highp int;
#include "splat_ray.glsl"

uniform float u_coverage;  // disks are drawn out to this many radii (render_kit.h RS_COVERAGE)

uniform float u_inv_two_sigma2;   // 1 / (2 sigma^2), sigma in disk radii
uniform float u_weight_scale;
uniform float u_weight_floor;     // RGBA8 fallback: rims count enough to survive 8-bit rounding
uniform float u_bent_scale;       // RT3's weights relative to w

flat in vec3 v_c;
flat in vec3 v_n;
flat in float v_r;
flat in vec3 v_albedo;
flat in vec2 v_spec;
flat in vec3 v_debug;
flat in vec3 v_layers;
flat in vec2 v_bent;
uniform int u_debug;

layout(location = 0) out vec4 o_albedo;
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_extra;
layout(location = 3) out vec4 o_bent;

void main()
{
    vec3 o, d, q;
    float l;
    rs_pixel_ray(gl_FragCoord.xy, o, d);
    if (!rs_ray_disk(o, d, v_c, v_n, v_r, u_coverage, q, l)) discard;
    gl_FragDepth = rs_depth_of(q);
    float w = max(exp(-l * l * u_inv_two_sigma2), u_weight_floor) * u_weight_scale;
    o_albedo = vec4(v_albedo, 1.0) * w;
    o_normal = vec4(v_n * 0.5 + 0.5, v_spec.x) * w;
    o_extra = vec4(v_spec.y, u_debug != 0 ? v_debug : v_layers) * w;
    o_bent = vec4(max(v_bent, 0.0), max(-v_bent, 0.0)).xzyw * (w * u_bent_scale);
}
