#version 300 es
// visibility.frag.glsl — per-pixel ray-disk intersection; writes the hit's depth, pushed back by u_eps
// along the view ray in the visibility pass so that the attribute pass blends every splat of the front
// surface layer (Botsch et al. 2005). RS_PICK also writes the splat index + 1 (0 = background).
precision highp float;
precision highp int;
#include "splat_ray.glsl"

uniform float u_coverage;  // disks are drawn out to this many radii (render_kit.h RS_COVERAGE)

uniform float u_eps;   // view units; 0 for the shadow map and the ID buffer

flat in vec3 v_c;
flat in vec3 v_n;
flat in float v_r;
#ifdef RS_PICK
flat in uint v_id;
layout(location = 0) out uint o_id;
#endif
#if defined(RS_SHADOW) && defined(RS_QUADS)
in vec2 v_disk;
#endif

void main()
{
#if defined(RS_SHADOW) && defined(RS_QUADS)
    // The shadow map's quads are the disks' own (visibility.vert.glsl) (orthographic): the rasteriser gives the plane's depth, and
    // the ray meets the plane where the interpolated disk coordinate says.
    if (dot(v_disk, v_disk) > 1.0) discard;
#else
    vec3 o, d, q;
    float l;
    rs_pixel_ray(gl_FragCoord.xy, o, d);
    if (!rs_ray_disk(o, d, v_c, v_n, v_r, u_coverage, q, l)) discard;
    // The rim beyond the disk (l > 1, drawn only to close sampling gaps) goes 2 eps further back: on a
    // concave crease a tangent disk's rim stands in front of the neighbouring surface, and must not
    // hide it (its normal is wrong there); in a gap, nothing else is in front of it anyway.
    gl_FragDepth = rs_depth_of(q + d * (l > 1.0 ? 3.0 * u_eps : u_eps));
#endif
#ifdef RS_PICK
    o_id = v_id;
#endif
}
