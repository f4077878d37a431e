// makeup.glsl — composes the makeup layer over the base skin (paper eq. 2), #include'd by the
// attribute-splat vertex shader (GLSL ES 3.00; no #version here). CPU mirror: rs_makeup_apply_cpu in
// src/makeup/makeup.c, which must do the same operations in the same order.
//
// The record (rs_makeup_gpu, one per splat, uploaded as a uvec3 attribute):
//   rec.x = r | g << 8 | b << 16 | colour_i << 24     cosmetic colour Cp (sRGB8), colour intensity I
//   rec.y = m | rho_s << 8 | spec_i << 16 | detail << 24   finish target, finish intensity,
//                                                        skin detail ratio L_base / L_local (q/128)
//   rec.z = coat | shimmer << 8 | coverage << 16      finish layers (clear coat, flakes), with spec_i;
//                                                     coverage (pigment opacity), with colour_i
// All zero = no makeup: the base is returned untouched.

// The face's original colour range (linear RGB, per channel): the product colour is clamped into it,
// so makeup never leaves the colours the face already has (rs_makeup_get_uniforms).
uniform vec3 rs_makeup_range_lo;
uniform vec3 rs_makeup_range_hi;

vec3 rs_makeup_srgb_to_linear(vec3 c)
{
    vec3 lo = c / 12.92;
    vec3 hi = pow((c + 0.055) / 1.055, vec3(2.4));
    return mix(hi, lo, vec3(lessThanEqual(c, vec3(0.04045))));  // IEC 61966-2-1: linear at and below
}

void rs_makeup_apply(uvec3 rec, inout vec3 albedo_lin, inout float m, inout float rho_s, out float coat,
                     out float shimmer)
{
    float ci = float(rec.x >> 24u) / 255.0;
    if (ci > 0.0) {
        vec3 cp = rs_makeup_srgb_to_linear(vec3(uvec3(rec.x, rec.x >> 8u, rec.x >> 16u) & 255u) / 255.0);
        // A sheer product's colour is held in the face's colour range and the skin texture shows through
        // it; an opaque one (coverage 1) keeps its own colour and hides the texture.
        float cov = float((rec.z >> 16u) & 255u) / 255.0;
        float detail = float(rec.y >> 24u) / 128.0 * (1.0 - cov) + cov;
        vec3 held = clamp(cp, rs_makeup_range_lo, rs_makeup_range_hi);
        vec3 pig = min((held * (1.0 - cov) + cp * cov) * detail, vec3(1.0));
        albedo_lin = albedo_lin * (1.0 - ci) + pig * ci;  // eq. (2): C = Cb (1 - I) + Cp I
    }
    float si = float((rec.y >> 16u) & 255u) / 255.0;
    // Bare skin has neither layer: they are the product's, weighted by the finish intensity.
    coat = float(rec.z & 255u) / 255.0 * si;
    shimmer = float((rec.z >> 8u) & 255u) / 255.0 * si;
    if (si > 0.0) {
        // The finish blends over the skin's measured m / rho_s the same way, with its own intensity.
        m = m * (1.0 - si) + (float(rec.y & 255u) / 255.0) * si;
        rho_s = rho_s * (1.0 - si) + (float((rec.y >> 8u) & 255u) / 255.0) * si;
    }
}
