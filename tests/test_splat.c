// test_splat.c — the splat cloud and the .rsf format: quantisation bounds per field, byte-exact round
// trips, the documented layout (docs/rsf.md), and a loader that rejects every malformed file cleanly.
#define _POSIX_C_SOURCE 200809L
#include "support/harness.h"
#include "splat/splat.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define PI 3.14159265358979323846

// ---- helpers ----

static const rs_splat_save_desc V1 = {.version = 1};

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;

static void rng_seed(uint64_t s) { rng_state = s * 0x9e3779b97f4a7c15ull + 1; }

// splitmix64: deterministic on every platform, unlike rand().
static uint64_t rng_u64(void)
{
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

static double rng_unit(void) { return (double)(rng_u64() >> 11) * (1.0 / 9007199254740992.0); }
static double rng_range(double lo, double hi) { return lo + (hi - lo) * rng_unit(); }

static void random_unit(float n[3])
{
    double z = rng_range(-1, 1), phi = rng_range(0, 2 * PI), s = sqrt(1 - z * z);
    n[0] = (float)(s * cos(phi));
    n[1] = (float)(s * sin(phi));
    n[2] = (float)z;
}

// A face-sized random cloud (units mm): positions in a 160 x 220 x 120 box, radii 0.2..1.5 mm.
static rs_splat *make_splats(uint32_t n, uint64_t seed)
{
    rng_seed(seed);
    rs_splat *s = calloc(n, sizeof *s);
    for (uint32_t i = 0; i < n; i++) {
        s[i].pos[0] = (float)rng_range(-80, 80);
        s[i].pos[1] = (float)rng_range(-100, 120);
        s[i].pos[2] = (float)rng_range(-20, 100);
        random_unit(s[i].normal);
        s[i].radius = (float)(0.2 * pow(7.5, rng_unit()));
        for (int c = 0; c < 3; c++) s[i].rgb[c] = (uint8_t)(rng_u64() & 0xff);
        s[i].region = (uint8_t)(rng_u64() % RS_REGION_BUILTIN_COUNT);
    }
    return s;
}

static uint32_t get_u32(const uint8_t *b, size_t off)
{
    return (uint32_t)b[off] | (uint32_t)b[off + 1] << 8 | (uint32_t)b[off + 2] << 16 | (uint32_t)b[off + 3] << 24;
}

static void put_u32(uint8_t *b, size_t off, uint32_t v)
{
    for (int k = 0; k < 4; k++) b[off + (size_t)k] = (uint8_t)(v >> (8 * k));
}

static void put_f32(uint8_t *b, size_t off, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    put_u32(b, off, u);
}

static float get_f32(const uint8_t *b, size_t off)
{
    uint32_t u = get_u32(b, off);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

// Rewrites the trailing CRC so that a deliberately broken field is what the loader meets.
static void fix_crc(uint8_t *b, size_t len) { put_u32(b, len - 4, rs_crc32(0, b, len - 4)); }

// The small reference file of the malformed-input tests, in version 1 (tests/test_rsf2.c covers version
// 2): 50 splats, LODs {50, 20, 5}, the default regions, 10 bytes of notes -> header_size 608, records at
// 608..1407, CRC at 1408, 1412 bytes in all.
enum { SMALL_N = 50, SMALL_HEADER = 608, SMALL_LEN = 1412 };

static uint8_t *small_file(size_t *len)
{
    rs_splat *s = make_splats(SMALL_N, 42);
    rs_splat_header h = {.mm_per_unit = 1.0f, .lod_count = 3, .lods = {SMALL_N, 20, 5}};
    strcpy(h.notes, "test notes");
    rs_error err = {0};
    rs_splat_cloud *c = NULL;
    void *data = NULL;
    if (rs_splat_create(s, SMALL_N, &h, &c, &err) != RS_OK ||
        rs_splat_save_memory_with(c, &V1, &data, len, &err) != RS_OK) {
        fprintf(stderr, "small_file: %s\n", err.msg);
        abort();
    }
    rs_splat_destroy(c);
    free(s);
    return data;
}

// Loads `b` expecting failure with `code` and a message containing each of up to two substrings; the
// output pointer must stay untouched.
static bool expect_reject(const uint8_t *b, size_t len, rs_result code, const char *want1, const char *want2)
{
    rs_splat_cloud sentinel_storage, *c = &sentinel_storage;
    rs_error err = {0};
    rs_result r = rs_splat_load_memory(b, len, &c, &err);
    if (r == RS_OK) rs_splat_destroy(c);
    if (!RS_CHECK(r != RS_OK, "loaded a malformed file (want \"%s\")", want1)) return false;
    if (!RS_CHECK(c == &sentinel_storage, "output changed on failure")) return false;
    if (!RS_CHECK(code == 0 || r == code, "got %s, want %s: %s", rs_result_name(r), rs_result_name(code), err.msg))
        return false;
    if (!RS_CHECK(strstr(err.msg, want1), "message \"%s\" lacks \"%s\"", err.msg, want1)) return false;
    return !want2 || RS_CHECK(strstr(err.msg, want2), "message \"%s\" lacks \"%s\"", err.msg, want2);
}

static double angle_deg(const float a[3], const float b[3])
{
    double cx = (double)a[1] * b[2] - (double)a[2] * b[1], cy = (double)a[2] * b[0] - (double)a[0] * b[2],
           cz = (double)a[0] * b[1] - (double)a[1] * b[0];
    double dot = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2];
    return atan2(sqrt(cx * cx + cy * cy + cz * cz), dot) * 180.0 / PI;
}

// ---- CRC and defaults ----

static uint32_t crc_bitwise(const uint8_t *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        c ^= p[i];
        for (int k = 0; k < 8; k++) c = (c & 1) ? (c >> 1) ^ 0xedb88320u : c >> 1;
    }
    return ~c;
}

