// pack_knn.c — k nearest neighbours of every point with a balanced k-d tree (see pack.h).
//
// Median splits by index (not by value) keep the tree balanced whatever the input: duplicates, clusters
// and collinear points still cost O(N log N) to build and O(log N) per query, which matters because a
// PLY file is untrusted input. Queries run in tree order so consecutive queries touch the same nodes.
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define LEAF_SIZE 8

typedef struct kd_point {
    float p[3];
    uint32_t id;
} kd_point;

typedef struct kd_tree {
    kd_point *pts;
    uint32_t n;
    uint8_t *axis;
    float *split;
    rs_pack_rng rng;  // pivot choice: random pivots make quadratic selection practically impossible
} kd_tree;

static void swap_pt(kd_point *a, kd_point *b)
{
    kd_point t = *a;
    *a = *b;
    *b = t;
}

// Moves the kth smallest (along axis) of a[0..n) to a[kth], smaller ones before, larger after.
// Three-way partitioning so runs of equal coordinates finish in one pass.
static void select_nth(kd_tree *t, kd_point *a, uint32_t n, uint32_t kth, int axis)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        float pivot = a[lo + rs_pack_rng_u32(&t->rng) % (hi - lo)].p[axis];
        uint32_t lt = lo, i = lo, gt = hi;
        while (i < gt) {
            float v = a[i].p[axis];
            if (v < pivot) swap_pt(&a[lt++], &a[i++]);
            else if (v > pivot) swap_pt(&a[i], &a[--gt]);
            else i++;
        }
        if (kth < lt) hi = lt;
        else if (kth >= gt) lo = gt;
        else return;
    }
}

// mn/mx bound the points of [lo, hi): the parent's box cut at its split, which is enough to pick the
// longest axis and avoids an O(n) pass per node.
static void build(kd_tree *t, uint32_t node, uint32_t lo, uint32_t hi, const float mn[3], const float mx[3])
{
    if (hi - lo <= LEAF_SIZE) return;
    int axis = 0;
    for (int a = 1; a < 3; a++)
        if (mx[a] - mn[a] > mx[axis] - mn[axis]) axis = a;
    uint32_t mid = lo + (hi - lo) / 2;
    select_nth(t, t->pts + lo, hi - lo, mid - lo, axis);
    float split = t->pts[mid].p[axis];
    t->axis[node] = (uint8_t)axis;
    t->split[node] = split;
    float lmx[3] = {mx[0], mx[1], mx[2]}, rmn[3] = {mn[0], mn[1], mn[2]};
    lmx[axis] = split;
    rmn[axis] = split;
    build(t, 2 * node + 1, lo, mid, mn, lmx);
    build(t, 2 * node + 2, mid, hi, rmn, mx);
}

typedef struct kd_best {
    uint32_t k, found;
    float bound;  // squared distance a point must be under to count (INFINITY: any)
    float d2[RS_PACK_KNN_MAX_K];
    uint32_t id[RS_PACK_KNN_MAX_K];
} kd_best;

static inline float worst(const kd_best *b)
{
    return b->found < b->k ? b->bound : b->d2[b->k - 1];
}

static void query(const kd_tree *t, uint32_t node, uint32_t lo, uint32_t hi, const float q[3],
                  uint32_t self, kd_best *b)
{
    if (hi - lo <= LEAF_SIZE) {
        for (uint32_t i = lo; i < hi; i++) {
            const kd_point *p = &t->pts[i];
            if (p->id == self) continue;
            float dx = p->p[0] - q[0], dy = p->p[1] - q[1], dz = p->p[2] - q[2];
            float d2 = dx * dx + dy * dy + dz * dz;
            if (d2 >= worst(b)) continue;
            uint32_t j = b->found < b->k ? b->found++ : b->k - 1;
            while (j > 0 && b->d2[j - 1] > d2) {
                b->d2[j] = b->d2[j - 1];
                b->id[j] = b->id[j - 1];
                j--;
            }
            b->d2[j] = d2;
            b->id[j] = p->id;
        }
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    float d = q[t->axis[node]] - t->split[node];
    if (d < 0) {
        query(t, 2 * node + 1, lo, mid, q, self, b);
        if (d * d < worst(b)) query(t, 2 * node + 2, mid, hi, q, self, b);
    } else {
        query(t, 2 * node + 2, mid, hi, q, self, b);
        if (d * d < worst(b)) query(t, 2 * node + 1, lo, mid, q, self, b);
    }
}

struct rs_pack_kdtree {
    kd_tree t;
};

void rs_pack_kdtree_destroy(rs_pack_kdtree *tree)
{
    if (!tree) return;
    free(tree->t.pts);
    free(tree->t.axis);
    free(tree->t.split);
    free(tree);
}

rs_result rs_pack_kdtree_create(const float (*pos)[3], uint32_t count, rs_pack_kdtree **out, rs_error *err)
{
    // Internal nodes: the tree halves ranges until they hold LEAF_SIZE points.
    uint32_t depth = 0;
    for (uint64_t size = count; size > LEAF_SIZE; size = (size + 1) / 2) depth++;
    size_t nodes = (size_t)1 << depth;
    rs_pack_kdtree *tree = calloc(1, sizeof *tree);
    kd_tree *t = tree ? &tree->t : NULL;
    if (t) {
        t->n = count;
        t->pts = rs_alloc_array(count, sizeof *t->pts);
        t->axis = rs_alloc_array(nodes, sizeof *t->axis);
        t->split = rs_alloc_array(nodes, sizeof *t->split);
    }
    if (!t || !t->pts || !t->axis || !t->split) {
        rs_pack_kdtree_destroy(tree);
        return rs_fail(err, RS_ERR_NOMEM, "knn: out of memory for %u points", count);
    }
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; i++) {
        memcpy(t->pts[i].p, pos[i], sizeof t->pts[i].p);
        t->pts[i].id = i;
        for (int a = 0; a < 3; a++) {
            if (pos[i][a] < mn[a]) mn[a] = pos[i][a];
            if (pos[i][a] > mx[a]) mx[a] = pos[i][a];
        }
    }
    rs_pack_rng_seed(&t->rng, 1);
    build(t, 0, 0, count, mn, mx);
    *out = tree;
    return RS_OK;
}

