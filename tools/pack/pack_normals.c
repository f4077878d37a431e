// pack_normals.c — normals by neighbourhood PCA with consistent orientation, and splat radii from the
// local spacing (see pack.h).
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void rs_pack_eigen_sym3(const double a_in[3][3], double values[3], double vectors[3][3])
{
    double a[3][3], v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    memcpy(a, a_in, sizeof a);
    // Cyclic Jacobi: each rotation zeroes one off-diagonal entry; converges quadratically and stays
    // accurate for nearly equal eigenvalues (flat patches have two), unlike the closed-form cubic.
    for (int sweep = 0; sweep < 50; sweep++) {
        double off = fabs(a[0][1]) + fabs(a[0][2]) + fabs(a[1][2]);
        double scale = fabs(a[0][0]) + fabs(a[1][1]) + fabs(a[2][2]);
        if (off <= 1e-15 * scale || off == 0.0) break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                if (a[p][q] == 0.0) continue;
                double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                double t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) {  // A <- A J (columns p, q)
                    double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) {  // A <- J^T A (rows p, q)
                    double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 3; k++) {  // V <- V J
                    double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 2; i++)
        for (int j = i + 1; j < 3; j++)
            if (a[order[j]][order[j]] < a[order[i]][order[i]]) {
                int tmp = order[i];
                order[i] = order[j];
                order[j] = tmp;
            }
    for (int i = 0; i < 3; i++) {
        values[i] = a[order[i]][order[i]];
        for (int k = 0; k < 3; k++) vectors[i][k] = v[k][order[i]];
    }
}

// Smallest-variance direction of the point and its neighbours.
static void pca_normal(const float (*pos)[3], const rs_pack_knn *knn, uint32_t i, float n[3])
{
    double c[3] = {pos[i][0], pos[i][1], pos[i][2]};
    uint32_t m = 1;
    const uint32_t *nb = knn->idx + (size_t)i * knn->k;
    for (uint32_t j = 0; j < knn->k && nb[j] != RS_PACK_NONE; j++, m++)
        for (int a = 0; a < 3; a++) c[a] += pos[nb[j]][a];
    for (int a = 0; a < 3; a++) c[a] /= m;
    double cov[3][3] = {{0}};
    for (uint32_t j = 0; j < m; j++) {
        const float *p = j == 0 ? pos[i] : pos[nb[j - 1]];
        double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
        for (int r = 0; r < 3; r++)
            for (int s = r; s < 3; s++) cov[r][s] += d[r] * d[s];
    }
    cov[1][0] = cov[0][1];
    cov[2][0] = cov[0][2];
    cov[2][1] = cov[1][2];
    double w[3], v[3][3];
    rs_pack_eigen_sym3(cov, w, v);
    if (m < 3) {  // too few neighbours for a plane: any direction; orientation still applies
        n[0] = n[1] = 0;
        n[2] = 1;
        return;
    }
    for (int a = 0; a < 3; a++) n[a] = (float)v[0][a];
}

// Indexed binary min-heap keyed by float, with decrease-key: O(N) memory for Prim's algorithm.
typedef struct heap {
    uint32_t *items, *where, size;  // where[i] = slot of item i, or UINT32_MAX when not in the heap
    float *key;
} heap;

static void heap_swap(heap *h, uint32_t a, uint32_t b)
{
    uint32_t ia = h->items[a], ib = h->items[b];
    h->items[a] = ib;
    h->items[b] = ia;
    h->where[ib] = a;
    h->where[ia] = b;
}

static void heap_up(heap *h, uint32_t s)
{
    while (s > 0 && h->key[h->items[(s - 1) / 2]] > h->key[h->items[s]]) {
        heap_swap(h, s, (s - 1) / 2);
        s = (s - 1) / 2;
    }
}