static void test_crc32_matches_zlib_check_values(void)
{
    RS_CHECK(rs_crc32(0, "123456789", 9) == 0xcbf43926u, "crc32(\"123456789\") = %08x", rs_crc32(0, "123456789", 9));
    RS_CHECK(rs_crc32(0, "a", 1) == 0xe8b7be43u, "crc32(\"a\")");
    RS_CHECK(rs_crc32(0, "", 0) == 0, "crc32 of nothing");
    RS_CHECK(rs_crc32(rs_crc32(0, "1234", 4), "56789", 5) == 0xcbf43926u, "crc32 does not chain like zlib");
    // The 8-bytes-at-a-time path for large buffers must agree with the textbook bit loop at any length.
    size_t n = 20000;
    uint8_t *buf = malloc(n);
    rng_seed(7);
    for (size_t i = 0; i < n; i++) buf[i] = (uint8_t)rng_u64();
    size_t lens[] = {4095, 4096, 4097, 8191, 19993, 20000};
    for (size_t k = 0; k < RS_COUNT_OF(lens); k++)
        RS_CHECK(rs_crc32(0, buf + (k & 3), lens[k] - (k & 3)) == crc_bitwise(buf + (k & 3), lens[k] - (k & 3)),
                 "sliced crc differs at length %zu", lens[k]);
    free(buf);
}

static void test_default_regions_are_weyrich_midpoints(void)
{
    rs_splat_header h;
    memset(&h, 0xab, sizeof h);
    rs_splat_default_regions(&h);
    RS_REQUIRE(h.region_count == RS_REGION_BUILTIN_COUNT, "region_count %u", h.region_count);
    static const struct { const char *name; float m, rho; } want[] = {
        {"other", 0.265f, 0.2725f}, {"cheek", 0.275f, 0.235f}, {"nose", 0.235f, 0.305f},
        {"forehead", 0.265f, 0.265f}, {"lips", 0.285f, 0.285f},
    };
    for (int k = 0; k < RS_REGION_BUILTIN_COUNT; k++) {
        RS_CHECK(strcmp(h.regions[k].name, want[k].name) == 0, "region %d is %s", k, h.regions[k].name);
        RS_CHECK(h.regions[k].m == want[k].m && h.regions[k].rho_s == want[k].rho, "region %s: m %g rho_s %g",
                 want[k].name, h.regions[k].m, h.regions[k].rho_s);
    }
    // "other" is the mean of the four measured regions.
    RS_CHECK(fabsf(h.regions[0].m - (0.275f + 0.235f + 0.265f + 0.285f) / 4) < 1e-6f, "other.m is not the mean");
    RS_CHECK(fabsf(h.regions[0].rho_s - (0.235f + 0.305f + 0.265f + 0.285f) / 4) < 1e-6f,
             "other.rho_s is not the mean");
    static const rs_region_info zero;
    RS_CHECK(memcmp(&h.regions[RS_REGION_BUILTIN_COUNT], &zero, sizeof zero) == 0, "unused region slots not zeroed");
}

// ---- quantisation bounds ----

static void test_positions_round_trip_within_half_step(void)
{
    uint32_t n = 20000;
    rs_splat *s = make_splats(n, 1);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, NULL, &c, &err) == RS_OK, "%s", err.msg);
    const rs_splat_header *h = &c->hdr;
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) lo[a] = fminf(lo[a], s[i].pos[a]), hi[a] = fmaxf(hi[a], s[i].pos[a]);
    for (int a = 0; a < 3; a++)
        RS_CHECK(h->bbox_min[a] == lo[a] && h->bbox_max[a] == hi[a], "bbox axis %d is not the tight box", a);
    double worst = 0;
    for (uint32_t i = 0; i < n; i++) {
        rs_splat g;
        rs_splat_get(c, i, &g);
        for (int a = 0; a < 3; a++) {
            double step = ((double)h->bbox_max[a] - h->bbox_min[a]) / 65535.0;
            // Half a step, plus float rounding of the decode at this magnitude.
            double tol = 0.5 * step + 4 * FLT_EPSILON * fmax(fabs(h->bbox_min[a]), fabs(h->bbox_max[a]));
            double e = fabs((double)g.pos[a] - s[i].pos[a]);
            worst = fmax(worst, e / step);
            RS_CHECK(e <= tol, "splat %u axis %d: error %g > %g", i, a, e, tol);
            RS_CHECK(g.pos[a] == c->pos[i][a], "rs_splat_get and the decoded array disagree");
        }
    }
    printf("# position: worst error %.4f steps\n", worst);
    rs_splat_destroy(c);
    free(s);
}

static void test_normals_round_trip_within_0_003_degrees(void)
{
    enum { N = 100000 };
    float (*n)[3] = malloc(N * sizeof *n);
    rng_seed(3);
    int k = 0;
    // Poles and axis directions, where octahedral folding is exact or discontinuous.
    static const float axes[][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (size_t i = 0; i < RS_COUNT_OF(axes); i++, k++) memcpy(n[k], axes[i], sizeof n[k]);
    // Fold edges of the lower hemisphere (|u| + |v| = 1 after unfolding): the equator z = 0, the planes x = 0
    // and y = 0 with z < 0, and points within a hair of them on both sides.
    for (; k < 30000; k++) {
        double phi = rng_range(0, 2 * PI), eps = (k % 3 == 0) ? 0.0 : rng_range(-1e-4, 1e-4);
        double t = rng_range(-PI / 2, PI / 2);
        float *v = n[k];
        switch (k % 3) {
        case 0: v[0] = (float)cos(phi), v[1] = (float)sin(phi), v[2] = 0; break;
        case 1: v[0] = (float)(eps), v[1] = (float)sin(t), v[2] = (float)-fabs(cos(t)); break;
        default: v[0] = (float)sin(t), v[1] = (float)(eps), v[2] = (float)-fabs(cos(t)); break;
        }
        if (k % 5 == 4) v[2] = (float)rng_range(-1e-5, 1e-5);  // just either side of the equator
    }
    for (; k < N; k++) random_unit(n[k]);
    double worst = 0;
    for (k = 0; k < N; k++) {
        double len = sqrt((double)n[k][0] * n[k][0] + (double)n[k][1] * n[k][1] + (double)n[k][2] * n[k][2]);
        for (int a = 0; a < 3; a++) n[k][a] = (float)(n[k][a] / len);
        float d[3];
        rs_splat_decode_normal(rs_splat_encode_normal(n[k]), d);
        double e = angle_deg(n[k], d);
        worst = fmax(worst, e);
        // 16+16-bit octahedral with the precise encode: about 0.0025 deg at worst. 0.003 rather than a looser
        // 0.01 catches an encoder that stops picking the best neighbour (that one measured 0.0074).
        if (!RS_CHECK(e <= 0.003, "normal (%g %g %g): error %g deg", n[k][0], n[k][1], n[k][2], e)) break;
    }
    printf("# normal: worst error %.5f deg over %d normals\n", worst, N);
    RS_CHECK(worst > 0.0, "no error at all: the check cannot be measuring anything");
    free(n);
}

static void test_radius_round_trip_within_half_log_step(void)
{
    uint32_t n = 5000;
    rs_splat *s = make_splats(n, 5);
    s[10].radius = 0.0f;   // clamped up to radius_min
    s[11].radius = -3.0f;  // likewise
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, NULL, &c, &err) == RS_OK, "%s", err.msg);
    float lo = INFINITY, hi = 0;
    for (uint32_t i = 0; i < n; i++)
        if (s[i].radius > 0) lo = fminf(lo, s[i].radius), hi = fmaxf(hi, s[i].radius);
    RS_CHECK(c->hdr.radius_min == lo && c->hdr.radius_max == hi, "radius range %g..%g, want %g..%g",
             c->hdr.radius_min, c->hdr.radius_max, lo, hi);
    double half_step = 0.5 * log((double)hi / lo) / 255.0;
    for (uint32_t i = 0; i < n; i++) {
        float want = s[i].radius > 0 ? s[i].radius : lo;
        double e = fabs(log((double)c->radius[i] / want));
        RS_CHECK(e <= half_step * (1 + 1e-6) + 1e-7, "splat %u: radius %g -> %g, log error %g > %g", i, want,
                 c->radius[i], e, half_step);
    }
    RS_CHECK(c->radius[10] == lo && c->radius[11] == lo, "zero/negative radii not raised to radius_min");
    rs_splat_destroy(c);
    free(s);
}

