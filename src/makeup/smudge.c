// smudge.c — the smudge and blend tools (smudge.h): sample the makeup, lay it down again by ordinary stamps.
//
// Why stamps and not a new kind of layer operation: a stamp is what both layers, the look files, undo and
// the renderer's fine layer already understand, so a smudge needs no new file field and replays exactly.
// The price: a stamp only adds product. A smudge therefore moves colour outwards and along the drag, and
// lays a load down only where it is stronger than what is there (else dragging through an even blush
// would build it up stamp after stamp: composing I over I gives 1 - (1 - I)^2); blend lays the
// footprint's average into its weaker part. Neither thins the stronger side.
//
// Products: a load is turned into a product (colour, weights, finish, coverage). When it matches a product
// the layer has already logged (within a step of the 8-bit colour and 0.06 in the finish), that product
// is reused with the amount that gives the sampled intensity: a smudged lipstick is more of the same
// lipstick in the look. Otherwise a "smudge" product is made (weights rounded to 1/64, so neighbouring
// loads share one); past RS_SMUDGE_PRODUCTS_MAX logged products the nearest is reused whatever it is,
// which keeps a look within its file's product limit.
#include "makeup/smudge.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char *const tool_names[RS_TOOL_COUNT] = {"paint", "smudge", "blend"};

const char *rs_paint_tool_name(rs_paint_tool t) { return (unsigned)t < RS_TOOL_COUNT ? tool_names[t] : "unknown"; }

bool rs_paint_tool_parse(const char *name, rs_paint_tool *out)
{
    for (int k = 0; k < RS_TOOL_COUNT; k++)
        if (strcmp(name, tool_names[k]) == 0) {
            *out = (rs_paint_tool)k;
            return true;
        }
    return false;
}

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }

// The makeup at one point, as the renderer stacks it: colour (linear), intensities, coverage, finish.
typedef struct layer {
    float lin[3], ci, cov, m, rho_s, coat, shimmer, si;
} layer;

// Eq. (2) stacked (makeup.c compose, makeup_fine.glsl rs_fine_stack): `top` over `base`.
static void stack(layer *base, const layer *top)
{
    if (top->ci > 0.0f) {
        float ii = 1.0f - (1.0f - base->ci) * (1.0f - top->ci), k = base->ci * (1.0f - top->ci);
        for (int ch = 0; ch < 3; ch++) base->lin[ch] = (base->lin[ch] * k + top->lin[ch] * top->ci) / ii;
        base->cov = (base->cov * k + top->cov * top->ci) / ii;
        base->ci = ii;
    }
    if (top->si > 0.0f) {
        float ss = 1.0f - (1.0f - base->si) * (1.0f - top->si), k = base->si * (1.0f - top->si);
        base->m = (base->m * k + top->m * top->si) / ss;
        base->rho_s = (base->rho_s * k + top->rho_s * top->si) / ss;
        base->coat = (base->coat * k + top->coat * top->si) / ss;
        base->shimmer = (base->shimmer * k + top->shimmer * top->si) / ss;
        base->si = ss;
    }
}

static layer record_layer(const rs_makeup_gpu *r)
{
    layer l = {{rs_srgb_to_linear(r->rgb[0] / 255.0f), rs_srgb_to_linear(r->rgb[1] / 255.0f),
                rs_srgb_to_linear(r->rgb[2] / 255.0f)},
               r->colour_i / 255.0f, r->coverage / 255.0f, r->m / 255.0f, r->rho_s / 255.0f, r->coat / 255.0f,
               r->shimmer / 255.0f, r->spec_i / 255.0f};
    return l;
}

// --- the fine layer on the CPU (shaders_es/makeup_fine.glsl rs_fine_apply, same order) ------------------

typedef struct fine_product {
    float lin[3], cw, fw, im, m, rho_s, coat, shimmer, cov, hard;
} fine_product;

