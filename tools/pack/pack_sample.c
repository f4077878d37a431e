// pack_sample.c — area-uniform sampling of a (textured) triangle mesh into points (see pack.h).
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rs_pack_points_free(rs_pack_points *p)
{
    if (!p) return;
    free(p->pos);
    free(p->normal);
    free(p->rgb);
    free(p->region);
    free(p->specular);
    memset(p, 0, sizeof *p);
}

uint8_t rs_pack_region_from_rgb(const uint8_t rgb[3])
{
    static const uint8_t code[8][3] = {{0, 0, 0},     {255, 0, 0},   {0, 255, 0},   {0, 0, 255},
                                       {255, 255, 0}, {255, 0, 255}, {0, 255, 255}, {255, 255, 255}};
    static const uint8_t id[8] = {RS_REGION_OTHER, RS_REGION_CHEEK,  RS_REGION_NOSE, RS_REGION_FOREHEAD,
                                  RS_REGION_LIPS,  RS_REGION_EYELID, RS_REGION_BROW, RS_PACK_REGION_AUTO};
    int best = 7, best_d = 1 << 30;
    for (int i = 0; i < 8; i++) {
        int d = 0;
        for (int c = 0; c < 3; c++) d += (rgb[c] - code[i][c]) * (rgb[c] - code[i][c]);
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    return id[best];
}

static void sub3(const float a[3], const float b[3], float o[3])
{
    for (int i = 0; i < 3; i++) o[i] = a[i] - b[i];
}

static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static bool normalize3(float v[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 1e-20f) || !isfinite(l)) return false;
    for (int i = 0; i < 3; i++) v[i] /= l;
    return true;
}

// A coordinate outside [0, 1] brought inside by the wrap mode (tiling UVs: the glTF BoxTextured sample runs
// 0..6); inside, every mode is the identity, so scans' atlases sample exactly as before.
static float wrap_coord(float s, uint8_t mode)
{
    if (s >= 0.0f && s <= 1.0f) return s;
    if (!isfinite(s)) return 0.0f;
    if (mode == RS_PACK_WRAP_CLAMP) return RS_CLAMP(s, 0.0f, 1.0f);
    if (mode == RS_PACK_WRAP_MIRROR) {
        float f = s - 2.0f * floorf(s * 0.5f);
        return f > 1.0f ? 2.0f - f : f;
    }
    return s - floorf(s);
}

static const uint8_t wrap_repeat[2] = {RS_PACK_WRAP_REPEAT, RS_PACK_WRAP_REPEAT};

// Texel (s W, (1 - t) H) counted from the top row, bilinear between texel centres, clamped to the edge
// after the wrap mode: the PLY's t = 0 is the bottom row of the image (OpenGL convention, data README).
static void sample_bilinear(const rs_image *img, const uint8_t wrap[2], float s, float t, float out[3])
{
    s = wrap_coord(s, wrap[0]), t = wrap_coord(t, wrap[1]);
    float x = s * img->width - 0.5f, y = (1.0f - t) * img->height - 0.5f;
    x = RS_CLAMP(x, 0.0f, (float)(img->width - 1));
    y = RS_CLAMP(y, 0.0f, (float)(img->height - 1));
    int x0 = (int)x, y0 = (int)y;
    int x1 = RS_MIN(x0 + 1, img->width - 1), y1 = RS_MIN(y0 + 1, img->height - 1);
    float fx = x - x0, fy = y - y0;
    const uint8_t *p = img->pixels;
    size_t stride = (size_t)img->width * img->channels;
    for (int c = 0; c < 3; c++) {
        float a = p[y0 * stride + (size_t)x0 * img->channels + c], b = p[y0 * stride + (size_t)x1 * img->channels + c];
        float d = p[y1 * stride + (size_t)x0 * img->channels + c], e = p[y1 * stride + (size_t)x1 * img->channels + c];
        out[c] = (a + (b - a) * fx) * (1 - fy) + (d + (e - d) * fx) * fy;
    }
}