static void test_colour_and_region_are_exact(void)
{
    uint32_t n = 3000;
    rs_splat *s = make_splats(n, 9);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, NULL, &c, &err) == RS_OK, "%s", err.msg);
    uint32_t counts[RS_SPLAT_MAX_REGIONS] = {0};
    for (uint32_t i = 0; i < n; i++) {
        rs_splat g;
        rs_splat_get(c, i, &g);
        RS_CHECK(memcmp(g.rgb, s[i].rgb, 3) == 0 && g.region == s[i].region, "splat %u colour/region changed", i);
        RS_CHECK((c->packed[i].w[3] >> 24) == 0, "splat %u: record flags not 0", i);
        counts[s[i].region]++;
    }
    RS_CHECK(memcmp(counts, c->region_counts, sizeof counts) == 0, "region_counts wrong");
    rs_splat_destroy(c);
    free(s);
}

static void test_degenerate_clouds_get_a_valid_frame(void)
{
    rs_splat one = {.pos = {3, 4, 5}, .normal = {0, 0, 2}, .radius = 0.5f};
    rs_splat flat[3] = {
        {.pos = {0, 0, 0}, .normal = {0, 0, 1}, .radius = 1},
        {.pos = {10, 0, 0}, .normal = {0, 0, 1}, .radius = 1},
        {.pos = {0, 10, 0}, .normal = {0, 0, 1}, .radius = 1},
    };
    struct { const rs_splat *s; uint32_t n; } cases[] = {{&one, 1}, {flat, 3}};
    for (size_t k = 0; k < RS_COUNT_OF(cases); k++) {
        rs_splat_cloud *c = NULL, *d = NULL;
        rs_error err = {0};
        RS_REQUIRE(rs_splat_create(cases[k].s, cases[k].n, NULL, &c, &err) == RS_OK, "case %zu: %s", k, err.msg);
        for (int a = 0; a < 3; a++) RS_CHECK(c->hdr.bbox_max[a] > c->hdr.bbox_min[a], "case %zu: flat axis %d", k, a);
        RS_CHECK(c->hdr.radius_max > c->hdr.radius_min, "case %zu: empty radius range", k);
        for (uint32_t i = 0; i < cases[k].n; i++) {
            RS_CHECK(c->radius[i] == cases[k].s[i].radius, "case %zu: a single radius must decode exactly", k);
            RS_CHECK(angle_deg(c->normal[i], (float[3]){0, 0, 1}) < 1e-3, "case %zu: normal not normalised", k);
            for (int a = 0; a < 3; a++)
                RS_CHECK(fabsf(c->pos[i][a] - cases[k].s[i].pos[a]) < 1e-3f, "case %zu: position moved", k);
        }
        void *data;
        size_t len;
        RS_REQUIRE(rs_splat_save_memory(c, &data, &len, &err) == RS_OK, "%s", err.msg);
        RS_CHECK(rs_splat_load_memory(data, len, &d, &err) == RS_OK, "case %zu: reload: %s", k, err.msg);
        rs_splat_destroy(d);
        free(data);
        rs_splat_destroy(c);
    }
}

// ---- rs_splat_create input checks ----

static void expect_create_fails(const rs_splat *s, uint32_t n, const rs_splat_header *h, rs_result code,
                                const char *want)
{
    rs_splat_cloud sentinel, *c = &sentinel;
    rs_error err = {0};
    rs_result r = rs_splat_create(s, n, h, &c, &err);
    if (r == RS_OK) rs_splat_destroy(c);
    RS_CHECK(r == code, "want %s for \"%s\", got %s: %s", rs_result_name(code), want, rs_result_name(r), err.msg);
    RS_CHECK(c == &sentinel, "output changed on failure");
    RS_CHECK(strstr(err.msg, want), "message \"%s\" lacks \"%s\"", err.msg, want);
}

static void test_create_rejects_bad_splats_naming_the_index(void)
{
    rs_splat *good = make_splats(20, 11), s[20];
    memcpy(s, good, sizeof s);
    s[7].pos[1] = NAN;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "splat 7: position[1] nan");
    memcpy(s, good, sizeof s);
    s[3].normal[2] = INFINITY;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "splat 3: normal[2] inf");
    memcpy(s, good, sizeof s);
    s[4].normal[0] = s[4].normal[1] = s[4].normal[2] = 0;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "splat 4: normal is zero");
    memcpy(s, good, sizeof s);
    s[12].radius = NAN;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "splat 12: radius nan");
    memcpy(s, good, sizeof s);
    s[2].region = RS_REGION_BUILTIN_COUNT;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "splat 2: region 5");
    memcpy(s, good, sizeof s);
    for (int i = 0; i < 20; i++) s[i].radius = 0;
    expect_create_fails(s, 20, NULL, RS_ERR_FORMAT, "no splat has a radius > 0");
    expect_create_fails(good, 0, NULL, RS_ERR_ARG, "count");
    // Rejected before any splat is read, so one splat stands in for 64M + 1.
    expect_create_fails(good, RS_SPLAT_MAX_COUNT + 1, NULL, RS_ERR_LIMIT, "count");
    free(good);
}

