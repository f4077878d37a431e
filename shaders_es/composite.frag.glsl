#version 300 es
// composite.frag.glsl — stage 5: normalises the accumulated attributes (albedo A, normal N, m, rho_s,
// ambient occlusion, clear coat, flakes), evaluates the specular S per pixel (Kelemen/Szirmay-Kalos: the
// shadowed key light, the unshadowed fill, the environment's prefiltered radiance and its other lamps,
// shadowed), reads the diffuse D
// of stage 4, and composes F = A (D + S) (paper eq. 1) or F = A D + S, then adds the makeup's untinted
// clear coat and its flakes; then exposure, the filmic curve (or a clamp) and the sRGB encoding. Also the
// debug views (render.h rs_render_mode). The makeup's fine layer (narrow brushes) is composed here per
// pixel, over the splat layer's A, m, rho_s, coat and flakes (makeup_fine.glsl).
precision highp float;
precision highp int;
#define RS_NEEDS_VISIBLE_POINT 1
#include "splat_ray.glsl"
#include "shadow_lookup.glsl"
#include "skin_brdf.glsl"
#include "env_light.glsl"
#include "bounce.glsl"
#include "tangent_basis.glsl"
#include "makeup_fine.glsl"
#include "skin_seen.glsl"

// Same numbering as rs_render_mode in render.h.
#define MODE_FULL 0
#define MODE_ALBEDO 1
#define MODE_DIFFUSE 2
#define MODE_SPECULAR 3
#define MODE_NORMALS 4
#define MODE_REGIONS 5
#define MODE_SHADOW 6
#define MODE_LOD 7
#define MODE_IRRADIANCE 8

uniform highp sampler2D u_attr1;
uniform highp sampler2D u_attr2;
uniform highp sampler2D u_attr3;
uniform float u_bent_scale;     // RT3's weights relative to RT0's (attribute.frag.glsl)
uniform highp usampler2D u_reflect;  // the face blocking reflections, half size (reflect.frag.glsl)
uniform int u_mode;
uniform int u_physical;         // 1: F = A D + S
uniform float u_exposure;
uniform float u_linear_output;  // 1: no sRGB encoding (tests of the composite's algebra)
uniform vec3 u_background;      // already in the output encoding
uniform float u_rho_s_scale;
uniform vec3 u_key_dir;
uniform vec3 u_key_color;
uniform vec3 u_fill_dir;
uniform vec3 u_fill_color;
uniform vec3 u_ambient;
uniform float u_key_widen;      // the key light's angular radius / 2: added in quadrature to m (area light)
uniform int u_tonemap;          // 0: filmic, 1: clamp (the paper's figures)
uniform mat4 u_inv_view;        // view -> model (flakes are fixed on the surface)
uniform float u_flake_size;     // model units
uniform float u_contour_reach;  // view units (20 mm): a surface this close behind a contour hides its rim
uniform int u_outline_coverage; // 1: the outline's 3x3 coverage here; 0: the edges pass anti-aliases it
uniform highp usampler3D u_body; // the cloud as a grid (render_env.c rs_render_env_body): albedo, normal
uniform vec3 u_body_lo;          // its corner, model units
uniform float u_body_cell;       // its cell size, model units
uniform int u_body_n;            // its side, cells
uniform float u_body_on;         // 1: reflections that leave the frame march it (the reference pipeline)

out vec4 o_color;

