// test_pack.c — rouge-pack's library (tools/pack/pack.h): neighbours, normals, radii, LOD order, mesh
// sampling, the face frame and regions, and whole conversions of every PLY fixture.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "pack/pack.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static float dist3(const float a[3], const float b[3])
{
    float d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrtf(dot3(d, d));
}

// Uniform random points on the unit sphere (Marsaglia), seeded.
static float (*sphere_points(uint32_t n, uint64_t seed))[3]
{
    float(*p)[3] = malloc((size_t)n * sizeof *p);
    rs_pack_rng r;
    rs_pack_rng_seed(&r, seed);
    for (uint32_t i = 0; i < n; i++) {
        float z = (float)(2.0 * rs_pack_rng_unit(&r) - 1.0), a = (float)(6.283185307 * rs_pack_rng_unit(&r));
        float s = sqrtf(1.0f - z * z);
        p[i][0] = s * cosf(a);
        p[i][1] = s * sinf(a);
        p[i][2] = z;
    }
    return p;
}

// ---- small pieces ----

static void test_morton_interleaves_x_then_y_then_z(void)
{
    RS_CHECK(rs_pack_morton3(1, 0, 0) == 1 && rs_pack_morton3(0, 1, 0) == 2 && rs_pack_morton3(0, 0, 1) == 4,
             "unit axes");
    RS_CHECK(rs_pack_morton3(3, 3, 3) == 63, "(3,3,3) -> %llu", (unsigned long long)rs_pack_morton3(3, 3, 3));
    RS_CHECK(rs_pack_morton3(0x1fffff, 0, 0) == 0x1249249249249249ull, "21 bits of x");
}

static void test_rng_is_reproducible_and_in_range(void)
{
    rs_pack_rng a, b;
    rs_pack_rng_seed(&a, 42);
    rs_pack_rng_seed(&b, 42);
    double lo = 1, hi = 0, sum = 0;
    for (int i = 0; i < 100000; i++) {
        double x = rs_pack_rng_unit(&a);
        RS_REQUIRE(x == rs_pack_rng_unit(&b), "same seed, different stream at %d", i);
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        sum += x;
    }
    RS_CHECK(lo >= 0 && hi < 1 && fabs(sum / 100000 - 0.5) < 0.01, "range %g..%g mean %g", lo, hi, sum / 100000);
}

static void test_eigen_sym3_diagonalises(void)
{
    rs_pack_rng r;
    rs_pack_rng_seed(&r, 7);
    for (int t = 0; t < 200; t++) {
        double a[3][3], w[3], v[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++) a[i][j] = a[j][i] = rs_pack_rng_unit(&r) * 2 - 1;
        if (t == 0) memset(a, 0, sizeof a), a[0][0] = a[1][1] = 1, a[2][2] = 1e-9;  // two equal eigenvalues
        rs_pack_eigen_sym3((const double(*)[3])a, w, v);
        RS_REQUIRE(w[0] <= w[1] && w[1] <= w[2], "not ascending: %g %g %g", w[0], w[1], w[2]);
        for (int k = 0; k < 3; k++) {
            double av[3] = {0, 0, 0}, len = 0;
            for (int i = 0; i < 3; i++) {
                for (int j = 0; j < 3; j++) av[i] += a[i][j] * v[k][j];
                len += v[k][i] * v[k][i];
            }
            for (int i = 0; i < 3; i++) RS_REQUIRE(fabs(av[i] - w[k] * v[k][i]) < 1e-9, "A v != w v (case %d)", t);
            RS_REQUIRE(fabs(len - 1) < 1e-9, "eigenvector not unit");
        }
    }
}

static void test_knn_matches_brute_force(void)
{
    uint32_t n = 3000, k = 10;
    float(*p)[3] = sphere_points(n, 3);
    for (uint32_t i = 0; i < 50; i++) memcpy(p[n - 1 - i], p[i], sizeof p[i]);  // exact duplicates too
    rs_pack_knn knn;
    rs_error err = {0};
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])p, n, k, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    float *d = malloc(n * sizeof *d);
    int bad = 0;
    for (uint32_t i = 0; i < n; i += 7) {
        for (uint32_t j = 0; j < n; j++) d[j] = j == i ? INFINITY : dist3(p[i], p[j]);
        // k-th smallest by partial selection.
        for (uint32_t s = 0; s < k; s++) {
            uint32_t m = s;
            for (uint32_t j = s + 1; j < n; j++)
                if (d[j] < d[m]) m = j;
            float t = d[s];
            d[s] = d[m];
            d[m] = t;
            if (fabsf(knn.dist[(size_t)i * k + s] - d[s]) > 1e-6f) bad++;
            if (knn.idx[(size_t)i * k + s] == i) bad++;
        }
    }
    RS_CHECK(bad == 0, "%d neighbour distances differ from brute force", bad);
    // The bounded queries the face search uses: the nearest point under a bound (the same squared distance
    // as a scan of all points, or none) and every point within a radius (the same set), at points on, off
    // and far from the sphere.
    rs_pack_kdtree *t = NULL;
    uint32_t *ids = malloc(n * sizeof *ids), *mark = calloc(n, sizeof *mark);
    RS_REQUIRE(rs_pack_kdtree_create((const float(*)[3])p, n, &t, &err) == RS_OK, "%s", err.msg);
    int bad_near = 0, bad_within = 0;
    for (uint32_t i = 0; i < n; i += 11) {
        float q[3] = {p[i][0] * (1 + 0.1f * (i % 3)), p[i][1] * (1 + 0.1f * (i % 3)), p[i][2] + 0.05f * (i % 5)};
        float bound2 = 0.01f * (float)(1 + i % 4), best = bound2, got = -1;
        uint32_t want_n = 0;
        for (uint32_t j = 0; j < n; j++) {
            float dx = p[j][0] - q[0], dy = p[j][1] - q[1], dz = p[j][2] - q[2], e = dx * dx + dy * dy + dz * dz;
            if (e < best) best = e;
            want_n += e <= bound2;
        }
        bool found = rs_pack_kdtree_nearest_within(t, q, bound2, &got);
        bad_near += found != (best < bound2) || (found && got != best);
        uint32_t m = rs_pack_kdtree_within(t, q, bound2, ids);
        for (uint32_t a = 0; a < m; a++) {
            float dx = p[ids[a]][0] - q[0], dy = p[ids[a]][1] - q[1], dz = p[ids[a]][2] - q[2];
            bad_within += dx * dx + dy * dy + dz * dz > bound2 || mark[ids[a]] == i + 1;  // outside, or twice
            mark[ids[a]] = i + 1;
        }
        bad_within += m != want_n;
    }
    RS_CHECK(bad_near == 0 && bad_within == 0, "bounded queries differ from brute force: %d nearest, %d within",
             bad_near, bad_within);
    rs_pack_kdtree_destroy(t);
    free(ids);
    free(mark);
    rs_pack_knn_free(&knn);
    free(d);
    free(p);
}

static void test_knn_of_identical_points_is_fast_and_zero(void)
{
    // A hostile file: 200k copies of one point. Median splits by index keep this O(N log N).
    uint32_t n = 200000;
    float(*p)[3] = calloc(n, sizeof *p);
    rs_pack_knn knn;
    rs_error err = {0};
    double t0 = rs_time_now();
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])p, n, 8, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    double dt = rs_time_now() - t0;
    RS_CHECK(knn.dist[(size_t)(n - 1) * 8 + 7] == 0.0f && knn.idx[0] != 0, "distances not zero");
    RS_CHECK(dt < 5.0, "took %.2fs: quadratic?", dt);
    rs_pack_knn_free(&knn);
    free(p);
}

// ---- normals and radii ----