typedef struct fine_set {
    rs_makeup_fine_stamp *stamps;  // those that may reach the footprint, log order
    uint32_t count;
    fine_product *products;        // by log cosmetic index
    uint32_t product_count;
    const rs_makeup_field *fields[RS_COSMETIC_REGION_COUNT];  // the region masks (rs_makeup_region_field)
} fine_set;

static void fine_free(fine_set *f)
{
    free(f->stamps);
    free(f->products);
}

static rs_result fine_load(const rs_makeup *mk, const float pos[3], float radius, fine_set *f, rs_error *err)
{
    memset(f, 0, sizeof *f);
    rs_result r = rs_makeup_fine_stamps(mk, &f->stamps, &f->count, err);
    if (r != RS_OK || f->count == 0) return r;
    uint32_t keep = 0;
    for (uint32_t k = 0; k < f->count; k++) {
        const rs_makeup_fine_stamp *s = &f->stamps[k];
        float dx = s->pos[0] - pos[0], dy = s->pos[1] - pos[1], dz = s->pos[2] - pos[2], reach = radius + s->radius;
        if (dx * dx + dy * dy + dz * dz < reach * reach) f->stamps[keep++] = *s;
    }
    f->count = keep;
    if (keep == 0) return RS_OK;
    for (int g = 1; g < RS_COSMETIC_REGION_COUNT; g++) f->fields[g] = rs_makeup_region_field(mk, (rs_cosmetic_region)g);
    f->product_count = rs_makeup_log_cosmetic_count(mk);
    f->products = rs_alloc_array(f->product_count ? f->product_count : 1, sizeof *f->products);
    if (!f->products) return rs_fail(err, RS_ERR_NOMEM, "smudge: out of memory");
    for (uint32_t i = 0; i < f->product_count; i++) {
        const rs_cosmetic *c = rs_makeup_log_cosmetic(mk, i);
        f->products[i] = (fine_product){{rs_srgb_to_linear(c->rgb[0] / 255.0f), rs_srgb_to_linear(c->rgb[1] / 255.0f),
                                         rs_srgb_to_linear(c->rgb[2] / 255.0f)},
                                        clamp01(c->colour_weight), clamp01(c->finish_weight),
                                        clamp01(c->material_weight), clamp01(c->m), clamp01(c->rho_s),
                                        clamp01(c->coat), clamp01(c->shimmer), clamp01(c->coverage),
                                        rs_makeup_tip_hardness(c)};
    }
    return RS_OK;
}

static void fine_stack(layer *l, float a, const fine_product *p, bool eraser, float *touches)
{
    if (!(a > 0.0f)) return;
    if (eraser) {
        l->ci *= 1.0f - a;
        l->si *= 1.0f - a;
        if (l->ci + l->si < 0.5f / 255.0f) *touches = 0.0f;
        return;
    }
    if (!p) return;
    layer t = {{p->lin[0], p->lin[1], p->lin[2]}, a * p->cw, p->cov, p->m, p->rho_s, p->coat, p->shimmer, a * p->fw};
    stack(l, &t);
}

