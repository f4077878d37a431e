// pack_ao.c — per-splat ambient occlusion for environment lighting (issue 12): the cosine-weighted fraction
// of the sky each splat sees, so that eye sockets, nostrils, the inside of the ears and under the chin are
// not lit by the environment like the cheek. Computed from software orthographic depth maps of the cloud
// from RS_PACK_AO_DIRS directions spread over the sphere (a Fibonacci spiral): a splat sees direction d
// when nothing of the cloud lies in front of it seen from d. The renderer multiplies the environment's SH
// irradiance and its specular by it (byte 15 of the record, RS_SPLAT_FLAG_AO). The same maps give each
// splat's bent normal, the cosine-weighted mean of its open directions (RS_SPLAT_FLAG_BENT): the axis of
// the cone of sky it sees, which the renderer lights instead of a hemisphere around the normal (a nostril's
// wing faces sideways but sees the ground through the opening below; the jaw's underside faces down but
// sees the horizon).
#define _POSIX_C_SOURCE 200809L  // sysconf
#include "pack/pack.h"

#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define AO_MAP 512      // depth map side, texels, over the cloud's bounding sphere
#define AO_MIN_OCCLUDERS 50000u  // splats drawn into the depth maps, at least (see rs_pack_ao_cloud)

// Work per splat is bounded whatever the model: a disk is drawn at most AO_MAX_DISK texels in radius (a
// splat that large is a sparse cloud's, and the map is coarsened for those: below), so one direction costs
// at most (2 AO_MAX_DISK + 2)^2 texels per splat drawn.
#define AO_MAX_DISK 8.0f
// A sparse cloud (few splats, each many texels wide at AO_MAP) gets a coarser map, so that its median
// occluder is this many texels in radius: the same occlusion, a fraction of the texels.
#define AO_MEDIAN_DISK 2.0f
#define AO_MIN_MAP 64
// Cosines are summed as 16.16 fixed point: integer sums do not depend on the order the threads finish in,
// so the result is the same on any number of cores.
#define AO_ONE 65536.0f
#define AO_MAX_THREADS 8

// One direction's orthonormal frame: d towards the sky, (u, v) across it.
typedef struct ao_dir {
    float d[3], u[3], v[3];
} ao_dir;

static ao_dir fibonacci_dir(int k)
{
    // Fibonacci sphere: evenly spread directions.
    ao_dir o;
    float z = 1.0f - (2.0f * (float)k + 1.0f) / RS_PACK_AO_DIRS, r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = 2.39996323f * (float)k;
    float *d = o.d, *u = o.u, *v = o.v;
    d[0] = r * cosf(phi), d[1] = r * sinf(phi), d[2] = z;
    float t[3] = {fabsf(d[0]) < 0.9f ? 1.0f : 0.0f, fabsf(d[0]) < 0.9f ? 0.0f : 1.0f, 0.0f};
    u[0] = d[1] * t[2] - d[2] * t[1], u[1] = d[2] * t[0] - d[0] * t[2], u[2] = d[0] * t[1] - d[1] * t[0];
    float ul = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int a = 0; a < 3; a++) u[a] /= ul;
    v[0] = d[1] * u[2] - d[2] * u[1], v[1] = d[2] * u[0] - d[0] * u[2], v[2] = d[0] * u[1] - d[1] * u[0];
    return o;
}