static void test_normals_on_sphere_point_outward(void)
{
    uint32_t n = 8000;
    float(*p)[3] = sphere_points(n, 11), (*nrm)[3] = malloc((size_t)n * sizeof *nrm);
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) p[i][a] = 2.0f * p[i][a] + (a == 0 ? 5.0f : 0.0f);  // off-origin
    rs_pack_knn knn;
    rs_error err = {0};
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])p, n, 16, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_estimate_normals((const float(*)[3])p, &knn, nrm, &err) == RS_OK, "%s", err.msg);
    uint32_t inward = 0;
    double worst = 0;
    for (uint32_t i = 0; i < n; i++) {
        float radial[3] = {(p[i][0] - 5.0f) / 2, p[i][1] / 2, p[i][2] / 2};
        float c = dot3(radial, nrm[i]) / sqrtf(dot3(radial, radial));
        inward += c < 0;
        worst = fmax(worst, acos(fmin(1.0, fabs(c))) * 180 / 3.14159265);
    }
    RS_CHECK(inward == 0, "%u of %u normals point inward", inward, n);
    RS_CHECK(worst < 4.0, "worst angle to the radial direction %.2f deg", worst);
    rs_pack_knn_free(&knn);
    free(p);
    free(nrm);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static void test_normals_on_demosthenes_agree_with_given(void)
{
    const char *path = rs_test_shared_path("demosthenes/demosthenes_points_100k.ply");
    if (!path) {
        rs_test_skip("shared data demosthenes/ not present");
        return;
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ply_load(path, &m, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(m->normal, "the cloud has normals to compare with");
    uint32_t n = m->vertex_count;
    float(*nrm)[3] = malloc((size_t)n * sizeof *nrm);
    double *angle = malloc(n * sizeof *angle);
    rs_pack_knn knn;
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])m->pos, n, 16, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_estimate_normals((const float(*)[3])m->pos, &knn, nrm, &err) == RS_OK, "%s", err.msg);
    uint32_t agree = 0;
    for (uint32_t i = 0; i < n; i++) {
        double c = dot3(nrm[i], m->normal[i]) / sqrt(dot3(m->normal[i], m->normal[i]));
        agree += c > 0;
        angle[i] = acos(fmin(1.0, fabs(c))) * 180 / 3.14159265;
    }
    qsort(angle, n, sizeof *angle, cmp_double);
    RS_CHECK(agree >= 0.99 * n, "only %.3f%% agree in sign", 100.0 * agree / n);
    RS_CHECK(angle[n / 2] < 5.0, "median angle %.2f deg", angle[n / 2]);
    rs_pack_knn_free(&knn);
    free(nrm);
    free(angle);
    rs_ply_destroy(m);
}

