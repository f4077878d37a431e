#version 300 es
// UI fragments: kind 0 = rounded box (filled or stroked; circles and capsules are rounded boxes),
// kind 1 = font glyph (coverage from the font texture), kind 2 = image (a rendered frame).
// Output is premultiplied alpha (blend ONE, ONE_MINUS_SRC_ALPHA).
precision highp float;
precision highp int;
in vec2 v_local;
flat in vec2 v_half;
flat in vec4 v_shape;
in vec2 v_uv;
in vec4 v_color;
uniform sampler2D u_font;
uniform sampler2D u_image;
out vec4 o_color;

// Signed distance to a box of half extents b with corners rounded by r (negative inside).
float sd_round_box(vec2 p, vec2 b, float r)
{
    vec2 q = abs(p) - b + r;
    return length(max(q, 0.0)) + min(max(q.x, q.y), 0.0) - r;
}

void main()
{
    int kind = int(v_shape.w + 0.5);
    vec4 c = v_color;
    if (kind == 1) {
        c.a *= texture(u_font, v_uv).r;
    } else if (kind == 2) {
        c = vec4(texture(u_image, v_uv).rgb * c.rgb, c.a);
    } else {
        float d = sd_round_box(v_local, v_half, v_shape.x);
        // A stroke is the band |d + w/2| < w/2 just inside the outline.
        if (v_shape.y > 0.0) d = abs(d + 0.5 * v_shape.y) - 0.5 * v_shape.y;
        float f = max(v_shape.z, 1.0);
        c.a *= smoothstep(0.5 * f, -0.5 * f, d);
    }
    if (c.a <= 0.0) discard;
    o_color = vec4(c.rgb * c.a, c.a);
}
