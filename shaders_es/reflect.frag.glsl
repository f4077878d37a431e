#version 300 es
// reflect.frag.glsl — stage 5's first pass, at half size: per pixel, whether the face itself blocks the
// mirror direction (reflection_open) and the skin it sees where it does, for the composite, which averages
// them over a millimetre around each pixel (composite.frag.glsl reflection_near): each of the march's
// steps decides "blocked" at one pixel, so its edge is a sharp copy of the blocker's contour, shifted by
// the step's projection (thin light lines along the upper lip's underside in a close-up: its first step's
// copy of the lip line). Out (RGBA32UI; 0 where no surface): the point's view depth (float bits), the
// skin the blocked share sees (half floats R, G | B, then the open share, plus 2 where the march ran off
// the frame), the normal (octahedral, snorm16 x 2): all the composite's average weighs, in one fetch.
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"
#include "skin_seen.glsl"

uniform highp sampler2D u_attr1;
uniform float u_contour_reach;  // view units (20 mm)

out uvec4 o_reflect;

// Whether the face itself blocks the mirror direction R (view space) from the surface point p. The
// environment's radiance is looked up as if every direction above the surface's horizon saw the sky; AO
// only scales it by the share of the sky the point sees in all. But a head is a closed solid: a reflection
// that runs back past the face's own surface (the side of the nose mirroring a lamp behind the subject,
// through the cheek and the eye socket) sees the inside of the head, not the lamp; the path tracer shows
// no highlight there and rouge drew a white streak down the nose at the physical strength (issue 22). So
// R is marched 2.5 to 80 mm (steps doubling: an ear's folds are a few mm deep) through the depth buffer:
// a point that lies behind the visible surface at its pixel by more than 1-3 mm (and less than a head's
// depth: beyond that the ray passes behind the head) is inside the head and blocks the reflection.
// Background leaves it open. hit: the pixel of the surface that blocks it most; left: the march ran off
// the frame, past what the depth buffer knows (the composite asks the splat's bent cone then).
float reflection_open(vec3 p, vec3 R, inout ivec2 hit, out bool left)
{
    left = false;
    float open = 1.0;
    float d = 0.125 * u_contour_reach;
    // The march's points in clip space are linear in d: no projection per step.
    vec4 cp = u_proj * vec4(p, 1.0), cr = u_proj * vec4(R, 0.0);
    for (int k = 0; k < 6; k++, d *= 2.0) {
        vec3 q = p + R * d;
        if (q.z > -1e-3) break;  // passes the eye's plane: in front of everything the camera sees
        vec4 c = cp + cr * d;
        vec2 f = (c.xy / c.w * 0.5 + 0.5) * u_viewport;
        if (any(lessThan(f, vec2(0.0))) || any(greaterThanEqual(f, u_viewport))) {
            left = true;
            break;
        }
        vec3 s;
        if (!rs_visible_point_at(rs_depth_pixel(f), s)) continue;
        float behind = s.z - q.z;
        float o = 1.0 - smoothstep(0.05 * u_contour_reach, 0.15 * u_contour_reach, behind)
                        * (1.0 - smoothstep(8.0 * u_contour_reach, 10.0 * u_contour_reach, behind));
        if (o < open) open = o, hit = rs_depth_pixel(f);
    }
    return open;
}

void main()
{
    ivec2 px = rs_depth_pixel(gl_FragCoord.xy);  // the full-size pixel at this one's centre
    vec4 t0 = texelFetch(u_attr0, px, 0);
    vec3 p;
    if (t0.a <= u_min_weight || !rs_visible_point_at(px, p)) {
        o_reflect = uvec4(0u);
        return;
    }
    vec3 N = normalize(texelFetch(u_attr1, px, 0).xyz / t0.a * 2.0 - 1.0);
    ivec2 hit = ivec2(-1);
    bool left;
    float open = reflection_open(p, reflect(normalize(p), N), hit, left);
    vec3 skin = open < 0.98 && hit.x >= 0 ? skin_at(hit) * (1.0 - open) : vec3(0.0);
    o_reflect = uvec4(floatBitsToUint(p.z), packHalf2x16(skin.rg),
                      packHalf2x16(vec2(skin.b, open + (left ? 2.0 : 0.0))), packSnorm2x16(rs_octahedral(N)));
}
