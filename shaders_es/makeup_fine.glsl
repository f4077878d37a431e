// makeup_fine.glsl — the makeup's fine layer, #include'd by the composite (GLSL ES 3.00; no #version here):
// narrow-brush stamps evaluated at the surface point a pixel sees, so their edges are as sharp as the
// picture (src/makeup/makeup.c, "Two resolutions"; src/render/render_fine.c uploads them). The same
// arithmetic as the splat layer: eq. (3) with the footprint on every term, the stroke's max over its
// stamps, I_F from the strokes that reached the point, eq. (2) stacked stroke by stroke in linear light.
//
// u_fine_data (RGBA32F, 1024 wide): per stamp k, texels 3k..3k+2 = (pos, radius), (view_dir, amount),
// (product, stroke, eraser, 0); from u_fine_products, per product 3 texels = (linear rgb, colour weight),
// (m, rho_s, finish weight, I_M), (coat, shimmer, coverage, tip hardness).
// u_fine_index (R32UI, 1024 wide): per grid cell (start, count), then the cells' stamp lists in log order.
// u_fine_field (R8 3D, linear): the region masks' fields (makeup.c, "Region masks per pixel") stacked
// along z; a stamp kept to a region (product texel's w) takes the field's ramp at the point as its mask.
uniform highp sampler2D u_fine_data;
uniform highp usampler2D u_fine_index;
uniform int u_fine_count;        // 0: no fine layer
uniform int u_fine_products;
uniform vec3 u_fine_origin;
uniform float u_fine_inv_cell;
uniform ivec3 u_fine_dim;
uniform vec3 rs_makeup_range_lo; // the face's colour range (makeup.glsl)
uniform vec3 rs_makeup_range_hi;

#define RS_FINE_LIST_MAX 4096    // stamps looked at per pixel, at most
#define RS_FINE_REGIONS 5        // RS_COSMETIC_REGION_COUNT (render_fine.c checks)

uniform mediump sampler3D u_fine_field;
uniform vec4 u_fine_field_box[2 * RS_FINE_REGIONS];  // per region (origin, 1 / voxel), (dims, first slice)
uniform vec2 u_fine_field_ramp[RS_FINE_REGIONS];     // per region (threshold, band)

vec4 rs_fine_texel(int i) { return texelFetch(u_fine_data, ivec2(i & 1023, i >> 10), 0); }
uint rs_fine_entry(uint i) { return texelFetch(u_fine_index, ivec2(int(i & 1023u), int(i >> 10u)), 0).r; }

// The stacked layer at a point: colour (linear), colour intensity, coverage; finish and its intensity.
struct rs_fine_layer {
    vec3 cp;
    float ci, cov;
    float m, rho_s, coat, shimmer, si;
};

// I_G (makeup.c falloff_t): the shifted Gaussian (sigma r / 2), or a flat top with a smooth rim.
float rs_fine_falloff(float u, float hard)
{
    if (u >= 1.0) return 0.0;
    if (hard > 0.0) return smoothstep(0.0, 1.0, (1.0 - u) / (1.0 - hard));
    const float rim = 0.1353352832;  // exp(-2)
    return (exp(-2.0 * u * u) - rim) / (1.0 - rim);
}

// makeup.c rs_makeup_facing: how much of a stamp made from view direction v (not normalised; 0: no test)
// reaches a surface of unit normal n.
#define RS_FINE_FACING_FULL 0.3  // RS_MAKEUP_FACING_FULL
float rs_fine_facing(vec3 n, vec3 v, bool whole)
{
    float vl = length(v);
    if (vl <= 0.0) return 1.0;
    float d = dot(n, v);
    if (d <= 0.0) return 0.0;
    return whole ? 1.0 : smoothstep(0.0, RS_FINE_FACING_FULL * vl, d);
}