// ACES filmic fit (Narkowicz 2015): a toe, a soft shoulder that keeps highlights from clipping flat.
vec3 filmic(vec3 x)
{
    return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Integer hash (a PCG step) of a flake cell: three uniform numbers in 0..1 and one for presence.
vec4 flake_hash(ivec3 c)
{
    uvec3 v = uvec3(c) * uvec3(1664525u, 1013904223u, 2654435761u);
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z; v.y += v.z * v.x; v.z += v.x * v.y;
    uint w = v.x ^ v.y ^ v.z;
    return vec4(v, w * 747796405u) / 4294967295.0;
}

// The flakes of a shimmer finish: pearl pigment, tiny mirrors (u_flake_size) lying in the film, tilted at
// random about the surface normal (Beckmann spread FLAKE_TILT, each with its own lobe of FLAKE_M), over
// FLAKE_FILL of the surface at full shimmer. They are smaller than a pixel, so a pixel shows their sum over
// its footprint on the surface (a filtered glint, not a pixel-sized mirror): the mean, a broad sheen lobe
// of roughness sqrt(tilt^2 + m^2) that catches the light, times the count of flakes that happen to mirror
// the key light over the count expected. That count is Poisson(lambda), lambda = the flakes in the
// footprint x the share of their orientations that see the key, drawn from a hash of the footprint's cell
// on the surface and of the half vector: fixed on the face, other flakes as the light or the face turns
// (sparkle). One flake adds mean / lambda: a fine glint where the flakes are many, nothing in a full-face
// view but the sheen.
#define FLAKE_TILT 0.3
#define FLAKE_M 0.08
#define FLAKE_FILL 0.35
#define FLAKE_REFLECTANCE 0.35  // a pearl (mica / TiO2) flake's reflectance at its colour
vec3 flakes(vec3 p, vec3 N, vec3 V, vec3 tint, float shadow, float ao, vec3 vis, float spread, float amount)
{
    float cover = FLAKE_FILL * amount;
    if (cover <= 0.0) return vec3(0.0);
    float me = sqrt(FLAKE_TILT * FLAKE_TILT + FLAKE_M * FLAKE_M);
    float w2 = u_key_widen * u_key_widen;
    // The key light over all flake orientations (unit reflectance, per unit of cover).
    float key = rs_ksk_lobe(N, u_key_dir, V, sqrt(me * me + w2), 1.0) * shadow;
    float g = 1.0;
    if (key > 0.0) {
        // The share of flakes that mirror the key: the orientation density at the half vector over one
        // aligned flake's peak (Beckmann peak 1 / m^2).
        vec3 H = normalize(u_key_dir + V);
        float share = min(rs_beckmann(max(dot(N, H), 1e-3), sqrt(me * me + w2)) * (FLAKE_M * FLAKE_M + w2), 1.0);
        // The pixel's footprint on the surface (view units = model units) and the flakes in it.
        float s = 2.0 * length(p) / (u_proj[1][1] * u_viewport.y);
        float area = s * s / max(dot(N, V), 0.2);
        float lambda = cover * area / (0.785398 * u_flake_size * u_flake_size) * share;
        // Cells of the footprint's size on the surface (a power of two of the flake size: stable while the
        // view moves by less than a zoom step) hold one draw each.
        float level = floor(log2(max(s / u_flake_size, 1.0)));
        vec3 pm = (u_inv_view * vec4(p, 1.0)).xyz;
        // Which flakes mirror the key depends on where the half vector points: one draw per bin of it (on
        // the face, a flake lobe wide), so when the light or the face turns other flakes glint.
        ivec3 hb = ivec3(floor(mat3(u_inv_view) * H / (FLAKE_M + u_key_widen)));
        vec4 h = flake_hash(ivec3(floor(pm / (u_flake_size * exp2(level)))) + ivec3(int(level) * 7919) + hb * 104729);
        float n;
        if (lambda < 24.0) {
            // Poisson by its inverse CDF.
            float pk = exp(-lambda), cdf = pk;
            n = 0.0;
            for (int k = 1; k < 64 && h.w > cdf; k++) {
                pk *= lambda / float(k);
                cdf += pk;
                n += 1.0;
            }
        } else {
            // Many flakes: the normal approximation (Box-Muller).
            n = lambda + sqrt(lambda) * sqrt(-2.0 * log(max(h.x, 1e-7))) * cos(6.2831853 * h.y);
        }
        g = lambda > 1e-6 ? max(n, 0.0) / lambda : 0.0;
    }
    vec3 s3 = u_key_color * (key * g);
    if (u_env_on > 0.5) s3 += (rs_env_specular(N, V, me, 1.0) + rs_env_lamp_specular(N, V, me, 1.0, vis, spread)) * ao;
    return s3 * (tint * (FLAKE_REFLECTANCE * cover));
}

// Burley's diffuse retro-reflection (Burley 2012, sec. 5.3; as a separate surface lobe beside the
// subsurface, Burley 2015 sec. 2.3): a rough dielectric throws light back towards where it came from, the
// more the more grazing the view or the light, RR (F_L + F_V + F_L F_V (RR - 1)) N.L / pi with
// F = (1 - cos)^5 and RR = r (1 + L.V), r the roughness (sqrt of the lobe's m, as tools/truth/ maps it).
// Lambert has no such term, and that was the contour band's darkness (issue 22): the path tracer's skin
// (Cycles 3.4's Principled BSDF, random-walk subsurface plus this lobe, no entry Fresnel) brightened by
// 1.23x over the same scene with Lambert's exit at N.V 0.2, 1.10x at 0.4, <= 2 % beyond 0.6, on both the
// lit and unlit sides, so rouge's whole silhouette ring (skull, jaw, the nose's sides) drew 10-25 % darker.
// It is a surface term: per pixel, times the albedo, not scattered under the skin. A light of colour e
// (its irradiance at normal incidence) from direction l (N, l, V in one frame):
vec3 burley_retro_light(vec3 e, vec3 N, vec3 l, vec3 V, float r, float fv)
{
    float nl = dot(N, l);
    if (nl <= 0.0) return vec3(0.0);
    float fl = rs_pow5(1.0 - nl), rr = r * (1.0 + dot(l, V));
    return e * (nl * rr * (fl + fv + fl * fv * (rr - 1.0)));
}

// The retro-reflection of the environment's SH light (smooth): its F_V term, which carries the grazing
// view's brightening (the F_L terms, ~5 % of the SH light at any view, are left out). Its integral of
// L (N.l) (1 + l.V) is taken as the SH irradiance at the normal bent halfway to the eye (the (1 + l.V)
// weight leans the cosine lobe towards V) times 1 + 2/3 N.V (exact under uniform light); with the ambient
// occlusion as the SH irradiance has it.
vec3 burley_retro_env(vec3 N, vec3 V, float r, float fv, float ao)
{
    return rs_env_irradiance(normalize(N + V)) * (ao * r * fv * (1.0 + 0.6667 * max(dot(N, V), 0.0)));
}

vec3 linear_to_srgb(vec3 c)
{
    c = clamp(c, 0.0, 1.0);
    return mix(1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, c * 12.92, step(c, vec3(0.0031308)));  // linear at and below
}

// Image-space hole filling: a pixel that no disk covered while at least 6 of its 8 neighbours are covered
// is a gap between splats (a sparse spot of a random sampling, a crease seen edge-on), not background.
// The attribute targets hold weighted sums, so adding the neighbours' sums and normalising once gives
// their weighted mean; the surface point and D are the neighbours' means.
bool fill_hole(ivec2 px, out vec4 t0, out vec4 t1, out vec4 t2, out vec4 t3, out vec3 p, out vec4 D)
{
    t0 = t1 = t2 = t3 = vec4(0.0);
    p = vec3(0.0);
    D = vec4(0.0);
    ivec2 hi = ivec2(u_viewport) - 1;
    // Quick reject (most background pixels): with 3 of the 4 edge neighbours uncovered, at most 5 of 8
    // can be covered.
    int open = 0;
    for (int i = 0; i < 4; i++) {
        ivec2 q = clamp(px + ivec2(i == 0 ? -1 : i == 1 ? 1 : 0, i == 2 ? -1 : i == 3 ? 1 : 0), ivec2(0), hi);
        if (texelFetch(u_attr0, q, 0).a <= u_min_weight) open++;
    }
    if (open >= 3) return false;
    int k = 0;
    for (int i = 0; i < 9; i++) {
        if (i == 4) continue;
        ivec2 q = clamp(px + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), hi);
        vec4 a = texelFetch(u_attr0, q, 0);
        vec3 pq;
        if (a.a <= u_min_weight || !rs_visible_point_at(q, pq)) continue;
        t0 += a;
        t1 += texelFetch(u_attr1, q, 0);
        t2 += texelFetch(u_attr2, q, 0);
        t3 += texelFetch(u_attr3, q, 0);
        p += pq;
        D += texelFetch(u_diffuse, q, 0);
        k++;
    }
    p /= max(float(k), 1.0);
    D /= max(float(k), 1.0);
    return k >= 6;
}

