// splat_sprite.glsl — vertex side of every splat pass: a screen-aligned sprite (a point sprite, or with
// RS_QUADS one instance of a 4-vertex strip) covering a view-space sphere, so the fragment shader can
// intersect the exact disk (or evaluate the kernel) inside it.
uniform mat4 u_proj;
uniform vec2 u_viewport;     // target size, pixels
uniform float u_point_max;   // GL_ALIASED_POINT_SIZE_RANGE max (points path)
uniform float u_persp;       // 1: perspective camera (eye at the origin), 0: orthographic (the light)

// The splat's index in the cloud (the buffer is drawn from record 0).
uint rs_splat_index()
{
#ifdef RS_QUADS
    return uint(gl_InstanceID);
#else
    return uint(gl_VertexID);
#endif
}

// Unit vector from view-space point c towards the eye.
vec3 rs_to_eye(vec3 c)
{
    return u_persp > 0.5 ? normalize(-c) : vec3(0.0, 0.0, 1.0);
}

// Drops the primitive: the vertex lands outside the clip volume.
void rs_sprite_cull()
{
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
}

// How far (in x / depth) a sphere's perspective projection reaches along one axis from its centre's
// projection: the tangents from the eye to the circle of radius R around (x, d) in that axis's plane
// (d: depth in front of the eye, d > R).
float rs_sphere_reach(float x, float d, float R)
{
    float den = d * d - R * R;
    float t = R * sqrt(x * x + den);
    float k0 = x / d;
    return max((x * d + t) / den - k0, k0 - (x * d - t) / den);
}

// Places the sprite over the sphere of radius R around view-space point c: a square about the centre's
// projection holding the sphere's whole projected outline (exact, any field of view), so every pixel
// whose ray meets the sphere gets a fragment and few others do. The fragment shaders test the exact
// footprint; a smaller sprite only spares them the pixels they would discard.
void rs_sprite(vec3 c, float R)
{
    vec4 clip = u_proj * vec4(c, 1.0);
    // The sphere must lie in front of the eye (perspective); w is 1 everywhere for ortho.
    float wmin = clip.w - R * length(vec3(u_proj[0][3], u_proj[1][3], u_proj[2][3]));
    if (wmin <= 1e-3 * clip.w) {
        rs_sprite_cull();
        return;
    }
    vec2 reach = u_persp > 0.5 ? vec2(rs_sphere_reach(c.x, -c.z, R), rs_sphere_reach(c.y, -c.z, R)) : vec2(R);
    // +0.5 px: pixel centres on the outline stay inside after rounding, and a reduced-resolution target's
    // pixel reads the full-size depth texel under its centre (diffusion), up to half a pixel away.
    vec2 half_xy = reach * abs(vec2(u_proj[0][0], u_proj[1][1])) * 0.5 * u_viewport;
    float half_px = max(half_xy.x, half_xy.y) + 0.5;
#ifdef RS_QUADS
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0;
    clip.xy += corner * (2.0 * half_px / u_viewport) * clip.w;
    gl_PointSize = 1.0;
#else
    gl_PointSize = min(2.0 * half_px, u_point_max);
#endif
    gl_Position = clip;
}
