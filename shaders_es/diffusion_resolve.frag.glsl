#version 300 es
// diffusion_resolve.frag.glsl — stage 4: normalises one level's accumulation and adds it, weighted by the
// profile's RGB weights for that Gaussian, into the diffuse target D = sum_i w_i D_i (additive blend).
// A level drawn at reduced resolution (the mobile pipeline's wide kernels) is upsampled depth-aware: the
// 2x2 reduced samples around the pixel, bilinear weights times a Gaussian of the 3D distance between
// the pixel's visible surface point and each sample's, so that a sample on another surface (the cheek
// behind the nose's silhouette) does not bleed across. Sums (E w, w) are interpolated, not ratios: a
// weighted sum of sums still normalises correctly.
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"

uniform highp sampler2D u_level;
uniform vec3 u_weight;       // this level's RGB weights in the profile
uniform float u_scale;       // undoes the fallback's E scale, applies the D target's scale
uniform float u_e_max;       // the largest E can be, in the level target's units (8-bit ratios overshoot)
uniform float u_min_weight;  // RGBA8 fallback: sums of a few 8-bit steps are unreliable
uniform int u_res_div;       // the level target is 1/u_res_div of this target's size
uniform float u_inv_two_sb2; // 1 / (2 sigma_b^2): sigma_b, the 3D distance scale of the upsampling
uniform float u_smooth;      // 1 for the narrowest level: its irradiance's luminance goes to alpha

out vec4 o_diffuse;

// The reduced level's sums at full-resolution pixel px.
vec4 upsampled(ivec2 px)
{
    vec3 p;
    if (!rs_visible_point_at(px, p)) return vec4(0.0);
    ivec2 lsize = textureSize(u_level, 0);
    vec2 dsize = vec2(textureSize(u_depth, 0));
    // Reduced sample k sits at the centre of depth pixel floor((k + 0.5) / lsize * dsize) (the pixel its
    // kernel sum was evaluated at, diffusion.frag.glsl).
    vec2 u = (vec2(px) + 0.5) * vec2(lsize) / dsize - 0.5;
    vec2 k0 = floor(u), t = u - k0;
    vec4 sum = vec4(0.0), nearest = vec4(0.0);
    float best = -1.0;
    for (int i = 0; i < 4; i++) {
        vec2 o = vec2(float(i & 1), float(i >> 1));
        ivec2 k = clamp(ivec2(k0 + o), ivec2(0), lsize - 1);
        vec3 q;
        if (!rs_visible_point_at(ivec2((vec2(k) + 0.5) / vec2(lsize) * dsize), q)) continue;
        vec3 d = q - p;
        float g = exp(-dot(d, d) * u_inv_two_sb2);
        vec2 b = mix(1.0 - t, t, o);
        vec4 a = texelFetch(u_level, k, 0);
        sum += a * (b.x * b.y * g);
        if (g > best) best = g, nearest = a;
    }
    // No sample on this surface within reach (a feature thinner than the reduced pixels): the nearest.
    return sum.a > 1e-20 ? sum : nearest;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 a;
    if (u_res_div > 1) {
        a = upsampled(px);
    } else {
        a = texelFetch(u_level, px, 0);
        // Fallback only: a pixel reached by faint kernel tails alone borrows its neighbours' sums (the
        // level is smooth at this scale, and sums of sums normalise correctly).
        if (a.a < u_min_weight) {
            ivec2 hi = textureSize(u_level, 0) - 1;
            for (int i = 0; i < 9; i++)
                if (i != 4) a += texelFetch(u_level, clamp(px + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), hi), 0);
        }
    }
    // Alpha: the narrowest level's own irradiance (luminance), the local splat-averaged light that the
    // composite holds the per-pixel term to (composite.frag.glsl).
    vec3 e = min(a.rgb / max(a.a, 1e-30), vec3(u_e_max));
    o_diffuse = a.a > 1e-12 ? vec4(u_weight * e, u_smooth * dot(e, vec3(0.2126, 0.7152, 0.0722))) * u_scale : vec4(0.0);
}