// The outline's coverage where the edges pass does not take it (u_outline_coverage: the sharp_contours
// views; edges.frag.glsl follows the outline along its runs, which a 3x3 rule cannot): a face pixel that
// touches the background (in its 3x3 neighbourhood) is drawn
// with coverage n / 8 for its n face pixels there (itself included), the background showing through the
// rest: a straight edge's last pixel at 3/4, the outer corner of a stair step at 1/2, an inner corner
// whole, a stray pixel outside the edge gone. A mask pixel's centre is on the face, so the edge runs
// between it and the next centre out: its coverage is 1/2 to 1, 3/4 on average on a straight edge (the
// box filter's (n - 1) / 8, 5/8 there, drew a dark ring half a pixel inside the path tracer's outline,
// issue 22: the silhouette's first full pixel at 0.50 of its luminance in studio, 0.55 now). The mask is binary and
// stable from frame to frame, so the edge is smooth without the speckle the splats' own (noisy) weights
// give; pixels with no background near are untouched.
// How much of the sky a pixel seen edge-on still reflects. At a contour in front of more face (the
// nostril rim over the upper lip, an ear over the neck) the grazing mirror direction runs into that
// surface close behind, not into the environment; the environment's grazing Fresnel reflection then drew
// a bright 1-px outline along such contours. The surface behind is looked for across the contour, a few
// pixels along the screen projection of the normal: one that lies behind this point and faces the eye
// (the same surface curving away stays edge-on there: a cheek's grazing sheen is kept), within
// u_contour_reach, occludes the rim (fully up to half the reach; hit: its pixel, whose skin the rim
// reflects instead, skin_at); background or a far surface leaves it open (a real rim light).
float contour_open(vec3 p, vec3 N, float ndotv, float edge_on, inout ivec2 hit)
{
    if (edge_on <= 0.0 || dot(N.xy, N.xy) < 1e-6) return 1.0;
    vec2 d = normalize(N.xy);
    ivec2 hi = ivec2(u_viewport) - 1;
    float gap = 1e9;
    for (int k = 1; k <= 4; k++) {
        vec2 f = gl_FragCoord.xy + d * float(k);
        vec3 q;
        if (!rs_visible_point_at(rs_depth_pixel(f), q)) continue;
        vec4 a = texelFetch(u_attr0, clamp(ivec2(f), ivec2(0), hi), 0);
        if (a.a <= u_min_weight) continue;
        vec3 nq = normalize(texelFetch(u_attr1, clamp(ivec2(f), ivec2(0), hi), 0).xyz / a.a * 2.0 - 1.0);
        float behind = p.z - q.z;
        if (behind > 0.05 * u_contour_reach && dot(nq, normalize(-q)) > ndotv + 0.25 && behind < gap)
            gap = behind, hit = clamp(ivec2(f), ivec2(0), hi);
    }
    return 1.0 - edge_on * (1.0 - smoothstep(0.5 * u_contour_reach, u_contour_reach, gap));
}