static void sample_nearest(const rs_image *img, float s, float t, uint8_t out[3])
{
    s = wrap_coord(s, RS_PACK_WRAP_REPEAT), t = wrap_coord(t, RS_PACK_WRAP_REPEAT);
    // Clamped as floats first: out-of-range (or NaN) UVs must not reach an int conversion.
    int x = (int)RS_CLAMP(floorf(s * img->width), 0.0f, (float)(img->width - 1));
    int y = (int)RS_CLAMP(floorf((1.0f - t) * img->height), 0.0f, (float)(img->height - 1));
    memcpy(out, img->pixels + ((size_t)y * img->width + x) * img->channels, 3);
}

static uint32_t uf_find(uint32_t *parent, uint32_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];  // path halving
        x = parent[x];
    }
    return x;
}

static void uf_union(uint32_t *parent, uint32_t x, uint32_t y)
{
    uint32_t a = uf_find(parent, x), b = uf_find(parent, y);
    if (a != b) parent[a < b ? b : a] = a < b ? a : b;
}

typedef struct vkey {
    float p[3];
    uint32_t id;
} vkey;

static int cmp_vkey(const void *a, const void *b)
{
    const vkey *x = a, *y = b;
    for (int k = 0; k < 3; k++)
        if (x->p[k] != y->p[k]) return x->p[k] < y->p[k] ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

// A multi-material model splits its surface into one vertex set per material: vertices of different
// pages at the same position are joined, so a scan cut into texture pages is still one component.
static rs_result join_pages(const rs_ply_mesh *m, uint32_t *parent, rs_error *err)
{
    uint16_t *vpage = rs_alloc_array(m->vertex_count, sizeof *vpage);
    vkey *k = rs_alloc_array(m->vertex_count, sizeof *k);
    if (!vpage || !k) {
        free(vpage);
        free(k);
        return rs_fail(err, RS_ERR_NOMEM, "mesh: out of memory for %u vertices", m->vertex_count);
    }
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int c = 0; c < 3; c++) vpage[m->tri[t][c]] = m->tri_page[t];
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        memcpy(k[v].p, m->pos[v], sizeof k[v].p);
        k[v].id = v;
    }
    qsort(k, m->vertex_count, sizeof *k, cmp_vkey);
    for (uint32_t i = 1; i < m->vertex_count; i++)
        if (!memcmp(k[i].p, k[i - 1].p, sizeof k[i].p) && vpage[k[i].id] != vpage[k[i - 1].id])
            uf_union(parent, k[i].id, k[i - 1].id);
    free(vpage);
    free(k);
    return RS_OK;
}

// Keeps the triangles of the largest component (by area): triangles sharing a vertex index are
// connected. The data's meshes split vertices along UV seams, so components are the UV islands and the
// largest is the skin (leeperrysmith README, "Non-skin parts of the mesh").
static rs_result largest_component(const rs_ply_mesh *m, const double *area, uint8_t *keep, rs_error *err)
{
    uint32_t *parent = rs_alloc_array(m->vertex_count, sizeof *parent);
    double *comp = calloc(m->vertex_count ? m->vertex_count : 1, sizeof *comp);
    if (!parent || !comp) {
        free(parent);
        free(comp);
        return rs_fail(err, RS_ERR_NOMEM, "mesh: out of memory for %u vertices", m->vertex_count);
    }
    for (uint32_t v = 0; v < m->vertex_count; v++) parent[v] = v;
    for (uint32_t t = 0; t < m->tri_count; t++)
        for (int e = 1; e < 3; e++) uf_union(parent, m->tri[t][0], m->tri[t][e]);
    if (m->tri_page) {
        rs_result r = join_pages(m, parent, err);
        if (r != RS_OK) {
            free(parent);
            free(comp);
            return r;
        }
    }
    for (uint32_t t = 0; t < m->tri_count; t++) comp[uf_find(parent, m->tri[t][0])] += area[t];
    uint32_t best = 0;
    for (uint32_t v = 1; v < m->vertex_count; v++)
        if (comp[v] > comp[best]) best = v;
    for (uint32_t t = 0; t < m->tri_count; t++) keep[t] = uf_find(parent, m->tri[t][0]) == best;
    free(parent);
    free(comp);
    return RS_OK;
}

