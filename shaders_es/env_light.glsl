// env_light.glsl — light from an HDR environment (src/formats/env.h, docs/env.md): SH9 irradiance for the
// diffuse, the prefiltered radiance mip chain for the specular lobes (split sum: the radiance around the
// mirror direction, prefiltered with the lobe's Beckmann roughness, times the lobe's directional albedo
// from a lookup table; render_env.c). Directions arrive in view space and turn into the environment's
// frame (the face frame, rotated by --env-rotate) through u_env_from_view. The environment's other compact
// lamps are lit and reflected exactly and shadow-mapped: shadow_lookup.glsl comes first.
uniform float u_env_on;             // 0: no environment (key/fill/ambient only)
uniform mat3 u_env_from_view;
uniform vec3 u_env_sh[9];           // irradiance / pi, times the environment's exposure normalisation
uniform vec3 u_env_lamp_dir[3];     // the other compact lamps (render_env.c find_lamps): taken out of the
uniform vec3 u_env_lamp_color[3];   // SH and the map, lit and reflected exactly and shadowed; colour 0
uniform float u_env_lamp_widen[3];  // when unused; half their angular radius, radians
uniform highp sampler2D u_env_map;  // RGB9E5 equirect, level k prefiltered with roughness u_env_m[k]
uniform float u_env_m[8];
uniform int u_env_levels;
uniform float u_env_scale;          // exposure normalisation of the map (the SH carry theirs)
uniform highp sampler2D u_spec_lut; // (N.V, m) -> (A, B): the lobe's directional albedo is F0 A + B
uniform float u_env_one_lookup;     // rs_env_specular: one lookup from this N.V on, the grid below it
uniform float u_env_across;         // 1: the grid has taps across the plane of incidence; 0: along it only
#ifndef RS_HAS_BENT_DECLARED  // splat_decode.glsl declares it too
#define RS_HAS_BENT_DECLARED
uniform float u_has_bent;           // 1: the splats carry bent normals (RS_SPLAT_FLAG_BENT): rs_env_sky's cones
#endif

// The SH's irradiance (the environment without its key light and lamps) in the environment's frame, each
// band scaled: k.x band 0, k.y band 1, k.z band 2 (1, 1, 1: the whole clamped cosine around n).
vec3 rs_env_sh_bands(vec3 n, vec3 k)
{
    // Real SH basis, l <= 2 (Ramamoorthi & Hanrahan 2001 order), the same as rs_env_sh_irradiance.
    vec3 e = u_env_sh[0] * (0.282095 * k.x)
           + (u_env_sh[1] * (0.488603 * n.y) + u_env_sh[2] * (0.488603 * n.z) + u_env_sh[3] * (0.488603 * n.x)) * k.y
           + (u_env_sh[4] * (1.092548 * n.x * n.y) + u_env_sh[5] * (1.092548 * n.y * n.z)
              + u_env_sh[6] * (0.315392 * (3.0 * n.z * n.z - 1.0)) + u_env_sh[7] * (1.092548 * n.x * n.z)
              + u_env_sh[8] * (0.546274 * (n.x * n.x - n.y * n.y))) * k.z;
    return max(e, vec3(0.0));
}

// The SH's irradiance at view-space normal n_view.
vec3 rs_env_irradiance(vec3 n_view) { return rs_env_sh_bands(u_env_from_view * n_view, vec3(1.0)); }

// The SH's irradiance on a surface of normal n_view that sees the sky only through a cone around b_view
// (its bent normal) holding the (cosine-weighted) share ao of its hemisphere: a bent cone (Klehm et al.
// 2014). The cone is the cosine lobe cut at the half-angle t with sin^2 t = ao; each SH band is scaled by
// that cut lobe's zonal coefficient over the whole lobe's: ao (band 0), 1 - cos^3 t (band 1),
// 1 - 3 cos^4 t + 2 cos^2 t (band 2), all 1 in the open. A hollow's light comes from where its opening
// looks (a nostril's wing sees the ground through the opening, the jaw's underside the horizon), and a
// narrow opening lights it more directionally. Without bent normals: the hemisphere around n scaled by ao,
// as before.
vec3 rs_env_sky(vec3 n_view, vec3 b_view, float ao)
{
    if (u_has_bent < 0.5) return rs_env_irradiance(n_view) * ao;
    float c2 = 1.0 - ao;
    return rs_env_sh_bands(u_env_from_view * b_view, vec3(ao, 1.0 - c2 * sqrt(c2), 1.0 - 3.0 * c2 * c2 + 2.0 * c2));
}

