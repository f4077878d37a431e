// skin_brdf.glsl — the Kelemen/Szirmay-Kalos specular BRDF as GPU Gems 3 ch. 14 uses it (METHOD.md):
// Beckmann P_H without the 1/pi (so Weyrich et al.'s rho_s keep their meaning), Schlick Fresnel with
// F0 = 0.028 (skin, n = 1.4), S = (N.L) rho_s max(P_H F / dot(h, h), 0) with h = L + V unnormalised.
// rho_s 1 is the physical lobe; the composite divides Weyrich's rho_s by their mean (RS_RHO_S_PHYSICAL).
// The same lobe with rho_s 1 and F0 0.04 is the clear coat of a gloss (docs/makeup.md).
#define RS_F0_SKIN 0.028
#define RS_F0_COAT 0.04

float rs_beckmann(float ndoth, float m)
{
    float c2 = ndoth * ndoth;
    float m2 = m * m;
    return exp((c2 - 1.0) / (c2 * m2)) / (m2 * c2 * c2);  // exp(-tan^2(a)/m^2) / (m^2 cos^4(a))
}

float rs_schlick(float vdoth, float f0)
{
    float e = pow(1.0 - vdoth, 5.0);
    return e + f0 * (1.0 - e);
}

float rs_ksk_lobe(vec3 N, vec3 L, vec3 V, float m, float f0)
{
    float ndotl = dot(N, L);
    vec3 h = L + V;
    float hh = dot(h, h);
    if (ndotl <= 0.0 || hh < 1e-6) return 0.0;
    vec3 H = h * inversesqrt(hh);
    float ndoth = dot(N, H);
    if (ndoth <= 0.0) return 0.0;
    float ph = rs_beckmann(ndoth, max(m, 0.02));
    float f = rs_schlick(clamp(dot(V, H), 0.0, 1.0), f0);
    return ndotl * max(ph * f / hh, 0.0);
}

float rs_ksk_specular(vec3 N, vec3 L, vec3 V, float m, float rho_s)
{
    return rho_s * rs_ksk_lobe(N, L, V, m, RS_F0_SKIN);
}