// The cosine-weighted mean open direction of a floor point d in front of the middle of a wall (x = 0, 8
// long, 1 high): the direction's angle from +z towards +x (away from the wall), by quadrature.
static double wall_bent_deg(double d)
{
    double sx = 0, sz = 0;
    enum { T = 400, P = 800 };
    for (int i = 0; i < T; i++)
        for (int j = 0; j < P; j++) {
            double th = (i + 0.5) * (PI / 2) / T, ph = (j + 0.5) * 2 * PI / P;
            double w[3] = {sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
            if (w[0] < 0) {
                double t = d / -w[0];
                if (fabs(t * w[1]) <= 4 && t * w[2] <= 1) continue;  // hits the wall
            }
            double wt = cos(th) * sin(th);  // cosine times the solid angle's sin(theta)
            sx += w[0] * wt, sz += w[2] * wt;
        }
    return atan2(sx, sz) * 180 / PI;
}

// Ambient occlusion (pack_ao.c) against analytic answers: a flat floor sees the whole upper hemisphere
// (1); the bottom of a hemispherical bowl sees the sky through its rim at 45 degrees from the axis, a
// cosine-weighted fraction of sin^2(45) = 0.5; a floor point at distance d from the foot of a long wall
// of height h misses the wall's form factor, AO = 1/2 + d / (2 sqrt(d^2 + h^2)); a splat under a lid
// sees nothing above it but what slips in under the lid's edge. The bent normals (the mean open
// direction): the floor's and the bowl bottom's straight up, the wall's tilted away from it as the
// quadrature above has it.
static void test_ambient_occlusion_matches_analytic_cases(void)
{
    enum { K = 60, BOWL = 4000, WALL_X = 200, WALL_Z = 50, LID = 40 };
    size_t cap = K * K + BOWL + WALL_X * (WALL_Z + 3) + LID * LID + 1, n = 0;
    rs_splat *s = calloc(cap, sizeof *s);
    uint8_t *ao = malloc(cap);
    float(*bent)[3] = malloc(sizeof *bent * cap);
    RS_REQUIRE(s && ao && bent, "out of memory");
    // A floor (z = 0, normal +z), 2 x 2 units, well away from the rest.
    for (int y = 0; y < K; y++)
        for (int x = 0; x < K; x++) {
            rs_splat *p = &s[n++];
            p->pos[0] = -6.0f + 2.0f * x / (K - 1), p->pos[1] = 2.0f * y / (K - 1), p->normal[2] = 1.0f;
            p->radius = 2.0f / K;
        }
    uint32_t floor_end = (uint32_t)n;
    // A bowl of radius 1 centred at (3, 0, 1): the lower hemisphere, normals pointing inwards (to the centre).
    uint32_t bottom = (uint32_t)n;
    for (int i = 0; i < BOWL; i++) {
        float z = -1.0f + (float)i / BOWL, r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.39996323f * (float)i;
        rs_splat *p = &s[n++];
        float d[3] = {r * cosf(phi), r * sinf(phi), z};
        for (int a = 0; a < 3; a++) p->pos[a] = d[a] + (a == 0 ? 3.0f : a == 2 ? 1.0f : 0.0f), p->normal[a] = -d[a];
        p->radius = 0.04f;
    }
    // A wall 8 units long, 1 high (x = 0, y in [-4, 4] shifted to y = -12, normal +x), and three floor
    // splats in front of its middle at d = 0.25, 0.5, 1.
    for (int i = 0; i < WALL_X; i++)
        for (int k = 0; k <= WALL_Z; k++) {
            rs_splat *p = &s[n++];
            p->pos[1] = -16.0f + 8.0f * i / (WALL_X - 1), p->pos[2] = (float)k / WALL_Z, p->normal[0] = 1.0f;
            p->radius = 0.04f;
        }
    const float wall_d[3] = {0.25f, 0.5f, 1.0f};
    uint32_t wall_probe = (uint32_t)n;
    for (int i = 0; i < 3; i++) {
        rs_splat *p = &s[n++];
        p->pos[0] = wall_d[i], p->pos[1] = -12.0f, p->normal[2] = 1.0f, p->radius = 0.02f;
    }
    // A lid: a 2 x 2 square 0.2 above a splat (at (-3, -6, 0)); the sky shows only below its edges,
    // atan(0.2 / 1) ~ 11 degrees above the horizon at most: AO <= cos^2(78.7 deg) = 0.04.
    for (int y = 0; y < LID; y++)
        for (int x = 0; x < LID; x++) {
            rs_splat *p = &s[n++];
            p->pos[0] = -4.0f + 2.0f * x / (LID - 1), p->pos[1] = -7.0f + 2.0f * y / (LID - 1), p->pos[2] = 0.2f;
            p->normal[2] = 1.0f;
            p->radius = 2.0f / LID;
        }
    uint32_t under = (uint32_t)n;
    s[n].pos[0] = -3.0f, s[n].pos[1] = -6.0f, s[n].normal[2] = 1.0f, s[n].radius = 0.02f;
    n++;
    rs_error err = {0};
    RS_REQUIRE(rs_pack_ao(s, (uint32_t)n, ao, bent, &err) == RS_OK, "%s", err.msg);
    double floor_mean = 0, floor_tilt = 0;
    for (uint32_t i = K + 1; i < floor_end - K - 1; i++)  // the edges see under the floor's rim
        if (i % K != 0 && i % K != K - 1) floor_tilt = fmax(floor_tilt, acos(fmin(bent[i][2], 1.0)) * 180 / PI);
    double bowl_tilt = acos(fmin(bent[bottom][2], 1.0)) * 180 / PI;
    printf("# bent normals: floor within %.2f deg of up, bowl bottom %.2f deg\n", floor_tilt, bowl_tilt);
    RS_CHECK(floor_tilt < 1.0, "open floor: bent normal %.2f deg from the normal", floor_tilt);
    RS_CHECK(bowl_tilt < 3.0, "bowl bottom: bent normal %.2f deg from the axis", bowl_tilt);
    for (uint32_t i = 0; i < floor_end; i++) floor_mean += ao[i] / 255.0;
    floor_mean /= floor_end;
    float b = ao[bottom] / 255.0f, lid = ao[under] / 255.0f;
    printf("# ambient occlusion: floor %.3f (1), bowl bottom %.3f (0.5), under a lid %.3f (~0)\n", floor_mean, b,
           lid);
    RS_CHECK(floor_mean > 0.99, "open floor: AO %.3f, want ~1", floor_mean);
    RS_CHECK(fabsf(b - 0.5f) < 0.06f, "bowl bottom: AO %.3f, want 0.5", b);
    RS_CHECK(lid < 0.06f, "under a lid: AO %.3f, want ~0", lid);
    for (int i = 0; i < 3; i++) {
        float d = wall_d[i], want = 0.5f + d / (2.0f * sqrtf(d * d + 1.0f)), got = ao[wall_probe + i] / 255.0f;
        printf("# %.2f from the foot of a wall as high: AO %.3f (%.3f)\n", d, got, want);
        RS_CHECK(fabsf(got - want) < 0.05f, "%.2f from a wall: AO %.3f, want %.3f", d, got, want);
        const float *bw = bent[wall_probe + i];
        double tilt = atan2(bw[0], bw[2]) * 180 / PI, want_tilt = wall_bent_deg(d);
        printf("# %.2f from the wall: bent normal %.1f deg away from it (%.1f), %.1f deg along it\n", d, tilt,
               want_tilt, asin(fabs(bw[1])) * 180 / PI);
        RS_CHECK(fabs(tilt - want_tilt) < 3.0 && fabs(bw[1]) < 0.05, "%.2f from a wall: bent normal (%.3f %.3f %.3f), "
                 "%.1f deg from up, want %.1f", d, bw[0], bw[1], bw[2], tilt, want_tilt);
    }
    free(s);
    free(ao);
    free(bent);
}

// Work per splat is bounded however few and large the splats (issue 24: a 1,000-triangle model did not
// finish in 120 s, stuck in the occlusion pass): 20k splats each 4x the cloud's size used to draw every
// disk over the whole 512^2 map from 96 directions (10^12 texel writes). And an LOD prefix drawn as the
// occluders (scaled radii) gives a flat floor under a lid the same answers as drawing every splat.
static void test_ambient_occlusion_bounded_and_prefix_agrees(void)
{
    enum { N = 20000, SIDE = 141 };
    rs_splat *s = calloc(N, sizeof *s);
    uint8_t *ao = malloc(N), *ao_all = malloc(N);
    RS_REQUIRE(s && ao && ao_all, "out of memory");
    for (int i = 0; i < N; i++) {
        s[i].pos[0] = (float)(i % SIDE) / SIDE, s[i].pos[1] = (float)(i / SIDE) / SIDE, s[i].normal[2] = 1.0f;
        s[i].radius = 4.0f;
    }
    rs_error err = {0};
    double t0 = rs_time_now();
    RS_REQUIRE(rs_pack_ao(s, N, ao, NULL, &err) == RS_OK, "%s", err.msg);
    double dt = rs_time_now() - t0;
    printf("# occlusion of %d splats 4x the cloud wide: %.2f s\n", N, dt);
    RS_CHECK(dt < 30.0, "took %.1f s", dt);
    // A floor (shuffled, as LOD order is) with a lid over one corner: every splat drawn vs a quarter.
    for (int i = 0; i < N; i++) {
        uint32_t h = (uint32_t)i * 2654435761u;
        s[i].pos[0] = (float)(h % 1000u) / 100.0f, s[i].pos[1] = (float)((h / 1000u) % 1000u) / 100.0f;
        s[i].pos[2] = 0, s[i].radius = 0.06f;
        s[i].normal[2] = 1.0f;
        if (s[i].pos[0] < 3 && s[i].pos[1] < 3 && i % 5 == 0) s[i].pos[2] = 0.3f, s[i].normal[2] = -1.0f;
    }
    RS_REQUIRE(rs_pack_ao(s, N, ao_all, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_ao_prefix(s, N, N / 4, ao, NULL, &err) == RS_OK, "%s", err.msg);
    double diff = 0;
    for (int i = 0; i < N; i++) diff += abs(ao[i] - ao_all[i]) / 255.0;
    diff /= N;
    printf("# occlusion from a quarter of the splats vs all: mean difference %.4f\n", diff);
    RS_CHECK(diff < 0.02, "mean AO difference %.4f", diff);
    free(s), free(ao), free(ao_all);
}

// The bundled face's occlusion where an artist expects it, as regional means over splats picked in the
// face frame (nose tip = the most forward splat, H = face height): eye sockets, the underside of the
// nose, under the chin and the ear's concha clearly darker than the cheek and forehead, which see
// nearly the whole sky. Leaves a front and a side view of the occlusion in the test output to look at.
enum { AO_CHEEK, AO_FOREHEAD, AO_EYE, AO_NOSTRIL, AO_CHIN, AO_EAR, AO_REGIONS };

static int ao_region(const rs_splat_cloud *c, uint32_t i, const float tip[3], int cheek, int forehead)
{
    const float *p = c->pos[i], *n = c->normal[i];
    float H = c->hdr.face_height, x = fabsf(p[0] - tip[0]) / H, y = (p[1] - tip[1]) / H, z = (p[2] - tip[2]) / H;
    // The bundled face's frame is +y up, +z forward (checked by the caller).
    if (x > 0.05f && x < 0.25f && y > 0.05f && y < 0.18f && z > -0.32f && n[2] > 0.0f) return AO_EYE;
    if (x < 0.1f && y > -0.1f && y < -0.01f && z > -0.19f && n[1] < -0.3f) return AO_NOSTRIL;
    if (x < 0.19f && y > -0.54f && y < -0.34f && z > -0.42f && n[1] < -0.5f) return AO_CHIN;
    float ex = x - 0.31f, ey = y - 0.017f, ez = z + 0.49f;
    if (x > 0.28f && ex > -0.06f && ex * ex + ey * ey + ez * ez < 0.06f * 0.06f) return AO_EAR;
    int region = (int)(c->packed[i].w[1] >> 24);
    return region == cheek ? AO_CHEEK : region == forehead ? AO_FOREHEAD : -1;
}

// Orthographic CPU views of the occlusion (grey) beside the colour, front and side, nearest splat wins.
static void save_ao_views(const rs_splat_cloud *c)
{
    enum { W = 400 };
    rs_image img = {0};
    float *zb = malloc(sizeof(float) * 2 * W * W);
    if (!zb || rs_image_create(2 * W, 2 * W, 3, &img, NULL) != RS_OK) {
        free(zb);
        return;
    }
    for (int i = 0; i < 2 * W * W; i++) zb[i] = -INFINITY;
    const float *m = c->hdr.centre;
    float s = W / (1.3f * c->hdr.face_height);
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        const float *p = c->pos[i];
        rs_splat sp;
        rs_splat_get(c, i, &sp);
        uint8_t a = (uint8_t)lrintf(rs_splat_ao(c, i) * 255.0f);
        for (int view = 0; view < 2; view++) {
            float u = view ? m[2] - p[2] : p[0] - m[0], v = p[1] - m[1], d = view ? p[0] : p[2];
            int x = (int)(W / 2 + u * s), y = (int)(W / 2 - v * s), rr = (int)ceilf(c->radius[i] * s);
            for (int yy = y - rr; yy <= y + rr; yy++)
                for (int xx = x - rr; xx <= x + rr; xx++) {
                    if (xx < 0 || yy < 0 || xx >= W || yy >= W) continue;
                    float *z = &zb[view * W * W + yy * W + xx];
                    if (d <= *z) continue;
                    *z = d;
                    uint8_t *q = img.pixels + ((size_t)(yy + view * W) * 2 * W + xx) * 3;
                    q[0] = q[1] = q[2] = a;
                    memcpy(q + 3 * W, sp.rgb, 3);
                }
        }
    }
    rs_test_save("face_ambient_occlusion", &img);
    rs_image_free(&img);
    free(zb);
}

static void test_bundled_face_occlusion_darkens_eyes_nostrils_chin_and_ears(void)
{
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_load("assets/face.rsf", &c, &err) == RS_OK, "%s", err.msg);
    const rs_splat_header *h = &c->hdr;
    if (!RS_CHECK(h->flags & RS_SPLAT_FLAG_AO, "assets/face.rsf has no ambient occlusion") ||
        !RS_CHECK(h->up[1] > 0.99f && h->forward[2] > 0.99f, "the bundled face's frame is not +y up, +z forward")) {
        rs_splat_destroy(c);
        return;
    }
    int cheek = -1, forehead = -1;
    for (uint32_t r = 0; r < h->region_count; r++) {
        if (!strcmp(h->regions[r].name, "cheek")) cheek = (int)r;
        if (!strcmp(h->regions[r].name, "forehead")) forehead = (int)r;
    }
    uint32_t tip = 0;
    for (uint32_t i = 1; i < h->count; i++)
        if (c->pos[i][2] > c->pos[tip][2]) tip = i;
    double sum[AO_REGIONS] = {0};
    int count[AO_REGIONS] = {0};
    for (uint32_t i = 0; i < h->count; i++) {
        int r = ao_region(c, i, c->pos[tip], cheek, forehead);
        if (r < 0) continue;
        sum[r] += rs_splat_ao(c, i);
        count[r]++;
    }
    static const char *names[AO_REGIONS] = {"cheek", "forehead", "eye sockets", "under the nose", "under the chin",
                                            "ear concha"};
    double mean[AO_REGIONS];
    for (int r = 0; r < AO_REGIONS; r++) {
        mean[r] = count[r] ? sum[r] / count[r] : NAN;
        printf("# ambient occlusion, %-14s %6d splats, mean %.3f\n", names[r], count[r], mean[r]);
        RS_CHECK(count[r] > 500, "%s: only %d splats picked", names[r], count[r]);
    }
    double open = fmin(mean[AO_CHEEK], mean[AO_FOREHEAD]);
    RS_CHECK(open > 0.93, "cheek %.3f / forehead %.3f: open skin should see nearly all the sky", mean[AO_CHEEK],
             mean[AO_FOREHEAD]);
    for (int r = AO_EYE; r < AO_REGIONS; r++)
        RS_CHECK(mean[r] < open - 0.12, "%s: AO %.3f, not clearly darker than the cheek and forehead (%.3f)",
                 names[r], mean[r], open);
    save_ao_views(c);
    rs_splat_destroy(c);
}

