#version 300 es
// attribute.vert.glsl — stage 3, attribute splatting: per splat, what the fragment shader blends: linear
// albedo (with the makeup layer composed over it), view-space normal, the specular parameters m and rho_s
// from the region table (and makeup), the finish layers (clear coat, flakes) and the splat's ambient
// occlusion, and a debug colour (region or LOD level).
precision highp float;
precision highp int;
#include "splat_decode.glsl"
#include "splat_sprite.glsl"

#include "makeup.glsl"

layout(location = 0) in uvec4 a_splat;
layout(location = 1) in uvec3 a_makeup;   // rs_makeup_gpu, 12 bytes per splat; all zero = no makeup
uniform mat4 u_view;
uniform float u_radius_scale;
uniform float u_cull_cos;
uniform float u_coverage;
uniform float u_makeup_on;                // 0: hide the makeup layer (before/after views)
uniform float u_region_m[16];             // region table (rs_splat_header.regions)
uniform float u_region_rho[16];
uniform vec3 u_debug_color[24];           // per region (u_debug 1) or per LOD level (u_debug 2)
uniform int u_debug;
uniform uint u_lods[24];                  // LOD table, descending
uniform int u_lod_count;

flat out vec3 v_c;
flat out vec3 v_n;
flat out float v_r;
flat out vec3 v_albedo;
flat out vec2 v_spec;    // m, rho_s
flat out vec3 v_layers;  // ambient occlusion, clear-coat weight, flake weight
flat out vec3 v_debug;
flat out vec2 v_bent;    // the bent normal along the view-space normal's tangents; environments only (RT3)
uniform float u_env_on;

// The coarsest LOD level whose prefix holds splat i (the table descends: lods[0] = all splats).
int lod_level(uint i)
{
    int level = 0;
    for (int k = 1; k < 24; k++)
        if (k < u_lod_count && i < u_lods[k]) level = k;
    return level;
}

void main()
{
    rs_splat s = rs_decode_splat(a_splat);
    vec3 c = (u_view * vec4(s.pos, 1.0)).xyz;
    vec3 n = mat3(u_view) * s.normal;
    if (dot(n, rs_to_eye(c)) < u_cull_cos) {
        rs_sprite_cull();
        return;
    }
    uint region = min(s.region, 15u);
    vec3 albedo = s.albedo;
    float m = u_region_m[region];
    float rho_s = u_region_rho[region];
    float coat = 0.0, shimmer = 0.0;
    if (u_makeup_on > 0.5) rs_makeup_apply(a_makeup, albedo, m, rho_s, coat, shimmer);
    v_c = c;
    v_n = n;
    v_bent = vec2(0.0);
    if (u_env_on > 0.5) {
        vec3 b = mat3(u_view) * rs_decode_bent(a_splat, s.normal), t1, t2;
        rs_tangents(n, t1, t2);
        v_bent = vec2(dot(b, t1), dot(b, t2));
    }
    v_r = s.radius * u_radius_scale;
    v_albedo = albedo;
    v_spec = vec2(m, rho_s);
    v_layers = vec3(s.ao, coat, shimmer);
    v_debug = u_debug == 1 ? u_debug_color[region]
            : u_debug == 2 ? u_debug_color[lod_level(rs_splat_index())] : vec3(0.0);
    rs_sprite(c, v_r * u_coverage);
}
