// bounce.glsl — light between skin surfaces, from the per-splat ambient occlusion (the converter's
// cosine-weighted sky visibility). The part of the hemisphere the occlusion takes away is not black: it
// is skin (the neck under the jaw, the cheek beside the nose, the other lip), lit by the same lights and
// reflecting them in its own colour, bounce after bounce. Jimenez et al. 2016 (GTAO, "multi-bounce")
// fitted the visibility that light from a uniform sky reaches after all those bounces in a cavity of
// albedo a, as a cubic in the visibility v per colour channel. Here the bounced part (fit - v) is lit by
// what lights the skin around a hollow, taken as the face's front surface on average (u_env_surround,
// render_env.c: its mean irradiance, SH and the environment's light, as a camera in front sees it). So a
// crease gets light in the skin's colour (red-brown under red-brown skin), and an underside facing a dark
// floor (under the jaw) is lit by the skin that faces the light. The composite then relights each pixel's
// share with the light of the walls it sees on screen (composite.frag.glsl surround_seen): the splats' pass
// cannot look at its neighbours.
uniform vec3 u_env_surround;

// The fit's cubic coefficients for the cavity's albedo (linear RGB): visibility (a v^2 + b v + c) v.
void rs_multibounce_fit(vec3 albedo, out vec3 a, out vec3 b, out vec3 c)
{
    a = 2.0404 * albedo - 0.3324;
    b = -4.7951 * albedo + 0.6417;
    c = 2.7552 * albedo + 0.6903;
}

// Visibility after interreflections: >= v; per channel.
vec3 rs_multibounce(float v, vec3 albedo)
{
    vec3 a, b, c;
    rs_multibounce_fit(albedo, a, b, c);
    return max(vec3(v), ((v * a + b) * v + c) * v);
}

// Irradiance that reaches a point of visibility v from the skin around it (albedo: its colour), that skin
// lit by `surround`.
vec3 rs_bounce_lit(float v, vec3 albedo, vec3 surround)
{
    return (rs_multibounce(v, clamp(albedo, 0.0, 1.0)) - v) * surround;
}

// The same, the skin around lit as the face's front is on average (what the splats get).
vec3 rs_bounce(float v, vec3 albedo)
{
    return rs_bounce_lit(v, albedo, u_env_surround);
}

// The radiance of that skin in the directions the occlusion hides: rs_bounce over the hidden share (1 - v),
// by dividing the cubic's (fit - v) by (1 - v) in closed form, -v (a (v + 1) + b) (the fit's value at
// v = 1, a + b + c, is 1 within 5e-4, which is dropped), so that it holds up as v -> 1.
vec3 rs_hidden_radiance(float v, vec3 albedo)
{
    vec3 a, b, c;
    rs_multibounce_fit(clamp(albedo, 0.0, 1.0), a, b, c);
    return max(-v * (a * (v + 1.0) + b), 0.0) * u_env_surround;
}