static layer fine_at(const fine_set *f, const float pm[3], const float nm[3])
{
    layer l = {{0, 0, 0}, 0, 0, 0, 0, 0, 0, 0};
    float touches = 0.0f, best = 0.0f;
    const fine_product *product = NULL;
    bool eraser = false, reached = false;
    uint32_t stroke = UINT32_MAX;
    for (uint32_t k = 0; k < f->count; k++) {
        const rs_makeup_fine_stamp *s = &f->stamps[k];
        if (s->stroke != stroke) {  // a new stroke: the last one's max goes onto the layer
            fine_stack(&l, best, product, eraser, &touches);
            stroke = s->stroke, best = 0.0f, reached = false;
        }
        const float *v = s->view_dir;
        float vl = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        eraser = s->eraser != 0;
        product = !eraser && s->cosmetic < f->product_count ? &f->products[s->cosmetic] : NULL;
        if (!eraser && !product) continue;
        // As makeup_fine.glsl: a product kept to a region needs the surface to face the view at all.
        float facing = rs_makeup_facing(nm, v, vl, eraser || s->region);
        if (!(facing > 0.0f)) continue;
        float dx = pm[0] - s->pos[0], dy = pm[1] - s->pos[1], dz = pm[2] - s->pos[2];
        float ig = rs_makeup_tip_falloff(sqrtf(dx * dx + dy * dy + dz * dz), s->radius, eraser ? 0.0f : product->hard)
                   * facing;
        if (s->region && ig > 0.0f)  // kept to a region: fills its mask within the brush's reach (the shader)
            ig = RS_MIN(1.0f, 4.0f * ig) * rs_makeup_field_weight(s->region < RS_COSMETIC_REGION_COUNT ? f->fields[s->region] : NULL, pm);
        if (!(ig > 0.0f)) continue;
        if (!reached && !eraser) touches += 1.0f;
        reached = true;
        float a;
        if (eraser) {
            a = s->amount * RS_MIN(1.0f, 2.0f * ig);
        } else {
            float v2 = product->cov, i3 = ig * (0.3f + 0.3f * product->im + 0.3f * (1.0f - expf(-touches)));
            a = s->amount * (i3 + v2 * (RS_MIN(1.0f, ig * (1.0f + 2.0f * v2)) - i3));
        }
        best = RS_MAX(best, a);
    }
    fine_stack(&l, best, product, eraser, &touches);
    return l;
}

// --- sampling ------------------------------------------------------------------------------------------

typedef struct gather_ctx {
    const rs_makeup *mk;
    const float *view;
    float view_len, radius;  // view_len 0: no facing test
    uint32_t seen, stride;
    const fine_set *fine;
    // sums
    double w, wc, ws, lin[3], cov, m, rho_s, coat, shimmer, level;
    float level_min;
    uint32_t points;
} gather_ctx;

// How much the brush reaches splat i: what it samples is weighted as a stamp there would lay it down.
static float facing(const gather_ctx *x, uint32_t i)
{
    return rs_makeup_facing(rs_makeup_cloud(x->mk)->normal[i], x->view, x->view_len, false);
}

static bool count_one(void *user, uint32_t i, float d2)
{
    (void)d2;
    gather_ctx *x = user;
    x->seen += facing(x, i) > 0.0f;
    return true;
}

static bool sample_one(void *user, uint32_t i, float d2)
{
    gather_ctx *x = user;
    float f = facing(x, i);
    if (!(f > 0.0f)) return true;
    if (x->seen++ % x->stride != 0) return true;
    float w = rs_makeup_falloff(sqrtf(d2), x->radius) * f;
    if (!(w > 0.0f)) return true;
    const rs_splat_cloud *cloud = rs_makeup_cloud(x->mk);
    layer l = record_layer(&rs_makeup_records(x->mk)[i]);
    if (x->fine->count) {
        layer f = fine_at(x->fine, cloud->pos[i], cloud->normal[i]);
        stack(&l, &f);
    }
    float level = RS_MAX(l.ci, l.si);
    x->points++;
    x->w += w;
    x->level += w * level;
    if (d2 < 0.25f * x->radius * x->radius) x->level_min = RS_MIN(x->level_min, level);
    x->wc += w * l.ci;
    for (int ch = 0; ch < 3; ch++) x->lin[ch] += w * l.ci * l.lin[ch];
    x->cov += w * l.ci * l.cov;
    x->ws += w * l.si;
    x->m += w * l.si * l.m;
    x->rho_s += w * l.si * l.rho_s;
    x->coat += w * l.si * l.coat;
    x->shimmer += w * l.si * l.shimmer;
    return true;
}

