// pack_convert.c — the whole PLY -> splat cloud conversion, step by step (see pack.h).
#include "pack/pack.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *rs_pack_step_name(rs_pack_step s)
{
    static const char *names[RS_PACK_STEP_COUNT] = {"sample", "neighbours", "normals", "radii", "lod", "regions",
                                                    "encode", "occlusion"};
    return s < RS_PACK_STEP_COUNT ? names[s] : "?";
}

typedef struct ctx {
    const rs_pack_desc *d;
    rs_pack_report *rep;
    rs_pack_step step;
    double t0;
} ctx;

static void step_begin(ctx *c, rs_pack_step s)
{
    c->step = s;
    c->t0 = rs_time_now();
    if (c->d->progress) c->d->progress(c->d->progress_user, s, 0.0);
}

static void step_end(ctx *c)
{
    c->rep->seconds[c->step] += rs_time_now() - c->t0;
    if (c->d->progress) c->d->progress(c->d->progress_user, c->step, 1.0);
}

static void step_progress(void *user, double f)
{
    ctx *c = user;
    if (c->d->progress) c->d->progress(c->d->progress_user, c->step, f);
}

static bool finite3(const float v[3])
{
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

static bool usable_normal(const float n[3])
{
    return finite3(n) && n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 1e-12f;
}

typedef struct pos_key {
    float p[3];
    uint32_t id;
} pos_key;

static int cmp_pos(const void *a, const void *b)
{
    const pos_key *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->p[k] != y->p[k]) return x->p[k] < y->p[k] ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

// Copies the kept points (keep[i] != 0) of src into a new set.
static rs_result compact(rs_pack_points *p, const uint8_t *keep, uint32_t kept, rs_error *err)
{
    rs_pack_points q = {.count = kept};
    q.pos = rs_alloc_array(kept, sizeof *q.pos);
    q.region = rs_alloc_array(kept, 1);
    if (p->normal) q.normal = rs_alloc_array(kept, sizeof *q.normal);
    if (p->rgb) q.rgb = rs_alloc_array(kept, sizeof *q.rgb);
    if (p->specular) q.specular = rs_alloc_array(kept, sizeof *q.specular);
    if (!q.pos || !q.region || (p->normal && !q.normal) || (p->rgb && !q.rgb) || (p->specular && !q.specular)) {
        rs_pack_points_free(&q);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory for %u points", kept);
    }
    uint32_t j = 0;
    for (uint32_t i = 0; i < p->count; i++) {
        if (!keep[i]) continue;
        memcpy(q.pos[j], p->pos[i], sizeof q.pos[j]);
        q.region[j] = p->region[i];
        if (q.normal) memcpy(q.normal[j], p->normal[i], sizeof q.normal[j]);
        if (q.rgb) memcpy(q.rgb[j], p->rgb[i], sizeof q.rgb[j]);
        if (q.specular) q.specular[j] = p->specular[i];
        j++;
    }
    rs_pack_points_free(p);
    *p = q;
    return RS_OK;
}

// A point cloud: its own points, coloured/labelled from maps where it has texture coordinates.
static rs_result points_from_cloud(const rs_ply_mesh *in, const rs_pack_desc *d, rs_pack_points *out, rs_error *err)
{
    uint32_t n = in->vertex_count;
    if (d->normal_map) return rs_fail(err, RS_ERR_ARG, "--normal-map needs a mesh (faces give the tangent frame); this PLY is a point cloud");
    if ((d->texture || d->specular_map || d->region_map) && !in->uv)
        return rs_fail(err, RS_ERR_ARG, "texture maps need texture coordinates (s t, u v or texture_u texture_v); this PLY has none");
    rs_pack_points p = {.count = n};
    p.pos = rs_alloc_array(n, sizeof *p.pos);
    p.region = rs_alloc_array(n, 1);
    if (in->normal) p.normal = rs_alloc_array(n, sizeof *p.normal);
    if (in->rgb || d->texture) p.rgb = rs_alloc_array(n, sizeof *p.rgb);
    if (d->specular_map) p.specular = rs_alloc_array(n, sizeof *p.specular);
    if (!p.pos || !p.region || (in->normal && !p.normal) || ((in->rgb || d->texture) && !p.rgb) ||
        (d->specular_map && !p.specular)) {
        rs_pack_points_free(&p);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory for %u points", n);
    }
    memcpy(p.pos, in->pos, (size_t)n * sizeof *p.pos);
    if (in->normal) memcpy(p.normal, in->normal, (size_t)n * sizeof *p.normal);
    if (in->rgb) memcpy(p.rgb, in->rgb, (size_t)n * sizeof *p.rgb);
    for (uint32_t i = 0; i < n; i++) {
        p.region[i] = in->region ? in->region[i] : RS_PACK_REGION_AUTO;
        // Nearest texel for ids, bilinear would be nicer for colour but a cloud with UVs is rare.
        const rs_image *maps[3] = {d->texture, d->specular_map, d->region_map};
        for (int k = 0; k < 3; k++) {
            if (!maps[k]) continue;
            const rs_image *m = maps[k];
            int x = (int)RS_CLAMP(floorf(in->uv[i][0] * m->width), 0.0f, (float)(m->width - 1));
            int y = (int)RS_CLAMP(floorf((1.0f - in->uv[i][1]) * m->height), 0.0f, (float)(m->height - 1));
            const uint8_t *px = m->pixels + ((size_t)y * m->width + x) * m->channels;
            if (k == 0) memcpy(p.rgb[i], px, 3);
            else if (k == 1) p.specular[i] = (px[0] + px[1] + px[2]) / (3.0f * 255.0f);
            else p.region[i] = rs_pack_region_from_rgb(px);
        }
    }
    *out = p;
    return RS_OK;
}

// Drops exact duplicate positions (they would get zero radii and degenerate neighbourhoods).
static rs_result drop_duplicates(rs_pack_points *p, uint32_t *dropped, rs_error *err)
{
    *dropped = 0;
    pos_key *k = rs_alloc_array(p->count, sizeof *k);
    uint8_t *keep = rs_alloc_array(p->count, 1);
    if (!k || !keep) {
        free(k);
        free(keep);
        return rs_fail(err, RS_ERR_NOMEM, "out of memory for %u points", p->count);
    }
    for (uint32_t i = 0; i < p->count; i++) {
        memcpy(k[i].p, p->pos[i], sizeof k[i].p);
        k[i].id = i;
        keep[i] = 1;
    }
    qsort(k, p->count, sizeof *k, cmp_pos);
    for (uint32_t i = 1; i < p->count; i++)
        if (k[i].p[0] == k[i - 1].p[0] && k[i].p[1] == k[i - 1].p[1] && k[i].p[2] == k[i - 1].p[2]) {
            keep[k[i].id] = 0;
            (*dropped)++;
        }
    free(k);
    rs_result r = *dropped ? compact(p, keep, p->count - *dropped, err) : RS_OK;
    free(keep);
    return r;
}

// Header notes: the input's PLY comments (CC-BY attribution) then the caller's provenance line, each
// line made valid, terminal-safe UTF-8 (a Latin-1 comment's bytes become \\xNN: the scan still converts
// and its attribution survives), cut at a character boundary if too long.
static void make_notes(char *dst, const char *comments, const char *extra)
{
    size_t cap = RS_SPLAT_MAX_NOTES, n = 0;
    const char *parts[2] = {comments ? comments : "", extra ? extra : ""};
    dst[0] = 0;
    for (int k = 0; k < 2; k++) {
        for (const char *s = parts[k]; *s && n + 1 < cap;) {
            const char *e = strchr(s, '\n');
            size_t len = e ? (size_t)(e - s) : strlen(s);
            if (n > 0) dst[n++] = '\n';
            n += rs_text_sanitize(dst + n, cap - n, s, len);
            s += len + (e ? 1 : 0);
        }
    }
    dst[n] = 0;
}

float rs_pack_unit_parse(const char *s)
{
    static const struct {
        const char *name;
        float mm;
    } units[] = {{"mm", 1.0f}, {"cm", 10.0f}, {"m", 1000.0f}, {"in", 25.4f}, {"inch", 25.4f}};
    for (size_t i = 0; s && i < RS_COUNT_OF(units); i++)
        if (!strcmp(s, units[i].name)) return units[i].mm;
    return 0;
}

static const char *unit_name(float mm_per_unit)
{
    return mm_per_unit == 1.0f ? "mm" : mm_per_unit == 10.0f ? "cm" : mm_per_unit == 1000.0f ? "m" : mm_per_unit == 25.4f ? "in" : NULL;
}

// The scale rule (pack.h): given, declared (if plausible), inferred from the head's size, estimated.
static float choose_scale(const rs_pack_desc *d, const rs_pack_face *f, rs_pack_report *rep)
{
    float H = f->face_height;
    if (d->mm_per_unit > 0) {
        const char *u = unit_name(d->mm_per_unit);
        rep->scale = RS_PACK_SCALE_GIVEN;
        snprintf(rep->scale_why, sizeof rep->scale_why, "given%s%s", u ? ": " : "", u ? u : "");
        return d->mm_per_unit;
    }
    const char *src = d->declared_unit ? d->declared_unit : "the file's unit";
    bool declared = d->declared_mm_per_unit > 0 && isfinite(d->declared_mm_per_unit);
    if (declared && !f->found) {
        rep->scale = RS_PACK_SCALE_DECLARED;
        snprintf(rep->scale_why, sizeof rep->scale_why, "declared: %s", src);
        return d->declared_mm_per_unit;
    }
    if (declared) {
        float mm = H * d->declared_mm_per_unit;
        if (mm >= RS_PACK_DECLARED_HEAD_MIN_MM && mm <= RS_PACK_DECLARED_HEAD_MAX_MM) {
            rep->scale = RS_PACK_SCALE_DECLARED;
            snprintf(rep->scale_why, sizeof rep->scale_why, "declared: %s; the head is %.0f mm tall", src, mm);
            return d->declared_mm_per_unit;
        }
    }
    char ignored[160] = "";
    if (declared) {
        float mm = H * d->declared_mm_per_unit;
        snprintf(ignored, sizeof ignored, "%s would make the head %.3g %s tall, ignored; ", src, mm >= 1000 ? mm / 1000 : mm,
                 mm >= 1000 ? "m" : "mm");
    }
    static const float units[4] = {1.0f, 10.0f, 1000.0f, 25.4f};
    static const char *names[4] = {"millimetres", "centimetres", "metres", "inches"};
    for (int k = 0; k < 4 && f->found; k++) {
        float mm = H * units[k];
        if (mm >= RS_PACK_HEAD_MIN_MM && mm <= RS_PACK_HEAD_MAX_MM) {
            rep->scale = RS_PACK_SCALE_INFERRED;
            snprintf(rep->scale_why, sizeof rep->scale_why, "%sinferred: in %s the head is %.0f mm tall (a head is %.0f..%.0f mm)",
                     ignored, names[k], mm, RS_PACK_HEAD_MIN_MM, RS_PACK_HEAD_MAX_MM);
            return units[k];
        }
    }
    rep->scale = RS_PACK_SCALE_ESTIMATED;
    rep->mm_estimated = true;
    float mm = RS_PACK_ASSUMED_HEAD_MM / H;
    // A degenerate scan (a line, a speck): no scale to read; 1 mm per unit keeps the header valid.
    if (!isfinite(mm) || !(mm > 0)) mm = 1.0f;
    if (f->found)
        snprintf(rep->scale_why, sizeof rep->scale_why,
                 "%sestimated: no unit (mm, cm, m, in) makes the head %.0f..%.0f mm tall, so it is taken as %.0f mm", ignored,
                 RS_PACK_HEAD_MIN_MM, RS_PACK_HEAD_MAX_MM, RS_PACK_ASSUMED_HEAD_MM);
    else
        snprintf(rep->scale_why, sizeof rep->scale_why, "estimated: no face to measure, the model's size taken as %.0f mm",
                 RS_PACK_ASSUMED_HEAD_MM);
    return mm;
}

static bool all_finite(const float *v, int k)
{
    for (int i = 0; i < k; i++)
        if (!isfinite(v[i])) return false;
    return true;
}

static bool face_finite(const rs_pack_face *f)
{
    return all_finite(f->up, 3) && all_finite(f->forward, 3) && all_finite(f->side, 3) && all_finite(f->top, 3) &&
           all_finite(f->nose_tip, 3) && all_finite(f->mouth, 3) && all_finite(f->mouth_corner[0], 6) &&
           all_finite(f->chin, 3) && all_finite(f->centre, 3) && isfinite(f->brow_y) && isfinite(f->face_height) &&
           f->face_height > 0 && isfinite(f->face_width);
}

// No face: the frame rs_pack_find_face gives a model without one (+Y up, +Z forward where its own axes
// are not finite; the bounding box's centre, its diagonal for the height).
static void unframe(rs_pack_face *f, const float (*pos)[3], uint32_t n)
{
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) mn[a] = fminf(mn[a], pos[i][a]), mx[a] = fmaxf(mx[a], pos[i][a]);
    rs_pack_face g = {0};
    bool axes = all_finite(f->up, 3) && all_finite(f->forward, 3) && all_finite(f->side, 3);
    memcpy(g.up, axes ? f->up : (const float[3]){0, 1, 0}, sizeof g.up);
    memcpy(g.forward, axes ? f->forward : (const float[3]){0, 0, 1}, sizeof g.forward);
    memcpy(g.side, axes ? f->side : (const float[3]){1, 0, 0}, sizeof g.side);
    for (int a = 0; a < 3; a++) g.centre[a] = 0.5f * (mn[a] + mx[a]);
    g.face_height = (float)hypot(hypot((double)mx[0] - mn[0], (double)mx[1] - mn[1]), (double)mx[2] - mn[2]);
    if (!(g.face_height > 0) || !isfinite(g.face_height)) g.face_height = 1.0f;
    *f = g;
}