static void test_create_rejects_bad_header_tables(void)
{
    rs_splat *s = make_splats(20, 12);
    rs_splat_header h = {.lod_count = 3, .lods = {20, 20, 5}};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "lods[1]");
    h = (rs_splat_header){.lod_count = 2, .lods = {19, 5}};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "lods[0]");
    h = (rs_splat_header){.lod_count = 3, .lods = {20, 5, 0}};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "lods[2]");
    h = (rs_splat_header){.lod_count = RS_SPLAT_MAX_LODS + 1};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "lod_count");
    h = (rs_splat_header){.region_count = 3};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "region_count");
    h = (rs_splat_header){0};
    rs_splat_default_regions(&h);
    h.regions[2].m = 0;
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "regions[2].m");
    rs_splat_default_regions(&h);
    memset(h.regions[1].name, 'x', sizeof h.regions[1].name);
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "regions[1].name");
    h = (rs_splat_header){0};
    strcpy(h.notes, "caf\xc3");  // UTF-8 cut in the middle of a character
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "notes");
    h = (rs_splat_header){.flags = 2};  // bit 0 is RS_SPLAT_FLAG_AO; bit 1 is unknown
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "flags");
    h = (rs_splat_header){.forward = {0, 0, 2}, .up = {0, 0, -1}};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "up");
    h = (rs_splat_header){.mm_per_unit = -1};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "mm_per_unit");
    h = (rs_splat_header){.centre = {0, NAN, 0}};
    expect_create_fails(s, 20, &h, RS_ERR_ARG, "centre[1]");
    free(s);
}

static void test_create_fills_zero_defaults_and_orthonormal_frame(void)
{
    rs_splat *s = make_splats(100, 13);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, 100, NULL, &c, &err) == RS_OK, "%s", err.msg);
    const rs_splat_header *h = &c->hdr;
    RS_CHECK(h->count == 100 && h->lod_count == 1 && h->lods[0] == 100, "default LOD table is not {count}");
    RS_CHECK(h->region_count == RS_REGION_BUILTIN_COUNT && strcmp(h->regions[RS_REGION_LIPS].name, "lips") == 0,
             "default regions missing");
    RS_CHECK(h->mm_per_unit == 1.0f, "mm_per_unit default %g", h->mm_per_unit);
    RS_CHECK(h->forward[2] == 1 && h->up[1] == 1, "default frame is not forward +z, up +y");
    RS_CHECK(h->face_height == h->bbox_max[1] - h->bbox_min[1], "face_height default is not the bbox height");
    RS_CHECK(h->flags == 0 && h->notes[0] == 0, "flags/notes");
    rs_splat_destroy(c);

    rs_splat_header in = {.forward = {0, 0, 3}, .up = {0, 2, 1}, .face_height = 200, .mm_per_unit = 47};
    strcpy(in.notes, "Infinite, 3D Head Scan by Lee Perry-Smith \xe2\x80\x94 CC BY 3.0");
    RS_REQUIRE(rs_splat_create(s, 100, &in, &c, &err) == RS_OK, "%s", err.msg);
    h = &c->hdr;
    RS_CHECK(h->forward[2] == 1 && h->forward[0] == 0 && h->forward[1] == 0, "forward not normalised");
    RS_CHECK(h->up[0] == 0 && h->up[1] == 1 && fabsf(h->up[2]) < 1e-7f, "up not made perpendicular to forward");
    RS_CHECK(h->face_height == 200 && h->mm_per_unit == 47, "given values not kept");
    RS_CHECK(strcmp(h->notes, in.notes) == 0, "notes not carried");
    rs_splat_destroy(c);
    free(s);
}

// ---- save / load ----

