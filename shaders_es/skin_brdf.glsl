// skin_brdf.glsl — the Kelemen/Szirmay-Kalos specular BRDF as GPU Gems 3 ch. 14 uses it (METHOD.md):
// Beckmann P_H without the 1/pi (so Weyrich et al.'s rho_s keep their meaning), Schlick Fresnel with
// F0 = 0.028 (skin, n = 1.4). rho_s 1 is the physical lobe; the composite divides Weyrich's rho_s by their
// mean (RS_RHO_S_PHYSICAL). The same lobe with rho_s 1 and F0 0.04 is the clear coat of a gloss (docs/makeup.md).
//
// Masking-shadowing: the microfacet lobe is f = D F G / (4 N.L N.V); every light here is divided by pi and
// P_H = pi D, so a light reflects (N.L) P_H F G / (4 N.L N.V). Kelemen & Szirmay-Kalos replace
// G / (N.L N.V) by 1 / (V.H)^2 (S = (N.L) P_H F / |L + V|^2): exact enough facing the eye, but that G
// reaches 1 where Smith's falls to 0, when light and eye both graze (forward scattering at a rim): with
// the lobe at the physical strength a side lamp then drew a white streak down the nose's lit side where a
// camera (and the path tracer, GGX with Smith masking) sees a soft sheen (issue 22). So G is Smith's
// height-correlated form for the Beckmann distribution, G = 1 / (1 + Lambda(V) + Lambda(L)) (Heitz 2014),
// Lambda by Walter et al. 2007's rational fit (within 0.2 % of the exact erf form).
#define RS_F0_SKIN 0.028
#define RS_F0_COAT 0.04

float rs_beckmann(float ndoth, float m)
{
    float c2 = ndoth * ndoth;
    float m2 = m * m;
    return exp((c2 - 1.0) / (c2 * m2)) / (m2 * c2 * c2);  // exp(-tan^2(a)/m^2) / (m^2 cos^4(a))
}

// x^5 by multiplication: pow() costs two transcendental ops, and the environment's composite takes
// fifth powers some 25 times a pixel (Schlick per lobe tap, Burley's retro-reflection).
float rs_pow5(float x)
{
    float x2 = x * x;
    return x2 * x2 * x;
}

float rs_schlick(float vdoth, float f0)
{
    float e = rs_pow5(1.0 - vdoth);
    return e + f0 * (1.0 - e);
}

// Smith's Lambda for the Beckmann distribution of roughness m at a direction with cos(theta) = c.
float rs_beckmann_lambda(float c, float m)
{
    float a = c / (m * sqrt(max(1.0 - c * c, 1e-8)));  // 1 / (m tan(theta))
    if (a >= 1.6) return 0.0;
    return (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a);
}

// The lobe towards light L from the factors that depend on the view alone (rs_ksk_view): where one view
// meets many lights (the environment's grid of taps, a lamp's strips) they are worked out once.
float rs_ksk_lobe_seen(vec3 N, vec3 L, vec3 V, float mm, float f0, vec2 view)
{
    float ndotl = dot(N, L);
    vec3 h = L + V;
    float hh = dot(h, h);
    if (ndotl <= 0.0 || hh < 1e-6) return 0.0;
    vec3 H = h * inversesqrt(hh);
    float ndoth = dot(N, H);
    if (ndoth <= 0.0) return 0.0;
    float ph = rs_beckmann(ndoth, mm);
    float f = rs_schlick(clamp(dot(V, H), 0.0, 1.0), f0);
    return max(ph * f / (1.0 + view.x + rs_beckmann_lambda(ndotl, mm)) * view.y, 0.0);
}

// The view's shadowing (Smith's lambda for N.V) and 1 / (4 N.V), for roughness mm = max(m, 0.02). At the
// outline the interpolated normal can turn a little away from the eye; the surface the camera sees there is
// edge-on, where G / N.V tends to a finite limit (about 3.5 / m): N.V is held above 1e-3.
vec2 rs_ksk_view(vec3 N, vec3 V, float mm)
{
    float ndotv = max(dot(N, V), 1e-3);
    return vec2(rs_beckmann_lambda(ndotv, mm), 0.25 / ndotv);
}

float rs_ksk_lobe(vec3 N, vec3 L, vec3 V, float m, float f0)
{
    float mm = max(m, 0.02);
    return rs_ksk_lobe_seen(N, L, V, mm, f0, rs_ksk_view(N, V, mm));
}

float rs_ksk_specular(vec3 N, vec3 L, vec3 V, float m, float rho_s)
{
    return rho_s * rs_ksk_lobe(N, L, V, m, RS_F0_SKIN);
}