// How much of each lamp reaches the view-space point p with normal n_view (its shadow map; 1 unshadowed).
vec3 rs_env_lamp_visibility(vec3 p, vec3 n_view)
{
    vec3 vis = vec3(1.0);
    for (int i = 0; i < 3; i++)
        if (dot(u_env_lamp_color[i], u_env_lamp_color[i]) > 0.0) vis[i] = rs_lamp_shadow(i, p, n_view);
    return vis;
}

// The lamps' irradiance at view-space normal n_view, lamp i seen by vis[i]. Not times the ambient
// occlusion, as the key light is not: the shadow map is their visibility.
vec3 rs_env_lamp_irradiance(vec3 n_view, vec3 vis)
{
    vec3 n = u_env_from_view * n_view, e = vec3(0.0);
    for (int i = 0; i < 3; i++) e += u_env_lamp_color[i] * (max(dot(n, u_env_lamp_dir[i]), 0.0) * vis[i]);
    return e;
}

// Fractional mip level for roughness m: piecewise linear between the levels' roughnesses.
float rs_env_lod(float m)
{
    if (m <= u_env_m[0]) return 0.0;
    for (int k = 1; k < 8; k++) {
        if (k >= u_env_levels) break;
        if (m <= u_env_m[k]) return float(k - 1) + (m - u_env_m[k - 1]) / (u_env_m[k] - u_env_m[k - 1]);
    }
    return float(u_env_levels - 1);
}

// atan(y, x) and acos(x) to within 1e-4 rad (Abramowitz & Stegun 4.4.49 and 4.4.45), a hundredth of the
// map's finest texel: the builtins were most of a tap's cost on the H100 (each specular tap needs both).
float rs_atan2(float y, float x)
{
    float ax = abs(x), ay = abs(y), t = min(ax, ay) / max(max(ax, ay), 1e-30), t2 = t * t;
    float a = t * (0.9998660 + t2 * (-0.3302995 + t2 * (0.1801410 + t2 * (-0.0851330 + t2 * 0.0208351))));
    a = ay > ax ? 1.5707963 - a : a;
    a = x < 0.0 ? 3.1415927 - a : a;
    return y < 0.0 ? -a : a;
}

float rs_acos(float x)
{
    float a = abs(x), r = sqrt(1.0 - min(a, 1.0)) * (1.5707288 + a * (-0.2121144 + a * (0.0742610 - 0.0187293 * a)));
    return x < 0.0 ? 3.1415927 - r : r;
}

// Radiance around the environment-frame unit direction d, from the map's (fractional) level lod.
vec3 rs_env_radiance(vec3 d, float lod)
{
    // docs/env.md: phi = atan(x, z) from forward towards the subject's left, theta from up.
    vec2 uv = vec2(rs_atan2(d.x, d.z) * 0.15915494 + 0.5, rs_acos(d.y) * 0.31830989);
    return textureLod(u_env_map, uv, lod).rgb * u_env_scale;
}

// Directional albedo of a Kelemen/Szirmay-Kalos lobe with rho_s 1 and Fresnel F0, for N.V and m.
float rs_env_lobe_albedo(float ndotv, float m, float f0)
{
    vec2 ab = texture(u_spec_lut, vec2(clamp(ndotv, 0.0, 1.0), clamp(m, 0.0, 1.0))).rg;
    return f0 * ab.x + ab.y;
}