static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Draws splat s (centre p relative to the cloud's centre) into the depth map seen from o.d, keeping the
// depth nearest to the sky: the disk as what it is from there, an ellipse (semi-axes r across its tilt,
// r |n.d| along it, at least ~a texel) at its plane's depth. A circle of radius r at the centre's depth
// would stand up to r tan(angle) above a tilted neighbour's centre and hide it from the sky: every open
// surface came out ~0.07 too dark, grainy with the normal map's tilts.
static void draw_disk(float *depth, int map, const ao_dir *o, const float p[3], const float normal[3], float radius, float R,
                      float texel)
{
    float x = (dot3(p, o->u) + R) / texel, y = (dot3(p, o->v) + R) / texel, h = dot3(p, o->d);
    float nu = dot3(normal, o->u), nv = dot3(normal, o->v), nd = dot3(normal, o->d);
    float r = fminf(radius / texel, AO_MAX_DISK), tilt = sqrtf(nu * nu + nv * nv);
    // e: the tilt's direction in the map (the ellipse's minor axis); edge-on disks get a texel of width.
    float ex = tilt > 1e-6f ? nu / tilt : 1.0f, ey = tilt > 1e-6f ? nv / tilt : 0.0f;
    float rr = fmaxf(r, 0.71f), minor = fmaxf(r * fabsf(nd), 0.71f);
    // Depth along d per texel of map offset, on the disk's plane (bounded: the disk spans +-r in depth).
    float gx = fabsf(nd) > 1e-3f ? -nu / nd * texel : 0.0f, gy = fabsf(nd) > 1e-3f ? -nv / nd * texel : 0.0f;
    float reach = radius;
    // Clamped to the map before the conversion (a degenerate cloud can put a disk 1e20 texels away).
    const float lo = -1.0f, hi = (float)map;
    int x0 = (int)floorf(RS_CLAMP(x - rr, lo, hi)), x1 = (int)floorf(RS_CLAMP(x + rr, lo, hi));
    int y0 = (int)floorf(RS_CLAMP(y - rr, lo, hi)), y1 = (int)floorf(RS_CLAMP(y + rr, lo, hi));
    for (int yy = RS_MAX(y0, 0); yy <= RS_MIN(y1, map - 1); yy++)
        for (int xx = RS_MAX(x0, 0); xx <= RS_MIN(x1, map - 1); xx++) {
            float dx = (float)xx + 0.5f - x, dy = (float)yy + 0.5f - y;
            float along = dx * ex + dy * ey, across = dy * ex - dx * ey;
            if (across * across / (rr * rr) + along * along / (minor * minor) > 1.0f) continue;
            float hh = h + RS_CLAMP(dx * gx + dy * gy, -reach, reach);
            float *z = &depth[yy * map + xx];
            if (hh > *z) *z = hh;
        }
}

// A splat as the pass reads it: position relative to the cloud's centre, normal, radius (occluders: scaled).
typedef struct ao_pt {
    float p[3], n[3], r;
} ao_pt;

typedef struct ao_job {
    const ao_pt *pts, *occ;  // every splat, and the occluders, each in Morton order (see rs_pack_ao_prefix)
    uint32_t n, occluders;
    float occluder_scale;  // occluders' radii are scaled by this (a prefix covers the surface with fewer disks)
    double c[3];
    float R, texel;
    int map;               // depth map side, texels
    int first, step;       // directions first, first + step, ...
    uint32_t *open, *total;
    int32_t (*bent)[3];    // sums of the open directions times their cosine, AO_ONE fixed point (or NULL)
    bool failed;
} ao_job;

static void *ao_worker(void *arg)
{
    ao_job *j = arg;
    int map = j->map;
    float *depth = malloc(sizeof(float) * (size_t)map * (size_t)map);
    if (!depth) {
        j->failed = true;
        return NULL;
    }
    for (int k = j->first; k < RS_PACK_AO_DIRS; k += j->step) {
        ao_dir o = fibonacci_dir(k);
        for (int i = 0; i < map * map; i++) depth[i] = -INFINITY;
        for (uint32_t i = 0; i < j->occluders; i++)
            draw_disk(depth, map, &o, j->occ[i].p, j->occ[i].n, j->occ[i].r, j->R, j->texel);
        for (uint32_t i = 0; i < j->n; i++) {
            const ao_pt *s = &j->pts[i];
            float nd = dot3(s->n, o.d);
            if (nd <= 0.0f) continue;
            const float *p = s->p;
            const float hi = (float)(map - 1);
            int x = (int)floorf(RS_CLAMP((dot3(p, o.u) + j->R) / j->texel, 0.0f, hi));
            int y = (int)floorf(RS_CLAMP((dot3(p, o.v) + j->R) / j->texel, 0.0f, hi));
            float slope = fminf(sqrtf(fmaxf(1.0f - nd * nd, 0.0f)) / nd, 10.0f);
            // The occluders' radius: a scaled-up disk of a prefix stands further proud of its neighbours.
            float bias = s->r * j->occluder_scale + j->texel * (1.0f + slope);
            uint32_t q = (uint32_t)lrintf(fminf(nd, 1.0f) * AO_ONE);
            j->total[i] += q;
            if (dot3(p, o.d) >= depth[y * map + x] - bias) {
                j->open[i] += q;
                if (j->bent)
                    for (int a = 0; a < 3; a++) j->bent[i][a] += (int32_t)lrintf(nd * o.d[a] * AO_ONE);
            }
        }
    }
    free(depth);
    return NULL;
}

typedef struct ao_key {
    uint32_t code, id;
} ao_key;

static int cmp_key(const void *a, const void *b)
{
    const ao_key *x = a, *y = b;
    return x->code != y->code ? (x->code > y->code) - (x->code < y->code) : (x->id > y->id) - (x->id < y->id);
}

// 10 bits spread to every third bit.
static uint32_t morton3(uint32_t v)
{
    v &= 1023u;
    v = (v | v << 16) & 0x030000FFu;
    v = (v | v << 8) & 0x0300F00Fu;
    v = (v | v << 4) & 0x030C30C3u;
    v = (v | v << 2) & 0x09249249u;
    return v;
}

static int cmp_float(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

// A splat is open towards d when its own depth is within `bias` of the map's at its centre: a radius
// (neighbouring disks on a curved surface, or tilted by the normal map, stand a little proud of each
// other) plus a texel scaled by the slope towards d (the texel's centre is up to a texel from the splat's).
// Directions are shared out over up to AO_MAX_THREADS threads (the cores online).
rs_result rs_pack_ao_prefix(const rs_splat *s, uint32_t n, uint32_t occluders, uint8_t *ao, float (*bent)[3],
                            rs_error *err)
{
    if (n == 0) return RS_OK;
    if (occluders == 0 || occluders > n) occluders = n;
    ao_job base = {.n = n, .occluders = occluders, .occluder_scale = sqrtf((float)n / (float)occluders)};
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) base.c[a] += s[i].pos[a];
    for (int a = 0; a < 3; a++) base.c[a] /= n;
    float R = 0.0f;
    for (uint32_t i = 0; i < n; i++) {
        float d2 = 0;
        for (int a = 0; a < 3; a++) d2 += (float)((s[i].pos[a] - base.c[a]) * (s[i].pos[a] - base.c[a]));
        R = fmaxf(R, sqrtf(d2) + s[i].radius);
    }
    if (!(R > 0) || !isfinite(R)) R = 1.0f;
    // Splats in Morton order (10 bits per axis over the bounding sphere): LOD order scatters neighbours
    // over the whole cloud, so every depth-map access missed the cache; in Morton order consecutive
    // splats touch neighbouring texels from every direction.
    ao_key *key = rs_alloc_array(n, sizeof *key);
    ao_pt *pts = rs_alloc_array(n, sizeof *pts), *occ = rs_alloc_array(occluders, sizeof *occ);
    uint32_t *where = rs_alloc_array(n, sizeof *where);  // sorted position -> splat index
    if (!key || !pts || !occ || !where) {
        free(key), free(pts), free(occ), free(where);
        return rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    }
    for (int pass = 0; pass < 2; pass++) {
        uint32_t m = pass ? occluders : n;
        for (uint32_t i = 0; i < m; i++) {
            uint32_t q[3];
            for (int a = 0; a < 3; a++) {
                float t = (float)((s[i].pos[a] - base.c[a]) / R) * 0.5f + 0.5f;
                q[a] = (uint32_t)(RS_CLAMP(isfinite(t) ? t : 0.0f, 0.0f, 1.0f) * 1023.0f);
            }
            key[i] = (ao_key){morton3(q[0]) | morton3(q[1]) << 1 | morton3(q[2]) << 2, i};
        }
        qsort(key, m, sizeof *key, cmp_key);
        ao_pt *dst = pass ? occ : pts;
        for (uint32_t k = 0; k < m; k++) {
            const rs_splat *sp = &s[key[k].id];
            for (int a = 0; a < 3; a++) dst[k].p[a] = (float)(sp->pos[a] - base.c[a]), dst[k].n[a] = sp->normal[a];
            dst[k].r = pass ? sp->radius * base.occluder_scale : sp->radius;
            if (!pass) where[k] = key[k].id;
        }
    }
    free(key);
    base.pts = pts, base.occ = occ;
    // The median occluder radius (of up to 4096 spread over the prefix) sets the map's resolution.
    uint32_t m = RS_MIN(occluders, 4096u);
    float *radii = malloc(sizeof(float) * m);
    if (!radii) {
        free(pts), free(occ), free(where);
        return rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    }
    for (uint32_t i = 0; i < m; i++) {
        float r = s[(uint64_t)i * occluders / m].radius * base.occluder_scale;
        radii[i] = isfinite(r) ? r : 0.0f;
    }
    qsort(radii, m, sizeof *radii, cmp_float);
    float median = radii[m / 2];
    free(radii);
    base.map = AO_MAP;
    if (median > 0 && 2.0f * R / AO_MAP < median / AO_MEDIAN_DISK)
        base.map = (int)RS_CLAMP(ceilf(2.0f * R * AO_MEDIAN_DISK / median), (float)AO_MIN_MAP, (float)AO_MAP);
    base.R = R, base.texel = 2.0f * R / base.map;

    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    int threads = (int)RS_CLAMP(cores, 1, AO_MAX_THREADS);
    ao_job jobs[AO_MAX_THREADS];
    pthread_t tid[AO_MAX_THREADS];
    bool started[AO_MAX_THREADS] = {false};
    rs_result r = RS_OK;
    for (int t = 0; t < threads; t++) {
        jobs[t] = base;
        jobs[t].first = t, jobs[t].step = threads;
        jobs[t].open = calloc(n, sizeof(uint32_t));
        jobs[t].total = calloc(n, sizeof(uint32_t));
        jobs[t].bent = bent ? calloc(n, sizeof *jobs[t].bent) : NULL;
        if (!jobs[t].open || !jobs[t].total || (bent && !jobs[t].bent)) r = RS_ERR_NOMEM;
    }
    // Thread 0 is this one; a thread that cannot start leaves its directions to be done here afterwards.
    for (int t = 1; t < threads && r == RS_OK; t++) started[t] = pthread_create(&tid[t], NULL, ao_worker, &jobs[t]) == 0;
    if (r == RS_OK) ao_worker(&jobs[0]);
    for (int t = 1; t < threads; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else if (r == RS_OK) ao_worker(&jobs[t]);
        if (jobs[t].failed) r = RS_ERR_NOMEM;
    }
    if (jobs[0].failed) r = RS_ERR_NOMEM;
    if (r == RS_OK)
        for (uint32_t i = 0; i < n; i++) {
            uint64_t open = 0, total = 0;
            for (int t = 0; t < threads; t++) open += jobs[t].open[i], total += jobs[t].total[i];
            float a = total > 0 ? (float)((double)open / (double)total) : 1.0f;
            ao[where[i]] = (uint8_t)lrintf(RS_CLAMP(a, 0.0f, 1.0f) * 255.0f);
            if (!bent) continue;
            // A splat that sees no sky keeps its normal (nothing to bend towards).
            double b[3] = {0, 0, 0};
            for (int t = 0; t < threads; t++)
                for (int k = 0; k < 3; k++) b[k] += jobs[t].bent[i][k];
            double l = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
            for (int k = 0; k < 3; k++) bent[where[i]][k] = l > 0.0 ? (float)(b[k] / l) : pts[i].n[k];
        }
    for (int t = 0; t < threads; t++) free(jobs[t].open), free(jobs[t].total), free(jobs[t].bent);
    free(pts), free(occ), free(where);
    if (r != RS_OK) return rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    return RS_OK;
}

rs_result rs_pack_ao(const rs_splat *s, uint32_t n, uint8_t *ao, float (*bent)[3], rs_error *err)
{
    return rs_pack_ao_prefix(s, n, n, ao, bent, err);
}

rs_result rs_pack_ao_cloud(rs_splat_cloud *c, rs_error *err)
{
    uint32_t n = c->hdr.count;
    rs_splat *s = malloc(sizeof *s * (size_t)RS_MAX(n, 1u));
    uint8_t *ao = malloc(RS_MAX(n, 1u));
    float(*bent)[3] = malloc(sizeof *bent * (size_t)RS_MAX(n, 1u));
    rs_result r = s && ao && bent ? RS_OK : rs_fail(err, RS_ERR_NOMEM, "ambient occlusion: out of memory");
    // The normals on the lattice the bent normal leaves them first, so that the occlusion is computed from
    // the normals the file will hold: recomputing it from the result gives the same bytes.
    if (r == RS_OK) rs_splat_quantize_normals(c, 10);
    for (uint32_t i = 0; r == RS_OK && i < n; i++) rs_splat_get(c, i, &s[i]);
    // Occluders: the smallest LOD prefix of at least AO_MIN_OCCLUDERS splats (every prefix is an even
    // subsample), drawn with radii scaled to cover the same surface: the depth maps cost a fraction, and
    // every splat is still tested against them.
    uint32_t occluders = n;
    for (uint32_t l = 0; l < c->hdr.lod_count; l++)
        if (c->hdr.lods[l] >= AO_MIN_OCCLUDERS && c->hdr.lods[l] < occluders) occluders = c->hdr.lods[l];
    if (r == RS_OK) r = rs_pack_ao_prefix(s, n, occluders, ao, bent, err);
    if (r == RS_OK) rs_splat_set_ao(c, ao), r = rs_splat_set_bent(c, (const float(*)[3])bent, err);
    free(s);
    free(ao);
    free(bent);
    return r;
}
