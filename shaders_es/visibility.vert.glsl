#version 300 es
// visibility.vert.glsl — stage 2, visibility splatting (Botsch et al. 2005): every splat as a disk in a
// depth pass (and its push, visibility.frag.glsl). The same program draws stage 1's shadow map (from the
// light, RS_SHADOW) and the ID buffer for picking (RS_PICK). RS_QUADS: instanced quads instead of point
// sprites.
precision highp float;
precision highp int;
#include "splat_decode.glsl"
#include "splat_sprite.glsl"

layout(location = 0) in uvec4 a_splat;
uniform mat4 u_view;           // model -> view (the camera, or the light)
uniform float u_radius_scale;  // LOD: sqrt(N / n)
uniform float u_cull_cos;
uniform float u_coverage;      // back-face culling: splats with dot(normal, to_eye) below this are dropped

flat out vec3 v_c;
flat out vec3 v_n;
flat out float v_r;
#ifdef RS_PICK
flat out uint v_id;
#endif
#if defined(RS_SHADOW) && defined(RS_QUADS)
out vec2 v_disk;  // the fragment's position in the disk's plane, in u_coverage radii from its centre
#endif

void main()
{
    rs_splat s = rs_decode_splat(a_splat);
    vec3 c = (u_view * vec4(s.pos, 1.0)).xyz;
    vec3 n = mat3(u_view) * s.normal;
    // A splat facing away is only ever seen edge-on at a silhouette, where its front-facing neighbours
    // cover the same pixels: dropping it halves the work and keeps the far side of thin parts hidden.
    if (dot(n, rs_to_eye(c)) < u_cull_cos) {
        rs_sprite_cull();
        return;
    }
    v_c = c;
    v_n = n;
    v_r = s.radius * u_radius_scale;
#ifdef RS_PICK
    v_id = rs_splat_index() + 1u;
#endif
#if defined(RS_SHADOW) && defined(RS_QUADS)
    // The shadow map (orthographic) as instanced quads: the square around the disk in the disk's own
    // plane, so the rasteriser interpolates the plane's depth (no gl_FragDepth: early depth test) and a
    // splat seen obliquely from the light covers cos(theta) of a screen-aligned sprite's texels: on
    // llvmpipe ~7x cheaper than point sprites, the same map to float rounding. Points (RS_PRIM_POINTS)
    // still take the ray-disk path below. 1.01: the inscribed disk's rim stays inside the square.
    vec3 t1 = normalize(abs(n.x) < 0.7 ? vec3(0.0, n.z, -n.y) : vec3(n.y, -n.x, 0.0));
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    v_disk = corner * 1.01;
    vec3 p = c + (corner.x * t1 + corner.y * cross(n, t1)) * (v_r * u_coverage * 1.01);
    gl_Position = u_proj * vec4(p, 1.0);
#else
    rs_sprite(c, v_r * u_coverage);
#endif
}