static void test_radius_matches_grid_spacing(void)
{
    // A 60x60 grid of spacing h: the 8th neighbour of an interior point is a diagonal one, sqrt(2) h.
    uint32_t side = 60, n = side * side;
    float h = 0.01f, (*p)[3] = malloc((size_t)n * sizeof *p), *r = malloc(n * sizeof *r);
    for (uint32_t i = 0; i < n; i++) {
        p[i][0] = (float)(i % side) * h;
        p[i][1] = (float)(i / side) * h;
        p[i][2] = 0.3f;
    }
    rs_pack_knn knn;
    rs_error err = {0};
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])p, n, RS_PACK_RADIUS_K, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_radii(&knn, r, &err) == RS_OK, "%s", err.msg);
    float want = RS_PACK_RADIUS_SCALE * sqrtf(2.0f) * h;
    int off = 0;
    for (uint32_t y = 2; y < side - 2; y++)
        for (uint32_t x = 2; x < side - 2; x++) off += fabsf(r[y * side + x] - want) > 1e-3f * want;
    RS_CHECK(off == 0, "%d interior radii differ from %g", off, want);
    // Splats overlap into a closed surface: radius well above half the spacing.
    RS_CHECK(want > 1.0f * h, "radius %g not above the spacing %g", want, h);
    rs_pack_knn_free(&knn);
    free(p);
    free(r);
}

// ---- LOD ----

typedef struct nn_stats {
    double mean, cv;
} nn_stats;

// Nearest-neighbour distances within the points ids[0..n).
static nn_stats nn_of(const float (*pos)[3], const uint32_t *ids, uint32_t n)
{
    float(*q)[3] = malloc((size_t)n * sizeof *q);
    for (uint32_t i = 0; i < n; i++) memcpy(q[i], pos[ids[i]], sizeof q[i]);
    rs_pack_knn knn;
    rs_error err = {0};
    nn_stats s = {0, 0};
    if (rs_pack_knn_compute((const float(*)[3])q, n, 1, &knn, NULL, NULL, &err) == RS_OK) {
        double sum = 0, sum2 = 0;
        for (uint32_t i = 0; i < n; i++) sum += knn.dist[i], sum2 += (double)knn.dist[i] * knn.dist[i];
        s.mean = sum / n;
        s.cv = sqrt(fmax(0, sum2 / n - s.mean * s.mean)) / s.mean;
        rs_pack_knn_free(&knn);
    }
    free(q);
    return s;
}

