// behind_surface.glsl — how far a splat lies behind the visible surface at its own pixel (the back of the
// head): the irradiance pass skips such splats' shadow lookups and stage 4's levels cull them. Shared by
// both so that they agree on which splats those are.
//
// View-space point c; proj / inv_proj: the camera's; depth: the visibility pass's depth (the view's size),
// pushed back along the view ray by what push and eps say (visibility_push.glsl). -1 when c is not behind
// it (off screen, background).
#include "visibility_push.glsl"

float rs_behind_visible(vec3 c, mat4 proj, mat4 inv_proj, highp sampler2D depth, highp sampler2D push, float eps)
{
    vec4 clip = proj * vec4(c, 1.0);
    if (clip.w <= 0.0) return -1.0;
    vec2 ndc = clip.xy / clip.w;
    if (any(greaterThan(abs(ndc), vec2(1.0)))) return -1.0;
    ivec2 size = textureSize(depth, 0);
    ivec2 px = clamp(ivec2((ndc * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1);
    float z = texelFetch(depth, px, 0).r;
    if (z >= 1.0) return -1.0;
    vec4 h = inv_proj * vec4(ndc, z * 2.0 - 1.0, 1.0);
    return length(c) - (length(h.xyz / h.w) - rs_push_at(push, px, eps));
}