// Environment light reflected by the lobe (N, m, F0) towards V (split sum): the lobe's albedo (from the
// table, which integrates the lobe over the upper hemisphere only) times the mean radiance the lobe sees.
// The prefiltered map averages an isotropic lobe around R (as if N = V = R: a Gaussian of about sqrt(2) m
// per axis). Seen obliquely the real lobe is narrower across the plane of incidence (a half vector tilted
// by d across turns l by 2 (V.h) d, not 2 d), skewed by Fresnel and cut by the surface's horizon; the
// isotropic lookup caught lamps beside and below the reflection (the studio's side lamps: issue 22, up to
// +400 % at grazing on a sphere). So the mean is taken over a grid of narrower prefiltered lobes (filtered
// importance sampling, Colbert & Krivanek, GPU Gems 3 ch. 20), spaced for a Gaussian of sqrt(2) m along
// the plane of incidence and sqrt(2) m (N.V) across (5 taps along it, binomial weights [1 4 6 4 1] / 16:
// variance spacing^2; 3 across, [1 2 1] / 4: spacing^2 / 2; plus the taps' own), each tap reweighted by
// the real lobe over that Gaussian, so the taps below the horizon drop out (the horizon fade of Russell
// 2015, applied across the lobe) and the rest carry the mean. A compact lamp falls between taps spaced
// much wider than their own spread (3 x 3 taps of 0.6 of the lobe: office, studio +-25 % on a sphere), so
// the taps' own spread is 0.75 of the lobe's across it: 3 taps across are then no wider apart than that, and
// along the plane 5 still resolve the horizon at grazing (test_env_specular: every band within 12 %; 5 x 5
// gave 8 % at two thirds of the cost). Where the surface faces the eye (N.V >= 0.6, most of a face in
// view) one lookup does (below): the grid's 15 taps there were two thirds of the environment's cost on
// llvmpipe and half of it on an H100 (the warps that hold one grid pixel run 15 taps), and bought under
// 3 % in any band of the sphere (from 0.8: the same bands within 1.5 %, the face's dE against the path
// tracer the same or lower). From 0.45 it would save llvmpipe another ~3 ms a 512^2 frame, but the rim
// pixels between lose the horizon's cut, whose taps above it are the brighter sky: the contour band
// against the path tracer fell 0.0005 (studio 3/4 to 0.9997, under issue 22's goal of 1).
// The mobile pipeline (render_kit.h, docs/mobile.md) saves both ways: one lookup from N.V 0.55 and the
// 5 taps along the plane of incidence only (across, the taps' own spread, 0.75 of the lobe's, stands for
// the lobe's): ~3.5 ms of a 512^2 frame on llvmpipe; its frames 52-67 dB from what it drew before.
vec3 rs_env_specular(vec3 N_view, vec3 V_view, float m, float f0)
{
    // All in the environment's frame (a rotation of view space: the lobe's dot products are kept).
    vec3 N = u_env_from_view * N_view, V = u_env_from_view * V_view;
    float ndotv = max(dot(N, V), 1e-4);
    vec3 R = reflect(-V, N);
    float across = clamp(ndotv, 0.0, 1.0);    // the lobe's width across the plane of incidence, relative
    // Facing the eye the lobe is nearly round and far above the horizon, and one lookup of its whole
    // spread (along and across averaged) does (from u_env_one_lookup); over the 0.15 of N.V below that
    // the grid's spread eases into that one lookup's, so its taps close in on R and no seam shows where
    // their number drops.
    float s1 = sqrt(0.5 + 0.5 * across * across);
    float e = smoothstep(u_env_one_lookup - 0.15, u_env_one_lookup, across);
    float s = mix(max(0.75 * across, 0.2), s1, e);  // the taps' own spread, relative to the lobe's
    float lod = rs_env_lod(s * m);
    // One lookup: the tap at R, whose weight is the lobe over itself (1).
    if (across >= u_env_one_lookup) return rs_env_radiance(R, lod) * rs_env_lobe_albedo(ndotv, m, f0);
    // t1: in the plane of incidence, from R towards N; t2 across it.
    vec3 t1 = N - R * dot(N, R);
    float l1 = dot(t1, t1);
    t1 = l1 > 1e-8 ? t1 * inversesqrt(l1) : (abs(R.y) < 0.9 ? normalize(cross(R, vec3(0.0, 1.0, 0.0)))
                                                            : normalize(cross(R, vec3(1.0, 0.0, 0.0))));
    vec3 t2 = cross(R, t1);
    float sigma = 1.4142 * max(m, 0.02);      // the lobe's spread along the plane, radians
    // The variances the grid stands for, relative to sigma^2, and the taps' spacing along and across.
    float va = mix(1.0, s1 * s1, e), vc = mix(across * across, s1 * s1, e);
    float d1 = min(sigma * sqrt(max(va - s * s, 0.0)), 0.6);
    float d2 = min(sigma * sqrt(2.0 * max(vc - s * s, 0.0)), 0.6);
    float g1 = d1 * d1 / (2.0 * sigma * sigma * va), g2 = d2 * d2 / (2.0 * sigma * sigma * max(vc, 1e-4));
    // Taps at a spacing of 0 fall on the centre's direction and leave the weighted mean as it is: a row or
    // column of them is skipped (at grazing, N.V <= 0.2, the grid has no width across).
    int na = d1 > 0.0 ? 2 : 0, nc = d2 > 0.0 && u_env_across > 0.5 ? 1 : 0;
    // The lobe's factors that depend on the view alone, once for all the taps, and 1 / the lobe at R.
    float mm = max(m, 0.02);
    vec2 view = rs_ksk_view(N, V, mm);
    float inv_fc = 1.0 / max(rs_ksk_lobe_seen(N, R, V, mm, f0, view), 1e-20);
    // tan(i d1) for i = 1, 2 (tan(2x) = 2 tan x / (1 - tan^2 x); d1 <= 0.6), tan(j d2) = j tan(d2) for
    // j in -1..1, and the weights' Gaussian factors exp(i^2 g1) exp(j^2 g2) as powers of two exps.
    float a1 = tan(d1), a2 = 2.0 * a1 / (1.0 - a1 * a1), b = tan(d2);
    float e1 = exp(g1), e4 = e1 * e1, eg2 = exp(g2);
    e4 *= e4;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    // Offsets and weights from the loop counters alone: a small local array indexed by them cost the H100
    // an eighth of the environment's time (it went to local memory). The bounds vary per pixel (na, nc), so
    // no compiler unrolls the loops (constant 5 x 3 bounds, unrolled by Mesa at this function's three call
    // sites, tripled llvmpipe's compile of the composite).
    for (int i = -na; i <= na; i++) {
        int ai = abs(i);
        float a = float(sign(i)) * (ai == 2 ? a2 : float(ai) * a1);
        // Binomial weights along ([1 4 6 4 1]) times the Gaussian's factor.
        float wi = ai == 2 ? e4 : ai == 1 ? 4.0 * e1 : 6.0;
        for (int j = -nc; j <= nc; j++) {
            vec3 l = normalize(R + t1 * a + t2 * (float(j) * b));
            float f = rs_ksk_lobe_seen(N, l, V, mm, f0, view);
            if (f <= 0.0) continue;
            // Times the binomial weight across ([1 2 1]) and the real lobe over the Gaussian the grid
            // stands for.
            float w = wi * (j == 0 ? 2.0 : eg2) * (f * inv_fc);
            sum += rs_env_radiance(l, lod) * w;
            wsum += w;
        }
    }
    vec3 L = wsum > 0.0 ? sum / wsum : vec3(0.0);
    return L * rs_env_lobe_albedo(ndotv, m, f0);
}

