#version 300 es
// A Lambert-shaded sphere over a gradient: exercises arithmetic, branching and output encoding.
precision highp float;
in vec2 v_uv;
out vec4 o_color;
uniform vec3 u_light;
void main()
{
    vec2 p = v_uv * 2.0 - 1.0;
    float r2 = dot(p, p);
    vec3 c = vec3(0.1, 0.1 + 0.3 * v_uv.y, 0.3);
    if (r2 < 0.64) {
        vec3 n = vec3(p / 0.8, sqrt(1.0 - r2 / 0.64));
        c = vec3(0.9, 0.6, 0.5) * max(dot(n, normalize(u_light)), 0.0);
    }
    o_color = vec4(pow(c, vec3(1.0 / 2.2)), 1.0);
}