static void test_lod_prefix_is_spatially_uniform(void)
{
    uint32_t n = 40000, lods[RS_SPLAT_MAX_LODS], levels = 0;
    float(*p)[3] = sphere_points(n, 5);
    uint32_t *order = malloc(n * sizeof *order), *rnd = malloc(n * sizeof *rnd);
    rs_error err = {0};
    RS_REQUIRE(rs_pack_lod_order((const float(*)[3])p, n, 2000, order, lods, &levels, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(levels >= 4 && lods[0] == n, "%u levels", levels);
    // A random subset of the same size, for comparison: its NN distances spread far more.
    rs_pack_rng r;
    rs_pack_rng_seed(&r, 9);
    for (uint32_t i = 0; i < n; i++) rnd[i] = i;
    for (uint32_t i = n; i > 1; i--) {
        uint32_t j = rs_pack_rng_u32(&r) % i, t = rnd[i - 1];
        rnd[i - 1] = rnd[j];
        rnd[j] = t;
    }
    for (uint32_t l = 1; l < levels; l++) {
        RS_CHECK(lods[l] < lods[l - 1] && lods[l] >= 2000, "lods not descending above min_lod");
        RS_CHECK(fabs((double)lods[l] / lods[l - 1] - 0.5) < 0.12, "level %u holds %u of %u", l, lods[l], lods[l - 1]);
        nn_stats a = nn_of((const float(*)[3])p, order, lods[l]), b = nn_of((const float(*)[3])p, rnd, lods[l]);
        RS_CHECK(a.cv < 0.22 && a.cv < 0.5 * b.cv, "prefix %u: NN-distance CV %.3f vs random %.3f", lods[l], a.cv, b.cv);
        // Blue noise: the nearest neighbour sits at ~1.5x the random subset's mean distance.
        RS_CHECK(a.mean > 1.3 * b.mean, "prefix %u: NN mean %.4f vs random %.4f", lods[l], a.mean, b.mean);
    }
    // Every point appears exactly once.
    uint8_t *seen = calloc(n, 1);
    int dup = 0;
    for (uint32_t i = 0; i < n; i++) dup += seen[order[i]]++ != 0;
    RS_CHECK(dup == 0, "%d points repeated in the order", dup);
    free(seen);
    free(order);
    free(rnd);
    free(p);
}

// Drawn as the renderer would draw a prefix (radius x sqrt(N / n)), splats cover the surface: points
// of an independent sample of the same sphere all lie on some splat's disk.
static void test_lod_prefix_covers_surface(void)
{
    uint32_t n = 30000, lods[RS_SPLAT_MAX_LODS], levels = 0, probes = 5000;
    float(*p)[3] = sphere_points(n, 21), (*q)[3] = sphere_points(probes, 22), *radius = malloc(n * sizeof *radius);
    uint32_t *order = malloc(n * sizeof *order);
    rs_pack_knn knn;
    rs_error err = {0};
    RS_REQUIRE(rs_pack_knn_compute((const float(*)[3])p, n, RS_PACK_RADIUS_K, &knn, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_radii(&knn, radius, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_lod_order((const float(*)[3])p, n, 1000, order, lods, &levels, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    float(*pre)[3] = malloc((size_t)n * sizeof *pre);
    for (uint32_t l = 0; l < levels; l++) {
        uint32_t m = lods[l];
        float scale = sqrtf((float)n / m);
        for (uint32_t i = 0; i < m; i++) memcpy(pre[i], p[order[i]], sizeof pre[i]);
        rs_pack_kdtree *t = NULL;
        RS_REQUIRE(rs_pack_kdtree_create((const float(*)[3])pre, m, &t, &err) == RS_OK, "%s", err.msg);
        uint32_t holes = 0;
        for (uint32_t k = 0; k < probes; k++) {
            uint32_t idx[16];
            float d[16];
            uint32_t found = rs_pack_kdtree_query(t, q[k], 16, RS_PACK_NONE, idx, d);
            bool covered = false;
            for (uint32_t j = 0; j < found && !covered; j++) {
                const float *c = p[order[idx[j]]];  // on the unit sphere the normal is the position
                float v[3] = {q[k][0] - c[0], q[k][1] - c[1], q[k][2] - c[2]};
                float along = dot3(v, c), tang = sqrtf(fmaxf(0.0f, dot3(v, v) - along * along));
                covered = tang <= radius[order[idx[j]]] * scale;
            }
            holes += !covered;
        }
        rs_pack_kdtree_destroy(t);
        // The full set is random (scanner-like), so a handful of probes may sit in its gaps.
        RS_CHECK(holes <= (l == 0 ? probes / 1000 : 0), "prefix %u: %u of %u probes uncovered", m, holes, probes);
    }
    rs_pack_knn_free(&knn);
    free(pre);
    free(order);
    free(radius);
    free(p);
    free(q);
}

static void test_morton_order_keeps_levels_compact(void)
{
    uint32_t n = 20000, lods[RS_SPLAT_MAX_LODS], levels = 0;
    float(*p)[3] = sphere_points(n, 8);
    uint32_t *order = malloc(n * sizeof *order);
    rs_error err = {0};
    RS_REQUIRE(rs_pack_lod_order((const float(*)[3])p, n, 2000, order, lods, &levels, NULL, NULL, &err) == RS_OK, "%s", err.msg);
    // Consecutive splats inside the finest level are close; in input (random) order they are not.
    double ordered = 0, random = 0;
    uint32_t lo = levels > 1 ? lods[1] : 0, cnt = 0;
    for (uint32_t i = lo + 1; i < n; i++, cnt++) {
        ordered += dist3(p[order[i]], p[order[i - 1]]);
        random += dist3(p[i], p[i - 1]);
    }
    RS_CHECK(ordered < 0.1 * random, "mean step %.4f in Morton order vs %.4f at random", ordered / cnt, random / cnt);
    // A brush-sized ball touches few contiguous runs of the finest level.
    float c[3] = {0, 0, 1};
    uint32_t runs = 0, inside = 0;
    bool prev = false;
    for (uint32_t i = lo; i < n; i++) {
        bool in = dist3(p[order[i]], c) < 0.2f;
        inside += in;
        runs += in && !prev;
        prev = in;
    }
    RS_CHECK(inside > 50 && runs * 4 < inside, "%u splats in %u runs (random order: about one run each)", inside, runs);
    free(order);
    free(p);
}

// ---- mesh sampling ----

static rs_ply_mesh *quad_mesh(bool mirrored_uv)
{
    // Two triangles in the z = 0 plane: [0,1]x[0,1] (area 0.5) and [1,4]x[0,1] (area 1.5), UV s = x/4
    // (or -x/4 mirrored), t = y, normals +z, counter-clockwise from +z.
    static float pos[6][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {4, 0, 0}, {4, 1, 0}};
    static float nrm[6][3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    static float uv[6][2], uvm[6][2];
    static uint32_t tri[2][3] = {{0, 1, 2}, {3, 4, 5}};
    for (int i = 0; i < 6; i++) {
        uv[i][0] = pos[i][0] / 4, uv[i][1] = pos[i][1];
        uvm[i][0] = 1 - pos[i][0] / 4, uvm[i][1] = pos[i][1];
    }
    rs_ply_mesh *m = calloc(1, sizeof *m);
    m->vertex_count = 6;
    m->pos = pos;
    m->normal = nrm;
    m->uv = mirrored_uv ? uvm : uv;
    m->tri_count = 2;
    m->tri = tri;
    return m;
}

static void test_sample_mesh_is_area_uniform_and_reproducible(void)
{
    rs_ply_mesh *m = quad_mesh(false);
    rs_pack_sample_desc d = {.points = 40000, .seed = 3, .all_components = true};
    rs_pack_points a = {0}, b = {0};
    rs_error err = {0};
    uint32_t dropped = 99;
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, &dropped, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &b, NULL, &err) == RS_OK, "%s", err.msg);
    uint32_t first = 0, outside = 0;
    for (uint32_t i = 0; i < a.count; i++) {
        float x = a.pos[i][0], y = a.pos[i][1];
        first += x < 1 && y <= 1 - x + 1e-5f;
        outside += y < -1e-6f || y > 1 + 1e-6f || x < -1e-6f || x > 4 + 1e-6f;
    }
    // Areas 0.5 and 1.5: a quarter of the samples on the first triangle (binomial sd ~ 0.2%).
    RS_CHECK(fabs(first / 40000.0 - 0.25) < 0.01, "first triangle got %.4f of the samples", first / 40000.0);
    RS_CHECK(outside == 0, "%u samples off the triangles", outside);
    RS_CHECK(memcmp(a.pos, b.pos, (size_t)a.count * sizeof *a.pos) == 0, "same seed, different samples");
    RS_CHECK(dropped == 0, "all_components dropped %u triangles", dropped);
    rs_pack_points_free(&a);
    rs_pack_points_free(&b);
    free(m);
}

static void test_sample_mesh_keeps_the_largest_component(void)
{
    // The two triangles share no vertex index: two components, 0.5 and 1.5 in area.
    rs_ply_mesh *m = quad_mesh(false);
    rs_pack_sample_desc d = {.points = 2000};
    rs_pack_points a = {0};
    rs_error err = {0};
    uint32_t dropped = 0;
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, &dropped, &err) == RS_OK, "%s", err.msg);
    uint32_t small = 0;
    for (uint32_t i = 0; i < a.count; i++) small += a.pos[i][0] < 1 - 1e-5f;
    RS_CHECK(dropped == 1 && small == 0, "dropped %u, %u samples on the small component", dropped, small);
    rs_pack_points_free(&a);
    d.all_components = true;
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, &dropped, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(dropped == 0, "all_components dropped %u", dropped);
    rs_pack_points_free(&a);
    free(m);
}

// A constant normal map tilting toward +s (red up) must tilt normals toward dP/ds, and toward -x when
// the UVs are mirrored (s grows toward -x); green tilts toward dP/dt (OpenGL convention).
static void test_normal_map_follows_uv_tangents(void)
{
    uint8_t px[4][3] = {{218, 128, 218}, {218, 128, 218}, {218, 128, 218}, {218, 128, 218}};
    rs_image nm = {2, 2, 3, &px[0][0]};
    rs_error err = {0};
    for (int mirrored = 0; mirrored < 2; mirrored++) {
        rs_ply_mesh *m = quad_mesh(mirrored);
        rs_pack_sample_desc d = {.points = 200, .all_components = true, .normal_map = &nm};
        rs_pack_points a = {0};
        RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, NULL, &err) == RS_OK, "%s", err.msg);
        float want = mirrored ? -1.0f : 1.0f;
        int bad = 0;
        for (uint32_t i = 0; i < a.count; i++) bad += !(a.normal[i][0] * want > 0.5f && a.normal[i][2] > 0.5f);
        RS_CHECK(bad == 0, "%s UVs: %d normals not tilted toward %+g x (first %g %g %g)", mirrored ? "mirrored" : "plain",
                 bad, want, a.normal[0][0], a.normal[0][1], a.normal[0][2]);
        rs_pack_points_free(&a);
        free(m);
    }
    for (int i = 0; i < 4; i++) px[i][0] = 128, px[i][1] = 218;
    rs_ply_mesh *m = quad_mesh(false);
    rs_pack_sample_desc d = {.points = 100, .all_components = true, .normal_map = &nm};
    rs_pack_points a = {0};
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, NULL, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(a.normal[0][1] > 0.5f, "green must tilt toward +t = +y: %g %g %g", a.normal[0][0], a.normal[0][1], a.normal[0][2]);
    rs_pack_points_free(&a);
    free(m);
}

static void test_texture_t0_is_the_bottom_row(void)
{
    // 1x2 texture: top row red, bottom row blue. Samples at small y (t) must be blue.
    uint8_t px[2][3] = {{255, 0, 0}, {0, 0, 255}};
    rs_image tex = {1, 2, 3, &px[0][0]};
    rs_ply_mesh *m = quad_mesh(false);
    rs_pack_sample_desc d = {.points = 2000, .texture = &tex};
    rs_pack_points a = {0};
    rs_error err = {0};
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, NULL, &err) == RS_OK, "%s", err.msg);
    int bad = 0;
    for (uint32_t i = 0; i < a.count; i++) {
        if (a.pos[i][1] < 0.2f) bad += !(a.rgb[i][2] > 200 && a.rgb[i][0] < 55);
        if (a.pos[i][1] > 0.8f) bad += !(a.rgb[i][0] > 200 && a.rgb[i][2] < 55);
    }
    RS_CHECK(bad == 0, "%d samples coloured against the t = 0 bottom-row convention", bad);
    rs_pack_points_free(&a);
    free(m);
}

