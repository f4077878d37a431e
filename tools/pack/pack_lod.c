// pack_lod.c — LOD ordering and decimation: Poisson-disk-like subsets of a scan (see pack.h).
//
// LOD levels come from dart throwing (random sequential adsorption) coarse to fine on a hashed grid:
// level l takes, in one seeded random order, every point at least r_l away from all points taken so
// far, r_l chosen so that the prefix holds about N / 2^l points. Each prefix is then a maximal
// Poisson-disk set: no two of its splats closer than r_l and every point of the scan within r_l of one,
// so a renderer drawing a prefix with radii scaled by sqrt(N / n) covers the surface without holes.
// Inside a level, Morton order keeps neighbours together. O(N) per level.
//
// Decimation to an exact count (--points on a cloud) uses weighted sample elimination (Yuksel 2015),
// which is slower (a kNN graph and a heap) but hits the count exactly.
#include "pack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define ELIM_K 12        // neighbours per point; ~7 lie within 2 r_max when halving a uniform set
#define ELIM_BETA 0.65   // weight limiting, Yuksel §4.2
#define ELIM_GAMMA 1.5

// Indexed binary max-heap over point weights; weights only ever decrease.
typedef struct max_heap {
    uint32_t *items, *where, size;
    const double *key;
} max_heap;

static void mh_swap(max_heap *h, uint32_t a, uint32_t b)
{
    uint32_t ia = h->items[a], ib = h->items[b];
    h->items[a] = ib;
    h->items[b] = ia;
    h->where[ib] = a;
    h->where[ia] = b;
}

