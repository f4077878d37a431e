#version 300 es
// edges_find.frag.glsl — the depth steps inside the face, for the edges pass (edges.frag.glsl): per pixel,
// whether the surface steps back or forward to its right neighbour (R) and to the one above it (G):
// 0 no step, 0.5 the neighbour is deeper, 1 it is nearer. A step is a contour when it is deeper than
// u_step_min and than the surfaces' own slopes on either side (a surface seen edge-on changes depth fast
// too, but evenly); between the face and the background (the composite's alpha 0) the outline is a step
// too. Also copies the composite's picture to the output (alpha 1), and writes depth 0 where the pixel
// has a step to any 4-neighbour (1 elsewhere), so that the edges pass shades only those.
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"

uniform highp sampler2D u_color;  // the composite's picture, alpha 0 on the background
uniform float u_step_min;         // view units
uniform int u_enabled;            // 0: no steps (views of data, tests of the composite)

layout(location = 0) out vec4 o_color;
layout(location = 1) out vec2 o_step;

const float STEP_OVER_SLOPE = 3.0;  // a contour's step against the surfaces' own slopes beside it

// View depth of the surface at pixel px as the visibility pass left it (pushed back by u_eps to
// RS_PUSH_MAX + 1 u_eps), along z: neighbouring rays are parallel to far below the steps looked for; -1 for
// the background and outside the target.
float pushed_depth_at(ivec2 px)
{
    if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, ivec2(u_viewport)))) return -1.0;
    float z = texelFetch(u_depth, px, 0).r;
    if (z >= 1.0) return -1.0;
    vec4 v = vec4((vec2(px) + 0.5) / u_viewport * 2.0 - 1.0, z * 2.0 - 1.0, 1.0);
    return -dot(transpose(u_inv_proj)[2], v) / dot(transpose(u_inv_proj)[3], v);
}

// The same with the push undone.
float depth_at(ivec2 px)
{
    float z = pushed_depth_at(px);
    return z < 0.0 ? z : z - rs_push_at(u_push, px, u_eps);
}

// The step from pixel px (depth b) to px + n, against the slopes at px - n and px + 2n.
float step_to(ivec2 px, ivec2 n, float b)
{
    float c = depth_at(px + n);
    if (c < 0.0 || abs(c - b) < u_step_min) return 0.0;  // most pixels
    float a = depth_at(px - n), d = depth_at(px + 2 * n), j = abs(c - b), slope = 1e30;
    if (a >= 0.0) slope = min(slope, abs(b - a));
    if (d >= 0.0) slope = min(slope, abs(d - c));
    if (slope < 1e30 && j <= STEP_OVER_SLOPE * slope) return 0.0;
    return c > b ? 0.5 : 1.0;
}

// The step from px to px + n as step_to codes it; face: the composite drew skin at px (its alpha), z its
// depth (-1: a gap the composite filled). The background is deeper than any face: the outline is a step.
float step_code(ivec2 px, ivec2 n, bool face, float z)
{
    ivec2 q = px + n;
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, ivec2(u_viewport)))) return 0.0;
    bool qface = texelFetch(u_color, q, 0).a > 0.5;
    if (face != qface) return face ? 0.5 : 1.0;
    return face && z >= 0.0 ? step_to(px, n, z) : 0.0;
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy), x = ivec2(1, 0), y = ivec2(0, 1);
    vec4 own = texelFetch(u_color, px, 0);
    o_color = vec4(own.rgb, 1.0);
    o_step = vec2(0.0);
    gl_FragDepth = 1.0;
    if (u_enabled == 0) return;
    bool face = own.a > 0.5;
    float z = pushed_depth_at(px);
    vec4 n = vec4(pushed_depth_at(px + x), pushed_depth_at(px - x), pushed_depth_at(px + y), pushed_depth_at(px - y));
    // Most pixels: background among background, or face whose neighbours are no further than a step could
    // be, pushes (which differ by up to RS_PUSH_MAX u_eps) included.
    if (!face && all(lessThan(n, vec4(0.0)))) return;
    if (face && z >= 0.0 && all(greaterThanEqual(n, vec4(0.0))) &&
        !any(greaterThan(abs(n - z), vec4(u_step_min - RS_PUSH_MAX * u_eps))))
        return;
    if (z >= 0.0) z = depth_at(px);
    o_step = vec2(step_code(px, x, face, z), step_code(px, y, face, z));
    // The steps to the left and below are those neighbours' (their R and G): found again here.
    if (o_step != vec2(0.0) || step_code(px, -x, face, z) != 0.0 || step_code(px, -y, face, z) != 0.0)
        gl_FragDepth = 0.0;
}