// A UV-space region map overrides where it is painted and leaves white to the segmentation; a
// per-vertex `region` property takes the nearest corner's id.
static void test_region_map_and_property_label_samples(void)
{
    uint8_t px[1][2][3] = {{{255, 0, 0}, {255, 255, 255}}};  // left half cheek, right half automatic
    rs_image map = {2, 1, 3, &px[0][0][0]};
    rs_ply_mesh *m = quad_mesh(false);
    rs_pack_sample_desc d = {.points = 3000, .all_components = true, .region_map = &map};
    rs_pack_points a = {0};
    rs_error err = {0};
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, NULL, &err) == RS_OK, "%s", err.msg);
    int bad = 0;
    for (uint32_t i = 0; i < a.count; i++) {
        float s = a.pos[i][0] / 4;
        if (fabsf(s - 0.5f) > 0.01f) bad += a.region[i] != (s < 0.5f ? RS_REGION_CHEEK : RS_PACK_REGION_AUTO);
    }
    RS_CHECK(bad == 0, "%d samples mislabelled by the region map", bad);
    rs_pack_points_free(&a);
    uint8_t ids[6] = {RS_REGION_NOSE, RS_REGION_NOSE, RS_REGION_NOSE, RS_REGION_LIPS, RS_REGION_LIPS, RS_REGION_LIPS};
    m->region = ids;
    d.region_map = NULL;
    RS_REQUIRE(rs_pack_sample_mesh(m, &d, &a, NULL, &err) == RS_OK, "%s", err.msg);
    bad = 0;
    for (uint32_t i = 0; i < a.count; i++) bad += a.region[i] != (a.pos[i][0] < 1 ? RS_REGION_NOSE : RS_REGION_LIPS);
    RS_CHECK(bad == 0, "%d samples did not take their triangle's region", bad);
    rs_pack_points_free(&a);
    free(m);
}

static void test_region_map_colour_codes(void)
{
    const uint8_t c[9][3] = {{0, 0, 0},     {250, 10, 5},    {0, 240, 20},   {10, 10, 250}, {250, 250, 10},
                             {250, 10, 240}, {10, 245, 250}, {255, 255, 255}, {240, 250, 245}};
    const uint8_t want[9] = {RS_REGION_OTHER,  RS_REGION_CHEEK,     RS_REGION_NOSE,     RS_REGION_FOREHEAD, RS_REGION_LIPS,
                             RS_REGION_EYELID, RS_REGION_BROW, RS_PACK_REGION_AUTO, RS_PACK_REGION_AUTO};
    for (int i = 0; i < 9; i++)
        RS_CHECK(rs_pack_region_from_rgb(c[i]) == want[i], "colour %d -> %u", i, rs_pack_region_from_rgb(c[i]));
}

static void test_axis_parse(void)
{
    RS_CHECK(rs_pack_axis_parse("+y") == RS_PACK_AXIS_POS_Y && rs_pack_axis_parse("z") == RS_PACK_AXIS_POS_Z &&
                 rs_pack_axis_parse("-X") == RS_PACK_AXIS_NEG_X,
             "axes");
    RS_CHECK(rs_pack_axis_parse("up") == RS_PACK_AXIS_DEFAULT && rs_pack_axis_parse("") == RS_PACK_AXIS_DEFAULT &&
                 rs_pack_axis_parse("+") == RS_PACK_AXIS_DEFAULT && rs_pack_axis_parse(NULL) == RS_PACK_AXIS_DEFAULT,
             "bad axes");
}

// ---- whole conversions ----

static bool ends_with(const char *s, const char *suffix)
{
    size_t a = strlen(s), b = strlen(suffix);
    return a >= b && strcmp(s + a - b, suffix) == 0;
}

static void test_every_ply_fixture_converts_or_fails_cleanly(void)
{
    DIR *dir = opendir("tests/fixtures/ply");
    if (!dir) {
        rs_test_skip("tests/fixtures/ply not present");
        return;
    }
    struct dirent *e;
    int converted = 0;
    while ((e = readdir(dir))) {
        if (!ends_with(e->d_name, ".ply")) continue;
        char path[512];
        snprintf(path, sizeof path, "tests/fixtures/ply/%s", e->d_name);
        rs_ply_mesh *m = NULL;
        rs_error err = {0};
        if (rs_ply_load(path, &m, &err) != RS_OK) {
            RS_CHECK(strncmp(e->d_name, "bad_", 4) == 0 || strncmp(e->d_name, "crash-", 6) == 0,
                     "%s does not load: %s", e->d_name, err.msg);
            continue;
        }
        rs_pack_desc d = {.points = 500};
        rs_splat_cloud *c = NULL;
        rs_result r = rs_pack_convert(m, &d, &c, NULL, &err);
        // points_region.ply carries region 7, which is not a region id: a clean error naming it.
        if (strstr(e->d_name, "region")) {
            RS_CHECK(r != RS_OK && strstr(err.msg, "region 7"), "%s: %s", e->d_name, r ? err.msg : "converted");
        } else if (RS_CHECK(r == RS_OK, "%s: %s", e->d_name, err.msg)) {
            uint32_t want = m->tri ? 500 : m->vertex_count;
            RS_CHECK(c->hdr.count <= want && c->hdr.count > 0, "%s: %u splats", e->d_name, c->hdr.count);
            void *bytes = NULL;
            size_t len = 0;
            rs_splat_cloud *back = NULL;
            RS_CHECK(rs_splat_save_memory(c, &bytes, &len, &err) == RS_OK &&
                         rs_splat_load_memory(bytes, len, &back, &err) == RS_OK,
                     "%s: the result does not round-trip: %s", e->d_name, err.msg);
            free(bytes);
            rs_splat_destroy(back);
            converted++;
        }
        rs_splat_destroy(c);
        rs_ply_destroy(m);
    }
    closedir(dir);
    RS_CHECK(converted >= 5, "only %d fixtures converted", converted);
}

static rs_ply_mesh *cloud_of(float (*p)[3], uint32_t n)
{
    rs_ply_mesh *m = calloc(1, sizeof *m);
    m->vertex_count = n;
    m->pos = p;
    return m;
}

