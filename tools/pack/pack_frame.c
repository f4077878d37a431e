// pack_frame.c — the face frame of a scan in any orientation (see pack.h, docs/regions.md).
//
// Nothing here looks at the coordinate axes, so the frame found for a rotated scan is the rotated frame:
//   1. side: the normal of the mirror plane. A mirror-symmetric shape's covariance has the mirror normal
//      as an eigenvector, so candidates are the three principal axes and directions between them (10 deg
//      apart, in case two variances are close); each is scored by how well the scan, reflected in the
//      plane, lands on itself (mean truncated squared distance to the nearest point), and the best is
//      refined by a pattern search over the normal and the plane's offset;
//   2. the nose tip: of the points on the mirror plane, the one that stands out most above rings around
//      it, along its own normal; the rough forward is the mean normal of the face around it;
//   3. the facial frame, for both senses of up: forward is the mean normal of the face around the nose
//      tip (a Gaussian of 0.25 face heights) in the mirror plane, up is perpendicular to it there; the
//      landmarks (pack_face.c) are found again in that frame, until forward moves less than 0.1 deg;
//   4. up or down: the sense whose face matches the bundled head's depth around the nose (a 9 x 9 grid
//      in face heights) better; if neither matches closely, it is no face (two cubes have a "nose").
// All of it runs on a subsample of at most 16000 points taken by index, so it does not depend on the
// coordinates either.
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FRAME_SAMPLE 16000u
#define MIRROR_QUERIES 2000u

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static bool normalize3(float v[3])
{
    float l = sqrtf(dot3(v, v));
    if (!(l > 1e-20f) || !isfinite(l)) return false;
    for (int i = 0; i < 3; i++) v[i] /= l;
    return true;
}

// Any unit vector perpendicular to n.
static void perpendicular(const float n[3], float out[3])
{
    float ax[3] = {0, 0, 0};
    int k = fabsf(n[0]) < fabsf(n[1]) ? (fabsf(n[0]) < fabsf(n[2]) ? 0 : 2) : (fabsf(n[1]) < fabsf(n[2]) ? 1 : 2);
    ax[k] = 1;
    cross3(n, ax, out);
    normalize3(out);
}

// The scan's points bucketed in cubes a little wider than the mirror cost's truncation distance: a
// point nearer a query than that lies in the 27 cubes around it. Per query that is cheaper than the k-d
// tree's walk (a good plane's reflections land on the surface, where the walk backtracks), and it finds
// the same nearest distance.
typedef struct grid {
    double o[3], inv;  // origin and 1 / cube side (double: a scan far from the origin keeps its cells)
    int dim[3];
    uint32_t *start;   // dim[0] dim[1] dim[2] + 1 offsets into pts, cell by cell (x fastest)
    float (*pts)[3];
} grid;

#define GRID_MAX_CELLS (1u << 22)

static int grid_cell(const grid *g, float v, int a)
{
    double c = floor(((double)v - g->o[a]) * g->inv);
    return c < -1 ? -1 : c > g->dim[a] ? g->dim[a] : (int)c;
}

