#version 300 es
// The UI: every shape is a quad whose fragments evaluate a signed distance (ui.frag.glsl), so edges are
// anti-aliased at any size without textures. Positions arrive in framebuffer pixels, top-left origin.
precision highp float;
layout(location = 0) in vec2 a_pos;    // framebuffer pixels
layout(location = 1) in vec2 a_local;  // pixels from the shape's centre, along the shape's own axes
layout(location = 2) in vec2 a_half;   // half extents of the shape, pixels
layout(location = 3) in vec4 a_shape;  // corner radius, stroke width (0 = filled), feather, kind
layout(location = 4) in vec2 a_uv;
layout(location = 5) in vec4 a_color;  // sRGB, straight alpha
uniform vec2 u_fb;                     // framebuffer size, pixels
out vec2 v_local;
flat out vec2 v_half;
flat out vec4 v_shape;
out vec2 v_uv;
out vec4 v_color;
void main()
{
    v_local = a_local;
    v_half = a_half;
    v_shape = a_shape;
    v_uv = a_uv;
    v_color = a_color;
    gl_Position = vec4(a_pos.x / u_fb.x * 2.0 - 1.0, 1.0 - a_pos.y / u_fb.y * 2.0, 0.0, 1.0);
}