static void test_degenerate_clouds_convert_without_crashing(void)
{
    float one[1][3] = {{1, 2, 3}};
    float same[300][3], line[300][3];
    for (int i = 0; i < 300; i++) {
        same[i][0] = 0.5f, same[i][1] = same[i][2] = 0;
        line[i][0] = (float)i, line[i][1] = line[i][2] = 0;
    }
    struct { float (*p)[3]; uint32_t n; const char *name; } cases[] = {
        {one, 1, "one point"}, {same, 300, "300 copies of a point"}, {line, 300, "collinear points"}, {line, 3, "three points"}};
    for (size_t k = 0; k < RS_COUNT_OF(cases); k++) {
        rs_ply_mesh *m = cloud_of(cases[k].p, cases[k].n);
        rs_splat_cloud *c = NULL;
        rs_error err = {0};
        rs_pack_report rep;
        rs_result r = rs_pack_convert(m, NULL, &c, &rep, &err);
        RS_CHECK(r == RS_OK, "%s: %s", cases[k].name, err.msg);
        if (r == RS_OK) RS_CHECK(c->hdr.count >= 1 && !rep.face.found, "%s: %u splats", cases[k].name, c->hdr.count);
        rs_splat_destroy(c);
        free(m);
    }
}

// NaN, inf and 1e300 normals in a PLY must be re-estimated, not clamped into a finite garbage direction
// (to_float once made every one of them (-0.58, -0.58, -0.58)).
static void test_nonfinite_input_normals_are_reestimated(void)
{
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ply_load("tests/fixtures/bad/ply_nonfinite_normals.ply", &m, &err) == RS_OK, "%s", err.msg);
    rs_splat_cloud *c = NULL;
    rs_pack_report rep;
    rs_result r = rs_pack_convert(m, NULL, &c, &rep, &err);
    rs_ply_destroy(m);
    RS_REQUIRE(r == RS_OK, "%s", err.msg);
    RS_CHECK(rep.normals_replaced == 80, "%u normals replaced, wanted the 80 bad ones", rep.normals_replaced);
    float worst = 1;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        rs_splat s;
        rs_splat_get(c, i, &s);
        // Points on a sphere around the origin: the normal is the (normalised) position.
        float len = sqrtf(dot3(s.pos, s.pos)), radial[3] = {s.pos[0] / len, s.pos[1] / len, s.pos[2] / len};
        worst = fminf(worst, dot3(s.normal, radial));
    }
    RS_CHECK(worst > 0.9f, "worst normal . radial = %.3f", worst);
    rs_splat_destroy(c);
}

// A model that is no face is framed whole: the "face height" the camera fits is its bounding sphere.
static void test_non_face_is_framed_by_its_bounding_sphere(void)
{
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ply_load("tests/fixtures/ply/mesh_two_cubes.ply", &m, &err) == RS_OK, "%s", err.msg);
    rs_pack_desc d = {.points = 5000, .all_components = true};
    rs_splat_cloud *c = NULL;
    rs_pack_report rep;
    rs_result r = rs_pack_convert(m, &d, &c, &rep, &err);
    rs_ply_destroy(m);
    RS_REQUIRE(r == RS_OK, "%s", err.msg);
    float diag = sqrtf(3.5f * 3.5f + 1 + 1);
    RS_CHECK(!rep.face.found, "a face in two cubes");
    RS_CHECK(fabsf(c->hdr.face_height - diag) < 0.02f * diag, "face height %g, bounding diameter %g",
             c->hdr.face_height, diag);
    RS_CHECK(fabsf(c->hdr.centre[0] - 1.75f) < 0.02f && fabsf(c->hdr.centre[1] - 0.5f) < 0.02f, "centre %g %g",
             c->hdr.centre[0], c->hdr.centre[1]);
    rs_splat_destroy(c);
}

static void test_convert_rejects_bad_inputs_with_clear_errors(void)
{
    float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {NAN, 0, 0}};
    rs_ply_mesh *m = cloud_of(p, 4);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_pack_convert(m, NULL, &c, NULL, &err) != RS_OK && strstr(err.msg, "vertex 3"), "NaN: %s", err.msg);
    m->vertex_count = 3;
    uint8_t px[3] = {1, 2, 3};
    rs_image tex = {1, 1, 3, px};
    rs_pack_desc d = {.texture = &tex};
    RS_CHECK(rs_pack_convert(m, &d, &c, NULL, &err) == RS_ERR_ARG && strstr(err.msg, "texture coordinates"),
             "texture without UVs: %s", err.msg);
    rs_pack_desc d2 = {.up = RS_PACK_AXIS_POS_Z, .forward = RS_PACK_AXIS_NEG_Z};
    RS_CHECK(rs_pack_convert(m, &d2, &c, NULL, &err) == RS_ERR_ARG && strstr(err.msg, "different axes"),
             "parallel axes: %s", err.msg);
    free(m);
}

