#version 300 es
// visibility.frag.glsl — per-pixel ray-disk intersection; writes the hit's depth, pushed back along the
// view ray in the visibility pass by u_eps (more towards the rim) so that the attribute pass blends every
// splat of the front surface layer (Botsch et al. 2005). RS_PICK also writes the splat index + 1
// (0 = background).
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
#elif !defined(RS_SHADOW)
layout(location = 0) out float o_push;  // the extra push's share (visibility_push.glsl)
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
    // A disk's outer part goes further back, up to RS_PUSH_MAX eps, from RS_PUSH_FROM radii out to the
    // rim and beyond (drawn only to close sampling gaps): on a concave fold (the lower lip over the chin's
    // hollow, a crease) a tangent disk at the surface's edge overhangs the surface just behind it and
    // hid it, its rim showing as a pale scallop with the wrong normal and colour; pushed back, the
    // surface behind wins wherever it is nearer, while where the disk is the only surface (a gap, a
    // silhouette) nothing changes. Inside one surface some disk's centre is nearer than RS_PUSH_FROM
    // radii at most pixels (the disks overlap that much: on the bundled face the push is 0 at 83 % of
    // them, and mostly small in the gaps between centres).
    float share = smoothstep(RS_PUSH_FROM, 1.0, l);
    gl_FragDepth = rs_depth_of(q + d * rs_push(share, u_eps));
#if !defined(RS_PICK) && !defined(RS_SHADOW)
    o_push = share;
#endif
#endif
#ifdef RS_PICK
    o_id = v_id;
#endif
}