// How many pixels a millimetre at view-space point p spans (u_contour_reach is 20 mm).
float pixels_per_mm(vec3 p)
{
    return u_proj[1][1] * 0.5 * u_viewport.y / -p.z * u_contour_reach / 20.0;
}

// Whether the face itself blocks the mirror direction R (reflect.frag.glsl's march, at half size),
// averaged over the pixel and 8 around it at 1 mm (at least 4 px) that lie on its surface (within 1 mm of
// its tangent plane and 5 mm of it) and mirror about its way: one pixel's march ends in a sharp edge where
// its step's projection crosses a blocker's contour, a line that the lobe's width blurs. open: the share
// the march left open; left: the march that counts most ran off the frame; blocked: the skin the blocked
// share sees.
void reflection_near(ivec2 px, vec3 p, vec3 N, vec3 R, out float open, out bool left, out vec3 blocked)
{
    open = 1.0, blocked = vec3(0.0), left = false;
    // 1 mm here in pixels, within 4..16 px (2..8 of the march's).
    float mm = clamp(pixels_per_mm(p), 4.0, 16.0);
    vec2 half_size = vec2(textureSize(u_reflect, 0));
    float w_sum = 0.0, o_sum = 0.0, w_left = 0.0;
    // The samples' rays: the unprojected point at the near plane is affine in the pixel's NDC (h0 + hx x
    // + hy y; its w cancels), and the 8 around turn by 45 degrees each. The sines and cosines and a matrix
    // per sample were half of this average's cost on llvmpipe.
    vec3 h0 = (u_inv_proj * vec4(0.0, 0.0, -1.0, 1.0)).xyz, hx = u_inv_proj[0].xyz, hy = u_inv_proj[1].xyz;
    const float c45 = 0.70710678;
    vec2 dir = vec2(c45, -c45) * mm;  // sample 7's offset, at 315 degrees
    ivec2 hi = ivec2(u_viewport) - 1;
    for (int i = 8; i >= 0; i--) {  // the pixel's own sample first, then 7 down to 0
        ivec2 t = clamp(px + (i == 8 ? ivec2(0) : ivec2(round(dir))), ivec2(0), hi) / 2;
        if (i < 8) dir = c45 * vec2(dir.x + dir.y, dir.y - dir.x);  // 45 degrees back
        uvec4 r = texelFetch(u_reflect, t, 0);
        if (r.x == 0u) continue;  // no surface there
        float o = unpackHalf2x16(r.z).y;
        bool l = o >= 2.0;
        o -= l ? 2.0 : 0.0;
        // Its point: on the ray through the full-size pixel at its centre, at its depth.
        vec2 ndc = (floor((vec2(t) + 0.5) / half_size * u_viewport) + 0.5) / u_viewport * 2.0 - 1.0;
        vec3 h = h0 + hx * ndc.x + hy * ndc.y;
        vec3 s = h * (uintBitsToFloat(r.x) / h.z), d = s - p;
        if (abs(dot(d, N)) > 0.05 * u_contour_reach || dot(d, d) > 0.0625 * u_contour_reach * u_contour_reach)
            continue;
        // Its mirror direction within the lobe's width of this one's (at a rim it turns fast).
        vec3 nq = rs_from_octahedral(unpackSnorm2x16(r.w));
        float w = smoothstep(0.95, 0.99, dot(reflect(normalize(s), nq), R));
        // The nearest march counts a little whatever it mirrors: at a rim, where the normal turns fast
        // and no other does, it decides alone.
        if (i == 8) w = max(w, 0.01);
        o_sum += o * w, w_sum += w;
        if (w > w_left) w_left = w, left = l;
        blocked += vec3(unpackHalf2x16(r.y), unpackHalf2x16(r.z).x) * w;
    }
    if (w_sum == 0.0) return;
    open = o_sum / w_sum, blocked /= w_sum;
}