rs_result rs_smudge_sample_at(const rs_makeup *mk, const float pos[3], const float view_dir[3], float radius,
                              rs_smudge_sample *out, rs_error *err)
{
    if (!isfinite(pos[0] + pos[1] + pos[2] + view_dir[0] + view_dir[1] + view_dir[2]) || !(radius > 0.0f) ||
        !isfinite(radius))
        return rs_fail(err, RS_ERR_ARG, "smudge: sample position, view or radius not finite");
    fine_set fine;
    rs_result r = fine_load(mk, pos, radius, &fine, err);
    if (r != RS_OK) {
        fine_free(&fine);
        return r;
    }
    float vl = sqrtf(view_dir[0] * view_dir[0] + view_dir[1] * view_dir[1] + view_dir[2] * view_dir[2]);
    gather_ctx x = {.mk = mk, .view = view_dir, .view_len = vl, .radius = radius, .fine = &fine, .level_min = 1.0f};
    rs_makeup_for_each_near(mk, pos, radius, count_one, &x);
    // Spread the evaluated points over the footprint: every stride-th splat in grid order.
    x.stride = x.seen > RS_SMUDGE_SAMPLES_MAX ? (x.seen + RS_SMUDGE_SAMPLES_MAX - 1) / RS_SMUDGE_SAMPLES_MAX : 1;
    x.seen = 0;
    rs_makeup_for_each_near(mk, pos, radius, sample_one, &x);
    fine_free(&fine);
    rs_smudge_sample s = {.points = x.points};
    if (x.w > 0.0) {
        s.level = (float)(x.level / x.w);
        s.level_min = RS_MIN(x.level_min, s.level);
        s.ci = (float)(x.wc / x.w);
        s.si = (float)(x.ws / x.w);
    }
    if (x.wc > 0.0) {
        for (int ch = 0; ch < 3; ch++) s.lin[ch] = (float)(x.lin[ch] / x.wc);
        s.cov = (float)(x.cov / x.wc);
    }
    if (x.ws > 0.0) {
        s.m = (float)(x.m / x.ws), s.rho_s = (float)(x.rho_s / x.ws);
        s.coat = (float)(x.coat / x.ws), s.shimmer = (float)(x.shimmer / x.ws);
    }
    *out = s;
    return RS_OK;
}

// --- products ------------------------------------------------------------------------------------------

static float q64(float v) { return roundf(clamp01(v) * 64.0f) / 64.0f; }

// How far a logged product is from the load's (colour in sRGB8 steps / 255, the rest as they are);
// weights compared as their ratio, the scale being the amount's.
static float product_distance(const rs_cosmetic *a, const rs_cosmetic *b)
{
    float wa = RS_MAX(a->colour_weight, a->finish_weight), wb = RS_MAX(b->colour_weight, b->finish_weight);
    if (!(wa > 0.0f) || !(wb > 0.0f)) return INFINITY;
    float ca = a->colour_weight / wa, cb = b->colour_weight / wb, fa = a->finish_weight / wa, fb = b->finish_weight / wb;
    float d = RS_MAX(fabsf(ca - cb), fabsf(fa - fb));
    if (ca > 0.0f && cb > 0.0f) {
        for (int ch = 0; ch < 3; ch++) d = RS_MAX(d, fabsf((float)a->rgb[ch] - (float)b->rgb[ch]) / 255.0f);
        d = RS_MAX(d, fabsf(a->coverage - b->coverage));
    }
    if (fa > 0.0f && fb > 0.0f) {
        d = RS_MAX(d, RS_MAX(fabsf(a->m - b->m), fabsf(a->rho_s - b->rho_s)));
        d = RS_MAX(d, RS_MAX(fabsf(a->coat - b->coat), fabsf(a->shimmer - b->shimmer)));
    }
    return d;
}