static void test_save_load_round_trip_is_byte_identical(void)
{
    uint32_t n = 500;
    rs_splat *s = make_splats(n, 21);
    rs_splat_header h = {.mm_per_unit = 46.8f, .centre = {1, 2, 3}, .face_height = 180, .lod_count = 4,
                         .lods = {500, 200, 60, 7}};
    rs_splat_default_regions(&h);
    h.regions[5] = (rs_region_info){"eyelid", 0.3f, 0.2f};
    h.region_count = 6;
    s[33].region = 5;
    strcpy(h.notes, "Attribution: sc\xc3\xa9ne (CC BY 3.0)\nline 2");
    rs_splat_cloud *c = NULL, *d = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, &h, &c, &err) == RS_OK, "%s", err.msg);
    void *a = NULL, *b = NULL;
    size_t alen = 0, blen = 0;
    RS_REQUIRE(rs_splat_save_memory(c, &a, &alen, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_splat_load_memory(a, alen, &d, &err) == RS_OK, "%s", err.msg);
    RS_REQUIRE(rs_splat_save_memory(d, &b, &blen, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(alen == blen && memcmp(a, b, alen) == 0, "save(load(save(c))) differs from save(c)");
    RS_CHECK(memcmp(&c->hdr, &d->hdr, sizeof c->hdr) == 0, "header changed through the file");
    RS_CHECK(memcmp(c->packed, d->packed, n * sizeof *c->packed) == 0, "records changed");
    RS_CHECK(memcmp(c->pos, d->pos, n * sizeof *c->pos) == 0 &&
                 memcmp(c->normal, d->normal, n * sizeof *c->normal) == 0 &&
                 memcmp(c->radius, d->radius, n * sizeof *c->radius) == 0,
             "decoded arrays differ after load");
    RS_CHECK(memcmp(c->region_counts, d->region_counts, sizeof c->region_counts) == 0 && d->region_counts[5] == 1,
             "region_counts differ");
    free(a);
    free(b);
    rs_splat_destroy(c);
    rs_splat_destroy(d);
    free(s);
}

static void test_save_to_file_is_atomic_and_loads(void)
{
    uint32_t n = 64;
    rs_splat *s = make_splats(n, 22);
    rs_splat_cloud *c = NULL, *d = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, NULL, &c, &err) == RS_OK, "%s", err.msg);
    char path[1024], tmp[1100];
    snprintf(path, sizeof path, "%s/test_splat_save.rsf", rs_test_out_dir());
    snprintf(tmp, sizeof tmp, "%s.tmp.%ld", path, (long)getpid());
    RS_REQUIRE(rs_splat_save(c, path, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(access(tmp, F_OK) != 0, "temporary file left behind");
    RS_REQUIRE(rs_splat_load(path, &d, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(memcmp(c->packed, d->packed, n * sizeof *c->packed) == 0, "records differ after file round trip");
    // Saving over an existing file replaces it.
    RS_CHECK(rs_splat_save(d, path, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(rs_splat_save(c, "/nonexistent-dir/x.rsf", &err) == RS_ERR_IO, "unwritable path not reported");
    unlink(path);
    rs_splat_destroy(c);
    rs_splat_destroy(d);
    free(s);
}

static void test_file_layout_matches_docs(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_load_memory(b, len, &c, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(len == SMALL_LEN, "file is %zu bytes, docs/rsf.md says %d", len, SMALL_LEN);
    RS_CHECK(memcmp(b, "RSF\0", 4) == 0, "magic");
    RS_CHECK(get_u32(b, 4) == 1 && get_u32(b, 8) == SMALL_HEADER && get_u32(b, 12) == 0, "version/header_size/flags");
    RS_CHECK(get_u32(b, 16) == SMALL_N, "count at byte 16");
    RS_CHECK(get_f32(b, 20) == c->hdr.bbox_min[0] && get_f32(b, 40) == c->hdr.bbox_max[2], "bbox at 20..43");
    RS_CHECK(get_f32(b, 44) == c->hdr.radius_min && get_f32(b, 48) == c->hdr.radius_max, "radius range at 44/48");
    RS_CHECK(get_f32(b, 52) == 1.0f && get_f32(b, 76) == 1.0f && get_f32(b, 84) == 1.0f, "mm_per_unit/forward/up");
    RS_CHECK(get_f32(b, 92) == c->hdr.face_height, "face_height at 92");
    RS_CHECK(get_u32(b, 96) == 3 && get_u32(b, 100) == 50 && get_u32(b, 104) == 20 && get_u32(b, 108) == 5 &&
                 get_u32(b, 112) == 0,
             "LOD table at 96..195");
    RS_CHECK(get_u32(b, 196) == 5 && memcmp(b + 200, "other", 6) == 0 && memcmp(b + 200 + 4 * 24, "lips", 5) == 0 &&
                 get_f32(b, 200 + 24 + 16) == 0.275f && get_f32(b, 200 + 24 + 20) == 0.235f,
             "region table at 196..583");
    RS_CHECK(get_u32(b, 584) == 10 && memcmp(b + 588, "test notes", 10) == 0, "notes at 584/588");
    for (uint32_t i = 0; i < SMALL_N; i++)
        for (int k = 0; k < 4; k++)
            RS_CHECK(get_u32(b, SMALL_HEADER + 16 * i + 4 * (uint32_t)k) == c->packed[i].w[k], "record %u word %d", i,
                     k);
    RS_CHECK(get_u32(b, len - 4) == rs_crc32(0, b, len - 4), "CRC of everything before it");
    rs_splat_destroy(c);
    free(b);
}

static void test_encoder_and_layout_match_the_v1_fixture(void)
{
    // Four splats chosen to land on exact codes (bbox corners, radius_min/max, axis normals): any change to
    // the encoding or the byte layout shows up as a difference from the committed file.
    rs_splat s[4] = {
        {.pos = {-10, -20, -30}, .normal = {0, 0, 1}, .radius = 0.25f, .rgb = {255, 128, 0}, .region = 0},
        {.pos = {10, 20, 30}, .normal = {0, 0, -1}, .radius = 1.0f, .rgb = {1, 2, 3}, .region = 4},
        {.pos = {0, 0, 0}, .normal = {1, 0, 0}, .radius = 0.6f, .rgb = {10, 20, 30}, .region = 1},
        {.pos = {10, -20, 30}, .normal = {0, -1, 0}, .radius = 0.25f, .rgb = {0, 0, 0}, .region = 3},
    };
    rs_splat_header h = {.mm_per_unit = 47.0f, .centre = {0, 1, 2}, .lod_count = 2, .lods = {4, 2}};
    strcpy(h.notes, "rouge test fixture, no scan data");
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, 4, &h, &c, &err) == RS_OK, "%s", err.msg);
    void *data;
    size_t len;
    RS_REQUIRE(rs_splat_save_memory_with(c, &V1, &data, &len, &err) == RS_OK, "%s", err.msg);
    const char *path = "tests/fixtures/rsf/tiny_v1.rsf";
    const char *upd = getenv("RS_UPDATE_GOLDEN");
    if (upd && *upd == '1') RS_CHECK(rs_file_write_atomic(path, data, len, &err) == RS_OK, "%s", err.msg);
    void *fix = NULL;
    size_t flen = 0;
    if (RS_CHECK(rs_file_read_all(path, 1 << 20, &fix, &flen, &err) == RS_OK, "%s (RS_UPDATE_GOLDEN=1 writes it)",
                 err.msg)) {
        RS_CHECK(flen == len && memcmp(fix, data, len) == 0, "encoder output differs from %s", path);
        rs_splat_cloud *d = NULL;
        RS_CHECK(rs_splat_load(path, &d, &err) == RS_OK, "%s", err.msg);
        if (d) {
            // Corners and axis normals decode exactly.
            RS_CHECK(d->pos[0][0] == -10 && d->pos[0][1] == -20 && d->pos[0][2] == -30, "min corner");
            RS_CHECK(fabsf(d->pos[1][1] - 20) < 1e-5f && fabsf(d->pos[3][2] - 30) < 1e-5f, "max corner");
            RS_CHECK(d->normal[0][2] == 1 && d->normal[1][2] == -1 && d->normal[2][0] == 1 && d->normal[3][1] == -1,
                     "axis normals");
            RS_CHECK(d->radius[0] == 0.25f && d->radius[1] == 1.0f && fabsf(d->radius[2] - 0.6f) < 0.6f * 0.003f,
                     "radii");
            RS_CHECK(d->region_counts[0] == 1 && d->region_counts[1] == 1 && d->region_counts[3] == 1 &&
                         d->region_counts[4] == 1,
                     "region counts");
        }
        rs_splat_destroy(d);
    }
    free(fix);
    free(data);
    rs_splat_destroy(c);
}

static void test_hostile_fixture_files_are_rejected(void)
{
    static const struct { const char *file, *want, *byte; } cases[] = {
        {"bad_truncated.rsf", "header: file is 100 bytes", "(byte 100)"},
        {"bad_crc.rsf", "crc: stored", "(byte 688)"},
        {"bad_region.rsf", "splat 1: region 9", "(byte 647)"},
        {"bad_huge_count.rsf", "count: 4294967295 splats", "(byte 16)"},
    };
    for (size_t k = 0; k < RS_COUNT_OF(cases); k++) {
        char path[256];
        snprintf(path, sizeof path, "tests/fixtures/rsf/%s", cases[k].file);
        rs_splat_cloud *c = NULL;
        rs_error err = {0};
        rs_result r = rs_splat_load(path, &c, &err);
        rs_splat_destroy(c);
        RS_CHECK(r == RS_ERR_FORMAT || r == RS_ERR_LIMIT, "%s: got %s: %s", path, rs_result_name(r), err.msg);
        RS_CHECK(strstr(err.msg, path) && strstr(err.msg, cases[k].want) && strstr(err.msg, cases[k].byte),
                 "%s: message \"%s\" lacks \"%s\" %s", path, err.msg, cases[k].want, cases[k].byte);
    }
}

// ---- malformed files ----

static void test_every_truncation_is_rejected(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    for (size_t cut = 0; cut < len; cut++) {
        // A copy of exactly `cut` bytes, so ASan sees any read past the end.
        uint8_t *p = malloc(cut ? cut : 1);
        memcpy(p, b, cut);
        bool ok = expect_reject(p, cut, RS_ERR_FORMAT, "(memory): ", "(byte ");
        free(p);
        if (!ok) {
            RS_CHECK(false, "at cut %zu", cut);
            break;
        }
    }
    free(b);
}

static void test_bad_magic_is_rejected(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    b[1] = 'X';
    expect_reject(b, len, RS_ERR_FORMAT, "magic: not an .rsf file", "(byte 0)");
    const char *ply = "ply\nformat ascii 1.0\n";
    expect_reject((const uint8_t *)ply, strlen(ply), RS_ERR_FORMAT, "magic", NULL);
    free(b);
}

static void test_unsupported_version_is_named(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    put_u32(b, 4, 3);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "unsupported version 3 (this build reads versions 1 and 2)", "(byte 4)");
    put_u32(b, 4, 0);
    expect_reject(b, len, RS_ERR_FORMAT, "unsupported version 0", NULL);
    free(b);
}

static void test_flipped_payload_byte_fails_crc(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    uint32_t stored = get_u32(b, len - 4);
    b[SMALL_HEADER + 16 * 7 + 2] ^= 0x10;
    char want[64];
    snprintf(want, sizeof want, "crc: stored 0x%08x, computed 0x%08x", stored, rs_crc32(0, b, len - 4));
    expect_reject(b, len, RS_ERR_FORMAT, want, "(byte 1408)");
    b[SMALL_HEADER + 16 * 7 + 2] ^= 0x10;
    b[len - 1] ^= 1;  // the CRC itself
    expect_reject(b, len, RS_ERR_FORMAT, "crc: stored", NULL);
    free(b);
}

static void test_count_larger_than_file_is_rejected_before_allocating(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    put_u32(b, 16, SMALL_N + 1);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "count: 51 splats need a 1428-byte file, this one has 1412", "(byte 16)");
    // Just under the limit: would be a 1 GiB allocation if believed.
    put_u32(b, 16, RS_SPLAT_MAX_COUNT);
    expect_reject(b, len, RS_ERR_FORMAT, "count:", "(byte 16)");
    put_u32(b, 16, 0);
    expect_reject(b, len, RS_ERR_FORMAT, "count: 0", "(byte 16)");
    put_u32(b, 16, SMALL_N - 1);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "unexpected bytes after the CRC", NULL);
    free(b);
}

static void test_count_times_16_overflow_is_rejected(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    put_u32(b, 16, 0xffffffffu);
    expect_reject(b, len, RS_ERR_LIMIT, "count: 4294967295 splats", "(byte 16)");
    put_u32(b, 16, 0x10000001u);  // count * 16 wraps to 16 in 32 bits
    expect_reject(b, len, RS_ERR_LIMIT, "count:", "(byte 16)");
    free(b);
}

// One header field set to a bad value (CRC fixed so the field check is what fails).
typedef struct field_case {
    size_t off;
    bool is_float;
    float f;
    uint32_t u;
    const char *want;
    const char *byte;
} field_case;

static void run_field_cases(const field_case *cases, size_t n)
{
    size_t len;
    uint8_t *b = small_file(&len);
    uint8_t *p = malloc(len);
    for (size_t k = 0; k < n; k++) {
        memcpy(p, b, len);
        if (cases[k].is_float) put_f32(p, cases[k].off, cases[k].f);
        else put_u32(p, cases[k].off, cases[k].u);
        fix_crc(p, len);
        if (!expect_reject(p, len, 0, cases[k].want, cases[k].byte)) {
            RS_CHECK(false, "case %zu", k);
            break;
        }
    }
    free(p);
    free(b);
}

static void test_non_finite_bbox_is_rejected(void)
{
    field_case cases[] = {
        {36, true, NAN, 0, "bbox_max[1]: nan is not finite", "(byte 36)"},
        {20, true, -INFINITY, 0, "bbox_min[0]: -inf is not finite", "(byte 20)"},
        {28, true, 1e30f, 0, "bbox_max[2]", "(byte 40)"},  // min above max
        {32, true, -3e38f, 0, "bbox_max[0]", "(byte 32)"},
    };
    run_field_cases(cases, RS_COUNT_OF(cases));
    // An extent that overflows a float.
    size_t len;
    uint8_t *b = small_file(&len);
    put_f32(b, 20, -3e38f);
    put_f32(b, 32, 3e38f);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "overflows a float", "(byte 32)");
    free(b);
}

static void test_zero_or_negative_radius_range_is_rejected(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    float rmin = get_f32(b, 44);
    free(b);
    field_case cases[] = {
        {44, true, 0.0f, 0, "radius_min: 0", "(byte 44)"},
        {44, true, -1.0f, 0, "radius_min: -1", "(byte 44)"},
        {44, true, NAN, 0, "radius_min", "(byte 44)"},
        {48, true, rmin, 0, "radius_max", "(byte 48)"},          // empty range
        {48, true, rmin * 0.5f, 0, "radius_max", "(byte 48)"},   // negative range
        {48, true, rmin * 2e6f, 0, "more than", "(byte 48)"},   // too wide for 8 bits
    };
    run_field_cases(cases, RS_COUNT_OF(cases));
}

static void test_lod_table_must_descend(void)
{
    field_case cases[] = {
        {108, false, 0, 30, "lods[2]: 30 is not below lods[1] = 20", "(byte 108)"},
        {104, false, 0, 50, "lods[1]: 50 is not below", "(byte 104)"},
        {100, false, 0, 49, "lods[0]: 49, must equal count 50", "(byte 100)"},
        {108, false, 0, 0, "lods[2]: 0", "(byte 108)"},
        {112, false, 0, 3, "lods[3]: 3 in an unused slot", "(byte 112)"},
        {96, false, 0, 0, "lod_count: 0", "(byte 96)"},
        {96, false, 0, 25, "lod_count: 25", "(byte 96)"},
    };
    run_field_cases(cases, RS_COUNT_OF(cases));
}

static void test_other_header_fields_are_checked(void)
{
    field_case cases[] = {
        {8, false, 0, 624, "header_size: 624, expected 608", "(byte 8)"},
        {12, false, 0, 2, "flags: 0x00000002", "(byte 12)"},
        {12, false, 0, 4, "bent normals without ambient occlusion", "(byte 12)"},
        {52, true, 0.0f, 0, "mm_per_unit: 0", "(byte 52)"},
        {52, true, INFINITY, 0, "mm_per_unit: inf", "(byte 52)"},
        {60, true, NAN, 0, "centre[1]: nan", "(byte 60)"},
        {76, true, 0.0f, 0, "forward: length 0", "(byte 68)"},
        {72, true, 1.0f, 0, "forward: length", "(byte 68)"},
        {80, true, NAN, 0, "up[0]", "(byte 80)"},
        {84, true, 0.0f, 0, "up: length 0", "(byte 80)"},
        {92, true, -5.0f, 0, "face_height: -5", "(byte 92)"},
        {196, false, 0, 17, "region_count: 17", "(byte 196)"},
        {196, false, 0, 4, "region_count: 4", "(byte 196)"},
        {200 + 24 + 16, true, NAN, 0, "regions[1].m: nan", "(byte 240)"},
        {200 + 48 + 20, true, -0.1f, 0, "regions[2].rho_s: -0.1", "(byte 268)"},
        {200, false, 0, 0, "regions[0].name: empty", "(byte 200)"},
        {200 + 24 + 8, false, 0, 0x7a, "regions[1].name: bytes after the NUL must be 0", "(byte 232)"},
        {200 + 5 * 24 + 16, true, 0.3f, 0, "regions[5]: unused slot", "(byte 320)"},
        {200 + 2 * 24, false, 0, 0x00657301u, "regions[2].name: byte 0x01", "(byte 248)"},
    };
    run_field_cases(cases, RS_COUNT_OF(cases));
    // A name with no NUL in its 16 bytes.
    size_t len;
    uint8_t *b = small_file(&len);
    memset(b + 200 + 72, 'a', 16);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "regions[3].name: not NUL-terminated", "(byte 272)");
    free(b);
}

