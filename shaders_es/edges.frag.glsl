#version 300 es
// edges.frag.glsl — the end of stage 5: anti-aliasing of the depth steps inside the face (the lip line, the
// nose's base, eyelids, the jaw over the neck) and of the face's outline. The composite draws each pixel as
// the one surface its centre sees, so a contour is a one-pixel staircase. As in morphological anti-aliasing (Reshetov 2009), each step between a pixel and a
// 4-neighbour (edges_find.frag.glsl) is followed along the contour to both ends of its straight run; the
// contour is taken to pass through the middles of the risers there, and the share of the pixel on the other
// side of that line shows the other side's colour (mixed in linear light). The steps come from the depth,
// not the colour, so skin texture and makeup edges stay as sharp as they were. Drawn only on the pixels
// the steps pass marked; it copied the others.
precision highp float;
precision highp int;

uniform highp sampler2D u_color;  // the composite's output (RGBA8)
uniform highp sampler2D u_edges;  // the steps (edges_find.frag.glsl)
uniform float u_linear_output;    // 1: u_color is linear already

out vec4 o_color;

const int SEARCH = 16;  // pixels followed each way along a contour

// The step from pixel c to c + n (n one of +-x, +-y): 0 none, 1 c + n is deeper, -1 it is nearer.
float step_of(ivec2 c, ivec2 n)
{
    bool back = n.x + n.y < 0;  // kept at c + n, as the step from there to c
    ivec2 at = back ? c + n : c;
    if (any(lessThan(at, ivec2(0))) || any(greaterThanEqual(at, textureSize(u_edges, 0)))) return 0.0;
    vec2 e = texelFetch(u_edges, at, 0).rg;
    float v = n.x != 0 ? e.r : e.g;
    float s = v > 0.75 ? -1.0 : v > 0.25 ? 1.0 : 0.0;
    return back ? -s : s;
}

// Follows the step s between p and p + n along a: (pixels to where it leaves this row, how: +1 one row
// towards n, -1 one row back, 0 it ends or runs past the search).
vec2 follow(ivec2 p, ivec2 n, ivec2 a, float s)
{
    for (int i = 1; i <= SEARCH; i++) {
        ivec2 c = p + a * i;
        if (step_of(c, n) == s) continue;
        return vec2(float(i), step_of(c + n, n) == s ? 1.0 : step_of(c - n, n) == s ? -1.0 : 0.0);
    }
    return vec2(float(SEARCH + 1), 0.0);
}

// Share of pixel p beyond the contour between it and p + n.
float share(ivec2 p, ivec2 n)
{
    float s = step_of(p, n);
    if (s == 0.0) return 0.0;
    ivec2 a = ivec2(n.y, n.x);
    vec2 lo = follow(p, n, -a, s), hi = follow(p, n, a, s);
    if (lo.y == 0.0 && hi.y == 0.0) return 0.0;  // a straight run: the pixels are right as they are
    // The contour's line through the risers' middles (x along a, height along n, the step at height 0); an
    // end without a riser holds it at the step. Risers to the same side: two lines meeting at the middle.
    float x0 = 0.5 - lo.x, h0 = 0.5 * lo.y, x1 = hi.x - 0.5, h1 = 0.5 * hi.y, mid = 0.5 * (x0 + x1);
    float area = 0.0;
    for (int k = 0; k < 4; k++) {
        float x = (float(k) - 1.5) * 0.25, h;
        if (lo.y == hi.y)
            h = x < mid ? h0 * (mid - x) / (mid - x0) : h1 * (x - mid) / (x1 - mid);
        else
            h = mix(h0, h1, (x - x0) / (x1 - x0));
        area += clamp(-h, 0.0, 1.0);
    }
    return 0.25 * area;
}

vec3 to_linear(vec3 c)
{
    return u_linear_output > 0.5 ? c : mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}

vec3 to_output(vec3 c)
{
    return u_linear_output > 0.5 ? c : mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 own = vec4(texelFetch(u_color, px, 0).rgb, 1.0);  // the composite's alpha marks the background
    o_color = own;
    const ivec2 dirs[4] = ivec2[4](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1));
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int i = 0; i < 4; i++) {
        float w = share(px, dirs[i]);
        if (w <= 0.0) continue;
        vec4 c = texelFetch(u_color, px + dirs[i], 0);
        sum += w * vec4(to_linear(c.rgb), 1.0);
        total += w;
    }
    if (total <= 0.0) return;
    float keep = max(1.0 - total, 0.0);
    vec4 mixed = (keep * vec4(to_linear(own.rgb), own.a) + sum) / (keep + total);
    o_color = vec4(to_output(mixed.rgb), mixed.a);
}
