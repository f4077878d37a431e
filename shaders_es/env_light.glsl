// env_light.glsl — light from an HDR environment (src/formats/env.h, docs/env.md): SH9 irradiance for the
// diffuse, the prefiltered radiance mip chain for the specular lobes (split sum: the radiance around the
// mirror direction, prefiltered with the lobe's Beckmann roughness, times the lobe's directional albedo
// from a lookup table; render_env.c). Directions arrive in view space and turn into the environment's
// frame (the face frame, rotated by --env-rotate) through u_env_from_view.
uniform float u_env_on;             // 0: no environment (key/fill/ambient only)
uniform mat3 u_env_from_view;
uniform vec3 u_env_sh[9];           // irradiance / pi, times the environment's exposure normalisation
uniform highp sampler2D u_env_map;  // RGB9E5 equirect, level k prefiltered with roughness u_env_m[k]
uniform float u_env_m[8];
uniform int u_env_levels;
uniform float u_env_scale;          // exposure normalisation of the map (the SH carry theirs)
uniform highp sampler2D u_spec_lut; // (N.V, m) -> (A, B): the lobe's directional albedo is F0 A + B

vec3 rs_env_irradiance(vec3 n_view)
{
    vec3 n = u_env_from_view * n_view;
    // Real SH basis, l <= 2 (Ramamoorthi & Hanrahan 2001 order), the same as rs_env_sh_irradiance.
    vec3 e = u_env_sh[0] * 0.282095
           + u_env_sh[1] * (0.488603 * n.y) + u_env_sh[2] * (0.488603 * n.z) + u_env_sh[3] * (0.488603 * n.x)
           + u_env_sh[4] * (1.092548 * n.x * n.y) + u_env_sh[5] * (1.092548 * n.y * n.z)
           + u_env_sh[6] * (0.315392 * (3.0 * n.z * n.z - 1.0)) + u_env_sh[7] * (1.092548 * n.x * n.z)
           + u_env_sh[8] * (0.546274 * (n.x * n.x - n.y * n.y));
    return max(e, vec3(0.0));
}

// Fractional mip level for roughness m: piecewise linear between the levels' roughnesses.
float rs_env_lod(float m)
{
    if (m <= u_env_m[0]) return 0.0;
    for (int k = 1; k < 8; k++) {
        if (k >= u_env_levels) break;
        if (m <= u_env_m[k]) return float(k - 1) + (m - u_env_m[k - 1]) / (u_env_m[k] - u_env_m[k - 1]);
    }
    return float(u_env_levels - 1);
}

// Radiance around view-space direction r, prefiltered for roughness m.
vec3 rs_env_radiance(vec3 r_view, float m)
{
    vec3 d = normalize(u_env_from_view * r_view);
    // docs/env.md: phi = atan(x, z) from forward towards the subject's left, theta from up.
    vec2 uv = vec2(atan(d.x, d.z) * 0.15915494 + 0.5, acos(clamp(d.y, -1.0, 1.0)) * 0.31830989);
    return textureLod(u_env_map, uv, rs_env_lod(m)).rgb * u_env_scale;
}

// Directional albedo of a Kelemen/Szirmay-Kalos lobe with rho_s 1 and Fresnel F0, for N.V and m.
float rs_env_lobe_albedo(float ndotv, float m, float f0)
{
    vec2 ab = texture(u_spec_lut, vec2(clamp(ndotv, 0.0, 1.0), clamp(m, 0.0, 1.0))).rg;
    return f0 * ab.x + ab.y;
}

// Environment light reflected by the lobe (N, m, F0) towards V: prefiltered radiance around the mirror
// direction times the lobe's albedo.
vec3 rs_env_specular(vec3 N, vec3 V, float m, float f0)
{
    float ndotv = max(dot(N, V), 1e-4);
    vec3 R = reflect(-V, N);
    return rs_env_radiance(R, m) * rs_env_lobe_albedo(ndotv, m, f0);
}