// The product a load lays down and the amount that gives its intensity; false when it holds nothing.
static bool load_product(const rs_makeup *mk, const rs_smudge_sample *l, float radius, rs_cosmetic *out,
                         float *amount)
{
    float level = RS_MAX(l->ci, l->si);
    if (!(level >= 0.5f / 255.0f)) return false;
    rs_cosmetic c = {.name = "smudge", .kind = RS_COSMETIC_CUSTOM, .material_weight = 1.0f,
                     .colour_weight = q64(l->ci / level), .finish_weight = q64(l->si / level),
                     .m = q64(l->m), .rho_s = q64(l->rho_s), .coat = q64(l->coat), .shimmer = q64(l->shimmer),
                     .coverage = q64(l->cov), .opacity = 1.0f, .region_mask = RS_COSMETIC_REGION_ANY};
    for (int ch = 0; ch < 3; ch++) c.rgb[ch] = (uint8_t)lroundf(rs_linear_to_srgb(l->lin[ch]) * 255.0f);
    const rs_splat_header *h = &rs_makeup_cloud(mk)->hdr;
    c.size_rel = RS_CLAMP(2.0f * radius / h->face_height, 1e-4f, 1.0f);
    if (!(c.colour_weight > 0.0f) && !(c.finish_weight > 0.0f)) return false;
    uint32_t n = rs_makeup_log_cosmetic_count(mk), best = UINT32_MAX;
    float best_d = INFINITY;
    for (uint32_t i = 0; i < n; i++) {
        float d = product_distance(rs_makeup_log_cosmetic(mk, i), &c);
        if (d < best_d) best_d = d, best = i;
    }
    const float tolerance = 0.06f;
    if (best != UINT32_MAX && (best_d <= tolerance || n >= RS_SMUDGE_PRODUCTS_MAX)) {
        c = *rs_makeup_log_cosmetic(mk, best);
        float w = RS_MAX(c.colour_weight, c.finish_weight);
        *amount = clamp01(level / w);
    } else {
        *amount = level;
    }
    *out = c;
    return true;
}

// --- the tools -----------------------------------------------------------------------------------------

void rs_smudge_begin(rs_smudge *s, rs_paint_tool tool)
{
    memset(s, 0, sizeof *s);
    s->tool = tool;
}

// Intensity `a` composed over `base` reaches `target` (eq. 2: 1 - (1 - base)(1 - a)); 0 when it is there.
static float excess(float target, float base)
{
    if (!(target > base) || !(base < 1.0f)) return 0.0f;
    return clamp01(1.0f - (1.0f - target) / (1.0f - base));
}

static rs_result lay_down(rs_makeup *mk, const rs_smudge_stamp_desc *d, const float pos[3], const float view[3],
                          const rs_smudge_sample *load, float scale, rs_makeup_stamp_info *info, rs_error *err)
{
    rs_cosmetic c;
    float amount;
    if (!(scale > 0.0f) || !load_product(mk, load, d->radius, &c, &amount)) return RS_OK;
    rs_makeup_stamp_desc s = {.pos = {pos[0], pos[1], pos[2]},
                              .view_dir = {view[0], view[1], view[2]},
                              .radius = d->radius,
                              .opacity = clamp01(amount * scale),
                              .pressure = d->pressure,
                              .pressure_map = d->pressure_map,
                              .cosmetic = &c};
    rs_makeup_stamp_info one;
    rs_result r = rs_makeup_stamp(mk, &s, &one, err);
    if (r != RS_OK) return r;
    if (one.dirty.lo < one.dirty.hi) {
        if (info->dirty.lo >= info->dirty.hi) info->dirty = one.dirty;
        else info->dirty.lo = RS_MIN(info->dirty.lo, one.dirty.lo), info->dirty.hi = RS_MAX(info->dirty.hi, one.dirty.hi);
    }
    info->cells += one.cells, info->examined += one.examined, info->touched += one.touched;
    return RS_OK;
}