static void mh_down(max_heap *h, uint32_t s)
{
    for (;;) {
        uint32_t l = 2 * s + 1, r = l + 1, m = s;
        if (l < h->size && h->key[h->items[l]] > h->key[h->items[m]]) m = l;
        if (r < h->size && h->key[h->items[r]] > h->key[h->items[m]]) m = r;
        if (m == s) return;
        mh_swap(h, s, m);
        s = m;
    }
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

// Yuksel eq. 2 with weight limiting (§4.2): distances clamped to [r_min, 2 r_max], alpha = 8.
static double elim_weight(double d, double r_min, double two_r)
{
    if (two_r <= 0) return 1.0;
    double x = 1.0 - RS_CLAMP(d, r_min, two_r) / two_r;
    x *= x;
    x *= x;
    return x * x;
}

rs_result rs_pack_eliminate(const float (*pos)[3], uint32_t *ids, uint32_t n, uint32_t target,
                            rs_error *err)
{
    if (target >= n) return RS_OK;
    uint32_t k = RS_MIN((uint32_t)ELIM_K, n - 1);
    float(*sub)[3] = rs_alloc_array(n, sizeof *sub);
    if (!sub) return rs_fail(err, RS_ERR_NOMEM, "lod: out of memory for %u points", n);
    for (uint32_t j = 0; j < n; j++) memcpy(sub[j], pos[ids[j]], sizeof sub[j]);
    rs_pack_knn knn = {0};
    rs_result res = k > 0 ? rs_pack_knn_compute((const float(*)[3])sub, n, k, &knn, NULL, NULL, err) : RS_OK;
    free(sub);
    if (res != RS_OK) return res;
    if (k == 0) {
        rs_pack_knn_free(&knn);
        return RS_OK;  // n == 1 > target == 0: nothing to choose
    }

    double *w = rs_alloc_array(n, sizeof *w);
    float *area = rs_alloc_array(n, sizeof *area);
    uint32_t *rev_start = calloc((size_t)n + 1, sizeof *rev_start);
    uint32_t *rev = rs_alloc_array((size_t)n * k, sizeof *rev);
    uint32_t *fill = rs_alloc_array(n, sizeof *fill);
    uint32_t *tmp = rs_alloc_array(n, sizeof *tmp);
    max_heap h = {rs_alloc_array(n, sizeof(uint32_t)), rs_alloc_array(n, sizeof(uint32_t)), n, w};
    if (!w || !area || !rev_start || !rev || !fill || !tmp || !h.items || !h.where) {
        res = rs_fail(err, RS_ERR_NOMEM, "lod: out of memory for %u points", n);
        goto out;
    }

    // Surface area from the kNN density (pi d_k^2 / k per point); the median resists stray points.
    uint32_t finite = 0;
    for (uint32_t j = 0; j < n; j++) {
        float d = knn.dist[(size_t)j * k + k - 1];
        if (isfinite(d)) area[finite++] = 3.14159265f * d * d / (float)k;
    }
    double a_total = 0;
    if (finite > 0) {
        qsort(area, finite, sizeof *area, cmp_float);
        a_total = (double)area[finite / 2] * n;
    }
    // Yuksel eq. 5 (2D domain): the largest Poisson-disk radius for `target` points on area A.
    double r_max = sqrt(a_total / (2.0 * sqrt(3.0) * target));
    double r_min = r_max * ELIM_BETA * (1.0 - pow((double)target / n, ELIM_GAMMA));
    double two_r = 2.0 * r_max;

    // Weights (Yuksel eq. 1-2): w_j = sum over neighbours of (1 - d_hat / 2 r_max)^alpha.
    for (uint32_t j = 0; j < n; j++) {
        w[j] = 0;
        for (uint32_t i = 0; i < k; i++) {
            uint32_t b = knn.idx[(size_t)j * k + i];
            if (b == RS_PACK_NONE) break;
            rev_start[b + 1]++;
            w[j] += elim_weight(knn.dist[(size_t)j * k + i], r_min, two_r);
        }
    }
    for (uint32_t j = 0; j < n; j++) rev_start[j + 1] += rev_start[j];
    memcpy(fill, rev_start, (size_t)n * sizeof *fill);
    for (uint32_t j = 0; j < n; j++)
        for (uint32_t i = 0; i < k; i++) {
            uint32_t b = knn.idx[(size_t)j * k + i];
            if (b == RS_PACK_NONE) break;
            rev[fill[b]++] = j * k + i;  // edge j -> b, stored at b: removing b lightens j
        }

    for (uint32_t j = 0; j < n; j++) {
        h.items[j] = j;
        h.where[j] = j;
    }
    for (uint32_t s = n / 2; s-- > 0;) mh_down(&h, s);

    // Remove the most crowded point until `target` remain; h.where[] == UINT32_MAX marks removed.
    while (h.size > target) {
        uint32_t top = h.items[0];
        mh_swap(&h, 0, --h.size);
        h.where[top] = UINT32_MAX;
        mh_down(&h, 0);
        for (uint32_t e = rev_start[top]; e < rev_start[top + 1]; e++) {
            uint32_t j = rev[e] / k, i = rev[e] % k;
            if (h.where[j] == UINT32_MAX) continue;
            w[j] -= elim_weight(knn.dist[(size_t)j * k + i], r_min, two_r);
            mh_down(&h, h.where[j]);
        }
    }
    // Kept points first (in their previous relative order), then the removed ones.
    uint32_t kept = 0, removed = target;
    for (uint32_t j = 0; j < n; j++) {
        if (h.where[j] != UINT32_MAX) tmp[kept++] = ids[j];
        else tmp[removed++] = ids[j];
    }
    memcpy(ids, tmp, (size_t)n * sizeof *ids);
out:
    rs_pack_knn_free(&knn);
    free(w);
    free(area);
    free(rev_start);
    free(rev);
    free(fill);
    free(tmp);
    free(h.items);
    free(h.where);
    return res;
}

// ---------------------------------------------------------------------------------------------------
// Levels by Poisson-disk dart throwing (random sequential adsorption) on a hashed grid.

typedef struct grid_node {
    float p[3];
    int32_t c[3];
    uint32_t next;  // next node in the same hash slot, RS_PACK_NONE at the end
} grid_node;

typedef struct disk_grid {
    uint32_t *head;   // hash slot -> first node, RS_PACK_NONE when empty
    grid_node *node;  // inserted points, in insertion order (small and contiguous for coarse levels)
    uint32_t nodes, mask;
    float inv_cell;
} disk_grid;

static uint32_t cell_hash(int32_t x, int32_t y, int32_t z)
{
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
    return h ^ (h >> 15);
}

static void cell_of(const disk_grid *g, const float p[3], int32_t c[3])
{
    // Clamped before the conversion: a float outside int32 would be undefined behaviour.
    for (int a = 0; a < 3; a++) c[a] = (int32_t)RS_CLAMP(floorf(p[a] * g->inv_cell), -1073741824.0f, 1073741824.0f);
}

// Empties the grid and sizes its hash table for about `expected` points (a power of two <= capacity).
static void grid_reset(disk_grid *g, float cell, uint32_t expected, uint32_t capacity)
{
    uint32_t size = 1;
    while (size < 2 * (uint64_t)expected && size < capacity) size <<= 1;
    g->mask = size - 1;
    g->nodes = 0;
    g->inv_cell = cell > 0 ? 1.0f / cell : 1.0f;
    for (uint32_t s = 0; s < size; s++) g->head[s] = RS_PACK_NONE;
}

static uint32_t grid_find_cell(const disk_grid *g, const int32_t c[3])
{
    for (uint32_t j = g->head[cell_hash(c[0], c[1], c[2]) & g->mask]; j != RS_PACK_NONE; j = g->node[j].next)
        if (g->node[j].c[0] == c[0] && g->node[j].c[1] == c[1] && g->node[j].c[2] == c[2]) return j;
    return RS_PACK_NONE;
}

static void grid_insert(disk_grid *g, const float p[3])
{
    grid_node *n = &g->node[g->nodes];
    memcpy(n->p, p, sizeof n->p);
    cell_of(g, p, n->c);
    uint32_t s = cell_hash(n->c[0], n->c[1], n->c[2]) & g->mask;
    n->next = g->head[s];
    g->head[s] = g->nodes++;
}

// True when no inserted point lies closer than sqrt(r2) to p. The cell size equals r, so the 27 cells
// around p hold every candidate; p's own cell is looked at first because it rejects most often.
static bool grid_free(const disk_grid *g, const float p[3], float r2)
{
    static const int8_t off[27][3] = {
        {0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1},
        {-1, -1, 0}, {-1, 1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 0, -1}, {-1, 0, 1}, {1, 0, -1},
        {1, 0, 1}, {0, -1, -1}, {0, -1, 1}, {0, 1, -1}, {0, 1, 1}, {-1, -1, -1}, {-1, -1, 1},
        {-1, 1, -1}, {-1, 1, 1}, {1, -1, -1}, {1, -1, 1}, {1, 1, -1}, {1, 1, 1}};
    int32_t c[3];
    cell_of(g, p, c);
    for (int o = 0; o < 27; o++) {
        int32_t x = c[0] + off[o][0], y = c[1] + off[o][1], z = c[2] + off[o][2];
        for (uint32_t j = g->head[cell_hash(x, y, z) & g->mask]; j != RS_PACK_NONE; j = g->node[j].next) {
            const grid_node *n = &g->node[j];
            if (n->c[0] != x || n->c[1] != y || n->c[2] != z) continue;
            float d0 = n->p[0] - p[0], d1 = n->p[1] - p[1], d2 = n->p[2] - p[2];
            if (d0 * d0 + d1 * d1 + d2 * d2 < r2) return false;
        }
    }
    return true;
}

typedef struct keyed {
    uint64_t key;
    uint32_t id;
} keyed;

static int cmp_keyed(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return (x->id > y->id) - (x->id < y->id);
}

// Saturated random sequential adsorption in 2D covers 54.7% of the plane with disks of diameter r
// (Feder 1980), so a surface of area A holds about 0.547 A / (pi r^2 / 4) = 0.6965 A / r^2 points.
#define RSA_DENSITY 0.6965

// Surface area estimate from the number of occupied grid cells: a surface of area A crosses about
// 1.5 A / h^2 cubes of side h (Cauchy: the mean projected area of a cube is 1.5 h^2), for h below the
// curvature radius and above the point spacing. h is picked so that cells hold ~16 points on average.
static double estimate_area(const float (*pos)[3], uint32_t count, const float mn[3], const float mx[3],
                            disk_grid *g, uint32_t capacity)
{
    double ext[3] = {mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]};
    // First guess: the points spread over half the box surface.
    double area = ext[0] * ext[1] + ext[1] * ext[2] + ext[0] * ext[2];
    for (int iter = 0; iter < 3 && area > 0; iter++) {
        double h = sqrt(16.0 * area / count);
        grid_reset(g, (float)h, count / 8, capacity);
        for (uint32_t i = 0; i < count; i++) {
            int32_t c[3];
            cell_of(g, pos[i], c);
            if (grid_find_cell(g, c) == RS_PACK_NONE) grid_insert(g, pos[i]);  // one node per cell
        }
        area = g->nodes * h * h / 1.5;
    }
    return area;
}

