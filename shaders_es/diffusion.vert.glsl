#version 300 es
// diffusion.vert.glsl — stage 4, splat-based diffusion (Kim et al. 2010): per splat, its irradiance (from
// the irradiance pass, irradiance.vert.glsl) and an isotropic 3D Gaussian kernel of one level of
// the skin profile, drawn as a sprite covering 3 sigma around the splat centre.
precision highp float;
precision highp int;
#include "splat_decode.glsl"
#include "splat_sprite.glsl"
#include "behind_surface.glsl"

layout(location = 0) in uvec4 a_splat;
layout(location = 2) in vec3 a_irradiance;  // E
uniform mat4 u_view;
uniform mat4 u_inv_proj;
uniform highp sampler2D u_depth;  // visibility depth
uniform highp sampler2D u_push;   // and its push (visibility_push.glsl)
uniform float u_eps;
uniform float u_radius_scale;   // LOD of this level: sqrt(N / n)
uniform float u_sigma;          // the level's Gaussian sigma, view units (sqrt(variance_mm2) / mm_per_unit)
uniform float u_px_size;        // size of a pixel at view distance 1, view units

flat out vec3 v_c;
flat out vec3 v_e;
flat out float v_k;      // 1 / (2 v)
flat out float v_a;      // area / (2 pi v): the splat's share of the kernel sum
flat out float v_cut2;   // (3 sigma)^2

void main()
{
    rs_splat s = rs_decode_splat(a_splat);
    vec3 c = (u_view * vec4(s.pos, 1.0)).xyz;
    float r = s.radius * u_radius_scale;
    // The kernel can't be narrower than the sample spacing (else it would show single splats as
    // speckles) nor than a pixel (else detail aliases): below that the level is a smooth interpolation.
    float sigma = max(u_sigma, 0.5 * max(r, -c.z * u_px_size));
    // Back-facing splats deep behind the visible surface (the back of the head) reach no visible pixel.
    if (dot(mat3(u_view) * s.normal, -c) < 0.0
        && rs_behind_visible(c, u_proj, u_inv_proj, u_depth, u_push, u_eps) > 3.0 * sigma) {
        rs_sprite_cull();
        return;
    }
    float v = sigma * sigma;
    v_c = c;
    v_e = a_irradiance;
    v_k = 0.5 / v;
    v_a = r * r / (6.2831853 * v);
    v_cut2 = 9.0 * v;
    rs_sprite(c, 3.0 * sigma);
}