static void test_record_region_and_flags_are_checked_naming_the_splat(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    b[SMALL_HEADER + 16 * 17 + 7] = 9;  // region byte of splat 17
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "splat 17: region 9 is not in the region table (5 regions)", "(byte 887)");
    b[SMALL_HEADER + 16 * 17 + 7] = 4;
    b[SMALL_HEADER + 16 * 49 + 15] = 0x80;  // flags byte of the last splat
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "splat 49: byte 15 is 0x80 but the header has no ambient occlusion",
                  "(byte 1407)");
    free(b);
}

static void test_notes_length_and_bytes_are_checked(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    put_u32(b, 584, 5000);
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "notes_len: 5000 bytes of notes run past the end", "(byte 584)");
    put_u32(b, 584, 0xffffffffu);
    expect_reject(b, len, RS_ERR_FORMAT, "notes_len: 4294967295 bytes, at most 8191", "(byte 584)");
    put_u32(b, 584, RS_SPLAT_MAX_NOTES);
    expect_reject(b, len, RS_ERR_FORMAT, "notes_len: 8192", "(byte 584)");
    put_u32(b, 584, 30);  // fits in the file, but header_size no longer matches
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "header_size: 608, expected 624 for 30 bytes of notes", "(byte 8)");
    free(b);
    b = small_file(&len);
    b[588 + 4] = 0;
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "notes: NUL byte inside the notes", "(byte 592)");
    b[588 + 4] = 0xff;
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "notes: invalid UTF-8 at notes byte 4", "(byte 592)");
    b[588 + 4] = ' ';
    b[600] = 1;  // padding between the notes and the records
    fix_crc(b, len);
    expect_reject(b, len, RS_ERR_FORMAT, "padding: must be 0", "(byte 600)");
    free(b);
}

