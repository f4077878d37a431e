// visibility_push.glsl — how far the visibility pass pushes a disk's depth back along the view ray
// (visibility.frag.glsl): u_eps, and up to RS_PUSH_MAX u_eps more from RS_PUSH_FROM radii out to the rim.
// Each pixel's extra push is kept in an R8 target (in RS_PUSH_MAX u_eps), so whoever reads the depth
// undoes it exactly. Included by splat_ray.glsl and behind_surface.glsl (guarded: a shader may take both).
#ifndef RS_VISIBILITY_PUSH
#define RS_VISIBILITY_PUSH
const float RS_PUSH_MAX = 4.0;
const float RS_PUSH_FROM = 0.5;

// The push (view units) for share 0..1 of the extra push (what the R8 target keeps) and the frame's eps.
float rs_push(float share, float eps)
{
    return eps * (1.0 + RS_PUSH_MAX * share);
}

// The push at depth-texture pixel px, from the R8 target push.
float rs_push_at(highp sampler2D push, ivec2 px, float eps)
{
    return rs_push(texelFetch(push, px, 0).r, eps);
}
#endif