// A region mask's weight at model-space point pm: its field interpolated there (the voxel centres are
// the texel centres), ramped linearly over the band around the threshold. 1 where the region has no field.
float rs_fine_region_weight(int region, vec3 pm)
{
    vec4 a = u_fine_field_box[2 * region], b = u_fine_field_box[2 * region + 1];
    if (b.x == 0.0) return 1.0;
    vec3 t = clamp((pm - a.xyz) * a.w, vec3(0.5), b.xyz - 0.5);  // within the region's own slices
    t.z += b.w;
    float f = textureLod(u_fine_field, t / vec3(textureSize(u_fine_field, 0)), 0.0).r;
    vec2 ramp = u_fine_field_ramp[region];
    return clamp((f - ramp.x) / ramp.y + 0.5, 0.0, 1.0);
}

// One stroke's contribution (intensity a of product p, or an eraser) stacked onto the layer (makeup.c
// compose / rs_makeup_erase).
void rs_fine_stack(inout rs_fine_layer l, float a, int p, bool eraser, inout float touches)
{
    if (a <= 0.0) return;
    if (eraser) {
        l.ci *= 1.0 - a;
        l.si *= 1.0 - a;
        if (l.ci + l.si < 0.5 / 255.0) touches = 0.0;
        return;
    }
    vec4 t0 = rs_fine_texel(u_fine_products + 3 * p), t1 = rs_fine_texel(u_fine_products + 3 * p + 1);
    vec4 t2 = rs_fine_texel(u_fine_products + 3 * p + 2);
    float i2 = a * t0.a;
    if (i2 > 0.0) {
        float ii = 1.0 - (1.0 - l.ci) * (1.0 - i2), k = l.ci * (1.0 - i2);
        l.cp = (l.cp * k + t0.rgb * i2) / ii;
        l.cov = (l.cov * k + t2.z * i2) / ii;
        l.ci = ii;
    }
    float s2 = a * t1.z;
    if (s2 > 0.0) {
        float ss = 1.0 - (1.0 - l.si) * (1.0 - s2), k = l.si * (1.0 - s2);
        l.m = (l.m * k + t1.x * s2) / ss;
        l.rho_s = (l.rho_s * k + t1.y * s2) / ss;
        l.coat = (l.coat * k + t2.x * s2) / ss;
        l.shimmer = (l.shimmer * k + t2.y * s2) / ss;
        l.si = ss;
    }
}

// The body colour seen through a clear wet coat (gloss, a satin's oil), its coverage `coat`, at N.V `ndotv`.
// A smooth film of index n = 1.5 over a diffuse surface of albedo a (Lekner & Dorf 1988, "Why some things
// are darker when wet"): light enters through the film (1 - r_e, its hemispherical mean 0.092 for the
// lighting from all around), is scattered back by the surface, and leaves towards the eye through the
// film's upper face (1 - F(theta_v)), radiance / n^2; what is beyond the critical angle (r_i = 1 - (1 -
// r_e) / n^2 = 0.596) is reflected back down and scattered again, and absorbed by the pigment each time:
//   a_wet / a = (1 - F(theta_v)) (1 - r_e) / (n^2 (1 - a r_i)),
// 0.96 for a white, 0.39 for a black: the wet colour is deeper and more saturated. A gloss
// over lipstick does not wet all of it so: where the product's wax already holds its pigment at the same
// index the film adds no new interface; only the porous, air-filled top of a (satin or matte) film fills
// with the oil. RS_COAT_WETTING is that share (chosen, not measured). The coat's reflection is the
// composite's clear-coat lobe (smooth, from the lamps and the whole room); the light it reflects is the
// light this transmission loses. Only `full` applies it: `diffuse` shows the dry surface's subsurface
// term, the coat (what it reflects and what it does to the light through it) being a layer above.
#define RS_COAT_WETTING 0.5
vec3 rs_fine_wet(vec3 a, float coat, float ndotv)
{
    if (coat <= 0.0) return a;
    const float n2 = 2.25, r_e = 0.092, r_i = 1.0 - (1.0 - r_e) / n2;
    float fv = 0.04 + 0.96 * pow(1.0 - clamp(ndotv, 0.0, 1.0), 5.0);
    vec3 ratio = (1.0 - fv) * (1.0 - r_e) / (n2 * (1.0 - a * r_i));
    return a * mix(vec3(1.0), ratio, RS_COAT_WETTING * clamp(coat, 0.0, 1.0));
}