// What a reflection that runs off the frame meets (under the jaw: the neck, shoulders and chest the frame
// cuts off, which the path tracer's skin mirrors at grazing angles, issue 22): the mirror ray from the
// view-space point p along R is marched through the cloud's grid (cells of ~5 mm, from 2.5 cells out: past
// the point's own surface) to the first cell of surface that faces it. False: it leaves the cloud. L: that
// skin's radiance, its albedo lit as the splats are (SH, the key and the lamps, through their shadow maps),
// without the skin's own occlusion or bounce.
bool body_seen(vec3 p, vec3 R, out vec3 L)
{
    L = vec3(0.0);
    vec3 o = ((u_inv_view * vec4(p, 1.0)).xyz - u_body_lo) / u_body_cell, d = mat3(u_inv_view) * R;
    float t = 2.5;
    for (int k = 0; k < 2 * u_body_n; k++, t += 0.7) {
        ivec3 q = ivec3(floor(o + d * t));
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, ivec3(u_body_n)))) return false;
        uvec2 w = texelFetch(u_body, q, 0).rg;
        if (w.x < 0x80000000u) continue;
        vec3 n = rs_from_octahedral(unpackSnorm2x16(w.y));  // coded as a splat record's normal
        if (dot(n, d) > -0.1) continue;  // a cell seen from behind: the ray runs along or out of that surface
        vec3 a = vec3(float((w.x >> 20) & 1023u), float((w.x >> 10) & 1023u), float(w.x & 1023u)) / 1023.0;
        vec3 nv = normalize(n * mat3(u_inv_view)), h = p + R * (t * u_body_cell);
        L = a * (rs_env_irradiance(nv) + u_key_color * (max(dot(nv, u_key_dir), 0.0) * rs_shadow(h, nv))
                 + rs_env_lamp_irradiance(nv, rs_env_lamp_visibility(h, nv)));
        return true;
    }
    return false;
}

// What lights the walls of this point's hollow, where the camera sees them: the irradiance (D, as skin_at
// reads it) of the visible surface within SURROUND_MM that lies above the point's tangent plane and faces
// it, u_surround_samples points on a sunflower spiral even over the disk, each weighted by how squarely the
// two see each other and faded out over the last half of the reach (a sample stepping across a hard cut
// showed as a crease in the light). w: the weights' sum (0: no wall seen; the face's mean front light
// returned).
// The bounce cubic (bounce.glsl) lit every hollow with that mean: a nostril's inside like a sunlit cheek,
// the shadowed side's ear like the lit side's (issue 22: the darkest tenth of a front view 1.00-1.09 of the
// path tracer's on the side the key does not reach, 1.00-1.05 with this).
#define SURROUND_MM 12.0
uniform int u_surround_samples;  // 16 (reference); 0: the mean light (mobile)
vec3 surround_seen(ivec2 px, vec3 p, vec3 N, out float w)
{
    vec3 sum = vec3(0.0);
    w = 0.0;
    float r_px = pixels_per_mm(p) * SURROUND_MM, reach = SURROUND_MM * u_contour_reach / 20.0;
    ivec2 hi = ivec2(u_viewport) - 1;
    for (int i = 0; i < u_surround_samples; i++) {
        float a = float(i) * 2.3999632, r = max(r_px * sqrt((float(i) + 0.5) / float(u_surround_samples)), 1.0);
        ivec2 q = clamp(px + ivec2(round(vec2(cos(a), sin(a)) * r)), ivec2(0), hi);
        vec3 pq;
        if (!rs_visible_point_at(q, pq)) continue;
        vec4 t = texelFetch(u_attr0, q, 0);
        if (t.a <= u_min_weight) continue;
        vec3 d = pq - p;
        float l = length(d);
        if (l < 1e-6 || l >= reach) continue;
        d /= l;
        vec3 nq = normalize(texelFetch(u_attr1, q, 0).xyz / t.a * 2.0 - 1.0);
        float k = max(dot(N, d), 0.0) * max(-dot(nq, d), 0.0) * (1.0 - smoothstep(0.5 * reach, reach, l));
        if (k <= 0.0) continue;
        vec4 dq = texelFetch(u_diffuse, q, 0) * u_diffuse_scale;
        sum += k * (dq.rgb + u_delta_weight * dq.a);
        w += k;
    }
    return w > 0.0 ? sum / w : u_env_surround;
}