// The lamps' reflection (the map has them taken out, render_env.c lamp_free_levels): each lamp as the key
// light is drawn, a directional light whose angular size widens the lobe (roughness in quadrature), times
// what its shadow map lets through (vis). A lamp is a disc, not a point: one that straddles the surface's
// horizon still shows its upper part, and a lobe seen at grazing makes that bright (a sphere's rim under
// studio's back lamp read -49 % of the exact integral when the lamp ended with its centre at the horizon).
// There the disc is taken as 4 strips parallel to the horizon (chord-length weights), those above it
// reflected. The pixel sees a range of normals (spread: radians, the normal's change across the pixel, a
// few degrees at a rim, as much as a lamp's radius), so the horizon sweeps over that much more of the lamp.
// The shadow map knows nothing of a lamp behind the surface's plane (vis holds the attached shadow, 0
// there), so such a lamp's upper part counts as lit.
vec3 rs_env_lamp_specular(vec3 N_view, vec3 V_view, float m, float f0, vec3 vis, float spread)
{
    vec3 N = u_env_from_view * N_view, V = u_env_from_view * V_view, s = vec3(0.0);
    for (int i = 0; i < 3; i++) {
        if (dot(u_env_lamp_color[i], u_env_lamp_color[i]) <= 0.0) continue;  // unused
        vec3 L = u_env_lamp_dir[i];
        float w = u_env_lamp_widen[i], e = dot(N, L);  // e: ~ the lamp's centre's elevation
        float r = sqrt(4.0 * w * w + spread * spread);  // its radius (2 w), and the normals' sweep
        if (e <= -r) continue;
        float mw = max(sqrt(m * m + w * w), 0.02), f = 0.0, fw = 0.0;
        vec2 view = rs_ksk_view(N, V, mw);
        int strips = e < r ? 4 : 1;  // a bound per pixel: no compiler unrolls this at each call site
        for (int k = 0; k < strips; k++) {
            float t = strips == 1 ? 0.0 : (float(k) - 1.5) * 0.5, wt = sqrt(1.0 - t * t);
            vec3 Ls = normalize(L + N * (t * r));
            fw += wt;
            if (dot(N, Ls) > 0.0) f += wt * rs_ksk_lobe_seen(N, Ls, V, mw, f0, view);
        }
        float v = min(vis[i] + (1.0 - rs_attached(e)), 1.0);  // rs_lamp_shadow's attached shadow undone
        s += u_env_lamp_color[i] * (f / fw * v);
    }
    return s;
}
