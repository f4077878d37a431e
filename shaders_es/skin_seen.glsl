// skin_seen.glsl — the skin at a pixel as the camera sees it diffusely, for reflections the face blocks
// (composite.frag.glsl, reflect.frag.glsl): what such a reflection shows instead of the sky.
uniform highp sampler2D u_attr0;
uniform highp sampler2D u_diffuse;
uniform float u_diffuse_scale;  // undoes the D target's scale (RGBA8 fallback)
uniform vec3 u_delta_weight;    // profile weight of the Gaussians too narrow to draw: per-pixel irradiance
uniform float u_min_weight;     // accumulated weights below this are unreliable (RGBA8 fallback): a hole

// A D at pixel q (the narrowest levels' share taken at their luminance): the skin a reflection runs into
// (the nearest surface behind a contour, the one a marched reflection passes behind). Black before: at the
// chin's edge over the neck that drew a dark line where the path tracer shows the neck's reflection,
// reddish at grazing Fresnel (issue 22).
vec3 skin_at(ivec2 q)
{
    vec4 a = texelFetch(u_attr0, q, 0);
    if (a.a <= u_min_weight) return vec3(0.0);
    vec4 d = texelFetch(u_diffuse, q, 0) * u_diffuse_scale;
    return a.rgb / a.a * (d.rgb + u_delta_weight * d.a);
}

// A unit vector in two numbers (octahedral: the sphere unfolded onto a square), and back.
vec2 rs_octahedral(vec3 n)
{
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    vec2 s = vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    return n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * s;
}

vec3 rs_from_octahedral(vec2 e)
{
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    vec2 s = vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * s;
    return normalize(n);
}