static void heap_down(heap *h, uint32_t s)
{
    for (;;) {
        uint32_t l = 2 * s + 1, r = l + 1, m = s;
        if (l < h->size && h->key[h->items[l]] < h->key[h->items[m]]) m = l;
        if (r < h->size && h->key[h->items[r]] < h->key[h->items[m]]) m = r;
        if (m == s) return;
        heap_swap(h, s, m);
        s = m;
    }
}

static void heap_push_or_lower(heap *h, uint32_t item, float key)
{
    if (h->where[item] == UINT32_MAX) {
        h->key[item] = key;
        h->items[h->size] = item;
        h->where[item] = h->size;
        heap_up(h, h->size++);
    } else if (key < h->key[item]) {
        h->key[item] = key;
        heap_up(h, h->where[item]);
    }
}

static uint32_t heap_pop(heap *h)
{
    uint32_t top = h->items[0];
    heap_swap(h, 0, --h->size);
    h->where[top] = UINT32_MAX;
    heap_down(h, 0);
    return top;
}

// Neighbours used for orientation: fewer than for PCA so the graph stays on one sheet near thin parts.
#define ORIENT_K 8

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

rs_result rs_pack_estimate_normals(const float (*pos)[3], const rs_pack_knn *knn, float (*normal)[3],
                                   rs_error *err)
{
    uint32_t n = knn->count, k = knn->k, ko = RS_MIN(k, (uint32_t)ORIENT_K);
    for (uint32_t i = 0; i < n; i++) pca_normal(pos, knn, i, normal[i]);
    if (n == 0) return RS_OK;

    // Undirected graph in CSR form: the kNN relation is not symmetric, and orientation must be able to
    // cross an edge from either end.
    uint32_t *start = calloc((size_t)n + 1, sizeof *start);
    uint32_t *adj = rs_alloc_array((size_t)n * ko * 2, sizeof *adj);
    uint32_t *fill = rs_alloc_array(n, sizeof *fill);
    uint32_t *by_dist = rs_alloc_array(n, sizeof *by_dist);
    float *dist = rs_alloc_array(n, sizeof *dist);
    heap h = {rs_alloc_array(n, sizeof(uint32_t)), rs_alloc_array(n, sizeof(uint32_t)), 0,
              rs_alloc_array(n, sizeof(float))};
    uint8_t *done = calloc(n, 1);
    rs_result res = RS_OK;
    if (!start || !adj || !fill || !by_dist || !dist || !h.items || !h.where || !h.key || !done) {
        res = rs_fail(err, RS_ERR_NOMEM, "normals: out of memory for %u points", n);
        goto out;
    }
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < ko; j++) {
            uint32_t b = knn->idx[(size_t)i * k + j];
            if (b == RS_PACK_NONE) break;
            start[i + 1]++;
            start[b + 1]++;
        }
    for (uint32_t i = 0; i < n; i++) start[i + 1] += start[i];
    memcpy(fill, start, (size_t)n * sizeof *fill);
    for (uint32_t i = 0; i < n; i++)
        for (uint32_t j = 0; j < ko; j++) {
            uint32_t b = knn->idx[(size_t)i * k + j];
            if (b == RS_PACK_NONE) break;
            adj[fill[i]++] = b;
            adj[fill[b]++] = i;
        }

    // Seeds in order of distance from the centroid, farthest first: the farthest point of a head-like
    // surface is on its convex hull, where "away from the centroid" is certainly outward.
    double c[3] = {0, 0, 0};
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) c[a] += pos[i][a];
    float cf[3] = {(float)(c[0] / n), (float)(c[1] / n), (float)(c[2] / n)};
    for (uint32_t i = 0; i < n; i++) {
        float d[3] = {pos[i][0] - cf[0], pos[i][1] - cf[1], pos[i][2] - cf[2]};
        dist[i] = dot3(d, d);
        by_dist[i] = i;
    }
    // Sorted through the heap (keys -distance), which Prim's algorithm below reuses: O(N log N).
    for (uint32_t i = 0; i < n; i++) h.where[i] = UINT32_MAX;
    for (uint32_t i = 0; i < n; i++) heap_push_or_lower(&h, i, -dist[i]);
    for (uint32_t i = 0; i < n; i++) by_dist[i] = heap_pop(&h);

    for (uint32_t s = 0; s < n; s++) {
        uint32_t seed = by_dist[s];
        if (done[seed]) continue;
        float d[3] = {pos[seed][0] - cf[0], pos[seed][1] - cf[1], pos[seed][2] - cf[2]};
        if (dot3(normal[seed], d) < 0)
            for (int a = 0; a < 3; a++) normal[seed][a] = -normal[seed][a];
        // Prim's algorithm: the heap holds frontier points keyed by their cheapest edge into the tree;
        // fill[] is reused as the parent through which that edge goes.
        heap_push_or_lower(&h, seed, 0.0f);
        fill[seed] = seed;
        while (h.size > 0) {
            uint32_t i = heap_pop(&h);
            done[i] = 1;
            if (dot3(normal[i], normal[fill[i]]) < 0)
                for (int a = 0; a < 3; a++) normal[i][a] = -normal[i][a];
            for (uint32_t e = start[i]; e < start[i + 1]; e++) {
                uint32_t b = adj[e];
                if (done[b]) continue;
                float e[3] = {pos[b][0] - pos[i][0], pos[b][1] - pos[i][1], pos[b][2] - pos[i][2]};
                float el = sqrtf(dot3(e, e));
                float w = 1.0f - fabsf(dot3(normal[i], normal[b]));
                // Edges that leave the tangent planes cross a fold or jump between layers (eyelids,
                // lips, ears): orientation is least reliable across them, so they come last.
                if (el > 0) w += (fabsf(dot3(normal[i], e)) + fabsf(dot3(normal[b], e))) / el;
                uint32_t before = h.where[b];
                float old = before == UINT32_MAX ? INFINITY : h.key[b];
                heap_push_or_lower(&h, b, w);
                if (w < old) fill[b] = i;
            }
        }
    }