// False (g->start NULL) when the cubes would be too many (a few far outliers): the tree answers then.
static bool grid_build(grid *g, const float (*p)[3], uint32_t n, const float lo[3], const float hi[3], float cell)
{
    memset(g, 0, sizeof *g);
    size_t cells = 1;
    for (int a = 0; a < 3; a++) {
        double d = floor(((double)hi[a] - lo[a]) / cell) + 1;
        if (!(d >= 1 && d <= GRID_MAX_CELLS)) return false;
        g->dim[a] = (int)d;
        g->o[a] = lo[a];
        cells *= (size_t)d;
        if (cells > GRID_MAX_CELLS) return false;
    }
    g->inv = 1.0 / cell;
    g->start = calloc(cells + 1, sizeof *g->start);
    g->pts = rs_alloc_array(n, sizeof *g->pts);
    uint32_t *at = rs_alloc_array(n, sizeof *at);
    if (!g->start || !g->pts || !at) {
        free(g->start), free(g->pts), free(at);
        g->start = NULL, g->pts = NULL;
        return false;
    }
    for (uint32_t i = 0; i < n; i++) {
        int x = grid_cell(g, p[i][0], 0), y = grid_cell(g, p[i][1], 1), z = grid_cell(g, p[i][2], 2);
        at[i] = (uint32_t)(((size_t)z * g->dim[1] + (size_t)y) * g->dim[0] + (size_t)x);
        g->start[at[i] + 1]++;
    }
    for (size_t c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
    for (uint32_t i = 0; i < n; i++) memcpy(g->pts[g->start[at[i]]++], p[i], sizeof *g->pts);
    for (size_t c = cells; c > 0; c--) g->start[c] = g->start[c - 1];  // back to the first of each cell
    g->start[0] = 0;
    free(at);
    return true;
}

static void grid_free(grid *g)
{
    free(g->start);
    free(g->pts);
}

// As rs_pack_kdtree_nearest_within: the smallest squared distance under bound2 (which is at most the
// cube side squared), false when no point is that near.
static bool grid_nearest_within(const grid *g, const float q[3], float bound2, float *d2)
{
    int c[3];
    for (int a = 0; a < 3; a++) c[a] = grid_cell(g, q[a], a);
    float best = bound2;
    bool found = false;
    for (int z = RS_MAX(c[2] - 1, 0); z <= RS_MIN(c[2] + 1, g->dim[2] - 1); z++)
        for (int y = RS_MAX(c[1] - 1, 0); y <= RS_MIN(c[1] + 1, g->dim[1] - 1); y++) {
            size_t row = ((size_t)z * g->dim[1] + (size_t)y) * g->dim[0];
            int x0 = RS_MAX(c[0] - 1, 0), x1 = RS_MIN(c[0] + 1, g->dim[0] - 1);
            if (x0 > x1) continue;
            // The cells of a row are consecutive: one run of points.
            for (uint32_t i = g->start[row + (size_t)x0]; i < g->start[row + (size_t)x1 + 1]; i++) {
                const float *p = g->pts[i];
                float dx = p[0] - q[0], dy = p[1] - q[1], dz = p[2] - q[2];
                float e = dx * dx + dy * dy + dz * dz;
                if (e < best) best = e, found = true;
            }
        }
    if (found) *d2 = best;
    return found;
}

typedef struct mirror {
    const float (*pos)[3];
    uint32_t count, queries, stride;
    const rs_pack_kdtree *tree;
    const grid *grid;  // NULL: the tree
    float cap2;        // squared truncation distance
} mirror;

// Mean truncated squared distance from the reflected query points to the scan. The callers only keep a
// plane that costs less than `bound`: once the partial mean (every term is >= 0) reaches it, that mean
// is returned as it is, which the caller turns down just as it would the whole.
static double mirror_cost(const mirror *m, const float n[3], float d, double bound)
{
    double sum = 0;
    for (uint32_t q = 0; q < m->queries; q++) {
        if ((q & 63) == 63 && sum / m->queries >= bound) break;
        const float *p = m->pos[(size_t)q * m->stride];
        float t = 2.0f * (dot3(p, n) - d), r[3] = {p[0] - t * n[0], p[1] - t * n[1], p[2] - t * n[2]};
        float d2;
        if (m->grid ? grid_nearest_within(m->grid, r, m->cap2, &d2) : rs_pack_kdtree_nearest_within(m->tree, r, m->cap2, &d2)) {
            float dist = sqrtf(d2);
            sum += fminf(dist * dist, m->cap2);
        } else {
            sum += m->cap2;
        }
    }
    return sum / m->queries;
}

// Rotates v by angle a about the unit axis k (Rodrigues).
static void rotate(const float v[3], const float k[3], float a, float out[3])
{
    float c = cosf(a), s = sinf(a), kv[3], kd = dot3(k, v);
    cross3(k, v, kv);
    for (int i = 0; i < 3; i++) out[i] = v[i] * c + kv[i] * s + k[i] * kd * (1 - c);
}

// The mirror plane: *n (unit) and *d (offset along n). Returns false for degenerate input.
static bool find_mirror(const mirror *m, const float centroid[3], const double vec[3][3], float n_out[3], float *d_out,
                        float extent)
{
    float best_n[3] = {0, 0, 1}, best_d = 0;
    double best = INFINITY;
    float seeds[3][3];
    double seed_cost[3] = {INFINITY, INFINITY, INFINITY};
    // Coarse: the principal axes and 17 directions between each pair.
    for (int pr = 0; pr < 3; pr++) {
        const double *a = vec[pr], *b = vec[(pr + 1) % 3];
        for (int k = 0; k < 18; k++) {
            float t = (float)k * 0.17453293f, n[3];
            for (int i = 0; i < 3; i++) n[i] = (float)(cosf(t) * a[i] + sinf(t) * b[i]);
            if (!normalize3(n)) continue;
            float d = dot3(centroid, n);
            double c = mirror_cost(m, n, d, seed_cost[2]);
            // Keep the three best distinct seeds.
            for (int s = 0; s < 3; s++)
                if (c < seed_cost[s]) {
                    for (int j = 2; j > s; j--) {
                        seed_cost[j] = seed_cost[j - 1];
                        memcpy(seeds[j], seeds[j - 1], sizeof seeds[j]);
                    }
                    seed_cost[s] = c;
                    memcpy(seeds[s], n, sizeof seeds[s]);
                    break;
                }
        }
    }
    // Fine: pattern search on the normal's direction (two tilt axes) and the offset, halving the steps.
    for (int s = 0; s < 3; s++) {
        if (!isfinite(seed_cost[s])) continue;
        float n[3], d;
        memcpy(n, seeds[s], sizeof n);
        d = dot3(centroid, n);
        double c = seed_cost[s];
        float step = 0.0873f, dstep = 0.01f * extent;  // 5 deg, 1% of the extent
        for (int it = 0; it < 60 && step > 0.0017f; it++) {
            bool moved = false;
            float t1[3], t2[3];
            perpendicular(n, t1);
            cross3(n, t1, t2);
            for (int k = 0; k < 6; k++) {
                float cn[3], cd = d;
                if (k < 4) {
                    rotate(n, k < 2 ? t1 : t2, (k & 1) ? -step : step, cn);
                    normalize3(cn);
                } else {
                    memcpy(cn, n, sizeof cn);
                    cd = d + ((k & 1) ? -dstep : dstep);
                }
                double cc = mirror_cost(m, cn, cd, c);
                if (cc < c) {
                    c = cc;
                    memcpy(n, cn, sizeof n);
                    d = cd;
                    moved = true;
                }
            }
            if (!moved) step *= 0.5f, dstep *= 0.5f;
        }
        if (c < best) {
            best = c;
            memcpy(best_n, n, sizeof best_n);
            best_d = d;
        }
    }
    memcpy(n_out, best_n, sizeof best_n);
    *d_out = best_d;
    return isfinite(best);
}

// Mean normal of the points near the nose tip (Gaussian weight, sigma 0.25 H, front-facing ones only),
// made perpendicular to side: the direction the face looks.
static bool face_forward(const float (*pos)[3], const float (*normal)[3], uint32_t count, const rs_pack_face *f,
                         const float side[3], float out[3])
{
    double acc[3] = {0, 0, 0};
    float s2 = 0.25f * f->face_height;
    s2 = 2 * s2 * s2;
    for (uint32_t i = 0; i < count; i++) {
        if (dot3(normal[i], f->forward) < 0.0f) continue;
        float d[3] = {pos[i][0] - f->nose_tip[0], pos[i][1] - f->nose_tip[1], pos[i][2] - f->nose_tip[2]};
        float w = expf(-dot3(d, d) / s2);
        for (int a = 0; a < 3; a++) acc[a] += w * normal[i][a];
    }
    float v[3] = {(float)acc[0], (float)acc[1], (float)acc[2]}, k = dot3(v, side);
    for (int a = 0; a < 3; a++) v[a] -= k * side[a];
    if (!normalize3(v) || dot3(v, f->forward) < 0.5f) return false;
    memcpy(out, v, sizeof v);
    return true;
}

// Depth of the front surface behind the nose tip, in face heights, on a 9 x 9 grid of 0.06 H cells
// centred on the tip, rows from 0.27 H below the tip (chin) to 0.27 H above it (brow), columns across
// the face: the bundled head (assets/face.rsf) in its own face frame. It only tells up from down: an
// upside-down face puts its brow where the template has lips and chin.
#define TEMPLATE_N 9
#define TEMPLATE_HALF 0.27f
#define TEMPLATE_MAX_COST 0.004f  // mean squared depth difference (face heights^2) still called a face
static const float face_template[TEMPLATE_N][TEMPLATE_N] = {
    {-0.187f, -0.123f, -0.095f, -0.064f, -0.056f, -0.061f, -0.090f, -0.127f, -0.190f},
    {-0.170f, -0.115f, -0.091f, -0.059f, -0.055f, -0.058f, -0.092f, -0.120f, -0.178f},
    {-0.168f, -0.115f, -0.085f, -0.053f, -0.047f, -0.055f, -0.088f, -0.120f, -0.177f},
    {-0.169f, -0.119f, -0.095f, -0.056f, -0.017f, -0.060f, -0.098f, -0.128f, -0.183f},
    {-0.175f, -0.130f, -0.118f, -0.012f, 0.000f, -0.015f, -0.124f, -0.139f, -0.189f},
    {-0.187f, -0.159f, -0.133f, -0.032f, -0.015f, -0.038f, -0.145f, -0.164f, -0.197f},
    {-0.188f, -0.147f, -0.146f, -0.087f, -0.064f, -0.112f, -0.147f, -0.152f, -0.205f},
    {-0.162f, -0.130f, -0.115f, -0.104f, -0.102f, -0.102f, -0.115f, -0.137f, -0.180f},
    {-0.165f, -0.129f, -0.105f, -0.099f, -0.099f, -0.099f, -0.110f, -0.138f, -0.190f},
};

// Mean squared difference between the scan's front depth grid (frame fw, up, side at the tip, face
// height H) and the template, over the cells both have; INFINITY when fewer than half do.
static float template_cost(const float (*pos)[3], const float (*normal)[3], uint32_t count, const float tip[3],
                           const float fw[3], const float up[3], const float side[3], float H)
{
    float grid[TEMPLATE_N][TEMPLATE_N];
    for (int y = 0; y < TEMPLATE_N; y++)
        for (int x = 0; x < TEMPLATE_N; x++) grid[y][x] = -INFINITY;
    float cell = 2 * TEMPLATE_HALF / TEMPLATE_N;
    for (uint32_t i = 0; i < count; i++) {
        if (dot3(normal[i], fw) < -0.2f) continue;
        float d[3] = {pos[i][0] - tip[0], pos[i][1] - tip[1], pos[i][2] - tip[2]};
        float sx = dot3(d, side) / H + TEMPLATE_HALF, uy = dot3(d, up) / H + TEMPLATE_HALF;
        if (!(sx >= 0 && uy >= 0 && sx < 2 * TEMPLATE_HALF && uy < 2 * TEMPLATE_HALF)) continue;
        int x = RS_MIN((int)(sx / cell), TEMPLATE_N - 1), y = RS_MIN((int)(uy / cell), TEMPLATE_N - 1);
        grid[y][x] = fmaxf(grid[y][x], dot3(d, fw) / H);
    }
    double sum = 0;
    int cells = 0;
    for (int y = 0; y < TEMPLATE_N; y++)
        for (int x = 0; x < TEMPLATE_N; x++) {
            if (grid[y][x] == -INFINITY) continue;
            float e = grid[y][x] - face_template[y][x];
            sum += e * e;
            cells++;
        }
    return cells * 2 > TEMPLATE_N * TEMPLATE_N ? (float)(sum / cells) : INFINITY;
}

// The facial frame from a rough one: forward is the mean normal of the face around the nose tip, up is
// perpendicular to it in the mirror plane (whose normal, side, stays); the landmarks are found again in
// the new frame, until forward moves less than 0.1 deg. *g gets the landmarks of the last frame.
static rs_result refine(float (*sp)[3], float (*sn)[3], uint32_t n, float up[3], float fw[3], rs_pack_face *g, rs_error *err)
{
    float side[3];
    cross3(up, fw, side);
    for (int it = 0; it < 16; it++) {
        rs_result r = rs_pack_find_face_frame((const float(*)[3])sp, (const float(*)[3])sn, n, up, fw, g, err);
        if (r != RS_OK || !g->found) return r;
        float nf[3], nu[3];
        if (!face_forward((const float(*)[3])sp, (const float(*)[3])sn, n, g, side, nf)) return RS_OK;
        cross3(nf, side, nu);
        if (!normalize3(nu)) return RS_OK;
        float moved = dot3(nf, fw);
        memcpy(fw, nf, sizeof nf);
        memcpy(up, nu, sizeof nu);
        if (moved > 0.9999985f) break;  // 0.1 deg
    }
    return rs_pack_find_face_frame((const float(*)[3])sp, (const float(*)[3])sn, n, up, fw, g, err);
}

rs_result rs_pack_orient(const float (*pos)[3], const float (*normal)[3], uint32_t count, float up[3], float forward[3],
                         float *mirror_offset, bool *found, rs_error *err)
{
    *found = false;
    if (count < 100 || !normal) return RS_OK;
    uint32_t stride = count > FRAME_SAMPLE ? (count + FRAME_SAMPLE - 1) / FRAME_SAMPLE : 1, n = (count + stride - 1) / stride;
    float(*sp)[3] = rs_alloc_array(n, sizeof *sp), (*sn)[3] = rs_alloc_array(n, sizeof *sn);
    if (!sp || !sn) {
        free(sp), free(sn);
        return rs_fail(err, RS_ERR_NOMEM, "face: out of memory");
    }
    double c[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++) {
        memcpy(sp[i], pos[(size_t)i * stride], sizeof sp[i]);
        memcpy(sn[i], normal[(size_t)i * stride], sizeof sn[i]);
        for (int a = 0; a < 3; a++) c[a] += sp[i][a];
    }
    for (int a = 0; a < 3; a++) c[a] /= n;
    double cov[3][3] = {{0}};
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++) {
        double d[3] = {sp[i][0] - c[0], sp[i][1] - c[1], sp[i][2] - c[2]};
        for (int a = 0; a < 3; a++) {
            for (int b = 0; b < 3; b++) cov[a][b] += d[a] * d[b];
            lo[a] = fminf(lo[a], sp[i][a]);
            hi[a] = fmaxf(hi[a], sp[i][a]);
        }
    }
    double w[3], vec[3][3];
    rs_pack_eigen_sym3((const double(*)[3])cov, w, vec);
    // The diagonal of the bounding box does not depend on orientation up to the box's own rotation; it
    // only scales steps and the truncation, so a rough size is enough: the RMS radius.
    float extent = (float)sqrt((w[0] + w[1] + w[2]) / n) * 2.0f;
    // A flat model (its thinnest spread under 0.1 % of its widest: a quad, a sheet, a decal) has nothing
    // standing out of it: no nose, and a face's depths (0.2 face heights) are not there to match.
    if (!(w[0] > 1e-6 * w[2])) {
        free(sp), free(sn);
        return RS_OK;
    }
    rs_pack_kdtree *tree = NULL;
    rs_result r = rs_pack_kdtree_create((const float(*)[3])sp, n, &tree, err);
    if (r != RS_OK || !(extent > 0) || !isfinite(extent)) {
        free(sp), free(sn);
        rs_pack_kdtree_destroy(tree);
        return r;
    }
    // Point spacing: the median distance to the nearest other point, over up to 256 points.
    float nn[256];
    uint32_t nn_n = RS_MIN(n, 256u);
    for (uint32_t i = 0; i < nn_n; i++) {
        uint32_t idx, id = (uint32_t)((uint64_t)i * n / nn_n);
        float dist = 0;
        nn[i] = rs_pack_kdtree_query(tree, sp[id], 1, id, &idx, &dist) ? dist : 0;
    }
    for (uint32_t i = 1; i < nn_n; i++)  // insertion sort: 256 values
        for (uint32_t j = i; j > 0 && nn[j - 1] > nn[j]; j--) {
            float t = nn[j];
            nn[j] = nn[j - 1], nn[j - 1] = t;
        }
    float spacing = nn[nn_n / 2];
    mirror mr = {.pos = (const float(*)[3])sp, .count = n, .tree = tree};
    mr.queries = RS_MIN(n, MIRROR_QUERIES);
    mr.stride = n / mr.queries;
    float cap = 0.03f * extent;
    mr.cap2 = cap * cap;
    grid g;
    if (grid_build(&g, (const float(*)[3])sp, n, lo, hi, cap * 1.001f)) mr.grid = &g;
    float centroid[3] = {(float)c[0], (float)c[1], (float)c[2]}, side[3], plane_d;
    bool ok = find_mirror(&mr, centroid, (const double(*)[3])vec, side, &plane_d, extent);
    if (mr.grid) grid_free(&g);
    // The nose tip: of the points near the mirror plane, the one standing out most along its own normal
    // above rings around it (the mean of (p - q) . n over each ring's points, over the ring's radius,
    // summed over three radii: the nose's size relative to the scan differs between a bust and a face
    // mask). The nose is narrow and sticks out ~2 cm; the chin and brow are broad, the crown a gentle
    // dome. A ring must surround the point (6 of 8 sectors), so a cut edge does not count.
    float ring[3] = {0.04f * extent, 0.06f * extent, 0.09f * extent};
    for (int k = 0; k < 3; k++) ring[k] = fmaxf(ring[k], (3.0f + k) * spacing);
    float slab = fmaxf(0.01f * extent, 0.75f * spacing), best_h = -INFINITY, tip[3] = {0}, tip_n[3] = {0};
    // The points within the outer ring come from the tree: a flat model puts every point on its mirror
    // plane, and scanning all points for each of them was quadratic.
    uint32_t *near = ok ? rs_alloc_array(n, sizeof *near) : NULL;
    if (ok && !near) {
        free(sp), free(sn);
        rs_pack_kdtree_destroy(tree);
        return rs_fail(err, RS_ERR_NOMEM, "face: out of memory");
    }
    float reach2 = 1.44f * ring[2] * ring[2];
    for (uint32_t i = 0; ok && i < n; i++) {
        if (fabsf(dot3(sp[i], side) - plane_d) > slab) continue;
        float t1[3], t2[3];
        perpendicular(sn[i], t1);
        cross3(sn[i], t1, t2);
        double sum[3] = {0, 0, 0};
        uint32_t cnt[3] = {0, 0, 0}, sectors[3] = {0, 0, 0};
        uint32_t near_n = rs_pack_kdtree_within(tree, sp[i], reach2, near);
        for (uint32_t jj = 0; jj < near_n; jj++) {
            uint32_t j = near[jj];
            float d[3] = {sp[j][0] - sp[i][0], sp[j][1] - sp[i][1], sp[j][2] - sp[i][2]}, r2 = dot3(d, d);
            if (r2 > 1.44f * ring[2] * ring[2] || dot3(sn[j], sn[i]) < 0) continue;
            float x = dot3(d, t1), y = dot3(d, t2);
            int sector = (x < 0) << 2 | (y < 0) << 1 | (fabsf(x) < fabsf(y));  // the octant around the point
            for (int k = 0; k < 3; k++)
                if (r2 >= 0.64f * ring[k] * ring[k] && r2 <= 1.44f * ring[k] * ring[k]) {
                    sum[k] -= dot3(d, sn[i]);
                    cnt[k]++;
                    sectors[k] |= 1u << sector;
                }
        }
        float h = 0;
        int scales = 0;
        for (int k = 0; k < 3; k++)
        {
            int covered = 0;
            for (int b = 0; b < 8; b++) covered += (sectors[k] >> b) & 1;
            if (cnt[k] >= 6 && covered >= 6) h += (float)(sum[k] / cnt[k]) / ring[k], scales++;
        }
        if (scales < 2) continue;
        h /= (float)scales;
        if (h > best_h) {
            best_h = h;
            memcpy(tip, sp[i], sizeof tip);
            memcpy(tip_n, sn[i], sizeof tip_n);
        }
    }
    free(near);
    rs_pack_kdtree_destroy(tree);
    if (ok && best_h > 0) {
        // Rough forward: the mean normal of the face around the tip (2 rings; the tip's own normal
        // tilts with where on the nose the tip point lies), in the mirror plane.
        double acc[3] = {0, 0, 0};
        for (uint32_t i = 0; i < n; i++) {
            float d[3] = {sp[i][0] - tip[0], sp[i][1] - tip[1], sp[i][2] - tip[2]};
            if (dot3(d, d) > 4.0f * ring[2] * ring[2] || dot3(sn[i], tip_n) < 0) continue;
            for (int a = 0; a < 3; a++) acc[a] += sn[i][a];
        }
        float fw[3] = {(float)acc[0], (float)acc[1], (float)acc[2]}, k = dot3(fw, side);
        for (int a = 0; a < 3; a++) fw[a] -= k * side[a];
        if (!normalize3(fw)) memcpy(fw, tip_n, sizeof fw);
        // Up or down: each sense is refined into a facial frame, and the one whose face matches the
        // bundled head's depth around the nose better wins (an upside-down face puts its brow where the
        // template has lips and chin).
        float fr_up[2][3], fr_fw[2][3], cost[2] = {INFINITY, INFINITY};
        for (int sg = 0; sg < 2 && r == RS_OK; sg++) {
            float u[3];
            cross3(fw, side, u);
            for (int a = 0; a < 3; a++) u[a] *= sg ? -1.0f : 1.0f;
            memcpy(fr_fw[sg], fw, sizeof fw);
            memcpy(fr_up[sg], u, sizeof u);
            rs_pack_face g;
            r = refine(sp, sn, n, fr_up[sg], fr_fw[sg], &g, err);
            if (r == RS_OK && g.found) {
                float ss[3];
                cross3(fr_up[sg], fr_fw[sg], ss);
                for (int sc = -2; sc <= 2; sc++)
                    cost[sg] = fminf(cost[sg], template_cost((const float(*)[3])sp, (const float(*)[3])sn, n, g.nose_tip,
                                                             fr_fw[sg], fr_up[sg], ss, g.face_height * powf(1.15f, (float)sc)));
            }
        }
        // A face matches to within ~0.0015 (the bearded, bowed Demosthenes bust 0.0013, a sparse
        // face-only scan 0.0003); two cubes with a corner for a nose score 0.012.
        int b = cost[1] < cost[0];
        if (r == RS_OK && cost[b] < TEMPLATE_MAX_COST) {
            memcpy(up, fr_up[b], sizeof fr_up[b]);
            memcpy(forward, fr_fw[b], sizeof fr_fw[b]);
            float sd[3];
            cross3(up, forward, sd);
            *mirror_offset = dot3(sd, side) < 0 ? -plane_d : plane_d;
            *found = true;
        }
    }
    free(sp);
    free(sn);
    return r;
}