// Per-vertex tangent frames from the UV derivatives (Lengyel 2001): T = dP/ds, B = dP/dt accumulated
// over the vertex's triangles, T made orthogonal to the normal, and the handedness w = sign((N x T) . B)
// so mirrored UV islands get B = w (N x T).
static void vertex_tangents(const rs_ply_mesh *m, float (*vn)[3], float (*tan)[4])
{
    float(*bit)[3] = calloc(m->vertex_count, sizeof *bit);
    for (uint32_t v = 0; v < m->vertex_count; v++) memset(tan[v], 0, sizeof tan[v]);
    for (uint32_t t = 0; t < m->tri_count && bit; t++) {
        const uint32_t *i = m->tri[t];
        float e1[3], e2[3];
        sub3(m->pos[i[1]], m->pos[i[0]], e1);
        sub3(m->pos[i[2]], m->pos[i[0]], e2);
        float s1 = m->uv[i[1]][0] - m->uv[i[0]][0], t1 = m->uv[i[1]][1] - m->uv[i[0]][1];
        float s2 = m->uv[i[2]][0] - m->uv[i[0]][0], t2 = m->uv[i[2]][1] - m->uv[i[0]][1];
        float det = s1 * t2 - s2 * t1;
        if (fabsf(det) < 1e-20f) continue;
        float r = 1.0f / det, T[3], B[3];
        for (int a = 0; a < 3; a++) {
            T[a] = (t2 * e1[a] - t1 * e2[a]) * r;
            B[a] = (s1 * e2[a] - s2 * e1[a]) * r;
        }
        if (!isfinite(T[0] + T[1] + T[2] + B[0] + B[1] + B[2])) continue;
        for (int c = 0; c < 3; c++)
            for (int a = 0; a < 3; a++) {
                tan[i[c]][a] += T[a];
                bit[i[c]][a] += B[a];
            }
    }
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        float *T = tan[v], *n = vn[v], d = dot3(n, T);
        for (int a = 0; a < 3; a++) T[a] -= n[a] * d;
        if (!normalize3(T)) {  // no UV gradient here: any tangent will do, the map is flat-ish anyway
            float ax[3] = {fabsf(n[0]) < 0.9f ? 1.0f : 0.0f, fabsf(n[0]) < 0.9f ? 0.0f : 1.0f, 0};
            cross3(n, ax, T);
            normalize3(T);
        }
        float nxt[3];
        cross3(n, T, nxt);
        T[3] = bit && dot3(nxt, bit[v]) < 0 ? -1.0f : 1.0f;
    }
    free(bit);
}