out:
    free(start);
    free(adj);
    free(fill);
    free(by_dist);
    free(dist);
    free(h.items);
    free(h.where);
    free(h.key);
    free(done);
    return res;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

rs_result rs_pack_radii(const rs_pack_knn *knn, float *radius, rs_error *err)
{
    uint32_t n = knn->count, k = knn->k;
    if (k < RS_PACK_RADIUS_K)
        return rs_fail(err, RS_ERR_ARG, "radii: need %d neighbours, have %u", RS_PACK_RADIUS_K, k);
    if (n == 0) return RS_OK;
    float *sorted = rs_alloc_array(n, sizeof *sorted);
    if (!sorted) return rs_fail(err, RS_ERR_NOMEM, "radii: out of memory for %u points", n);
    uint32_t finite = 0;
    for (uint32_t i = 0; i < n; i++) {
        // Fewer than RS_PACK_RADIUS_K other points (a tiny cloud): the farthest neighbour there is.
        const float *d = knn->dist + (size_t)i * k;
        int j = RS_PACK_RADIUS_K - 1;
        while (j > 0 && !isfinite(d[j])) j--;
        radius[i] = RS_PACK_RADIUS_SCALE * d[j];
        if (isfinite(d[j]) && d[j] > 0) sorted[finite++] = radius[i];
    }
    if (finite == 0) {
        // One point, or all at one position: no spacing to measure; any size will do.
        for (uint32_t i = 0; i < n; i++) radius[i] = 1.0f;
        free(sorted);
        return RS_OK;
    }
    qsort(sorted, finite, sizeof *sorted, cmp_float);
    float lo = sorted[(size_t)(finite - 1) / 100], hi = sorted[(size_t)(finite - 1) * 99 / 100];
    free(sorted);
    for (uint32_t i = 0; i < n; i++)
        radius[i] = isfinite(radius[i]) ? RS_CLAMP(radius[i], lo, hi) : hi;
    return RS_OK;
}