static rs_result step(rs_smudge *sm, rs_smudge_side *side, rs_makeup *mk, const rs_smudge_stamp_desc *d,
                      const float pos[3], const float view[3], rs_makeup_stamp_info *info, rs_error *err)
{
    rs_smudge_sample here;
    rs_result r = rs_smudge_sample_at(mk, pos, view, d->radius, &here, err);
    if (r != RS_OK) return r;
    float strength = clamp01(d->strength);
    if (sm->tool == RS_TOOL_BLEND) {
        // The footprint's average into its weaker part: from the inner minimum up to the mean.
        return lay_down(mk, d, pos, view, &here, strength * excess(here.level, here.level_min) /
                                                  RS_MAX(here.level, 1e-6f), info, err);
    }
    if (!side->loaded) {
        side->loaded = true;
        side->load = here;
        memcpy(side->last, pos, sizeof side->last);
        return RS_OK;
    }
    // Only where the load is stronger than what lies here (see the top).
    float level = RS_MAX(side->load.ci, side->load.si);
    r = lay_down(mk, d, pos, view, &side->load, excess(level, here.level) / RS_MAX(level, 1e-6f), info, err);
    if (r != RS_OK) return r;
    // The load mixes with what the brush passes over, by distance: spacing and speed do not change it.
    float dx = pos[0] - side->last[0], dy = pos[1] - side->last[1], dz = pos[2] - side->last[2];
    float length = d->radius * (0.5f + 3.5f * strength);
    float k = 1.0f - expf(-sqrtf(dx * dx + dy * dy + dz * dz) / length);
    rs_smudge_sample *l = &side->load;
    float ci = l->ci * (1.0f - k) + here.ci * k, si = l->si * (1.0f - k) + here.si * k;
    if (ci > 0.0f) {
        for (int ch = 0; ch < 3; ch++) l->lin[ch] = (l->lin[ch] * l->ci * (1.0f - k) + here.lin[ch] * here.ci * k) / ci;
        l->cov = (l->cov * l->ci * (1.0f - k) + here.cov * here.ci * k) / ci;
    }
    if (si > 0.0f) {
        l->m = (l->m * l->si * (1.0f - k) + here.m * here.si * k) / si;
        l->rho_s = (l->rho_s * l->si * (1.0f - k) + here.rho_s * here.si * k) / si;
        l->coat = (l->coat * l->si * (1.0f - k) + here.coat * here.si * k) / si;
        l->shimmer = (l->shimmer * l->si * (1.0f - k) + here.shimmer * here.si * k) / si;
    }
    l->ci = ci, l->si = si;
    memcpy(side->last, pos, sizeof side->last);
    return RS_OK;
}

rs_result rs_smudge_stamp(rs_smudge *s, rs_makeup *mk, const rs_smudge_stamp_desc *d, rs_makeup_stamp_info *info,
                          rs_error *err)
{
    rs_makeup_stamp_info local;
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    if (s->tool != RS_TOOL_SMUDGE && s->tool != RS_TOOL_BLEND)
        return rs_fail(err, RS_ERR_ARG, "smudge: tool %d is neither smudge nor blend", (int)s->tool);
    const rs_splat_header *h = &rs_makeup_cloud(mk)->hdr;
    if (!isfinite(d->radius) || !(d->radius > 0.0f) || !(d->radius <= h->face_height))
        return rs_fail(err, RS_ERR_ARG, "smudge: radius %g, must be in (0, face height %g]", d->radius, h->face_height);
    rs_result r = step(s, &s->side[0], mk, d, d->pos, d->view_dir, info, err);
    if (r != RS_OK || !d->mirror) return r;
    // The mirror image samples its own side: a smudge there moves what lies there.
    float mpos[3], mview[3];
    uint32_t idx;
    rs_makeup_mirror_point(h, d->pos, mpos);
    if (!rs_makeup_nearest(mk, mpos, d->radius, &idx)) return RS_OK;
    rs_makeup_mirror_dir(h, d->view_dir, mview);
    r = step(s, &s->side[1], mk, d, rs_makeup_cloud(mk)->pos[idx], mview, info, err);
    if (r == RS_OK) info->mirrored = true;
    return r;
}
