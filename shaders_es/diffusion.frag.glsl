#version 300 es
// diffusion.frag.glsl — stage 4: the splat's kernel evaluated at the visible surface point of this pixel,
// by 3D distance (so light does not cross to the far side of the head), accumulated as (E w, w); the
// resolve pass divides (a normalised convolution: energy preserving, independent of sampling density).
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"

uniform vec2 u_acc_scale;   // (E scale, weight scale): 1 with float targets; keeps RGBA8 sums below 1

flat in vec3 v_c;
flat in vec3 v_e;
flat in float v_k;
flat in float v_a;
flat in float v_cut2;

out vec4 o_acc;

void main()
{
    vec3 p;
    if (!rs_visible_point(p)) discard;
    vec3 dv = p - v_c;
    float d2 = dot(dv, dv);
    if (d2 > v_cut2) discard;
    float w = v_a * exp(-d2 * v_k) * u_acc_scale.y;
    o_acc = vec4(v_e * (w * u_acc_scale.x), w);
}