// Random damage, with and without a fixed-up CRC: never a crash, and anything accepted is canonical
// (saving it again gives back the same bytes).
static void test_random_damage_never_crashes_and_accepted_files_are_canonical(void)
{
    size_t len;
    uint8_t *b = small_file(&len);
    uint8_t *p = malloc(len);
    rng_seed(99);
    int accepted = 0;
    for (int trial = 0; trial < 3000; trial++) {
        memcpy(p, b, len);
        int flips = 1 + (int)(rng_u64() % 3);
        for (int f = 0; f < flips; f++) {
            // Mostly the header, where the checks are.
            size_t at = (rng_u64() & 1) ? rng_u64() % SMALL_HEADER : rng_u64() % len;
            p[at] ^= (uint8_t)(1u << (rng_u64() % 8));
        }
        if (trial & 1) fix_crc(p, len);
        rs_splat_cloud *c = NULL;
        rs_error err = {0};
        if (rs_splat_load_memory(p, len, &c, &err) != RS_OK) {
            if (!RS_CHECK(strstr(err.msg, "(byte "), "error without a byte offset: %s", err.msg)) break;
            continue;
        }
        accepted++;
        void *q = NULL;
        size_t qlen = 0;
        bool same = rs_splat_save_memory_with(c, &V1, &q, &qlen, &err) == RS_OK && qlen == len && memcmp(q, p, len) == 0;
        free(q);
        rs_splat_destroy(c);
        if (!RS_CHECK(same, "trial %d: an accepted file does not re-save to the same bytes", trial)) break;
    }
    printf("# random damage: %d of 3000 damaged files accepted (payload colour/position bits)\n", accepted);
    free(p);
    free(b);
}