uint32_t rs_pack_kdtree_query(const rs_pack_kdtree *tree, const float q[3], uint32_t k, uint32_t skip,
                              uint32_t *idx, float *dist)
{
    kd_best b = {.k = RS_MIN(k, (uint32_t)RS_PACK_KNN_MAX_K), .bound = INFINITY};
    if (b.k > 0) query(&tree->t, 0, 0, tree->t.n, q, skip, &b);
    for (uint32_t i = 0; i < b.found; i++) {
        idx[i] = b.id[i];
        dist[i] = sqrtf(b.d2[i]);
    }
    return b.found;
}

bool rs_pack_kdtree_nearest_within(const rs_pack_kdtree *tree, const float q[3], float bound2, float *d2)
{
    // The bound prunes every branch farther than it, which is what makes a truncated distance cheap far
    // from the points (a mirror plane candidate that reflects the scan into empty space).
    kd_best b = {.k = 1, .bound = bound2};
    query(&tree->t, 0, 0, tree->t.n, q, RS_PACK_NONE, &b);
    if (b.found) *d2 = b.d2[0];
    return b.found > 0;
}

static void within(const kd_tree *t, uint32_t node, uint32_t lo, uint32_t hi, const float q[3], float r2,
                   uint32_t *ids, uint32_t *n)
{
    if (hi - lo <= LEAF_SIZE) {
        for (uint32_t i = lo; i < hi; i++) {
            const kd_point *p = &t->pts[i];
            float dx = p->p[0] - q[0], dy = p->p[1] - q[1], dz = p->p[2] - q[2];
            if (dx * dx + dy * dy + dz * dz <= r2) ids[(*n)++] = p->id;
        }
        return;
    }
    uint32_t mid = lo + (hi - lo) / 2;
    float d = q[t->axis[node]] - t->split[node];
    if (d < 0 || d * d <= r2) within(t, 2 * node + 1, lo, mid, q, r2, ids, n);
    if (d >= 0 || d * d <= r2) within(t, 2 * node + 2, mid, hi, q, r2, ids, n);
}

uint32_t rs_pack_kdtree_within(const rs_pack_kdtree *tree, const float q[3], float r2, uint32_t *ids)
{
    uint32_t n = 0;
    within(&tree->t, 0, 0, tree->t.n, q, r2, ids, &n);
    return n;
}

void rs_pack_knn_free(rs_pack_knn *knn)
{
    if (!knn) return;
    free(knn->idx);
    free(knn->dist);
    memset(knn, 0, sizeof *knn);
}

rs_result rs_pack_knn_compute(const float (*pos)[3], uint32_t count, uint32_t k, rs_pack_knn *out,
                              void (*progress)(void *user, double fraction), void *user, rs_error *err)
{
    if (k < 1 || k > RS_PACK_KNN_MAX_K)
        return rs_fail(err, RS_ERR_ARG, "knn: k = %u is outside 1..%d", k, RS_PACK_KNN_MAX_K);
    rs_pack_knn r = {.count = count, .k = k};
    r.idx = rs_alloc_array((size_t)count * k, sizeof *r.idx);
    r.dist = rs_alloc_array((size_t)count * k, sizeof *r.dist);
    rs_pack_kdtree *tree = NULL;
    if (!r.idx || !r.dist) {
        rs_pack_knn_free(&r);
        return rs_fail(err, RS_ERR_NOMEM, "knn: out of memory for %u points", count);
    }
    rs_result res = rs_pack_kdtree_create(pos, count, &tree, err);
    if (res != RS_OK) {
        rs_pack_knn_free(&r);
        return res;
    }
    // Queries in tree order: neighbouring queries walk the same nodes, so they stay in cache.
    const kd_tree *t = &tree->t;
    for (uint32_t j = 0; j < count; j++) {
        kd_best b = {.k = k, .bound = INFINITY};
        uint32_t id = t->pts[j].id;
        query(t, 0, 0, count, t->pts[j].p, id, &b);
        for (uint32_t i = 0; i < k; i++) {
            r.idx[(size_t)id * k + i] = i < b.found ? b.id[i] : RS_PACK_NONE;
            r.dist[(size_t)id * k + i] = i < b.found ? sqrtf(b.d2[i]) : INFINITY;
        }
        if (progress && (j & 0xffff) == 0) progress(user, (double)j / count);
    }
    rs_pack_kdtree_destroy(tree);
    *out = r;
    return RS_OK;
}
