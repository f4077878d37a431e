#version 300 es
// irradiance.vert.glsl — stage 4's per-splat input, by transform feedback (no rasterisation) so the
// diffusion levels don't repeat the shadow-map PCF: each splat's irradiance E = key (N.L, shadow-mapped) +
// fill (N.L) + ambient + the environment's SH irradiance through the splat's bent cone (its bent normal and
// ambient occlusion, env_light.glsl rs_env_sky: so stage 4 scatters environment light like the key light)
// + its other lamps (N.L, shadow-mapped) + the light the skin around it bounces into what the occlusion
// hides (bounce.glsl; the splat's own scanned albedo stands for its surroundings', never the makeup's).
// E depends on the lights and the splat, not on the camera: render_diffusion.c keeps it while the lights
// hold still (u_reach: see main).
precision highp float;
precision highp int;
#include "splat_decode.glsl"
#include "shadow_lookup.glsl"
#include "skin_brdf.glsl"  // env_light.glsl weighs its taps with the lobe
#include "env_light.glsl"
#include "bounce.glsl"
#include "behind_surface.glsl"

layout(location = 0) in uvec4 a_splat;
uniform mat4 u_view;
uniform mat4 u_proj;
uniform mat4 u_inv_proj;
uniform vec3 u_key_dir;         // view space, towards the light
uniform vec3 u_key_color;       // linear RGB * intensity
uniform vec3 u_fill_dir;
uniform vec3 u_fill_color;      // zero when the fill light is off
uniform vec3 u_ambient;
uniform highp sampler2D u_depth;  // visibility depth
uniform highp sampler2D u_push;   // and its push (visibility_push.glsl)
uniform float u_eps;
uniform float u_reach;          // the widest kernel's reach (3 sigma), view units

out vec3 v_irradiance;          // E

// How far view-space point c lies outside the view frustum's side planes (0 inside), view units.
float outside_view(vec3 c)
{
    vec4 h = vec4(c, 1.0);
    vec4 rx = vec4(u_proj[0][0], u_proj[1][0], u_proj[2][0], u_proj[3][0]);
    vec4 ry = vec4(u_proj[0][1], u_proj[1][1], u_proj[2][1], u_proj[3][1]);
    vec4 rw = vec4(u_proj[0][3], u_proj[1][3], u_proj[2][3], u_proj[3][3]);
    float d = 0.0;
    vec4 planes[4] = vec4[4](rw - rx, rw + rx, rw - ry, rw + ry);
    for (int i = 0; i < 4; i++) d = max(d, -dot(planes[i], h) / length(planes[i].xyz));
    return d;
}

void main()
{
    rs_splat s = rs_decode_splat(a_splat);
    vec3 c = (u_view * vec4(s.pos, 1.0)).xyz;
    vec3 n = mat3(u_view) * s.normal;
    float behind = dot(n, -c) < 0.0 ? rs_behind_visible(c, u_proj, u_inv_proj, u_depth, u_push, u_eps) : -1.0;
    vec3 e = u_key_color * max(dot(n, u_key_dir), 0.0);
    // Splats no kernel carries to a visible pixel (the back of the head, the shoulders below the view)
    // skip the shadow-map lookup: their E is not read in this view. The pass that makes the E kept for
    // other views sets an infinite reach.
    bool unseen = behind > u_reach || outside_view(c) > u_reach;
    if (dot(e, e) > 0.0 && !unseen) e *= rs_shadow(c, n);
    e += u_fill_color * max(dot(n, u_fill_dir), 0.0) + u_ambient;
    if (u_env_on > 0.5)
        e += rs_env_sky(n, mat3(u_view) * rs_decode_bent(a_splat, s.normal), s.ao)
           + rs_env_lamp_irradiance(n, unseen ? vec3(1.0) : rs_env_lamp_visibility(c, n)) + rs_bounce(s.ao, s.albedo);
    v_irradiance = e;
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
    gl_PointSize = 1.0;
}
