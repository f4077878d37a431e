// shadow_lookup.glsl — stage 1's consumer side: visibility of the key light at a view-space point from the
// splat shadow map (orthographic, fitted to the cloud's bounding sphere), with a normal-offset + depth bias
// against acne and a 4x4 grid of the hardware's bilinear 2x2 PCF, 1.5 texels apart: a penumbra about
// 8 texels (~2 mm on the bundled head) wide, as from a small studio light rather than a point. A sharper
// edge would leave a band of pure red at every shadow boundary (the skin profile's red reaches millimetres
// past an edge that green and blue barely cross), which reads as a painted outline.
uniform highp sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_matrix;   // view space -> light clip space
uniform float u_shadow_on;      // 0: no shadows (everything lit)
uniform float u_shadow_texel;   // 1 / shadow map size
uniform float u_shadow_bias;    // window-depth units
uniform float u_shadow_offset;  // normal offset, view units
uniform vec3 u_shadow_dir;      // towards the light, view space

float rs_shadow(vec3 p, vec3 n)
{
    if (u_shadow_on < 0.5) return 1.0;
    // Slope scaling: towards grazing light, neighbouring disks (tilted a few degrees from each other)
    // disagree in light depth by ~ r tan(theta), so both offsets grow with the angle.
    float ndl = clamp(dot(n, u_shadow_dir), 0.05, 1.0);
    float slope = min(sqrt(1.0 - ndl * ndl) / ndl, 4.0);
    vec4 lc = u_shadow_matrix * vec4(p + n * (u_shadow_offset * (1.0 + slope)), 1.0);
    vec3 s = lc.xyz / lc.w * 0.5 + 0.5;
    s.z -= u_shadow_bias * (1.0 + slope);
    float sum = 0.0;
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            vec2 o = (vec2(x, y) - 1.5) * 1.5 * u_shadow_texel;
            sum += textureLod(u_shadow_map, vec3(s.xy + o, s.z), 0.0);
        }
    return sum / 16.0;
}