// Composes the fine layer at model-space point pm (unit normal nm) over the splat layer's values.
void rs_fine_apply(vec3 pm, vec3 nm, inout vec3 albedo, inout float m, inout float rho_s, inout float coat,
                   inout float shimmer)
{
    if (u_fine_count == 0) return;
    ivec3 c = ivec3(floor((pm - u_fine_origin) * u_fine_inv_cell));
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, u_fine_dim))) return;
    uint cell = uint((c.z * u_fine_dim.y + c.y) * u_fine_dim.x + c.x);
    uint start = rs_fine_entry(2u * cell), n = min(rs_fine_entry(2u * cell + 1u), uint(RS_FINE_LIST_MAX));
    rs_fine_layer l = rs_fine_layer(vec3(0.0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    float touches = 0.0, best = 0.0, stroke = -1.0;
    int product = 0;
    bool eraser = false, reached = false;
    int region = 0;        // the last region's weight here, kept: a stroke's stamps share their region
    float region_w = 1.0;
    for (uint k = 0u; k < n; k++) {
        int s = int(rs_fine_entry(start + k));
        vec4 t0 = rs_fine_texel(3 * s), t1 = rs_fine_texel(3 * s + 1), t2 = rs_fine_texel(3 * s + 2);
        if (t2.y != stroke) {  // a new stroke: the last one's max goes onto the layer
            rs_fine_stack(l, best, product, eraser, touches);
            stroke = t2.y, best = 0.0, reached = false;
        }
        int reg = int(t2.w);
        product = int(t2.x), eraser = t2.z > 0.5;
        // A product kept to a region only needs the surface to face the view at all: its mask, not the
        // grazing angle, bounds it (the lips roll into the mouth line at a grazing angle).
        float facing = rs_fine_facing(nm, t1.xyz, eraser || reg != 0);
        if (facing <= 0.0) continue;
        vec4 pr = rs_fine_texel(u_fine_products + 3 * product + 2);
        float ig = rs_fine_falloff(length(pm - t0.xyz) / t0.w, eraser ? 0.0 : pr.w) * facing;
        if (reg != 0 && ig > 0.0) {
            if (reg != region) region = reg, region_w = rs_fine_region_weight(reg, pm);
            // Kept to a region, the stroke fills it up to the mask within the brush's reach, as a lipstick
            // is applied: the mask draws the border, the stroke only has to pass near it.
            ig = min(1.0, 4.0 * ig) * region_w;
        }
        if (ig <= 0.0) continue;
        if (!reached && !eraser) touches += 1.0;
        reached = true;
        float a;
        if (eraser) {
            a = t1.w * min(1.0, 2.0 * ig);
        } else {
            // eq. (3) with coverage v moving it towards the footprint (makeup.c stamp_splat).
            float im = rs_fine_texel(u_fine_products + 3 * product + 1).w, v = pr.z;
            float i3 = ig * (0.3 + 0.3 * im + 0.3 * (1.0 - exp(-touches)));
            a = t1.w * (i3 + v * (min(1.0, ig * (1.0 + 2.0 * v)) - i3));
        }
        best = max(best, a);
    }
    rs_fine_stack(l, best, product, eraser, touches);
    if (l.ci > 0.0) {
        // eq. (2); a sheer pigment is held in the face's colour range, an opaque one keeps its own.
        vec3 held = clamp(l.cp, rs_makeup_range_lo, rs_makeup_range_hi);
        albedo = albedo * (1.0 - l.ci) + min(mix(held, l.cp, l.cov), vec3(1.0)) * l.ci;
    }
    if (l.si > 0.0) {
        m = mix(m, l.m, l.si);
        rho_s = mix(rho_s, l.rho_s, l.si);
        coat = mix(coat, l.coat, l.si);
        shimmer = mix(shimmer, l.shimmer, l.si);
    }
}
