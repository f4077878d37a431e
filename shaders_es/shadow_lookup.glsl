// shadow_lookup.glsl — stage 1's consumer side: visibility of the key light at a view-space point from the
// splat shadow map (orthographic, fitted to the cloud's bounding sphere), with a receiver-plane depth bias
// against acne and a 4x4 grid of the hardware's bilinear 2x2 PCF, 1.5 texels of a 2048^2 map apart
// whatever the map's own size: a penumbra about 2 mm wide on the bundled head, as from a small studio
// light rather than a point. A sharper edge would leave a band of pure red at every shadow boundary (the
// skin profile's red reaches millimetres past an edge that green and blue barely cross), which reads as a
// painted outline.
uniform highp sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_matrix;   // view space -> light clip space
uniform mat3 u_shadow_normals;  // view-space normals -> light clip space (inverse transpose)
uniform float u_shadow_on;      // 0: no shadows (everything lit)
uniform float u_shadow_texel;   // the PCF grid's texel, uv (1 / 2048)
uniform float u_shadow_map_texel;  // the map's own texel, uv (1 / its size)
uniform float u_shadow_bias;    // window-depth units
uniform vec3 u_shadow_dir;      // towards the light, view space
// The environment's other lamps (render_shadow.c lamp_shadows): a layer of one depth array each.
uniform highp sampler2DArrayShadow u_lamp_shadow_map;
uniform mat4 u_lamp_shadow_matrix[3];
uniform mat3 u_lamp_shadow_normals[3];
uniform vec3 u_lamp_shadow_dir[3];
uniform float u_lamp_shadow_on[3];     // 0: lit, unshadowed (no map: no lamp, or shadows off)
uniform float u_lamp_shadow_bias;
uniform float u_lamp_shadow_texel;     // a layer's texel, uv

// The receiver's plane in a map's light clip space: the lookup point s (uv, window depth), the window
// depth per unit of uv along the plane (grad), and the constant and slope bias (bias), for the light's
// direction dir (view space) and a map of texel `texel` (uv) with depth bias `base`.
void rs_shadow_plane(vec3 p, vec3 n, mat4 m, mat3 nm, vec3 dir, float base, float texel,
                     out vec3 s, out vec2 grad, out float bias)
{
    vec4 lc = m * vec4(p, 1.0);
    s = lc.xyz / lc.w * 0.5 + 0.5;
    vec3 nc = nm * n;
    float ndl = clamp(dot(n, dir), 0.05, 1.0);
    float slope = min(sqrt(1.0 - ndl * ndl) / ndl, 4.0);
    // Window depth per unit of shadow-map uv along the receiver's plane (clamped at grazing light).
    grad = -nc.xy / (abs(nc.z) > 1e-4 ? nc.z : 1e-4);
    float glen = length(grad);
    if (glen > 4.0) grad *= 4.0 / glen;
    // Each tap compares the 2x2 texels around it, up to a texel of the map away along the receiver's
    // plane: that much slope, plus the constant.
    bias = base * (1.0 + slope) + texel * min(glen, 4.0);
}

// A surface facing away from a light is in its own (attached) shadow whatever a map says, faded in over the
// last few degrees (n.l: the cosine to the light), where N.L is near zero anyway, so the blended normals'
// noise leaves no jagged edge.
float rs_attached(float ndotl)
{
    return smoothstep(0.0, 0.08, ndotl);
}

float rs_shadow(vec3 p, vec3 n)
{
    if (u_shadow_on < 0.5) return 1.0;
    // No normal offset: shifting the lookup point along the normal moves every cast-shadow edge towards
    // its occluder by offset x tan(theta) (0.5-5.9 mm at 30-70 degrees with the old offset). Instead the
    // receiver's own plane gives each PCF tap its depth (receiver-plane depth bias): a tilted receiver
    // does not shadow itself, and the constant bias left (the disks' departure from the surface, a
    // texel's quantisation) moves only contact shadows, by bias x tan(theta).
    // Facing away from the light: attached shadow (the receiver plane below would tilt the comparison the
    // wrong way).
    float attached = rs_attached(dot(n, u_shadow_dir));
    if (attached <= 0.0) return 0.0;
    vec3 s;
    vec2 grad;
    float bias;
    rs_shadow_plane(p, n, u_shadow_matrix, u_shadow_normals, u_shadow_dir, u_shadow_bias, u_shadow_map_texel,
                    s, grad, bias);
    float sum = 0.0;
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            // The grid turned by atan(1/4): its 16 taps fall at 16 distinct distances from an edge
            // along either axis, so taps several texels apart still ramp smoothly.
            vec2 g = vec2(x, y) - 1.5;
            vec2 o = vec2(0.9701 * g.x - 0.2425 * g.y, 0.2425 * g.x + 0.9701 * g.y) * 1.5 * u_shadow_texel;
            sum += textureLod(u_shadow_map, vec3(s.xy + o, s.z + dot(grad, o) - bias), 0.0);
        }
    return sum / 16.0 * attached;
}

// Visibility of lamp k (0..2) at a view-space point: the key's lookup (receiver plane, attached shadow) on
// a 2x2 grid of the hardware's 2x2 PCF 1.5 texels of the lamp's map apart (0.85 mm on the bundled head):
// a penumbra of ~2.5 mm, about the key's, from maps a quarter of its resolution, at a quarter of its taps. The lamps are area lights
// (studio's softboxes) and their shadows fall on skin that scatters light millimetres past an edge.
float rs_lamp_shadow(int k, vec3 p, vec3 n)
{
    if (u_lamp_shadow_on[k] < 0.5) return 1.0;
    float attached = rs_attached(dot(n, u_lamp_shadow_dir[k]));
    if (attached <= 0.0) return 0.0;
    vec3 s;
    vec2 grad;
    float bias;
    rs_shadow_plane(p, n, u_lamp_shadow_matrix[k], u_lamp_shadow_normals[k], u_lamp_shadow_dir[k],
                    u_lamp_shadow_bias, u_lamp_shadow_texel, s, grad, bias);
    float sum = 0.0;
    for (int i = 0; i < 4; i++) {
        // A 2x2 grid turned by atan(1/2), 1.5 texels apart: its 4 taps at 4 distinct distances from an
        // edge along either axis.
        vec2 g = vec2(i & 1, i >> 1) - 0.5;
        vec2 o = vec2(0.8944 * g.x - 0.4472 * g.y, 0.4472 * g.x + 0.8944 * g.y) * 1.5 * u_lamp_shadow_texel;
        // texture(), not textureGrad() (ES 3.0 has no textureLod for array shadows): the array has one level
        // and equal min/mag filters, so the implicit level cannot matter, and explicit gradients made the
        // H100 take a path that cost as much as the rest of the lamps' lookups.
        sum += texture(u_lamp_shadow_map, vec4(s.xy + o, float(k), s.z + dot(grad, o) - bias));
    }
    return sum / 4.0 * attached;
}