rs_result rs_pack_convert(const rs_ply_mesh *in, const rs_pack_desc *desc, rs_splat_cloud **out,
                          rs_pack_report *report, rs_error *err)
{
    static const rs_pack_desc zero_desc;
    const rs_pack_desc *d = desc ? desc : &zero_desc;
    rs_pack_report rep_local;
    rs_pack_report *rep = report ? report : &rep_local;
    memset(rep, 0, sizeof *rep);
    for (int k = 0; k < RS_SPLAT_MAX_REGIONS; k++) rep->specular_mean[k] = NAN;
    rep->input_vertices = in->vertex_count;
    rep->input_triangles = in->tri ? in->tri_count : 0;
    ctx c = {.d = d, .rep = rep};

    if (in->vertex_count == 0) return rs_fail(err, RS_ERR_FORMAT, "the PLY has no vertices");
    for (uint32_t i = 0; i < in->vertex_count; i++) {
        if (!finite3(in->pos[i]))
            return rs_fail(err, RS_ERR_FORMAT, "vertex %u: position is not finite", i);
        if (in->region && in->region[i] >= RS_REGION_STANDARD_COUNT && in->region[i] != RS_PACK_REGION_AUTO)
            return rs_fail(err, RS_ERR_FORMAT,
                           "vertex %u: region %u is not a region id (0 other, 1 cheek, 2 nose, 3 forehead, 4 lips, "
                           "5 eyelid, 6 brow, 255 automatic)",
                           i, in->region[i]);
    }
    // Extents beyond 1e30 overflow squared distances and areas in float; no scan is that large.
    for (int a = 0; a < 3; a++) {
        double lo = INFINITY, hi = -INFINITY;
        for (uint32_t i = 0; i < in->vertex_count; i++) {
            lo = fmin(lo, in->pos[i][a]);
            hi = fmax(hi, in->pos[i][a]);
        }
        if (hi - lo > 1e30)
            return rs_fail(err, RS_ERR_LIMIT, "positions span %g units along axis %d; at most 1e30 is supported", hi - lo, a);
    }
    if (d->mm_per_unit != 0 && !(d->mm_per_unit > 0 && isfinite(d->mm_per_unit)))
        return rs_fail(err, RS_ERR_ARG, "mm per unit %g must be a finite number > 0", d->mm_per_unit);
    if (d->declared_mm_per_unit != 0 && !(d->declared_mm_per_unit > 0 && isfinite(d->declared_mm_per_unit)))
        return rs_fail(err, RS_ERR_ARG, "declared mm per unit %g must be a finite number > 0", d->declared_mm_per_unit);

    rs_pack_points p = {0};
    rs_pack_knn knn = {0};
    float *radius = NULL;
    uint32_t *order = NULL;
    rs_splat *splats = NULL;
    rs_splat_header *hdr = NULL;
    rs_result r;

    step_begin(&c, RS_PACK_STEP_SAMPLE);
    if (in->tri && in->tri_count > 0) {
        rs_pack_sample_desc sd = {.points = d->points, .seed = d->seed, .all_components = d->all_components,
                                  .texture = d->texture, .pages = d->pages, .page_count = d->page_count,
                                  .page_wrap = d->page_wrap,
                                  .normal_map = d->normal_map,
                                  .specular_map = d->specular_map, .region_map = d->region_map};
        r = rs_pack_sample_mesh(in, &sd, &p, &rep->triangles_dropped, err);
        rep->sampled_mesh = true;
    } else {
        r = points_from_cloud(in, d, &p, err);
        if (r == RS_OK) r = drop_duplicates(&p, &rep->duplicates_dropped, err);
        if (r == RS_OK && d->points && d->points < p.count) {
            // Decimation keeps a Poisson-disk-like subset, so the kept points still cover evenly.
            uint32_t *ids = rs_alloc_array(p.count, sizeof *ids);
            uint8_t *keep = calloc(p.count, 1);
            if (!ids || !keep) r = rs_fail(err, RS_ERR_NOMEM, "out of memory for %u points", p.count);
            if (r == RS_OK) {
                for (uint32_t i = 0; i < p.count; i++) ids[i] = i;
                r = rs_pack_eliminate((const float(*)[3])p.pos, ids, p.count, d->points, err);
            }
            if (r == RS_OK) {
                for (uint32_t i = 0; i < d->points; i++) keep[ids[i]] = 1;
                r = compact(&p, keep, d->points, err);
            }
            free(ids);
            free(keep);
        }
    }
    if (r != RS_OK) goto out;
    if (p.count > RS_SPLAT_MAX_COUNT) {
        r = rs_fail(err, RS_ERR_LIMIT, "%u points, more than the %u a .rsf holds", p.count, RS_SPLAT_MAX_COUNT);
        goto out;
    }
    step_end(&c);

    uint32_t n = p.count, bad_normals = 0;
    for (uint32_t i = 0; p.normal && i < n; i++) bad_normals += !usable_normal(p.normal[i]);
    bool estimate = !p.normal || bad_normals > 0;

    step_begin(&c, RS_PACK_STEP_NEIGHBOURS);
    r = rs_pack_knn_compute((const float(*)[3])p.pos, n, estimate ? 16 : RS_PACK_RADIUS_K, &knn, step_progress, &c, err);
    if (r != RS_OK) goto out;
    step_end(&c);

    if (estimate) {
        step_begin(&c, RS_PACK_STEP_NORMALS);
        float(*est)[3] = rs_alloc_array(n, sizeof *est);
        if (!est) {
            r = rs_fail(err, RS_ERR_NOMEM, "out of memory for %u normals", n);
            goto out;
        }
        r = rs_pack_estimate_normals((const float(*)[3])p.pos, &knn, est, err);
        if (r != RS_OK) {
            free(est);
            goto out;
        }
        if (!p.normal) {
            p.normal = est;
        } else {
            // Only some normals are unusable (zero or not finite): fill those, flipped to agree with
            // the majority of the given ones.
            int64_t agree = 0;
            for (uint32_t i = 0; i < n; i++)
                if (usable_normal(p.normal[i]))
                    agree += p.normal[i][0] * est[i][0] + p.normal[i][1] * est[i][1] + p.normal[i][2] * est[i][2] >= 0 ? 1 : -1;
            for (uint32_t i = 0; i < n; i++)
                if (!usable_normal(p.normal[i]))
                    for (int a = 0; a < 3; a++) p.normal[i][a] = agree >= 0 ? est[i][a] : -est[i][a];
            free(est);
            rep->normals_replaced = bad_normals;
        }
        rep->normals_estimated = true;
        step_end(&c);
    }

    step_begin(&c, RS_PACK_STEP_RADII);
    radius = rs_alloc_array(n, sizeof *radius);
    if (!radius) {
        r = rs_fail(err, RS_ERR_NOMEM, "out of memory for %u radii", n);
        goto out;
    }
    if (knn.k >= RS_PACK_RADIUS_K) r = rs_pack_radii(&knn, radius, err);
    if (r != RS_OK) goto out;
    rs_pack_knn_free(&knn);
    step_end(&c);

    step_begin(&c, RS_PACK_STEP_LOD);
    order = rs_alloc_array(n, sizeof *order);
    hdr = calloc(1, sizeof *hdr);
    if (!order || !hdr) {
        r = rs_fail(err, RS_ERR_NOMEM, "out of memory for %u points", n);
        goto out;
    }
    r = rs_pack_lod_order((const float(*)[3])p.pos, n, d->min_lod, order, hdr->lods, &hdr->lod_count, step_progress, &c, err);
    if (r != RS_OK) goto out;
    step_end(&c);

    step_begin(&c, RS_PACK_STEP_REGIONS);
    for (uint32_t i = 0; i < n; i++) rep->regions_given += p.region[i] != RS_PACK_REGION_AUTO;
    if (in->tri && in->tri_count > 0 && !estimate) {
        // A mesh's face comes from a sample of its own, the same at every requested count: on the splats
        // themselves the random sample tilts the face frame by up to ~0.7 deg, which moves the face
        // height by ~1 % (10k vs 300k points: 2 %). Normal maps tilt the frame's normals as the splats'.
        uint64_t kept = (uint64_t)in->tri_count - RS_MIN(rep->triangles_dropped, in->tri_count);
        uint32_t face_points = (uint32_t)RS_CLAMP(kept * RS_PACK_FACE_SAMPLE_PER_TRIANGLE, (uint64_t)RS_PACK_FACE_SAMPLE_MIN,
                                                  (uint64_t)RS_PACK_FACE_SAMPLE_POINTS);
        rs_pack_sample_desc fd = {.points = face_points, .seed = d->seed,
                                  .all_components = d->all_components, .normal_map = d->normal_map};
        rs_pack_points fp = {0};
        uint32_t dropped = 0;
        r = rs_pack_sample_mesh(in, &fd, &fp, &dropped, err);
        if (r == RS_OK)
            r = rs_pack_find_face((const float(*)[3])fp.pos, (const float(*)[3])fp.normal, fp.count, d->up, d->forward,
                                  &rep->face, err);
        rs_pack_points_free(&fp);
    } else {
        r = rs_pack_find_face((const float(*)[3])p.pos, (const float(*)[3])p.normal, n, d->up, d->forward, &rep->face, err);
    }
    if (r != RS_OK) goto out;
    if (rep->face.found && !face_finite(&rep->face)) {
        // A face whose landmarks are not finite (seen on a spider and an engine part) is no face: the
        // model is framed by its bounds, without face regions, and the caller says so.
        unframe(&rep->face, (const float(*)[3])p.pos, n);
        rep->face_rejected = true;
    }
    rs_pack_segment((const float(*)[3])p.pos, (const float(*)[3])p.normal, n, &rep->face, p.region);
    if (p.specular) {
        double sum[RS_SPLAT_MAX_REGIONS] = {0};
        uint32_t cnt[RS_SPLAT_MAX_REGIONS] = {0};
        for (uint32_t i = 0; i < n; i++) {
            sum[p.region[i]] += p.specular[i];
            cnt[p.region[i]]++;
        }
        for (int k = 0; k < RS_REGION_STANDARD_COUNT; k++)
            if (cnt[k]) rep->specular_mean[k] = (float)(sum[k] / cnt[k]);
    }
    step_end(&c);

    step_begin(&c, RS_PACK_STEP_ENCODE);
    splats = rs_alloc_array(n, sizeof *splats);
    if (!splats) {
        r = rs_fail(err, RS_ERR_NOMEM, "out of memory for %u splats", n);
        goto out;
    }
    // Colour from the input only where some point got it (pages that failed to load colour nothing).
    rep->colour_default = !p.rgb || p.default_rgb == p.count;
    rep->colour_default_points = p.rgb ? p.default_rgb : p.count;
    for (uint32_t j = 0; j < n; j++) {
        uint32_t i = order[j];
        rs_splat *s = &splats[j];
        memcpy(s->pos, p.pos[i], sizeof s->pos);
        memcpy(s->normal, p.normal[i], sizeof s->normal);
        s->radius = radius[i];
        if (p.rgb) memcpy(s->rgb, p.rgb[i], 3);
        else s->rgb[0] = RS_PACK_DEFAULT_RGB_R, s->rgb[1] = RS_PACK_DEFAULT_RGB_G, s->rgb[2] = RS_PACK_DEFAULT_RGB_B;
        s->region = p.region[i];
    }
    const rs_pack_face *f = &rep->face;
    memcpy(hdr->forward, f->forward, sizeof hdr->forward);
    memcpy(hdr->up, f->up, sizeof hdr->up);
    memcpy(hdr->centre, f->centre, sizeof hdr->centre);
    hdr->face_height = f->face_height;
    hdr->mm_per_unit = choose_scale(d, f, rep);
    rs_splat_default_regions(hdr);
    // The regions brushes need beside the built-ins. Not measured by Weyrich et al.: thin lid skin takes
    // the mean like `other`; brow hair scatters more broadly (rougher) and less (lower rho_s).
    hdr->regions[RS_REGION_EYELID] = (rs_region_info){"eyelid", hdr->regions[RS_REGION_OTHER].m,
                                                      hdr->regions[RS_REGION_OTHER].rho_s};
    hdr->regions[RS_REGION_BROW] = (rs_region_info){"brow", 0.35f, 0.18f};
    hdr->region_count = RS_REGION_STANDARD_COUNT;
    make_notes(hdr->notes, in->comments, d->notes);
    r = rs_splat_create(splats, n, hdr, out, err);
    if (r != RS_OK) goto out;
    rs_splat_quantize_normals(*out, RS_PACK_NORMAL_BITS);
    rs_splat_quantize_radii(*out, RS_PACK_RADIUS_BITS);
    step_end(&c);
    if (!d->no_ao) {
        step_begin(&c, RS_PACK_STEP_AO);
        r = rs_pack_ao_cloud(*out, err);
        if (r != RS_OK) {
            rs_splat_destroy(*out);
            *out = NULL;
            goto out;
        }
        step_end(&c);
    }
    rep->splats = n;
out:
    rs_pack_points_free(&p);
    rs_pack_knn_free(&knn);
    free(radius);
    free(order);
    free(splats);
    free(hdr);
    return r;
}