// How far the normal turns across this pixel (radians): the larger of its changes to the next pixel right
// and up, where those are surface (at a rim the pixel spans a few degrees of a curved surface).
float normal_spread(ivec2 px, vec3 N)
{
    float d = 0.0;
    for (int i = 0; i < 2; i++) {
        ivec2 q = min(px + ivec2(1 - i, i), ivec2(u_viewport) - 1);
        vec4 a = texelFetch(u_attr0, q, 0);
        if (a.a <= u_min_weight) continue;
        vec3 nq = normalize(texelFetch(u_attr1, q, 0).xyz / a.a * 2.0 - 1.0);
        d = max(d, rs_acos(clamp(dot(N, nq), -1.0, 1.0)));
    }
    return d;
}

bool uncovered(ivec2 q)
{
    return texelFetch(u_attr0, clamp(q, ivec2(0), ivec2(u_viewport) - 1), 0).a <= u_min_weight;
}

// Background proper: uncovered, and not a gap that fill_hole fills (at least 6 of 8 neighbours covered).
bool background_at(ivec2 q)
{
    if (!uncovered(q)) return false;
    int covered = 0;
    for (int i = 0; i < 9; i++)
        if (i != 4 && !uncovered(q + ivec2(i % 3 - 1, i / 3 - 1))) covered++;
    return covered < 6;
}

float coverage(ivec2 px)
{
    int n = 9;
    for (int i = 0; i < 9; i++)
        if (i != 4 && uncovered(px + ivec2(i % 3 - 1, i / 3 - 1)) && background_at(px + ivec2(i % 3 - 1, i / 3 - 1))) n--;
    return n <= 1 ? 0.0 : min(float(n) / 8.0, 1.0);
}