rs_result rs_pack_sample_mesh(const rs_ply_mesh *m, const rs_pack_sample_desc *d, rs_pack_points *out,
                              uint32_t *triangles_dropped, rs_error *err)
{
    uint32_t n = d->points ? d->points : RS_PACK_DEFAULT_MESH_POINTS;
    if (m->tri_count == 0 || !m->tri) return rs_fail(err, RS_ERR_ARG, "mesh: the PLY has no faces to sample");
    if ((d->texture || d->normal_map || d->specular_map || d->region_map) && !m->uv)
        return rs_fail(err, RS_ERR_ARG, "mesh: texture maps need texture coordinates (s t, u v or texture_u texture_v)");
    // Material pages without texture coordinates cannot be sampled: vertex colours (or none) instead.
    bool paged = !d->texture && m->uv && d->pages && d->page_count > 0;
    if (n > RS_SPLAT_MAX_COUNT) return rs_fail(err, RS_ERR_LIMIT, "mesh: %u points asked, at most %u", n, RS_SPLAT_MAX_COUNT);

    rs_pack_points p = {.count = n};
    double *area = rs_alloc_array(m->tri_count, sizeof *area);
    uint8_t *keep = rs_alloc_array(m->tri_count, 1);
    float(*vn)[3] = rs_alloc_array(m->vertex_count, sizeof *vn);
    float(*tan)[4] = d->normal_map ? rs_alloc_array(m->vertex_count, sizeof *tan) : NULL;
    p.pos = rs_alloc_array(n, sizeof *p.pos);
    p.normal = rs_alloc_array(n, sizeof *p.normal);
    p.region = rs_alloc_array(n, 1);
    p.rgb = d->texture || paged || m->rgb ? rs_alloc_array(n, sizeof *p.rgb) : NULL;
    p.specular = d->specular_map ? rs_alloc_array(n, sizeof *p.specular) : NULL;
    rs_result res = RS_OK;
    if (!area || !keep || !vn || (d->normal_map && !tan) || !p.pos || !p.normal || !p.region ||
        ((d->texture || paged || m->rgb) && !p.rgb) || (d->specular_map && !p.specular)) {
        res = rs_fail(err, RS_ERR_NOMEM, "mesh: out of memory sampling %u points", n);
        goto out;
    }

    // Face normals (length = twice the area) give the areas and, when the file has none, area-weighted
    // vertex normals; faces are counter-clockwise seen from outside (PLY convention).
    memset(vn, 0, (size_t)m->vertex_count * sizeof *vn);
    for (uint32_t t = 0; t < m->tri_count; t++) {
        const uint32_t *i = m->tri[t];
        float e1[3], e2[3], fn[3];
        sub3(m->pos[i[1]], m->pos[i[0]], e1);
        sub3(m->pos[i[2]], m->pos[i[0]], e2);
        cross3(e1, e2, fn);
        double a = 0.5 * sqrt((double)dot3(fn, fn));
        area[t] = isfinite(a) ? a : 0.0;
        for (int c = 0; c < 3 && !m->normal; c++)
            for (int k = 0; k < 3; k++) vn[i[c]][k] += fn[k];
    }
    for (uint32_t v = 0; v < m->vertex_count; v++) {
        if (m->normal) memcpy(vn[v], m->normal[v], sizeof vn[v]);
        if (!normalize3(vn[v])) vn[v][0] = vn[v][1] = 0, vn[v][2] = 1;
    }
    if (d->all_components) memset(keep, 1, m->tri_count);
    else if ((res = largest_component(m, area, keep, err)) != RS_OK) goto out;
    uint32_t dropped = 0;
    double total = 0;
    for (uint32_t t = 0; t < m->tri_count; t++) {
        if (!keep[t]) {
            dropped++;
            area[t] = 0;
        }
        total += area[t];
        area[t] = total;  // now the CDF
    }
    if (!(total > 0)) {
        res = rs_fail(err, RS_ERR_FORMAT, "mesh: the triangles have no area");
        goto out;
    }
    if (tan) vertex_tangents(m, vn, tan);

    rs_pack_rng rng;
    rs_pack_rng_seed(&rng, d->seed ? d->seed : RS_PACK_DEFAULT_SEED);
    for (uint32_t s = 0; s < n; s++) {
        // Triangle by area: the first with CDF > u (binary search), skipping zero-area ones.
        double u = rs_pack_rng_unit(&rng) * total;
        uint32_t lo = 0, hi = m->tri_count - 1;
        while (lo < hi) {
            uint32_t mid = lo + (hi - lo) / 2;
            if (area[mid] > u) hi = mid;
            else lo = mid + 1;
        }
        const uint32_t *i = m->tri[lo];
        // Osada et al. eq. 1: uniform on the triangle from two uniforms.
        float r1 = sqrtf((float)rs_pack_rng_unit(&rng)), r2 = (float)rs_pack_rng_unit(&rng);
        float w[3] = {1.0f - r1, r1 * (1.0f - r2), r1 * r2};
        float nrm[3] = {0, 0, 0}, uv[2] = {0, 0};
        for (int a = 0; a < 3; a++) {
            p.pos[s][a] = w[0] * m->pos[i[0]][a] + w[1] * m->pos[i[1]][a] + w[2] * m->pos[i[2]][a];
            nrm[a] = w[0] * vn[i[0]][a] + w[1] * vn[i[1]][a] + w[2] * vn[i[2]][a];
        }
        if (!normalize3(nrm)) memcpy(nrm, vn[i[0]], sizeof nrm);
        if (m->uv)
            for (int a = 0; a < 2; a++) uv[a] = w[0] * m->uv[i[0]][a] + w[1] * m->uv[i[1]][a] + w[2] * m->uv[i[2]][a];
        if (d->normal_map) {
            float T[3], B[3], h = 0, ts[3];
            for (int a = 0; a < 3; a++) T[a] = w[0] * tan[i[0]][a] + w[1] * tan[i[1]][a] + w[2] * tan[i[2]][a];
            for (int c = 0; c < 3; c++) h += w[c] * tan[i[c]][3];
            float dn = dot3(T, nrm);
            for (int a = 0; a < 3; a++) T[a] -= nrm[a] * dn;
            if (normalize3(T)) {
                cross3(nrm, T, B);
                for (int a = 0; a < 3; a++) B[a] *= h < 0 ? -1.0f : 1.0f;
                // Tangent-space normal n = rgb / 255 * 2 - 1, OpenGL convention: R along +s, G along +t.
                sample_bilinear(d->normal_map, wrap_repeat, uv[0], uv[1], ts);
                for (int a = 0; a < 3; a++) ts[a] = ts[a] / 255.0f * 2.0f - 1.0f;
                float pn[3];
                for (int a = 0; a < 3; a++) pn[a] = ts[0] * T[a] + ts[1] * B[a] + ts[2] * nrm[a];
                if (normalize3(pn) && dot3(pn, nrm) > 0) memcpy(nrm, pn, sizeof nrm);
            }
        }
        memcpy(p.normal[s], nrm, sizeof nrm);
        const rs_image *colour = d->texture;
        const uint8_t *wrap = wrap_repeat;
        if (paged) {
            uint32_t pg = m->tri_page ? m->tri_page[lo] : 0;
            colour = pg < d->page_count && d->pages[pg].pixels ? &d->pages[pg] : NULL;
            if (colour && d->page_wrap) wrap = d->page_wrap[pg];
        }
        if (colour) {
            float c[3];
            sample_bilinear(colour, wrap, uv[0], uv[1], c);
            for (int a = 0; a < 3; a++) p.rgb[s][a] = (uint8_t)lrintf(RS_CLAMP(c[a], 0.0f, 255.0f));
        } else if (m->rgb) {
            for (int a = 0; a < 3; a++)
                p.rgb[s][a] = (uint8_t)lrintf(w[0] * m->rgb[i[0]][a] + w[1] * m->rgb[i[1]][a] + w[2] * m->rgb[i[2]][a]);
        } else if (p.rgb) {
            p.rgb[s][0] = RS_PACK_DEFAULT_RGB_R, p.rgb[s][1] = RS_PACK_DEFAULT_RGB_G, p.rgb[s][2] = RS_PACK_DEFAULT_RGB_B;
            p.default_rgb++;
        }
        if (d->specular_map) {
            float c[3];
            sample_bilinear(d->specular_map, wrap_repeat, uv[0], uv[1], c);
            p.specular[s] = (c[0] + c[1] + c[2]) / (3.0f * 255.0f);
        }
        p.region[s] = RS_PACK_REGION_AUTO;
        if (d->region_map) {
            uint8_t c[3];
            sample_nearest(d->region_map, uv[0], uv[1], c);
            p.region[s] = rs_pack_region_from_rgb(c);
        } else if (m->region) {
            int c = w[0] >= w[1] && w[0] >= w[2] ? 0 : w[1] >= w[2] ? 1 : 2;  // ids do not interpolate
            p.region[s] = m->region[i[c]];
        }
    }
    if (triangles_dropped) *triangles_dropped = dropped;
    *out = p;
    memset(&p, 0, sizeof p);
out:
    rs_pack_points_free(&p);
    free(area);
    free(keep);
    free(vn);
    free(tan);
    return res;
}