static void test_convert_is_deterministic_and_decimates(void)
{
    const char *path = rs_test_shared_path("leeperrysmith/head_points_20k_ascii.ply");
    if (!path) {
        rs_test_skip("shared data leeperrysmith/ not present");
        return;
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ply_load(path, &m, &err) == RS_OK, "%s", err.msg);
    rs_pack_desc d = {.points = 12000, .min_lod = 1000};
    rs_splat_cloud *a = NULL, *b = NULL;
    rs_pack_report rep;
    RS_REQUIRE(rs_pack_convert(m, &d, &a, &rep, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_pack_convert(m, &d, &b, NULL, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(a->hdr.count == 12000, "decimated to %u, wanted 12000", a->hdr.count);
    RS_CHECK(memcmp(a->packed, b->packed, (size_t)a->hdr.count * sizeof *a->packed) == 0 &&
                 memcmp(&a->hdr, &b->hdr, sizeof a->hdr) == 0,
             "two conversions differ");
    RS_CHECK(rep.face.found && a->region_counts[RS_REGION_NOSE] > 0 && a->region_counts[RS_REGION_LIPS] > 0,
             "the sparse cloud still has a face with nose and lips");
    RS_CHECK(strstr(a->hdr.notes, "Lee Perry-Smith") != NULL, "PLY comments not carried into the notes");
    rs_splat_destroy(a);
    rs_splat_destroy(b);
    rs_ply_destroy(m);
}

// Issue 14's goal: the 600k scan as rouge-pack writes it (version 2, 12-bit normals, 6-bit radii, ambient
// occlusion in byte 15) in at most 8 bytes a splat, decoding to the very records converted.
static void test_600k_scan_packs_to_at_most_8_bytes_per_splat(void)
{
    const char *path = rs_test_shared_path("leeperrysmith/head_points_600k.ply");
    if (!path) {
        rs_test_skip("shared data leeperrysmith/ not present");
        return;
    }
    rs_ply_mesh *m = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_ply_load(path, &m, &err) == RS_OK, "%s", err.msg);
    rs_splat_cloud *c = NULL, *d = NULL;
    RS_REQUIRE(rs_pack_convert(m, &(rs_pack_desc){.mm_per_unit = 47}, &c, NULL, &err) == RS_OK, "%s", err.msg);
    rs_ply_destroy(m);
    // The normals' low bits hold the bent normals (the normal itself: the code with them cleared).
    bool lattice = (c->hdr.flags & RS_SPLAT_FLAG_BENT) != 0;
    for (uint32_t i = 0; i < c->hdr.count; i++) lattice &= (c->packed[i].w[1] & 0x00030000u) == 0;
    RS_CHECK(lattice, "no bent normals, or radii not on the %d-bit lattice", RS_PACK_RADIUS_BITS);
    void *data = NULL;
    size_t len = 0;
    RS_REQUIRE(rs_splat_save_memory(c, &data, &len, &err) == RS_OK, "%s", err.msg);
    double bps = (double)len / c->hdr.count;
    printf("# 600k scan: %zu bytes, %.3f bytes/splat (.rsf v2)\n", len, bps);
    RS_CHECK(bps <= 8.0, "%.3f bytes/splat, the goal is 8", bps);
    RS_CHECK(rs_splat_load_memory(data, len, &d, &err) == RS_OK &&
                 memcmp(c->packed, d->packed, (size_t)c->hdr.count * sizeof *c->packed) == 0,
             "the file does not decode to the converted records: %s", err.msg);
    free(data);
    rs_splat_destroy(c);
    rs_splat_destroy(d);
}

// ---- the bundled face ----

// The splat nearest the line of sight through (x, y) from the front (+z), i.e. on the visible surface.
static int front_splat(const rs_splat_cloud *c, float x, float y)
{
    int best = -1;
    float best_z = -INFINITY;
    for (uint32_t i = 0; i < c->hdr.count; i++) {
        if (fabsf(c->pos[i][0] - x) > 0.015f || fabsf(c->pos[i][1] - y) > 0.015f) continue;
        if (c->pos[i][2] > best_z) best_z = c->pos[i][2], best = (int)i;
    }
    return best;
}

static void test_bundled_face_regions_are_where_they_belong(void)
{
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_load("assets/face.rsf", &c, &err) == RS_OK, "%s", err.msg);
    const rs_splat_header *h = &c->hdr;
    RS_CHECK(h->count == 600000 && h->lod_count >= 5, "%u splats, %u LOD prefixes", h->count, h->lod_count);
    RS_CHECK(fabsf(h->mm_per_unit - 47.0f) < 1e-3f, "mm_per_unit %g", h->mm_per_unit);
    RS_CHECK(h->forward[2] > 0.999f && h->up[1] > 0.999f, "face frame: forward %g %g %g, up %g %g %g", h->forward[0],
             h->forward[1], h->forward[2], h->up[0], h->up[1], h->up[2]);
    // Vertex to menton is 4.75 units on this head (data README).
    RS_CHECK(fabsf(h->face_height - 4.75f) < 0.25f, "face height %g", h->face_height);
    // The mirror plane (through the centre, normal = side) passes through the nose tip at x = -0.088.
    RS_CHECK(fabsf(h->centre[0] + 0.088f) < 0.03f, "centre x %g", h->centre[0]);
    RS_CHECK(strstr(h->notes, "Lee Perry-Smith") && strstr(h->notes, "converted by rouge-pack"), "notes: %.200s", h->notes);

    // Landmarks on the visible surface (x, y in model units; README and a look at the preview render).
    struct { float x, y; rs_region want; const char *what; } probe[] = {
        {-0.088f, 1.097f, RS_REGION_NOSE, "nose tip (pronasale)"},
        {-0.088f, 1.50f, RS_REGION_NOSE, "nose bridge"},
        {-0.49f, 0.39f, RS_REGION_LIPS, "mouth corner, subject's right"},
        {0.33f, 0.39f, RS_REGION_LIPS, "mouth corner, subject's left"},
        {-0.088f, 0.55f, RS_REGION_LIPS, "upper lip"},
        {-0.088f, 0.35f, RS_REGION_LIPS, "lower lip"},
        {-0.088f, 2.80f, RS_REGION_FOREHEAD, "forehead"},
        {-0.85f, 0.90f, RS_REGION_CHEEK, "right cheek"},
        {0.70f, 0.90f, RS_REGION_CHEEK, "left cheek"},
        {-0.088f, -0.20f, RS_REGION_OTHER, "chin"},
        {-0.55f, 1.75f, RS_REGION_EYELID, "right eyelid"},
        {0.38f, 1.75f, RS_REGION_EYELID, "left eyelid"},
        {-0.30f, 1.64f, RS_REGION_EYELID, "right eye, inner corner"},
        {-0.74f, 2.02f, RS_REGION_BROW, "right brow"},
        {0.57f, 2.02f, RS_REGION_BROW, "left brow"},
        {-0.088f, 2.12f, RS_REGION_OTHER, "between the brows (glabella)"},
        {-0.74f, 2.41f, RS_REGION_FOREHEAD, "above the right brow"},
    };
    for (size_t k = 0; k < RS_COUNT_OF(probe); k++) {
        int i = front_splat(c, probe[k].x, probe[k].y);
        if (!RS_CHECK(i >= 0, "no splat at the %s", probe[k].what)) continue;
        rs_splat s;
        rs_splat_get(c, (uint32_t)i, &s);
        RS_CHECK(s.region == probe[k].want, "%s (%.2f %.2f %.2f) is %s, want %s", probe[k].what, s.pos[0], s.pos[1],
                 s.pos[2], h->regions[s.region].name, h->regions[probe[k].want].name);
    }
    // The back of the head is `other`: every splat facing backwards.
    uint32_t back_face = 0;
    for (uint32_t i = 0; i < h->count; i++) {
        rs_splat s;
        if (c->normal[i][2] > -0.5f) continue;
        rs_splat_get(c, i, &s);
        back_face += s.region != RS_REGION_OTHER;
    }
    RS_CHECK(back_face == 0, "%u back-facing splats are not `other`", back_face);
    // Sizes: lips and nose are small, cheeks and forehead larger; everything else dominates.
    double f[RS_REGION_STANDARD_COUNT];
    RS_CHECK(h->region_count == RS_REGION_STANDARD_COUNT && strcmp(h->regions[RS_REGION_EYELID].name, "eyelid") == 0 &&
                 strcmp(h->regions[RS_REGION_BROW].name, "brow") == 0,
             "%u regions", h->region_count);
    for (int r = 0; r < RS_REGION_STANDARD_COUNT; r++) f[r] = (double)c->region_counts[r] / h->count;
    RS_CHECK(f[RS_REGION_LIPS] > 0.002 && f[RS_REGION_LIPS] < f[RS_REGION_NOSE] && f[RS_REGION_NOSE] < f[RS_REGION_CHEEK] &&
                 f[RS_REGION_FOREHEAD] > 0.01 && f[RS_REGION_OTHER] > 0.8 && f[RS_REGION_EYELID] > 0.004 &&
                 f[RS_REGION_BROW] > 0.003 && f[RS_REGION_BROW] < f[RS_REGION_EYELID] &&
                 f[RS_REGION_EYELID] < f[RS_REGION_CHEEK],
             "region fractions other %.3f cheek %.3f nose %.3f forehead %.3f lips %.3f eyelid %.3f brow %.3f", f[0], f[1],
             f[2], f[3], f[4], f[5], f[6]);
    rs_splat_destroy(c);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_morton_interleaves_x_then_y_then_z);
    RS_RUN(test_rng_is_reproducible_and_in_range);
    RS_RUN(test_eigen_sym3_diagonalises);
    RS_RUN(test_knn_matches_brute_force);
    RS_RUN(test_knn_of_identical_points_is_fast_and_zero);
    RS_RUN(test_normals_on_sphere_point_outward);
    RS_RUN(test_nonfinite_input_normals_are_reestimated);
    RS_RUN(test_non_face_is_framed_by_its_bounding_sphere);
    RS_RUN(test_normals_on_demosthenes_agree_with_given);
    RS_RUN(test_radius_matches_grid_spacing);
    RS_RUN(test_ambient_occlusion_matches_analytic_cases);
    RS_RUN(test_ambient_occlusion_bounded_and_prefix_agrees);
    RS_RUN(test_bundled_face_occlusion_darkens_eyes_nostrils_chin_and_ears);
    RS_RUN(test_lod_prefix_is_spatially_uniform);
    RS_RUN(test_lod_prefix_covers_surface);
    RS_RUN(test_morton_order_keeps_levels_compact);
    RS_RUN(test_sample_mesh_is_area_uniform_and_reproducible);
    RS_RUN(test_sample_mesh_keeps_the_largest_component);
    RS_RUN(test_normal_map_follows_uv_tangents);
    RS_RUN(test_texture_t0_is_the_bottom_row);
    RS_RUN(test_region_map_colour_codes);
    RS_RUN(test_region_map_and_property_label_samples);
    RS_RUN(test_axis_parse);
    RS_RUN(test_every_ply_fixture_converts_or_fails_cleanly);
    RS_RUN(test_degenerate_clouds_convert_without_crashing);
    RS_RUN(test_convert_rejects_bad_inputs_with_clear_errors);
    RS_RUN(test_convert_is_deterministic_and_decimates);
    RS_RUN(test_600k_scan_packs_to_at_most_8_bytes_per_splat);
    RS_RUN(test_bundled_face_regions_are_where_they_belong);
    return rs_test_finish();
}
