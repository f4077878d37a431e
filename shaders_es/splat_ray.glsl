// splat_ray.glsl — fragment side of the splat passes: the pixel's view ray, its intersection with a splat
// disk (Botsch et al. 2005, per-pixel ray-disk), depth of a view-space point, and the visible surface point
// reconstructed from the visibility pass's depth.
uniform mat4 u_proj;
uniform mat4 u_inv_proj;
uniform vec2 u_viewport;     // target size, pixels

vec2 rs_pixel_ndc(vec2 frag)
{
    return frag / u_viewport * 2.0 - 1.0;
}

// The ray through a pixel, view space: origin on the near plane, unit direction away from the eye.
void rs_pixel_ray(vec2 frag, out vec3 o, out vec3 d)
{
    vec2 ndc = rs_pixel_ndc(frag);
    vec4 a = u_inv_proj * vec4(ndc, -1.0, 1.0);
    vec4 b = u_inv_proj * vec4(ndc, 1.0, 1.0);
    o = a.xyz / a.w;
    d = normalize(b.xyz / b.w - o);
}

// Intersects the ray with the plane of the disk (centre c, unit normal n, radius r). q: the hit point;
// l: its distance from the centre in radii. False when l exceeds `reach` (1: the disk itself).
bool rs_ray_disk(vec3 o, vec3 d, vec3 c, vec3 n, float r, float reach, out vec3 q, out float l)
{
    float dn = dot(d, n);
    q = c;
    l = 2.0;
    if (abs(dn) < 1e-5) return false;
    q = o + d * (dot(c - o, n) / dn);
    l = length(q - c) / r;
    return l <= reach;
}

#include "visibility_push.glsl"

// Window depth (default depth range) of a view-space point.
float rs_depth_of(vec3 q)
{
    vec4 clip = u_proj * vec4(q, 1.0);
    return clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
}

#ifdef RS_NEEDS_VISIBLE_POINT
uniform highp sampler2D u_depth;  // visibility pass depth, pushed back along the view ray (visibility_push.glsl)
uniform highp sampler2D u_push;   // that push beyond u_eps, R8
uniform float u_eps;              // view units

// The front surface point under pixel px of the depth texture (view space), undoing the visibility
// pass's push; false on background. The camera is perspective: the ray runs from the eye at the origin
// through the point. Works from targets of another size too (reduced-resolution diffusion levels):
// px is always a pixel of the depth texture.
bool rs_visible_point_at(ivec2 px, out vec3 p)
{
    float z = texelFetch(u_depth, px, 0).r;
    p = vec3(0.0);
    if (z >= 1.0) return false;
    vec2 ndc = (vec2(px) + 0.5) / vec2(textureSize(u_depth, 0)) * 2.0 - 1.0;
    vec4 h = u_inv_proj * vec4(ndc, z * 2.0 - 1.0, 1.0);
    p = h.xyz * (1.0 / h.w);
    p -= normalize(p) * rs_push_at(u_push, px, u_eps);
    return true;
}

// The depth texture's pixel holding the centre of this target's pixel (the same pixel at full size).
ivec2 rs_depth_pixel(vec2 frag)
{
    return ivec2(frag / u_viewport * vec2(textureSize(u_depth, 0)));
}

bool rs_visible_point(out vec3 p)
{
    return rs_visible_point_at(rs_depth_pixel(gl_FragCoord.xy), p);
}
#endif