void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 t0 = texelFetch(u_attr0, px, 0), t1, t2, t3;
    vec3 p;
    vec4 D;
    float alpha = 1.0;
    if (t0.a > u_min_weight && rs_visible_point(p)) {
        if (u_outline_coverage == 1) alpha = coverage(px);
        t1 = texelFetch(u_attr1, px, 0);
        t2 = texelFetch(u_attr2, px, 0);
        t3 = u_env_on > 0.5 ? texelFetch(u_attr3, px, 0) : vec4(0.0);  // written under an environment only
        D = texelFetch(u_diffuse, px, 0);
    } else if (!fill_hole(px, t0, t1, t2, t3, p, D)) {
        o_color = vec4(u_background, 0.0);  // alpha 0: background, for the edges pass (the output's is 1)
        return;
    }
    float inv = 1.0 / t0.a;
    vec3 A = t0.rgb * inv;
    vec3 N, debug = vec3(0.0);
    N = normalize(t1.xyz * inv * 2.0 - 1.0);
    float m = t1.a * inv;
    float rho_s = t2.r * inv;
    debug = t2.gba * inv;       // the debug views' colour, else (ambient occlusion, coat, flakes)
    float ao = debug.x, coat = debug.y, shimmer = debug.z;
    vec3 V = normalize(-p);

    if (u_mode == MODE_NORMALS) { o_color = vec4(N * 0.5 + 0.5, 1.0); return; }
    if (u_mode == MODE_REGIONS || u_mode == MODE_LOD) { o_color = vec4(debug, 1.0); return; }
    rs_fine_apply((u_inv_view * vec4(p, 1.0)).xyz, normalize(mat3(u_inv_view) * N), A, m, rho_s, coat, shimmer);
    rho_s *= u_rho_s_scale;
    float shadow = rs_shadow(p, N);
    if (u_mode == MODE_SHADOW) { o_color = vec4(vec3(shadow), 1.0); return; }

    vec3 c;
    if (u_mode == MODE_ALBEDO) {
        c = A;
    } else {
        // The key light is an area light when it stands for an environment's brightest region: its
        // angular size widens the lobe (roughness added in quadrature), keeping the lobe's energy.
        float mk = sqrt(m * m + u_key_widen * u_key_widen);
        vec3 S = u_key_color * (rs_ksk_specular(N, u_key_dir, V, mk, rho_s) * shadow)
               + u_fill_color * rs_ksk_specular(N, u_fill_dir, V, m, rho_s);
        vec3 E = u_key_color * max(dot(N, u_key_dir), 0.0) * shadow + u_fill_color * max(dot(N, u_fill_dir), 0.0)
               + u_ambient;
        // The makeup's clear coat: the same lobe family, smooth (m 0.1), F0 0.04, untinted, on top.
        const float mc = 0.1;
        vec3 C = vec3(0.0), Eb = vec3(0.0), Eb_walls = vec3(0.0), vis = vec3(1.0);
        float spread = 0.0;
        if (coat > 0.0)
            C = u_key_color * (rs_ksk_lobe(N, u_key_dir, V, sqrt(mc * mc + u_key_widen * u_key_widen), RS_F0_COAT)
                               * shadow);
        if (u_env_on > 0.5) {
            // Sky occlusion stands in for the specular's visibility too (eye sockets, nostrils), and at
            // contours the surface just behind them.
            float ndotv = dot(N, V);
            ivec2 hit_c = ivec2(-1);
            float open_c = contour_open(p, N, ndotv, 1.0 - smoothstep(0.1, 0.5, ndotv), hit_c);
            float open_r;
            bool left;
            vec3 Rv = reflect(-V, N), blocked_r;
            reflection_near(px, p, N, Rv, open_r, left, blocked_r);
            vis = rs_env_lamp_visibility(p, N);
            spread = normal_spread(px, N);
            vec3 B = N;  // the bent normal (RT3), where the splats carry one
            if (u_has_bent > 0.5) {
                vec2 bt = vec2(t3.x - t3.y, t3.z - t3.w) * (inv / u_bent_scale);
                vec3 t1, t2;
                rs_tangents(N, t1, t2);
                B = normalize(sqrt(max(1.0 - dot(bt, bt), 0.0)) * N + bt.x * t1 + bt.y * t2);
            }
            // A reflection that runs off the frame unblocked is decided in the cloud's grid (body_seen):
            // blocked where it meets the body, which it then shows. The mobile pipeline asks the splat's
            // bent cone instead (a march costs llvmpipe ~40 ms of a 512^2 frame): around B with the
            // occlusion's share (sin^2 of its half-angle = ao; soft over +-0.1 in cosine: a model of the
            // open directions, not their outline); outside it the lobe sees the skin around, at the
            // radiance the bounce gives that share.
            vec3 L_body = vec3(0.0);
            float open_body = 1.0;
            if (left && u_body_on > 0.5) {
                open_body = body_seen(p, Rv, L_body) ? 0.0 : 1.0;
            } else if (left && u_has_bent > 0.5) {
                float ct = sqrt(max(1.0 - ao, 0.0));
                // A cone of nearly the whole hemisphere (ao near 1) closes nothing: it fades in as ao
                // goes from 1 to 0.99, not below a splat's horizon at once.
                open_body = 1.0 - (1.0 - smoothstep(ct - 0.1, ct + 0.1, dot(Rv, B))) * smoothstep(0.0, 0.1, ct);
                L_body = rs_hidden_radiance(ao, A);
            }
            float so = ao * open_c * open_r * open_body;
            E += rs_env_sky(N, B, ao) + rs_env_lamp_irradiance(N, vis);
            // The per-pixel share of the diffuse gets the bounce as the splats do (irradiance.vert.glsl),
            // in the colour of the surface as painted: a lipstick's crease bounces lipstick.
            Eb = rs_bounce(ao, A);
            // Where the point is occluded enough for its bounce to show (above 0.98 it is under 1 % of its
            // light), the bounce is lit by the walls it sees (surround_seen), faded in from 0.98 to 0.95
            // and by how much wall was found; Eb_walls, the difference, relights the drawn levels' share
            // (D holds the splats' bounce, lit by the mean) as Eb does the per-pixel share.
            if (ao < 0.98 && u_surround_samples > 0) {
                float ws;
                vec3 Es = surround_seen(px, p, N, ws);
                Es = mix(u_env_surround, Es, smoothstep(0.0, 0.5, ws) * smoothstep(0.98, 0.95, ao));
                vec3 lit = rs_bounce_lit(ao, A, Es);
                Eb_walls = lit - Eb;
                Eb = lit;
            }
            // The lobe's share the occlusion hides (1 - ao) reflects that skin too, not black: Eb is its
            // radiance over the hidden share, (1 - ao) L_skin, so that share adds Eb times the lobe's albedo
            // (under the jaw: the lit neck; its shares below come to 1 with so and the blocked ones times ao).
            float lobe = rho_s * rs_env_lobe_albedo(max(ndotv, 1e-4), m, RS_F0_SKIN);
            S += Eb * lobe;
            // The map's reflection and the lamps' (those as their shadow maps let them through; the sky
            // occlusion too, as for the map: the lamps' maps are too coarse for an ear's folds, issue 22).
            S += (rs_env_specular(N, V, m, RS_F0_SKIN) + rs_env_lamp_specular(N, V, m, RS_F0_SKIN, vis, spread))
                 * (rho_s * so);
            // Where the face blocks it, the reflection shows the skin it runs into: behind a contour (only
            // where that share is worth a lookup: a few % of a reflection that is a few % of the skin's light
            // is below a level of the output) and where the march found it blocked (reflection_near).
            float wc = 1.0 - open_c;
            vec3 blocked = open_c * blocked_r;
            if (wc > 0.02 && hit_c.x >= 0) blocked += skin_at(hit_c) * wc;
            S += blocked * (ao * lobe);
            S += L_body * (open_c * open_r * (1.0 - open_body) * ao * lobe);
            if (coat > 0.0)
                C += (rs_env_specular(N, V, mc, RS_F0_COAT) + rs_env_lamp_specular(N, V, mc, RS_F0_COAT, vis, spread)) * so;
        }
        C *= coat;
        // Flakes reflect in the pigment's colour (a metallic tint, normalised to keep their brightness).
        if (shimmer > 0.0) C += flakes(p, N, V, A / max(max(A.r, max(A.g, A.b)), 0.05), shadow, ao, vis, spread, shimmer);
        // The Gaussians too narrow to draw take the pixel's own irradiance. At an occluding contour or a
        // crease (nostril rim, lid fold) that pixel sees a sliver of surface edge-on, whose interpolated
        // normal can turn fully away from (or into) the light: one pixel's E drops to 0 while every drawn
        // level, averaged over splats, stays lit, and the missing green and blue leave a saturated red
        // line. So where the surface is seen edge-on (N.V under ~0.3) the per-pixel E is held within
        // [0.8, 1.25] of the narrowest drawn level's splat-averaged irradiance (its luminance, in D's
        // alpha), keeping E's colour. Surfaces facing the eye keep their per-pixel E untouched: normal-map
        // detail and the sharp green/blue shadow edges stay.
        vec3 El = E;  // the lights' own colour, before the skin's bounce tints it
        E += Eb;
        vec3 Ed = E;
        float es = D.a * u_diffuse_scale;
        float edge_on = 1.0 - smoothstep(0.15, 0.45, dot(N, V));
        if (es > 0.0 && edge_on > 0.0) {
            float le = dot(E, vec3(0.2126, 0.7152, 0.0722));
            float lc = mix(le, clamp(le, 0.8 * es, 1.25 * es), edge_on);
            Ed = le > 1e-6 ? E * (lc / le) : vec3(lc);
        }
        vec3 Dd = D.rgb * u_diffuse_scale + u_delta_weight * Ed + (vec3(1.0) - u_delta_weight) * Eb_walls;
        // Across a fold (the alar groove, a lid crease) the drawn levels' widest, reddest Gaussians gather
        // light from the lit side of the groove; seen edge-on, that bleed reads as a thin red line. There
        // D's red is held within 1.25 x its green, relative to the light's own colour (El: a sunset's
        // orange stays orange; the bounce's red is the skin's, the very bleed this holds back).
        if (edge_on > 0.0) {
            float k = 1.25 * (El.r + 1e-4) / (El.g + 1e-4);
            Dd.r = mix(Dd.r, min(Dd.r, k * Dd.g), edge_on);
        }
        // Under an environment (rouge's realistic lighting; the paper's lights keep the paper's Lambert
        // diffuse and its figures), the diffuse is Burley's: the retro-reflection of the key light, the
        // environment's lamps and its SH light, per pixel on top of the subsurface D.
        if (u_env_on > 0.5) {
            float fv = rs_pow5(1.0 - clamp(dot(N, V), 0.0, 1.0)), r = sqrt(max(m, 0.0));
            vec3 Er = burley_retro_light(u_key_color * shadow, N, u_key_dir, V, r, fv)
                    + burley_retro_env(N, V, r, fv, ao);
            // The lamps' directions are in the environment's frame: N and V go there once (a rotation).
            vec3 Ne = u_env_from_view * N, Ve = u_env_from_view * V;
            for (int i = 0; i < 3; i++)
                Er += burley_retro_light(u_env_lamp_color[i] * vis[i], Ne, u_env_lamp_dir[i], Ve, r, fv);
            Dd += Er;
        }
        if (u_mode == MODE_DIFFUSE) c = A * Dd;
        else if (u_mode == MODE_SPECULAR) c = S + C;
        else if (u_mode == MODE_IRRADIANCE) c = E;
        else {
            vec3 Aw = rs_fine_wet(A, coat, dot(N, V));  // the body seen through the coat (makeup_fine.glsl)
            c = (u_physical == 1 ? Aw * Dd + S : Aw * (Dd + S)) + C;
        }
        c *= u_exposure;
        if (u_tonemap == 0 && u_linear_output < 0.5) c = filmic(c);
    }
    c = u_linear_output > 0.5 ? clamp(c, 0.0, 1.0) : linear_to_srgb(c);
    o_color = vec4(mix(u_background, c, alpha), 1.0);
}