rs_result rs_pack_lod_order(const float (*pos)[3], uint32_t count, uint32_t min_lod, uint32_t *order,
                            uint32_t lods[RS_SPLAT_MAX_LODS], uint32_t *lod_count,
                            void (*progress)(void *user, double fraction), void *user, rs_error *err)
{
    if (min_lod == 0) min_lod = RS_PACK_DEFAULT_MIN_LOD;
    uint32_t levels = 1;
    while (levels < RS_SPLAT_MAX_LODS && (count >> levels) >= min_lod) levels++;
    lods[0] = count;
    *lod_count = 1;
    for (uint32_t i = 0; i < count; i++) order[i] = i;
    if (levels == 1 || count == 0) return RS_OK;

    uint32_t table = 1;
    while (table < count) table <<= 1;
    disk_grid g = {rs_alloc_array(table, sizeof(uint32_t)), rs_alloc_array(count, sizeof(grid_node)), 0, 0, 1};
    uint32_t *perm = rs_alloc_array(count, sizeof *perm);
    uint8_t *level = rs_alloc_array(count, sizeof *level);   // finest level that holds the point
    keyed *tmp = rs_alloc_array(count, sizeof *tmp);
    // The candidates' positions and levels in the order they are tried: the passes below read them in
    // sequence instead of jumping about the scan.
    float(*tried)[3] = rs_alloc_array(count, sizeof *tried);
    uint8_t *tried_level = rs_alloc_array(count, sizeof *tried_level);
    rs_result res = RS_OK;
    if (!g.head || !g.node || !perm || !level || !tmp || !tried || !tried_level) {
        res = rs_fail(err, RS_ERR_NOMEM, "lod: out of memory for %u points", count);
        goto out;
    }
    float mn[3] = {INFINITY, INFINITY, INFINITY}, mx[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < count; i++)
        for (int a = 0; a < 3; a++) {
            if (pos[i][a] < mn[a]) mn[a] = pos[i][a];
            if (pos[i][a] > mx[a]) mx[a] = pos[i][a];
        }
    double area = estimate_area(pos, count, mn, mx, &g, table);

    // Candidates are tried in one seeded random order; random order is what makes the accepted set
    // blue noise rather than a lattice.
    rs_pack_rng rng;
    rs_pack_rng_seed(&rng, RS_PACK_DEFAULT_SEED);
    for (uint32_t i = 0; i < count; i++) {
        perm[i] = i;
        level[i] = 0;
    }
    for (uint32_t i = count; i > 1; i--) {
        uint32_t j = rs_pack_rng_u32(&rng) % i, t = perm[i - 1];
        perm[i - 1] = perm[j];
        perm[j] = t;
    }
    for (uint32_t i = 0; i < count; i++) {
        memcpy(tried[i], pos[perm[i]], sizeof tried[i]);
        tried_level[i] = 0;
    }

    // Coarse to fine: level l accepts, among points not yet taken, those at least r_l away from every
    // point taken so far, so each level's set contains all coarser ones.
    uint32_t accepted = 0;
    for (uint32_t l = levels - 1; l >= 1; l--) {
        uint32_t want = count >> l;
        double r = area > 0 ? sqrt(RSA_DENSITY * area / want) : 0.0;
        grid_reset(&g, (float)r, want + want / 2, table);
        for (uint32_t i = 0; i < count; i++)
            if (tried_level[i] != 0) grid_insert(&g, tried[i]);
        uint32_t before = accepted;
        float r2 = (float)(r * r);
        // A finite candidate set saturates below the continuous density once r nears the input's own
        // spacing; then shrink r and throw again. Points already taken stay valid (they are farther apart
        // than the new r) and the 27 cells of the old size still cover the smaller radius.
        for (int pass = 0; pass < 3; pass++) {
            for (uint32_t i = 0; i < count; i++) {
                if (tried_level[i] != 0 || !grid_free(&g, tried[i], r2)) continue;
                grid_insert(&g, tried[i]);
                tried_level[i] = (uint8_t)l;
                accepted++;
            }
            // Learn the effective area from what the first pass achieved, so sizes track N / 2^l.
            if (pass == 0 && accepted > before && r > 0) area = accepted * r * r / RSA_DENSITY;
            if (accepted >= want - want / 16 || accepted == 0) break;
            r2 *= (float)accepted / (float)want;
        }
        if (progress) progress(user, (double)(levels - l) / levels);
    }

    for (uint32_t i = 0; i < count; i++) level[perm[i]] = tried_level[i];

    // Counting sort by level, coarse first, then Morton order inside each level.
    uint32_t level_size[RS_SPLAT_MAX_LODS] = {0};
    for (uint32_t i = 0; i < count; i++) level_size[level[i]]++;
    uint32_t at = 0, starts[RS_SPLAT_MAX_LODS + 1];
    for (uint32_t l = levels; l-- > 0;) {
        starts[l] = at;
        at += level_size[l];
    }
    float ext = fmaxf(fmaxf(mx[0] - mn[0], mx[1] - mn[1]), mx[2] - mn[2]);
    float scale = ext > 0 ? 2097151.0f / ext : 0.0f;
    uint32_t fillp[RS_SPLAT_MAX_LODS];
    memcpy(fillp, starts, sizeof fillp);
    for (uint32_t i = 0; i < count; i++) {
        uint32_t q[3];
        for (int a = 0; a < 3; a++) q[a] = (uint32_t)RS_CLAMP((pos[i][a] - mn[a]) * scale, 0.0f, 2097151.0f);
        keyed *e = &tmp[fillp[level[i]]++];
        e->key = rs_pack_morton3(q[0], q[1], q[2]);
        e->id = i;
    }
    for (uint32_t l = 0; l < levels; l++) qsort(tmp + starts[l], level_size[l], sizeof *tmp, cmp_keyed);
    for (uint32_t i = 0; i < count; i++) order[i] = tmp[i].id;

    // Prefix table: level l's prefix holds levels >= l. Prefixes below min_lod are not listed (their
    // splats still lead the order); neither are empty levels.
    uint32_t n = 1, cum = count;
    for (uint32_t l = 0; l + 1 < levels; l++) {
        cum -= level_size[l];  // prefix without level l: levels l+1 and coarser
        if (cum >= min_lod && cum < lods[n - 1]) lods[n++] = cum;
    }
    *lod_count = n;
    if (progress) progress(user, 1.0);
out:
    free(g.head);
    free(g.node);
    free(perm);
    free(level);
    free(tmp);
    free(tried);
    free(tried_level);
    return res;
}