static void test_directory_and_dev_null_give_clear_errors(void)
{
    rs_splat_cloud sentinel, *c = &sentinel;
    rs_error err = {0};
    RS_CHECK(rs_splat_load("tests", &c, &err) == RS_ERR_IO && strstr(err.msg, "tests: not a regular file"),
             "directory: %s", err.msg);
    RS_CHECK(rs_splat_load("/dev/null", &c, &err) == RS_ERR_IO && strstr(err.msg, "/dev/null: not a regular file"),
             "/dev/null: %s", err.msg);
    RS_CHECK(rs_splat_load("tests/no-such-file.rsf", &c, &err) == RS_ERR_IO && strstr(err.msg, "cannot open"),
             "missing file: %s", err.msg);
    char path[1024];
    snprintf(path, sizeof path, "%s/test_splat_empty.rsf", rs_test_out_dir());
    RS_REQUIRE(rs_file_write_atomic(path, "", 0, &err) == RS_OK, "%s", err.msg);
    RS_CHECK(rs_splat_load(path, &c, &err) == RS_ERR_FORMAT && strstr(err.msg, path) && strstr(err.msg, "magic"),
             "empty file: %s", err.msg);
    unlink(path);
    RS_CHECK(c == &sentinel, "output changed on failure");
}

// ---- LOD queries ----

static void test_lod_count_picks_largest_fitting_prefix(void)
{
    uint32_t n = 1000;
    rs_splat *s = make_splats(n, 31);
    rs_splat_header h = {.lod_count = 4, .lods = {1000, 400, 100, 25}};
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_REQUIRE(rs_splat_create(s, n, &h, &c, &err) == RS_OK, "%s", err.msg);
    static const uint32_t ask[][2] = {{5000, 1000}, {1000, 1000}, {999, 400}, {400, 400}, {399, 100},
                                      {100, 100}, {99, 25}, {25, 25}, {10, 25}, {0, 25}};
    for (size_t k = 0; k < RS_COUNT_OF(ask); k++)
        RS_CHECK(rs_splat_lod_count(c, ask[k][0]) == ask[k][1], "lod_count(%u) = %u, want %u", ask[k][0],
                 rs_splat_lod_count(c, ask[k][0]), ask[k][1]);
    RS_CHECK(rs_splat_lod_radius_scale(c, 1000) == 1.0f, "full cloud scale");
    RS_CHECK(fabsf(rs_splat_lod_radius_scale(c, 250) - 2.0f) < 1e-6f, "quarter of the splats -> radius x2");
    RS_CHECK(fabsf(rs_splat_lod_radius_scale(c, 25) - sqrtf(40.0f)) < 1e-5f, "sqrt(count / n)");
    RS_CHECK(rs_splat_lod_radius_scale(c, 0) == sqrtf(1000.0f), "n = 0 is clamped to 1");
    rs_splat_destroy(c);
    free(s);
}

// The work bound: disks that together cover hundreds of times the model (a file of whole-model splats that
// once took hours to shadow) are refused; a dense real-scan-like cloud passes.
static void test_splat_area_beyond_the_work_bound_is_refused(void)
{
    enum { N = 2000 };
    rs_splat *s = calloc(N, sizeof *s);
    RS_REQUIRE(s, "oom");
    rs_splat_header h;
    memset(&h, 0, sizeof h);
    h.face_height = 1.0f, h.lod_count = 1, h.lods[0] = N;
    for (uint32_t i = 0; i < N; i++)
        s[i] = (rs_splat){{(float)(i % 45) / 44.0f, (float)(i / 45) / 44.0f, 0.0f}, {0, 0, 1}, 0.5f, {200, 150, 130}, 0};
    rs_splat_cloud *c = NULL;
    rs_error err = {0};
    RS_CHECK(rs_splat_create(s, N, &h, &c, &err) != RS_OK && strstr(err.msg, "radii: the splats cover"),
             "2000 half-model disks: %s", c ? "accepted" : err.msg);
    rs_splat_destroy(c);
    c = NULL;
    for (uint32_t i = 0; i < N; i++) s[i].radius = 0.03f;  // about the grid spacing: a surface sample
    RS_CHECK(rs_splat_create(s, N, &h, &c, &err) == RS_OK, "%s", err.msg);
    rs_splat_destroy(c);
    free(s);
}

int main(int argc, char **argv)
{
    rs_test_init(argc, argv);
    RS_RUN(test_crc32_matches_zlib_check_values);
    RS_RUN(test_default_regions_are_weyrich_midpoints);
    RS_RUN(test_positions_round_trip_within_half_step);
    RS_RUN(test_normals_round_trip_within_0_003_degrees);
    RS_RUN(test_radius_round_trip_within_half_log_step);
    RS_RUN(test_colour_and_region_are_exact);
    RS_RUN(test_degenerate_clouds_get_a_valid_frame);
    RS_RUN(test_splat_area_beyond_the_work_bound_is_refused);
    RS_RUN(test_create_rejects_bad_splats_naming_the_index);
    RS_RUN(test_create_rejects_bad_header_tables);
    RS_RUN(test_create_fills_zero_defaults_and_orthonormal_frame);
    RS_RUN(test_save_load_round_trip_is_byte_identical);
    RS_RUN(test_save_to_file_is_atomic_and_loads);
    RS_RUN(test_file_layout_matches_docs);
    RS_RUN(test_encoder_and_layout_match_the_v1_fixture);
    RS_RUN(test_hostile_fixture_files_are_rejected);
    RS_RUN(test_every_truncation_is_rejected);
    RS_RUN(test_bad_magic_is_rejected);
    RS_RUN(test_unsupported_version_is_named);
    RS_RUN(test_flipped_payload_byte_fails_crc);
    RS_RUN(test_count_larger_than_file_is_rejected_before_allocating);
    RS_RUN(test_count_times_16_overflow_is_rejected);
    RS_RUN(test_non_finite_bbox_is_rejected);
    RS_RUN(test_zero_or_negative_radius_range_is_rejected);
    RS_RUN(test_lod_table_must_descend);
    RS_RUN(test_other_header_fields_are_checked);
    RS_RUN(test_record_region_and_flags_are_checked_naming_the_splat);
    RS_RUN(test_notes_length_and_bytes_are_checked);
    RS_RUN(test_random_damage_never_crashes_and_accepted_files_are_canonical);
    RS_RUN(test_directory_and_dev_null_give_clear_errors);
    RS_RUN(test_lod_count_picks_largest_fitting_prefix);
    return rs_test_finish();
}
