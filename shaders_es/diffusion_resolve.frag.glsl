#version 300 es
// diffusion_resolve.frag.glsl — stage 4: normalises one level's accumulation and adds it, weighted by the
// profile's RGB weights for that Gaussian, into the diffuse target D = sum_i w_i D_i (additive blend).
precision highp float;

uniform highp sampler2D u_level;
uniform vec3 u_weight;       // this level's RGB weights in the profile
uniform float u_scale;       // undoes the fallback's E scale, applies the D target's scale
uniform float u_e_max;       // the largest E can be, in the level target's units (8-bit ratios overshoot)
uniform float u_min_weight;  // RGBA8 fallback: sums of a few 8-bit steps are unreliable

out vec4 o_diffuse;

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 a = texelFetch(u_level, px, 0);
    // Fallback only: a pixel reached by faint kernel tails alone borrows its neighbours' sums (the level
    // is smooth at this scale, and sums of sums normalise correctly).
    if (a.a < u_min_weight) {
        ivec2 hi = textureSize(u_level, 0) - 1;
        for (int i = 0; i < 9; i++)
            if (i != 4) a += texelFetch(u_level, clamp(px + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), hi), 0);
    }
    o_diffuse = a.a > 1e-12 ? vec4(u_weight * min(a.rgb / a.a, vec3(u_e_max)) * u_scale, 0.0) : vec4(0.0);
}
